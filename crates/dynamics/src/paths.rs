//! Explicit paths: a sequence of waypoints in actuator space, one quintic rest-to-rest move
//! per segment, and optionally a payload picked at one waypoint and dropped at a later one
//! (the paper's path Λ, Sec. 3.3).
//!
//! While carried, the payload's mass, first moment and inertia are part of its carrier body's
//! parameters (a second parameter column), so the torques and reactions of a carried segment
//! include it. A segment's samples are `samples_per_segment` equally spaced times including its
//! start; its end is the next segment's start (the final waypoint is sampled once, at the end).
//! The payload is on board from the sample at the pick waypoint up to, not including, the
//! sample at the drop waypoint.

use counterpoise_model::Model;
use serde::{Deserialize, Serialize};

use crate::error::DynamicsError;
use crate::evaluate::JointSeries;
use crate::indicators::{StatsAccumulator, TaskStats};
use crate::params::{BODY_PARAMS, ParameterSet, body_params};
use crate::runner::{Evaluator, Workspace};

/// The time series of a path and its statistics.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PathSeries {
    pub name: String,
    pub t: Vec<f64>,
    pub u: Vec<Vec<f64>>,
    pub q: Vec<Vec<f64>>,
    /// Generalized force per actuated coordinate (N·m or N), before the ratio.
    pub actuator_force: Vec<Vec<f64>>,
    /// Motor torque per actuator, N·m.
    pub motor_torque: Vec<Vec<f64>>,
    pub joints: Vec<JointSeries>,
    /// Whether the payload is on board at each sample.
    pub carried: Vec<bool>,
    /// RMS and peak motor torques over the whole path, peak reactions.
    #[serde(skip)]
    pub stats: TaskStats,
    pub rms: Vec<f64>,
    pub peak: Vec<f64>,
}

/// Runs path `path` of the model for column `column` of `params`.
pub fn path_series(
    model: &Model,
    params: &ParameterSet,
    column: usize,
    path: usize,
    samples_per_segment: usize,
) -> Result<PathSeries, DynamicsError> {
    let spec = model
        .paths
        .get(path)
        .ok_or_else(|| DynamicsError::BadPath {
            path: format!("#{path}"),
            reason: "no such path".into(),
        })?;
    let bad = |reason: String| DynamicsError::BadPath {
        path: spec.name.clone(),
        reason,
    };
    if samples_per_segment < 2 {
        return Err(bad("at least 2 samples per segment".into()));
    }
    if spec.sequence.len() < 2 || spec.durations.len() + 1 != spec.sequence.len() {
        return Err(bad(format!(
            "{} waypoints in the sequence need {} durations, got {}",
            spec.sequence.len(),
            spec.sequence.len().saturating_sub(1),
            spec.durations.len()
        )));
    }
    // column 0: as given; column 1: with the payload on its body
    let mut set = ParameterSet::empty(params.bodies, params.springs.clone());
    set.push_column(params.column(column))?;
    let mut carried = params.column(column).to_vec();
    if let Some(p) = &spec.payload {
        let add = body_params(p.mass, &p.com, &p.inertia_com);
        for (x, y) in carried[BODY_PARAMS * p.body..].iter_mut().zip(add) {
            *x += y;
        }
    }
    set.push_column(&carried)?;
    let ev = Evaluator::new(model)?;
    let n = ev.mech.n;
    let first = &spec.waypoints[spec.sequence[0]].u;
    let mut q = ev.solve_point(first).map_err(DynamicsError::TaskFailed)?;
    let mut out = PathSeries {
        name: spec.name.clone(),
        t: Vec::new(),
        u: Vec::new(),
        q: Vec::new(),
        actuator_force: Vec::new(),
        motor_torque: Vec::new(),
        joints: JointSeries::for_joints(&ev),
        carried: Vec::new(),
        stats: TaskStats::default(),
        rms: Vec::new(),
        peak: Vec::new(),
    };
    let mut acc = StatsAccumulator::new(n, ev.reactions.joint_count());
    let mut ws = Workspace::default();
    let mut t0 = 0.0;
    let segments = spec.durations.len();
    for (k, &duration) in spec.durations.iter().enumerate() {
        let on = spec
            .payload
            .as_ref()
            .is_some_and(|p| p.pick_at <= k && k < p.drop_at);
        let ua = &spec.waypoints[spec.sequence[k]].u;
        let ub = &spec.waypoints[spec.sequence[k + 1]].u;
        let last = k + 1 == segments;
        let column = [usize::from(on)];
        ev.run_move(
            ua,
            ub,
            duration,
            samples_per_segment,
            &mut q,
            &set,
            &column,
            true,
            &mut ws,
            |s, view| {
                if s + 1 == samples_per_segment && !last {
                    return;
                }
                out.t.push(t0 + view.t);
                out.u.push(view.u.clone());
                out.q.push(view.q.clone());
                out.actuator_force
                    .push(view.actuator_force[0][..n].to_vec());
                out.motor_torque.push(view.motor_torque[0][..n].to_vec());
                out.carried.push(on);
                let r = &view.reactions[0];
                JointSeries::record(&mut out.joints, r);
                acc.add_torques(&view.motor_torque[0][..n]);
                acc.add_reactions(r.force_magnitudes(), r.moment_magnitudes());
            },
        )
        .map_err(|(_, reason)| DynamicsError::TaskFailed(reason))?;
        t0 += duration;
    }
    out.stats = acc.finish(true);
    out.rms = out.stats.rms.clone();
    out.peak = out.stats.peak.clone();
    Ok(out)
}
