//! The number field ℚ(√2, √3): the cosines and sines of every multiple of π/12.
//!
//! A rotation by a multiple of π/6 or π/4 (a three-chain leg at 120°, a joint tilted by 45°) has
//! constants such as cos 30° = √3/2 and cos 45° = √2/2, irrational but algebraic. Every element of
//! the field is `q₀ + q₁√2 + q₂√3 + q₃√6` with rational `qᵢ`, uniquely (1, √2, √3, √6 are
//! linearly independent over ℚ), so equality is equality of the four rationals and arithmetic is
//! exact. The field is ordered as a subfield of ℝ, and the sign of an element is decided exactly
//! by squaring with sign cases (see [`Surd::signum`]): no floating point ever decides `K > 0`.

use std::cmp::Ordering;
use std::fmt;
use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

use num_traits::{One, Signed, Zero};

use crate::scalar::{Rational, Scalar, rational_to_f64};

/// `q[0] + q[1]·√2 + q[2]·√3 + q[3]·√6`.
#[derive(Clone, Debug, PartialEq, Eq, Hash, Default)]
pub struct Surd {
    pub q: [Rational; 4],
}

fn rational(n: i64) -> Rational {
    Rational::from_integer(n.into())
}

impl Surd {
    pub fn new(q0: Rational, q1: Rational, q2: Rational, q3: Rational) -> Surd {
        Surd {
            q: [q0, q1, q2, q3],
        }
    }

    pub fn from_rational(q: Rational) -> Surd {
        Surd::new(q, rational(0), rational(0), rational(0))
    }

    /// `√2`.
    pub fn sqrt2() -> Surd {
        Surd::new(rational(0), rational(1), rational(0), rational(0))
    }

    /// `√3`.
    pub fn sqrt3() -> Surd {
        Surd::new(rational(0), rational(0), rational(1), rational(0))
    }

    /// The element when it is rational.
    pub fn as_rational(&self) -> Option<&Rational> {
        self.q[1..].iter().all(Zero::is_zero).then_some(&self.q[0])
    }

    /// The image under √3 ↦ −√3 (an automorphism of the field).
    fn conjugate3(&self) -> Surd {
        let [a, b, c, d] = &self.q;
        Surd::new(a.clone(), b.clone(), -c.clone(), -d.clone())
    }

    /// The image under √2 ↦ −√2.
    fn conjugate2(&self) -> Surd {
        let [a, b, c, d] = &self.q;
        Surd::new(a.clone(), -b.clone(), c.clone(), -d.clone())
    }

    /// `1/x` for `x ≠ 0`: `x·σ₃(x) = N` lies in ℚ(√2), `N·σ₂(N)` in ℚ, so
    /// `1/x = σ₃(x)·σ₂(N) / (N·σ₂(N))`. `None` for zero.
    pub fn inverse(&self) -> Option<Surd> {
        if self.is_zero_value() {
            return None;
        }
        let c3 = self.conjugate3();
        let n = self * &c3;
        let c2 = n.conjugate2();
        let norm = &n * &c2;
        debug_assert!(norm.as_rational().is_some());
        let norm = norm.q[0].clone();
        Some((&c3 * &c2).scale(&norm.recip()))
    }

    fn is_zero_value(&self) -> bool {
        self.q.iter().all(Zero::is_zero)
    }

    /// Every coefficient times the rational `s`.
    pub fn scale(&self, s: &Rational) -> Surd {
        Surd {
            q: [
                &self.q[0] * s,
                &self.q[1] * s,
                &self.q[2] * s,
                &self.q[3] * s,
            ],
        }
    }

