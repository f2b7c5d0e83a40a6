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

/// The error's message followed by each cause it does not already say: what the command line
/// prints after `error:`, and the Python module's exception message.
pub fn with_causes(e: &dyn std::error::Error) -> String {
    let mut message = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        let text = c.to_string();
        if !message.contains(&text) {
            message = format!("{message}: {text}");
        }
        cause = c.source();
    }
    message
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A cause the message already says is not repeated; one it does not say is appended.
    #[test]
    fn causes_are_said_once() {
        let gone = std::io::Error::new(std::io::ErrorKind::NotFound, "gone");
        let io = StudyError::io("cannot read case.json", gone);
        assert_eq!(with_causes(&io), "cannot read case.json: gone");
        #[derive(Debug, thiserror::Error)]
        #[error("writing the shard")]
        struct Outer(#[source] StudyError);
        let outer = Outer(io);
        assert_eq!(
            with_causes(&outer),
            "writing the shard: cannot read case.json: gone"
        );
    }
}
