//! Exact balance as linear algebra: `A_S x = −b` per variant (docs/design.md §3, paper Eqs. 10, A3–A4).
//!
//! The potential energy is constant iff every non-constant coefficient of its canonical
//! trigonometric-polynomial form vanishes. Rows of `A` are the non-constant basis monomials, its
//! columns the lifted variables of the chosen elements, `b` the unbalanced coefficients.
//!
//! When the case is exact, [`solve`] returns the exact family ([`crate::exact`]) rounded to
//! doubles: rank, consistency and free directions are then facts. Otherwise it decides in floating
//! point with faer's SVD of `A` with unit-norm columns (so that kilograms and newtons per metre
//! compare fairly), with an explicit ambiguous zone: a singular value above [`RANK_TOL`]·σ_max is
//! non-zero, one below [`ZERO_TOL`]·σ_max is zero, and one in between makes the variant
//! *ambiguous*; likewise a relative residual below [`CONSISTENCY_TOL`] is consistent, one above
//! [`INCONSISTENCY_TOL`] is not, and one in between is ambiguous. An ambiguous variant is reported
//! undecided, never rounded into a verdict.

use std::collections::BTreeMap;

use counterpoise_symbolic::Monomial;
use nalgebra::{DMatrix, DVector};

use crate::element::Catalogue;
use crate::energy::MechanismEnergy;
use crate::exact::{ExactBasis, ExactSolution};

/// Relative singular value above which a direction certainly counts (numeric path).
pub const RANK_TOL: f64 = 1e-9;
/// Relative singular value below which a direction certainly does not count (numeric path).
pub const ZERO_TOL: f64 = 1e-12;
/// Relative residual below which `A x = −b` certainly counts as solvable (numeric path).
pub const CONSISTENCY_TOL: f64 = 1e-9;
/// Relative residual above which `A x = −b` certainly has no solution (numeric path).
pub const INCONSISTENCY_TOL: f64 = 1e-6;
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
    /// The exact basis, when the case's numbers are rational.
    pub exact: Option<ExactBasis>,
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
            exact: energy
                .exact
                .as_ref()
                .ok()
                .map(|mechanism| ExactBasis::build(mechanism, catalogue)),
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
    /// Numeric path only: why rank or consistency is neither clearly one thing nor the other.
    pub ambiguity: Option<String>,
}

/// Solves one variant's balance system: exactly when the basis has an exact part, in floating
/// point otherwise.
pub fn solve(basis: &LiftedBasis, elements: &[usize]) -> LinearSolution {
    match &basis.exact {
        Some(exact) => {
            let solution = exact.solve(elements);
            if solution.consistent() {
                // Where confident floating point agrees with the exact facts its SVD basis spans
                // the same family; the optimiser was tuned on that basis, so keep it. Where it
                // is wrong or ambiguous, the exact family decides.
                let numeric = numeric_solve(basis, elements);
                if numeric.ambiguity.is_none()
                    && numeric.consistent
                    && numeric.rank == solution.rank()
                {
                    numeric
                } else {
                    from_exact(basis, &solution)
                }
            } else {
                // The least-squares residual is only informative; consistency is the exact fact.
                let mut numeric = numeric_solve(basis, elements);
                numeric.consistent = false;
                numeric.ambiguity = None;
                numeric.rank = solution.rank();
                numeric
            }
        }
        None => numeric_solve(basis, elements),
    }
}

