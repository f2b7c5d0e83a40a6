//! The physical parameters of a variant's elements, as every stage after the balance search
//! records them and every document writes them: which element (its catalogue label), where it
//! sits (body names, `base` for the ground), its mass or stiffness and anchors, in SI units.
//!
//! The optimiser's result, the shard files and results.json hold these very types, so a
//! counterweight or a spring is declared once; the stages that compute work on bodies by index
//! and name them here.

use serde::{Deserialize, Serialize};

use crate::element::Plane;

/// Physical parameters of a counterweight.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Counterweight {
    pub label: String,
    pub body: String,
    /// kg.
    pub mass: f64,
    /// Centre of mass in the body frame, m.
    pub offset: [f64; 3],
    /// Plane of the offset, when the case restricts it to one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plane: Option<Plane>,
}

/// Physical parameters of a zero-free-length spring.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Spring {
    pub label: String,
    /// Body carrying anchor `a`.
    pub body: String,
    /// Body carrying anchor `b` (`base` for the ground).
    pub other: String,
    /// N/m.
    pub stiffness: f64,
    /// Anchor on `body`, in its frame, m.
    pub anchor_a: [f64; 3],
    /// Anchor on `other`, in its frame, m.
    pub anchor_b: [f64; 3],
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plane: Option<Plane>,
}

/// The physical parameters of a variant.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PhysicalParameters {
    pub counterweights: Vec<Counterweight>,
    pub springs: Vec<Spring>,
}

/// The name of the fixed ground in a spring's `other` (the case format's name for it).
pub const BASE: &str = "base";

impl Spring {
    /// Whether anchor `b` is on the fixed ground.
    pub fn to_base(&self) -> bool {
        self.other == BASE
    }
}

impl Counterweight {
    /// `|offset|`, m: the reach the bounds limit.
    pub fn radius(&self) -> f64 {
        self.offset.iter().map(|v| v * v).sum::<f64>().sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 3-4-12 offset is 13 long; the plane is left out of the JSON when the case sets none.
    #[test]
    fn a_counterweights_radius_and_its_json() {
        let c = Counterweight {
            label: "m4".into(),
            body: "arm".into(),
            mass: 2.0,
            offset: [3.0, -4.0, 12.0],
            plane: None,
        };
        assert_eq!(c.radius(), 13.0);
        let json = serde_json::to_string(&c).unwrap();
        assert!(!json.contains("plane"), "{json}");
        let with_plane = Counterweight {
            plane: Some(Plane::Xz),
            ..c
        };
        let json = serde_json::to_string(&with_plane).unwrap();
        assert!(json.contains("\"plane\":\"xz\""), "{json}");
        let back: Counterweight = serde_json::from_str(&json).unwrap();
        assert_eq!(back, with_plane);
    }

    #[test]
    fn a_spring_to_the_base_names_it() {
        let s = Spring {
            label: "K41".into(),
            body: "upper_arm".into(),
            other: BASE.into(),
            stiffness: 1e3,
            anchor_a: [0.0; 3],
            anchor_b: [0.0; 3],
            plane: None,
        };
        assert!(s.to_base());
        let between = Spring {
            other: "column".into(),
            ..s
        };
        assert!(!between.to_base());
    }
}
