//! Verification of a witness by sampling the physical potential energy.
//!
//! Independent of the lifted algebra on purpose: the energy is evaluated from the numeric body
//! poses and the physical parameters (`−m g·(p + R r)`, `(K/2)|p_i + R_i a − p_s − R_s b|²`), so a
//! mistake in the coefficient bookkeeping cannot certify itself.

use counterpoise_symbolic::Point;
use serde::Serialize;

use crate::energy::MechanismEnergy;
use crate::realize::Witness;
use counterpoise_model::sampling::SplitMix64;

/// Configurations sampled per verification (the issue asks for at least 200).
pub const VERIFY_SAMPLES: usize = 256;
/// Largest accepted spread of the balanced energy relative to the unbalanced spread.
pub const VERIFY_TOL: f64 = 1e-9;

/// The result of sampling one witness.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Verification {
    /// (max − min) of the total energy over the samples divided by that of the unbalanced one.
    pub residual: f64,
    pub samples: usize,
    pub passed: bool,
}

/// Random configurations inside the coordinate ranges (deterministic).
pub fn sample_configurations(energy: &MechanismEnergy, count: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = SplitMix64::new(seed);
    (0..count)
        .map(|_| {
            energy
                .ranges
                .iter()
                .map(|&(lo, hi)| rng.uniform(lo, hi))
                .collect()
        })
        .collect()
}

fn apply(r: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| r[i][0] * v[0] + r[i][1] * v[1] + r[i][2] * v[2])
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

type Pose = ([[f64; 3]; 3], [f64; 3]);

/// The verification configurations with every body pose and the unbalanced energy evaluated
/// once, shared by all witnesses of a search.
#[derive(Clone, Debug)]
pub struct VerificationSet {
    poses: Vec<Vec<Pose>>,
    /// Body names in the order of each sample's poses.
    bodies: Vec<String>,
    unbalanced: Vec<f64>,
    gravity: [f64; 3],
    unbalanced_spread: f64,
}

impl VerificationSet {
    /// Samples [`VERIFY_SAMPLES`] configurations (fixed seed) and evaluates the mechanism there.
    pub fn new(energy: &MechanismEnergy) -> VerificationSet {
        let mut poses = Vec::with_capacity(VERIFY_SAMPLES);
        let mut unbalanced = Vec::with_capacity(VERIFY_SAMPLES);
        for q in sample_configurations(energy, VERIFY_SAMPLES, 0x7e57_0fba_1a5c_e5e5) {
            let at = Point::new(&q, &energy.kinds);
            poses.push(
                (0..energy.bodies.len())
                    .map(|i| energy.pose(i, &at))
                    .collect(),
            );
            unbalanced.push(energy.unbalanced.eval(&at));
        }
        let (lo, hi) = spread(&unbalanced);
        VerificationSet {
            poses,
            bodies: energy.bodies.iter().map(|b| b.name.clone()).collect(),
            unbalanced,
            gravity: energy.gravity,
            unbalanced_spread: hi - lo,
        }
    }

    /// Samples the witness's total energy over the set.
    pub fn verify(&self, witness: &Witness) -> Verification {
        let totals: Vec<f64> = self
            .poses
            .iter()
            .zip(&self.unbalanced)
            .map(|(poses, v_ub)| v_ub + element_energy(poses, &self.bodies, self.gravity, witness))
            .collect();
        let (lo, hi) = spread(&totals);
        let residual = if self.unbalanced_spread > 0.0 {
            (hi - lo) / self.unbalanced_spread
        } else {
            hi - lo
        };
        Verification {
            residual,
            samples: totals.len(),
            passed: residual.is_finite() && residual <= VERIFY_TOL,
        }
    }
}

fn spread(values: &[f64]) -> (f64, f64) {
    values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        })
}

