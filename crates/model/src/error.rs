//! Errors of case loading and validation.
//!
//! Validation does not stop at the first problem: a designer fixing a case file wants to see
//! every mistake at once, so the validator collects [`ModelError`]s and returns them together as
//! [`CaseErrors`]. Every error carries the JSON path of the offending field (`bodies[3].inertia`,
//! `joints[2].bodies[1]`, `parameters.d1`) so that it can be found in the file.

use std::fmt;

use counterpoise_symbolic::ExprError;

/// One problem found in a case file.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ModelError {
    /// The file could not be read.
    #[error("{path}: cannot read the case file: {message}")]
    Io { path: String, message: String },
    /// The JSON is malformed or does not have the expected shape (wrong type, unknown field,
    /// missing field). `line`/`column` locate it in the text.
    #[error("{path}: {message} (line {line}, column {column})")]
    Syntax {
        path: String,
        line: usize,
        column: usize,
        message: String,
    },
    /// A value is out of its domain (negative mass, min ≥ max, zero axis, …).
    #[error("{path}: {reason}")]
    Invalid { path: String, reason: String },
    /// A reference to a body, joint, actuator, coordinate or waypoint that does not exist.
    #[error("{path}: unknown {what} `{name}`")]
    UnknownName {
        path: String,
        what: &'static str,
        name: String,
    },
    /// A name defined twice.
    #[error("{path}: duplicate {what} `{name}` (already defined at {first})")]
    Duplicate {
        path: String,
        what: &'static str,
        name: String,
        first: String,
    },
    /// The `parent` references of the bodies form a cycle, so no body on it has a world pose.
    #[error("{path}: the parent chain is a cycle: {cycle}")]
    Cycle { path: String, cycle: String },
    /// An expression that the symbolic core refused.
    #[error("{path}: {source}")]
    Expression {
        path: String,
        #[source]
        source: ExprError,
    },
    /// The two bodies of a joint disagree on its geometry somewhere in the coordinate ranges.
    #[error("{path}: joint `{joint}` is inconsistent: {deviation} at {configuration}")]
    JointInconsistent {
        path: String,
        joint: String,
        deviation: String,
        configuration: String,
    },
}

impl ModelError {
    /// JSON path of the field the error is about (`.` for the whole file).
    pub fn path(&self) -> &str {
        match self {
            ModelError::Io { path, .. }
            | ModelError::Syntax { path, .. }
            | ModelError::Invalid { path, .. }
            | ModelError::UnknownName { path, .. }
            | ModelError::Duplicate { path, .. }
            | ModelError::Cycle { path, .. }
            | ModelError::Expression { path, .. }
            | ModelError::JointInconsistent { path, .. } => path,
        }
    }

    pub(crate) fn invalid(path: impl Into<String>, reason: impl Into<String>) -> ModelError {
        ModelError::Invalid {
            path: path.into(),
            reason: reason.into(),
        }
    }
}

/// All problems found in one case file (never empty).
#[derive(Clone, Debug, PartialEq)]
pub struct CaseErrors {
    pub errors: Vec<ModelError>,
}

impl CaseErrors {
    pub fn iter(&self) -> impl Iterator<Item = &ModelError> {
        self.errors.iter()
    }

    pub fn len(&self) -> usize {
        self.errors.len()
    }

    pub fn is_empty(&self) -> bool {
        self.errors.is_empty()
    }
}

impl From<ModelError> for CaseErrors {
    fn from(error: ModelError) -> Self {
        CaseErrors {
            errors: vec![error],
        }
    }
}

impl fmt::Display for CaseErrors {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let n = self.errors.len();
        write!(
            f,
            "{n} error{} in the case file",
            if n == 1 { "" } else { "s" }
        )?;
        for error in &self.errors {
            write!(f, "\n  {error}")?;
        }
        Ok(())
    }
}

impl std::error::Error for CaseErrors {}

impl<'a> IntoIterator for &'a CaseErrors {
    type Item = &'a ModelError;
    type IntoIter = std::slice::Iter<'a, ModelError>;

    fn into_iter(self) -> Self::IntoIter {
        self.errors.iter()
    }
}
