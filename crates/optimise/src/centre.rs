//! Counterweight offsets that neither the balance nor the motors see, centred on their body.
//!
//! On the palletizer the column and both sliders turn about the vertical axis only, so a
//! counterweight's height on them moves no motor torque (its inertia about the vertical axis
//! does not depend on it, and gravity only adds a constant to its potential energy) and no
//! balance relation holds it. The objective cannot choose such an offset: the searches left it
//! wherever their paths had put it (m3 + K42 + K76 at y = −0.060 m for one `--seed`, +0.079 m for
//! another), and the joint reactions, hence ΔR and the rank, followed it. A designer centres
//! such a counterweight on its body; so does the optimiser, to 0 on each such axis where the
//! bounds allow it (a radius floor may not). The motor torques are those of the design before,
//! so the objective, the peak limits and the certified bound keep their meaning.
//!
//! An axis is free when its first moment's column of the balance system is zero (no balance
//! relation holds it, so it is a direction of the balanced family on its own; the anchor
//! restriction only adds rows on spring variables) and the torque of every actuator on every
//! sample of the working set's tasks is independent of it: the first moment's column and every
//! inertia column the offset enters (the products of inertia with that axis, the moments about
//! the other two) are zero, to 1e-12 of the body's largest column. The loop's all-task
//! evaluation then checks the centred design on every other task, as it checks every design.

use std::sync::Arc;

use counterpoise_dynamics::params::BODY_PARAMS;

use crate::certify::{Design, verified_design};
use crate::problem::{Objective, VariantProblem};
use crate::torque::TaskTorques;

/// Relative size below which a torque column counts as zero (of the body's largest).
const ZERO_COLUMN: f64 = 1e-12;

/// Index among a body's lifted inertial parameters `(m, m·r, I_xx, I_yy, I_zz, I_xy, I_xz,
/// I_yz)` of the inertia entry `(i, j)`.
fn inertia_index(i: usize, j: usize) -> usize {
    match (i.min(j), i.max(j)) {
        (d, e) if d == e => 4 + d,
        (0, 1) => 7,
        (0, 2) => 8,
        _ => 9,
    }
}

/// The lifted parameters whose torque columns must vanish for the offset along body axis
/// `axis` to move no torque: its first moment, the moments of inertia about the other two axes
/// (`∂I_ii/∂r_a = 2m·r_a`) and the products of inertia with `axis` (`∂I_aj/∂r_a = −m·r_j`).
fn offset_columns(axis: usize) -> Vec<usize> {
    let mut columns = vec![1 + axis];
    for other in (0..3).filter(|&o| o != axis) {
        columns.push(inertia_index(other, other));
        columns.push(inertia_index(axis, other));
    }
    columns
}

/// The lifted columns (first moments `m·r_a`) of the counterweight offsets that no balance
/// relation holds and no torque on `tasks` depends on (see the module doc).
pub fn free_offsets(problem: &VariantProblem, tasks: &[Arc<TaskTorques>]) -> Vec<usize> {
    // No balance relation holds a lifted variable whose column of the balance system is zero.
    let matrix = &problem.solution.matrix;
    let in_no_relation = |column: usize| matrix.column(column).iter().all(|&v| v == 0.0);
    let mut free = Vec::new();
    for c in &problem.counterweights {
        let largest = tasks
            .iter()
            .flat_map(|t| (0..BODY_PARAMS).flat_map(move |j| t.sens(c.torque_slot, j).iter()))
            .fold(0.0f64, |a, &v| a.max(v.abs()));
        for (p, &axis) in c.axes.iter().enumerate() {
            let column = c.column + 1 + p;
            let torque_free = offset_columns(axis).into_iter().all(|j| {
                tasks.iter().all(|t| {
                    t.sens(c.torque_slot, j)
                        .iter()
                        .all(|v| v.abs() <= ZERO_COLUMN * largest)
                })
            });
            if torque_free && in_no_relation(column) {
                free.push(column);
            }
        }
    }
    free
}

/// `design` with its free offsets ([`free_offsets`]) at 0, verified again; `design` itself when
/// it has none off centre, or when the centred design fails a bound (a radius floor) or would
/// be worse than `design` by more than 1e-12 of its value.
pub fn centred(
    problem: &VariantProblem,
    tasks: &[Arc<TaskTorques>],
    objective: Objective,
    design: Design,
) -> Design {
    let free = free_offsets(problem, tasks);
    if free.iter().all(|&c| design.x[c] == 0.0) {
        return design;
    }
    let mut x = design.x.clone();
    for &c in &free {
        x[c] = 0.0;
    }
    match verified_design(problem, tasks, objective, design.springs.clone(), x) {
        Some(d) if d.value <= design.value + 1e-12 * design.value.abs() => d,
        _ => design,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use counterpoise_dynamics::params::body_params;
    use nalgebra::{Matrix3, Vector3};

    /// The index map is `body_params`' order: a point mass of 1 kg at `r` has
    /// `I_o = |r|²·1 − r rᵀ`, so with `r = (1, 2, 3)` the entry `(i, j)` is `14·δ_ij − r_i r_j`.
    #[test]
    fn inertia_entries_are_read_where_body_params_puts_them() {
        let r = Vector3::new(1.0, 2.0, 3.0);
        let pi = body_params(1.0, &r, &Matrix3::zeros());
        for i in 0..3 {
            for j in 0..3 {
                let by_hand = if i == j { 14.0 } else { 0.0 } - r[i] * r[j];
                assert_eq!(pi[inertia_index(i, j)], by_hand, "({i}, {j})");
            }
        }
    }

    /// The columns an offset along `a` enters, by the derivatives of `body_params` with respect
    /// to `r_a` (central differences of a point mass at a generic `r`): exactly the listed ones
    /// change, and no other.
    #[test]
    fn an_offset_enters_exactly_the_columns_listed() {
        let r = Vector3::new(0.3, -0.7, 0.45);
        for axis in 0..3 {
            let mut up = r;
            let mut down = r;
            up[axis] += 1e-3;
            down[axis] -= 1e-3;
            let (pu, pd) = (
                body_params(2.0, &up, &Matrix3::zeros()),
                body_params(2.0, &down, &Matrix3::zeros()),
            );
            let moved: Vec<usize> = (0..BODY_PARAMS)
                .filter(|&j| (pu[j] - pd[j]).abs() > 1e-12)
                .collect();
            let mut listed = offset_columns(axis);
            listed.sort_unstable();
            assert_eq!(moved, listed, "axis {axis}");
        }
    }
}
