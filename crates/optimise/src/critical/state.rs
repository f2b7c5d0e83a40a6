//! What the critical-task loop carries per variant: its options, each variant's run (working
//! set, passes, state, candidate) and the stages' timings.

use nalgebra::DVector;
use serde::{Deserialize, Serialize};

use crate::certify::SearchState;
use crate::problem::{CwPhysical, Objective, VariantProblem};
use crate::result::Iteration;
use crate::springs::{Spring, StartRecord};
use crate::timing::StageTime;

/// Settings of the optimisation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct OptimiseOptions {
    pub objective: Objective,
    /// Most passes of the critical-task loop.
    pub max_iterations: usize,
    /// Relative gap below which the relaxation's recovered point is accepted without local
    /// refinement.
    pub gap_tolerance: f64,
    /// Starts of the spring realization per pass (the final choice uses four times as many).
    pub spring_starts: usize,
    /// Compute joint reactions in the final all-task evaluation (F_j, M_j, ΔR).
    pub final_reactions: bool,
    /// How the final all-task evaluation solves each sample's joint reactions. A variant's
    /// figures are the same bits in any batch under one choice, and differ in the last bits
    /// between the two; a study sets it from its whole balance search
    /// ([`FinalReactionSolve::for_study`]) so that every shard makes the same choice.
    #[serde(default)]
    pub final_reaction_solve: FinalReactionSolve,
    /// How the critical-task loop's all-task evaluations (motor torques only) combine their
    /// batch; set, like the final solve, from the whole balance search
    /// ([`LoopTorques::for_study`]).
    #[serde(default)]
    pub loop_torques: LoopTorques,
    /// clarabel iteration limit.
    pub solver_iterations: u32,
    /// Boxes the certified search ([`crate::certify`]) solves at most per variant and pass: the
    /// only limit that can leave a variant undecided.
    #[serde(default = "default_max_nodes")]
    pub max_nodes: usize,
    /// Seed of the local search's starting points after the first. Verdicts do not depend on
    /// it, nor an objective beyond its certified gap; ranks can move where another design
    /// within the gap gives the spring choice by ΔR (a local search, not certified) other
    /// options, or a ΔQTR near a cell boundary crosses it (at Dmax 3 on the palletizer, 23 of
    /// 788 rank numbers between two seeds, with [`Self::siblings`]; 96 without).
    #[serde(default = "default_start_seed")]
    pub start_seed: u64,
    /// Solve each class of mirror-twin variants once (see [`crate::twins`]): a variant whose
    /// springs have twins of lower catalogue index takes the certified search of the variant
    /// holding those twins instead (its verdict, bound and design, anchors mirrored, then its
    /// own spring choice, evaluation and verification). `false` searches every variant itself.
    #[serde(default = "default_twins")]
    pub twins: bool,
    /// Weight each spring coordinate's choice for a split by what its earlier splits did to the
    /// bounds ([`crate::certify::BranchOptions::split_history`]). `false` keeps the coupling
    /// error alone (to compare).
    #[serde(default = "default_split_history")]
    pub split_history: bool,
    /// After each pass, let each variant try the designs of the study's variants with the same
    /// counterweights and springs (module `critical::siblings`): the first its springs admit
    /// that is better than its own replaces it. `false` keeps each search's own design (to
    /// compare).
    #[serde(default = "default_siblings")]
    pub siblings: bool,
}

pub(super) fn default_siblings() -> bool {
    true
}

pub(super) fn default_split_history() -> bool {
    true
}

pub(super) fn default_twins() -> bool {
    true
}

