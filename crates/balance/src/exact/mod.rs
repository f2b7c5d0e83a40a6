//! The exact balance decision: the lifted system `A_S x = −b` over ℚ, or over ℚ(√2, √3) when
//! the case's rotations are multiples of π/12 ([`field`]; everything here is generic over the
//! field, and the search tries ℚ first).
//!
//! When every number of the case is rational (see [`counterpoise_model::exact_mechanism`]) the
//! energy coefficients of the mechanism and of every element are rational, computed by the same
//! generic formulas as the numeric ones ([`crate::element::counterweight_energy`],
//! [`crate::element::spring_energy`]). Each row (monomial) of `[A_all | b]` is scaled once by a
//! positive rational to coprime integers — which changes no solution — and every variant is then
//! eliminated exactly ([`elimination`]). Rank, consistency, the particular solution, the null
//! space, "this variable is fixed" and "this contribution vanishes" are facts, not thresholds:
//! a superset of a consistent set is consistent by construction, and one ulp in an input is a
//! different rational, never a flipped threshold.
//!
//! Positivity of masses and stiffnesses over the family is decided exactly too ([`positivity`]),
//! with a Farkas certificate when it fails, and the admissible range of each lifted variable is
//! the projection of the positive family. Springs whose balance zeroes a block of `K·a·bᵀ` are
//! split on which anchor part vanishes ([`split`]).

pub mod anchors;
pub mod elimination;
pub mod elimination_field;
pub mod field;
pub mod positivity;
pub mod rank_one;
mod rational_field;
pub mod split;

use std::collections::BTreeMap;

use counterpoise_model::ExactMechanism;
use counterpoise_symbolic::{Monomial, Poly, Rational, RefArith};

use crate::element::{Attachment, Catalogue, Element, counterweight_energy, spring_energy};
use elimination::Echelon;
pub use field::ExactField;
use positivity::Affine;

/// The exact coefficient vectors of the unbalanced energy and of every catalogue element, on one
/// shared list of monomials, each row scaled by a positive factor (to coprime integers over ℚ).
#[derive(Clone, Debug)]
pub struct ExactBasis<F: ExactField = Rational> {
    /// Non-constant monomials that appear anywhere (the rows).
    pub monomials: Vec<Monomial>,
    /// Row-scaled coefficients of the unbalanced energy (`b`).
    pub unbalanced: Vec<F::Entry>,
    /// Per catalogue entry, per lifted variable: the row-scaled column.
    pub elements: Vec<Vec<Vec<F::Entry>>>,
    /// The positive factor each row was scaled by (physical coefficient × factor = entry).
    pub row_factors: Vec<F>,
}

/// The exact energy polynomials of one catalogue entry, per lifted variable.
pub fn element_polys<F: ExactField>(
    mechanism: &ExactMechanism<F>,
    element: &Element,
) -> Vec<Poly<F>> {
    match element {
        Element::Counterweight { body, axes } => {
            let frame = &mechanism.bodies[*body];
            counterweight_energy(&mechanism.gravity, &frame.rotation, &frame.origin, axes)
        }
        Element::Spring {
            body,
            other,
            axes_a,
            ..
        } => {
            let frame = &mechanism.bodies[*body];
            let other = match other {
                Attachment::Base => None,
                Attachment::Body(s) => {
                    let f = &mechanism.bodies[*s];
                    Some((&f.rotation, &f.origin))
                }
            };
            spring_energy((&frame.rotation, &frame.origin), other, axes_a)
        }
    }
}

