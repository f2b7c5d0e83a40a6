//! The principal moments of an inertia tensor, with an eigensolver that cannot hang.
//!
//! The model's scale (`MechanismScale`) and the validator's checks of each body's inertia both
//! need them; they live apart from either.

use nalgebra::{Matrix3, SymmetricEigen, Vector3};

/// Most iterations of the symmetric eigensolver on a 3 × 3 inertia: it converges in a few for
/// any finite tensor (nalgebra scales it first, so huge and subnormal entries are alike), and
/// nalgebra's default is no cap at all.
pub const EIGEN_MAX_ITERATIONS: usize = 1000;

/// The principal moments of a symmetric 3 × 3 tensor, or `None` when the capped eigensolver
/// does not converge (never seen for finite entries; the cap is there so that it cannot hang).
pub fn principal_moments(m: &Matrix3<f64>) -> Option<Vector3<f64>> {
    if !m.iter().all(|x| x.is_finite()) {
        return None;
    }
    SymmetricEigen::try_new(*m, f64::EPSILON, EIGEN_MAX_ITERATIONS).map(|e| e.eigenvalues)
}
