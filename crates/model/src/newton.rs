//! Inverse of the actuator map: the chart coordinates `q` with `f(q) = u`.
//!
//! Tasks are given in actuator space, but every pose is written in the chart, so each sample of
//! a task needs `q` from `u`. Newton's method warm-started from the previous sample converges in
//! a few iterations; it must never return a wrong configuration quietly, so it fails with a
//! reason instead: no convergence, a singular actuator Jacobian (a singular configuration or an
//! unreachable target), or a solution outside the coordinate ranges (another assembly branch).

use counterpoise_symbolic::VarKind;
use nalgebra::{DMatrix, DVector, LU, SVD};

use crate::kinematics::Kinematics;

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

impl Kinematics {
    /// `q` with `f(q) = u_target`, starting from `q_guess`, with default [`NewtonOptions`].
    pub fn solve_coordinates(
        &self,
        u_target: &DVector<f64>,
        q_guess: &DVector<f64>,
    ) -> Result<DVector<f64>, KinematicsError> {
        self.solve_coordinates_with(u_target, q_guess, &NewtonOptions::default())
    }

    /// Damped Newton with a backtracking line search on `|f(q) − u|`. Angles that enter `u`
    /// only through cos/sin are shifted by multiples of 2π into their ranges when possible
    /// (an angle that is itself actuated, `u = θ`, is not: that would change `u`).
    pub fn solve_coordinates_with(
        &self,
        u_target: &DVector<f64>,
        q_guess: &DVector<f64>,
        options: &NewtonOptions,
    ) -> Result<DVector<f64>, KinematicsError> {
        assert_eq!(
            u_target.len(),
            self.dof(),
            "target has the wrong number of actuators"
        );
        let tolerance = options.tolerance * (1.0 + u_target.amax());
        let step_limits: Vec<f64> = self
            .coordinates
            .iter()
            .map(|c| {
                let half = 0.5 * (c.range[1] - c.range[0]);
                match c.kind {
                    VarKind::Angle => half.min(options.max_angle_step),
                    VarKind::Length => half,
                }
            })
            .collect();
        let mut q = q_guess.clone();
        let mut residual = self.actuator_values(&q) - u_target;
        let mut iterations = 0;
        loop {
            // A NaN residual compares false with the tolerance: tested first, never taken for
            // convergence.
            if !residual.iter().all(|r| r.is_finite()) {
                return Err(KinematicsError::NonFinite {
                    what: "the actuator residual f(q) − u",
                    q: q.iter().copied().collect(),
                });
            }
            if residual.amax() <= tolerance {
                break;
            }
            if iterations == options.max_iterations {
                return Err(KinematicsError::NotConverged {
                    iterations,
                    residual: residual.amax(),
                });
            }
            iterations += 1;
            let g = self.actuator_jacobian(&q);
            let lu = checked_lu(&g, &q, options.max_condition)?;
            let mut step = -lu.solve(&residual).expect("checked non-singular");
            let scale = step
                .iter()
                .zip(&step_limits)
                .map(|(s, limit)| {
                    if s.abs() > *limit {
                        limit / s.abs()
                    } else {
                        1.0
                    }
                })
                .fold(1.0, f64::min);
            step *= scale;
            let norm = residual.norm();
            let mut t = 1.0;
            loop {
                let candidate = &q + &step * t;
                let r = self.actuator_values(&candidate) - u_target;
                if r.norm() <= (1.0 - 1e-4 * t) * norm || r.amax() <= tolerance {
                    q = candidate;
                    residual = r;
                    break;
                }
                t *= 0.5;
                if t < 1e-6 {
                    return Err(KinematicsError::NotConverged {
                        iterations,
                        residual: residual.amax(),
                    });
                }
            }
        }
        self.move_into_ranges(&mut q)?;
        Ok(q)
    }

    /// Moves periodic angles by multiples of 2π into their ranges; fails for a coordinate
    /// outside its range.
    fn move_into_ranges(&self, q: &mut DVector<f64>) -> Result<(), KinematicsError> {
        let two_pi = std::f64::consts::TAU;
        for ((value, c), &periodic) in q.iter_mut().zip(&self.coordinates).zip(&self.periodic) {
            let [lo, hi] = c.range;
            let slack = 1e-9 * (hi - lo);
            if periodic && !(lo - slack..=hi + slack).contains(value) {
                let shifted = *value - two_pi * ((*value - lo) / two_pi).floor();
                if shifted <= hi + slack {
                    *value = shifted;
                }
            }
            if !(lo - slack..=hi + slack).contains(value) {
                return Err(KinematicsError::OutOfRange {
                    coordinate: c.name.clone(),
                    value: *value,
                    range: c.range,
                });
            }
        }
        Ok(())
    }
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
