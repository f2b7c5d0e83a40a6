//! The actuator Jacobian's checked factorisation and the errors of solving for coordinates.
//!
//! Both the Newton inverse of the actuator map (`newton`) and the velocity/acceleration maps
//! (`kinematics`) factorise the actuator Jacobian `G`, and both must refuse a singular or
//! non-finite one with the same reason. The check lives here so that neither of those modules
//! depends on the other for it.

use nalgebra::{DMatrix, DVector, LU, SVD};

/// Why `solve_coordinates` gave no configuration.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum KinematicsError {
    #[error("Newton did not converge in {iterations} iterations (residual {residual:.3e})")]
    NotConverged { iterations: usize, residual: f64 },
    #[error("actuator Jacobian is singular at q = {q:?} (condition number {condition:.3e})")]
    Singular { q: Vec<f64>, condition: f64 },
    #[error("solution has {coordinate} = {value} outside its range [{}, {}]", range[0], range[1])]
    OutOfRange {
        coordinate: String,
        value: f64,
        range: [f64; 2],
    },
    #[error("{what} is not finite at q = {q:?} (a number of the case overflows)")]
    NonFinite { what: &'static str, q: Vec<f64> },
    #[error("the SVD of the actuator Jacobian failed at q = {q:?}: {reason}")]
    SvdFailed { q: Vec<f64>, reason: &'static str },
}

/// Most iterations of the SVD that checks the actuator Jacobian's condition number: it
/// converges in a handful for the few coordinates a case has, so hitting the cap means the
/// matrix is not a sane one (nalgebra's own default is no cap, which never returns on a NaN).
const SVD_MAX_ITERATIONS: usize = 1000;

/// nalgebra's default SVD tolerance (the one `SVD::new` uses): the same singular values as
/// before the cap, bit for bit.
const SVD_EPS: f64 = 5.0 * f64::EPSILON;

/// Settings of the Newton solver.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewtonOptions {
    /// Converged when `max_i |f_i(q) − u_i| ≤ tolerance · (1 + max_i |u_i|)`.
    pub tolerance: f64,
    pub max_iterations: usize,
    /// `G` counts as singular when `σ_max/σ_min` exceeds this.
    pub max_condition: f64,
    /// Largest step of an angle coordinate per iteration (rad); a length coordinate may move
    /// at most half its range width. Keeps the iteration on its assembly branch.
    pub max_angle_step: f64,
}

impl Default for NewtonOptions {
    fn default() -> Self {
        NewtonOptions {
            tolerance: 1e-12,
            max_iterations: 50,
            max_condition: 1e10,
            max_angle_step: 0.5,
        }
    }
}

/// LU of `g` after checking its condition number by SVD.
pub(crate) fn checked_lu(
    g: &DMatrix<f64>,
    q: &DVector<f64>,
    max_condition: f64,
) -> Result<LU<f64, nalgebra::Dyn, nalgebra::Dyn>, KinematicsError> {
    if !g.iter().all(|x| x.is_finite()) {
        return Err(KinematicsError::NonFinite {
            what: "the actuator Jacobian",
            q: q.iter().copied().collect(),
        });
    }
    // Unordered: nalgebra's sorting panics on a NaN singular value, which its shifted QR can
    // produce even from a finite, rank-deficient matrix (an underflowing Wilkinson shift). Only
    // the largest and the smallest are needed.
    let failed = |reason| KinematicsError::SvdFailed {
        q: q.iter().copied().collect(),
        reason,
    };
    let Some(svd) = SVD::try_new_unordered(g.clone(), false, false, SVD_EPS, SVD_MAX_ITERATIONS)
    else {
        return Err(failed("no convergence within the iteration cap"));
    };
    let singular = svd.singular_values;
    if !singular.iter().all(|s| s.is_finite()) {
        return Err(failed("a singular value is not finite"));
    }
    let (max, min) = singular
        .iter()
        .fold((0.0f64, f64::INFINITY), |(hi, lo), &s| {
            (hi.max(s), lo.min(s))
        });
    let condition = if min > 0.0 { max / min } else { f64::INFINITY };
    if condition.is_nan() || condition > max_condition {
        return Err(KinematicsError::Singular {
            q: q.iter().copied().collect(),
            condition,
        });
    }
    Ok(g.clone().lu())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn q() -> DVector<f64> {
        DVector::from_vec(vec![0.1, 0.2])
    }

    /// A NaN or an infinity in the Jacobian is refused before the SVD (nalgebra's uncapped SVD
    /// never returns on a NaN; this test would hang without the guard).
    #[test]
    fn a_non_finite_jacobian_is_refused_by_name() {
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let g = DMatrix::from_row_slice(2, 2, &[1.0, 0.0, bad, 1.0]);
            match checked_lu(&g, &q(), 1e10) {
                Err(KinematicsError::NonFinite { what, q }) => {
                    assert_eq!(what, "the actuator Jacobian");
                    assert_eq!(q, vec![0.1, 0.2]);
                }
                other => panic!("{bad}: {other:?}"),
            }
        }
    }

    /// Huge and tiny finite Jacobians: diag(1e308, 1e-308) has condition number 1e616, which
    /// overflows to infinity (singular); diag(1e300, 1e300) is perfectly conditioned (1) and
    /// factorises; the zero matrix is singular with condition ∞.
    #[test]
    fn extreme_finite_jacobians_are_decided() {
        let wide = DMatrix::from_row_slice(2, 2, &[1e308, 0.0, 0.0, 1e-308]);
        assert!(matches!(
            checked_lu(&wide, &q(), 1e10),
            Err(KinematicsError::Singular { condition, .. }) if condition == f64::INFINITY
        ));
        let big = DMatrix::from_row_slice(2, 2, &[1e300, 0.0, 0.0, 1e300]);
        let lu = checked_lu(&big, &q(), 1e10).expect("condition 1");
        let x = lu.solve(&DVector::from_vec(vec![2e300, 3e300])).unwrap();
        assert!(
            (x[0] - 2.0).abs() < 1e-12 && (x[1] - 3.0).abs() < 1e-12,
            "{x}"
        );
        let zero = DMatrix::zeros(2, 2);
        assert!(matches!(
            checked_lu(&zero, &q(), 1e10),
            Err(KinematicsError::Singular { condition, .. }) if condition == f64::INFINITY
        ));
    }

    /// The condition number is the singular values' ratio computed to nalgebra's default
    /// tolerance. G = [[1, 5], [0, 1]] is already bidiagonal: its diagonal (1, 1) would give a
    /// condition of 1 with a tolerance loose enough to accept the off-diagonal 5 as zero.
    /// By hand: σ_max·σ_min = |det G| = 1 and σ_max² + σ_min² = ‖G‖_F² = 27, so the condition
    /// σ_max/σ_min = σ_max² = (27 + √725)/2 ≈ 26.96: singular at a limit of 10, not at 30.
    #[test]
    fn the_condition_number_is_the_converged_singular_values_ratio() {
        let g = DMatrix::from_row_slice(2, 2, &[1.0, 5.0, 0.0, 1.0]);
        let exact = (27.0 + 725f64.sqrt()) / 2.0;
        match checked_lu(&g, &q(), 10.0) {
            Err(KinematicsError::Singular { condition, .. }) => {
                assert!((condition - exact).abs() <= 1e-12 * exact, "{condition}")
            }
            other => panic!("{other:?}"),
        }
        assert!(checked_lu(&g, &q(), 30.0).is_ok());
    }
}