/// Potential energy of the witness's elements alone, given every body's numeric pose (`bodies`
/// names them, in the same order). An element on a body that is not there has no energy: NaN,
/// which no verification passes.
pub fn element_energy(
    poses: &[Pose],
    bodies: &[String],
    gravity: [f64; 3],
    witness: &Witness,
) -> f64 {
    let pose = |name: &str| bodies.iter().position(|b| b == name).map(|i| &poses[i]);
    let mut total = 0.0;
    for cw in &witness.counterweights {
        let Some((r, p)) = pose(&cw.body) else {
            return f64::NAN;
        };
        let offset = apply(r, cw.offset);
        let position = [p[0] + offset[0], p[1] + offset[1], p[2] + offset[2]];
        total -= cw.mass * dot(gravity, position);
    }
    for spring in &witness.springs {
        let Some((r_i, p_i)) = pose(&spring.body) else {
            return f64::NAN;
        };
        let a = apply(r_i, spring.anchor_a);
        let b = if spring.to_base() {
            spring.anchor_b
        } else {
            let Some((r_s, p_s)) = pose(&spring.other) else {
                return f64::NAN;
            };
            let b = apply(r_s, spring.anchor_b);
            [p_s[0] + b[0], p_s[1] + b[1], p_s[2] + b[2]]
        };
        let d: [f64; 3] = std::array::from_fn(|k| p_i[k] + a[k] - b[k]);
        total += 0.5 * spring.stiffness * dot(d, d);
    }
    total
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::energy::BodyFrame;
    use crate::realize::{Counterweight, Spring};
    use counterpoise_symbolic::{LinearAngle, PolyMat3, PolyVec3, TrigPoly, VarKind};

    /// A turntable: one body turning about z, with gravity along z. Its unbalanced energy is zero
    /// at every angle, so no spread can be measured relative to it.
    fn turntable() -> MechanismEnergy {
        MechanismEnergy {
            kinds: vec![VarKind::Angle],
            ranges: vec![(-3.0, 3.0)],
            gravity: [0.0, 0.0, -9.81],
            bodies: vec![BodyFrame {
                name: "table".into(),
                rotation: PolyMat3::rot_z(&LinearAngle::coordinate(0)),
                origin: PolyVec3::zero(),
            }],
            unbalanced: TrigPoly::zero(),
            exact: Err("built by hand".into()),
            surd: Err("built by hand".into()),
        }
    }

    #[test]
    fn element_energy_matches_a_hand_calculation() {
        // Body 0 turned a quarter turn about z and moved to (1, 2, 3); body 1 unturned at
        // (0, 0, 1). Gravity (−1, −2, −3) has a component along every axis.
        let quarter = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
        let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let poses = [(quarter, [1.0, 2.0, 3.0]), (identity, [0.0, 0.0, 1.0])];
        let gravity = [-1.0, -2.0, -3.0];
        // 2 kg at (0.5, 0.25, −1) on body 0: R·r = (−0.25, 0.5, −1), world (0.75, 2.5, 2),
        // g·x = −0.75 − 5 − 6 = −11.75, energy −m g·x = 23.5 J.
        let bodies = ["zero".to_string(), "one".to_string()];
        let counterweight = Counterweight {
            label: "m1".into(),
            body: "zero".into(),
            mass: 2.0,
            offset: [0.5, 0.25, -1.0],
            plane: None,
        };
        // K = 4 from (1, 0, 0) on body 0 — world (1, 2, 3) + (0, 1, 0) = (1, 3, 3) — to (0, 0, 2)
        // on body 1 — world (0, 0, 3): d = (1, 3, 0), |d|² = 10, energy 4/2·10 = 20 J.
        let between = Spring {
            label: "K12".into(),
            body: "zero".into(),
            other: "one".into(),
            stiffness: 4.0,
            anchor_a: [1.0, 0.0, 0.0],
            anchor_b: [0.0, 0.0, 2.0],
            plane: None,
        };
        // K = 3 from (1, 1, 0) on body 1 — world (1, 1, 1) — to the base point (1, 1, −1):
        // d = (0, 0, 2), energy 3/2·4 = 6 J.
        let to_base = Spring {
            label: "K20".into(),
            body: "one".into(),
            other: "base".into(),
            stiffness: 3.0,
            anchor_a: [1.0, 1.0, 0.0],
            anchor_b: [1.0, 1.0, -1.0],
            plane: None,
        };
        let alone = |counterweights: Vec<Counterweight>, springs: Vec<Spring>| {
            element_energy(
                &poses,
                &bodies,
                gravity,
                &Witness {
                    counterweights,
                    springs,
                },
            )
        };
        assert_eq!(alone(vec![counterweight.clone()], vec![]), 23.5);
        assert_eq!(alone(vec![], vec![between.clone()]), 20.0);
        assert_eq!(alone(vec![], vec![to_base.clone()]), 6.0);
        assert_eq!(
            alone(vec![counterweight.clone()], vec![between, to_base.clone()]),
            23.5 + 20.0 + 6.0
        );
        // An element on a body the mechanism does not have is never balanced.
        let elsewhere = Counterweight {
            body: "two".into(),
            ..counterweight
        };
        assert!(alone(vec![elsewhere], vec![]).is_nan());
        let to_nowhere = Spring {
            other: "two".into(),
            ..to_base
        };
        assert!(alone(vec![], vec![to_nowhere]).is_nan());
    }

    #[test]
    fn a_mechanism_without_energy_swing_is_verified_by_the_absolute_spread() {
        let checks = VerificationSet::new(&turntable());
        // Hand calculation: a counterweight of 2 kg at (0.3, 0, 0.5) in the table frame stays at
        // height 0.5 m whatever the angle, so its energy is −m·g·z = 2·9.81·0.5 = 9.81 J at every
        // sample, and the total energy does not spread at all.
        let witness = Witness {
            counterweights: vec![Counterweight {
                label: "m1".into(),
                body: "table".into(),
                mass: 2.0,
                offset: [0.3, 0.0, 0.5],
                plane: None,
            }],
            springs: Vec::new(),
        };
        let verification = checks.verify(&witness);
        assert_eq!(verification.residual, 0.0);
        assert_eq!(verification.samples, VERIFY_SAMPLES);
        assert!(verification.passed);
        // Nothing installed: the energy is zero everywhere, which balances too.
        let nothing = checks.verify(&Witness::default());
        assert_eq!(nothing.residual, 0.0);
        assert!(nothing.passed);
    }
}
