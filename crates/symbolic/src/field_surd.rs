//! The expression language lowered into ℚ(√2, √3): rotations by any multiple of π/12.
//!
//! A constant is `v + q·π + Σ nⱼ·atan2(yⱼ, xⱼ)` with `v` in ℚ(√2, √3) ([`SurdConstant`]): the
//! ℚ constant of [`ExactConstant`] with its plain part widened, so that `cos(pi/6)` written in a
//! case is a number like any other. A rotation angle is exact when its plain part is zero, its
//! π part a multiple of 1/12 (every sum of multiples of π/6 and π/4 is one) and its `atan2` part
//! an integer combination of rotations whose cosine and sine lie in the field; its own cosine and
//! sine then lie in the field.
//!
//! `atan2(y, x)` of field numbers is exact exactly when the hypotenuse `√(x² + y²)` lies in the
//! field (the cosine is `x` over it): `atan2(1, 1)` is π/4 and `atan2(2*sin(pi/3), 1)` is π/3
//! (found as twelfth turns, so they print and add as such; see `surd_atan2`), and
//! `atan2(2*sin(pi/4), 1)` = atan2(√2, 1) the rotation with cosine 1/√3 = √3/3 and sine √6/3;
//! `atan2(1, 2)` (cosine 2/√5) is refused with the reason.

use crate::field::{ExactConstant, Field};
use crate::scalar::{Rational, Scalar};
use crate::surd::Surd;

/// A rotation `(cos, sin)` with both in ℚ(√2, √3) and `cos² + sin² = 1`.
pub type SurdRotation = (Surd, Surd);

/// `value + angle + Σ n·turn`: `angle` an [`ExactConstant`] without plain part (`π` and
/// rational `atan2` multiples only), `turns` the field rotations that are neither (from
/// `atan2` of field numbers) with their multiples.
#[derive(Clone, Debug, PartialEq)]
pub struct SurdConstant {
    pub value: Surd,
    pub angle: ExactConstant,
    pub turns: Vec<(SurdRotation, Rational)>,
}

impl SurdConstant {
    fn plain(value: Surd) -> SurdConstant {
        SurdConstant {
            value,
            angle: Rational::zero_constant(),
            turns: Vec::new(),
        }
    }

    /// A pure angle: `π` and rational rotations.
    fn angle(angle: ExactConstant) -> SurdConstant {
        SurdConstant {
            value: Surd::zero(),
            angle,
            turns: Vec::new(),
        }
    }

    /// Whether the constant has an angle part (π, `atan2`).
    fn has_angle(&self) -> bool {
        self.angle != Rational::zero_constant() || !self.turns.is_empty()
    }

    /// The constant when it has no π or atan2 part.
    fn as_value(&self) -> Option<&Surd> {
        (!self.has_angle()).then_some(&self.value)
    }
}

/// `(cos, sin)` of `k·π/12`, by `k` exact turns of the 15° unit `((√6 + √2)/4, (√6 − √2)/4)`.
fn twelfth_turns(k: i64) -> (Surd, Surd) {
    let quarter = Rational::new(1.into(), 4.into());
    let c15 = Surd::new(
        Rational::zero(),
        quarter.clone(),
        Rational::zero(),
        quarter.clone(),
    );
    let s15 = Surd::new(
        Rational::zero(),
        -quarter.clone(),
        Rational::zero(),
        quarter,
    );
    let mut out = (Surd::one(), Surd::zero());
    for _ in 0..k.rem_euclid(24) {
        out = (&out.0 * &c15 - &out.1 * &s15, &out.0 * &s15 + &out.1 * &c15);
    }
    out
}

/// `(c + i s)^n` for an integer `n` (negative: the conjugate), in the field.
fn turn_power(r: &SurdRotation, n: i64) -> SurdRotation {
    let (c, s) = r;
    let s = if n < 0 { -s.clone() } else { s.clone() };
    let mut out = (Surd::one(), Surd::zero());
    for _ in 0..n.unsigned_abs() {
        out = (&out.0 * c - &out.1 * &s, &out.0 * &s + &out.1 * c);
    }
    out
}

