//! The physical parameters of a variant's elements as the results document records them:
//! which element, where it sits, its mass or stiffness and anchors (SI units).
//!
//! The practical figures, the spring specifications and the variant records all read these;
//! they sit on the ground floor of the crate, with no dependence on what reads them.

use serde::{Deserialize, Serialize};

/// The plane of a counterweight offset or spring anchor (polar display, Table 1) and what an
/// element is: the shared vocabulary.
pub use counterpoise_vocabulary::{ElementKind, Plane};

/// One installed element of a variant.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ElementInfo {
    /// Catalogue label, e.g. `m4` or `K43`.
    pub label: String,
    #[serde(rename = "type")]
    pub kind: ElementKind,
    /// Body names: one for a counterweight, two for a spring (`base` for the ground).
    pub bodies: Vec<String>,
}

/// The physical parameters of a variant's elements: the shared vocabulary.
pub use counterpoise_vocabulary::{Counterweight, PhysicalParameters, Spring};

/// One free direction of the balanced family (lifted variable → component).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FreeDirection {
    pub components: Vec<(String, f64)>,
    /// Interval of the step along the direction keeping masses and stiffnesses positive
    /// (`None` bound = unbounded on that side).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub positive_interval: Option<(Option<f64>, Option<f64>)>,
}
