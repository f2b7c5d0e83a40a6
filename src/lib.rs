//! counterpoise: find every way to statically balance a mechanism with counterweights and
//! springs, tune each for low motor effort, and rank them.
//!
//! This package is the command-line tool and a facade over the crates: [`symbolic`]
//! (trigonometric-polynomial algebra), [`model`] (case format, validation, kinematics),
//! [`balance`] (exact balancing search), [`dynamics`] (inverse dynamics and indicators over
//! tasks), and [`study`]: the case study as a library (the pipeline `run` drives, shards and
//! their merge, the checks of the costly stages).

pub use counterpoise_balance as balance;
pub use counterpoise_dynamics as dynamics;
pub use counterpoise_model as model;
pub use counterpoise_study as study;
pub use counterpoise_study::{preflight, shard};
pub use counterpoise_symbolic as symbolic;
