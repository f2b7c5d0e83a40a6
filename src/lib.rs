//! counterpoise: find every way to statically balance a mechanism with counterweights and
//! springs, tune each for low motor effort, and rank them.
//!
//! This package is the command-line tool and a facade over the stage crates:
//! [`symbolic`] (trigonometric-polynomial algebra), [`model`] (case format, validation,
//! kinematics), [`balance`] (exact balancing search), [`dynamics`] (inverse dynamics and
//! indicators over tasks), and [`preflight`]: the checks `check` runs beyond validation and the
//! guards of the costly stages; and [`shard`]: splitting a study's balanced variants into
//! shards of equal expected cost.

pub mod preflight;
pub mod shard;

pub use counterpoise_balance as balance;
pub use counterpoise_dynamics as dynamics;
pub use counterpoise_model as model;
pub use counterpoise_symbolic as symbolic;