impl<F: ExactField> ExactBasis<F>
where
    for<'a> &'a F: RefArith<F>,
{
    pub fn build(mechanism: &ExactMechanism<F>, catalogue: &Catalogue) -> ExactBasis<F> {
        let polys: Vec<Vec<Poly<F>>> = catalogue
            .entries
            .iter()
            .map(|entry| element_polys(mechanism, &entry.element))
            .collect();
        let mut index: BTreeMap<Monomial, usize> = BTreeMap::new();
        for poly in std::iter::once(&mechanism.unbalanced).chain(polys.iter().flatten()) {
            for (m, _) in poly.terms_ref() {
                if !m.is_one() {
                    index.entry(*m).or_insert(0);
                }
            }
        }
        for (row, slot) in index.values_mut().enumerate() {
            *slot = row;
        }
        let rows = index.len();
        let column = |poly: &Poly<F>| {
            let mut v = vec![F::zero(); rows];
            for (m, c) in poly.terms_ref() {
                if let Some(&row) = index.get(m) {
                    v[row] = c.clone();
                }
            }
            v
        };
        let b = column(&mechanism.unbalanced);
        let columns: Vec<Vec<Vec<F>>> = polys
            .iter()
            .map(|entry| entry.iter().map(&column).collect())
            .collect();
        let (unbalanced, elements, row_factors) = F::scale_rows(b, columns);
        ExactBasis {
            monomials: index.into_keys().collect(),
            unbalanced,
            elements,
            row_factors,
        }
    }

    /// Eliminates variant `elements` exactly.
    pub fn solve(&self, elements: &[usize]) -> ExactSolution<F> {
        self.solve_with(elements, &[])
    }

    /// Eliminates variant `elements` exactly with extra homogeneous equations `e·x = 0` (rows
    /// over the variant's lifted variables), e.g. a spring's `W = a₀ βᵀ` once its anchor is known.
    pub fn solve_with(&self, elements: &[usize], extra: &[Vec<F>]) -> ExactSolution<F> {
        let mut offsets = Vec::with_capacity(elements.len() + 1);
        let mut columns: Vec<&Vec<F::Entry>> = Vec::new();
        for &e in elements {
            offsets.push(columns.len());
            columns.extend(&self.elements[e]);
        }
        offsets.push(columns.len());
        let n = columns.len();
        let mut rows: Vec<Vec<F::Entry>> = (0..self.monomials.len())
            .filter(|&r| {
                !F::entry_is_zero(&self.unbalanced[r])
                    || columns.iter().any(|c| !F::entry_is_zero(&c[r]))
            })
            .map(|r| {
                let mut row: Vec<F::Entry> = columns.iter().map(|c| c[r].clone()).collect();
                row.push(F::neg_entry(&self.unbalanced[r]));
                row
            })
            .collect();
        for e in extra {
            let mut row = F::equation_row(e);
            row.push(F::zero_entry());
            rows.push(row);
        }
        let echelon = F::eliminate(rows, n);
        let (particular, nullspace) = if echelon.consistent {
            (echelon.particular(), echelon.nullspace())
        } else {
            (Vec::new(), Vec::new())
        };
        ExactSolution {
            elements: elements.to_vec(),
            offsets,
            echelon,
            particular,
            nullspace,
        }
    }
}

/// One variant's exact solution set `x_p + N z`, or the fact that it is empty.
#[derive(Clone, Debug)]
pub struct ExactSolution<F: ExactField = Rational> {
    /// Catalogue entries of the variant.
    pub elements: Vec<usize>,
    /// Start of each element's variables in `x`, plus the total at the end.
    pub offsets: Vec<usize>,
    pub echelon: Echelon<F>,
    /// Particular solution (free variables zero); empty when inconsistent.
    pub particular: Vec<F>,
    /// Basis of the free directions; empty when inconsistent.
    pub nullspace: Vec<Vec<F>>,
}

impl<F: ExactField> ExactSolution<F>
where
    for<'a> &'a F: RefArith<F>,
{
    pub fn consistent(&self) -> bool {
        self.echelon.consistent
    }

    pub fn rank(&self) -> usize {
        self.echelon.rank()
    }

    pub fn nullity(&self) -> usize {
        self.echelon.columns - self.echelon.rank()
    }

    /// The variables of element `k` of the variant.
    pub fn element_range(&self, k: usize) -> std::ops::Range<usize> {
        self.offsets[k]..self.offsets[k + 1]
    }

    /// Whether variable `j` takes the same value in every solution.
    pub fn is_fixed(&self, j: usize) -> bool {
        self.nullspace.iter().all(|v| v[j].is_zero())
    }

    /// Variable `j` as an affine function of the free parameters `z`.
    pub fn affine(&self, j: usize) -> Affine<F> {
        Affine {
            constant: self.particular[j].clone(),
            coefficients: self.nullspace.iter().map(|v| v[j].clone()).collect(),
        }
    }

    /// Whether element `k`'s energy contribution `A_k x_k` is zero in every solution.
    pub fn contribution_forced_zero(&self, basis: &ExactBasis<F>, k: usize) -> bool {
        let columns = &basis.elements[self.elements[k]];
        let range = self.element_range(k);
        let vanishes = |x: &[F]| {
            (0..basis.monomials.len()).all(|r| {
                let mut sum = F::zero();
                for (c, j) in columns.iter().zip(range.clone()) {
                    if !F::entry_is_zero(&c[r]) && !x[j].is_zero() {
                        sum += &x[j] * F::entry_value(&c[r]);
                    }
                }
                sum.is_zero()
            })
        };
        vanishes(&self.particular) && self.nullspace.iter().all(|v| vanishes(v))
    }

    /// `Some(v)` when variables `range` equal `v·K(z)` on the whole family for the constant
    /// vector `v` (the spring's anchor is fixed by balance), `K` being variable `stiffness`.
    pub fn proportional_to(
        &self,
        stiffness: usize,
        range: std::ops::Range<usize>,
    ) -> Option<Vec<F>> {
        self.proportional_components(stiffness, range)
            .into_iter()
            .collect()
    }

    /// For each variable of `range`, `Some(v)` when it equals `v·K(z)` on the whole family for
    /// a constant `v`: that component of the spring's anchor is fixed by balance (zero when
    /// the lifted variable `K·a_i` vanishes on the family), whatever the others do.
    pub fn proportional_components(
        &self,
        stiffness: usize,
        range: std::ops::Range<usize>,
    ) -> Vec<Option<F>> {
        let k = self.affine(stiffness);
        let pivot = k.coefficients.iter().position(|c| !c.is_zero());
        range
            .map(|j| {
                let f = self.affine(j);
                let ratio = match pivot {
                    Some(u) => &f.coefficients[u] / &k.coefficients[u],
                    None if k.constant.is_zero() => return None,
                    None => &f.constant / &k.constant,
                };
                let same = f.constant == &ratio * &k.constant
                    && f.coefficients
                        .iter()
                        .zip(&k.coefficients)
                        .all(|(a, b)| *a == &ratio * b);
                same.then_some(ratio)
            })
            .collect()
    }

    /// Heads (masses and stiffnesses) of the variant's elements as affine functions of `z`.
    pub fn heads(&self) -> Vec<Affine<F>> {
        (0..self.elements.len())
            .map(|k| self.affine(self.offsets[k]))
            .collect()
    }

    /// `true` when the fixed value of variable `j` is strictly positive.
    pub fn fixed_positive(&self, j: usize) -> bool {
        self.particular[j].is_positive()
    }
}

