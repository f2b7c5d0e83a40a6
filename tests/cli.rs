//! End-to-end tests of the command line on the reference cases.

use std::path::PathBuf;
use std::process::{Command, Output};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn counterpoise(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_counterpoise"))
        .args(args)
        .current_dir(root())
        .output()
        .expect("the binary runs")
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn check_summarises_the_palletizer() {
    let out = counterpoise(&["check", "cases/palletizer.json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    // palletizer.md: total ≈ 1990 kg with the 800 kg base, which does not move: 1188.625 kg moves
    assert!(text.contains("total mass 1188.625 kg"), "{text}");
    assert!(
        text.contains("V = const − 672.84·sin(th2) + 2830.49·sin(th3) J"),
        "{text}"
    );
    assert!(text.contains("343 points, 343 reachable"), "{text}");
    assert!(text.contains("Dmax 2 → 406 variants"), "{text}");
}

#[test]
fn check_reports_every_error_with_its_path_and_fails() {
    let dir = std::env::temp_dir().join(format!("counterpoise-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let text = std::fs::read_to_string(root().join("cases/pendulum.json")).unwrap();
    let mut case: serde_json::Value = serde_json::from_str(&text).unwrap();
    case["bodies"][0]["mass"] = serde_json::json!(-1.0);
    case["actuators"][0]["joint"] = serde_json::json!("nope");
    let path = dir.join("bad.json");
    std::fs::write(&path, serde_json::to_string(&case).unwrap()).unwrap();
    let out = counterpoise(&["check", path.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(err.contains("bodies[0].mass"), "{err}");
    assert!(err.contains("actuators[0].joint"), "{err}");

    std::fs::write(&path, "{ \"name\": ").unwrap();
    let out = counterpoise(&["check", path.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("line 1"), "{}", stderr(&out));
    let out = counterpoise(&["check", "cases/does-not-exist.json"]);
    assert_eq!(out.status.code(), Some(1));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn variants_json_lists_every_variant_with_elements_and_status() {
    let out = counterpoise(&["variants", "cases/palletizer.json", "--dmax", "1", "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let doc: serde_json::Value = serde_json::from_str(&stdout(&out)).unwrap();
    assert_eq!(doc["schema_version"], 1);
    let variants = doc["variants"].as_array().unwrap();
    assert_eq!(variants.len(), 28, "7 counterweights + 21 springs");
    let m4 = variants
        .iter()
        .find(|v| v["elements"][0]["label"] == "m4")
        .unwrap();
    assert_eq!(m4["status"], "balanced");
    assert_eq!(m4["elements"][0]["type"], "counterweight");
    assert_eq!(m4["elements"][0]["bodies"][0], "upper_arm");
    assert!(m4["verification"]["residual"].as_f64().unwrap() < 1e-9);
    let total: u64 = doc["counts"]
        .as_object()
        .unwrap()
        .values()
        .map(|v| v.as_u64().unwrap())
        .sum();
    assert_eq!(total, 28);
}

#[test]
fn variants_are_identical_with_one_and_two_threads() {
    let one = counterpoise(&["--jobs", "1", "variants", "cases/palletizer.json", "--json"]);
    let two = counterpoise(&["--jobs", "2", "variants", "cases/palletizer.json", "--json"]);
    let strip = |o: &Output| {
        let mut doc: serde_json::Value = serde_json::from_str(&stdout(o)).unwrap();
        doc["seconds"] = serde_json::Value::Null;
        doc
    };
    assert_eq!(strip(&one), strip(&two));
}

#[test]
fn evaluate_series_of_the_pendulum_matches_its_equation_of_motion() {
    // rod: m = 2 kg, CoM at L/2 = 0.5 m, I_zz about the CoM 0.1667 kg·m², ratio 0.01;
    // grid −1.5…1.5 rad in 5 points; move 0 → 4 is −1.5 → 1.5 rad in 1 s (quintic).
    let dir = std::env::temp_dir().join(format!("counterpoise-series-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("series.json");
    let out = counterpoise(&[
        "evaluate",
        "cases/pendulum.json",
        "--task",
        "0,4",
        "--series",
        file.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
    let (m, c, g, i_zz, ratio) = (2.0, 0.5, 9.81, 0.1667, 0.01);
    let t = s["t"].as_array().unwrap();
    assert_eq!(t.len(), 21);
    for (k, tk) in t.iter().enumerate() {
        let tau = tk.as_f64().unwrap(); // duration 1 s
        let (q0, dq) = (-1.5, 3.0);
        let s5 = 10.0 * tau.powi(3) - 15.0 * tau.powi(4) + 6.0 * tau.powi(5);
        let a5 = 60.0 * tau - 180.0 * tau.powi(2) + 120.0 * tau.powi(3);
        let (q, qdd) = (q0 + dq * s5, dq * a5);
        // τ = (I_zz + m c²) q̈ + m g c cos q
        let expected = (i_zz + m * c * c) * qdd + m * g * c * q.cos();
        let force = s["actuator_force"][k][0].as_f64().unwrap();
        assert!(
            (force - expected).abs() < 1e-6 * (1.0 + expected.abs()),
            "t={tau}: {force} vs {expected}"
        );
        let motor = s["motor_torque"][k][0].as_f64().unwrap();
        assert!((motor - ratio * expected).abs() < 1e-8 * (1.0 + expected.abs()));
    }
    std::fs::remove_dir_all(&dir).ok();
}
