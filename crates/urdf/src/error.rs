//! Import errors: each names the URDF element at fault.

use thiserror::Error;

#[derive(Debug, Error, Clone, PartialEq)]
pub enum UrdfError {
    /// The text is not well-formed XML.
    #[error("not well-formed XML: {0}")]
    Xml(String),
    /// A URDF element is malformed or unsupported.
    #[error("{element}: {reason}")]
    Invalid { element: String, reason: String },
    /// The generated case did not pass counterpoise's own validation (a bug or a physically
    /// inconsistent URDF, e.g. an inertia that is not positive semi-definite).
    #[error("the imported case is invalid:\n{0}")]
    Case(String),
}

impl UrdfError {
    pub fn invalid(element: impl Into<String>, reason: impl Into<String>) -> UrdfError {
        UrdfError::Invalid {
            element: element.into(),
            reason: reason.into(),
        }
    }
}
