//! Canonical trigonometric polynomials: sparse maps from [`Monomial`] to coefficients of a
//! [`Scalar`] field — `f64` ([`TrigPoly`]) for the numeric stages, exact rationals
//! ([`ExactPoly`]) for the balance decision.

use std::collections::BTreeMap;
use std::ops::{Add, AddAssign, Mul, Neg, Sub, SubAssign};

use crate::monomial::{MAX_VARS, Monomial, VarKind};
use crate::scalar::{Rational, Scalar};

/// A point of the chart at which polynomials are evaluated: `cos`/`sin` of the angles and the
/// values of the lengths, computed once and shared by every polynomial evaluated there.
#[derive(Clone, Debug)]
pub struct Point {
    /// `cos q_k` for an angle, `q_k` for a length.
    base: [f64; MAX_VARS],
    /// `sin q_k` for an angle, unused for a length.
    sine: [f64; MAX_VARS],
}

impl Point {
    /// Precomputes the trigonometric values of `q`, whose entries have the given kinds.
    pub fn new(q: &[f64], kinds: &[VarKind]) -> Point {
        assert_eq!(q.len(), kinds.len(), "coordinate and kind counts differ");
        assert!(q.len() <= MAX_VARS, "at most {MAX_VARS} coordinates");
        let mut base = [0.0; MAX_VARS];
        let mut sine = [0.0; MAX_VARS];
        for (k, (&value, kind)) in q.iter().zip(kinds).enumerate() {
            match kind {
                VarKind::Angle => {
                    let (s, c) = value.sin_cos();
                    base[k] = c;
                    sine[k] = s;
                }
                VarKind::Length => base[k] = value,
            }
        }
        Point { base, sine }
    }

    /// Value of one monomial at this point.
    pub fn monomial(&self, m: &Monomial) -> f64 {
        let mut value = 1.0;
        for k in m.variables() {
            let p = m.power(k);
            if p > 0 {
                value *= self.base[k].powi(i32::from(p));
            }
            if m.has_sine(k) {
                value *= self.sine[k];
            }
        }
        value
    }
}

/// A trigonometric polynomial in the chart coordinates, in canonical form, with coefficients in
/// the field `C`.
///
/// Zero coefficients are never stored, so two polynomials are equal as functions exactly when
/// their maps are equal (for `f64`, up to rounding of the coefficients, see [`TrigPoly::prune`]
/// and [`TrigPoly::approx_eq`]; for rationals, exactly).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Poly<C> {
    terms: BTreeMap<Monomial, C>,
}

/// The numeric polynomial used by kinematics, dynamics and optimisation.
pub type TrigPoly = Poly<f64>;
/// The exact polynomial used by the balance decision.
pub type ExactPoly = Poly<Rational>;

impl<C: Scalar> Poly<C> {
    pub fn zero() -> Self {
        Poly {
            terms: BTreeMap::new(),
        }
    }

    pub fn constant(c: C) -> Self {
        Self::monomial(Monomial::ONE, c)
    }

    /// `coefficient · m`.
    pub fn monomial(m: Monomial, coefficient: C) -> Self {
        let mut p = Self::zero();
        p.add_term(m, coefficient);
        p
    }

    /// `cos q_var` of an angle coordinate.
    pub fn cos(var: usize) -> Self {
        Self::monomial(Monomial::base(var), C::one())
    }

    /// `sin q_var` of an angle coordinate.
    pub fn sin(var: usize) -> Self {
        Self::monomial(Monomial::sine(var), C::one())
    }

    /// The length coordinate `q_var` itself.
    pub fn length(var: usize) -> Self {
        Self::monomial(Monomial::base(var), C::one())
    }

    pub fn is_zero(&self) -> bool {
        self.terms.is_empty()
    }

    pub fn is_constant(&self) -> bool {
        self.terms.keys().all(Monomial::is_one)
    }

    pub fn constant_term(&self) -> C {
        self.coefficient(&Monomial::ONE)
    }

