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
use crate::exact::{ExactBasis, ExactField, ExactSolution};
use counterpoise_symbolic::{RefArith, Surd};

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
    /// The exact basis over ℚ(√2, √3), when the case is not rational but every rotation is a
    /// multiple of π/12 (tried only when `exact` is `None`).
    pub surd: Option<ExactBasis<Surd>>,
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
            surd: match (&energy.exact, &energy.surd) {
                (Err(_), Ok(mechanism)) => Some(ExactBasis::build(mechanism, catalogue)),
                _ => None,
            },
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
    match (&basis.exact, &basis.surd) {
        (Some(exact), _) => solve_exact(basis, exact, elements),
        (None, Some(surd)) => solve_exact(basis, surd, elements),
        (None, None) => numeric_solve(basis, elements),
    }
}

/// [`solve`] over the exact field `F`.
fn solve_exact<F: ExactField>(
    basis: &LiftedBasis,
    exact: &ExactBasis<F>,
    elements: &[usize],
) -> LinearSolution
where
    for<'a> &'a F: RefArith<F>,
{
    {
        {
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
    }
}

/// An exact consistent family rounded to doubles (the witness search and the optimiser work in
/// floating point), in the numeric path's conventions: the free directions orthonormal in
/// column-scaled units and the particular solution of least scaled norm. The exact family
/// decides what the span is; this only picks the same basis of it that an SVD would.
pub fn from_exact<F: ExactField>(basis: &LiftedBasis, solution: &ExactSolution<F>) -> LinearSolution
where
    for<'a> &'a F: RefArith<F>,
{
    let (matrix, offsets) = basis.system(&solution.elements);
    let cols = matrix.ncols();
    let column_scale = column_norms(&matrix);
    let scaled_particular = DVector::from_iterator(
        cols,
        solution
            .particular
            .iter()
            .zip(column_scale.iter())
            .map(|(x, s)| x.to_f64() * s),
    );
    let scaled_null = DMatrix::from_fn(cols, solution.nullspace.len(), |j, f| {
        solution.nullspace[f][j].to_f64() * column_scale[j]
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

/// Why a floating-point factorisation of a variant's system gave no usable answer. The search
/// turns it into an `undecided` verdict with this text as the reason, never a panic.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum NumericError {
    /// A coefficient of `A_S` or `b` is NaN or infinite (an extreme case, or an overflow on the
    /// way): no factorisation of it means anything, so none is attempted.
    #[error("a coefficient of the balance equations is not finite ({0})")]
    NonFinite(&'static str),
    /// The SVD stopped without converging, or produced a non-finite value from finite input.
    #[error("the {solver} SVD failed ({reason})")]
    Svd {
        solver: &'static str,
        reason: String,
    },
}

/// Most implicit-shift QR sweeps nalgebra's SVD may take on an `n`-column problem before it is
/// declared non-convergent (LAPACK's bound is 6·n² inner steps): with `max_niter = 0` it would
/// loop for ever on a bidiagonal that never deflates, which a NaN produces.
fn nalgebra_max_sweeps(n: usize) -> usize {
    (6 * n * n).max(100)
}

/// `Err` unless every entry of `values` is finite; `what` names them in the error.
fn ensure_finite<'a>(
    values: impl IntoIterator<Item = &'a f64>,
    what: &'static str,
) -> Result<(), NumericError> {
    if values.into_iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(NumericError::NonFinite(what))
    }
}

/// The singular triplets of the column-scaled matrix by faer, every right singular vector
/// included (σ = 0 past the rows); `Err` when the SVD fails or returns a non-finite value.
fn faer_triplets(
    matrix: &DMatrix<f64>,
    column_scale: &DVector<f64>,
) -> Result<Vec<Triplet>, NumericError> {
    let (rows, cols) = matrix.shape();
    ensure_finite(matrix.iter(), "A_S")?;
    ensure_finite(column_scale.iter(), "column scale")?;
    if rows == 0 || cols == 0 {
        return Ok(unit_triplets(rows, cols));
    }
    let scaled = faer::Mat::from_fn(rows, cols, |i, j| matrix[(i, j)] / column_scale[j]);
    let failed = |reason: String| NumericError::Svd {
        solver: "faer",
        reason,
    };
    let svd = scaled
        .svd()
        .map_err(|e| failed(format!("did not converge: {e:?}")))?;
    let (u, v) = (svd.U(), svd.V());
    let sigma: Vec<f64> = svd.S().column_vector().iter().copied().collect();
    let triplets: Vec<Triplet> = (0..cols)
        .map(|k| {
            let s = sigma.get(k).copied().unwrap_or(0.0);
            let u_k = DVector::from_fn(rows, |i, _| if k < rows { u[(i, k)] } else { 0.0 });
            (s, u_k, DVector::from_fn(cols, |j, _| v[(j, k)]))
        })
        .collect();
    triplets_finite(&triplets).map_err(|_| failed("a non-finite singular triplet".into()))?;
    Ok(triplets)
}

/// The SVD of a matrix with no rows or no columns: every right vector `e_j` with σ = 0.
fn unit_triplets(rows: usize, cols: usize) -> Vec<Triplet> {
    (0..cols)
        .map(|k| {
            (
                0.0,
                DVector::zeros(rows),
                DVector::from_fn(cols, |j, _| f64::from(j == k)),
            )
        })
        .collect()
}

fn triplets_finite(triplets: &[Triplet]) -> Result<(), NumericError> {
    for (s, u, v) in triplets {
        ensure_finite(std::iter::once(s).chain(u.iter()).chain(v.iter()), "SVD")?;
    }
    Ok(())
}

/// The same triplets by nalgebra (padded so that the thin SVD yields every right vector).
///
/// nalgebra's implicit-shift QR can produce a NaN from a *finite* matrix: the Householder
/// bidiagonalisation of a rank-deficient `A_S` with zero columns and rows (a redundant element,
/// such as a counterweight on a vertical-axis link, and the monomials other elements use) leaves
/// a cascade of entries `1e-16, 1e-33, …, 1e-131` that its relative deflation test never
/// discards, and the Wilkinson shift of such a block underflows to `0/0`. Its `svd` then panics
/// while sorting ("Singular value was NaN"), and so does `try_svd`, which sorts too. So the
/// factorisation is unordered with a sweep limit, checked for finiteness, and only then sorted
/// exactly as `svd` sorts (the result is bit-identical wherever `svd` succeeds). When it fails,
/// it is retried on the matrix without its zero rows and columns — an exact reduction: a zero
/// column is a right singular vector `e_j` with σ = 0, and a zero row changes no product —
/// which removes the underflowing cascade.
fn nalgebra_triplets(
    matrix: &DMatrix<f64>,
    column_scale: &DVector<f64>,
) -> Result<Vec<Triplet>, NumericError> {
    let (rows, cols) = matrix.shape();
    ensure_finite(matrix.iter(), "A_S")?;
    ensure_finite(column_scale.iter(), "column scale")?;
    if rows == 0 || cols == 0 {
        return Ok(unit_triplets(rows, cols));
    }
    let mut scaled = DMatrix::zeros(rows.max(cols), cols);
    for j in 0..cols {
        let column = matrix.column(j) / column_scale[j];
        scaled.view_mut((0, j), (rows, 1)).copy_from(&column);
    }
    match nalgebra_svd(scaled, rows) {
        Ok(triplets) => Ok(triplets),
        Err(first) => {
            let used_rows: Vec<usize> = (0..rows)
                .filter(|&i| matrix.row(i).iter().any(|&v| v != 0.0))
                .collect();
            let used_cols: Vec<usize> = (0..cols)
                .filter(|&j| matrix.column(j).iter().any(|&v| v != 0.0))
                .collect();
            if used_rows.len() == rows && used_cols.len() == cols {
                return Err(first);
            }
            let (r, c) = (used_rows.len(), used_cols.len());
            let mut reduced = DMatrix::zeros(r.max(c).max(1), c);
            for (jj, &j) in used_cols.iter().enumerate() {
                for (ii, &i) in used_rows.iter().enumerate() {
                    reduced[(ii, jj)] = matrix[(i, j)] / column_scale[j];
                }
            }
            let inner = if c == 0 {
                Vec::new()
            } else {
                nalgebra_svd(reduced, r).map_err(|_| first)?
            };
            // Back to the full row and column spaces; the zero columns' unit vectors after.
            let mut triplets: Vec<Triplet> = inner
                .into_iter()
                .map(|(s, u, v)| {
                    let mut u_full = DVector::zeros(rows);
                    for (ii, &i) in used_rows.iter().enumerate() {
                        u_full[i] = u[ii];
                    }
                    let mut v_full = DVector::zeros(cols);
                    for (jj, &j) in used_cols.iter().enumerate() {
                        v_full[j] = v[jj];
                    }
                    (s, u_full, v_full)
                })
                .collect();
            for j in (0..cols).filter(|j| !used_cols.contains(j)) {
                triplets.push((
                    0.0,
                    DVector::zeros(rows),
                    DVector::from_fn(cols, |k, _| f64::from(k == j)),
                ));
            }
            Ok(triplets)
        }
    }
}

/// nalgebra's SVD of `padded` (at least as many rows as columns), whose first `rows` rows are
/// the matrix: finite, sorted by decreasing σ, or `Err`.
fn nalgebra_svd(padded: DMatrix<f64>, rows: usize) -> Result<Vec<Triplet>, NumericError> {
    let failed = |reason: &str| NumericError::Svd {
        solver: "nalgebra",
        reason: reason.to_string(),
    };
    let sweeps = nalgebra_max_sweeps(padded.ncols());
    // nalgebra's default tolerance, the one `svd` uses.
    let eps = f64::EPSILON * 5.0;
    let mut svd = nalgebra::linalg::SVD::try_new_unordered(padded, true, true, eps, sweeps)
        .ok_or_else(|| failed("no convergence within the sweep limit"))?;
    ensure_finite(svd.singular_values.iter(), "SVD").map_err(|_| failed("a NaN singular value"))?;
    let (Some(u), Some(v_t)) = (&svd.u, &svd.v_t) else {
        return Err(failed("singular vectors missing"));
    };
    ensure_finite(u.iter().chain(v_t.iter()), "SVD")
        .map_err(|_| failed("a non-finite singular vector"))?;
    svd.sort_by_singular_values();
    let (Some(u), Some(v_t)) = (svd.u, svd.v_t) else {
        return Err(failed("singular vectors missing"));
    };
    Ok((0..svd.singular_values.len())
        .map(|k| {
            (
                svd.singular_values[k],
                u.column(k).rows(0, rows).into_owned(),
                v_t.row(k).transpose(),
            )
        })
        .collect())
}

/// A variant's system with no usable factorisation: inconsistent, rank 0, no free direction,
/// and the reason as its ambiguity (the search reports it undecided).
fn failed_solution(
    matrix: DMatrix<f64>,
    offsets: Vec<usize>,
    column_scale: DVector<f64>,
    error: &NumericError,
) -> LinearSolution {
    let cols = matrix.ncols();
    LinearSolution {
        consistent: false,
        residual: f64::NAN,
        particular: DVector::zeros(cols),
        nullspace: DMatrix::zeros(cols, 0),
        rank: 0,
        matrix,
        offsets,
        column_scale,
        ambiguity: Some(error.to_string()),
    }
}

/// `‖A_S x + b‖/‖b‖` of the least-squares solution, by the same SVD and the same arithmetic as
/// [`numeric_solve`]'s residual — what the exact path reports for an inconsistent variant,
/// whose verdict it already has. Only that one factorisation is computed: the second
/// (nalgebra's basis of the family) would be thrown away.
pub fn least_squares_residual(
    basis: &LiftedBasis,
    elements: &[usize],
) -> Result<f64, NumericError> {
    let (matrix, _) = basis.system(elements);
    let b = &basis.unbalanced;
    ensure_finite(b.iter(), "b")?;
    let column_scale = column_norms(&matrix);
    let triplets = faer_triplets(&matrix, &column_scale)
        .or_else(|_| nalgebra_triplets(&matrix, &column_scale))?;
    let residual = family_from_svd(&matrix, b, &column_scale, &triplets).residual;
    ensure_finite(std::iter::once(&residual), "residual")?;
    Ok(residual)
}

/// Solves one variant's balance system in floating point. faer's SVD decides — rank,
/// consistency and the ambiguous zone of the module documentation. The family handed on is
/// nalgebra's SVD basis of the span when that one agrees (same rank, and it solves the system
/// when faer says it is solvable): the optimiser's local searches were tuned on that basis;
/// otherwise faer's. A non-finite coefficient or an SVD that fails both ways gives an
/// inconsistent solution whose `ambiguity` says why (the variant is undecided), never a panic.
pub fn numeric_solve(basis: &LiftedBasis, elements: &[usize]) -> LinearSolution {
    let (matrix, offsets) = basis.system(elements);
    let b = &basis.unbalanced;
    let column_scale = column_norms(&matrix);
    if let Err(e) = ensure_finite(matrix.iter().chain(b.iter()), "A_S or b") {
        return failed_solution(matrix, offsets, column_scale, &e);
    }
    let triplets = match faer_triplets(&matrix, &column_scale) {
        Ok(t) => t,
        Err(reason) => {
            let family = match nalgebra_triplets(&matrix, &column_scale) {
                Ok(t) => family_from_svd(&matrix, b, &column_scale, &t),
                Err(_) => return failed_solution(matrix, offsets, column_scale, &reason),
            };
            return LinearSolution {
                consistent: false,
                matrix,
                offsets,
                residual: family.residual,
                particular: family.particular,
                nullspace: family.nullspace,
                rank: family.rank,
                column_scale,
                ambiguity: Some(reason.to_string()),
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
    // nalgebra's basis only when it exists and agrees; faer's decision stands either way.
    let family = match nalgebra_triplets(&matrix, &column_scale) {
        Ok(t) => {
            let tuned = family_from_svd(&matrix, b, &column_scale, &t);
            let agrees =
                tuned.rank == decided.rank && (!consistent || tuned.residual <= CONSISTENCY_TOL);
            if agrees { tuned } else { decided }
        }
        Err(_) => decided,
    };
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
    /// `Err` when the particular solution or a free direction has a NaN or infinite entry
    /// (an exact family whose numbers overflow a double).
    pub fn ensure_finite(&self) -> Result<(), NumericError> {
        ensure_finite(
            self.particular.iter().chain(self.nullspace.iter()),
            "solution set",
        )
    }

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

#[cfg(test)]
mod tests {
    use super::*;

    /// A basis with one element of two columns over three monomials, `b` as given.
    fn basis(a: [[f64; 2]; 3], b: [f64; 3]) -> LiftedBasis {
        LiftedBasis {
            monomials: (0..3).map(Monomial::sine).collect(),
            unbalanced: DVector::from_row_slice(&b),
            elements: vec![DMatrix::from_fn(3, 2, |i, j| a[i][j])],
            exact: None,
            surd: None,
        }
    }

    /// NaN or infinity in `A_S` or `b` is an error with the reason, from every entry point:
    /// no SVD is attempted on it, so none can panic or loop.
    #[test]
    fn non_finite_coefficients_are_an_error_not_a_panic() {
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            for (a, b) in [
                ([[1.0, 0.0], [0.0, bad], [0.0, 0.0]], [1.0, 0.0, 0.0]),
                ([[1.0, 0.0], [0.0, 1.0], [0.0, 0.0]], [1.0, bad, 0.0]),
            ] {
                let basis = basis(a, b);
                let solution = numeric_solve(&basis, &[0]);
                assert!(!solution.consistent);
                let reason = solution.ambiguity.expect("a reason");
                assert!(reason.contains("not finite"), "{reason}");
                assert!(least_squares_residual(&basis, &[0]).is_err());
                let (matrix, _) = basis.system(&[0]);
                let scale = column_norms(&matrix);
                if matrix.iter().any(|v| !v.is_finite()) {
                    assert!(faer_triplets(&matrix, &scale).is_err());
                    assert!(nalgebra_triplets(&matrix, &scale).is_err());
                }
            }
        }
    }

    /// A finite system still solves, and both SVDs agree on it: `x = (1, 2)` solves
    /// `[[1, 0], [0, 1], [0, 0]] x = −(−1, −2, 0)` exactly, by hand.
    #[test]
    fn a_finite_system_solves_by_either_svd() {
        let basis = basis([[1.0, 0.0], [0.0, 1.0], [0.0, 0.0]], [-1.0, -2.0, 0.0]);
        let solution = numeric_solve(&basis, &[0]);
        assert!(solution.ambiguity.is_none());
        assert!(solution.consistent);
        assert_eq!(solution.rank, 2);
        assert!((solution.particular[0] - 1.0).abs() < 1e-12);
        assert!((solution.particular[1] - 2.0).abs() < 1e-12);
        assert!(least_squares_residual(&basis, &[0]).unwrap() < 1e-15);
    }

    /// The fallback of nalgebra's SVD, without the zero rows and columns, gives the triplets
    /// of the whole matrix: by hand, `[[0, 3, 0], [0, 0, 0], [0, 0, 4]]` has σ = 4, 3, 0 with
    /// right vectors e₃, e₂, e₁.
    #[test]
    fn zero_rows_and_columns_are_an_exact_reduction() {
        let matrix = DMatrix::from_row_slice(3, 3, &[0.0, 3.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 4.0]);
        let scale = DVector::from_element(3, 1.0);
        let full = nalgebra_triplets(&matrix, &scale).unwrap();
        let mut sigma: Vec<f64> = full.iter().map(|t| t.0).collect();
        sigma.sort_by(|a, b| b.total_cmp(a));
        assert_eq!(sigma, vec![4.0, 3.0, 0.0]);
        // Reduced by hand to [[3, 0], [0, 4]]: the same values, the zero column's e₁ added.
        let reduced = nalgebra_svd(DMatrix::from_row_slice(2, 2, &[3.0, 0.0, 0.0, 4.0]), 2);
        let reduced: Vec<f64> = reduced.unwrap().iter().map(|t| t.0).collect();
        assert_eq!(reduced, vec![4.0, 3.0]);
        let e1 = full.iter().find(|t| t.0 == 0.0).unwrap();
        assert!((e1.2[0].abs() - 1.0).abs() < 1e-15);
    }
}
