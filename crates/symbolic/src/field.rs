//! What the expression language needs of a coefficient field: how a literal, `pi`, `atan2` and
//! the constant part of an angle are represented, and which of them it can hold.
//!
//! For `f64` everything is a double. For exact rationals a constant is
//! `q₀ + q₁·π + Σ nⱼ·atan2(yⱼ, xⱼ)` ([`ExactConstant`]): the polynomial coefficients it can
//! become are the rational ones (`q₁ = 0`, no `atan2`), and the rotation angles whose cosine and
//! sine are rational are the multiples of π/2 plus integer multiples of rational rotations
//! (`atan2(4, 3)`). Anything else is refused as *not exact* with the reason, and the caller
//! takes the numeric path.

use std::fmt::Debug;

use crate::scalar::{Rational, Scalar, decimal_to_rational, rational_sqrt};

/// A coefficient field the expression language can be lowered into.
pub trait Field: Scalar {
    /// The value of a coordinate-free expression.
    type Constant: Clone + Debug;
    /// A number literal (read as a double by the tokenizer).
    fn literal(x: f64) -> Result<Self::Constant, String>;
    fn zero_constant() -> Self::Constant;
    fn pi() -> Self::Constant;
    fn from_scalar(c: Self) -> Self::Constant;
    /// The constant's value as a double (for checks such as "is the exponent an integer").
    fn constant_value(c: &Self::Constant) -> f64;
    fn add_constants(a: &Self::Constant, b: &Self::Constant) -> Self::Constant;
    fn mul_constants(a: &Self::Constant, b: &Self::Constant) -> Result<Self::Constant, String>;
    /// `1/c` for a non-zero `c`.
    fn reciprocal(c: &Self::Constant) -> Result<Self::Constant, String>;
    fn pow_constant(c: &Self::Constant, n: u32) -> Result<Self::Constant, String>;
    /// The angle `atan2(y, x)` for `(x, y) ≠ 0`.
    fn atan2(y: &Self::Constant, x: &Self::Constant) -> Result<Self::Constant, String>;
    /// The constant as a polynomial coefficient.
    fn to_scalar(c: &Self::Constant) -> Result<Self, String>;
    /// `(cos c, sin c)` of an angle constant.
    fn cos_sin(c: &Self::Constant) -> Result<(Self, Self), String>;
}

impl Field for f64 {
    type Constant = f64;
    fn literal(x: f64) -> Result<f64, String> {
        Ok(x)
    }
    fn zero_constant() -> f64 {
        0.0
    }
    fn pi() -> f64 {
        std::f64::consts::PI
    }
    fn from_scalar(c: f64) -> f64 {
        c
    }
    fn constant_value(c: &f64) -> f64 {
        *c
    }
    fn add_constants(a: &f64, b: &f64) -> f64 {
        a + b
    }
    fn mul_constants(a: &f64, b: &f64) -> Result<f64, String> {
        Ok(a * b)
    }
    fn reciprocal(c: &f64) -> Result<f64, String> {
        Ok(1.0 / c)
    }
    fn pow_constant(c: &f64, n: u32) -> Result<f64, String> {
        Ok(c.powi(n as i32))
    }
    fn atan2(y: &f64, x: &f64) -> Result<f64, String> {
        Ok(y.atan2(*x))
    }
    fn to_scalar(c: &f64) -> Result<f64, String> {
        Ok(*c)
    }
    fn cos_sin(c: &f64) -> Result<(f64, f64), String> {
        let (s, c) = c.sin_cos();
        Ok((c, s))
    }
}

/// A rotation whose cosine and sine are rational: `(cos, sin)` with `cos² + sin² = 1`.
pub type RationalRotation = (Rational, Rational);

/// An exact constant `rational + pi·π + Σ n·atan2(sin, cos)` (see the module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct ExactConstant {
    pub rational: Rational,
    /// Coefficient of π.
    pub pi: Rational,
    /// Rational rotations and their (rational) multiples, in order of first appearance.
    pub rotations: Vec<(RationalRotation, Rational)>,
}

impl ExactConstant {
    fn rational(q: Rational) -> ExactConstant {
        ExactConstant {
            rational: q,
            pi: Rational::zero(),
            rotations: Vec::new(),
        }
    }

