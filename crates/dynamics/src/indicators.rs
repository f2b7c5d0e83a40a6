//! Per-task statistics and the paper's indicators (Eqs. 1–3, Sec. 2.1).
//!
//! Per task `w` and actuator `n`: `RMS_n^w = sqrt(mean_t τ_n(t)²)` over the task's samples (both
//! ends included, equal weights) and `PK_n^w = max_t |τ_n(t)|`, `τ` the motor torque.
//!
//! - `QTR = max_w Σ_n RMS_n^w` (Eq. 1: the maximum over tasks of the *sum* over motors of the
//!   per-task RMS — "maximum total RMS").
//! - `QIT = max_{t,w} Σ_n |τ_n(t)|` (Eq. 2).
//! - `F_j = max_{t,w} |F_j(t)|`, `M_j = max_{t,w} |M_j(t)|` (Eq. 3).
//! - CRT of actuator `n`: the task with the largest `RMS_n^w`; CPT: the largest `PK_n^w`.
//!
//! Reductions run sequentially over tasks in index order with strict `>`, so ties go to the
//! lowest task index and the result does not depend on how the tasks were computed in
//! parallel.

use serde::{Deserialize, Serialize};

/// Statistics of one task for one parameter column.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TaskStats {
    pub rms: Vec<f64>,
    pub peak: Vec<f64>,
    /// `max_t Σ_n |τ_n(t)|`.
    pub total_peak: f64,
    /// Per joint, empty without reactions.
    pub force_peak: Vec<f64>,
    pub moment_peak: Vec<f64>,
}

/// Accumulates one task's samples.
#[derive(Clone, Debug, Default)]
pub struct StatsAccumulator {
    sum_sq: Vec<f64>,
    peak: Vec<f64>,
    total_peak: f64,
    force_peak: Vec<f64>,
    moment_peak: Vec<f64>,
    samples: usize,
}

impl StatsAccumulator {
    pub fn new(actuators: usize, joints: usize) -> Self {
        StatsAccumulator {
            sum_sq: vec![0.0; actuators],
            peak: vec![0.0; actuators],
            total_peak: 0.0,
            force_peak: vec![0.0; joints],
            moment_peak: vec![0.0; joints],
            samples: 0,
        }
    }

    pub fn add_torques(&mut self, torque: &[f64]) {
        let mut total = 0.0;
        for (a, &t) in torque.iter().enumerate().take(self.sum_sq.len()) {
            self.sum_sq[a] += t * t;
            self.peak[a] = self.peak[a].max(t.abs());
            total += t.abs();
        }
        self.total_peak = self.total_peak.max(total);
        self.samples += 1;
    }

    pub fn add_reactions(
        &mut self,
        force: impl Iterator<Item = f64>,
        moment: impl Iterator<Item = f64>,
    ) {
        for (p, f) in self.force_peak.iter_mut().zip(force) {
            *p = p.max(f);
        }
        for (p, m) in self.moment_peak.iter_mut().zip(moment) {
            *p = p.max(m);
        }
    }

    pub fn finish(&self, with_reactions: bool) -> TaskStats {
        let n = self.samples.max(1) as f64;
        TaskStats {
            rms: self.sum_sq.iter().map(|s| (s / n).sqrt()).collect(),
            peak: self.peak.clone(),
            total_peak: self.total_peak,
            force_peak: if with_reactions {
                self.force_peak.clone()
            } else {
                Vec::new()
            },
            moment_peak: if with_reactions {
                self.moment_peak.clone()
            } else {
                Vec::new()
            },
        }
    }
}

/// Indicators of one actuator.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ActuatorIndicators {
    pub name: String,
    /// Critical RMS task `[from, to]` (grid indices) and its RMS motor torque (N·m).
    pub crt: [usize; 2],
    pub crt_rms: f64,
    /// Critical peak task and its peak |motor torque| (N·m).
    pub cpt: [usize; 2],
    pub cpt_peak: f64,
}

/// Peak reactions of one joint (Eq. 3).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct JointIndicators {
    pub name: String,
    /// `F_j`, N, and the task where it occurs.
    pub force: f64,
    pub force_task: [usize; 2],
    /// `M_j`, N·m (about the joint point), and its task.
    pub moment: f64,
    pub moment_task: [usize; 2],
}

/// The indicators of one parameter vector over all tasks that ran.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Indicators {
    /// Eq. 1, N·m.
    pub qtr: f64,
    pub qtr_task: [usize; 2],
    /// Eq. 2, N·m.
    pub qit: f64,
    pub qit_task: [usize; 2],
    pub actuators: Vec<ActuatorIndicators>,
    /// Empty when reactions were not computed.
    pub joints: Vec<JointIndicators>,
}

/// Reduces per-task statistics (in task order; `None` = excluded) to indicators.
/// `pair(w)` gives the grid indices of task `w`.
pub fn reduce(
    stats: &[Option<&TaskStats>],
    actuator_names: &[String],
    joint_names: &[String],
    pair: impl Fn(usize) -> (usize, usize),
) -> Indicators {
    let na = actuator_names.len();
    let nj = joint_names.len();
    let mut qtr = (0.0, 0usize);
    let mut qit = (0.0, 0usize);
    let mut crt = vec![(0.0, 0usize); na];
    let mut cpt = vec![(0.0, 0usize); na];
    let mut fj = vec![(0.0, 0usize); nj];
    let mut mj = vec![(0.0, 0usize); nj];
    let mut any_reactions = false;
    let mut first = true;
    for (w, s) in stats.iter().enumerate() {
        let Some(s) = s else { continue };
        let better = |cur: &(f64, usize), v: f64| first || v > cur.0;
        let total: f64 = s.rms.iter().sum();
        if better(&qtr, total) {
            qtr = (total, w);
        }
        if better(&qit, s.total_peak) {
            qit = (s.total_peak, w);
        }
        for a in 0..na {
            if better(&crt[a], s.rms[a]) {
                crt[a] = (s.rms[a], w);
            }
            if better(&cpt[a], s.peak[a]) {
                cpt[a] = (s.peak[a], w);
            }
        }
        if !s.force_peak.is_empty() {
            any_reactions = true;
            for j in 0..nj {
                if better(&fj[j], s.force_peak[j]) {
                    fj[j] = (s.force_peak[j], w);
                }
                if better(&mj[j], s.moment_peak[j]) {
                    mj[j] = (s.moment_peak[j], w);
                }
            }
        }
        first = false;
    }
    let idx = |w: usize| {
        let (i, j) = pair(w);
        [i, j]
    };
    Indicators {
        qtr: qtr.0,
        qtr_task: idx(qtr.1),
        qit: qit.0,
        qit_task: idx(qit.1),
        actuators: (0..na)
            .map(|a| ActuatorIndicators {
                name: actuator_names[a].clone(),
                crt: idx(crt[a].1),
                crt_rms: crt[a].0,
                cpt: idx(cpt[a].1),
                cpt_peak: cpt[a].0,
            })
            .collect(),
        joints: if any_reactions {
            (0..nj)
                .map(|j| JointIndicators {
                    name: joint_names[j].clone(),
                    force: fj[j].0,
                    force_task: idx(fj[j].1),
                    moment: mj[j].0,
                    moment_task: idx(mj[j].1),
                })
                .collect()
        } else {
            Vec::new()
        },
    }
}