/// An exact consistent family rounded to doubles (the witness search and the optimiser work in
/// floating point), in the numeric path's conventions: the free directions orthonormal in
/// column-scaled units and the particular solution of least scaled norm. The exact family
/// decides what the span is; this only picks the same basis of it that an SVD would.
pub fn from_exact(basis: &LiftedBasis, solution: &ExactSolution) -> LinearSolution {
    use counterpoise_symbolic::rational_to_f64;
    let (matrix, offsets) = basis.system(&solution.elements);
    let cols = matrix.ncols();
    let column_scale = column_norms(&matrix);
    let scaled_particular = DVector::from_iterator(
        cols,
        solution
            .particular
            .iter()
            .zip(column_scale.iter())
            .map(|(x, s)| rational_to_f64(x) * s),
    );
    let scaled_null = DMatrix::from_fn(cols, solution.nullspace.len(), |j, f| {
        rational_to_f64(&solution.nullspace[f][j]) * column_scale[j]
    });
    let orthonormal = if scaled_null.ncols() == 0 {
        scaled_null
    } else {
        scaled_null.qr().q()
    };
    let projected =
        &scaled_particular - &orthonormal * (orthonormal.transpose() * &scaled_particular);
    let particular = projected.component_div(&column_scale);
    let mut nullspace = orthonormal;
    for j in 0..cols {
        nullspace.row_mut(j).scale_mut(1.0 / column_scale[j]);
    }
    let b = &basis.unbalanced;
    let residual = (&matrix * &particular + b).norm() / b.norm().max(f64::MIN_POSITIVE);
    LinearSolution {
        matrix,
        offsets,
        consistent: true,
        residual,
        particular,
        nullspace,
        rank: solution.rank(),
        column_scale,
        ambiguity: None,
    }
}

fn column_norms(matrix: &DMatrix<f64>) -> DVector<f64> {
    DVector::from_iterator(
        matrix.ncols(),
        matrix.column_iter().map(|c| {
            let n = c.norm();
            if n > 0.0 { n } else { 1.0 }
        }),
    )
}

/// A singular value with its left and right singular vectors.
type Triplet = (f64, DVector<f64>, DVector<f64>);

/// One SVD's reading of a variant: its least-scaled-norm solution, free directions and rank.
struct SvdFamily {
    particular: DVector<f64>,
    nullspace: DMatrix<f64>,
    rank: usize,
    residual: f64,
}

/// Builds the family from singular triplets `(σ_k, u_k, v_k)` of the column-scaled matrix.
fn family_from_svd(
    matrix: &DMatrix<f64>,
    b: &DVector<f64>,
    column_scale: &DVector<f64>,
    triplets: &[Triplet],
) -> SvdFamily {
    let cols = matrix.ncols();
    let sigma_max = triplets.iter().fold(0.0f64, |a, t| a.max(t.0));
    let mut y = DVector::zeros(cols);
    let mut null_columns = Vec::new();
    let mut rank = 0;
    for (s, u, v) in triplets {
        if sigma_max > 0.0 && *s > RANK_TOL * sigma_max {
            rank += 1;
            let coefficient = -(0..matrix.nrows()).map(|i| u[i] * b[i]).sum::<f64>() / s;
            y += v * coefficient;
        } else {
            null_columns.push(v.clone());
        }
    }
    let particular = y.component_div(column_scale);
    let mut nullspace = if null_columns.is_empty() {
        DMatrix::zeros(cols, 0)
    } else {
        DMatrix::from_columns(&null_columns)
    };
    for j in 0..cols {
        nullspace.row_mut(j).scale_mut(1.0 / column_scale[j]);
    }
    let b_norm = b.norm();
    let residual_vector = matrix * &particular + b;
    let residual = if b_norm > 0.0 {
        residual_vector.norm() / b_norm
    } else {
        residual_vector.norm()
    };
    SvdFamily {
        particular,
        nullspace,
        rank,
        residual,
    }
}

/// The singular triplets of the column-scaled matrix by faer, every right singular vector
/// included (σ = 0 past the rows); `Err` when the SVD fails.
fn faer_triplets(
    matrix: &DMatrix<f64>,
    column_scale: &DVector<f64>,
) -> Result<Vec<Triplet>, String> {
    let (rows, cols) = matrix.shape();
    let scaled = faer::Mat::from_fn(rows, cols, |i, j| matrix[(i, j)] / column_scale[j]);
    let svd = scaled
        .svd()
        .map_err(|e| format!("the SVD did not converge ({e:?})"))?;
    let (u, v) = (svd.U(), svd.V());
    let sigma: Vec<f64> = svd.S().column_vector().iter().copied().collect();
    Ok((0..cols)
        .map(|k| {
            let s = sigma.get(k).copied().unwrap_or(0.0);
            let u_k = DVector::from_fn(rows, |i, _| if k < rows { u[(i, k)] } else { 0.0 });
            (s, u_k, DVector::from_fn(cols, |j, _| v[(j, k)]))
        })
        .collect())
}