    /// The non-negative square root when it lies in the field, `None` otherwise (or for a
    /// negative number): `√(2 + √3) = (√6 + √2)/2`, `√3`, but not `√5` or `√(1 + √2)`.
    ///
    /// Write `x = A + B√3` with `A, B` in ℚ(√2) and look for `s = X + Y√3` with `X, Y` in ℚ(√2):
    /// `X² + 3Y² = A` and `2XY = B` give `(X² − 3Y²)² = A² − 3B²`, so `C = X² − 3Y²` is a square
    /// root of `A² − 3B²` in ℚ(√2), `X² = (A + C)/2` and then `Y = B/(2X)` (or, for `X = 0`,
    /// `Y² = A/3`). ℚ(√2) is the same step once lower, over ℚ. Every candidate is squared back
    /// before it is returned, so a root is never wrong, only possibly missed — and none is: the
    /// steps are the complete case analysis of `s² = x`.
    pub fn sqrt(&self) -> Option<Surd> {
        if self.signum() < 0 {
            return None;
        }
        let [a, b, c, d] = &self.q;
        let zero = rational(0);
        let big_a = Surd::new(a.clone(), b.clone(), zero.clone(), zero.clone());
        let big_b = Surd::new(c.clone(), d.clone(), zero.clone(), zero.clone());
        let discriminant = &(&big_a * &big_a) - &(&big_b * &big_b).scale(&rational(3));
        let root = sqrt_in_q2(&discriminant)?;
        let half = Rational::new(1.into(), 2.into());
        for c in [root.clone(), -root] {
            let x_squared = (&big_a + &c).scale(&half);
            let candidate = if x_squared.is_zero_value() {
                // X = 0: x = 3Y², a multiple of √3 in s.
                sqrt_in_q2(&big_a.scale(&Rational::new(1.into(), 3.into())))
                    .map(|y| Surd::new(zero.clone(), zero.clone(), y.q[0].clone(), y.q[1].clone()))
            } else {
                sqrt_in_q2(&x_squared).and_then(|x| {
                    let y = &big_b * &x.scale(&rational(2)).inverse()?;
                    Some(
                        &x + &Surd::new(zero.clone(), zero.clone(), y.q[0].clone(), y.q[1].clone()),
                    )
                })
            };
            if let Some(s) = candidate
                && &s * &s == *self
            {
                return Some(if s.signum() < 0 { -s } else { s });
            }
        }
        None
    }

    /// The exact sign: −1, 0 or 1.
    ///
    /// Write `x = u + v√3` with `u = q₀ + q₁√2`, `v = q₂ + q₃√2`. When `u` and `v` have the same
    /// sign (or one is zero) that is the sign of `x`; otherwise `x` has the sign of the larger
    /// of `|u|`, `|v|√3`, i.e. `sign(u)·sign(u² − 3v²)`, with `u² − 3v²` in ℚ(√2). Signs in
    /// ℚ(√2) are decided the same way with `a² − 2b²` in ℚ.
    pub fn signum(&self) -> i32 {
        let [a, b, c, d] = &self.q;
        let su = sign2(a, b);
        let sv = sign2(c, d);
        if sv == 0 || su == sv {
            return if su == 0 { sv } else { su };
        }
        if su == 0 {
            return sv;
        }
        // u² − 3v² = (a² + 2b² − 3c² − 6d²) + (2ab − 6cd)√2.
        let two = rational(2);
        let three = rational(3);
        let r0 = a * a + &two * b * b - &three * c * c - rational(6) * d * d;
        let r1 = &two * a * b - rational(6) * c * d;
        su * sign2(&r0, &r1)
    }
}

/// A square root in ℚ(√2) of `x = a + b√2` (`x` in ℚ(√2)), when there is one: `s = u + v√2`
/// with `u² + 2v² = a`, `2uv = b`, so `u² − 2v² = ±√(a² − 2b²)` is rational, `u² = (a ± that)/2`,
/// `v = b/(2u)` (or `v² = a/2` when `u = 0`). Checked by squaring back.
fn sqrt_in_q2(x: &Surd) -> Option<Surd> {
    let (a, b) = (&x.q[0], &x.q[1]);
    let root = crate::scalar::rational_sqrt(&(a * a - rational(2) * b * b))?;
    let zero = rational(0);
    for c in [root.clone(), -root] {
        let u_squared = (a + &c) / rational(2);
        let candidate = if Zero::is_zero(&u_squared) {
            crate::scalar::rational_sqrt(&(a / rational(2)))
                .map(|v| Surd::new(zero.clone(), v, zero.clone(), zero.clone()))
        } else {
            crate::scalar::rational_sqrt(&u_squared).map(|u| {
                let v = b / (rational(2) * &u);
                Surd::new(u, v, zero.clone(), zero.clone())
            })
        };
        if let Some(s) = candidate
            && &s * &s == *x
        {
            return Some(s);
        }
    }
    None
}

fn sign(q: &Rational) -> i32 {
    if q.is_positive() {
        1
    } else if q.is_negative() {
        -1
    } else {
        0
    }
}

/// The sign of `a + b√2`.
fn sign2(a: &Rational, b: &Rational) -> i32 {
    let (sa, sb) = (sign(a), sign(b));
    if sb == 0 || sa == sb {
        return if sa == 0 { sb } else { sa };
    }
    if sa == 0 {
        return sb;
    }
    sa * sign(&(a * a - rational(2) * b * b))
}

