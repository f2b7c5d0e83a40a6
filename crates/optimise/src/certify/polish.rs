//! A local descent from a verified design: Nelder–Mead over the counterweights, the springs
//! realized again at every step.
//!
//! The objective depends on the counterweights alone (massless springs never change a balanced
//! variant's motor torques); the springs only decide whether a counterweight choice is
//! admissible. A box proposes a design near its relaxed point, where the springs often cannot
//! be realized, and the realization that moves the counterweights too lands wherever the
//! springs allow, not where the motors are best: on the palletizer at Dmax 3, m4 + K53 + K54
//! kept a design at 12.144 N·m where 11.843 N·m is admissible. Descending from each new best
//! design within the admissible set (the springs' realization is warm-started from the last
//! design, whose lifted point is nearly rank-one) takes such designs to a local optimum. It
//! only ever replaces a design by a better verified one, so the bound and the verdict keep
//! their meaning; every step is deterministic.

use std::sync::Arc;

use nalgebra::DVector;

use super::{Design, verified_design};
use crate::problem::{Objective, VariantProblem};
use crate::refine::{
    FEASIBILITY_TOL, counterweight_directions, free_coordinates, merit, minimise_along,
    project_radius,
};
use crate::springs::realize_springs;
use crate::torque::TaskTorques;

/// The best verified design met on a descent from the full lifted point `x` (a design's, or
/// one that misses a bound or limit: the descent's merit is penalised there); `None` when the
/// variant has no counterweight and spring to trade, or no step met every bound.
pub(super) fn descend(
    problem: &VariantProblem,
    b: &DVector<f64>,
    tasks: &[Arc<TaskTorques>],
    objective: Objective,
    x: &DVector<f64>,
    scale: f64,
) -> Option<Design> {
    if problem.springs.is_empty() || problem.counterweights.is_empty() {
        return None;
    }
    let directions = counterweight_directions(problem);
    let start = free_coordinates(problem, x)?;
    let mut best: Option<Design> = None;
    minimise_along(&start, &directions, |z| {
        let Some(z) = project_radius(problem, z, &directions) else {
            return f64::INFINITY;
        };
        let (penalised, _, violation) = merit(problem, tasks, objective, &z, scale);
        if violation > FEASIBILITY_TOL {
            return penalised;
        }
        let (found, _) = realize_springs(problem, b, &problem.lifted(&z), 1, false);
        let Some(d) = found
            .into_iter()
            .find_map(|(springs, x)| verified_design(problem, tasks, objective, springs, x))
        else {
            return f64::INFINITY;
        };
        let value = d.value;
        if best.as_ref().is_none_or(|bd| value < bd.value) {
            best = Some(d);
        }
        value
    });
    best
}
