//! What the exact balance decision needs of its numbers: an ordered field with exact arithmetic.
//!
//! Two fields implement it: the rationals (every case whose rotations are quarter turns or
//! rational rotations) and ℚ(√2, √3) ([`Surd`], rotations by multiples of π/12). Elimination,
//! Fourier–Motzkin and the rank-one test are written once over this trait, so a proof reads the
//! same in both fields. Generic code asks for `for<'a> &'a F: RefArith<F>` to keep writing
//! `&a * &b` (the trait cannot imply that bound on references by itself).

use std::fmt::Display;
use std::ops::{Add, AddAssign, Div, Mul, Neg, Sub, SubAssign};

use num_traits::Signed;

use crate::scalar::{Rational, Scalar};
use crate::surd::Surd;

/// An exact ordered field.
pub trait Ordered:
    Scalar
    + Ord
    + Display
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + for<'a> Add<&'a Self, Output = Self>
    + for<'a> Sub<&'a Self, Output = Self>
    + for<'a> Mul<&'a Self, Output = Self>
    + for<'a> Div<&'a Self, Output = Self>
    + AddAssign
    + SubAssign
    + for<'a> AddAssign<&'a Self>
    + for<'a> SubAssign<&'a Self>
{
    /// The field's name as `check` states it (`ℚ`, `ℚ(√2, √3)`).
    const NAME: &'static str;
    fn is_positive(&self) -> bool;
    fn is_negative(&self) -> bool;
    fn from_rational(q: Rational) -> Self;
    /// The element when it is rational.
    fn rational(&self) -> Option<Rational>;
}

/// Arithmetic on references: `&a op &b` and `&a op b`.
pub trait RefArith<F>:
    Sized
    + Add<Self, Output = F>
    + Sub<Self, Output = F>
    + Mul<Self, Output = F>
    + Div<Self, Output = F>
    + Add<F, Output = F>
    + Sub<F, Output = F>
    + Mul<F, Output = F>
    + Div<F, Output = F>
    + Neg<Output = F>
{
}

impl<T, F> RefArith<F> for T where
    T: Sized
        + Add<T, Output = F>
        + Sub<T, Output = F>
        + Mul<T, Output = F>
        + Div<T, Output = F>
        + Add<F, Output = F>
        + Sub<F, Output = F>
        + Mul<F, Output = F>
        + Div<F, Output = F>
        + Neg<Output = F>
{
}

impl Ordered for Rational {
    const NAME: &'static str = "ℚ";
    fn is_positive(&self) -> bool {
        Signed::is_positive(self)
    }
    fn is_negative(&self) -> bool {
        Signed::is_negative(self)
    }
    fn from_rational(q: Rational) -> Rational {
        q
    }
    fn rational(&self) -> Option<Rational> {
        Some(self.clone())
    }
}

impl Ordered for Surd {
    const NAME: &'static str = "ℚ(√2, √3)";
    fn is_positive(&self) -> bool {
        self.signum() > 0
    }
    fn is_negative(&self) -> bool {
        self.signum() < 0
    }
    fn from_rational(q: Rational) -> Surd {
        Surd::from_rational(q)
    }
    fn rational(&self) -> Option<Rational> {
        self.as_rational().cloned()
    }
}