fn product(x: &Surd, y: &Surd) -> Surd {
    let [a0, a1, a2, a3] = &x.q;
    let [b0, b1, b2, b3] = &y.q;
    let (two, three) = (rational(2), rational(3));
    // √2·√2 = 2, √3·√3 = 3, √6·√6 = 6, √2·√3 = √6, √2·√6 = 2√3, √3·√6 = 3√2.
    Surd::new(
        a0 * b0 + &two * a1 * b1 + &three * a2 * b2 + rational(6) * a3 * b3,
        a0 * b1 + a1 * b0 + &three * (a2 * b3 + a3 * b2),
        a0 * b2 + a2 * b0 + &two * (a1 * b3 + a3 * b1),
        a0 * b3 + a3 * b0 + a1 * b2 + a2 * b1,
    )
}

fn sum(x: &Surd, y: &Surd) -> Surd {
    Surd {
        q: std::array::from_fn(|i| &x.q[i] + &y.q[i]),
    }
}

fn difference(x: &Surd, y: &Surd) -> Surd {
    Surd {
        q: std::array::from_fn(|i| &x.q[i] - &y.q[i]),
    }
}

fn quotient(x: &Surd, y: &Surd) -> Surd {
    product(x, &y.inverse().expect("division of a Surd by zero"))
}

/// `impl Op<Surd | &Surd> for Surd | &Surd` through one function of two references.
macro_rules! binary {
    ($trait:ident, $method:ident, $f:ident) => {
        impl $trait<&Surd> for &Surd {
            type Output = Surd;
            fn $method(self, other: &Surd) -> Surd {
                $f(self, other)
            }
        }
        impl $trait<Surd> for &Surd {
            type Output = Surd;
            fn $method(self, other: Surd) -> Surd {
                $f(self, &other)
            }
        }
        impl $trait<&Surd> for Surd {
            type Output = Surd;
            fn $method(self, other: &Surd) -> Surd {
                $f(&self, other)
            }
        }
        impl $trait<Surd> for Surd {
            type Output = Surd;
            fn $method(self, other: Surd) -> Surd {
                $f(&self, &other)
            }
        }
    };
}

binary!(Add, add, sum);
binary!(Sub, sub, difference);
binary!(Mul, mul, product);
binary!(Div, div, quotient);

impl Neg for Surd {
    type Output = Surd;
    fn neg(self) -> Surd {
        Surd {
            q: self.q.map(|x| -x),
        }
    }
}

impl Neg for &Surd {
    type Output = Surd;
    fn neg(self) -> Surd {
        -self.clone()
    }
}

impl AddAssign for Surd {
    fn add_assign(&mut self, other: Surd) {
        *self = sum(self, &other);
    }
}

impl AddAssign<&Surd> for Surd {
    fn add_assign(&mut self, other: &Surd) {
        *self = sum(self, other);
    }
}

impl SubAssign for Surd {
    fn sub_assign(&mut self, other: Surd) {
        *self = difference(self, &other);
    }
}

impl SubAssign<&Surd> for Surd {
    fn sub_assign(&mut self, other: &Surd) {
        *self = difference(self, other);
    }
}

impl MulAssign<&Surd> for Surd {
    fn mul_assign(&mut self, other: &Surd) {
        *self = product(self, other);
    }
}

