//! A 3R spatial chain (yaw on the base, two pitch joints; gravity along −z) with counterweights
//! at a fixed distance of 0.2 m and zero-free-length springs: the case where feasible variants
//! used to be discarded after a numerical or local-search failure.
//!
//! Checks, each against an independent derivation:
//! - every variant the optimiser calls feasible is balanced: its total potential energy,
//!   computed here from the chain's own kinematics (rotation matrices written out), is the same
//!   at random configurations;
//! - the fixed distance holds and every element is within its bounds;
//! - a discard is only ever a proved one, and its reason names the binding bound with the value
//!   a hand calculation gives (m2 + m3: 7.5 kg at 0.2 m);
//! - nothing is discarded because a solver or a local search gave up.

mod common;

use counterpoise_model::Case;
use counterpoise_optimise::{OptimiseOptions, OptimisedVariant, Status};
use nalgebra::{Matrix3, Vector3};

fn model() -> counterpoise_model::Model {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/spatial_leg.json");
    Case::from_path(&path).expect("the spatial leg loads")
}

fn rot_z(q: f64) -> Matrix3<f64> {
    let (s, c) = q.sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

fn rot_y(q: f64) -> Matrix3<f64> {
    let (s, c) = q.sin_cos();
    Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)
}

/// World poses (R, o) of hip, thigh and shank at `q`, from the case's pose lists.
fn poses(q: [f64; 3]) -> [(Matrix3<f64>, Vector3<f64>); 3] {
    let r1 = rot_z(q[0]);
    let o1 = Vector3::zeros();
    let r2 = r1 * rot_y(q[1]);
    let o2 = o1 + r1 * Vector3::new(0.0, 0.0, 0.2);
    let r3 = r2 * rot_y(q[2]);
    let o3 = o2 + r2 * Vector3::new(0.5, 0.0, 0.0);
    [(r1, o1), (r2, o2), (r3, o3)]
}

fn body(name: &str) -> Option<usize> {
    ["hip", "thigh", "shank"].iter().position(|b| *b == name)
}

/// Gravity plus spring energy of the bodies, counterweights and springs at `q` (J).
fn energy(v: &OptimisedVariant, q: [f64; 3]) -> f64 {
    let g = 9.81;
    let p = poses(q);
    let links = [
        (1.5, Vector3::new(0.0, 0.0, 0.1)),
        (2.0, Vector3::new(0.25, 0.0, 0.0)),
        (1.0, Vector3::new(0.2, 0.0, 0.0)),
    ];
    let mut e = 0.0;
    for (k, (m, c)) in links.iter().enumerate() {
        e += m * g * (p[k].1 + p[k].0 * c).z;
    }
    for c in &v.counterweights {
        let k = body(&c.body).unwrap();
        e += c.mass * g * (p[k].1 + p[k].0 * Vector3::from(c.offset)).z;
    }
    for s in &v.springs {
        let k = body(&s.body).unwrap();
        let a = p[k].1 + p[k].0 * Vector3::from(s.anchor_a);
        let b = match body(&s.other) {
            Some(o) => p[o].1 + p[o].0 * Vector3::from(s.anchor_b),
            None => Vector3::from(s.anchor_b),
        };
        e += 0.5 * s.stiffness * (a - b).norm_squared();
    }
    e
}

