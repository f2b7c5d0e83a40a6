//! The small reference cases and the joint kinds and pose steps the palletizer does not use.

use counterpoise_model::{Case, JointKind, Kinematics, KinematicsError, Model, PayloadMode};
use counterpoise_symbolic::Monomial;
use nalgebra::{DVector, Matrix3, Vector3};
use serde_json::json;

fn case(name: &str) -> Model {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../cases")
        .join(format!("{name}.json"));
    Case::from_path(&path).unwrap_or_else(|e| panic!("{name}: {e}"))
}

#[test]
fn pendulum_energy_and_kinematics() {
    let m = case("pendulum");
    // V = m g (L/2) sin θ with m = 2 kg, L = 1 m.
    let v = m.potential_energy(PayloadMode::InBalance);
    assert_eq!(v.len(), 1);
    assert!((v.coefficient(&Monomial::sine(0)) - 2.0 * 9.81 * 0.5).abs() < 1e-12);
    let kin = Kinematics::new(&m);
    let q = DVector::from_vec(vec![0.4]);
    let motion = kin.body_motion(
        0,
        &q,
        &DVector::from_vec(vec![2.0]),
        &DVector::from_vec(vec![0.0]),
    );
    assert!((motion.angular_velocity - Vector3::new(0.0, 0.0, 2.0)).norm() < 1e-14);
    let u = DVector::from_vec(vec![1.2]);
    let solved = kin.solve_coordinates(&u, &q).unwrap();
    assert!((solved[0] - 1.2).abs() < 1e-12);
    let springs = m.balancing.as_ref().unwrap().springs.as_ref().unwrap();
    assert_eq!(springs.pairs().len(), 1);
}

#[test]
fn two_link_tool_point_and_energy() {
    let m = case("two_link");
    let kin = Kinematics::new(&m);
    let (l1, l2) = (0.8, 0.6);
    for (q1, q2) in [(0.3, -0.7), (-1.2, 2.1), (2.5, 0.4)] {
        let q = DVector::from_vec(vec![q1, q2]);
        let pose = kin.body_pose(1, &q);
        let tip = pose.position + pose.rotation * Vector3::new(l2, 0.0, 0.0);
        let expected = Vector3::new(
            l1 * f64::cos(q1) + l2 * f64::cos(q1 + q2),
            l1 * f64::sin(q1) + l2 * f64::sin(q1 + q2),
            0.0,
        );
        assert!((tip - expected).norm() < 1e-14);
    }
    // V = g [ (m1 L1/2 + (m2 + mt) L1) sin q1 + (m2 L2/2 + mt L2) sin(q1+q2) ] with the tool
    // payload counted (in_balance) and sin(q1+q2) = s1 c2 + c1 s2.
    let g = 9.81;
    let v = m.potential_energy(PayloadMode::InBalance);
    let a = g * (4.0 * 0.4 + 3.5 * 0.8);
    let b = g * (2.5 * 0.3 + 1.0 * 0.6);
    assert!((v.coefficient(&Monomial::sine(0)) - a).abs() < 1e-12);
    let none = m.potential_energy(PayloadMode::None);
    assert!((none.coefficient(&Monomial::sine(0)) - g * (4.0 * 0.4 + 2.5 * 0.8)).abs() < 1e-12);
    let q = [0.3, -0.7];
    let at = m.point(&q);
    let expected = a * q[0].sin() + b * (q[0] + q[1]).sin();
    assert!((v.eval(&at) - expected).abs() < 1e-12);
    // Spring pairs: link1–base, link2–base, link2–link1.
    let pairs = m
        .balancing
        .as_ref()
        .unwrap()
        .springs
        .as_ref()
        .unwrap()
        .pairs();
    assert_eq!(pairs.len(), 3);
}

/// A cart on a rail (length coordinate), a pole on the cart, and a tip on the pole held by each
/// of the remaining joint kinds in turn.
fn cart_pole(tip_joint: serde_json::Value) -> serde_json::Value {
    json!({
        "name": "cart_pole",
        "gravity": [0, 0, -9.81],
        "coordinates": [
            { "name": "s", "kind": "length", "range": [-0.5, 0.5] },
            { "name": "a", "kind": "angle", "range": [-1.0, 1.0] }
        ],
        "bodies": [
            { "name": "cart", "parent": "base", "pose": [ { "translate": ["s", 0, 0.1] } ],
              "mass": 5, "com": [0, 0, 0], "inertia": [0.1, 0.1, 0.1, 0, 0, 0] },
            { "name": "pole", "parent": "cart",
              "pose": [ { "dh": { "d": 0.2, "theta": "a", "a": 0.05, "alpha": "pi/2" } } ],
              "mass": 1, "com": [0, 0, 0.5], "inertia": [0.08, 0.08, 0.001, 0, 0, 0] },
            { "name": "tip", "parent": "pole", "pose": [ { "translate": [0, 0, 1] }, { "rot_x": 0.3 } ],
              "mass": 0 }
        ],
        "joints": [
            { "name": "rail", "kind": "prismatic", "bodies": ["base", "cart"], "point": [0, 0, 0.1], "axis": [2, 0, 0] },
            { "name": "level", "kind": "orientation", "bodies": ["base", "cart"] },
            { "name": "hinge", "kind": "revolute", "bodies": ["cart", "pole"], "point": [0, 0, 0.2], "axis": [0, 0, 1] },
            tip_joint
        ],
        "actuators": [
            { "name": "push", "joint": "rail", "coordinate": "s", "ratio": 0.01 },
            { "name": "turn", "joint": "hinge", "coordinate": "a", "ratio": 0.01 }
        ]
    })
}