/// The same triplets by nalgebra (padded so that the thin SVD yields every right vector).
fn nalgebra_triplets(matrix: &DMatrix<f64>, column_scale: &DVector<f64>) -> Vec<Triplet> {
    let (rows, cols) = matrix.shape();
    let mut scaled = DMatrix::zeros(rows.max(cols), cols);
    for j in 0..cols {
        let column = matrix.column(j) / column_scale[j];
        scaled.view_mut((0, j), (rows, 1)).copy_from(&column);
    }
    let svd = scaled.svd(true, true);
    let u = svd.u.expect("SVD computed with U");
    let v_t = svd.v_t.expect("SVD computed with Vᵀ");
    (0..svd.singular_values.len())
        .map(|k| {
            (
                svd.singular_values[k],
                u.column(k).rows(0, rows).into_owned(),
                v_t.row(k).transpose(),
            )
        })
        .collect()
}

/// Solves one variant's balance system in floating point. faer's SVD decides — rank,
/// consistency and the ambiguous zone of the module documentation. The family handed on is
/// nalgebra's SVD basis of the span when that one agrees (same rank, and it solves the system
/// when faer says it is solvable): the optimiser's local searches were tuned on that basis;
/// otherwise faer's.
pub fn numeric_solve(basis: &LiftedBasis, elements: &[usize]) -> LinearSolution {
    let (matrix, offsets) = basis.system(elements);
    let b = &basis.unbalanced;
    let column_scale = column_norms(&matrix);
    let triplets = match faer_triplets(&matrix, &column_scale) {
        Ok(t) => t,
        Err(reason) => {
            let family = family_from_svd(
                &matrix,
                b,
                &column_scale,
                &nalgebra_triplets(&matrix, &column_scale),
            );
            return LinearSolution {
                consistent: false,
                matrix,
                offsets,
                residual: family.residual,
                particular: family.particular,
                nullspace: family.nullspace,
                rank: family.rank,
                column_scale,
                ambiguity: Some(reason),
            };
        }
    };
    let sigma_max = triplets.iter().fold(0.0f64, |a, t| a.max(t.0));
    let mut ambiguity = triplets
        .iter()
        .map(|t| t.0)
        .find(|&s| sigma_max > 0.0 && s <= RANK_TOL * sigma_max && s > ZERO_TOL * sigma_max)
        .map(|s| {
            format!(
                "a singular value of {:.1e} relative to the largest is neither clearly zero \
                 (< {ZERO_TOL:.0e}) nor clearly not (> {RANK_TOL:.0e})",
                s / sigma_max
            )
        });
    let decided = family_from_svd(&matrix, b, &column_scale, &triplets);
    let residual = decided.residual;
    let consistent = residual <= CONSISTENCY_TOL;
    if ambiguity.is_none() && !consistent && residual < INCONSISTENCY_TOL {
        ambiguity = Some(format!(
            "the relative residual {residual:.1e} is neither clearly zero (< {CONSISTENCY_TOL:.0e}) \
             nor clearly not (> {INCONSISTENCY_TOL:.0e})"
        ));
    }
    let tuned = family_from_svd(
        &matrix,
        b,
        &column_scale,
        &nalgebra_triplets(&matrix, &column_scale),
    );
    let agrees = tuned.rank == decided.rank && (!consistent || tuned.residual <= CONSISTENCY_TOL);
    let family = if agrees { tuned } else { decided };
    LinearSolution {
        consistent,
        matrix,
        offsets,
        residual,
        particular: family.particular,
        nullspace: family.nullspace,
        rank: family.rank,
        column_scale,
        ambiguity,
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
