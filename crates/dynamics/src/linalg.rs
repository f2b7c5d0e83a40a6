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
}
