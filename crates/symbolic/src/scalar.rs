//! Coefficient fields of the polynomial algebra: `f64` for the numeric workhorse (kinematics,
//! dynamics, optimisation) and exact rationals for the balance decision.
//!
//! One algebra serves both, so the exact energy polynomials are built by the very code that
//! builds the numeric ones: a formula cannot differ between the two paths.

use std::fmt::Debug;

use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{One, Signed, ToPrimitive, Zero};

/// An exact rational number.
pub type Rational = BigRational;

/// What a polynomial coefficient must support.
pub trait Scalar: Clone + PartialEq + Debug + Default + Send + Sync + 'static {
    fn zero() -> Self;
    fn one() -> Self;
    fn is_zero(&self) -> bool;
    fn from_i64(value: i64) -> Self;
    /// `numerator / denominator` (`denominator ≠ 0`).
    fn from_ratio(numerator: i64, denominator: i64) -> Self;
    fn add_ref(&self, other: &Self) -> Self;
    fn mul_ref(&self, other: &Self) -> Self;
    fn neg_ref(&self) -> Self;
    /// The nearest double (exact for `f64`).
    fn to_f64(&self) -> f64;
}

impl Scalar for f64 {
    fn zero() -> f64 {
        0.0
    }
    fn one() -> f64 {
        1.0
    }
    fn is_zero(&self) -> bool {
        *self == 0.0
    }
    fn from_i64(value: i64) -> f64 {
        value as f64
    }
    fn from_ratio(numerator: i64, denominator: i64) -> f64 {
        numerator as f64 / denominator as f64
    }
    fn add_ref(&self, other: &f64) -> f64 {
        self + other
    }
    fn mul_ref(&self, other: &f64) -> f64 {
        self * other
    }
    fn neg_ref(&self) -> f64 {
        -self
    }
    fn to_f64(&self) -> f64 {
        *self
    }
}

impl Scalar for Rational {
    fn zero() -> Rational {
        <Rational as Zero>::zero()
    }
    fn one() -> Rational {
        <Rational as One>::one()
    }
    fn is_zero(&self) -> bool {
        Zero::is_zero(self)
    }
    fn from_i64(value: i64) -> Rational {
        Rational::from_integer(BigInt::from(value))
    }
    fn from_ratio(numerator: i64, denominator: i64) -> Rational {
        Rational::new(BigInt::from(numerator), BigInt::from(denominator))
    }
    fn add_ref(&self, other: &Rational) -> Rational {
        self + other
    }
    fn mul_ref(&self, other: &Rational) -> Rational {
        self * other
    }
    fn neg_ref(&self) -> Rational {
        -self
    }
    fn to_f64(&self) -> f64 {
        rational_to_f64(self)
    }
}

/// The double nearest to `q` (also for numerators and denominators beyond the `f64` range).
pub fn rational_to_f64(q: &Rational) -> f64 {
    if let Some(x) = ToPrimitive::to_f64(q).filter(|x| x.is_finite() && *x != 0.0) {
        return x;
    }
    if Zero::is_zero(q.numer()) {
        return 0.0;
    }
    // Scale both parts down by the same power of two so that their ratio survives.
    let shift = |n: &BigInt| n.bits().saturating_sub(1000);
    let (num, den) = (q.numer(), q.denom());
    let s = shift(num).max(shift(den));
    let num = (num >> s).to_f64().unwrap_or(f64::NAN);
    let den = (den >> s).to_f64().unwrap_or(f64::NAN);
    if den == 0.0 {
        return if num > 0.0 {
            f64::INFINITY
        } else {
            f64::NEG_INFINITY
        };
    }
    num / den
}

/// The decimal a designer wrote, recovered from the double it was read into: the shortest
/// decimal that rounds to `x` (Rust's `Display` of `f64`), taken as an exact rational.
///
/// `0.3` in a case file is read as the double nearest to 3/10; this returns exactly 3/10, so
/// geometric coincidences the designer wrote (`0.1 + 0.2 = 0.3`) hold exactly. Returns `None`
/// for NaN and infinities.
pub fn decimal_to_rational(x: f64) -> Option<Rational> {
    if !x.is_finite() {
        return None;
    }
    let text = format!("{x:e}"); // shortest round-trip digits: `-1.234e-5`
    let (mantissa, exponent) = text.split_once('e')?;
    let exponent: i64 = exponent.parse().ok()?;
    let negative = mantissa.starts_with('-');
    let digits_part = mantissa.trim_start_matches('-');
    let (int_part, frac_part) = digits_part.split_once('.').unwrap_or((digits_part, ""));
    let digits: BigInt = format!("{int_part}{frac_part}").parse().ok()?;
    let scale = exponent - frac_part.len() as i64;
    let ten = BigInt::from(10);
    let magnitude = if scale >= 0 {
        Rational::from_integer(digits * num_traits::pow(ten, scale as usize))
    } else {
        Rational::new(digits, num_traits::pow(ten, (-scale) as usize))
    };
    Some(if negative { -magnitude } else { magnitude })
}

/// The exact square root of a non-negative rational, when it is rational.
pub fn rational_sqrt(q: &Rational) -> Option<Rational> {
    if q.is_negative() {
        return None;
    }
    let root = |n: &BigInt| {
        let r = n.sqrt();
        (&r * &r == *n).then_some(r)
    };
    Some(Rational::new(root(q.numer())?, root(q.denom())?))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn q(n: i64, d: i64) -> Rational {
        Rational::new(BigInt::from(n), BigInt::from(d))
    }

    #[test]
    fn decimals_are_recovered_exactly() {
        assert_eq!(decimal_to_rational(0.3), Some(q(3, 10)));
        assert_eq!(decimal_to_rational(-9.81), Some(q(-981, 100)));
        assert_eq!(decimal_to_rational(124.875), Some(q(999, 8)));
        assert_eq!(decimal_to_rational(1e-20), Some(q(1, 1) / q(10, 1).pow(20)));
        assert_eq!(
            decimal_to_rational(2.5e21),
            Some(q(25, 1) * q(10, 1).pow(20))
        );
        assert_eq!(decimal_to_rational(0.0), Some(q(0, 1)));
        assert_eq!(decimal_to_rational(f64::NAN), None);
        // One ulp above 0.3 is a different decimal, and stays different.
        let above = f64::from_bits(0.3f64.to_bits() + 1);
        assert_eq!(
            decimal_to_rational(above),
            Some(q(30000000000000004, 1) / q(10, 1).pow(17))
        );
        // The recovered decimal rounds back to the same double.
        for x in [0.1, 1.0 / 3.0, 6.02214076e23, -4.9e-324, f64::MAX] {
            let r = decimal_to_rational(x).unwrap();
            assert_eq!(rational_to_f64(&r), x, "{x}");
        }
    }

    #[test]
    fn square_roots_of_squares_only() {
        assert_eq!(rational_sqrt(&q(9, 25)), Some(q(3, 5)));
        assert_eq!(rational_sqrt(&q(2, 1)), None);
        assert_eq!(rational_sqrt(&q(-4, 1)), None);
    }
}