/// Writes an exact number, with its decimal value beside it when it is not an integer:
/// `1829/8 (228.625)`, `1/2√3 (0.866025)`.
pub fn exact_text<F: ExactField>(x: &F) -> String {
    let Some(q) = x.rational() else {
        return format!(
            "{x} ({})",
            crate::number_text::significant(counterpoise_symbolic::Scalar::to_f64(x))
        );
    };
    if q.is_integer() {
        format!("{}", q.numer())
    } else {
        format!(
            "{}/{} ({})",
            q.numer(),
            q.denom(),
            crate::number_text::significant(counterpoise_symbolic::rational_to_f64(&q))
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_bigint::BigInt;

    fn ints(v: &[i64]) -> Vec<BigInt> {
        v.iter().map(|&x| BigInt::from(x)).collect()
    }

    fn q(n: i64, d: i64) -> Rational {
        Rational::new(BigInt::from(n), BigInt::from(d))
    }

    /// A basis written by hand: `unbalanced[r]` is `b` on row `r`, `columns[e][j][r]` the
    /// coefficient of element `e`'s variable `j`. Solving means `Σ columns·x = −b` row by row.
    fn basis(unbalanced: &[i64], columns: &[&[&[i64]]]) -> ExactBasis {
        let rows = unbalanced.len();
        ExactBasis {
            monomials: (0..rows).map(Monomial::sine).collect(),
            unbalanced: ints(unbalanced),
            elements: columns
                .iter()
                .map(|e| e.iter().map(|c| ints(c)).collect())
                .collect(),
            row_factors: vec![q(1, 1); rows],
        }
    }

    #[test]
    fn a_row_without_unbalanced_energy_still_constrains_the_variant() {
        // By hand: x = 2 (row 0: x = −(−2)) and x = 0 (row 1, where b is zero) contradict.
        let b = basis(&[-2, 0], &[&[&[1, 1]]]);
        assert!(!b.solve(&[0]).consistent());
        // Without the second row's coefficient the variant balances with x = 2.
        let b = basis(&[-2, 0], &[&[&[1, 0]]]);
        let s = b.solve(&[0]);
        assert!(s.consistent());
        assert_eq!(s.particular, vec![q(2, 1)]);
    }

    #[test]
    fn an_anchor_is_proportional_to_a_fixed_stiffness() {
        // Variables (K, αx, αy) with K = 3, 4·αx = 3, αy = 0: by hand α = (3/4, 0) = (1/4, 0)·K.
        let b = basis(&[-3, -3, 0], &[&[&[1, 0, 0], &[0, 4, 0], &[0, 0, 1]]]);
        let s = b.solve(&[0]);
        assert!(s.is_fixed(0) && s.fixed_positive(0));
        assert_eq!(s.proportional_to(0, 1..3), Some(vec![q(1, 4), q(0, 1)]));
        // αx left free (no equation on it): αx is not a fixed multiple of the fixed K.
        let free = basis(&[-3, 0], &[&[&[1, 0], &[0, 0], &[0, 1]]]);
        assert_eq!(free.solve(&[0]).proportional_to(0, 1..3), None);
        // K forced to zero: α = a₀·K says nothing about a₀, so there is no anchor.
        let zero = basis(&[0, -3, 0], &[&[&[1, 0, 0], &[0, 4, 0], &[0, 0, 1]]]);
        assert_eq!(zero.solve(&[0]).proportional_to(0, 1..3), None);
    }
}
