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

/// Per-task statistics of many columns in one flat table: for task `w` and column `c`,
/// `[rms (na), peak (na), total_peak, force_peak (nj), moment_peak (nj)]`.
#[derive(Clone, Debug, PartialEq)]
pub struct StatsTable {
    pub tasks: usize,
    pub columns: usize,
    pub actuators: usize,
    /// Joints with reaction statistics (0 without reactions).
    pub joints: usize,
    /// Whether each task ran (false: excluded).
    pub ok: Vec<bool>,
    data: Vec<f64>,
}

impl StatsTable {
    pub fn new(tasks: usize, columns: usize, actuators: usize, joints: usize) -> StatsTable {
        let width = 2 * actuators + 1 + 2 * joints;
        StatsTable {
            tasks,
            columns,
            actuators,
            joints,
            ok: vec![false; tasks],
            data: vec![0.0; tasks * columns * width],
        }
    }

    /// Values per task and column.
    pub fn width(&self) -> usize {
        2 * self.actuators + 1 + 2 * self.joints
    }

    /// The raw row of task `w`, column `c` (`None` for an excluded task).
    pub fn row(&self, w: usize, c: usize) -> Option<&[f64]> {
        let width = self.width();
        let off = (w * self.columns + c) * width;
        self.ok[w].then(|| &self.data[off..off + width])
    }

    /// Statistics of task `w`, column `c` (`None` for an excluded task).
    pub fn get(&self, w: usize, c: usize) -> Option<TaskStats> {
        let r = self.row(w, c)?;
        let (na, nj) = (self.actuators, self.joints);
        Some(TaskStats {
            rms: r[..na].to_vec(),
            peak: r[na..2 * na].to_vec(),
            total_peak: r[2 * na],
            force_peak: r[2 * na + 1..2 * na + 1 + nj].to_vec(),
            moment_peak: r[2 * na + 1 + nj..].to_vec(),
        })
    }

    /// Stores the statistics of task `w` (one per column) and marks it as run.
    pub fn set(&mut self, w: usize, stats: &[TaskStats]) {
        let width = self.width();
        let (na, nj) = (self.actuators, self.joints);
        for (c, s) in stats.iter().enumerate() {
            let off = (w * self.columns + c) * width;
            let r = &mut self.data[off..off + width];
            r[..na].copy_from_slice(&s.rms[..na]);
            r[na..2 * na].copy_from_slice(&s.peak[..na]);
            r[2 * na] = s.total_peak;
            if nj > 0 {
                r[2 * na + 1..2 * na + 1 + nj].copy_from_slice(&s.force_peak[..nj]);
                r[2 * na + 1 + nj..].copy_from_slice(&s.moment_peak[..nj]);
            }
        }
        self.ok[w] = true;
    }

    /// Stores task `w`'s rows (all columns, `columns × width` values in row layout) and marks
    /// it as run.
    pub fn set_rows(&mut self, w: usize, rows: &[f64]) {
        let n = self.columns * self.width();
        self.data[w * n..(w + 1) * n].copy_from_slice(rows);
        self.ok[w] = true;
    }

    /// Copies task `from`'s rows to task `to`.
    pub fn copy_task(&mut self, from: usize, to: usize) {
        let n = self.columns * self.width();
        self.data.copy_within(from * n..(from + 1) * n, to * n);
        self.ok[to] = self.ok[from];
    }
}

