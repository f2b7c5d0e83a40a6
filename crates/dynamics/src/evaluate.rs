//! The `evaluate` command logic: the indicators of the unbalanced mechanism (or of any
//! parameter vectors) over the task grid, and the time series of one task.
//!
//! # Output fields
//!
//! [`EvaluationReport`] (JSON):
//! - `case`: case name; `points`: grid points; `tasks`: tasks in the set; `samples`: samples
//!   per task (both ends included); `duration`: seconds per task; `pairs`: `"all"` (unordered,
//!   one direction per pair — the reverse has the same RMS and peaks) or `"ordered"`.
//! - `evaluated`: tasks that ran; `excluded`: `{count, by_reason: {kind: count}, examples: [{task,
//!   sample, reason}]}` — tasks whose kinematics failed (unreachable: `not_converged`; singular
//!   actuator Jacobian: `singular`; another assembly branch: `out_of_range`), left out of every
//!   indicator.
//! - `qtr` (N·m, Eq. 1: max over tasks of the sum over actuators of the task's RMS motor
//!   torque) and `qtr_task` (`[from, to]` grid indices); `qit` (N·m, Eq. 2: max over tasks and
//!   samples of the sum of |motor torque|) and `qit_task`.
//! - `actuators[]`: `name`, `crt` (critical RMS task `[from, to]`), `crt_rms` (N·m), `cpt`
//!   (critical peak task), `cpt_peak` (N·m).
//! - `joints[]` (when reactions are computed): `name`, `force` (`F_j`, N), `force_task`,
//!   `moment` (`M_j`, N·m about the joint point), `moment_task`.
//! - `reactions_minimum_norm`: true when the mechanism is overconstrained and the reactions are
//!   the minimum-norm solution (then `F_j`, `M_j` are one admissible distribution, not the
//!   unique one).
//! - `cyclic_coordinate`: the chart coordinate found cyclic (a rotation of the whole mechanism
//!   about a gravity-parallel axis, e.g. the palletizer's `th1`) and factored out of the task
//!   loop, or `null`. Tasks that differ only by such a rotation have identical indicators; the
//!   critical task reported is then the lowest-indexed of them.
//!
//! Grid indices count grid points with the first actuator varying slowest, each actuator's
//! values running from `from` to `to`.
//!
//! Torques and reactions are those of rigid bodies without friction; RMS values are over the
//! task's samples with equal weights (both ends included).
//!
//! [`Series`] (JSON, one task): `task` `[from, to]`, `t` (s), `u[k][a]` (actuated coordinates),
//! `q[k][c]` (chart coordinates), `actuator_force[k][a]` (generalized force along actuated
//! coordinate `a`, N·m or N, before the ratio), `motor_torque[k][a]` (N·m), `joints[]` with
//! `name`, `force[k]` (N) and `moment[k]` (N·m) magnitudes, `reactions_minimum_norm`.
//!
//! Paths (waypoint sequences with a payload, [`crate::paths::path_series`]) give a
//! [`crate::paths::PathSeries`] with the same fields plus `carried[k]`, and `rms`, `peak` per
//! actuator over the whole path.

use std::collections::BTreeMap;

use counterpoise_model::{Model, PairMode};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::{DynamicsError, TaskFailure};
use crate::indicators::{IndicatorAccumulator, Indicators, StatsTable, TaskStats, reduce};
use crate::params::ParameterSet;
use crate::progress::{GridProgress, Ticker, silent};
use crate::reactions::JointReactions;
use crate::runner::{Evaluator, Workspace};
use crate::tasks::TaskSet;

pub use crate::evaluate_options::{Combination, EvaluateOptions};

/// Tasks left out of the indicators.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Excluded {
    pub count: usize,
    pub by_reason: BTreeMap<String, usize>,
    /// The first few failures (lowest task index first).
    pub examples: Vec<TaskFailure>,
}

/// Most failures listed in [`Excluded::examples`].
pub const MAX_FAILURE_EXAMPLES: usize = 20;

/// The result of [`evaluate`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EvaluationReport {
    pub case: String,
    pub points: usize,
    pub tasks: usize,
    pub samples: usize,
    pub duration: f64,
    pub pairs: String,
    pub evaluated: usize,
    pub excluded: Excluded,
    pub reactions_minimum_norm: bool,
    /// Chart coordinate found cyclic and factored out of the task loop (`null` if none).
    pub cyclic_coordinate: Option<String>,
    #[serde(flatten)]
    pub indicators: Indicators,
}

