//! Honest parameters: which elements of a variant only idle, and which parameters sit on a
//! bound.
//!
//! **Idle elements.** The optimiser keeps every element of a variant installed with at least a
//! floor mass (10⁻⁶ of the upper mass bound, 0.5 g for the palletizer's 500 kg), so a variant
//! whose best design has no use for a counterweight reports it at that floor: at Dmax 3 a
//! "hybrid" `m6 + K42 + K53` with a 0.54 g counterweight on a 1.2 t robot is the spring pair
//! `K42 + K53` with a crumb attached. An element is *idle* when the largest force it can
//! exert is below [`IDLE_FRACTION`] of the weight of the moving mass: a counterweight's own
//! weight `m·|g|`, a spring's peak force over the configurations checked (see
//! [`crate::practical`]). At 10⁻³ that is 1.19 kg on the palletizer (moving mass 1,189 kg),
//! 6.5 g on the two-link arm: less than the uncertainty with which a mechanism's own masses
//! are known (a body's mass is rarely known to better than a percent), so what such an element
//! balances is below what the model can tell. On the palletizer at Dmax 3 the feasible
//! variants' counterweights fall into two groups, 0.5 g to 0.5 kg (the optimiser's floor and
//! small trims on top of a spring design) and 3 kg and up (real counterweights); the threshold
//! lies in the gap between them. The variant is, to that accuracy, the smaller one its other
//! elements make. The reports name idle elements, show the smaller variant, and the
//! recommendation never picks a variant holding one (it would be recommending a part that
//! does nothing, under a class it does not belong to).
//!
//! **Parameters on a bound.** The optimiser's design often sits on a bound (an anchor at its
//! largest distance, a stiffness at its cap): the bound, not the mechanics, decided it, and a
//! designer who can relax the bound can do better. `run` records the bounds every element was
//! optimised within ([`ElementBounds`]); a value within [`BOUND_TOLERANCE`] (relative to the
//! bound's magnitude, or absolute below 1) of either end is reported as on that bound.

use serde::{Deserialize, Serialize};

use crate::parameters::{ElementKind, PhysicalParameters};
use crate::practical::PracticalFigures;
use crate::variant::VariantRecord;

/// An element whose largest force is below this fraction of the moving mass's weight idles.
pub const IDLE_FRACTION: f64 = 1e-3;

/// Relative distance to a bound at which a value counts as on it.
pub const BOUND_TOLERANCE: f64 = 1e-6;

/// The bounds one element was optimised within (the case's `balancing.bounds` with its
/// overrides, or the bounds derived from the mechanism), SI units. A counterweight has `mass`
/// and `radius` (the offset's length); a spring `stiffness` and the lengths of its anchors.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ElementBounds {
    pub label: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mass: Option<[f64; 2]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius: Option<[f64; 2]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stiffness: Option<[f64; 2]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub anchor_a: Option<[f64; 2]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub anchor_b: Option<[f64; 2]>,
}

/// Which end of its range a value sits on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OnBound {
    Lower,
    Upper,
}

impl OnBound {
    /// `min` / `max`, as the tables print it.
    pub fn word(self) -> &'static str {
        match self {
            OnBound::Lower => "min",
            OnBound::Upper => "max",
        }
    }
}

/// Whether `x` is on an end of `range` (within [`BOUND_TOLERANCE`]); the upper end wins when
/// the range is a point.
pub fn on_bound(x: f64, range: Option<[f64; 2]>) -> Option<OnBound> {
    let [lo, hi] = range?;
    let near = |b: f64| b.is_finite() && (x - b).abs() <= BOUND_TOLERANCE * b.abs().max(1.0);
    if near(hi) {
        Some(OnBound::Upper)
    } else if near(lo) {
        Some(OnBound::Lower)
    } else {
        None
    }
}

/// Labels of the idle elements of a variant with parameters `p` and practical figures
/// `practical` (the springs' peak forces), for a mechanism of `moving_mass` kg under gravity
/// of magnitude `gravity` m/s². Without a moving mass nothing is called idle (no scale to
/// judge by); a spring without a measured peak is not either.
pub fn idle_elements(
    p: &PhysicalParameters,
    practical: Option<&PracticalFigures>,
    moving_mass: Option<f64>,
    gravity: f64,
) -> Vec<String> {
    let Some(m) = moving_mass.filter(|m| *m > 0.0 && m.is_finite()) else {
        return Vec::new();
    };
    let threshold = IDLE_FRACTION * m * gravity;
    let mut idle = Vec::new();
    for c in &p.counterweights {
        if c.mass * gravity < threshold {
            idle.push(c.label.clone());
        }
    }
    for s in &p.springs {
        let peak = practical.and_then(|f| f.springs.iter().find(|x| x.label == s.label));
        if let Some(peak) = peak
            && peak.force < threshold
        {
            idle.push(s.label.clone());
        }
    }
    idle
}

