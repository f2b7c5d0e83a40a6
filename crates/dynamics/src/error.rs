//! Errors: set-up problems that stop an evaluation, and task failures that only exclude a task.
//!
//! A task that cannot be run (its target leaves the reachable set, its actuator Jacobian turns
//! singular, or Newton lands outside the coordinate ranges) is not an error of the evaluation:
//! it is recorded as a [`TaskFailure`], excluded from the indicators and counted in the report.

use serde::{Deserialize, Serialize};

/// Why the kinematics of one sample could not be computed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, thiserror::Error)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum FailureReason {
    /// Newton on `f(q) = u` did not converge (typically an unreachable target).
    #[error("Newton did not converge (residual {residual:.3e})")]
    NotConverged { residual: f64 },
    /// The actuator Jacobian `G = ∂f/∂q` is singular (pivot ratio below the threshold).
    #[error("singular actuator Jacobian (pivot ratio {pivot_ratio:.3e})")]
    Singular { pivot_ratio: f64 },
    /// The solution left the range of a chart coordinate (another assembly branch).
    #[error("coordinate `{coordinate}` = {value} outside its range [{}, {}]", range[0], range[1])]
    OutOfRange {
        coordinate: String,
        value: f64,
        range: [f64; 2],
    },
    /// A computed quantity was not finite.
    #[error("non-finite value in the dynamics")]
    NonFinite,
}

impl FailureReason {
    /// Short stable name used to count failures by kind.
    pub fn kind(&self) -> &'static str {
        match self {
            FailureReason::NotConverged { .. } => "not_converged",
            FailureReason::Singular { .. } => "singular",
            FailureReason::OutOfRange { .. } => "out_of_range",
            FailureReason::NonFinite => "non_finite",
        }
    }
}

/// A task excluded from the indicators.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TaskFailure {
    /// Task index (see [`crate::tasks::TaskSet`]).
    pub task: usize,
    /// Sample index within the task where it failed.
    pub sample: usize,
    pub reason: FailureReason,
}

/// Problems that prevent an evaluation from starting.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum DynamicsError {
    #[error(
        "the model has {actuators} actuators but {coordinates} chart coordinates; the actuator map must be square"
    )]
    NotSquare {
        actuators: usize,
        coordinates: usize,
    },
    #[error("the case defines no task grid")]
    NoTasks,
    #[error("task grid: {0}")]
    BadGrid(String),
    #[error("task {i}→{j} does not exist: the grid has {points} points (indices 0 to {last})", last = points.saturating_sub(1))]
    NoSuchTask { i: usize, j: usize, points: usize },
    #[error("task {i}→{i} is a zero-length move: a task goes from one grid point to another")]
    ZeroLengthTask { i: usize },
    #[error("parameter set: {0}")]
    BadParameters(String),
    #[error("path `{path}`: {reason}")]
    BadPath { path: String, reason: String },
    #[error("task failed: {0}")]
    TaskFailed(FailureReason),
}