impl PartialOrd for Surd {
    fn partial_cmp(&self, other: &Surd) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Surd {
    fn cmp(&self, other: &Surd) -> Ordering {
        difference(self, other).signum().cmp(&0)
    }
}

impl Scalar for Surd {
    fn zero() -> Surd {
        Surd::default()
    }
    fn one() -> Surd {
        Surd::from_rational(rational(1))
    }
    fn is_zero(&self) -> bool {
        self.is_zero_value()
    }
    fn from_i64(value: i64) -> Surd {
        Surd::from_rational(rational(value))
    }
    fn from_ratio(numerator: i64, denominator: i64) -> Surd {
        Surd::from_rational(Rational::new(numerator.into(), denominator.into()))
    }
    fn add_ref(&self, other: &Surd) -> Surd {
        sum(self, other)
    }
    fn mul_ref(&self, other: &Surd) -> Surd {
        product(self, other)
    }
    fn neg_ref(&self) -> Surd {
        -self
    }
    /// Each part rounded, then summed: a few ulps of the value (only ever used to seed floating
    /// point, never to decide).
    fn to_f64(&self) -> f64 {
        let roots = [1.0, std::f64::consts::SQRT_2, 3f64.sqrt(), 6f64.sqrt()];
        self.q
            .iter()
            .zip(roots)
            .map(|(q, r)| rational_to_f64(q) * r)
            .sum()
    }
}

impl fmt::Display for Surd {
    /// `1/2 + 3/4√3`; `0` for zero.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names = ["", "√2", "√3", "√6"];
        let mut first = true;
        for (q, name) in self.q.iter().zip(names) {
            if Zero::is_zero(q) {
                continue;
            }
            let magnitude = q.abs();
            let sign = if q.is_negative() { "−" } else { "+" };
            match (first, q.is_negative()) {
                (true, true) => write!(f, "−")?,
                (true, false) => {}
                (false, _) => write!(f, " {sign} ")?,
            }
            if name.is_empty() || !magnitude.is_one() {
                write!(f, "{magnitude}")?;
            }
            write!(f, "{name}")?;
            first = false;
        }
        if first {
            write!(f, "0")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_bigint::BigInt;

    fn q(n: i64, d: i64) -> Rational {
        Rational::new(BigInt::from(n), BigInt::from(d))
    }

    fn s(a: i64, b: i64, c: i64, d: i64) -> Surd {
        Surd::new(q(a, 1), q(b, 1), q(c, 1), q(d, 1))
    }

    #[test]
    fn square_roots_in_the_field_by_hand() {
        let half = q(1, 2);
        // √(2 + √3) = (√6 + √2)/2: ((√6 + √2)/2)² = (6 + 2 + 2√12)/4 = 2 + √3.
        assert_eq!(
            s(2, 0, 1, 0).sqrt(),
            Some(Surd::new(q(0, 1), half.clone(), q(0, 1), half.clone()))
        );
        // √(5 + 2√6) = √2 + √3; √(4 − 2√3) = √3 − 1 (positive root).
        assert_eq!(s(5, 0, 0, 2).sqrt(), Some(s(0, 1, 1, 0)));
        assert_eq!(s(4, 0, -2, 0).sqrt(), Some(s(-1, 0, 1, 0)));
        // √3, √6, √8 = 2√2, √(3/2) = √6/2, √(1/4) = 1/2, √0 = 0.
        assert_eq!(s(3, 0, 0, 0).sqrt(), Some(s(0, 0, 1, 0)));
        assert_eq!(s(6, 0, 0, 0).sqrt(), Some(s(0, 0, 0, 1)));
        assert_eq!(s(8, 0, 0, 0).sqrt(), Some(s(0, 2, 0, 0)));
        assert_eq!(
            Surd::from_rational(q(3, 2)).sqrt(),
            Some(Surd::new(q(0, 1), q(0, 1), q(0, 1), half.clone()))
        );
        assert_eq!(
            Surd::from_rational(q(1, 4)).sqrt(),
            Some(Surd::from_rational(half))
        );
        assert_eq!(s(0, 0, 0, 0).sqrt(), Some(s(0, 0, 0, 0)));
        // Not in the field: √5, √(1 + √2) (its norm −1 is no square), √√2; negatives.
        assert_eq!(s(5, 0, 0, 0).sqrt(), None);
        assert_eq!(s(1, 1, 0, 0).sqrt(), None);
        assert_eq!(s(0, 1, 0, 0).sqrt(), None);
        assert_eq!(s(-1, 0, 0, 0).sqrt(), None);
        assert_eq!(s(1, -1, 0, 0).sqrt(), None); // 1 − √2 < 0
        // Every square of a small element has its absolute value as root.
        for a in -2..=2 {
            for b in -2..=2 {
                for c in -1..=1 {
                    for d in -1..=1 {
                        let x = s(a, b, c, d);
                        let root = (&x * &x).sqrt().expect("a square");
                        let abs = if x.signum() < 0 {
                            -x.clone()
                        } else {
                            x.clone()
                        };
                        assert_eq!(root, abs, "{x}");
                    }
                }
            }
        }
    }

    #[test]
    fn products_and_inverses_are_the_hand_identities() {
        // (1 + √2)(−1 + √2) = 2 − 1 = 1.
        assert_eq!(s(1, 1, 0, 0) * s(-1, 1, 0, 0), s(1, 0, 0, 0));
        // (√2 + √3)(√3 − √2) = 3 − 2 = 1: the inverse of √2 + √3 is √3 − √2.
        assert_eq!(s(0, 1, 1, 0).inverse(), Some(s(0, -1, 1, 0)));
        // √2·√3 = √6, √6·√6 = 6, √2·√6 = 2√3, √3·√6 = 3√2.
        assert_eq!(Surd::sqrt2() * Surd::sqrt3(), s(0, 0, 0, 1));
        assert_eq!(s(0, 0, 0, 1) * s(0, 0, 0, 1), s(6, 0, 0, 0));
        assert_eq!(Surd::sqrt2() * s(0, 0, 0, 1), s(0, 0, 2, 0));
        assert_eq!(Surd::sqrt3() * s(0, 0, 0, 1), s(0, 3, 0, 0));
        // (1 + √2 + √3)⁻¹: x·σ₃(x) = (1 + √2)² − 3 = 2√2, so 1/x = (1 + √2 − √3)/(2√2)
        // = (√2 + 2 − √6)/4.
        let x = s(1, 1, 1, 0);
        let expected = Surd::new(q(1, 2), q(1, 4), q(0, 1), q(-1, 4));
        assert_eq!(x.inverse(), Some(expected.clone()));
        assert_eq!(&x * &expected, Surd::one());
        assert_eq!(Surd::zero().inverse(), None);
        // cos²30° + sin²30° = 3/4 + 1/4 = 1.
        let c = Surd::new(q(0, 1), q(0, 1), q(1, 2), q(0, 1));
        let half = Surd::from_rational(q(1, 2));
        assert_eq!(&c * &c + &half * &half, Surd::one());
        assert_eq!(s(3, 1, 4, 1) / s(3, 1, 4, 1), Surd::one());
    }

    #[test]
    fn signs_are_decided_exactly() {
        // 7 − 4√3 = 1/(7 + 4√3) ≈ 0.0718 > 0: 49 > 48. 26 − 15√3 = 1/(26 + 15√3) ≈ 0.0192 > 0:
        // 676 > 675. 4√3 − 7 < 0, and 97 − 56√3 ≈ 0.00515 > 0 (9409 > 9408).
        assert_eq!(s(7, 0, -4, 0).signum(), 1);
        assert_eq!(s(26, 0, -15, 0).signum(), 1);
        assert_eq!(s(-7, 0, 4, 0).signum(), -1);
        assert_eq!(s(97, 0, -56, 0).signum(), 1);
        // √2 + √3 − √6 − 1 ≈ 1.4142 + 1.7321 − 2.4495 − 1 = −0.3032 < 0, but it equals
        // −(√2 − 1)(√3 − 1)... expand: (√2 − 1)(√3 − 1) = √6 − √2 − √3 + 1 > 0.
        assert_eq!(s(-1, 1, 1, -1).signum(), -1);
        // 5 − 2√6 = (√3 − √2)² > 0, and 5 − 2√6 − 1/10 ≈ 0.1010 − 0.1 > 0 while − 1/9 < 0.
        assert_eq!(s(5, 0, 0, -2).signum(), 1);
        assert_eq!((s(5, 0, 0, -2) - Surd::from_rational(q(1, 10))).signum(), 1);
        assert_eq!((s(5, 0, 0, -2) - Surd::from_rational(q(1, 9))).signum(), -1);
        // √2 + √3 versus √6 + 1/2 (≈ 3.1463 vs 2.9495) and √10-free pairs.
        assert!(s(0, 1, 1, 0) > Surd::new(q(1, 2), q(0, 1), q(0, 1), q(1, 1)));
        assert_eq!(Surd::zero().signum(), 0);
        // Agreement with floating point far from zero, on a grid of small elements.
        for a in -3..=3 {
            for b in -3..=3 {
                for c in -3..=3 {
                    for d in -3..=3 {
                        let x = s(a, b, c, d);
                        let v = x.to_f64();
                        if v.abs() > 1e-9 {
                            assert_eq!(x.signum(), if v > 0.0 { 1 } else { -1 }, "{x}");
                        } else {
                            assert_eq!(x.signum(), 0, "{x}");
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn display_reads_like_a_formula() {
        assert_eq!(
            Surd::new(q(1, 2), q(0, 1), q(-3, 4), q(1, 1)).to_string(),
            "1/2 − 3/4√3 + √6"
        );
        assert_eq!(s(0, -1, 0, 0).to_string(), "−√2");
        assert_eq!(Surd::zero().to_string(), "0");
    }
}