    /// Coefficient of a basis monomial (zero when absent).
    pub fn coefficient(&self, m: &Monomial) -> C {
        self.terms.get(m).cloned().unwrap_or_else(C::zero)
    }

    /// Terms in canonical (deterministic) order, coefficients by value.
    pub fn terms(&self) -> impl Iterator<Item = (&Monomial, C)> + '_ {
        self.terms.iter().map(|(m, c)| (m, c.clone()))
    }

    /// Terms in canonical order, coefficients by reference.
    pub fn terms_ref(&self) -> impl Iterator<Item = (&Monomial, &C)> + '_ {
        self.terms.iter()
    }

    pub fn len(&self) -> usize {
        self.terms.len()
    }

    pub fn is_empty(&self) -> bool {
        self.terms.is_empty()
    }

    /// Adds `coefficient · m`, dropping the term if it cancels exactly.
    pub fn add_term(&mut self, m: Monomial, coefficient: C) {
        if coefficient.is_zero() {
            return;
        }
        match self.terms.entry(m) {
            std::collections::btree_map::Entry::Vacant(slot) => {
                slot.insert(coefficient);
            }
            std::collections::btree_map::Entry::Occupied(mut slot) => {
                let sum = slot.get().add_ref(&coefficient);
                if sum.is_zero() {
                    slot.remove();
                } else {
                    *slot.get_mut() = sum;
                }
            }
        }
    }

    pub fn scale(&self, s: C) -> Self {
        if s.is_zero() {
            return Self::zero();
        }
        Poly {
            terms: self
                .terms
                .iter()
                .map(|(m, c)| (*m, c.mul_ref(&s)))
                .collect(),
        }
    }

    /// `self^n` by repeated squaring.
    pub fn pow(&self, n: u32) -> Self {
        let mut result = Self::constant(C::one());
        let mut base = self.clone();
        let mut n = n;
        while n > 0 {
            if n & 1 == 1 {
                result = &result * &base;
            }
            n >>= 1;
            if n > 0 {
                base = &base * &base;
            }
        }
        result
    }

    /// Partial derivative with respect to coordinate `var` of the given kind.
    ///
    /// Angle: `d(cᵃ sᵇ)/dθ = −a cᵃ⁻¹ sᵇ⁺¹ + b cᵃ⁺¹ sᵇ⁻¹`, with `s² = 1 − c²` reduced.
    /// Length: `d(xᵉ)/dx = e xᵉ⁻¹`.
    pub fn derivative(&self, var: usize, kind: VarKind) -> Self {
        let mut out = Self::zero();
        for (m, c) in &self.terms {
            let a = m.power(var);
            let ca = c.mul_ref(&C::from_i64(i64::from(a)));
            match kind {
                VarKind::Length => {
                    if a > 0 {
                        out.add_term(m.with_power(var, a - 1), ca);
                    }
                }
                VarKind::Angle => {
                    let b = m.has_sine(var);
                    if a > 0 {
                        // −a cᵃ⁻¹ · s · sᵇ
                        let lowered = m.with_power(var, a - 1);
                        if b {
                            // s² = 1 − c²: −a cᵃ⁻¹ (1 − c²) = −a cᵃ⁻¹ + a cᵃ⁺¹
                            let without_sine = lowered.with_sine(var, false);
                            out.add_term(without_sine, ca.neg_ref());
                            out.add_term(without_sine.with_power(var, a + 1), ca);
                        } else {
                            out.add_term(lowered.with_sine(var, true), ca.neg_ref());
                        }
                    }
                    if b {
                        // b cᵃ⁺¹ sᵇ⁻¹
                        out.add_term(m.with_sine(var, false).with_power(var, a + 1), c.clone());
                    }
                }
            }
        }
        out
    }

    /// Value at a chart point (coefficients rounded to `f64` first for exact polynomials).
    pub fn eval(&self, at: &Point) -> f64 {
        self.terms
            .iter()
            .map(|(m, c)| c.to_f64() * at.monomial(m))
            .sum()
    }

    /// The same polynomial with every coefficient rounded to the nearest double.
    pub fn to_f64(&self) -> TrigPoly {
        let mut out = TrigPoly::zero();
        for (m, c) in &self.terms {
            out.add_term(*m, c.to_f64());
        }
        out
    }

    /// Highest power of any single coordinate (`cos q_k` or `q_k`) in any term.
    pub fn max_power(&self) -> u32 {
        self.terms
            .keys()
            .flat_map(|m| {
                (0..MAX_VARS).map(move |k| u32::from(m.power(k)) + u32::from(m.has_sine(k)))
            })
            .max()
            .unwrap_or(0)
    }

    /// Coordinates this polynomial depends on.
    pub fn variables(&self) -> Vec<usize> {
        let mut used = [false; MAX_VARS];
        for m in self.terms.keys() {
            for k in m.variables() {
                used[k] = true;
            }
        }
        (0..MAX_VARS).filter(|&k| used[k]).collect()
    }

    fn mul_ref(&self, other: &Self) -> Self {
        let mut out = Self::zero();
        for (ma, ca) in &self.terms {
            for (mb, cb) in &other.terms {
                let (m, squared) = ma.raw_product(mb);
                out.add_reduced(m, squared, ca.mul_ref(cb));
            }
        }
        out
    }

    /// Adds `coefficient · m · Π_{k ∈ squared} s_k²`, expanding each `s_k² = 1 − c_k²`.
    fn add_reduced(&mut self, m: Monomial, squared: u16, coefficient: C) {
        if squared == 0 {
            self.add_term(m, coefficient);
            return;
        }
        let k = squared.trailing_zeros() as usize;
        let rest = squared & !(1 << k);
        let raised = m.power(k) + 2;
        let negated = coefficient.neg_ref();
        self.add_reduced(m, rest, coefficient);
        self.add_reduced(m.with_power(k, raised), rest, negated);
    }
}

