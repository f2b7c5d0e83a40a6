//! A singular value decomposition that never hangs or panics, for every crate that factorises
//! matrices built from a case's numbers.

use nalgebra::{DMatrix, Dyn, SVD};

/// Most iterations of one SVD: it converges in tens for any sane matrix, and nalgebra's
/// default (no cap) never returns on a matrix it cannot reduce.
pub const SVD_MAX_ITERATIONS: usize = 10_000;

/// The SVD of `a`, or `None`: capped at [`SVD_MAX_ITERATIONS`], only of finite entries
/// (nalgebra's SVD never returns on a NaN), and unordered with its values checked finite
/// before they are sorted (its shifted QR can turn a finite rank-deficient matrix into a NaN
/// singular value, on which its sorting panics). The tolerance is nalgebra's default and the
/// order is `svd()`'s, so wherever `svd()` succeeds the result is the same, bit for bit.
pub fn checked_svd(a: DMatrix<f64>, vectors: bool) -> Option<SVD<f64, Dyn, Dyn>> {
    if !a.iter().all(|x| x.is_finite()) {
        return None;
    }
    let mut svd =
        SVD::try_new_unordered(a, vectors, vectors, 5.0 * f64::EPSILON, SVD_MAX_ITERATIONS)?;
    let finite =
        |m: &Option<DMatrix<f64>>| m.as_ref().is_none_or(|m| m.iter().all(|x| x.is_finite()));
    if !(svd.singular_values.iter().all(|s| s.is_finite()) && finite(&svd.u) && finite(&svd.v_t)) {
        return None;
    }
    svd.sort_by_singular_values();
    Some(svd)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A NaN or an infinity gives `None`, not a hang or a panic; a finite matrix gives the
    /// singular values of `svd()`, bit for bit (diag(3, 4) rotated: 4 and 3 by hand).
    #[test]
    fn non_finite_entries_give_none_and_finite_ones_svds_values() {
        assert!(checked_svd(DMatrix::from_element(2, 2, f64::NAN), true).is_none());
        assert!(checked_svd(DMatrix::from_row_slice(1, 2, &[1.0, f64::INFINITY]), false).is_none());
        let (c, s) = (0.6, 0.8);
        let a = DMatrix::from_row_slice(2, 2, &[3.0 * c, -4.0 * s, 3.0 * s, 4.0 * c]);
        let svd = checked_svd(a.clone(), true).unwrap();
        assert!((svd.singular_values[0] - 4.0).abs() <= 1e-14);
        assert!((svd.singular_values[1] - 3.0).abs() <= 1e-14);
        assert_eq!(svd.singular_values, a.svd(true, true).singular_values);
    }

    /// nalgebra's unordered SVD of `a`, and whether its singular values, `U` and `Vᵀ` are all
    /// finite: the premise of the test below, checked so that it cannot pass vacuously.
    fn raw_parts_finite(a: &DMatrix<f64>, vectors: bool) -> [bool; 3] {
        let svd = SVD::try_new_unordered(
            a.clone(),
            vectors,
            vectors,
            5.0 * f64::EPSILON,
            SVD_MAX_ITERATIONS,
        )
        .unwrap();
        let finite =
            |m: &Option<DMatrix<f64>>| m.as_ref().is_none_or(|m| m.iter().all(|x| x.is_finite()));
        [
            svd.singular_values.iter().all(|s| s.is_finite()),
            finite(&svd.u),
            finite(&svd.v_t),
        ]
    }

    /// Finite matrices whose decomposition nalgebra computes with a non-finite part give
    /// `None`: every entry is finite, and so are their exact singular values (by hand: the
    /// 2 × 2 one has rank 1, σ = √2·√(2.25² + 1.5e308²) ≈ 2.12e308 < f64::MAX; the 3 × 3 one
    /// has one non-zero column c, σ = ‖c‖ ≈ 1e308), but the shifted QR overflows on the way —
    /// a NaN singular value in the first (where sorting would panic), a non-finite `Vᵀ` with
    /// finite values and `U` in the second. Each part of the check is needed: either alone
    /// would pass one of them.
    #[test]
    fn a_non_finite_part_of_a_finite_matrix_gives_none() {
        let values_only =
            DMatrix::<f64>::from_column_slice(2, 2, &[2.25, 2.25, -1.5e308, -1.5e308]);
        assert!(values_only.iter().all(|&x| x.is_finite()));
        assert_eq!(raw_parts_finite(&values_only, false), [false, true, true]);
        assert!(checked_svd(values_only.clone(), false).is_none());
        assert!(checked_svd(values_only, true).is_none());

        let v_only = DMatrix::<f64>::from_column_slice(
            3,
            3,
            &[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 2e150, 2e150, -1e308],
        );
        assert!(v_only.iter().all(|&x| x.is_finite()));
        assert_eq!(raw_parts_finite(&v_only, true), [true, true, false]);
        assert!(checked_svd(v_only.clone(), true).is_none());
        // Without vectors only the values are computed, and they are finite here: the
        // largest is the column's norm, 1e308 to within rounding.
        let svd = checked_svd(v_only, false).unwrap();
        let norm = (2.0 * (2e150f64 / 1e308).powi(2) + 1.0).sqrt() * 1e308;
        assert!((svd.singular_values[0] - norm).abs() <= 1e-12 * norm);
    }
}