/// `atan2(y, x)` for `(x, y) ≠ 0` in ℚ(√2, √3), when its cosine and sine lie in the field.
///
/// First as `k·π/12`, or `k·π/12` plus a rotation with rational cosine and sine: `(x, y)` turned
/// back by `k·π/12` points along the positive x axis, or along a rational direction `(1, t)`
/// with `1 + t²` a rational square. The turn is exact and the signs are decided exactly
/// ([`Surd::signum`]), so `atan2(1, 1)` is π/4 and `atan2(2*sin(pi/3), 1)` is π/3, not doubles
/// near them. Otherwise, when the hypotenuse `√(x² + y²)` lies in the field ([`Surd::sqrt`]), the
/// rotation `(x, y)/√(x² + y²)` itself. `None` when it does not (`atan2(1, 2)`: √5), and for
/// `(0, 0)`.
fn surd_atan2(y: &Surd, x: &Surd) -> Option<SurdConstant> {
    let twelfths = |k: i64| {
        let angle = Rational::mul_constants(
            &Rational::from_scalar(Rational::new(k.into(), 12.into())),
            &Rational::pi(),
        )
        .expect("a rational multiple of π");
        SurdConstant::angle(angle)
    };
    // (x, y) turned by −k·π/12.
    let turned: Vec<(i64, Surd, Surd)> = (0..24)
        .map(|k| {
            let (c, s) = twelfth_turns(k);
            (k, &c * x + &s * y, &c * y - &s * x)
        })
        .collect();
    if let Some((k, _, _)) = turned
        .iter()
        .find(|(_, u, v)| v.is_zero() && u.signum() > 0)
    {
        return Some(twelfths(*k));
    }
    let lattice = turned.iter().find_map(|(k, u, v)| {
        if u.signum() <= 0 {
            return None;
        }
        let t = (v * &u.inverse()?).as_rational()?.clone();
        let rotation = Rational::atan2(
            &Rational::from_scalar(t),
            &Rational::from_scalar(Rational::one()),
        )
        .ok()?;
        Some(Surd::add_constants(
            &twelfths(*k),
            &SurdConstant::angle(rotation),
        ))
    });
    if lattice.is_some() {
        return lattice;
    }
    let hypotenuse = (x * x + y * y).sqrt()?;
    let inverse = hypotenuse.inverse()?;
    Some(SurdConstant {
        value: Surd::zero(),
        angle: Rational::zero_constant(),
        turns: vec![((x * &inverse, y * &inverse), Rational::one())],
    })
}

impl Field for Surd {
    type Constant = SurdConstant;