impl TrigPoly {
    /// Largest coefficient magnitude (zero for the zero polynomial).
    pub fn max_abs_coefficient(&self) -> f64 {
        self.terms.values().fold(0.0, |acc, c| acc.max(c.abs()))
    }

    /// Drops coefficients of magnitude at most `tol`: the residue of cancellations such as
    /// `cos²θ + sin²θ − 1` computed in floating point. Absolute, because a polynomial that should
    /// be zero has nothing to be relative to; see [`TrigPoly::prune_relative`].
    pub fn prune(&mut self, tol: f64) {
        self.terms.retain(|_, c| c.abs() > tol);
    }

    /// Drops coefficients of magnitude at most `tol` times the largest one.
    pub fn prune_relative(&mut self, tol: f64) {
        let limit = tol * self.max_abs_coefficient();
        self.terms.retain(|_, c| c.abs() > limit);
    }

    /// Equality of coefficient maps within `tol` times the larger maximum coefficient.
    pub fn approx_eq(&self, other: &TrigPoly, tol: f64) -> bool {
        let scale = self.max_abs_coefficient().max(other.max_abs_coefficient());
        (self - other).max_abs_coefficient() <= tol * scale
    }
}

impl From<f64> for TrigPoly {
    fn from(c: f64) -> TrigPoly {
        TrigPoly::constant(c)
    }
}

impl<C: Scalar> AddAssign<&Poly<C>> for Poly<C> {
    fn add_assign(&mut self, rhs: &Poly<C>) {
        for (m, c) in &rhs.terms {
            self.add_term(*m, c.clone());
        }
    }
}

impl<C: Scalar> SubAssign<&Poly<C>> for Poly<C> {
    fn sub_assign(&mut self, rhs: &Poly<C>) {
        for (m, c) in &rhs.terms {
            self.add_term(*m, c.neg_ref());
        }
    }
}