impl VariantRecord {
    /// The labels of the elements that do something (all but the idle ones), joined:
    /// the variant this one really is.
    pub fn effective_label(&self) -> String {
        self.elements
            .iter()
            .filter(|e| !self.idle.contains(&e.label))
            .map(|e| e.label.as_str())
            .collect::<Vec<_>>()
            .join(" + ")
    }

    /// The class of [`VariantRecord::effective_label`].
    pub fn effective_class(&self) -> crate::ranking::Class {
        use crate::ranking::Class;
        let working = self
            .elements
            .iter()
            .filter(|e| !self.idle.contains(&e.label));
        let (mut cw, mut sp) = (false, false);
        for e in working {
            match e.kind {
                ElementKind::Counterweight => cw = true,
                ElementKind::Spring => sp = true,
            }
        }
        match (cw, sp) {
            (true, false) => Class::Counterweights,
            (false, true) => Class::Springs,
            _ if self.idle.is_empty() => self.class,
            _ => Class::Hybrid,
        }
    }

    /// `m6 idle: really K42 + K53 (springs)`, or `None` when no element idles.
    pub fn idle_note(&self) -> Option<String> {
        if self.idle.is_empty() {
            return None;
        }
        Some(format!(
            "{} idle: really {} ({})",
            self.idle.join(", "),
            self.effective_label(),
            self.effective_class().name()
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::practical::SpringPeak;
    use crate::results::{Counterweight, Spring};

    fn params(mass: f64) -> PhysicalParameters {
        PhysicalParameters {
            counterweights: vec![Counterweight {
                label: "m6".into(),
                body: "b".into(),
                mass,
                offset: [0.1, 0.0, 0.0],
                plane: None,
            }],
            springs: vec![Spring {
                label: "K42".into(),
                body: "a".into(),
                other: "base".into(),
                stiffness: 2000.0,
                anchor_a: [0.1, 0.0, 0.0],
                anchor_b: [0.0, 0.1, 0.0],
                plane: None,
            }],
        }
    }

    #[test]
    fn idle_by_the_weight_of_the_moving_mass() {
        // Moving mass 1000 kg: the threshold is 1e-3 · 1000 kg = 1 kg of weight, i.e.
        // 9.81 N at g = 9.81.
        let p = params(0.00054); // the Dmax 3 crumb: 0.54 g
        let peaks = |f: f64| PracticalFigures {
            springs: vec![SpringPeak {
                label: "K42".into(),
                elongation: f / 2000.0,
                force: f,
                shortest: None,
            }],
            ..PracticalFigures::new(&p, Some(1000.0), vec![])
        };
        assert_eq!(
            idle_elements(&p, Some(&peaks(500.0)), Some(1000.0), 9.81),
            vec!["m6".to_string()]
        );
        assert_eq!(
            idle_elements(&params(0.99), Some(&peaks(500.0)), Some(1000.0), 9.81),
            vec!["m6".to_string()]
        );
        // 1.01 kg is above the threshold: installed.
        let heavy = params(1.01);
        assert!(idle_elements(&heavy, Some(&peaks(500.0)), Some(1000.0), 9.81).is_empty());
        // A spring of 9 N peak (below 9.81 N) idles; at 10 N it works.
        assert_eq!(
            idle_elements(&heavy, Some(&peaks(9.0)), Some(1000.0), 9.81),
            vec!["K42".to_string()]
        );
        assert!(idle_elements(&heavy, Some(&peaks(10.0)), Some(1000.0), 9.81).is_empty());
        // No moving mass: no scale, nothing idle.
        assert!(idle_elements(&p, None, None, 9.81).is_empty());
    }

    #[test]
    fn bounds_at_either_end() {
        assert_eq!(on_bound(0.5, Some([0.0, 0.5])), Some(OnBound::Upper));
        assert_eq!(on_bound(0.5 - 1e-8, Some([0.0, 0.5])), Some(OnBound::Upper));
        assert_eq!(on_bound(0.49, Some([0.0, 0.5])), None);
        assert_eq!(on_bound(1000.0, Some([1000.0, 1e4])), Some(OnBound::Lower));
        assert_eq!(on_bound(1000.5, Some([1000.0, 1e4])), None);
        assert_eq!(on_bound(0.3, None), None);
        assert_eq!(on_bound(0.3, Some([0.0, f64::INFINITY])), None);
    }
}
