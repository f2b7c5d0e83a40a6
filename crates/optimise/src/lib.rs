//! Optimisation of balanced variants (docs/design.md §2 Phase 2, §3; paper Eqs. 11–14, Proc-5…8).
//!
//! Each balanced variant is a family of parameter sets `x = x_p + N z` (the balance search's
//! lifted solution set). This crate picks the member that minimises the energy estimate RMS*
//! (or QTR, [`Objective::Minimax`]) over the tasks, within the element bounds and the peak
//! limits, and says how close to the true optimum it is:
//!
//! 1. [`torque`]: the balanced variant's motor torque is inertial only and affine in the
//!    counterweights' lifted parameters; its columns come from the dynamics crate, once per task;
//! 2. [`relaxation`]: the convex relaxation over the working set of critical tasks, solved with
//!    clarabel ([`clarabel_map`]) — a certified lower bound;
//! 3. [`refine`]: the recovered point refined with the exact objective (Nelder–Mead);
//! 4. [`springs`]: physical springs inside the family and the bounds, chosen for low joint
//!    reactions (ΔR);
//! 5. [`critical`]: the critical-task loop over all tasks (Proc-7/8), batched over variants;
//! 6. [`verify`]: balance, bounds and peak limits re-checked before `feasible` is reported;
//! 7. [`overrides`]: per-element bounds from the case.
//!
//! Entry points: [`Context::new`], then [`optimise_all`] or [`optimise_variant`].

// Index loops over samples, actuators and axes read like the formulas they implement.
#![allow(clippy::needless_range_loop, clippy::too_many_arguments)]

pub mod anchor_restriction;
pub mod centre;
pub mod certify;
pub mod clarabel_map;
pub mod context;
pub mod critical;
pub(crate) mod dense_ipm;
pub mod diagnose;
pub mod error;
pub mod overrides;
pub mod problem;
pub mod progress;
pub mod refine;
pub mod relaxation;
pub mod result;
pub mod slots;
pub mod springs;
pub mod timing;
pub mod torque;
pub mod twins;
pub mod verify;

pub use clarabel_map::ConicStatus;
pub use context::Context;
pub use critical::{
    FinalReactionSolve, LoopTorques, OptimiseOptions, StageTimings, delta_r, lowest_delta_r,
    objective_of, optimise_all, optimise_all_reporting, optimise_all_timed, optimise_variant,
    sibling_group,
};
pub use error::OptimiseError;
pub use overrides::{BoundsTable, CounterweightBounds, ElementBounds, SpringBounds};
pub use problem::Objective;
pub use progress::{ProgressSink, StageProgress, Unit};
pub use result::{
    Counterweight, DisplayRow, FreeParameter, Iteration, OptimisedVariant, Spring, Status,
    display_rows,
};
pub use timing::{StageTime, Stopwatch, process_cpu_seconds};
pub use verify::{PeakCheck, VerificationReport};