/// Indicators of many parameter columns over the same tasks.
#[derive(Clone, Debug, PartialEq)]
pub struct GridEvaluation {
    pub tasks: TaskSet,
    /// One per column.
    pub indicators: Vec<Indicators>,
    /// Per task and column statistics (see [`GridEvaluation::stats`]).
    pub table: StatsTable,
    pub excluded: Excluded,
    pub reactions_minimum_norm: bool,
    /// The cyclic coordinate whose value was factored out, if the shortcut was used.
    pub cyclic_coordinate: Option<String>,
    /// Distinct moves actually computed (tasks that differ only by a rotation about the
    /// cyclic axis share one computation).
    pub distinct_moves: usize,
}

impl GridEvaluation {
    /// Statistics of task `w` for column `c` (`None` when the task was excluded).
    pub fn stats(&self, w: usize, c: usize) -> Option<TaskStats> {
        self.table.get(w, c)
    }
}

fn excluded_from(failures: &[TaskFailure]) -> Excluded {
    let mut by_reason = BTreeMap::new();
    for f in failures {
        *by_reason.entry(f.reason.kind().to_string()).or_insert(0) += 1;
    }
    Excluded {
        count: failures.len(),
        by_reason,
        examples: failures
            .iter()
            .take(MAX_FAILURE_EXAMPLES)
            .cloned()
            .collect(),
    }
}

/// What both grid evaluations start from: the task set, the evaluator, and the cyclic coordinate
/// when the shortcut applies (it needs every spring between two bodies).
fn grid_setup<'m>(
    model: &'m Model,
    params: &ParameterSet,
    options: &EvaluateOptions,
) -> Result<(TaskSet, Evaluator<'m>, Option<crate::symmetry::Cyclic>), DynamicsError> {
    let tasks = TaskSet::new(
        model.tasks.as_ref().ok_or(DynamicsError::NoTasks)?,
        options.samples,
    )?;
    let ev = Evaluator::new(model)?;
    let cyclic = if options.shortcut && params.springs.iter().all(|s| s.other.is_some()) {
        crate::symmetry::detect_cyclic(model, &ev.mech)
    } else {
        None
    };
    Ok((tasks, ev, cyclic))
}

/// Runs every grid task for every column of `params` (in parallel over tasks on the current
/// rayon pool; results are identical for any thread count).
pub fn evaluate_grid(
    model: &Model,
    params: &ParameterSet,
    options: &EvaluateOptions,
) -> Result<GridEvaluation, DynamicsError> {
    evaluate_grid_reporting(model, params, options, Combination::Direct, &silent)
}

/// [`evaluate_grid`] of the model's own parameters (the unbalanced robot, Phase 1), its
/// reactions by substitution ([`Combination::Substitution`]: a one-column batch does not pay
/// for the reaction operator). Every grid evaluation of the unbalanced robot goes through
/// here (`evaluate`, a study's Phase 1 and its reach check, a context built without Phase 1's
/// figures), so the unbalanced figures are the same bits in all of them.
pub fn evaluate_unbalanced_grid(
    model: &Model,
    options: &EvaluateOptions,
) -> Result<GridEvaluation, DynamicsError> {
    let params = ParameterSet::unbalanced(model);
    evaluate_grid_reporting(model, &params, options, Combination::Substitution, &silent)
}

/// [`evaluate_grid`] with the columns combined as `combination` says, reporting the units of
/// work done to `progress`.
fn evaluate_grid_reporting(
    model: &Model,
    params: &ParameterSet,
    options: &EvaluateOptions,
    combination: Combination,
    progress: GridProgress,
) -> Result<GridEvaluation, DynamicsError> {
    let (tasks, ev, cyclic) = grid_setup(model, params, options)?;
    let joints = if options.reactions {
        ev.reactions.joint_count()
    } else {
        0
    };
    let mut table = StatsTable::new(tasks.len(), params.len(), ev.mech.n, joints);
    let (failures, distinct) = match cyclic {
        Some(cyc) => crate::fast::evaluate_cyclic(
            &ev,
            cyc,
            &tasks,
            params,
            options.reactions,
            combination,
            crate::fast::GridSink::Table(&mut table),
            progress,
        ),
        None => {
            let mut failures = Vec::new();
            for (w, r) in direct_tasks(&ev, &tasks, params, options.reactions, progress)
                .into_iter()
                .enumerate()
            {
                match r {
                    Ok(s) => table.set(w, &s),
                    Err(f) => failures.push(f),
                }
            }
            (failures, tasks.len())
        }
    };
    let names = ev.actuator_names();
    let joint_names = ev.joint_names();
    // Each column's reduction is sequential over tasks (deterministic ties); columns are
    // independent and run in parallel.
    let indicators = (0..params.len())
        .into_par_iter()
        .map(|c| reduce(&table, c, &names, &joint_names, |w| tasks.pair(w)))
        .collect();
    Ok(GridEvaluation {
        indicators,
        table,
        excluded: excluded_from(&failures),
        reactions_minimum_norm: options.reactions && ev.reactions.minimum_norm,
        cyclic_coordinate: cyclic.map(|c| model.coordinates[c.coordinate].name.clone()),
        distinct_moves: distinct,
        tasks,
    })
}

