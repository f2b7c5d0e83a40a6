//! `counterpoise import-urdf` end to end: import, then `check` and `variants` on the result.

mod common;

use common::{assert_success, counterpoise, root, stderr, stdout};

#[test]
fn imported_two_link_arm_is_the_example_case_and_checks_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let out_path = dir.path().join("arm.json");
    let out = counterpoise(&[
        "import-urdf",
        "crates/urdf/tests/data/two_link.urdf",
        "--out",
        out_path.to_str().unwrap(),
    ]);
    assert_success(&out);
    let written = std::fs::read_to_string(&out_path).unwrap();
    let example = std::fs::read_to_string(root().join("cases/two_link_urdf.json")).unwrap();
    assert_eq!(
        written, example,
        "cases/two_link_urdf.json is the importer's output"
    );
    // Without --out the case goes to standard output.
    let out = counterpoise(&["import-urdf", "crates/urdf/tests/data/two_link.urdf"]);
    assert_success(&out);
    assert_eq!(stdout(&out), example);

    let out = counterpoise(&["check", out_path.to_str().unwrap()]);
    assert_success(&out);
    let text = stdout(&out);
    // g·(m1·c1 + m2·l1) = 9.81·(4·0.4 + 2.5·0.8) = 35.316; g·m2·c2 = 9.81·2.5·0.3 = 7.3575.
    assert!(
        text.contains("V = const + 35.32·sin(shoulder) + 7.36·sin(shoulder)·cos(elbow) + 7.36·cos(shoulder)·sin(elbow) J"),
        "{text}"
    );
    assert!(text.contains("balance decision: exact"), "{text}");
    assert!(text.contains("9 points, 9 reachable"), "{text}");

    let out = counterpoise(&["variants", out_path.to_str().unwrap(), "--json"]);
    assert_success(&out);
    let doc: serde_json::Value = serde_json::from_str(&stdout(&out)).unwrap();
    let variants = doc["variants"].as_array().unwrap();
    let pair = variants
        .iter()
        .find(|v| {
            v["elements"]
                .as_array()
                .unwrap()
                .iter()
                .map(|e| e["label"].as_str().unwrap())
                .collect::<Vec<_>>()
                == ["m1", "m2"]
        })
        .unwrap();
    assert_eq!(pair["status"], "balanced", "{pair}");
}