impl<C: Scalar> Neg for &Poly<C> {
    type Output = Poly<C>;
    fn neg(self) -> Poly<C> {
        Poly {
            terms: self.terms.iter().map(|(m, c)| (*m, c.neg_ref())).collect(),
        }
    }
}

impl<C: Scalar> Neg for Poly<C> {
    type Output = Poly<C>;
    fn neg(self) -> Poly<C> {
        -&self
    }
}

macro_rules! binary_ops {
    ($trait:ident, $method:ident, $body:expr) => {
        impl<C: Scalar> $trait<&Poly<C>> for &Poly<C> {
            type Output = Poly<C>;
            fn $method(self, rhs: &Poly<C>) -> Poly<C> {
                let f: fn(&Poly<C>, &Poly<C>) -> Poly<C> = $body;
                f(self, rhs)
            }
        }
        impl<C: Scalar> $trait<Poly<C>> for Poly<C> {
            type Output = Poly<C>;
            fn $method(self, rhs: Poly<C>) -> Poly<C> {
                (&self).$method(&rhs)
            }
        }
        impl<C: Scalar> $trait<&Poly<C>> for Poly<C> {
            type Output = Poly<C>;
            fn $method(self, rhs: &Poly<C>) -> Poly<C> {
                (&self).$method(rhs)
            }
        }
        impl<C: Scalar> $trait<Poly<C>> for &Poly<C> {
            type Output = Poly<C>;
            fn $method(self, rhs: Poly<C>) -> Poly<C> {
                self.$method(&rhs)
            }
        }
    };
}

binary_ops!(Add, add, |a, b| {
    let mut out = a.clone();
    out += b;
    out
});
binary_ops!(Sub, sub, |a, b| {
    let mut out = a.clone();
    out -= b;
    out
});
binary_ops!(Mul, mul, |a, b| a.mul_ref(b));

impl Mul<f64> for &TrigPoly {
    type Output = TrigPoly;
    fn mul(self, s: f64) -> TrigPoly {
        self.scale(s)
    }
}

impl Mul<f64> for TrigPoly {
    type Output = TrigPoly;
    fn mul(self, s: f64) -> TrigPoly {
        self.scale(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const A: [VarKind; 2] = [VarKind::Angle, VarKind::Angle];

    #[test]
    fn pythagoras_reduces_to_one() {
        let c = TrigPoly::cos(0);
        let s = TrigPoly::sin(0);
        let one = &(&c * &c) + &(&s * &s);
        assert_eq!(one, TrigPoly::constant(1.0));
    }

    #[test]
    fn derivative_of_sin_squared_is_sin_2x() {
        // d/dθ sin²θ = 2 sinθ cosθ
        let s = TrigPoly::sin(0);
        let d = (&s * &s).derivative(0, VarKind::Angle);
        let expected = (&TrigPoly::sin(0) * &TrigPoly::cos(0)).scale(2.0);
        assert_eq!(d, expected);
    }

    #[test]
    fn length_derivative_and_eval() {
        let kinds = [VarKind::Length];
        let x = TrigPoly::length(0);
        let p = &x.pow(3) + &x.scale(2.0); // x³ + 2x
        let d = p.derivative(0, VarKind::Length); // 3x² + 2
        let at = Point::new(&[1.5], &kinds);
        assert!((p.eval(&at) - (1.5f64.powi(3) + 3.0)).abs() < 1e-14);
        assert!((d.eval(&at) - (3.0 * 2.25 + 2.0)).abs() < 1e-14);
    }

    #[test]
    fn eval_matches_closed_form() {
        // (cos a + 2 sin b)² at a=0.3, b=-1.1
        let p = (&TrigPoly::cos(0) + &TrigPoly::sin(1).scale(2.0)).pow(2);
        let (a, b) = (0.3f64, -1.1f64);
        let expected = (a.cos() + 2.0 * b.sin()).powi(2);
        assert!((p.eval(&Point::new(&[a, b], &A)) - expected).abs() < 1e-14);
    }
}
