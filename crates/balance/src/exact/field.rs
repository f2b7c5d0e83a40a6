//! The two fields the exact decision runs in, and how each stores and eliminates a basis.
//!
//! Over ℚ every row of `[A | b]` is scaled to coprime integers and eliminated fraction-free
//! ([`super::elimination`]): the fast path every rational case (the palletizer) takes. Over
//! ℚ(√2, √3) entries are field elements and the elimination is plain Gauss–Jordan with exact
//! division ([`super::elimination_field`]); such systems are small (a variant has a few dozen
//! lifted variables), so the 4-rational arithmetic costs little. Everything downstream
//! (positivity, the rank-one test, relations) is written once over [`ExactField`].

use std::fmt::Debug;

use counterpoise_symbolic::{Ordered, Rational};

/// An exact ordered field with its basis storage and elimination.
pub trait ExactField: Ordered {
    /// One stored entry of the basis: a row-scaled integer over ℚ, the element itself otherwise.
    type Entry: Clone + Debug + PartialEq + Send + Sync;
    fn entry_is_zero(e: &Self::Entry) -> bool;
    fn zero_entry() -> Self::Entry;
    fn neg_entry(e: &Self::Entry) -> Self::Entry;
    /// The entry as a field element.
    fn entry_value(e: &Self::Entry) -> Self;
    /// `a / p` for a non-zero `p`.
    fn ratio(a: &Self::Entry, p: &Self::Entry) -> Self;
    /// Scales every row (monomial) of `[b | columns]` by a positive factor, returning the scaled
    /// `b`, the scaled columns and the factors (physical coefficient × factor = stored entry).
    #[allow(clippy::type_complexity)]
    fn scale_rows(
        b: Vec<Self>,
        columns: Vec<Vec<Vec<Self>>>,
    ) -> (Vec<Self::Entry>, Vec<Vec<Vec<Self::Entry>>>, Vec<Self>);
    /// A homogeneous equation over the field as a row of entries (any non-zero multiple).
    fn equation_row(e: &[Self]) -> Vec<Self::Entry>;
    /// Gauss–Jordan elimination of `[A | r]` (rows of `columns + 1` entries).
    fn eliminate(rows: Vec<Vec<Self::Entry>>, columns: usize) -> Echelon<Self>;
}

/// One solved row: `(pivot column, [(free column, coefficient)], value)`, meaning
/// `x_pivot + Σ coefficient·x_free = value`.
pub type Relation<F = Rational> = (usize, Vec<(usize, F)>, F);

/// The echelon form of `[A | r]` after Gauss–Jordan elimination, over the field `F` (rows of
/// integers over ℚ, of field elements otherwise).
#[derive(Clone, Debug, PartialEq)]
pub struct Echelon<F: ExactField = Rational> {
    /// Number of unknowns (columns of `A`).
    pub columns: usize,
    /// Non-zero rows: entries for columns `0..columns`, then the right-hand side.
    pub(super) rows: Vec<Vec<F::Entry>>,
    /// Pivot column of each row (strictly increasing).
    pub pivots: Vec<usize>,
    /// Whether `A x = r` has a solution (no row `0 = c ≠ 0`).
    pub consistent: bool,
}

impl<F: ExactField> Echelon<F> {
    /// Rank of `A`.
    pub fn rank(&self) -> usize {
        self.pivots.len()
    }

    /// Columns that are not pivots: one free direction each.
    pub fn free_columns(&self) -> Vec<usize> {
        (0..self.columns)
            .filter(|c| !self.pivots.contains(c))
            .collect()
    }

    /// The solution with every free variable zero (only meaningful when consistent).
    pub fn particular(&self) -> Vec<F> {
        let mut x = vec![F::zero(); self.columns];
        for (row, &c) in self.rows.iter().zip(&self.pivots) {
            x[c] = F::ratio(&row[self.columns], &row[c]);
        }
        x
    }

    /// Each row as `x_pivot + Σ coefficient·x_j = value` (coefficients of the free columns).
    pub fn relations(&self) -> Vec<Relation<F>> {
        self.rows
            .iter()
            .zip(&self.pivots)
            .map(|(row, &p)| {
                let terms = (0..self.columns)
                    .filter(|&j| j != p && !F::entry_is_zero(&row[j]))
                    .map(|j| (j, F::ratio(&row[j], &row[p])))
                    .collect();
                (p, terms, F::ratio(&row[self.columns], &row[p]))
            })
            .collect()
    }

    /// A basis of the null space of `A`: for each free column `f`, `x_f = 1`, other free
    /// variables zero, pivots solved.
    pub fn nullspace(&self) -> Vec<Vec<F>> {
        self.free_columns()
            .into_iter()
            .map(|f| {
                let mut v = vec![F::zero(); self.columns];
                v[f] = F::one();
                for (row, &c) in self.rows.iter().zip(&self.pivots) {
                    if !F::entry_is_zero(&row[f]) {
                        v[c] = F::ratio(&F::neg_entry(&row[f]), &row[c]);
                    }
                }
                v
            })
            .collect()
    }
}
