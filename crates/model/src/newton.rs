//! Inverse of the actuator map: the chart coordinates `q` with `f(q) = u`.
//!
//! Tasks are given in actuator space, but every pose is written in the chart, so each sample of
//! a task needs `q` from `u`. Newton's method warm-started from the previous sample converges in
//! a few iterations; it must never return a wrong configuration quietly, so it fails with a
//! reason instead: no convergence, a singular actuator Jacobian (a singular configuration or an
//! unreachable target), or a solution outside the coordinate ranges (another assembly branch).

use counterpoise_symbolic::VarKind;
use nalgebra::DVector;

use crate::jacobian_lu::checked_lu;
pub use crate::jacobian_lu::{KinematicsError, NewtonOptions};
use crate::kinematics::Kinematics;

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
