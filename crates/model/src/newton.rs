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
}

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
    let singular = SVD::new(g.clone(), false, false).singular_values;
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
        while residual.amax() > tolerance {
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