/// The indicators of many columns over the grid, without the per-task table.
#[derive(Clone, Debug, PartialEq)]
pub struct GridIndicators {
    /// One per column.
    pub indicators: Vec<Indicators>,
    pub excluded: Excluded,
    pub reactions_minimum_norm: bool,
    pub distinct_moves: usize,
}

/// [`evaluate_grid`]'s indicators, computed without keeping the statistics of every task and
/// column: with a cyclic coordinate each worker keeps running maxima per column (ties to the
/// lowest task, as [`reduce`]), so memory does not grow with tasks × columns. The indicators
/// are identical to [`evaluate_grid`]'s for any thread count.
pub fn evaluate_grid_indicators(
    model: &Model,
    params: &ParameterSet,
    options: &EvaluateOptions,
) -> Result<GridIndicators, DynamicsError> {
    evaluate_grid_indicators_with(model, params, options, Combination::Direct)
}

/// [`evaluate_grid_indicators`] with the columns combined as `combination` says (with the
/// cyclic shortcut; the direct path over every task has no superposition).
pub fn evaluate_grid_indicators_with(
    model: &Model,
    params: &ParameterSet,
    options: &EvaluateOptions,
    combination: Combination,
) -> Result<GridIndicators, DynamicsError> {
    evaluate_grid_indicators_reporting(model, params, options, combination, &silent)
}

/// [`evaluate_grid_indicators_with`] that reports the units of work done (sub-tasks of the
/// cyclic decomposition, or tasks) to `progress` as they end, for a progress line that moves
/// during one long batch; the indicators are the same bits.
pub fn evaluate_grid_indicators_reporting(
    model: &Model,
    params: &ParameterSet,
    options: &EvaluateOptions,
    combination: Combination,
    progress: GridProgress,
) -> Result<GridIndicators, DynamicsError> {
    let (tasks, ev, cyclic) = grid_setup(model, params, options)?;
    let Some(cyc) = cyclic else {
        let grid = evaluate_grid_reporting(model, params, options, combination, progress)?;
        return Ok(GridIndicators {
            indicators: grid.indicators,
            excluded: grid.excluded,
            reactions_minimum_norm: grid.reactions_minimum_norm,
            distinct_moves: grid.distinct_moves,
        });
    };
    let joints = if options.reactions {
        ev.reactions.joint_count()
    } else {
        0
    };
    let mut maxima = IndicatorAccumulator::new(params.len(), ev.mech.n, joints);
    let (failures, distinct) = crate::fast::evaluate_cyclic(
        &ev,
        cyc,
        &tasks,
        params,
        options.reactions,
        combination,
        crate::fast::GridSink::Maxima(&mut maxima),
        progress,
    );
    let indicators = maxima.finish(&ev.actuator_names(), &ev.joint_names(), |w| tasks.pair(w));
    Ok(GridIndicators {
        indicators,
        excluded: excluded_from(&failures),
        reactions_minimum_norm: options.reactions && ev.reactions.minimum_norm,
        distinct_moves: distinct,
    })
}

/// Every task run directly: Newton along the move, dynamics at every sample.
fn direct_tasks(
    ev: &Evaluator,
    tasks: &TaskSet,
    params: &ParameterSet,
    with_reactions: bool,
    progress: GridProgress,
) -> Vec<Result<Vec<TaskStats>, TaskFailure>> {
    let grid_q: Vec<_> = tasks.points.par_iter().map(|u| ev.solve_point(u)).collect();
    let ticker = Ticker::start(progress, tasks.len());
    (0..tasks.len())
        .into_par_iter()
        .map_init(Workspace::default, |ws, w| {
            let (i, j) = tasks.pair(w);
            let mut q = match &grid_q[i] {
                Ok(q) => q.clone(),
                Err(reason) => {
                    return Err(TaskFailure {
                        task: w,
                        sample: 0,
                        reason: reason.clone(),
                    });
                }
            };
            ev.move_stats(
                &tasks.points[i],
                &tasks.points[j],
                tasks.duration,
                tasks.samples,
                &mut q,
                params,
                with_reactions,
                ws,
            )
            .map_err(|(sample, reason)| TaskFailure {
                task: w,
                sample,
                reason,
            })
        })
        .inspect(|_| ticker.tick())
        .collect()
}

