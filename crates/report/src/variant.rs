//! One variant as the results document records it: its status, its evaluation on the tasks,
//! the optimiser's account, and the Phase 3 fields (ΔQTR, ΔQIT, ΔR, ranks).
//!
//! The data only: what fills and ranks the records lives in `results`, `ranking` and
//! `decision`, which read these types.

use serde::{Deserialize, Serialize};

use crate::indicators::{DeltaR, JointReaction};
use crate::parameters::{ElementInfo, FreeDirection, PhysicalParameters};
use crate::practical::PracticalFigures;
use crate::ranking::Class;

/// A task: the move between two grid points, `[from, to]` (grid indices, as in the dynamics
/// crate).
pub type TaskRef = [usize; 2];

/// What became of a variant: the shared status, from the search's verdict to the study's.
pub use counterpoise_vocabulary::Status;

/// RMS and peak motor torque of one actuator on its critical tasks.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ActuatorSummary {
    pub name: String,
    /// Critical RMS task and its RMS motor torque, N·m.
    pub crt: TaskRef,
    pub crt_rms: f64,
    /// Critical peak task and its peak |motor torque|, N·m.
    pub cpt: TaskRef,
    pub cpt_peak: f64,
}

/// Peak joint reactions with the tasks where they occur (Eq. 3).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct JointPeak {
    pub name: String,
    /// `F_j`, N.
    pub force: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub force_task: Option<TaskRef>,
    /// `M_j`, N·m.
    pub moment: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub moment_task: Option<TaskRef>,
}

/// Indicators of one mechanism (the unbalanced robot or a variant) over all tasks (Eqs. 1–3).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Evaluation {
    /// Eq. 1, N·m, and the task where the maximum occurs.
    pub qtr: f64,
    pub qtr_task: TaskRef,
    /// Eq. 2, N·m.
    pub qit: f64,
    pub qit_task: TaskRef,
    pub actuators: Vec<ActuatorSummary>,
    /// Empty when joint reactions were not computed.
    pub joints: Vec<JointPeak>,
    /// Tasks evaluated and tasks excluded (e.g. singular configurations on the way).
    pub tasks: usize,
    pub excluded_tasks: usize,
    /// Joint reactions are minimum-norm (overconstrained mechanism).
    #[serde(default)]
    pub reactions_minimum_norm: bool,
}

impl Evaluation {
    pub(crate) fn reactions(&self) -> Vec<JointReaction> {
        self.joints
            .iter()
            .map(|j| JointReaction {
                name: j.name.clone(),
                force: j.force,
                moment: j.moment,
            })
            .collect()
    }
}

/// What the optimiser reports about a variant (all optional: not every optimiser has each).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct OptimiserInfo {
    /// Objective value (Eq. 11, N·m) at the returned parameters.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub objective: Option<f64>,
    /// Certified lower bound from the convex relaxation, N·m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lower_bound: Option<f64>,
    /// Relative gap between objective and lower bound.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gap: Option<f64>,
    /// Critical-task iterations (Proc-5…8).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub iterations: Option<usize>,
    /// Boxes the certified branch-and-bound solved (0: the local search's design was within
    /// the gap tolerance of the relaxation's bound).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub boxes: Option<usize>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub message: Option<String>,
}

/// Every variant examined.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct VariantRecord {
    /// Enumeration index (stable for a case and Dmax).
    pub id: usize,
    pub elements: Vec<ElementInfo>,
    pub class: Class,
    pub status: Status,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// Balance relations in readable form (balanced variants).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub relations: Vec<String>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub free_directions: Vec<FreeDirection>,
    /// Relative spread of the total potential energy at random configurations.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub verification_residual: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub parameters: Option<PhysicalParameters>,
    /// Re-evaluation over all tasks with the optimised parameters (feasible variants).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub evaluation: Option<Evaluation>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub optimiser: Option<OptimiserInfo>,
    /// Added mass, element count, peak spring force and stretch, peak counterweight offset
    /// (feasible variants; filled by the caller, see [`crate::practical`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub practical: Option<PracticalFigures>,
    // ---- Phase 3, filled by `finalize` for feasible variants ----
    /// Display name `SB<rank>` (SB1 = best overall).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Eq. 15, percent (negative = reduction = better).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dqtr: Option<f64>,
    /// Eq. 16, percent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dqit: Option<f64>,
    /// Eq. 19, percent (≥ 0, lower is better).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dr: Option<f64>,
    /// Per-joint breakdown of ΔR.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dr_terms: Option<DeltaR>,
    /// Global and per-class rank, 1 = best.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rank: Option<usize>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub class_rank: Option<usize>,
    /// True when the rank was decided by the element labels (tied on all three criteria).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub tie_broken_by_label: bool,
    /// Labels of the elements that only idle (see [`crate::honest`]); filled by `finalize`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub idle: Vec<String>,
}

impl VariantRecord {
    /// A record with only the search's fields; the rest default to empty.
    pub fn new(id: usize, elements: Vec<ElementInfo>, class: Class, status: Status) -> Self {
        VariantRecord {
            id,
            elements,
            class,
            status,
            reason: None,
            relations: Vec::new(),
            free_directions: Vec::new(),
            verification_residual: None,
            parameters: None,
            evaluation: None,
            optimiser: None,
            practical: None,
            name: None,
            dqtr: None,
            dqit: None,
            dr: None,
            dr_terms: None,
            rank: None,
            class_rank: None,
            tie_broken_by_label: false,
            idle: Vec::new(),
        }
    }

    /// Element labels joined, e.g. `m4 + K43` (also the final ranking tie-break).
    pub fn label(&self) -> String {
        self.elements
            .iter()
            .map(|e| e.label.as_str())
            .collect::<Vec<_>>()
            .join(" + ")
    }

    /// `SB3 (m4 + K43)` when ranked, else the labels.
    pub fn display_name(&self) -> String {
        match &self.name {
            Some(n) => format!("{n} ({})", self.label()),
            None => self.label(),
        }
    }
}
