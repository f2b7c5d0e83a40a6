//! Serialisable results of the optimisation stage (SI units in the data; [`display_rows`]
//! gives the paper's Table 1 units: N/mm, mm, kg, rad).

use counterpoise_balance::Class;
use counterpoise_dynamics::Indicators;
use serde::Serialize;

use crate::clarabel_map::ConicStatus;
use crate::problem::Objective;
use crate::verify::VerificationReport;

/// The optimiser's verdict is the shared status: `Feasible`, `Discarded` (paper Proc-6) or
/// `Undecided`.
pub use counterpoise_vocabulary::Status;

/// The optimised elements are the shared physical-parameter types (SI, body frames).
pub use counterpoise_vocabulary::{Counterweight, PhysicalParameters, Spring};

/// One free coordinate of the balanced family at the chosen point: the lifted parameters are
/// `x_p + Σ_k value_k · direction_k` (directions normalised like the balance crate's, largest
/// component ±1). `interval` is the range of this coordinate, the others held, over which the
/// bounds that are convex in the lifted parameters hold (masses, `|r| ≤ r_hi`, stiffness,
/// `|a| ≤ a_hi`, `|b| ≤ b_hi`); the lower radius/anchor bounds and spring realizability are
/// checked at the chosen point only.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FreeParameter {
    pub components: Vec<(String, f64)>,
    pub value: f64,
    pub interval: [f64; 2],
    /// Whether a counterweight variable is among `components`, i.e. this coordinate changes a
    /// counterweight; otherwise it changes only springs, on which the motor torques do not
    /// depend. (`components` omits the negligible ones: below 1e-4 of the largest, in the
    /// balance matrix's column-scaled units.)
    pub moves_counterweights: bool,
}

/// One pass of the critical-task loop (Proc-7/8).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Iteration {
    /// Tasks `[from, to]` the pass optimised over.
    pub tasks: usize,
    /// Lower bound from the relaxation on those tasks (N·m).
    pub lower_bound: f64,
    /// Objective on those tasks at the pass's optimum (N·m).
    pub objective_working: f64,
    /// Objective over all tasks at the pass's optimum (N·m).
    pub objective_all: f64,
    /// Newly critical tasks found over all tasks (added for the next pass).
    pub added: Vec<[usize; 2]>,
    pub relaxation_status: ConicStatus,
    pub relaxation_iterations: u32,
    /// Relative gap between the relaxation and the true value at its recovered point, before
    /// local refinement.
    pub gap_before_refinement: f64,
    /// Boxes the certified branch-and-bound solved in this pass (0: the local search's design
    /// was already within the gap tolerance of the relaxation's bound).
    pub boxes: usize,
    /// The variant (element labels) whose counterweights the pass's design takes, when that
    /// variant's design, tried with this variant's springs, was better than its own search's
    /// (see the optimiser's `critical::siblings`); absent for the search's own design.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub design_from: Option<String>,
}

/// The optimisation result of one balanced variant.
#[derive(Clone, Debug, Serialize)]
pub struct OptimisedVariant {
    /// Element labels (`m4`, `K43`).
    pub elements: Vec<String>,
    pub class: Class,
    pub status: Status,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    pub objective_kind: Objective,
    /// True objective over all tasks (RMS* or QTR), N·m.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub objective: Option<f64>,
    /// Certified lower bound on the optimum (N·m).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lower_bound: Option<f64>,
    /// `(objective − lower_bound)/objective`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gap: Option<f64>,
    /// Balance residual of the final parameters (the verification's).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub residual: Option<f64>,
    pub converged: bool,
    pub iterations: Vec<Iteration>,
    /// The final working set of critical tasks.
    pub critical_tasks: Vec<[usize; 2]>,
    pub counterweights: Vec<Counterweight>,
    pub springs: Vec<Spring>,
    pub free_parameters: Vec<FreeParameter>,
    /// ΔR (%) on the reaction tasks used to choose the springs (UB joint-critical tasks and the
    /// critical tasks).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub delta_r_estimate: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub verification: Option<VerificationReport>,
    /// Indicators over all tasks of the final parameters (with reactions when requested).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub indicators: Option<Indicators>,
}

impl OptimisedVariant {
    /// The optimised elements: what the dynamics crate evaluates and the results record.
    pub fn physical_parameters(&self) -> PhysicalParameters {
        PhysicalParameters {
            counterweights: self.counterweights.clone(),
            springs: self.springs.clone(),
        }
    }

    pub fn is_feasible(&self) -> bool {
        self.status == Status::Feasible
    }
}

/// One row of the paper's Table 1 (N/mm, mm, rad, kg).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DisplayRow {
    pub label: String,
    pub stiffness_n_per_mm: Option<f64>,
    pub a_mm: Option<f64>,
    pub alpha_rad: Option<f64>,
    pub b_mm: Option<f64>,
    pub beta_rad: Option<f64>,
    pub mass_kg: Option<f64>,
    pub r_mm: Option<f64>,
    pub phi_rad: Option<f64>,
}

/// Planar angle in `[0, 2π)` of a body-frame vector in the plane of its two largest axes
/// (x–y unless the vector lies elsewhere).
fn angle(v: [f64; 3]) -> f64 {
    let (x, y) = if v[2].abs() > 0.0 && v[0] == 0.0 {
        (v[1], v[2])
    } else if v[2].abs() > 0.0 && v[1] == 0.0 {
        (v[0], v[2])
    } else {
        (v[0], v[1])
    };
    let a = y.atan2(x);
    if a < -1e-12 {
        a + std::f64::consts::TAU
    } else {
        a.max(0.0)
    }
}

fn len(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// Table rows of a variant in the paper's units.
pub fn display_rows(v: &OptimisedVariant) -> Vec<DisplayRow> {
    let mut rows = Vec::new();
    for label in &v.elements {
        if let Some(c) = v.counterweights.iter().find(|c| &c.label == label) {
            rows.push(DisplayRow {
                label: label.clone(),
                stiffness_n_per_mm: None,
                a_mm: None,
                alpha_rad: None,
                b_mm: None,
                beta_rad: None,
                mass_kg: Some(c.mass),
                r_mm: Some(c.radius() * 1e3),
                phi_rad: Some(angle(c.offset)),
            });
        } else if let Some(s) = v.springs.iter().find(|s| &s.label == label) {
            rows.push(DisplayRow {
                label: label.clone(),
                stiffness_n_per_mm: Some(s.stiffness * 1e-3),
                a_mm: Some(len(s.anchor_a) * 1e3),
                alpha_rad: Some(angle(s.anchor_a)),
                b_mm: Some(len(s.anchor_b) * 1e3),
                beta_rad: Some(angle(s.anchor_b)),
                mass_kg: None,
                r_mm: None,
                phi_rad: None,
            });
        }
    }
    rows
}
