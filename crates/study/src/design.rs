//! What the report shows of a design beyond its numbers, computed from the model: the bounds
//! each element was optimised within (to mark parameters on a bound) and the schematics
//! (world coordinates of bodies, joints, counterweights and spring anchors at one pose). Called at the end of
//! `run` and `merge` and by `report DIR`, which rebuilds the model from the case echo in
//! results.json, so reports of older results gain them too.

use crate::error::{Result, invalid};
use counterpoise_balance::{Catalogue, catalogue_options, mechanism_energy};
use counterpoise_dynamics::{ParameterSet, Variant};
use counterpoise_model::{BodyId, Kinematics, Model, PayloadMode};
use counterpoise_optimise::{BoundsTable, ElementBounds as OptBounds};
use counterpoise_report as report;
use nalgebra::{DVector, Vector3};

/// The bounds of every catalogue element of `model`, by label.
pub fn element_bounds(model: &Model) -> Result<Vec<report::ElementBounds>> {
    let catalogue = Catalogue::build(&mechanism_energy(model), &catalogue_options(model));
    let table = BoundsTable::new(model, &catalogue)?;
    Ok(catalogue
        .entries
        .iter()
        .zip(&table.entries)
        .map(|(e, b)| match b {
            OptBounds::Counterweight(c) => report::ElementBounds {
                label: e.label.clone(),
                mass: Some(c.mass),
                radius: Some(c.radius),
                stiffness: None,
                anchor_a: None,
                anchor_b: None,
            },
            OptBounds::Spring(s) => report::ElementBounds {
                label: e.label.clone(),
                mass: None,
                radius: None,
                stiffness: Some(s.stiffness),
                anchor_a: Some(s.anchor_a),
                anchor_b: Some(s.anchor_b),
            },
        })
        .collect())
}

/// The pose the schematics are drawn at, in words, and its configuration: the first waypoint
/// of the case's first path (the start of the cycle the report simulates), else the middle
/// point of the task grid, else the coordinates' range midpoints (the model's reference
/// configuration). A waypoint or grid point whose configuration cannot be solved falls back to
/// the next choice.
pub fn reference_pose(model: &Model) -> (String, Vec<f64>) {
    let solver = counterpoise_dynamics::Evaluator::new(model).ok();
    let solve = |u: &[f64]| solver.as_ref().and_then(|e| e.solve_point(u).ok());
    if let Some(path) = model.paths.first()
        && let Some(&first) = path.sequence.first()
        && let Some(w) = path.waypoints.get(first)
        && let Some(q) = solve(&w.u)
    {
        return (
            format!(
                "waypoint {} of path {} (where its cycle starts)",
                w.name, path.name
            ),
            q,
        );
    }
    if let Some(tasks) = &model.tasks {
        let points = tasks.grid_points();
        let k = points.len() / 2;
        if let Some(q) = points.get(k).and_then(|u| solve(u)) {
            return (format!("task-grid point {k} (the middle of the grid)"), q);
        }
    }
    (
        "the middle of every coordinate's range".into(),
        model.reference_configuration(),
    )
}

/// World position of `p` (body frame of `body`, or the base frame) at `q`.
fn world(
    model: &Model,
    kin: &Kinematics,
    body: Option<usize>,
    p: Vector3<f64>,
    q: &DVector<f64>,
) -> [f64; 3] {
    let w = match body {
        Some(b) if b < model.bodies.len() => {
            let pose = kin.body_pose(b, q);
            pose.position + pose.rotation * p
        }
        _ => p,
    };
    [w.x, w.y, w.z]
}

/// The schematic of variant `v` (its optimised parameters; `None`: the unbalanced mechanism)
/// at configuration `q`.
pub fn schematic(
    model: &Model,
    kin: &Kinematics,
    v: Option<&report::VariantRecord>,
    (pose, q): (&str, &[f64]),
) -> report::Schematic {
    let qv = DVector::from_column_slice(q);
    let body_index = |name: &str| model.body_index(name);
    // Each body's points: where it hangs from (joints where it is the second body first),
    // then its other joints.
    let mut points: Vec<Vec<[f64; 3]>> = vec![Vec::new(); model.bodies.len()];
    for second in [true, false] {
        for j in &model.joints {
            for (k, id) in j.bodies.iter().enumerate() {
                if (k == 1) != second {
                    continue;
                }
                if let BodyId::Body(b) = id {
                    points[*b].push(world(model, kin, Some(*b), j.points[k], &qv));
                }
            }
        }
    }
    let bodies: Vec<report::DrawnBody> = model
        .bodies
        .iter()
        .enumerate()
        .map(|(b, body)| {
            let mut pts = points[b].clone();
            if pts.is_empty() {
                pts.push(world(model, kin, Some(b), Vector3::zeros(), &qv));
            }
            report::DrawnBody {
                name: body.name.clone(),
                points: pts,
                com: world(model, kin, Some(b), body.com, &qv),
            }
        })
        .collect();
    let hang = |b: Option<usize>, fallback: [f64; 3]| {
        b.and_then(|b| bodies.get(b))
            .and_then(|d| d.points.first().copied())
            .unwrap_or(fallback)
    };
    let joints = model
        .joints
        .iter()
        .map(|j| report::DrawnJoint {
            name: j.name.clone(),
            at: world(model, kin, j.bodies[0].index(), j.points[0], &qv),
            grounded: j.bodies.contains(&BodyId::Base),
        })
        .collect();
    let params = v.and_then(|v| v.parameters.clone()).unwrap_or_default();
    let counterweights = params
        .counterweights
        .iter()
        .map(|c| {
            let b = body_index(&c.body);
            let at = world(model, kin, b, Vector3::from(c.offset), &qv);
            report::DrawnCounterweight {
                label: c.label.clone(),
                at,
                from: hang(b, at),
            }
        })
        .collect();
    let springs = params
        .springs
        .iter()
        .map(|s| {
            let (ba, bb) = (body_index(&s.body), body_index(&s.other));
            let a = world(model, kin, ba, Vector3::from(s.anchor_a), &qv);
            let b = world(model, kin, bb, Vector3::from(s.anchor_b), &qv);
            report::DrawnSpring {
                label: s.label.clone(),
                a,
                b,
                a_from: hang(ba, a),
                b_from: hang(bb, b),
            }
        })
        .collect();
    report::Schematic {
        variant: v.map(|v| v.id),
        pose: pose.to_string(),
        q: q.to_vec(),
        gravity: [model.gravity.x, model.gravity.y, model.gravity.z],
        bodies,
        joints,
        counterweights,
        springs,
    }
}

