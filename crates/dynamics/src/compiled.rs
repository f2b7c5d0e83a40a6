//! Flat evaluators for banks of trigonometric polynomials.
//!
//! [`TrigPoly`] keeps its terms in a `BTreeMap` keyed by monomial, which is right for algebra
//! and wrong for a hot loop that evaluates the same few hundred polynomials millions of times.
//! A [`PolyBank`] compiles a list of polynomials once: the distinct monomials of all of them,
//! each as a short list of `(coordinate, power, sine)` factors, and every polynomial as a
//! contiguous run of `(monomial, coefficient)` terms. Evaluation then computes the powers of
//! `cos q_k` (or `q_k`) once per coordinate, every monomial once, and every polynomial as a dot
//! product — no allocation, no map lookups.

use counterpoise_symbolic::{MAX_VARS, Monomial, TrigPoly, VarKind};

/// Most powers of one coordinate a bank supports (the palletizer needs 3).
const MAX_POWER: usize = 16;

/// A compiled list of trigonometric polynomials evaluated together.
#[derive(Clone, Debug)]
pub struct PolyBank {
    kinds: Vec<VarKind>,
    /// Highest power of each coordinate used by any monomial.
    max_power: Vec<usize>,
    /// Per monomial: range into `factors`.
    mono_ranges: Vec<(u32, u32)>,
    /// `(coordinate, power, sine)`.
    factors: Vec<(u8, u8, bool)>,
    /// Per polynomial: range into `terms`.
    poly_ranges: Vec<(u32, u32)>,
    /// `(monomial index, coefficient)`.
    terms: Vec<(u32, f64)>,
}

/// Scratch space for [`PolyBank::eval`]; reuse it across calls to avoid allocation.
#[derive(Clone, Debug, Default)]
pub struct BankScratch {
    powers: Vec<f64>,
    monos: Vec<f64>,
}

impl PolyBank {
    /// Compiles `polys` (all in the chart with the given coordinate kinds).
    pub fn new(polys: &[TrigPoly], kinds: &[VarKind]) -> PolyBank {
        assert!(kinds.len() <= MAX_VARS);
        let mut index: std::collections::HashMap<Monomial, u32> = Default::default();
        let mut monos: Vec<Monomial> = Vec::new();
        let mut poly_ranges = Vec::with_capacity(polys.len());
        let mut terms = Vec::new();
        for p in polys {
            let start = terms.len() as u32;
            for (m, c) in p.terms() {
                let id = *index.entry(*m).or_insert_with(|| {
                    monos.push(*m);
                    (monos.len() - 1) as u32
                });
                terms.push((id, c));
            }
            poly_ranges.push((start, terms.len() as u32));
        }
        let mut max_power = vec![0usize; kinds.len()];
        let mut mono_ranges = Vec::with_capacity(monos.len());
        let mut factors = Vec::new();
        for m in &monos {
            let start = factors.len() as u32;
            for k in 0..kinds.len() {
                let p = m.power(k) as usize;
                let s = m.has_sine(k);
                if p > 0 || s {
                    assert!(p < MAX_POWER, "power {p} of coordinate {k} too high");
                    max_power[k] = max_power[k].max(p);
                    factors.push((k as u8, p as u8, s));
                }
            }
            mono_ranges.push((start, factors.len() as u32));
        }
        PolyBank {
            kinds: kinds.to_vec(),
            max_power,
            mono_ranges,
            factors,
            poly_ranges,
            terms,
        }
    }

    /// Number of polynomials.
    pub fn len(&self) -> usize {
        self.poly_ranges.len()
    }

    pub fn is_empty(&self) -> bool {
        self.poly_ranges.is_empty()
    }

    /// Total number of stored terms (a cost measure).
    pub fn term_count(&self) -> usize {
        self.terms.len()
    }

    /// Evaluates every polynomial at `q` into `out` (length [`PolyBank::len`]).
    pub fn eval(&self, q: &[f64], scratch: &mut BankScratch, out: &mut [f64]) {
        let n = self.kinds.len();
        debug_assert_eq!(out.len(), self.len());
        // powers[k * (MAX_POWER + 1) + p] = base_k^p, and slot MAX_POWER holds sin q_k.
        let stride = MAX_POWER + 1;
        scratch.powers.resize(n * stride, 0.0);
        for k in 0..n {
            let row = &mut scratch.powers[k * stride..(k + 1) * stride];
            let (base, sine) = match self.kinds[k] {
                VarKind::Angle => {
                    let (s, c) = q[k].sin_cos();
                    (c, s)
                }
                VarKind::Length => (q[k], 0.0),
            };
            row[0] = 1.0;
            for p in 1..=self.max_power[k] {
                row[p] = row[p - 1] * base;
            }
            row[MAX_POWER] = sine;
        }
        scratch.monos.resize(self.mono_ranges.len(), 0.0);
        for (value, &(a, b)) in scratch.monos.iter_mut().zip(&self.mono_ranges) {
            let mut v = 1.0;
            for &(k, p, s) in &self.factors[a as usize..b as usize] {
                let row = &scratch.powers[k as usize * stride..];
                v *= row[p as usize];
                if s {
                    v *= row[MAX_POWER];
                }
            }
            *value = v;
        }
        for (o, &(a, b)) in out.iter_mut().zip(&self.poly_ranges) {
            let mut acc = 0.0;
            for &(m, c) in &self.terms[a as usize..b as usize] {
                acc += c * scratch.monos[m as usize];
            }
            *o = acc;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use counterpoise_symbolic::Point;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn bank_matches_trigpoly_eval(q0 in -3.0f64..3.0, q1 in -2.0f64..2.0, q2 in -3.0f64..3.0) {
            let kinds = [VarKind::Angle, VarKind::Length, VarKind::Angle];
            let c0 = TrigPoly::cos(0);
            let s2 = TrigPoly::sin(2);
            let x = TrigPoly::length(1);
            let p1 = &(&c0 * &c0) * &x + s2.scale(3.0) + TrigPoly::constant(0.5);
            let p2 = &(&c0 * &s2) * &(&x * &x) - TrigPoly::sin(0).scale(2.0);
            let p3 = p1.derivative(0, VarKind::Angle);
            let polys = [p1, p2, p3, TrigPoly::zero()];
            let bank = PolyBank::new(&polys, &kinds);
            let mut out = vec![0.0; 4];
            bank.eval(&[q0, q1, q2], &mut BankScratch::default(), &mut out);
            let at = Point::new(&[q0, q1, q2], &kinds);
            for (p, v) in polys.iter().zip(&out) {
                prop_assert!((p.eval(&at) - v).abs() < 1e-12 * (1.0 + v.abs()));
            }
        }
    }
}
