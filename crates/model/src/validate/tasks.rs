//! The tasks section: the grid of moves, its size against the limits, and the paths with
//! their payloads.

use std::collections::HashMap;

use nalgebra::Vector3;

use super::magnitudes::*;
use super::topology::*;
use super::validator::*;
use crate::case::{Case, LawSpec, PairsSpec, TasksSpec};
use crate::limits::Limit;
use crate::model::{BodyId, GridAxis, MotionLaw, PairMode, PathPayload, TaskPath, Tasks, Waypoint};
use crate::pose::Parser;
use crate::reader::too_large;

pub(super) fn tasks(
    v: &mut Validator,
    t: &TasksSpec,
    case: &Case,
    actuator_index: &dyn Fn(&str) -> Option<usize>,
) -> Option<Tasks> {
    let start = v.errors.len();
    let mut grid: Vec<Option<GridAxis>> = vec![None; case.actuators.len()];
    for (name, &[from, to, n]) in t.grid.iter() {
        let path = format!("tasks.grid.{name}");
        let Some(k) = actuator_index(name) else {
            v.unknown(&path, "actuator", name);
            continue;
        };
        if !v.bounded(&[from, to], MAX_LENGTH.max(MAX_ANGLE), &path, "") || !v.finite(&[n], &path) {
            continue;
        }
        if n < 1.0 || n.fract() != 0.0 {
            v.invalid(
                format!("{path}[2]"),
                format!("the number of values must be an integer ≥ 1 (found {n})"),
            );
            continue;
        }
        if n > v.limits.grid_points as f64 {
            v.push(too_large(
                &format!("{path}[2]"),
                "values on one axis",
                n,
                Limit::GridPoints,
                v.limits.grid_points,
            ));
            continue;
        }
        grid[k] = Some(GridAxis {
            from,
            to,
            n: n as usize,
        });
    }
    let missing: Vec<&str> = case
        .actuators
        .iter()
        .zip(&grid)
        .filter(|(_, g)| g.is_none())
        .map(|(a, _)| a.name.as_str())
        .collect();
    if !missing.is_empty() && v.errors.len() == start {
        v.invalid(
            "tasks.grid",
            format!(
                "every actuator needs a grid axis; missing: {}",
                missing.join(", ")
            ),
        );
    }
    if v.errors.len() == start {
        grid_size(v, &grid, t);
    }
    v.duration(t.duration, "tasks.duration");
    if t.samples < 2 {
        v.invalid(
            "tasks.samples",
            format!("must be ≥ 2 (found {})", t.samples),
        );
    } else if u64::from(t.samples) > v.limits.samples {
        v.push(too_large(
            "tasks.samples",
            "samples per task",
            f64::from(t.samples),
            Limit::Samples,
            v.limits.samples,
        ));
    }
    (v.errors.len() == start).then(|| Tasks {
        grid: grid.into_iter().map(|g| g.expect("checked")).collect(),
        pairs: match t.pairs {
            PairsSpec::All => PairMode::All,
            PairsSpec::Ordered => PairMode::Ordered,
        },
        law: match t.law {
            LawSpec::Quintic => MotionLaw::Quintic,
        },
        duration: t.duration,
        samples: t.samples as usize,
    })
}

/// The number of tasks of a grid of `points` points (computed in floating point: it must not
/// overflow before it is compared with a limit).
pub fn task_count(points: f64, pairs: PairMode) -> f64 {
    match pairs {
        PairMode::All => points * (points - 1.0) / 2.0,
        PairMode::Ordered => points * (points - 1.0),
    }
}

/// Checks the grid's point count, task count and evaluations against the limits, from the axis
/// sizes alone (the grid is not built), and refuses a grid of one point: a task moves between
/// two points.
pub(super) fn grid_size(v: &mut Validator, grid: &[Option<GridAxis>], t: &TasksSpec) {
    let sizes: Vec<f64> = grid.iter().flatten().map(|g| g.n as f64).collect();
    let points: f64 = sizes.iter().product();
    if points > v.limits.grid_points as f64 {
        v.push(too_large(
            "tasks.grid",
            "grid points",
            points,
            Limit::GridPoints,
            v.limits.grid_points,
        ));
        return;
    }
    if points < 2.0 {
        v.invalid(
            "tasks.grid",
            "the grid has a single point (every axis has n = 1), so there is no move between two points: give some actuator n ≥ 2",
        );
        return;
    }
    let pairs = match t.pairs {
        PairsSpec::All => PairMode::All,
        PairsSpec::Ordered => PairMode::Ordered,
    };
    let evaluations = task_count(points, pairs) * f64::from(t.samples.max(2));
    if evaluations > v.limits.task_samples as f64 {
        v.push(too_large(
            "tasks",
            &format!(
                "evaluations ({} tasks × {} samples)",
                crate::limits::format_count(task_count(points, pairs)),
                t.samples
            ),
            evaluations,
            Limit::TaskSamples,
            v.limits.task_samples,
        ));
    }
}