/// Schematics of the recommended variants (after the decision), then of `extra` (variant
/// names such as `SB12`, or labels such as `m4 + K43`), each once; the unbalanced mechanism
/// when there is none of either (so every report shows what the mechanism looks like).
pub fn schematics(
    model: &Model,
    results: &report::RunResults,
    extra: &[String],
) -> Result<Vec<report::Schematic>> {
    let kin = Kinematics::new(model);
    let (pose, q) = reference_pose(model);
    let mut ids = results.recommended_ids();
    for name in extra {
        let found = results
            .ranked()
            .into_iter()
            .find(|v| v.name.as_deref() == Some(name.as_str()) || v.label() == *name);
        match found {
            Some(v) => {
                if !ids.contains(&v.id) {
                    ids.push(v.id);
                }
            }
            None => invalid!(
                "--draw {name}: no ranked variant of that name (SB1…SB{}) or elements",
                results.ranked().len()
            ),
        }
    }
    if ids.is_empty() {
        return Ok(vec![schematic(model, &kin, None, (&pose, &q))]);
    }
    Ok(ids
        .iter()
        .filter_map(|&id| results.variant(id))
        .map(|v| schematic(model, &kin, Some(v), (&pose, &q)))
        .collect())
}

/// Samples per path segment of the energy chart (as the path simulation samples it).
const ENERGY_SAMPLES_PER_SEGMENT: usize = 60;

/// Potential energy of the unbalanced mechanism (bodies and the payloads the balancing counts)
/// and of the recommended and drawn variants (plus their counterweights' weight and their
/// springs' `½·K·L²`), along the case's first path, or, without one, along the unbalanced
/// robot's QTR task; each relative to its first sample.
pub fn energy_chart(
    model: &Model,
    results: &report::RunResults,
) -> Result<Option<report::EnergyChart>> {
    let variants = report::tables::design_variants(results);
    if variants.is_empty() {
        return Ok(None);
    }
    let params = ParameterSet::from_variants(model, &[Variant::default()])?;
    let (along, t, qs) = if model.paths.is_empty() {
        let task = results.unbalanced.qtr_task;
        let s = counterpoise_dynamics::task_series_with(model, &params, 0, task[0], task[1], None)?;
        (
            format!(
                "task {}→{} (the unbalanced robot's QTR task)",
                task[0], task[1]
            ),
            s.t,
            s.q,
        )
    } else {
        let s =
            counterpoise_dynamics::path_series(model, &params, 0, 0, ENERGY_SAMPLES_PER_SEGMENT)?;
        (format!("path {}", model.paths[0].name), s.t, s.q)
    };
    let kin = Kinematics::new(model);
    let unbalanced = model.potential_energy(PayloadMode::InBalance);
    let g = model.gravity;
    let ub: Vec<f64> = qs
        .iter()
        .map(|q| unbalanced.eval(&model.point(q)))
        .collect();
    let relative = |v: Vec<f64>| -> Vec<f64> {
        let v0 = v.first().copied().unwrap_or(0.0);
        v.into_iter().map(|x| x - v0).collect()
    };
    let mut curves = vec![report::Curve {
        label: "UB".into(),
        variant: None,
        values: relative(ub.clone()),
    }];
    for v in variants {
        let Some(p) = &v.parameters else { continue };
        let values: Vec<f64> = qs
            .iter()
            .zip(&ub)
            .map(|(q, v_ub)| {
                let qv = DVector::from_column_slice(q);
                let at = |body: &str, r: [f64; 3]| -> Vector3<f64> {
                    let w = world(model, &kin, model.body_index(body), Vector3::from(r), &qv);
                    Vector3::from(w)
                };
                let mut e = *v_ub;
                for c in &p.counterweights {
                    e -= c.mass * g.dot(&at(&c.body, c.offset));
                }
                for s in &p.springs {
                    let d = at(&s.body, s.anchor_a) - at(&s.other, s.anchor_b);
                    e += 0.5 * s.stiffness * d.norm_squared();
                }
                e
            })
            .collect();
        curves.push(report::Curve {
            label: results.shown_label(v),
            variant: Some(v.id),
            values: relative(values),
        });
    }
    let picked = model
        .paths
        .first()
        .and_then(|p| p.payload.as_ref())
        .map(|_| " The path's payload, picked and dropped on the way, is not counted: the balancing does not see it.")
        .unwrap_or("");
    Ok(Some(report::EnergyChart {
        along,
        note: Some(format!(
            "Gravity energy of the bodies and of the payloads the balancing counts, plus the \
             counterweights' and the springs' (½·K·L²), relative to the first sample.{picked}"
        )),
        t,
        curves,
    }))
}
