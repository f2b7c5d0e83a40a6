//! Exact balance as linear algebra: `A_S x = −b` per variant (DESIGN §3, paper Eqs. 10, A3–A4).
//!
//! The potential energy is constant iff every non-constant coefficient of its canonical
//! trigonometric-polynomial form vanishes. Rows of `A` are the non-constant basis monomials, its
//! columns the lifted variables of the chosen elements, `b` the unbalanced coefficients.
//!
//! Rank decisions use the SVD of `A` with unit-norm columns (so that kilograms and newtons per
//! metre compare fairly): singular values below [`RANK_TOL`]·σ_max count as zero, and the system
//! is consistent when the least-squares residual is below [`CONSISTENCY_TOL`]·‖b‖. An
//! inconsistent system is a proof (to that tolerance) that no parameters balance the variant.

use std::collections::BTreeMap;

use counterpoise_symbolic::Monomial;
use nalgebra::{DMatrix, DVector};

use crate::element::Catalogue;
use crate::energy::MechanismEnergy;

/// Relative singular-value threshold for rank decisions.
pub const RANK_TOL: f64 = 1e-9;
/// Relative residual below which `A x = −b` counts as solvable.
pub const CONSISTENCY_TOL: f64 = 1e-9;
/// Scaled magnitude below which a free direction is taken not to move a variable.
pub const FIXED_TOL: f64 = 1e-7;

/// The coefficient vectors of the unbalanced energy and of every catalogue element, on one
/// shared list of monomials: computed once, then every variant only selects columns.
#[derive(Clone, Debug)]
pub struct LiftedBasis {
    /// Non-constant monomials that appear anywhere (the rows).
    pub monomials: Vec<Monomial>,
    /// Coefficients of the unbalanced potential energy (`b`).
    pub unbalanced: DVector<f64>,
    /// Per catalogue entry: rows × lifted variables.
    pub elements: Vec<DMatrix<f64>>,
}

impl LiftedBasis {
    pub fn build(energy: &MechanismEnergy, catalogue: &Catalogue) -> LiftedBasis {
        let mut index: BTreeMap<Monomial, usize> = BTreeMap::new();
        let all_polys = std::iter::once(&energy.unbalanced)
            .chain(catalogue.entries.iter().flat_map(|e| e.energy.iter()));
        for poly in all_polys {
            for (m, _) in poly.terms() {
                if !m.is_one() {
                    index.entry(*m).or_insert(0);
                }
            }
        }
        for (row, slot) in index.values_mut().enumerate() {
            *slot = row;
        }
        let rows = index.len();
        let coefficients = |poly: &counterpoise_symbolic::TrigPoly| {
            let mut v = DVector::zeros(rows);
            for (m, c) in poly.terms() {
                if let Some(&row) = index.get(m) {
                    v[row] = c;
                }
            }
            v
        };
        let unbalanced = coefficients(&energy.unbalanced);
        let elements = catalogue
            .entries
            .iter()
            .map(|entry| {
                let columns: Vec<DVector<f64>> = entry.energy.iter().map(coefficients).collect();
                DMatrix::from_columns(&columns)
            })
            .collect();
        LiftedBasis {
            monomials: index.into_keys().collect(),
            unbalanced,
            elements,
        }
    }

    /// `A_S`: the columns of the chosen elements side by side, and where each element starts.
    pub fn system(&self, elements: &[usize]) -> (DMatrix<f64>, Vec<usize>) {
        let mut offsets = Vec::with_capacity(elements.len() + 1);
        let mut total = 0;
        for &e in elements {
            offsets.push(total);
            total += self.elements[e].ncols();
        }
        offsets.push(total);
        let mut a = DMatrix::zeros(self.monomials.len(), total);
        for (k, &e) in elements.iter().enumerate() {
            a.columns_mut(offsets[k], self.elements[e].ncols())
                .copy_from(&self.elements[e]);
        }
        (a, offsets)
    }
}