/// The unbalanced indicators of a model over its task grid.
pub fn evaluate(
    model: &Model,
    options: &EvaluateOptions,
) -> Result<EvaluationReport, DynamicsError> {
    let mut grid = evaluate_unbalanced_grid(model, options)?;
    let tasks = &grid.tasks;
    Ok(EvaluationReport {
        case: model.name.clone(),
        points: tasks.points.len(),
        tasks: tasks.len(),
        samples: tasks.samples,
        duration: tasks.duration,
        pairs: match tasks.mode {
            PairMode::All => "all",
            PairMode::Ordered => "ordered",
        }
        .to_string(),
        evaluated: tasks.len() - grid.excluded.count,
        excluded: grid.excluded.clone(),
        reactions_minimum_norm: grid.reactions_minimum_norm,
        cyclic_coordinate: grid.cyclic_coordinate.clone(),
        indicators: grid.indicators.swap_remove(0),
    })
}

/// Reaction magnitudes of one joint along a task.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct JointSeries {
    pub name: String,
    pub force: Vec<f64>,
    pub moment: Vec<f64>,
}

impl JointSeries {
    /// One empty series per joint of the evaluator's model.
    pub(crate) fn for_joints(ev: &Evaluator) -> Vec<JointSeries> {
        ev.joint_names()
            .into_iter()
            .map(|name| JointSeries {
                name,
                force: Vec::new(),
                moment: Vec::new(),
            })
            .collect()
    }

    /// Appends one sample's reaction magnitudes to every joint's series.
    pub(crate) fn record(series: &mut [JointSeries], reactions: &JointReactions) {
        for (js, (f, m)) in series.iter_mut().zip(
            reactions
                .force_magnitudes()
                .zip(reactions.moment_magnitudes()),
        ) {
            js.force.push(f);
            js.moment.push(m);
        }
    }
}

/// The time series of one task (see the module doc).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Series {
    pub task: [usize; 2],
    pub t: Vec<f64>,
    pub u: Vec<Vec<f64>>,
    pub q: Vec<Vec<f64>>,
    pub actuator_force: Vec<Vec<f64>>,
    pub motor_torque: Vec<Vec<f64>>,
    pub joints: Vec<JointSeries>,
    pub reactions_minimum_norm: bool,
}

/// The series of the move from grid point `i` to grid point `j` of the unbalanced model
/// (any two distinct points; the direction is as given). `samples` overrides the case's.
pub fn task_series(
    model: &Model,
    i: usize,
    j: usize,
    samples: Option<usize>,
) -> Result<Series, DynamicsError> {
    task_series_with(model, &ParameterSet::unbalanced(model), 0, i, j, samples)
}

/// Like [`task_series`] for column `column` of `params`.
pub fn task_series_with(
    model: &Model,
    params: &ParameterSet,
    column: usize,
    i: usize,
    j: usize,
    samples: Option<usize>,
) -> Result<Series, DynamicsError> {
    let spec = model.tasks.as_ref().ok_or(DynamicsError::NoTasks)?;
    let tasks = TaskSet::new(spec, samples)?;
    let points = tasks.points.len();
    if i >= points || j >= points {
        return Err(DynamicsError::NoSuchTask { i, j, points });
    }
    if i == j {
        return Err(DynamicsError::ZeroLengthTask { i });
    }
    let ev = Evaluator::new(model)?;
    let mut q = ev
        .solve_point(&tasks.points[i])
        .map_err(DynamicsError::TaskFailed)?;
    let n = ev.mech.n;
    let mut series = Series {
        task: [i, j],
        t: Vec::new(),
        u: Vec::new(),
        q: Vec::new(),
        actuator_force: Vec::new(),
        motor_torque: Vec::new(),
        joints: JointSeries::for_joints(&ev),
        reactions_minimum_norm: ev.reactions.minimum_norm,
    };
    let mut ws = Workspace::default();
    ev.run_move(
        &tasks.points[i],
        &tasks.points[j],
        tasks.duration,
        tasks.samples,
        &mut q,
        params,
        &[column],
        true,
        &mut ws,
        |_, view| {
            series.t.push(view.t);
            series.u.push(view.u.clone());
            series.q.push(view.q.clone());
            series
                .actuator_force
                .push(view.actuator_force[0][..n].to_vec());
            series.motor_torque.push(view.motor_torque[0][..n].to_vec());
            JointSeries::record(&mut series.joints, &view.reactions[0]);
        },
    )
    .map_err(|(_, reason)| DynamicsError::TaskFailed(reason))?;
    Ok(series)
}
