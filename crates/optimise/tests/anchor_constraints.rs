//! Anchor constraints in `balancing.overrides`: a fixed anchor and a box per body-frame axis
//! enter the relaxation, the spring realization and the final check; malformed or
//! contradictory ones are rejected with the field path.
//!
//! The pendulum (m = 2 kg, CoM at c = 0.5 m, g = 9.81) balanced by a zero-free-length spring
//! K10 from base point b to rod point a: the spring energy ½K|R a − b|² contains
//! −K·bᵀR a, and with a on the rod's x axis the gravity energy m g c sin θ cancels exactly
//! when b_x = 0 and K·a_x·b_y = m g c = 9.81 N·m (hand calculation).

mod common;

use counterpoise_optimise::{Context, OptimiseOptions, Status};

fn pendulum_with_spring(overrides: serde_json::Value) -> serde_json::Value {
    let mut json = common::case_json("pendulum.json");
    let b = &mut json["balancing"];
    b.as_object_mut().unwrap().remove("counterweights");
    b["overrides"] = overrides;
    json
}

#[test]
fn a_fixed_anchor_and_a_box_are_met_and_the_spring_balances() {
    let json = pendulum_with_spring(serde_json::json!([
        { "element": "K10", "anchor_a_fixed": [0.1, 0, 0],
          "anchor_b_box": { "y": [0.3, 0.5] } }
    ]));
    let model = common::model(&json);
    let (_, results) = common::optimise(&model, &[&["K10"]], &OptimiseOptions::default());
    let v = &results[0];
    assert_eq!(v.status, Status::Feasible, "{:?}", v.reason);
    let s = &v.springs[0];
    for (k, want) in [0.1, 0.0, 0.0].iter().enumerate() {
        assert!((s.anchor_a[k] - want).abs() <= 1e-9, "a = {:?}", s.anchor_a);
    }
    let by = s.anchor_b[1];
    assert!(
        (0.3 - 1e-9..=0.5 + 1e-9).contains(&by),
        "b = {:?}",
        s.anchor_b
    );
    assert!(s.anchor_b[0].abs() <= 1e-9, "b = {:?}", s.anchor_b);
    let moment = s.stiffness * s.anchor_a[0] * by;
    assert!((moment - 9.81).abs() <= 1e-8 * 9.81, "K·a·b = {moment}");
}

#[test]
fn a_half_space_keeps_the_anchor_on_the_link() {
    // a_x ≥ 0.2 (on the rod, at least 0.2 m from the pivot), b_y ≤ 0.25.
    let json = pendulum_with_spring(serde_json::json!([
        { "element": "K10", "anchor_a_box": { "x": [0.2, null] }, "anchor_b_box": { "y": [null, 0.25] } }
    ]));
    let model = common::model(&json);
    let (_, results) = common::optimise(&model, &[&["K10"]], &OptimiseOptions::default());
    let v = &results[0];
    assert_eq!(v.status, Status::Feasible, "{:?}", v.reason);
    let s = &v.springs[0];
    assert!(s.anchor_a[0] >= 0.2 - 1e-9, "a = {:?}", s.anchor_a);
    assert!(s.anchor_b[1] <= 0.25 + 1e-9, "b = {:?}", s.anchor_b);
    let moment = s.stiffness * (s.anchor_a[0] * s.anchor_b[1] - s.anchor_a[1] * s.anchor_b[0]);
    assert!((moment - 9.81).abs() <= 1e-8 * 9.81, "K·(a×b)_z = {moment}");
}

#[test]
fn malformed_and_contradictory_anchor_constraints_name_the_field() {
    let mut json = common::case_json("pendulum.json");
    json["balancing"]["overrides"] = serde_json::json!([
        { "element": "K10", "anchor_a_box": { "w": [0, 1] } },
        { "element": "K10", "anchor_b_box": { "y": [0.5, 0.2] } },
        { "element": "m1", "anchor_a_fixed": [0.1, 0, 0] },
        { "element": "K10", "anchor_a_fixed": [2.0, 0, 0] },
        { "element": "K10", "anchor_b_box": { "z": [0.1, 0.2] } }
    ]);
    let model = common::model(&json);
    let err = Context::new(&model, None)
        .err()
        .expect("overrides rejected")
        .to_string();
    for needle in [
        "balancing.overrides[0].anchor_a_box: unknown axis `w`",
        "balancing.overrides[1].anchor_b_box: y: lo > hi",
        "balancing.overrides[2].anchor_a_fixed: unknown field for a counterweight",
        // The fixed anchor at 2 m is beyond the default |a| ≤ 1 m.
        "balancing.overrides[4].anchor_a: every point of K10's anchor_a box is at least 2 m",
        // Planar springs: z is 0, outside [0.1, 0.2].
        "balancing.overrides[4].anchor_b: K10's anchors lie in a plane where the z coordinate",
    ] {
        assert!(err.contains(needle), "missing `{needle}` in:\n{err}");
    }
}
