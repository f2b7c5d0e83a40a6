//! Inverse dynamics of counterpoise mechanisms over task grids: motor torques, joint
//! reactions and the paper's indicators QTR, QIT, F_j, M_j (Martini et al. 2019, Eqs. 1–4).
//!
//! Everything is linear in lifted inertial parameters ([`params`]): the kinematics and the
//! regressor of a sample are computed once and shared by every parameter vector evaluated
//! with it ([`runner`]). Entry points: [`evaluate()`] (the `evaluate` command),
//! [`task_series`] (one task's time series), [`evaluate_grid`] (many parameter vectors).

// Index loops over small fixed-size numeric arrays read like the formulas they implement, and
// the hot-loop entry points take their buffers explicitly rather than bundled.
#![allow(clippy::needless_range_loop, clippy::too_many_arguments)]

mod coefficient_sweeps;
pub mod compiled;
pub mod error;
pub mod evaluate;
pub mod evaluate_options;
pub mod fast;
pub mod indicators;
pub mod kernel;
pub mod law;
pub mod linalg;
pub mod lu;
pub mod mechanism;
pub mod params;
pub mod paths;
pub mod progress;
mod reaction_kernels;
pub mod reactions;
pub mod regressor;
pub mod runner;
mod simd;
mod superposition;
pub mod symmetry;
pub mod tasks;

pub use error::{DynamicsError, FailureReason, TaskFailure};
pub use evaluate::{
    Combination, EvaluateOptions, EvaluationReport, Excluded, GridEvaluation, GridIndicators,
    JointSeries, Series, evaluate, evaluate_grid, evaluate_grid_indicators,
    evaluate_grid_indicators_reporting, evaluate_grid_indicators_with, evaluate_unbalanced_grid,
    task_series, task_series_with,
};
pub use indicators::{ActuatorIndicators, Indicators, JointIndicators, TaskStats};
pub use params::{Counterweight, ParameterSet, Spring, SpringSlot, Variant};
pub use paths::{PathSeries, path_series};
pub use progress::GridProgress;
pub use runner::Evaluator;
pub use tasks::TaskSet;
