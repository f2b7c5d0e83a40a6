//! What building a variant takes: added mass (kg and share of the moving mass), element count,
//! the largest counterweight offset, and the largest force and stretch of its springs.
//!
//! These are the figures a designer weighs once several variants are equivalent on the motor
//! indicators (the paper chose its variant as "a hybrid adding under 10 % mass"). Masses and
//! offsets come straight from the optimised parameters. Spring figures need the kinematics, so
//! the caller (the `run` command) measures each spring's length at a set of configurations and
//! passes the peaks in: a zero-free-length spring's stretch *is* its length, and its force is
//! `K·length`.

use serde::{Deserialize, Serialize};

use crate::parameters::PhysicalParameters;

/// Peak stretch and force of one spring over the configurations the caller checked.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SpringPeak {
    pub label: String,
    /// Largest anchor-to-anchor distance, m (= the stretch: the free length is zero).
    pub elongation: f64,
    /// `K · elongation`, N.
    pub force: f64,
    /// Smallest anchor-to-anchor distance over the same configurations, m (absent in results
    /// written before it was recorded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shortest: Option<f64>,
}

impl SpringPeak {
    /// The peak of a spring of stiffness `stiffness` (N/m) whose anchor distance was measured at
    /// each of `lengths` (m).
    pub fn from_lengths(
        label: &str,
        stiffness: f64,
        lengths: impl IntoIterator<Item = f64>,
    ) -> SpringPeak {
        let finite: Vec<f64> = lengths.into_iter().filter(|l| l.is_finite()).collect();
        let elongation = finite.iter().copied().fold(0.0f64, f64::max);
        SpringPeak {
            label: label.to_string(),
            elongation,
            force: stiffness * elongation,
            shortest: finite.iter().copied().reduce(f64::min),
        }
    }
}

/// Practical figures of one variant (see the module doc).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PracticalFigures {
    /// Sum of the counterweight masses, kg (the springs are massless in the model).
    pub added_mass: f64,
    /// `added_mass` as a percentage of the mechanism's moving mass (absent when it is unknown).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub added_mass_percent: Option<f64>,
    /// Counterweights plus springs.
    pub elements: usize,
    /// Largest distance of a counterweight's centre of mass from its body origin, m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub peak_counterweight_offset: Option<f64>,
    /// Largest spring force over the springs and the checked configurations, N.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub peak_spring_force: Option<f64>,
    /// Largest spring stretch, m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub peak_spring_elongation: Option<f64>,
    /// Per spring, in the order of the parameters.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub springs: Vec<SpringPeak>,
}

impl PracticalFigures {
    /// The figures of a variant with parameters `p`, given the mechanism's moving mass (kg)
    /// and its springs' measured peaks.
    pub fn new(
        p: &PhysicalParameters,
        moving_mass: Option<f64>,
        springs: Vec<SpringPeak>,
    ) -> PracticalFigures {
        // A fold from +0: `sum` of no masses is −0.0, which would print as "-0.0 %".
        let added_mass = p.counterweights.iter().fold(0.0, |a, c| a + c.mass);
        let norm = |v: [f64; 3]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
        let max = |it: &mut dyn Iterator<Item = f64>| it.reduce(f64::max);
        PracticalFigures {
            added_mass,
            added_mass_percent: moving_mass
                .filter(|m| *m > 0.0 && m.is_finite())
                .map(|m| added_mass / m * 100.0),
            elements: p.counterweights.len() + p.springs.len(),
            peak_counterweight_offset: max(&mut p.counterweights.iter().map(|c| norm(c.offset))),
            peak_spring_force: max(&mut springs.iter().map(|s| s.force)),
            peak_spring_elongation: max(&mut springs.iter().map(|s| s.elongation)),
            springs,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::results::{Counterweight, Spring};

    #[test]
    fn figures_of_a_hybrid_by_hand() {
        let p = PhysicalParameters {
            counterweights: vec![Counterweight {
                label: "m4".into(),
                body: "arm".into(),
                mass: 30.0,
                offset: [0.3, -0.4, 0.0], // |r| = 0.5 m (3-4-5)
                plane: None,
            }],
            springs: vec![Spring {
                label: "K43".into(),
                body: "arm".into(),
                other: "forearm".into(),
                stiffness: 2000.0,
                anchor_a: [0.1, 0.0, 0.0],
                anchor_b: [0.0, 0.2, 0.0],
                plane: None,
            }],
        };
        // lengths 0.25, 0.6, 0.4 m: the peak is 0.6 m, 2000 N/m · 0.6 m = 1200 N
        let peak = SpringPeak::from_lengths("K43", 2000.0, [0.25, 0.6, f64::NAN, 0.4]);
        assert_eq!(peak.elongation, 0.6);
        assert_eq!(peak.shortest, Some(0.25));
        assert!((peak.force - 1200.0).abs() < 1e-9);
        let f = PracticalFigures::new(&p, Some(120.0), vec![peak]);
        assert_eq!(f.added_mass, 30.0);
        assert_eq!(f.added_mass_percent, Some(25.0)); // 30 of 120 kg
        assert_eq!(f.elements, 2);
        assert!((f.peak_counterweight_offset.unwrap() - 0.5).abs() < 1e-15);
        assert!((f.peak_spring_force.unwrap() - 1200.0).abs() < 1e-9);
        assert_eq!(f.peak_spring_elongation, Some(0.6));
        let none = PracticalFigures::new(&PhysicalParameters::default(), None, vec![]);
        assert_eq!(none.added_mass, 0.0);
        assert!(none.added_mass.is_sign_positive());
        assert_eq!(none.added_mass_percent, None);
        assert_eq!(none.peak_spring_force, None);
        assert_eq!(none.peak_counterweight_offset, None);
    }
}