#[test]
fn every_joint_kind_validates_on_a_consistent_model() {
    let tips = [
        json!({ "name": "tip", "kind": "fixed", "bodies": ["pole", "tip"], "point": [0, 0, 1] }),
        json!({ "name": "tip", "kind": "spherical", "bodies": ["pole", "tip"], "point": [0, 0, 1] }),
        json!({ "name": "tip", "kind": "universal", "bodies": ["pole", "tip"], "point": [0, 0, 1],
                "axis": [1, 0, 0], "axis2": [0, 1, 0] }),
    ];
    for tip in tips {
        let text = serde_json::to_string(&cart_pole(tip.clone())).unwrap();
        let m = Case::from_json_str(&text).unwrap_or_else(|e| panic!("{tip}: {e}"));
        let j = &m.joints[3];
        // The point in the tip's frame is the tip origin.
        assert!(j.points[1].norm() < 1e-12, "{:?}", j.points);
        if j.kind == JointKind::Universal {
            let axes = j.axes.unwrap();
            // Axis x of the pole seen from the tip rotated by 0.3 rad about x: still x.
            assert!((axes[1] - Vector3::x()).norm() < 1e-12);
        }
    }
    let m = Case::from_json_str(
        &serde_json::to_string(&cart_pole(
            json!({ "name": "tip", "kind": "fixed", "bodies": ["pole", "tip"], "point": [0, 0, 1] }),
        ))
        .unwrap(),
    )
    .unwrap();
    // The rail's axis is normalised and its point seen from the cart sits at the reference s = 0.
    let rail = &m.joints[0];
    assert_eq!(rail.axes.unwrap()[0], Vector3::x());
    assert!((rail.points[1] - Vector3::zeros()).norm() < 1e-12);
}

#[test]
fn dh_step_is_rz_tz_tx_rx() {
    let text = serde_json::to_string(&cart_pole(
        json!({ "name": "tip", "kind": "fixed", "bodies": ["pole", "tip"], "point": [0, 0, 1] }),
    ))
    .unwrap();
    let m = Case::from_json_str(&text).unwrap();
    let kin = Kinematics::new(&m);
    let (s, a) = (0.2, 0.7);
    let pose = kin.body_pose(1, &DVector::from_vec(vec![s, a]));
    // Rz(a)·Tz(0.2)·Tx(0.05)·Rx(π/2), after the cart's translation (s, 0, 0.1).
    let rz = Matrix3::new(a.cos(), -a.sin(), 0.0, a.sin(), a.cos(), 0.0, 0.0, 0.0, 1.0);
    let rx = Matrix3::new(1.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 1.0, 0.0);
    let expected_r = rz * rx;
    let expected_p = Vector3::new(s, 0.0, 0.1) + rz * Vector3::new(0.05, 0.0, 0.2);
    assert!((pose.rotation - expected_r).norm() < 1e-14);
    assert!((pose.position - expected_p).norm() < 1e-14);
    // cos(π/2) noise was pruned: the pole's rotation has no tiny coefficients.
    for row in &m.bodies[1].rotation.0 {
        for entry in row {
            assert!(entry.terms().all(|(_, c)| c.abs() > 1e-12), "{entry:?}");
        }
    }
}

#[test]
fn newton_with_a_length_coordinate_and_range_limits() {
    let text = serde_json::to_string(&cart_pole(
        json!({ "name": "tip", "kind": "spherical", "bodies": ["pole", "tip"], "point": [0, 0, 1] }),
    ))
    .unwrap();
    let m = Case::from_json_str(&text).unwrap();
    let kin = Kinematics::new(&m);
    let guess = DVector::from_vec(vec![0.0, 0.0]);
    let q = kin
        .solve_coordinates(&DVector::from_vec(vec![0.3, -0.8]), &guess)
        .unwrap();
    assert!((q - DVector::from_vec(vec![0.3, -0.8])).norm() < 1e-12);
    // An angle 2π away is brought back into its range; a length outside its range is refused.
    let q = kin.solve_coordinates(
        &DVector::from_vec(vec![0.3, -0.8 + std::f64::consts::TAU]),
        &guess,
    );
    assert!(
        matches!(q, Err(KinematicsError::OutOfRange { .. })),
        "{q:?}"
    );
    let q = kin.solve_coordinates(&DVector::from_vec(vec![0.9, 0.1]), &guess);
    match q {
        Err(KinematicsError::OutOfRange { coordinate, .. }) => assert_eq!(coordinate, "s"),
        other => panic!("{other:?}"),
    }
}
