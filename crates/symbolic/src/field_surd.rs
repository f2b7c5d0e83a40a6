//! The expression language lowered into ℚ(√2, √3): rotations by any multiple of π/12.
//!
//! A constant is `v + q·π + Σ nⱼ·atan2(yⱼ, xⱼ)` with `v` in ℚ(√2, √3) ([`SurdConstant`]): the
//! ℚ constant of [`ExactConstant`] with its plain part widened, so that `cos(pi/6)` written in a
//! case is a number like any other. A rotation angle is exact when its plain part is zero, its
//! π part a multiple of 1/12 (every sum of multiples of π/6 and π/4 is one) and its `atan2` part
//! an integer combination of rational rotations; its cosine and sine then lie in the field.

use crate::field::{ExactConstant, Field};
use crate::scalar::{Rational, Scalar};
use crate::surd::Surd;

/// `value + angle`, `angle` being an [`ExactConstant`] without plain part (`π` and `atan2`
/// multiples only).
#[derive(Clone, Debug, PartialEq)]
pub struct SurdConstant {
    pub value: Surd,
    pub angle: ExactConstant,
}

impl SurdConstant {
    fn plain(value: Surd) -> SurdConstant {
        SurdConstant {
            value,
            angle: Rational::zero_constant(),
        }
    }

    /// The constant when it has no π or atan2 part.
    fn as_value(&self) -> Option<&Surd> {
        (self.angle == Rational::zero_constant()).then_some(&self.value)
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
        SurdConstant {
            value: Surd::zero(),
            angle: Rational::pi(),
        }
    }
    fn from_scalar(c: Surd) -> SurdConstant {
        SurdConstant::plain(c)
    }
    fn constant_value(c: &SurdConstant) -> f64 {
        c.value.to_f64() + Rational::constant_value(&c.angle)
    }
    fn add_constants(a: &SurdConstant, b: &SurdConstant) -> SurdConstant {
        SurdConstant {
            value: &a.value + &b.value,
            angle: Rational::add_constants(&a.angle, &b.angle),
        }
    }
    fn mul_constants(a: &SurdConstant, b: &SurdConstant) -> Result<SurdConstant, String> {
        let scale = |v: &Surd, c: &SurdConstant| -> Result<SurdConstant, String> {
            let angle = if c.angle == Rational::zero_constant() {
                c.angle.clone()
            } else {
                let q = v.as_rational().ok_or_else(|| {
                    "not exact: an angle (π or atan2) times an irrational number".to_string()
                })?;
                Rational::mul_constants(&Rational::from_scalar(q.clone()), &c.angle)?
            };
            Ok(SurdConstant {
                value: v * &c.value,
                angle,
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
        let rational = |c: &SurdConstant| {
            c.as_value()
                .and_then(Surd::as_rational)
                .map(|q| Rational::from_scalar(q.clone()))
                .ok_or_else(|| "not exact: atan2 of irrational arguments".to_string())
        };
        Ok(SurdConstant {
            value: Surd::zero(),
            angle: Rational::atan2(&rational(y)?, &rational(x)?)?,
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
                 multiples of pi/12, such as pi/6 or pi/4, or atan2(y, x) with a rational \
                 hypotenuse)",
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
        Ok((&c0 * &c1 - &s0 * &s1, &c0 * &s1 + &s0 * &c1))
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
