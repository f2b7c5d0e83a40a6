//! Per-element overrides of the bounds: applied to the right element, kept exactly when they fix
//! a value, and rejected with the field path when malformed.

mod common;

use counterpoise_optimise::{Context, OptimiseOptions, Status};

fn pendulum(overrides: serde_json::Value) -> serde_json::Value {
    let mut json = common::case_json("pendulum.json");
    let b = &mut json["balancing"];
    b.as_object_mut().unwrap().remove("springs");
    b["counterweights"]["shape"] =
        serde_json::json!({ "cylinder": { "radius_to_thickness": 1.0, "density": 7850 } });
    b["bounds"] = serde_json::json!({ "mass": [1, 100], "radius": [0, 0.5] });
    b["overrides"] = overrides;
    json
}

#[test]
fn a_fixed_distance_is_met_exactly() {
    // Balance needs m·r = M·L/2 = 1 kg·m: |r| = 0.125 m forces m = 8 kg.
    let json = pendulum(serde_json::json!([{ "element": "rod", "radius": [0.125, 0.125] }]));
    let model = common::model(&json);
    let (_, results) = common::optimise(&model, &[&["m1"]], &OptimiseOptions::default());
    let v = &results[0];
    assert_eq!(v.status, Status::Feasible, "{:?}", v.reason);
    let c = &v.counterweights[0];
    assert!(
        (c.radius() - 0.125).abs() <= 1e-9 * 0.125,
        "radius {}",
        c.radius()
    );
    assert!((c.mass - 8.0).abs() <= 1e-8, "mass {}", c.mass);
}

#[test]
fn a_fixed_mass_is_met_exactly() {
    let json = pendulum(serde_json::json!([{ "element": "m1", "mass": [5, 5] }]));
    let model = common::model(&json);
    let (_, results) = common::optimise(&model, &[&["m1"]], &OptimiseOptions::default());
    let v = &results[0];
    assert_eq!(v.status, Status::Feasible, "{:?}", v.reason);
    assert!((v.counterweights[0].mass - 5.0).abs() <= 1e-9 * 5.0);
    assert!((v.counterweights[0].radius() - 0.2).abs() <= 1e-9);
}

#[test]
fn malformed_overrides_name_the_field() {
    let json = pendulum(serde_json::json!([
        { "element": "m9", "mass": [0, 1] },
        { "element": "m1", "stiffness": [0, 1] },
        { "element": "m1", "mass": [2, 1] },
        { "mass": [0, 1] },
        "m1"
    ]));
    let model = common::model(&json);
    let err = Context::new(&model, None)
        .err()
        .expect("overrides rejected")
        .to_string();
    for needle in [
        "balancing.overrides[0].element",
        "balancing.overrides[1].stiffness",
        "balancing.overrides[2].mass",
        "balancing.overrides[3].element",
        "balancing.overrides[4]",
    ] {
        assert!(err.contains(needle), "missing {needle} in:\n{err}");
    }
}

#[test]
fn spring_overrides_by_body_pair() {
    let mut json = common::case_json("two_link.json");
    json["balancing"]["overrides"] = serde_json::json!([
        { "element": ["link2", "link1"], "anchor_b": [0.1, 0.3] },
        { "element": "K21", "stiffness": [10, 20] }
    ]);
    let model = common::model(&json);
    let ctx = Context::new(&model, None).unwrap();
    let k = ctx
        .catalogue
        .entries
        .iter()
        .position(|e| e.label == "K21")
        .unwrap();
    let b = ctx.bounds.spring(k);
    assert_eq!(b.anchor_b, [0.1, 0.3]);
    assert_eq!(b.stiffness, [10.0, 20.0]);
    let k10 = ctx
        .catalogue
        .entries
        .iter()
        .position(|e| e.label == "K10")
        .unwrap();
    assert_ne!(ctx.bounds.spring(k10).anchor_b, [0.1, 0.3]);
}