/// How the final all-task evaluation solves the joint reactions of a sample for the batch's
/// right-hand sides (every finalist, and three per inertia group).
///
/// The reaction operator costs one substitution per body wrench row to form (`6L`, 48 on the
/// palletizer) and then less than a substitution per right-hand side, so it pays for large
/// batches only. Measured on the palletizer's final evaluation (release, 2 cores, one run
/// each): at Dmax 2 (50 finalists in 14 inertia groups, 92 right-hand sides per sample)
/// substitution takes 2.08 s against the operator's 2.28 s; at Dmax 3 (788 finalists) the
/// operator takes 25.8 s against substitution's 29.3 s. [`Self::for_study`] switches at
/// `2.5 · 6L` balanced variants, on the Dmax 2 side of that range.
///
/// A large batch holds many inertia groups too (nearly every variant with a counterweight is
/// its own: 344 groups for the 788 Dmax 3 finalists), each evaluated at three rotation speeds;
/// by superposition over the inertial rows the groups touch they cost three right-hand sides
/// per basis column (50 at Dmax 3) and a short sum each
/// ([`counterpoise_dynamics::Combination::InertiaSuperposition`]). On the 788 Dmax 3 designs'
/// final grid that takes 20.0 s against the operator's 23.4 s, on every fourth of them (197,
/// 11 samples per move) 1.40 s against 1.54 s, on every eighth (99) 0.85 s against 0.78 s
/// (release, 2 cores; `crates/dynamics/examples/time_final.rs`), so it takes over at the
/// loop's threshold ([`LoopTorques::for_study`], `60·L` balanced variants).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FinalReactionSolve {
    /// Through the sample's reaction operator (large batches).
    #[default]
    Operator,
    /// By substitution in the sample's factorisation, right-hand side by right-hand side
    /// (small batches).
    Substitution,
    /// Through the operator, the inertia groups' changes by superposition (the largest
    /// batches).
    OperatorInertiaSums,
}

impl FinalReactionSolve {
    /// The choice for a study whose balance search found `balanced` variants. The final
    /// batch's right-hand sides per sample are not known before the optimisation (its
    /// finalists and their inertia groups); the balanced count bounds the finalists and,
    /// unlike them, is the same in every shard of the study. On the palletizer it tracks
    /// them: 97 balanced variants at Dmax 2 give 92 right-hand sides per sample.
    pub fn for_study(model: &counterpoise_model::Model, balanced: usize) -> Self {
        // 2.5 · 6L, in integers
        let crossover = 15 * model.bodies.len();
        if balanced <= crossover {
            FinalReactionSolve::Substitution
        } else if LoopTorques::for_study(model, balanced) == LoopTorques::Direct {
            FinalReactionSolve::Operator
        } else {
            FinalReactionSolve::OperatorInertiaSums
        }
    }

    /// The dynamics crate's way of combining a batch that makes this choice.
    pub fn combination(self) -> counterpoise_dynamics::Combination {
        match self {
            FinalReactionSolve::Operator => counterpoise_dynamics::Combination::Direct,
            FinalReactionSolve::Substitution => counterpoise_dynamics::Combination::Substitution,
            FinalReactionSolve::OperatorInertiaSums => {
                counterpoise_dynamics::Combination::InertiaSuperposition
            }
        }
    }
}

/// How the critical-task loop's all-task evaluations combine a batch's motor torques.
///
/// Torques are linear in the lifted parameters, and a variant differs from the robot in its
/// elements' rows only: by superposition a sample solves the robot and one unit column per
/// row that the batch changes (239 for the 788 Dmax 3 designs), and each variant is a sum over
/// its own rows (at most 27 at Dmax 3: 7 per counterweight in a plane, 9 per spring), against
/// one wrench and actuator solve per variant and three per inertia group directly. It pays
/// once a batch holds more variants than the rows they touch: on the palletizer's 788 feasible Dmax 3 designs, torques over all tasks take 2.9 s
/// by superposition against 5.2 s directly, on every fourth of them (197) 1.27 s against
/// 1.56 s, on every eighth (99) 1.08 s against 0.85 s (release, 2 cores;
/// `crates/dynamics/examples/time_final.rs`). A study's first pass evaluates about as many
/// variants as it has balanced ones and later passes a fraction of those (Dmax 3: 1169
/// balanced, 248 in the second pass), so [`Self::for_study`] switches at `60·L` balanced
/// variants (480 for the palletizer's 8 bodies: Dmax 2's 97 below, Dmax 3's 1169 above). The
/// two give the same indicators to rounding; a variant's bits do not depend on its batch
/// under either, only on this choice, which every shard of a study makes alike.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LoopTorques {
    /// Every variant's own wrench and actuator solves (small batches).
    #[default]
    Direct,
    /// The robot's and the changed rows' unit columns, summed per variant (large batches).
    Superposition,
}

impl LoopTorques {
    /// The choice for a study whose balance search found `balanced` variants (the same in
    /// every shard).
    pub fn for_study(model: &counterpoise_model::Model, balanced: usize) -> Self {
        if balanced <= 60 * model.bodies.len() {
            LoopTorques::Direct
        } else {
            LoopTorques::Superposition
        }
    }

    /// The dynamics crate's way of combining a batch that makes this choice.
    pub fn combination(self) -> counterpoise_dynamics::Combination {
        match self {
            LoopTorques::Direct => counterpoise_dynamics::Combination::Direct,
            LoopTorques::Superposition => counterpoise_dynamics::Combination::Superposition,
        }
    }
}