/// The solution set `x_p + N z` of one variant's balance system, or the proof that it is empty.
#[derive(Clone, Debug)]
pub struct LinearSolution {
    /// The system matrix `A_S` (rows: monomials; columns: lifted variables).
    pub matrix: DMatrix<f64>,
    /// Start of each element's variables in `x`, plus the total at the end.
    pub offsets: Vec<usize>,
    /// Whether `A_S x = −b` has a solution.
    pub consistent: bool,
    /// ‖A_S x_p + b‖ / ‖b‖.
    pub residual: f64,
    /// Least-squares (minimum scaled norm) solution.
    pub particular: DVector<f64>,
    /// Columns span the free directions (the designer's freedom), in lifted units.
    pub nullspace: DMatrix<f64>,
    pub rank: usize,
    /// Column norms used for scaling (1 for zero columns).
    pub column_scale: DVector<f64>,
}

/// Solves one variant's balance system.
pub fn solve(basis: &LiftedBasis, elements: &[usize]) -> LinearSolution {
    let (matrix, offsets) = basis.system(elements);
    let b = &basis.unbalanced;
    let (rows, cols) = matrix.shape();
    let column_scale = DVector::from_iterator(
        cols,
        matrix.column_iter().map(|c| {
            let n = c.norm();
            if n > 0.0 { n } else { 1.0 }
        }),
    );
    // Scaled and padded so that the thin SVD still yields the whole right singular basis.
    let mut scaled = DMatrix::zeros(rows.max(cols), cols);
    for j in 0..cols {
        let column = matrix.column(j) / column_scale[j];
        scaled.view_mut((0, j), (rows, 1)).copy_from(&column);
    }
    let mut rhs = DVector::zeros(rows.max(cols));
    rhs.rows_mut(0, rows).copy_from(&(-b));

    let svd = scaled.svd(true, true);
    let u = svd.u.expect("SVD computed with U");
    let v_t = svd.v_t.expect("SVD computed with Vᵀ");
    let sigma = &svd.singular_values;
    let sigma_max = sigma.iter().fold(0.0f64, |a, &s| a.max(s));
    let cutoff = RANK_TOL * sigma_max;

    let mut y = DVector::zeros(cols);
    let mut null_columns = Vec::new();
    let mut rank = 0;
    for k in 0..sigma.len() {
        let v_k = v_t.row(k).transpose();
        if sigma[k] > cutoff && sigma_max > 0.0 {
            rank += 1;
            let coefficient = u.column(k).dot(&rhs) / sigma[k];
            y += v_k * coefficient;
        } else {
            null_columns.push(v_k);
        }
    }
    let particular = y.component_mul(&column_scale.map(|s| 1.0 / s));
    let nullspace = if null_columns.is_empty() {
        DMatrix::zeros(cols, 0)
    } else {
        let mut n = DMatrix::from_columns(&null_columns);
        for j in 0..cols {
            let s = column_scale[j];
            n.row_mut(j).scale_mut(1.0 / s);
        }
        n
    };
    let b_norm = b.norm();
    let residual_vector = &matrix * &particular + b;
    let residual = if b_norm > 0.0 {
        residual_vector.norm() / b_norm
    } else {
        residual_vector.norm()
    };
    LinearSolution {
        consistent: residual <= CONSISTENCY_TOL,
        matrix,
        offsets,
        residual,
        particular,
        nullspace,
        rank,
        column_scale,
    }
}

impl LinearSolution {
    /// Whether lifted variable `j` takes the same value in every solution.
    pub fn is_fixed(&self, j: usize) -> bool {
        // Nullspace columns come from orthonormal scaled vectors: compare in scaled units.
        let s = self.column_scale[j];
        self.nullspace
            .row(j)
            .iter()
            .all(|&v| (v * s).abs() <= FIXED_TOL)
    }

    /// The variables of element `k` of the variant.
    pub fn element_range(&self, k: usize) -> std::ops::Range<usize> {
        self.offsets[k]..self.offsets[k + 1]
    }

    /// Whether element `k`'s energy contribution `A_k x_k` vanishes for every solution, relative
    /// to the unbalanced energy `‖b‖`.
    pub fn contribution_forced_zero(&self, k: usize, b_norm: f64) -> bool {
        let range = self.element_range(k);
        let a_k = self.matrix.columns(range.start, range.len());
        let fixed = a_k * self.particular.rows(range.start, range.len());
        if fixed.norm() > FIXED_TOL * b_norm {
            return false;
        }
        let moving = a_k * self.nullspace.rows(range.start, range.len());
        // `A_k N` is in scaled units (unit columns times orthonormal vectors): at most 1.
        moving.iter().all(|v| v.abs() <= FIXED_TOL)
    }
}