#[test]
fn feasible_variants_are_balanced_within_bounds_and_discards_are_proved() {
    let model = model();
    let (_, results) = common::optimise(&model, &[], &OptimiseOptions::default());
    let mut feasible = 0;
    for v in &results {
        let name = v.elements.join(" + ");
        match v.status {
            Status::Feasible => {
                feasible += 1;
                // Balance: the same energy at pseudo-random configurations in the ranges.
                let mut seed = 12345u64;
                let mut next = || {
                    seed = seed
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
                };
                let e0 = energy(v, [0.0; 3]);
                let scale = 4.5 * 9.81 * 0.7;
                for _ in 0..8 {
                    let q = [2.0 * next(), 1.5 * next(), 2.0 * next()];
                    let e = energy(v, q);
                    assert!(
                        (e - e0).abs() <= 1e-8 * scale,
                        "{name}: energy {e} at {q:?}, {e0} at 0"
                    );
                }
                for c in &v.counterweights {
                    assert!(
                        (c.radius() - 0.2).abs() <= 1e-9,
                        "{name}: |r| = {}",
                        c.radius()
                    );
                    assert!(
                        c.mass > 0.0 && c.mass <= 5.0 * (1.0 + 1e-9),
                        "{name}: m = {}",
                        c.mass
                    );
                }
                for s in &v.springs {
                    assert!(s.stiffness > 0.0 && s.stiffness <= 2000.0 * (1.0 + 1e-9));
                    let (a, b) = (Vector3::from(s.anchor_a), Vector3::from(s.anchor_b));
                    assert!(a.norm() <= 0.6 * (1.0 + 1e-9) && b.norm() <= 0.6 * (1.0 + 1e-9));
                }
            }
            Status::Discarded => {
                let reason = v.reason.clone().unwrap_or_default();
                assert!(
                    reason.contains("would need") || reason.contains("cannot all be met"),
                    "{name} discarded without a proof: {reason}"
                );
                assert!(
                    !reason.contains("clarabel"),
                    "{name}: solver jargon: {reason}"
                );
                assert!(
                    !reason.contains("peak"),
                    "{name}: the case has no peak limits"
                );
            }
            Status::Undecided => {
                let reason = v.reason.clone().unwrap_or_default();
                assert!(!reason.is_empty(), "{name}: undecided without a reason");
            }
            other => panic!("{name}: the optimiser gave {other:?}, not one of its verdicts"),
        }
    }
    // Variants with a counter-mass and two springs, balanced by hand-checkable arrangements.
    for wanted in [
        ["m3", "K30", "K31"],
        ["m3", "K20", "K31"],
        ["m1", "K30", "K31"],
    ] {
        let v = results
            .iter()
            .find(|v| {
                v.elements.len() == 3 && wanted.iter().all(|w| v.elements.iter().any(|e| e == w))
            })
            .unwrap_or_else(|| panic!("{wanted:?} is balanced"));
        assert_eq!(v.status, Status::Feasible, "{wanted:?}: {:?}", v.reason);
    }
    assert!(feasible > 0);
}

#[test]
fn a_discard_names_the_bound_and_the_value_a_hand_calculation_gives() {
    // Shank (1 kg, CoM 0.2 m past J3) balanced about J3 by m3 at 0.2 m: m3 = 1 kg. Then about
    // J2 the thigh (2 kg at 0.25 m) and the shank with m3 (2 kg at 0.5 m) need
    // m2·r2 = 0.5 + 1.0 = 1.5 kg·m: at |r2| = 0.2 m that is m2 = 7.5 kg (bound 5 kg), or with
    // m2 ≤ 5 kg an offset of 0.3 m (bound 0.2 m).
    let model = model();
    let (_, results) = common::optimise(&model, &[&["m2", "m3"]], &OptimiseOptions::default());
    let v = &results[0];
    assert_eq!(v.status, Status::Discarded, "{:?}", v.reason);
    let reason = v.reason.clone().unwrap();
    let number_after = |text: &str| -> f64 {
        let at = reason
            .find(text)
            .unwrap_or_else(|| panic!("`{text}` in {reason}"))
            + text.len();
        reason[at..]
            .split_whitespace()
            .next()
            .unwrap()
            .parse()
            .unwrap()
    };
    let mass = number_after("m2 would need a mass of at least ");
    assert!((7.5 * 0.98..=7.5).contains(&mass), "{reason}");
    let offset = number_after("m2 would need an offset of at least ");
    assert!((0.3 * 0.98..=0.3).contains(&offset), "{reason}");
    assert!(reason.contains("the bound is 5 kg") && reason.contains("the bound is 0.2 m"));
}
