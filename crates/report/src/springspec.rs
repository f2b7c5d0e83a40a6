//! What to order for each spring: its stiffness, the range of its installed length, its peak
//! force, and two practical realisations of a zero-free-length spring.
//!
//! The model's springs have zero free length: force `K·L` at anchor distance `L`. No helical
//! spring does that by itself; two standard arrangements do, over the lengths it must work at
//! (the shortest and longest anchor distances measured, [`crate::practical::SpringPeak`]):
//!
//! * **Cable and pulley.** An ordinary extension spring of rate `K` sits beyond a pulley at
//!   anchor b; a cable runs from anchor a over the pulley to the spring, so the spring extends
//!   by exactly the anchor distance (pulley radius and cable stretch neglected). The spring
//!   works between extensions `L_min` and `L_max` beyond its own free length (its *stroke* is
//!   `L_max − L_min`); the cable carries up to `K·L_max`; the pulley's axle up to twice that
//!   (the cable turning through 180°, the worst case).
//! * **Pre-tensioned extension spring.** A helical extension spring coiled with initial
//!   tension `F₀` and body length `L₀` pulls `F₀ + K·(L − L₀)`, which is `K·L` when
//!   `F₀ = K·L₀`. Its body must fit between the anchors at the shortest distance
//!   (`L₀ ≤ L_min`), and the initial tension a coiling machine can put in is limited; we
//!   assume at most [`MAX_INITIAL_TENSION_SHARE`] of the peak force. So
//!   `L₀ = min(L_min, share·L_max)`, `F₀ = K·L₀`, and the spring extends from `L_min − L₀` to
//!   `L_max − L₀`. When `L₀` would be below [`MIN_BODY_SHARE`] of `L_max` (the anchors come
//!   nearly together) there is no room for a body: cable and pulley only.
//!
//! **Size.** Either way the wire stores `½·K·L_max²` at the peak (a pre-tensioned spring holds
//! its initial tension as wire stress too). A helical spring's wire, in torsion, stores at most
//! `τ²/(4·G·K_w²)` per unit volume; with `τ` = 700 MPa (a working shear stress of spring
//! steel), `G` = 79.3 GPa, `K_w` = 1.2 (the Wahl curvature factor of a spring index near 6)
//! and 7,850 kg/m³ that is [`WIRE_ENERGY_PER_KG`] ≈ 137 J per kg of wire: the least wire
//! mass is `½·K·L_max² / 137 J/kg`. These are assumptions of a first sizing, stated in the
//! README; a spring maker's catalogue decides.

use serde::{Deserialize, Serialize};

use crate::parameters::Spring;
use crate::practical::SpringPeak;
use crate::variant::VariantRecord;

/// Largest initial tension assumed achievable, as a share of the peak force.
pub const MAX_INITIAL_TENSION_SHARE: f64 = 0.25;
/// Below this share of the longest length, a pre-tensioned spring's body has no room.
pub const MIN_BODY_SHARE: f64 = 0.05;
/// Shear stress, shear modulus, Wahl factor and density of the wire (see the module doc).
pub const WIRE_SHEAR_STRESS: f64 = 700e6;
pub const WIRE_SHEAR_MODULUS: f64 = 79.3e9;
pub const WAHL_FACTOR: f64 = 1.2;
pub const WIRE_DENSITY: f64 = 7850.0;
/// Energy a helical spring's wire can store per kg, J/kg (≈ 137).
pub const WIRE_ENERGY_PER_KG: f64 = WIRE_SHEAR_STRESS * WIRE_SHEAR_STRESS
    / (4.0 * WIRE_SHEAR_MODULUS * WAHL_FACTOR * WAHL_FACTOR * WIRE_DENSITY);

/// A pre-tensioned extension spring realising a zero-free-length spring.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PreTensioned {
    /// Body (free) length, m.
    pub body_length: f64,
    /// Initial tension, N.
    pub initial_tension: f64,
    /// Extension beyond the body length at the shortest and longest anchor distance, m.
    pub extension: [f64; 2],
}

