//! Errors of the optimisation stage: problems with the inputs (the case's overrides, a model
//! without tasks), never with a variant — a variant that cannot be optimised is reported as
//! `discarded` with its reason, not as an error.

use counterpoise_dynamics::DynamicsError;
use thiserror::Error;

#[derive(Debug, Error)]
pub enum OptimiseError {
    /// `balancing.overrides[i].field: message` — one entry per problem found.
    #[error("invalid balancing overrides:\n  {}", .0.join("\n  "))]
    Overrides(Vec<String>),
    #[error("the case has no balancing section")]
    NoBalancing,
    #[error("dynamics: {0}")]
    Dynamics(#[from] DynamicsError),
    #[error("{0}")]
    Other(String),
}
