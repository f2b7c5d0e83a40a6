//! The options of an evaluation: samples, reactions, the cyclic shortcut, and how a batch's
//! columns are combined.
//!
//! Both the direct evaluation (`evaluate`) and the cyclic one (`fast`) read them; they sit
//! apart so that neither of those modules depends on the other for them.

/// Options of [`crate::evaluate::evaluate`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct EvaluateOptions {
    /// Samples per task (default: the case's).
    pub samples: Option<usize>,
    /// Compute joint reactions (`F_j`, `M_j`).
    pub reactions: bool,
    /// Use the cyclic-coordinate decomposition ([`crate::symmetry`], `fast` module) when the
    /// model has a cyclic coordinate; `false` runs every task directly (the reference path).
    pub shortcut: bool,
}

impl Default for EvaluateOptions {
    fn default() -> Self {
        EvaluateOptions {
            samples: None,
            reactions: true,
            shortcut: true,
        }
    }
}

/// How the outputs of a batch's columns are computed by the grid evaluation.
///
/// Both give the same values to rounding (the root package's `tests/superposition.rs`: the
/// palletizer's joint reaction peaks to 1e-9 relative); each is deterministic per column,
/// whatever else is in the batch. A study uses one of them throughout, so that its shards
/// merge into the single run's bits.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Combination {
    /// Every column through the reaction solve of its own right-hand side (and its inertia
    /// group's changes with the rotation speed).
    #[default]
    Direct,
    /// The model's own parameters and one unit column per lifted row that any column changes
    /// are solved; each column is the model's outputs plus its elements' rows times their unit
    /// outputs, its own rows in ascending order. Cheaper once the batch has more columns than
    /// rows (Dmax 3 and up), and the way to evaluate one variant's many spring options.
    Superposition,
    /// Every column as [`Combination::Direct`], but each sample's reaction right-hand sides
    /// solved by substitution in the sample's factorisation instead of through the reaction
    /// operator. Forming the operator costs one substitution per body wrench row (48 on the
    /// palletizer) and applying it less than a substitution per right-hand side, so it pays
    /// for large batches only; a batch of one column has four right-hand sides (the column,
    /// and its inertia group at three rotation speeds), so the unbalanced robot of Phase 1 is
    /// evaluated this way (the palletizer's grid: 0.69 s against 1.18 s wall), and so is the
    /// final evaluation of a small study (the optimiser's `FinalReactionSolve`: the Dmax 2
    /// palletizer's 92 right-hand sides per sample, 2.08 s against 2.28 s). The same values to
    /// rounding; a column's bits do not depend on the rest of the batch, only on this choice.
    Substitution,
    /// Every column as [`Combination::Direct`] at `Δ = 0`, but the inertia groups' changes
    /// with the rotation speed by superposition: the model's own inertia and one unit column
    /// per inertial row that some group changes are evaluated, and each group's change is
    /// their sum over its own rows (in ascending order, so a column's bits do not depend on
    /// its batch). Pays when a batch holds many inertia groups (every hybrid variant is one).
    InertiaSuperposition,
}