    /// The constant when it is a plain rational number.
    fn as_rational(&self) -> Option<&Rational> {
        (self.pi.is_zero() && self.rotations.is_empty()).then_some(&self.rational)
    }

    fn scaled(&self, s: &Rational) -> ExactConstant {
        ExactConstant {
            rational: &self.rational * s,
            pi: &self.pi * s,
            rotations: self
                .rotations
                .iter()
                .map(|(r, n)| (r.clone(), n * s))
                .filter(|(_, n)| !n.is_zero())
                .collect(),
        }
    }
}

const NOT_RATIONAL: &str =
    "not exact: π or atan2 appears outside a rotation angle (the value is irrational)";

fn rational_power(q: &Rational, n: u32) -> Rational {
    num_traits::pow(q.clone(), n as usize)
}

/// `(c + i s)^n` for an integer `n` (negative: the conjugate).
fn rotation_power(r: &RationalRotation, n: i64) -> RationalRotation {
    let (c, s) = r;
    let s = if n < 0 { -s.clone() } else { s.clone() };
    let mut out = (Rational::one(), Rational::zero());
    for _ in 0..n.unsigned_abs() {
        out = (&out.0 * c - &out.1 * &s, &out.0 * &s + &out.1 * c);
    }
    out
}

impl Field for Rational {
    type Constant = ExactConstant;

