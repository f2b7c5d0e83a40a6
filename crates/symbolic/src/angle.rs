//! Angle expressions: integer-linear combinations of chart angles plus a constant.
//!
//! Only these angles keep a rotation a trigonometric polynomial: `cos(2θ₁ − θ₂ + c)` expands into
//! products of `cos θ_k`, `sin θ_k`, while `cos(θ/2)` or `cos(θ₁θ₂)` do not.

use crate::poly::{Poly, TrigPoly};
use crate::scalar::Scalar;

/// `Σ n_k θ_k + offset` with integer `n_k`.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct LinearAngle {
    /// `(coordinate index, integer multiple)`, sorted by index, no zero multiples.
    pub terms: Vec<(usize, i32)>,
    /// Constant part, in radians.
    pub offset: f64,
}

impl LinearAngle {
    /// The angle `θ_var`.
    pub fn coordinate(var: usize) -> LinearAngle {
        LinearAngle {
            terms: vec![(var, 1)],
            offset: 0.0,
        }
    }

    /// A constant angle.
    pub fn constant(offset: f64) -> LinearAngle {
        LinearAngle {
            terms: Vec::new(),
            offset,
        }
    }

    /// `(cos φ, sin φ)` as trigonometric polynomials, from `e^{iφ} = e^{i·offset} Π (c_k + i s_k)^{n_k}`.
    pub fn cos_sin(&self) -> (TrigPoly, TrigPoly) {
        let (s0, c0) = self.offset.sin_cos();
        self.expand(c0, s0)
    }

    /// `(cos φ, sin φ)` with the constant part's cosine and sine given in the field `C` (exact
    /// rationals when the constant is a multiple of π/2 or a rational rotation), the offset
    /// field itself ignored.
    pub fn expand<C: Scalar>(&self, cos_offset: C, sin_offset: C) -> (Poly<C>, Poly<C>) {
        let mut re = Poly::constant(cos_offset);
        let mut im = Poly::constant(sin_offset);
        for &(var, n) in &self.terms {
            let unit_re = Poly::<C>::cos(var);
            let unit_im = if n < 0 {
                -Poly::<C>::sin(var)
            } else {
                Poly::<C>::sin(var)
            };
            for _ in 0..n.unsigned_abs() {
                let next_re = &(&re * &unit_re) - &(&im * &unit_im);
                let next_im = &(&re * &unit_im) + &(&im * &unit_re);
                re = next_re;
                im = next_im;
            }
        }
        (re, im)
    }

    /// Numeric value at the chart angles `q`.
    pub fn value(&self, q: &[f64]) -> f64 {
        self.offset
            + self
                .terms
                .iter()
                .map(|&(k, n)| f64::from(n) * q[k])
                .sum::<f64>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Point, VarKind};

    #[test]
    fn multiple_angle_matches_libm() {
        let angle = LinearAngle {
            terms: vec![(0, 3), (1, -2)],
            offset: 0.4,
        };
        let (c, s) = angle.cos_sin();
        let q = [0.7, -1.3];
        let at = Point::new(&q, &[VarKind::Angle, VarKind::Angle]);
        let phi = angle.value(&q);
        assert!((c.eval(&at) - phi.cos()).abs() < 1e-13);
        assert!((s.eval(&at) - phi.sin()).abs() < 1e-13);
    }
}