#[test]
fn malformed_urdf_fails_naming_the_element() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.urdf");
    let text =
        std::fs::read_to_string(root().join("crates/urdf/tests/data/two_link.urdf")).unwrap();
    std::fs::write(
        &bad,
        text.replace("<child link=\"link2\"/>", "<child link=\"link7\"/>"),
    )
    .unwrap();
    let out = counterpoise(&["import-urdf", bad.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(
        err.contains("joint `elbow`.child: child link `link7` does not exist"),
        "{err}"
    );
    assert!(stdout(&out).is_empty());
}

/// Runs `evaluate CASE --states` on `states` and returns the parsed output.
fn states_of(case: &str, states: &serde_json::Value) -> serde_json::Value {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("states.json");
    std::fs::write(&path, states.to_string()).unwrap();
    let out = counterpoise(&["evaluate", case, "--states", path.to_str().unwrap()]);
    assert_success(&out);
    serde_json::from_str(&stdout(&out)).unwrap()
}

#[test]
fn states_give_the_closed_form_inverse_dynamics_of_the_two_link_arm() {
    // Planar arm (angles measured from the horizontal x axis, gravity −z):
    // τ = M(q) q̈ + C(q, q̇) q̇ + g(q) with link inertias about y I1 = 0.2133, I2 = 0.075.
    let (m1, m2, l1, c1, c2, i1, i2, g) = (4.0, 2.5, 0.8, 0.4, 0.3, 0.2133, 0.075, 9.81_f64);
    let states = serde_json::json!([
        { "q": [0.3, -0.4], "qd": [0.5, 1.0], "qdd": [-0.7, 2.0] },
        { "q": [-1.2, 2.1], "qd": [-1.5, 0.25], "qdd": [0.4, -3.0] },
        { "q": [0.9, 0.2] }
    ]);
    let doc = states_of("cases/two_link_urdf.json", &states);
    assert_eq!(doc["actuators"], serde_json::json!(["shoulder", "elbow"]));
    for (k, s) in states.as_array().unwrap().iter().enumerate() {
        let v = |key: &str, i: usize| s.get(key).map_or(0.0, |x| x[i].as_f64().unwrap());
        let (q1, q2, d1, d2, a1, a2) = (
            v("q", 0),
            v("q", 1),
            v("qd", 0),
            v("qd", 1),
            v("qdd", 0),
            v("qdd", 1),
        );
        let m11 = i1 + i2 + m1 * c1 * c1 + m2 * (l1 * l1 + c2 * c2 + 2.0 * l1 * c2 * q2.cos());
        let m12 = i2 + m2 * (c2 * c2 + l1 * c2 * q2.cos());
        let m22 = i2 + m2 * c2 * c2;
        let h = m2 * l1 * c2 * q2.sin();
        let g1 = g * ((m1 * c1 + m2 * l1) * q1.cos() + m2 * c2 * (q1 + q2).cos());
        let g2 = g * m2 * c2 * (q1 + q2).cos();
        let tau = [
            m11 * a1 + m12 * a2 - h * (2.0 * d1 * d2 + d2 * d2) + g1,
            m12 * a1 + m22 * a2 + h * d1 * d1 + g2,
        ];
        let potential =
            g * (m1 * (0.5 + c1 * q1.sin()) + m2 * (0.5 + l1 * q1.sin() + c2 * (q1 + q2).sin()));
        let got = &doc["states"][k];
        for a in 0..2 {
            let f = got["actuator_forces"][a].as_f64().unwrap();
            assert!(
                (f - tau[a]).abs() < 1e-9 * (1.0 + tau[a].abs()),
                "state {k}: {f} vs {}",
                tau[a]
            );
            // ratio 1: the motor torque is the actuator force
            assert_eq!(got["motor_torques"][a], got["actuator_forces"][a]);
        }
        let v = got["potential_energy"].as_f64().unwrap();
        assert!(
            (v - potential).abs() < 1e-12,
            "state {k}: {v} vs {potential}"
        );
    }
}

/// Checks `--states` against the task evaluator along the task from the first to the last grid
/// point of `case` (every actuator `u = q`, ratio 1): a rest-to-rest quintic
/// `u(t) = u0 + Δ·(10s³ − 15s⁴ + 6s⁵)`, `s = t/T`. The evaluator's actuator forces at its
/// samples must equal the states evaluation at the same `(q, q̇, q̈)`.
fn states_match_the_task_evaluator(case: &str) {
    let dir = tempfile::tempdir().unwrap();
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(case).unwrap()).unwrap();
    let axes: Vec<[f64; 3]> = doc["actuators"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| {
            let axis = &doc["tasks"]["grid"][a["name"].as_str().unwrap()];
            [0, 1, 2].map(|i| axis[i].as_f64().unwrap())
        })
        .collect();
    let last: usize = axes.iter().map(|a| a[2] as usize).product::<usize>() - 1;
    let duration = doc["tasks"]["duration"].as_f64().unwrap();
    let series_path = dir.path().join("series.json");
    let task = format!("0,{last}");
    let out = counterpoise(&[
        "evaluate",
        case,
        "--task",
        &task,
        "--series",
        series_path.to_str().unwrap(),
    ]);
    assert_success(&out);
    let series: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&series_path).unwrap()).unwrap();
    let picks = [3usize, 8, 15];
    let states: Vec<serde_json::Value> = picks
        .iter()
        .map(|&k| {
            let t = series["t"][k].as_f64().unwrap();
            let s = t / duration;
            let p = 10.0 * s.powi(3) - 15.0 * s.powi(4) + 6.0 * s.powi(5);
            let dp = (30.0 * s.powi(2) - 60.0 * s.powi(3) + 30.0 * s.powi(4)) / duration;
            let ddp = (60.0 * s - 180.0 * s.powi(2) + 120.0 * s.powi(3)) / (duration * duration);
            let d = |a: &[f64; 3]| a[1] - a[0];
            serde_json::json!({
                "q": axes.iter().map(|a| a[0] + d(a) * p).collect::<Vec<_>>(),
                "qd": axes.iter().map(|a| d(a) * dp).collect::<Vec<_>>(),
                "qdd": axes.iter().map(|a| d(a) * ddp).collect::<Vec<_>>(),
            })
        })
        .collect();
    let doc = states_of(case, &serde_json::json!(states));
    for (n, &k) in picks.iter().enumerate() {
        for a in 0..axes.len() {
            let want = series["actuator_force"][k][a].as_f64().unwrap();
            let got = doc["states"][n]["actuator_forces"][a].as_f64().unwrap();
            assert!(
                (got - want).abs() < 1e-9 * (1.0 + want.abs()),
                "{case} sample {k} actuator {a}: {got} vs {want}"
            );
        }
    }
}

#[test]
fn states_agree_with_the_task_evaluator_on_the_planar_and_the_seven_joint_arm() {
    states_match_the_task_evaluator("cases/two_link_urdf.json");
    let dir = tempfile::tempdir().unwrap();
    let seven = dir.path().join("seven.json");
    let out = counterpoise(&[
        "import-urdf",
        "crates/urdf/tests/data/seven_dof.urdf",
        "--out",
        seven.to_str().unwrap(),
    ]);
    assert_success(&out);
    states_match_the_task_evaluator(seven.to_str().unwrap());
}

#[test]
fn states_of_the_wrong_size_are_refused_naming_the_state() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("states.json");
    std::fs::write(&path, r#"[{"q": [0, 0]}, {"q": [0, 0], "qd": [1]}]"#).unwrap();
    let out = counterpoise(&[
        "evaluate",
        "cases/two_link_urdf.json",
        "--states",
        path.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains("states[1].qd: 1 values for 2 coordinates"),
        "{}",
        stderr(&out)
    );
}