    fn literal(x: f64) -> Result<ExactConstant, String> {
        decimal_to_rational(x)
            .map(ExactConstant::rational)
            .ok_or_else(|| format!("not exact: {x} is not a finite number"))
    }
    fn zero_constant() -> ExactConstant {
        ExactConstant::rational(Rational::zero())
    }
    fn pi() -> ExactConstant {
        ExactConstant {
            rational: Rational::zero(),
            pi: Rational::one(),
            rotations: Vec::new(),
        }
    }
    fn from_scalar(c: Rational) -> ExactConstant {
        ExactConstant::rational(c)
    }
    fn constant_value(c: &ExactConstant) -> f64 {
        let rotations: f64 = c
            .rotations
            .iter()
            .map(|((cos, sin), n)| n.to_f64() * sin.to_f64().atan2(cos.to_f64()))
            .sum();
        c.rational.to_f64() + c.pi.to_f64() * std::f64::consts::PI + rotations
    }
    fn add_constants(a: &ExactConstant, b: &ExactConstant) -> ExactConstant {
        let mut out = ExactConstant {
            rational: &a.rational + &b.rational,
            pi: &a.pi + &b.pi,
            rotations: a.rotations.clone(),
        };
        for (rotation, n) in &b.rotations {
            match out.rotations.iter_mut().find(|(r, _)| r == rotation) {
                Some((_, m)) => *m = &*m + n,
                None => out.rotations.push((rotation.clone(), n.clone())),
            }
        }
        out.rotations.retain(|(_, n)| !n.is_zero());
        out
    }
    fn mul_constants(a: &ExactConstant, b: &ExactConstant) -> Result<ExactConstant, String> {
        if let Some(q) = a.as_rational() {
            Ok(b.scaled(q))
        } else if let Some(q) = b.as_rational() {
            Ok(a.scaled(q))
        } else {
            Err("not exact: a product of two irrational constants (π or atan2)".to_string())
        }
    }
    fn reciprocal(c: &ExactConstant) -> Result<ExactConstant, String> {
        let q = c.as_rational().ok_or_else(|| {
            "not exact: division by an irrational constant (π or atan2)".to_string()
        })?;
        Ok(ExactConstant::rational(q.recip()))
    }
    fn pow_constant(c: &ExactConstant, n: u32) -> Result<ExactConstant, String> {
        match (c.as_rational(), n) {
            (Some(q), _) => Ok(ExactConstant::rational(rational_power(q, n))),
            (None, 1) => Ok(c.clone()),
            (None, 0) => Ok(ExactConstant::rational(Rational::one())),
            (None, _) => Err("not exact: a power of π or atan2".to_string()),
        }
    }
    fn atan2(y: &ExactConstant, x: &ExactConstant) -> Result<ExactConstant, String> {
        let (Some(y), Some(x)) = (y.as_rational(), x.as_rational()) else {
            return Err("not exact: atan2 of irrational arguments".to_string());
        };
        let hypotenuse = rational_sqrt(&(x * x + y * y)).ok_or_else(|| {
            format!(
                "not exact: atan2({y}, {x}) has an irrational cosine (√(x² + y²) is irrational)"
            )
        })?;
        Ok(ExactConstant {
            rational: Rational::zero(),
            pi: Rational::zero(),
            rotations: vec![((x / &hypotenuse, y / &hypotenuse), Rational::one())],
        })
    }
    fn to_scalar(c: &ExactConstant) -> Result<Rational, String> {
        c.as_rational()
            .cloned()
            .ok_or_else(|| NOT_RATIONAL.to_string())
    }
    fn cos_sin(c: &ExactConstant) -> Result<(Rational, Rational), String> {
        if !c.rational.is_zero() {
            return Err(format!(
                "not exact: the angle constant {} rad has an irrational cosine (write multiples \
                 of pi/2, or atan2(y, x) with a rational hypotenuse)",
                c.rational
            ));
        }
        let quarter_turns = &c.pi * Rational::from_integer(2.into());
        if !quarter_turns.is_integer() {
            return Err(format!(
                "not exact: {}·π is not a multiple of π/2 (its cosine is irrational)",
                c.pi
            ));
        }
        let k = quarter_turns.to_integer() % num_bigint::BigInt::from(4);
        let k: i64 = i64::try_from(k).expect("remainder of 4 fits").rem_euclid(4);
        let mut out: RationalRotation = match k {
            0 => (Rational::one(), Rational::zero()),
            1 => (Rational::zero(), Rational::one()),
            2 => (-Rational::one(), Rational::zero()),
            _ => (Rational::zero(), -Rational::one()),
        };
        for (rotation, n) in &c.rotations {
            if !n.is_integer() {
                return Err(format!(
                    "not exact: a fractional multiple ({n}) of an atan2 rotation"
                ));
            }
            let n = i64::try_from(n.to_integer())
                .ok()
                .filter(|n| n.abs() <= 64)
                .ok_or_else(|| "not exact: an atan2 multiple beyond 64".to_string())?;
            let (c2, s2) = rotation_power(rotation, n);
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

    #[test]
    fn quarter_turns_and_rational_rotations_are_exact() {
        let half_pi = Rational::pi().scaled(&q(1, 2));
        assert_eq!(Rational::cos_sin(&half_pi), Ok((q(0, 1), q(1, 1))));
        let minus_pi = Rational::pi().scaled(&q(-1, 1));
        assert_eq!(Rational::cos_sin(&minus_pi), Ok((q(-1, 1), q(0, 1))));
        let rot = Rational::atan2(
            &ExactConstant::rational(q(4, 1)),
            &ExactConstant::rational(q(3, 1)),
        )
        .unwrap();
        assert_eq!(Rational::cos_sin(&rot), Ok((q(3, 5), q(4, 5))));
        // cos(2φ) = 2·(3/5)² − 1 = −7/25, sin(2φ) = 2·(3/5)(4/5) = 24/25; plus π/2 turns it.
        let twice = Rational::add_constants(&rot, &rot);
        assert_eq!(Rational::cos_sin(&twice), Ok((q(-7, 25), q(24, 25))));
        let turned = Rational::add_constants(&twice, &half_pi);
        assert_eq!(Rational::cos_sin(&turned), Ok((q(-24, 25), q(-7, 25))));
        let back = Rational::add_constants(&rot, &rot.scaled(&q(-1, 1)));
        assert_eq!(Rational::cos_sin(&back), Ok((q(1, 1), q(0, 1))));
    }

    #[test]
    fn irrational_constants_are_refused_with_a_reason() {
        let third_pi = Rational::pi().scaled(&q(1, 3));
        assert!(Rational::cos_sin(&third_pi).unwrap_err().contains("π/2"));
        let small = ExactConstant::rational(q(3, 10));
        assert!(Rational::cos_sin(&small).unwrap_err().contains("3/10 rad"));
        let one = ExactConstant::rational(q(1, 1));
        assert!(
            Rational::atan2(&one, &one)
                .unwrap_err()
                .contains("irrational")
        );
        assert!(Rational::to_scalar(&Rational::pi()).is_err());
        assert!(Rational::mul_constants(&Rational::pi(), &Rational::pi()).is_err());
        assert!(Rational::reciprocal(&Rational::pi()).is_err());
    }
}
