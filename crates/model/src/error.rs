//! Errors of case loading and validation.
//!
//! Validation does not stop at the first problem: a designer fixing a case file wants to see
//! every mistake at once, so the validator collects [`ModelError`]s and returns them together as
//! [`CaseErrors`]. Every error carries the JSON path of the offending field (`bodies[3].inertia`,
//! `joints[2].bodies[1]`, `parameters.d1`) so that it can be found in the file.

use std::fmt;

use counterpoise_symbolic::ExprError;

pub use crate::locate::Position;

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

    /// A value out of its domain at `path`.
    pub fn invalid(path: impl Into<String>, reason: impl Into<String>) -> ModelError {
        ModelError::Invalid {
            path: path.into(),
            reason: reason.into(),
        }
    }
}

/// All problems found in one case file (never empty), sorted by path.
#[derive(Clone, Debug, PartialEq)]
pub struct CaseErrors {
    pub errors: Vec<ModelError>,
    /// Where each error's field is in the text (same order as `errors`; `None` when the errors
    /// were not produced from a text). [`ModelError::Syntax`] carries its own.
    pub positions: Vec<Option<Position>>,
}

impl CaseErrors {
    /// Errors without positions, in the given order.
    pub fn new(errors: Vec<ModelError>) -> CaseErrors {
        let positions = vec![None; errors.len()];
        CaseErrors { errors, positions }
    }

    /// Sorts the errors by path (array indices numerically; a stable sort keeps the order of
    /// errors on the same field) and locates each in `text`, the case file's text.
    pub fn sorted_and_located(mut errors: Vec<ModelError>, text: &str) -> CaseErrors {
        errors.sort_by_cached_key(|e| path_key(e.path()));
        let paths: Vec<&str> = errors.iter().map(ModelError::path).collect();
        let found = crate::locate::positions(text, &paths);
        let positions = errors
            .iter()
            .map(|e| match e {
                ModelError::Syntax { line, column, .. } if *line > 0 => Some(Position {
                    line: *line,
                    column: *column,
                }),
                // A command-line option (`--dmax`) is not in the file.
                _ if e.path().starts_with("--") => None,
                _ => found.get(e.path()).copied(),
            })
            .collect();
        CaseErrors { errors, positions }
    }

    /// Each error with its position.
    pub fn located(&self) -> impl Iterator<Item = (&ModelError, Option<Position>)> {
        self.errors.iter().zip(
            self.positions
                .iter()
                .copied()
                .chain(std::iter::repeat(None)),
        )
    }

    /// One line per error: the error, then its line and column where the text has them.
    pub fn lines(&self) -> Vec<String> {
        self.located()
            .map(|(e, at)| match (e, at) {
                (ModelError::Syntax { .. }, _) | (_, None) => e.to_string(),
                (_, Some(at)) => format!("{e} (line {}, column {})", at.line, at.column),
            })
            .collect()
    }

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
        CaseErrors::new(vec![error])
    }
}

/// One segment of a path, ordered so that `bodies[2]` comes before `bodies[10]`.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Segment {
    Index(u64),
    Name(String),
}

fn path_key(path: &str) -> Vec<Segment> {
    let mut key = Vec::new();
    for part in path.split('.').filter(|p| !p.is_empty()) {
        let mut pieces = part.split('[');
        if let Some(name) = pieces.next()
            && !name.is_empty()
        {
            key.push(Segment::Name(name.to_string()));
        }
        for index in pieces {
            let digits = index.trim_end_matches(']');
            key.push(match digits.parse() {
                Ok(n) => Segment::Index(n),
                Err(_) => Segment::Name(digits.to_string()),
            });
        }
    }
    key
}

impl fmt::Display for CaseErrors {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let n = self.errors.len();
        write!(
            f,
            "{n} error{} in the case file",
            if n == 1 { "" } else { "s" }
        )?;
        for line in self.lines() {
            write!(f, "\n  {line}")?;
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_sort_naturally() {
        let mut paths = vec![
            "tasks.grid.M1[2]",
            "bodies[10].mass",
            "bodies[2].pose[0].rot_z",
            ".",
            "bodies[2].mass",
            "actuators",
        ];
        paths.sort_by_key(|p| path_key(p));
        assert_eq!(
            paths,
            vec![
                ".",
                "actuators",
                "bodies[2].mass",
                "bodies[2].pose[0].rot_z",
                "bodies[10].mass",
                "tasks.grid.M1[2]"
            ]
        );
    }
}