pub(super) fn default_start_seed() -> u64 {
    crate::springs::DEFAULT_SEED
}

pub(super) fn default_max_nodes() -> usize {
    OptimiseOptions::default().max_nodes
}

impl OptimiseOptions {
    /// The certified search's settings ([`crate::certify::branch_and_bound`]) these options
    /// give: their gap tolerance, box limit and clarabel iteration limit.
    pub fn branch_options(&self) -> crate::certify::BranchOptions {
        crate::certify::BranchOptions {
            gap_tolerance: self.gap_tolerance,
            max_nodes: self.max_nodes,
            solver_iterations: self.solver_iterations,
            split_history: self.split_history,
        }
    }
}

impl Default for OptimiseOptions {
    fn default() -> Self {
        OptimiseOptions {
            objective: Objective::RmsStar,
            max_iterations: 8,
            gap_tolerance: 1e-3,
            spring_starts: 8,
            final_reactions: true,
            final_reaction_solve: FinalReactionSolve::default(),
            loop_torques: LoopTorques::default(),
            solver_iterations: 200,
            max_nodes: crate::certify::DEFAULT_MAX_NODES,
            start_seed: crate::springs::DEFAULT_SEED,
            twins: default_twins(),
            split_history: default_split_history(),
            siblings: default_siblings(),
        }
    }
}

/// A variant in the loop.
#[derive(Clone)]
pub(super) struct Run {
    pub(super) elements: Vec<String>,
    pub(super) class: counterpoise_balance::Class,
    pub(super) problem: Option<VariantProblem>,
    pub(super) working: Vec<usize>,
    pub(super) iterations: Vec<Iteration>,
    pub(super) state: State,
    pub(super) candidate: Option<Candidate>,
    /// What the last branch-and-bound left (its next pass starts from these boxes).
    pub(super) search: Option<SearchState>,
}

#[derive(Clone, Debug, PartialEq)]
pub(super) enum State {
    Running,
    Converged,
    Stopped,
    /// Proved impossible (the reason names the binding constraint).
    Discarded(String),
    /// Not built, not proved impossible.
    Undecided(String),
}

/// Why a pass produced no candidate.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum Failure {
    Discard(String),
    Undecided(String),
}

impl Failure {
    pub(super) fn into_state(self) -> State {
        match self {
            Failure::Discard(r) => State::Discarded(r),
            Failure::Undecided(r) => State::Undecided(r),
        }
    }
}

#[derive(Clone, Debug)]
pub(super) struct Candidate {
    pub(super) x: DVector<f64>,
    pub(super) cws: Vec<CwPhysical>,
    pub(super) springs: Vec<Spring>,
    /// 0 (the trivial bound) when the relaxation was not solved.
    pub(super) lower_bound: f64,
    /// Whether `lower_bound` is the relaxation's certified bound.
    pub(super) bound_certified: bool,
    pub(super) working_value: f64,
    pub(super) relaxation_status: crate::clarabel_map::ConicStatus,
    pub(super) relaxation_iterations: u32,
    pub(super) gap_before: f64,
    /// The spring realization's local solves for these counterweights (the spring choice
    /// reuses them).
    pub(super) spring_starts: Option<StartRecord>,
    /// Boxes the certified search solved (0 when the fast path was within the tolerance).
    pub(super) boxes: usize,
    /// The variant whose counterweights the design takes, when a sibling's gave a better one
    /// than the search's own (module `siblings`).
    pub(super) design_from: Option<Vec<String>>,
}

/// Wall and CPU time of the stages of [`optimise_all`].
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct StageTimings {
    /// Relaxations, refinements and spring realizations of every pass, and the designs the
    /// siblings share (module `siblings`).
    pub solve: StageTime,
    /// The all-task torque evaluations of the critical-task loop.
    pub loop_grid: StageTime,
    /// Spring choice by ΔR on the reaction tasks.
    pub spring_choice: StageTime,
    /// Of the spring choice, the joint reactions of the options on the reaction tasks (the
    /// rest is the realization of the options).
    pub spring_reactions: StageTime,
    /// Final all-task evaluation (torques and joint reactions).
    pub final_grid: StageTime,
    /// Verification and records.
    pub records: StageTime,
    /// Passes of the critical-task loop.
    pub passes: usize,
    /// Variants the loop searched: one per class of mirror twins (see [`crate::twins`]), with
    /// any leader that is not among the variants.
    pub searched: usize,
}