pub(super) fn task_paths(
    v: &mut Validator,
    case: &Case,
    parser: &Parser,
    body_id: &dyn Fn(&str) -> Option<BodyId>,
) -> Option<Vec<TaskPath>> {
    let start = v.errors.len();
    let mut names = HashMap::new();
    let mut out = Vec::new();
    for (i, p) in case.paths.iter().enumerate() {
        let path = format!("paths[{i}]");
        v.name(&p.name, &format!("{path}.name"));
        v.unique(&mut names, &p.name, format!("{path}.name"), "path");
        let mut waypoints = Vec::new();
        let sizes_ok = v.list_size(p.waypoints.len(), &format!("{path}.waypoints"))
            & v.list_size(p.sequence.len(), &format!("{path}.sequence"))
            & v.list_size(p.durations.len(), &format!("{path}.durations"));
        if !sizes_ok {
            continue;
        }
        for (name, u) in p.waypoints.iter() {
            let wp = format!("{path}.waypoints.{name}");
            if u.len() != case.actuators.len() {
                v.invalid(
                    &wp,
                    format!(
                        "needs one value per actuator ({}), found {}",
                        case.actuators.len(),
                        u.len()
                    ),
                );
            }
            v.bounded(u, MAX_LENGTH.max(MAX_ANGLE), &wp, "");
            waypoints.push(Waypoint {
                name: name.to_string(),
                u: u.clone(),
            });
        }
        let mut sequence = Vec::new();
        for (k, name) in p.sequence.iter().enumerate() {
            match waypoints.iter().position(|w| w.name == *name) {
                Some(w) => sequence.push(w),
                None => v.unknown(format!("{path}.sequence[{k}]"), "waypoint", name),
            }
        }
        if p.sequence.len() < 2 {
            v.invalid(format!("{path}.sequence"), "needs at least two waypoints");
        }
        if p.durations.len() + 1 != p.sequence.len() {
            v.invalid(
                format!("{path}.durations"),
                format!(
                    "needs one duration per segment ({}), found {}",
                    p.sequence.len().saturating_sub(1),
                    p.durations.len()
                ),
            );
        }
        for (k, &d) in p.durations.iter().enumerate() {
            v.duration(d, &format!("{path}.durations[{k}]"));
        }
        let payload = p.payload.as_ref().and_then(|pl| {
            let pp = format!("{path}.payload");
            let body = carried_body(v, body_id, &pl.body, &format!("{pp}.body"));
            v.positive_at_most(pl.mass, MAX_MASS, &format!("{pp}.mass"), "kg");
            let com = parser.constant_vec(&pl.com, &format!("{pp}.com"), &mut v.errors);
            let com = v.length_vec(com, &format!("{pp}.com"));
            let inertia = v.inertia(&pl.inertia.unwrap_or([0.0; 6]), &format!("{pp}.inertia"));
            let pick = p.sequence.iter().position(|s| *s == pl.pick_at);
            if pick.is_none() {
                v.unknown(
                    format!("{pp}.pick_at"),
                    "waypoint of the sequence",
                    &pl.pick_at,
                );
            }
            let drop = pick.and_then(|k| {
                let found = p.sequence[k + 1..]
                    .iter()
                    .position(|s| *s == pl.drop_at)
                    .map(|d| d + k + 1);
                if found.is_none() {
                    v.invalid(
                        format!("{pp}.drop_at"),
                        format!(
                            "`{}` must occur in the sequence after pick_at `{}`",
                            pl.drop_at, pl.pick_at
                        ),
                    );
                }
                found
            });
            Some(PathPayload {
                body: body?,
                mass: pl.mass,
                com: Vector3::from(com?),
                inertia_com: inertia?,
                pick_at: pick?,
                drop_at: drop?,
            })
        });
        out.push(TaskPath {
            name: p.name.clone(),
            waypoints,
            sequence,
            durations: p.durations.clone(),
            payload,
        });
    }
    (v.errors.len() == start).then_some(out)
}
