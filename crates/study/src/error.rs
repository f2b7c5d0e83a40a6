//! Why a study stopped, as one type the callers match on (the CLI prints it; the Python module
//! raises it with the same message).

use std::path::PathBuf;

use counterpoise_model::{CaseErrors, ModelError};

/// Why a study (or one of its commands) gave no result.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// The case is invalid, or a guard refused it before a costly stage (too many variants, an
    /// unfollowable path): every problem, each naming its field and location.
    #[error("{}: {} error(s)\n  {}", path.display(), errors.len(), errors.lines().join("\n  "))]
    Case { path: PathBuf, errors: CaseErrors },
    /// Problems found in a case beyond validation (element overrides), listed as the command
    /// line prints them: a header naming the file, then one problem a line.
    #[error("{0}")]
    Problems(String),
    /// The case has no section the study needs, or an option is out of range.
    #[error("{0}")]
    Invalid(String),
    /// The shards given to a merge do not make one study.
    #[error("{0}")]
    Shards(String),
    /// A stage failed.
    #[error(transparent)]
    Model(#[from] ModelError),
    #[error(transparent)]
    Minimal(#[from] counterpoise_balance::minimal::MinimalError),
    #[error(transparent)]
    Partial(#[from] counterpoise_balance::partial::PartialError),
    #[error(transparent)]
    Dynamics(#[from] counterpoise_dynamics::DynamicsError),
    #[error(transparent)]
    Optimise(#[from] counterpoise_optimise::OptimiseError),
    #[error(transparent)]
    Results(#[from] counterpoise_report::ResultsError),
    #[error(transparent)]
    Output(#[from] counterpoise_report::OutputError),
    #[error(transparent)]
    Json(#[from] serde_json::Error),
    /// A file could not be read or written.
    #[error("{what}: {source}")]
    Io {
        what: String,
        #[source]
        source: std::io::Error,
    },
    /// The caller cancelled the study (between stages).
    #[error("cancelled")]
    Cancelled,
}

impl StudyError {
    /// An I/O error with what was being done (`cannot read case.json`).
    pub fn io(what: impl Into<String>, source: std::io::Error) -> StudyError {
        StudyError::Io {
            what: what.into(),
            source,
        }
    }
}

/// `Err(StudyError::Invalid(format!(…)))`, the library's `bail!`.
macro_rules! invalid {
    ($($arg:tt)*) => {
        return Err($crate::error::StudyError::Invalid(format!($($arg)*)))
    };
}
pub(crate) use invalid;

/// A study's result.
pub type Result<T, E = StudyError> = std::result::Result<T, E>;