/// The specification of one spring.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SpringSpec {
    pub label: String,
    /// N/m.
    pub stiffness: f64,
    /// Shortest and longest anchor distance, m.
    pub length: [f64; 2],
    /// Force at those lengths, N.
    pub force: [f64; 2],
    /// `L_max − L_min`, m.
    pub stroke: f64,
    /// `½·K·L_max²`, J.
    pub energy: f64,
    /// Least wire mass, kg.
    pub wire_mass: f64,
    /// Largest load on the pulley's axle of the cable arrangement, N.
    pub pulley_load: f64,
    /// `None` when the anchors come too close together for a spring body.
    pub pre_tensioned: Option<PreTensioned>,
}

impl SpringSpec {
    /// The specification of a spring of stiffness `k` (N/m) working between `shortest` and
    /// `longest` (m).
    pub fn new(label: &str, k: f64, shortest: f64, longest: f64) -> SpringSpec {
        let (lo, hi) = (shortest.max(0.0), longest.max(shortest.max(0.0)));
        let body = lo.min(MAX_INITIAL_TENSION_SHARE * hi);
        let energy = 0.5 * k * hi * hi;
        SpringSpec {
            label: label.to_string(),
            stiffness: k,
            length: [lo, hi],
            force: [k * lo, k * hi],
            stroke: hi - lo,
            energy,
            wire_mass: energy / WIRE_ENERGY_PER_KG,
            pulley_load: 2.0 * k * hi,
            pre_tensioned: (hi > 0.0 && body >= MIN_BODY_SHARE * hi).then_some(PreTensioned {
                body_length: body,
                initial_tension: k * body,
                extension: [lo - body, hi - body],
            }),
        }
    }

    /// From a spring's parameters and its measured peak (`None` without a shortest length:
    /// results written before it was recorded).
    pub fn of(s: &Spring, peak: &SpringPeak) -> Option<SpringSpec> {
        Some(SpringSpec::new(
            &s.label,
            s.stiffness,
            peak.shortest?,
            peak.elongation,
        ))
    }

    /// The specifications of a variant's springs, in the order of its parameters.
    pub fn of_variant(v: &VariantRecord) -> Vec<SpringSpec> {
        let (Some(p), Some(f)) = (&v.parameters, &v.practical) else {
            return Vec::new();
        };
        p.springs
            .iter()
            .filter_map(|s| {
                let peak = f.springs.iter().find(|x| x.label == s.label)?;
                SpringSpec::of(s, peak)
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_palletizer_spring_by_hand() {
        // K = 5,660 N/m between 300 mm and 1,054 mm.
        let s = SpringSpec::new("K42", 5660.0, 0.300, 1.054);
        assert!((s.force[1] - 5965.64).abs() < 1e-6); // 5660 · 1.054
        assert!((s.stroke - 0.754).abs() < 1e-12);
        // ½ · 5660 · 1.054² = 3143.89 J
        assert!((s.energy - 3143.89228).abs() < 1e-4);
        // 700e6² / (4 · 79.3e9 · 1.44 · 7850) = 136.657 J/kg
        assert!((WIRE_ENERGY_PER_KG - 136.6566).abs() < 1e-3);
        assert!((s.wire_mass - 3143.89228 / WIRE_ENERGY_PER_KG).abs() < 1e-9);
        assert!((s.pulley_load - 2.0 * 5965.64).abs() < 1e-6);
        // The body: min(300 mm, 0.25 · 1054 mm = 263.5 mm) = 263.5 mm; F0 = 5660 · 0.2635.
        let p = s.pre_tensioned.unwrap();
        assert!((p.body_length - 0.2635).abs() < 1e-12);
        assert!((p.initial_tension - 1491.41).abs() < 1e-6);
        assert!((p.extension[0] - 0.0365).abs() < 1e-12);
        assert!((p.extension[1] - 0.7905).abs() < 1e-12);
        // Force check: F0 + K·(L − L0) = K·L at both ends.
        for (l, e) in [(0.300, p.extension[0]), (1.054, p.extension[1])] {
            assert!((p.initial_tension + 5660.0 * e - 5660.0 * l).abs() < 1e-6);
        }
    }

    #[test]
    fn no_body_when_the_anchors_meet() {
        // The anchors come to 10 mm of each other, 10/1000 < 5 %: cable and pulley only.
        let s = SpringSpec::new("K1", 1000.0, 0.010, 1.0);
        assert!(s.pre_tensioned.is_none());
        let s = SpringSpec::new("K1", 1000.0, 0.060, 1.0);
        assert!((s.pre_tensioned.unwrap().body_length - 0.060).abs() < 1e-15);
    }
}