    fn literal(x: f64) -> Result<SurdConstant, String> {
        let q = Rational::literal(x)?;
        Ok(SurdConstant::plain(Surd::from_rational(
            Rational::to_scalar(&q)?,
        )))
    }
    fn zero_constant() -> SurdConstant {
        SurdConstant::plain(Surd::zero())
    }
    fn pi() -> SurdConstant {
        SurdConstant::angle(Rational::pi())
    }
    fn from_scalar(c: Surd) -> SurdConstant {
        SurdConstant::plain(c)
    }
    fn constant_value(c: &SurdConstant) -> f64 {
        let turns: f64 = c
            .turns
            .iter()
            .map(|((cos, sin), n)| n.to_f64() * sin.to_f64().atan2(cos.to_f64()))
            .sum();
        c.value.to_f64() + Rational::constant_value(&c.angle) + turns
    }
    fn add_constants(a: &SurdConstant, b: &SurdConstant) -> SurdConstant {
        let mut turns = a.turns.clone();
        for (turn, n) in &b.turns {
            match turns.iter_mut().find(|(t, _)| t == turn) {
                Some((_, m)) => *m = &*m + n,
                None => turns.push((turn.clone(), n.clone())),
            }
        }
        turns.retain(|(_, n)| !n.is_zero());
        SurdConstant {
            value: &a.value + &b.value,
            angle: Rational::add_constants(&a.angle, &b.angle),
            turns,
        }
    }
    fn mul_constants(a: &SurdConstant, b: &SurdConstant) -> Result<SurdConstant, String> {
        let scale = |v: &Surd, c: &SurdConstant| -> Result<SurdConstant, String> {
            if !c.has_angle() {
                return Ok(SurdConstant::plain(v * &c.value));
            }
            let q = v.as_rational().ok_or_else(|| {
                "not exact: an angle (π or atan2) times an irrational number".to_string()
            })?;
            Ok(SurdConstant {
                value: v * &c.value,
                angle: Rational::mul_constants(&Rational::from_scalar(q.clone()), &c.angle)?,
                turns: c
                    .turns
                    .iter()
                    .map(|(t, n)| (t.clone(), n * q))
                    .filter(|(_, n)| !n.is_zero())
                    .collect(),
            })
        };
        match (a.as_value(), b.as_value()) {
            (Some(v), _) => scale(v, b),
            (None, Some(v)) => scale(v, a),
            (None, None) => {
                Err("not exact: a product of two irrational constants (π or atan2)".to_string())
            }
        }
    }
    fn reciprocal(c: &SurdConstant) -> Result<SurdConstant, String> {
        let v = c.as_value().ok_or_else(|| {
            "not exact: division by an irrational constant (π or atan2)".to_string()
        })?;
        v.inverse()
            .map(SurdConstant::plain)
            .ok_or_else(|| "division by zero".to_string())
    }
    fn pow_constant(c: &SurdConstant, n: u32) -> Result<SurdConstant, String> {
        match (c.as_value(), n) {
            (Some(v), _) => {
                let mut out = Surd::one();
                for _ in 0..n {
                    out = &out * v;
                }
                Ok(SurdConstant::plain(out))
            }
            (None, 1) => Ok(c.clone()),
            (None, 0) => Ok(SurdConstant::plain(Surd::one())),
            (None, _) => Err("not exact: a power of π or atan2".to_string()),
        }
    }
    fn atan2(y: &SurdConstant, x: &SurdConstant) -> Result<SurdConstant, String> {
        let value = |c: &SurdConstant| {
            c.as_value()
                .cloned()
                .ok_or_else(|| "not exact: atan2 of an angle (π or atan2)".to_string())
        };
        let (y, x) = (value(y)?, value(x)?);
        // Rational arguments with a rational hypotenuse: a rational rotation, as over ℚ.
        if let (Some(qy), Some(qx)) = (y.as_rational(), x.as_rational())
            && let Ok(angle) = Rational::atan2(
                &Rational::from_scalar(qy.clone()),
                &Rational::from_scalar(qx.clone()),
            )
        {
            return Ok(SurdConstant::angle(angle));
        }
        surd_atan2(&y, &x).ok_or_else(|| {
            format!(
                "not exact: atan2({y}, {x}) has cosine x/√(x² + y²), and √(x² + y²) = √({}) \
                 is not in ℚ(√2, √3) (nor is the angle a multiple of π/12)",
                &x * &x + &y * &y
            )
        })
    }
    fn to_scalar(c: &SurdConstant) -> Result<Surd, String> {
        c.as_value().cloned().ok_or_else(|| {
            "not exact: π or atan2 appears outside a rotation angle (the value is transcendental)"
                .to_string()
        })
    }
    fn cos_sin(c: &SurdConstant) -> Result<(Surd, Surd), String> {
        if !c.value.is_zero() {
            return Err(format!(
                "not exact: the angle constant {} rad has a transcendental cosine (write \
                 multiples of pi/12, such as pi/6 or pi/4, or atan2(y, x) with x, y in the field \
                 and √(x² + y²) too)",
                c.value
            ));
        }
        let twelfths = &c.angle.pi * Rational::from_integer(12.into());
        if !twelfths.is_integer() {
            return Err(format!(
                "not exact: {}·π is not a multiple of π/12 (its cosine is not in ℚ(√2, √3))",
                c.angle.pi
            ));
        }
        let k = twelfths.to_integer() % num_bigint::BigInt::from(24);
        let k = i64::try_from(k).expect("remainder of 24 fits");
        let (c0, s0) = twelfth_turns(k);
        let rotations = ExactConstant {
            rational: Rational::zero(),
            pi: Rational::zero(),
            rotations: c.angle.rotations.clone(),
        };
        let (c1, s1) = Rational::cos_sin(&rotations)?;
        let (c1, s1) = (Surd::from_rational(c1), Surd::from_rational(s1));
        let mut out = (&c0 * &c1 - &s0 * &s1, &c0 * &s1 + &s0 * &c1);
        for (turn, n) in &c.turns {
            if !n.is_integer() {
                return Err(format!(
                    "not exact: a fractional multiple ({n}) of an atan2 rotation"
                ));
            }
            let n = i64::try_from(n.to_integer())
                .ok()
                .filter(|n| n.abs() <= 64)
                .ok_or_else(|| "not exact: an atan2 multiple beyond 64".to_string())?;
            let (c2, s2) = turn_power(turn, n);
            out = (&out.0 * &c2 - &out.1 * &s2, &out.0 * &s2 + &out.1 * &c2);
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_bigint::BigInt;

    fn q(n: i64, d: i64) -> Rational {
        Rational::new(BigInt::from(n), BigInt::from(d))
    }

    fn pi_times(n: i64, d: i64) -> SurdConstant {
        Surd::mul_constants(
            &Surd::from_scalar(Surd::from_rational(q(n, d))),
            &Surd::pi(),
        )
        .unwrap()
    }

    #[test]
    fn twelfths_of_a_turn_are_the_table_values() {
        let half = Surd::from_rational(q(1, 2));
        let root3_2 = Surd::new(q(0, 1), q(0, 1), q(1, 2), q(0, 1));
        let root2_2 = Surd::new(q(0, 1), q(1, 2), q(0, 1), q(0, 1));
        // 120°: (−1/2, √3/2); 45°: (√2/2, √2/2); −30°: (√3/2, −1/2); 180°: (−1, 0).
        assert_eq!(
            Surd::cos_sin(&pi_times(2, 3)),
            Ok((-half.clone(), root3_2.clone()))
        );
        assert_eq!(
            Surd::cos_sin(&pi_times(1, 4)),
            Ok((root2_2.clone(), root2_2.clone()))
        );
        assert_eq!(
            Surd::cos_sin(&pi_times(-1, 6)),
            Ok((root3_2.clone(), -half.clone()))
        );
        assert_eq!(
            Surd::cos_sin(&pi_times(1, 1)),
            Ok((-Surd::one(), Surd::zero()))
        );
        // π/6 + π/4 = 5π/12: cos 75° = (√6 − √2)/4, sin 75° = (√6 + √2)/4.
        let sum = Surd::add_constants(&pi_times(1, 6), &pi_times(1, 4));
        assert_eq!(
            Surd::cos_sin(&sum),
            Ok((
                Surd::new(q(0, 1), q(-1, 4), q(0, 1), q(1, 4)),
                Surd::new(q(0, 1), q(1, 4), q(0, 1), q(1, 4)),
            ))
        );
        // Every twelfth: cos² + sin² = 1 and agreement with libm.
        for k in -24..=24 {
            let (c, s) = Surd::cos_sin(&pi_times(k, 12)).unwrap();
            assert_eq!(&c * &c + &s * &s, Surd::one());
            let angle = k as f64 * std::f64::consts::PI / 12.0;
            assert!((c.to_f64() - angle.cos()).abs() < 1e-15, "{k}");
            assert!((s.to_f64() - angle.sin()).abs() < 1e-15, "{k}");
        }
    }

    #[test]
    fn huge_multiples_of_a_twelfth_reduce_modulo_a_turn() {
        // (24·10²⁰ + 2)·π/12 is 10²⁰ whole turns plus π/6: (√3/2, 1/2), without overflow.
        let turns = Rational::from_integer(num_bigint::BigInt::from(10).pow(20) * 24 + 2);
        let angle = Surd::mul_constants(
            &Surd::from_scalar(Surd::from_rational(turns / q(12, 1))),
            &Surd::pi(),
        )
        .unwrap();
        assert_eq!(
            Surd::cos_sin(&angle),
            Ok((
                Surd::new(q(0, 1), q(0, 1), q(1, 2), q(0, 1)),
                Surd::from_rational(q(1, 2))
            ))
        );
    }

    #[test]
    fn rational_rotations_combine_with_twelfths() {
        // atan2(4, 3) + π/3: cos = 3/5·1/2 − 4/5·√3/2 = 3/10 − 2/5√3,
        // sin = 4/5·1/2 + 3/5·√3/2 = 2/5 + 3/10√3.
        let four = Surd::from_scalar(Surd::from_rational(q(4, 1)));
        let three = Surd::from_scalar(Surd::from_rational(q(3, 1)));
        let rot = Surd::atan2(&four, &three).unwrap();
        let angle = Surd::add_constants(&rot, &pi_times(1, 3));
        assert_eq!(
            Surd::cos_sin(&angle),
            Ok((
                Surd::new(q(3, 10), q(0, 1), q(-2, 5), q(0, 1)),
                Surd::new(q(2, 5), q(0, 1), q(3, 10), q(0, 1)),
            ))
        );
    }

    fn c(v: Surd) -> SurdConstant {
        Surd::from_scalar(v)
    }

    fn r(n: i64, d: i64) -> Surd {
        Surd::from_rational(q(n, d))
    }

    #[test]
    fn atan2_of_field_numbers_is_a_twelfth_turn_by_hand() {
        let root2_2 = Surd::new(q(0, 1), q(1, 2), q(0, 1), q(0, 1));
        let root3_2 = Surd::new(q(0, 1), q(0, 1), q(1, 2), q(0, 1));
        // atan2(1, 1) = π/4: the constant itself is π/4 (no rotation part), cos = sin = √2/2.
        let quarter = Surd::atan2(&c(r(1, 1)), &c(r(1, 1))).unwrap();
        assert_eq!(quarter, pi_times(1, 4));
        assert_eq!(
            Surd::cos_sin(&quarter),
            Ok((root2_2.clone(), root2_2.clone()))
        );
        assert!((Surd::constant_value(&quarter) - std::f64::consts::FRAC_PI_4).abs() < 1e-15);
        // atan2(√3, 1) = π/3: (1/2, √3/2).
        let third = Surd::atan2(&c(Surd::sqrt3()), &c(r(1, 1))).unwrap();
        assert_eq!(Surd::cos_sin(&third), Ok((r(1, 2), root3_2.clone())));
        // atan2(−1, −√3) = −150°: (−√3/2, −1/2).
        let third_quadrant = Surd::atan2(&c(r(-1, 1)), &c(-Surd::sqrt3())).unwrap();
        assert_eq!(
            Surd::cos_sin(&third_quadrant),
            Ok((-root3_2.clone(), r(-1, 2)))
        );
        // atan2(1, 2 + √3) = 15° (tan 15° = 2 − √3 = 1/(2 + √3)): ((√6 + √2)/4, (√6 − √2)/4).
        let two_plus_root3 = &r(2, 1) + &Surd::sqrt3();
        let fifteen = Surd::atan2(&c(r(1, 1)), &c(two_plus_root3)).unwrap();
        assert_eq!(
            Surd::cos_sin(&fifteen),
            Ok((
                Surd::new(q(0, 1), q(1, 4), q(0, 1), q(1, 4)),
                Surd::new(q(0, 1), q(-1, 4), q(0, 1), q(1, 4)),
            ))
        );
        // On the axes: atan2(√2, 0) = π/2, atan2(0, −√3) = π.
        let up = Surd::atan2(&c(Surd::sqrt2()), &c(r(0, 1))).unwrap();
        assert_eq!(Surd::cos_sin(&up), Ok((r(0, 1), r(1, 1))));
        let back = Surd::atan2(&c(r(0, 1)), &c(-Surd::sqrt3())).unwrap();
        assert_eq!(Surd::cos_sin(&back), Ok((r(-1, 1), r(0, 1))));
        // (−√2/2, 7√2/2) is (3, 4) turned by 45°: π/4 + atan2(4, 3), with
        // cos = √2/2·3/5 − √2/2·4/5 = −√2/10 and sin = √2/2·(4/5 + 3/5) = 7√2/10.
        let x = Surd::new(q(0, 1), q(-1, 2), q(0, 1), q(0, 1));
        let y = Surd::new(q(0, 1), q(7, 2), q(0, 1), q(0, 1));
        let mixed = Surd::atan2(&c(y), &c(x)).unwrap();
        assert_eq!(
            Surd::cos_sin(&mixed),
            Ok((
                Surd::new(q(0, 1), q(-1, 10), q(0, 1), q(0, 1)),
                Surd::new(q(0, 1), q(7, 10), q(0, 1), q(0, 1)),
            ))
        );
        // Rational arguments with a rational hypotenuse stay the rational rotation.
        let rational = Surd::atan2(&c(r(4, 1)), &c(r(3, 1))).unwrap();
        assert_eq!(Surd::cos_sin(&rational), Ok((r(3, 5), r(4, 5))));
    }

    #[test]
    fn atan2_is_exact_when_the_hypotenuse_is_in_the_field_and_refused_otherwise() {
        // cos atan2(1, 2) = 2/√5: not in ℚ(√2, √3).
        let err = Surd::atan2(&c(r(1, 1)), &c(r(2, 1))).unwrap_err();
        assert!(err.contains("ℚ(√2, √3)") && err.contains("√(5)"), "{err}");
        assert!(err.contains("atan2(1, 2)"), "{err}");
        // (1, √2): 54.7°, no twelfth turn (turned back by 45°, tan = 3 − 2√2 is irrational),
        // but its hypotenuse √3 is in the field: cos = 1/√3 = √3/3, sin = √2/√3 = √6/3.
        let tilted = Surd::atan2(&c(Surd::sqrt2()), &c(r(1, 1))).unwrap();
        assert_eq!(
            Surd::cos_sin(&tilted),
            Ok((
                Surd::new(q(0, 1), q(0, 1), q(1, 3), q(0, 1)),
                Surd::new(q(0, 1), q(0, 1), q(0, 1), q(1, 3)),
            ))
        );
        // Twice that angle: cos 2θ = 2/3 − 1 = −1/3, sin 2θ = 2·√3/3·√6/3 = 2√2/3.
        let twice = Surd::mul_constants(&c(r(2, 1)), &tilted).unwrap();
        assert_eq!(
            Surd::cos_sin(&twice),
            Ok((r(-1, 3), Surd::new(q(0, 1), q(2, 3), q(0, 1), q(0, 1))))
        );
        assert!((Surd::constant_value(&twice) - 2.0 * 2f64.sqrt().atan()).abs() < 1e-15);
        // Half of it is refused where a rotation needs it.
        let half = Surd::mul_constants(&c(r(1, 2)), &tilted).unwrap();
        assert!(Surd::cos_sin(&half).unwrap_err().contains("fractional"));
        // An angle as an argument.
        let err = Surd::atan2(&Surd::pi(), &c(r(1, 1))).unwrap_err();
        assert!(err.contains("angle"), "{err}");
    }

    #[test]
    fn other_angles_and_products_are_refused_with_a_reason() {
        assert!(Surd::cos_sin(&pi_times(1, 5)).unwrap_err().contains("π/12"));
        let small = Surd::literal(0.3).unwrap();
        assert!(Surd::cos_sin(&small).unwrap_err().contains("3/10 rad"));
        assert!(Surd::to_scalar(&Surd::pi()).is_err());
        assert!(Surd::mul_constants(&Surd::pi(), &Surd::pi()).is_err());
        // √3·π is no angle of the field's rotations.
        let root3 = Surd::from_scalar(Surd::sqrt3());
        assert!(Surd::mul_constants(&root3, &Surd::pi()).is_err());
        // 1/(√2 + √3) = √3 − √2 as a constant.
        let x = Surd::from_scalar(&Surd::sqrt2() + &Surd::sqrt3());
        assert_eq!(
            Surd::to_scalar(&Surd::reciprocal(&x).unwrap()),
            Ok(&Surd::sqrt3() - &Surd::sqrt2())
        );
    }
}
