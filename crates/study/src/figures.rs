//! What Phase 3 draws and measures beyond the ranking: the mechanisms the report shows (the
//! unbalanced robot, the best-ranked and the recommended variants), their torque curves, the
//! path simulation, and the practical figures (added mass, spring peaks and stretch).

use counterpoise_dynamics::params::ParameterSet;
use counterpoise_dynamics::{Variant, task_series_with};
use counterpoise_model::Model;
use counterpoise_report as report;
use report::{RunResults, Status};

use crate::error::{Result, StudyError};
use crate::shard_file::OptimisedRecord;

/// The unbalanced robot and the variants the report shows (the best-ranked and the
/// recommended of each class, [`RunResults::shown_variants`]) as parameter columns, with their
/// labels (`UB`, then `SB6 (K42 + K43), recommended`-style names) and variant ids.
pub struct Mechanisms {
    params: ParameterSet,
    labels: Vec<(String, Option<usize>)>,
}

pub fn shown_mechanisms(
    model: &Model,
    results: &RunResults,
    optimised: &[OptimisedRecord],
) -> Result<Mechanisms> {
    let mut variants = vec![Variant::default()];
    let mut labels = vec![("UB".to_string(), None)];
    for v in results.shown_variants() {
        let label = v.label();
        let Some(opt) = optimised.iter().find(|o| o.label() == label) else {
            continue;
        };
        variants.push(opt.physical_parameters());
        labels.push((results.shown_label(v), Some(v.id)));
    }
    Ok(Mechanisms {
        params: ParameterSet::from_variants(model, &variants)?,
        labels,
    })
}

/// [`shown_mechanisms`] from the parameters stored in the results (`report DIR`, which has no
/// optimiser records).
pub fn shown_mechanisms_of_results(model: &Model, results: &RunResults) -> Result<Mechanisms> {
    let mut variants = vec![Variant::default()];
    let mut labels = vec![("UB".to_string(), None)];
    for v in results.shown_variants() {
        let Some(p) = &v.parameters else { continue };
        variants.push(p.clone());
        labels.push((results.shown_label(v), Some(v.id)));
    }
    // The bodies are named in results.json: one the case does not have is the user's mistake
    // (results of another case), said as such.
    let params = ParameterSet::from_variants(model, &variants)
        .map_err(|e| StudyError::Invalid(format!("results.json does not fit the case: {e}")))?;
    Ok(Mechanisms { params, labels })
}

/// Samples per path segment in the path simulation.
const PATH_SAMPLES_PER_SEGMENT: usize = 60;
/// How much the quasi-static run stretches the path's durations: velocities scale by 1e-6 and
/// the inertial torques by 1e-12, far below anything a report shows.
const STATIC_STRETCH: f64 = 1e6;

/// The configurations along path `index`, sampled as [`path_simulation`] samples them (they
/// are kinematics, the same for every mechanism): where the practical figures take the springs'
/// peaks, needed before the simulation because the recommendation reads those figures.
pub fn path_configurations(model: &Model, index: usize) -> Result<Vec<Vec<f64>>> {
    let params = ParameterSet::from_variants(model, &[Variant::default()])?;
    let series =
        counterpoise_dynamics::path_series(model, &params, 0, index, PATH_SAMPLES_PER_SEGMENT)?;
    Ok(series.q)
}

/// The paper's Sec. 3.3 simulation along path `index`: the timed cycle, and the same path
/// traversed quasi-statically (static torques).
pub fn path_simulation(
    model: &Model,
    m: &Mechanisms,
    index: usize,
) -> Result<(report::PathSimulation, Vec<Vec<f64>>)> {
    let spec = &model.paths[index];
    let actuators: Vec<String> = model.actuators.iter().map(|a| a.name.clone()).collect();
    let mut configurations: Vec<Vec<f64>> = Vec::new();
    let mut run_of = |model: &Model, time_scale: f64| -> Result<report::PathRun> {
        let mut x = Vec::new();
        let mut mechanisms = Vec::new();
        for (column, (label, variant)) in m.labels.iter().enumerate() {
            let series = counterpoise_dynamics::path_series(
                model,
                &m.params,
                column,
                index,
                PATH_SAMPLES_PER_SEGMENT,
            )?;
            if x.is_empty() {
                x = series.t.iter().map(|t| t / time_scale).collect();
                if configurations.is_empty() {
                    configurations = series.q.clone();
                }
            }
            let torques = (0..actuators.len())
                .map(|k| series.motor_torque.iter().map(|row| row[k]).collect())
                .collect();
            mechanisms.push(report::PathMechanism {
                label: label.clone(),
                variant: *variant,
                torques,
            });
        }
        Ok(report::PathRun {
            x_label: "time".into(),
            x_unit: "s".into(),
            x,
            mechanisms,
        })
    };
    let dynamic_run = run_of(model, 1.0)?;
    let mut slow = model.clone();
    for d in &mut slow.paths[index].durations {
        *d *= STATIC_STRETCH;
    }
    let static_run = run_of(&slow, STATIC_STRETCH)?;
    let name = |k: usize| spec.waypoints[spec.sequence[k]].name.clone();
    let waypoints = (0..spec.sequence.len())
        .map(name)
        .collect::<Vec<_>>()
        .join("-");
    let payload = spec
        .payload
        .as_ref()
        .map(|p| {
            format!(
                ", {} kg payload picked at {} and dropped at {}",
                p.mass,
                name(p.pick_at),
                name(p.drop_at)
            )
        })
        .unwrap_or_default();
    let simulation = report::PathSimulation {
        name: spec.name.clone(),
        description: Some(format!(
            "{waypoints} in {:.2} s{payload}; static torques from the same path traversed \
             {STATIC_STRETCH:e} times slower",
            spec.durations.iter().sum::<f64>()
        )),
        actuators,
        static_run: Some(static_run),
        dynamic_run: Some(dynamic_run),
        table: Vec::new(),
    };
    Ok((simulation, configurations))
}