/// Reduces column `c` of the table (tasks in index order, excluded ones skipped) to
/// indicators. `pair(w)` gives the grid indices of task `w`.
pub fn reduce(
    table: &StatsTable,
    c: usize,
    actuator_names: &[String],
    joint_names: &[String],
    pair: impl Fn(usize) -> (usize, usize),
) -> Indicators {
    let na = table.actuators;
    let nj = table.joints;
    let mut qtr = (0.0, 0usize);
    let mut qit = (0.0, 0usize);
    let mut crt = vec![(0.0, 0usize); na];
    let mut cpt = vec![(0.0, 0usize); na];
    let mut fj = vec![(0.0, 0usize); nj];
    let mut mj = vec![(0.0, 0usize); nj];
    let mut first = true;
    for w in 0..table.tasks {
        let Some(r) = table.row(w, c) else { continue };
        let better = |cur: &(f64, usize), v: f64| first || v > cur.0;
        let total: f64 = r[..na].iter().sum();
        if better(&qtr, total) {
            qtr = (total, w);
        }
        if better(&qit, r[2 * na]) {
            qit = (r[2 * na], w);
        }
        for a in 0..na {
            if better(&crt[a], r[a]) {
                crt[a] = (r[a], w);
            }
            if better(&cpt[a], r[na + a]) {
                cpt[a] = (r[na + a], w);
            }
        }
        for j in 0..nj {
            let (f, m) = (r[2 * na + 1 + j], r[2 * na + 1 + nj + j]);
            if better(&fj[j], f) {
                fj[j] = (f, w);
            }
            if better(&mj[j], m) {
                mj[j] = (m, w);
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
        joints: (0..nj)
            .map(|j| JointIndicators {
                name: joint_names[j].clone(),
                force: fj[j].0,
                force_task: idx(fj[j].1),
                moment: mj[j].0,
                moment_task: idx(mj[j].1),
            })
            .collect(),
    }
}

/// The running maxima of [`reduce`] for many columns at once, fed task by task in *any* order:
/// a value replaces the current one when it is larger, or equal and from a lower task index,
/// so the result is the one [`reduce`] gives on the full table (ties to the lowest task)
/// whatever order or split the tasks arrive in. It lets a grid evaluation keep a few values per
/// column instead of a table of every task and column.
#[derive(Clone, Debug, PartialEq)]
pub struct IndicatorAccumulator {
    pub columns: usize,
    pub actuators: usize,
    pub joints: usize,
    /// Per column: QTR, QIT, CRT (na), CPT (na), F_j (nj), M_j (nj) as `(value, task)`.
    best: Vec<(f64, usize)>,
}

impl IndicatorAccumulator {
    pub fn new(columns: usize, actuators: usize, joints: usize) -> IndicatorAccumulator {
        let slots = 2 + 2 * actuators + 2 * joints;
        IndicatorAccumulator {
            columns,
            actuators,
            joints,
            best: vec![(f64::NEG_INFINITY, usize::MAX); columns * slots],
        }
    }

    fn slots(&self) -> usize {
        2 + 2 * self.actuators + 2 * self.joints
    }

    fn offer(slot: &mut (f64, usize), v: f64, w: usize) {
        if v > slot.0 || (v == slot.0 && w < slot.1) {
            *slot = (v, w);
        }
    }

    /// Adds task `w`'s rows: every column's row in the layout of [`StatsTable`], one after
    /// the other.
    pub fn add_rows(&mut self, w: usize, rows: &[f64]) {
        let (na, nj) = (self.actuators, self.joints);
        let width = 2 * na + 1 + 2 * nj;
        let slots = self.slots();
        for (best, r) in self
            .best
            .chunks_exact_mut(slots)
            .zip(rows.chunks_exact(width))
        {
            let total: f64 = r[..na].iter().sum();
            Self::offer(&mut best[0], total, w);
            Self::offer(&mut best[1], r[2 * na], w);
            for a in 0..na {
                Self::offer(&mut best[2 + a], r[a], w);
                Self::offer(&mut best[2 + na + a], r[na + a], w);
            }
            for j in 0..2 * nj {
                Self::offer(&mut best[2 + 2 * na + j], r[2 * na + 1 + j], w);
            }
        }
    }

    /// Per joint reaction row and column (`[force/moment][joint][column]`), the square of
    /// the peak reached so far less a relative margin: a sub-task whose rows stay below it
    /// cannot change the maxima (0 where no task has run).
    pub(crate) fn reaction_floor(&self, margin: f64) -> Vec<f64> {
        let slots = self.slots();
        let rows = 2 * self.joints;
        let mut floor = vec![0.0; rows * self.columns];
        for (c, best) in self.best.chunks_exact(slots).enumerate() {
            for r in 0..rows {
                let v = best[2 + 2 * self.actuators + r].0;
                if v.is_finite() && v > 0.0 {
                    floor[r * self.columns + c] = v * v * (1.0 - margin);
                }
            }
        }
        floor
    }

    /// Combines the maxima of two disjoint sets of tasks.
    pub fn merge(mut self, other: &IndicatorAccumulator) -> IndicatorAccumulator {
        for (a, b) in self.best.iter_mut().zip(&other.best) {
            Self::offer(a, b.0, b.1);
        }
        self
    }

    /// The indicators of every column (all zero at task 0 when no task ran, like [`reduce`]).
    pub fn finish(
        &self,
        actuator_names: &[String],
        joint_names: &[String],
        pair: impl Fn(usize) -> (usize, usize),
    ) -> Vec<Indicators> {
        let (na, nj) = (self.actuators, self.joints);
        let slots = self.slots();
        let get = |s: &(f64, usize)| {
            if s.1 == usize::MAX {
                let (i, j) = pair(0);
                (0.0, [i, j])
            } else {
                let (i, j) = pair(s.1);
                (s.0, [i, j])
            }
        };
        self.best
            .chunks_exact(slots)
            .map(|b| {
                let (qtr, qtr_task) = get(&b[0]);
                let (qit, qit_task) = get(&b[1]);
                Indicators {
                    qtr,
                    qtr_task,
                    qit,
                    qit_task,
                    actuators: (0..na)
                        .map(|a| {
                            let (crt_rms, crt) = get(&b[2 + a]);
                            let (cpt_peak, cpt) = get(&b[2 + na + a]);
                            ActuatorIndicators {
                                name: actuator_names[a].clone(),
                                crt,
                                crt_rms,
                                cpt,
                                cpt_peak,
                            }
                        })
                        .collect(),
                    joints: (0..nj)
                        .map(|j| {
                            let (force, force_task) = get(&b[2 + 2 * na + j]);
                            let (moment, moment_task) = get(&b[2 + 2 * na + nj + j]);
                            JointIndicators {
                                name: joint_names[j].clone(),
                                force,
                                force_task,
                                moment,
                                moment_task,
                            }
                        })
                        .collect(),
                }
            })
            .collect()
    }
}