/// Configurations at every task-grid point (where each task starts and ends), solved as the
/// dynamics solves them; points whose kinematics fail are left out (they are excluded tasks).
fn grid_configurations(model: &Model) -> Result<Vec<Vec<f64>>> {
    let Some(spec) = &model.tasks else {
        return Ok(Vec::new());
    };
    let ev = counterpoise_dynamics::Evaluator::new(model)?;
    Ok(spec
        .grid_points()
        .iter()
        .filter_map(|u| ev.solve_point(u).ok())
        .collect())
}

/// Length of a spring (the distance of its anchors, world frame) at configuration `q`.
fn spring_length(
    model: &Model,
    kinematics: &counterpoise_model::Kinematics,
    s: &report::Spring,
    q: &nalgebra::DVector<f64>,
) -> Option<f64> {
    let point = |body: &str, anchor: [f64; 3]| -> Option<nalgebra::Vector3<f64>> {
        let a = nalgebra::Vector3::from(anchor);
        if body == "base" {
            return Some(a);
        }
        let pose = kinematics.body_pose(model.body_index(body)?, q);
        Some(pose.position + pose.rotation * a)
    };
    Some((point(&s.body, s.anchor_a)? - point(&s.other, s.anchor_b)?).norm())
}

/// The practical figures of every feasible variant (added mass, elements, peak offset, peak
/// spring force and stretch). The spring peaks are the largest anchor distances over the
/// task-grid points and the samples of the path simulation: the configurations the mechanism
/// rests in and the one cycle simulated in full. A move between two grid points can pass
/// through a longer stretch; that is the documented limit of the figure.
pub fn add_practical_figures(
    model: &Model,
    results: &mut RunResults,
    path_configurations: Vec<Vec<f64>>,
) -> Result<()> {
    let grid = grid_configurations(model)?;
    let (grid_n, path_n) = (grid.len(), path_configurations.len());
    let configurations: Vec<nalgebra::DVector<f64>> = grid
        .into_iter()
        .chain(path_configurations)
        .map(nalgebra::DVector::from_vec)
        .collect();
    let kinematics = counterpoise_model::Kinematics::new(model);
    let moving_mass = results.moving_mass;
    for v in results.variants.iter_mut() {
        if v.status != Status::Feasible {
            continue;
        }
        let Some(p) = &v.parameters else { continue };
        let peaks = p
            .springs
            .iter()
            .map(|s| {
                report::SpringPeak::from_lengths(
                    &s.label,
                    s.stiffness,
                    configurations
                        .iter()
                        .filter_map(|q| spring_length(model, &kinematics, s, q)),
                )
            })
            .collect();
        v.practical = Some(report::PracticalFigures::new(p, moving_mass, peaks));
    }
    results.spring_peaks_basis = Some(if path_n > 0 {
        format!(
            "the largest over the {grid_n} task-grid points (where every task starts and ends) \
             and the {path_n} samples of the path simulation"
        )
    } else {
        format!("the largest over the {grid_n} task-grid points (where every task starts and ends)")
    });
    Ok(())
}

/// Torque curves (paper Fig. 10-style) of the unbalanced robot and the shown variants (the
/// best-ranked and the recommended of each class), on the critical RMS and peak tasks of each
/// of them.
pub fn add_torque_charts(model: &Model, results: &mut RunResults, m: &Mechanisms) -> Result<()> {
    let (params, labels) = (&m.params, &m.labels);
    let columns = labels.len();
    let critical = results.critical_tasks();
    let mut cache: Vec<([usize; 2], Vec<counterpoise_dynamics::Series>)> = Vec::new();
    let mut charts = Vec::new();
    for c in critical {
        if !cache.iter().any(|(t, _)| *t == c.task) {
            let series = (0..columns)
                .map(|col| task_series_with(model, params, col, c.task[0], c.task[1], None))
                .collect::<Result<Vec<_>, _>>()?;
            cache.push((c.task, series));
        }
        let series = &cache.iter().find(|(t, _)| *t == c.task).expect("cached").1;
        charts.push(report::TorqueChart {
            actuator: c.actuator_name.clone(),
            task: c.task,
            critical_for: c.critical_for.clone(),
            t: series[0].t.clone(),
            curves: series
                .iter()
                .zip(labels)
                .map(|(s, (label, variant))| report::Curve {
                    label: label.clone(),
                    variant: *variant,
                    values: s.motor_torque.iter().map(|row| row[c.actuator]).collect(),
                })
                .collect(),
        });
    }
    results.torque_charts = charts;
    Ok(())
}
