//! `counterpoise partial`: the command against hand calculations (the pendulum's closed forms,
//! with a counterweight and with a spring), joint selection by actuator or joint name, the
//! case's bounds and overrides, and its errors.

mod common;

use common::{assert_success, case_json, counterpoise, stderr, stdout, write_case};
use serde_json::{Value, json};

const G: f64 = 9.81;

fn run_json(args: &[&str]) -> Value {
    let out = counterpoise(args);
    assert_success(&out);
    serde_json::from_str(&stdout(&out)).expect("JSON on stdout")
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap()
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + a.abs().max(b.abs()))
}

/// The pendulum (2 kg rod, centre of mass at 0.5 m, gravity −9.81 y): `τ = 9.81 cos θ`. The
/// workspace is 7 values of the task grid's [−1.5, 1.5]; with `m ≤ 2 kg` and `|r| ≤ 0.25 m`
/// the best counterweight is `m·r = (−0.5, 0)` (the grid is symmetric, so `Σ cos θ sin θ = 0`
/// and the `sin θ` component only adds), which halves the torque: RMS `9.81·0.5·√(mean cos²)`.
/// The lightest such design is 2 kg at 0.25 m.
///
/// The spring `K10` (rod to base) exerts `−K·bᵀR(θ)a`'s derivative, at best `−K|a||b| cos θ`
/// (b a quarter turn ahead of a); with `K ≤ 100 N/m`, `|a| ≤ 0.1 m`, `|b| ≤ 0.5 m` that is
/// `5 cos θ`, leaving `(9.81 − 5)/9.81 = 49.0 %` of the torque: it ranks before the
/// counterweight's 50 %, and is certified (in the plane the relaxation is exact).
#[test]
fn pendulum_matches_the_closed_form() {
    let dir = tempfile::tempdir().unwrap();
    let mut case = case_json("pendulum.json");
    case["balancing"]["bounds"] = json!({
        "mass": [0, 2], "radius": [0, 0.25],
        "stiffness": [0, 100], "anchor_a": [0, 0.1], "anchor_b": [0, 0.5]
    });
    let path = write_case(dir.path(), "pendulum.json", &case);
    let both = run_json(&["partial", &path, "--json"]);
    assert_eq!(both["springs_searched"], true);
    assert_eq!(both["sets"], 2);
    let spring = &both["designs"][0];
    assert_eq!(spring["labels"], json!(["K10"]));
    let thetas: Vec<f64> = (0..7).map(|i| -1.5 + 0.5 * i as f64).collect();
    let mean_cos = (thetas.iter().map(|t| t.cos().powi(2)).sum::<f64>() / 7.0).sqrt();
    assert!(
        close(f(&spring["total_rms"]), (G - 5.0) * mean_cos, 1e-6),
        "{spring}"
    );
    assert_eq!(spring["certified"], true, "{spring}");
    assert!(f(&spring["gap"]) < 1e-3 * G * mean_cos, "{spring}");
    let k = &spring["springs"][0];
    assert_eq!(k["body"], "rod");
    assert_eq!(k["other"], "base");
    assert!(close(f(&k["stiffness"]), 100.0, 1e-5), "{k}");
    assert!(close(f(&k["torque_rms"]), 5.0 * mean_cos, 1e-5), "{k}");
    assert_eq!(both["designs"][1]["labels"], json!(["m1"]));
    let doc = run_json(&["partial", &path, "--json", "--counterweights-only"]);
    assert_eq!(doc["springs_searched"], false);
    assert_eq!(doc["sets"], 1);
    let thetas: Vec<f64> = (0..7).map(|i| -1.5 + 0.5 * i as f64).collect();
    let mean_cos2 = thetas.iter().map(|t| t.cos().powi(2)).sum::<f64>() / 7.0;
    let unbalanced = G * mean_cos2.sqrt();
    assert_eq!(doc["workspace"]["points"], 7);
    assert!(
        close(f(&doc["unbalanced_total"]), unbalanced, 1e-9),
        "{doc}"
    );
    let best = &doc["designs"][0];
    assert_eq!(best["labels"], json!(["m1"]));
    assert!(
        close(f(&best["total_rms"]), 0.5 * unbalanced, 1e-6),
        "{best}"
    );
    let cw = &best["counterweights"][0];
    assert!(close(f(&cw["mass"]), 2.0, 1e-5), "{cw}");
    assert!(close(f(&cw["offset"][0]), -0.25, 1e-5), "{cw}");
    assert!(f(&cw["offset"][1]).abs() < 1e-5, "{cw}");
    // the exact search on that set: one counterweight balances a pendulum (m·r = (−1, 0))
    assert_eq!(doc["exact"][0], json!({ "rank": 1, "status": "balanced" }));
}

/// Naming the elbow (by actuator `M2`) or the shoulder (by joint `J1`) changes the answer: the
/// elbow alone is balanced exactly by `m2` (`m2·r2 = (−1.35, 0)`: link 2's 2.5 kg at 0.3 m and
/// the 1 kg tool at 0.6 m), and the shoulder's design leaves the shoulder less torque than
/// the elbow's.
#[test]
fn joints_are_chosen_by_actuator_or_joint_name() {
    let dir = tempfile::tempdir().unwrap();
    let mut case = case_json("two_link.json");
    case["balancing"]["bounds"] = json!({ "mass": [0, 20], "radius": [0, 1] });
    let path = write_case(dir.path(), "two_link.json", &case);
    let elbow = run_json(&[
        "partial", &path, "--budget", "1", "--joints", "M2", "--json",
    ]);
    assert_eq!(elbow["joints"], json!(["M2"]));
    let best = &elbow["designs"][0];
    assert_eq!(best["labels"], json!(["m2"]));
    assert!(
        f(&best["rms"][1]) < 1e-6 * f(&elbow["unbalanced_rms"][1]),
        "{best}"
    );
    let cw = &best["counterweights"][0];
    assert!(
        close(f(&cw["mass"]) * f(&cw["offset"][0]), -1.35, 1e-5),
        "{cw}"
    );
    let shoulder = run_json(&[
        "partial", &path, "--budget", "1", "--joints", "J1", "--json",
    ]);
    assert_eq!(shoulder["joints"], json!(["M1"]));
    let first = &shoulder["designs"][0];
    assert!(
        f(&first["rms"][0]) < 0.9 * f(&best["rms"][0]),
        "{first} vs {best}"
    );
}

/// Every design within the case's bounds, and an override tighter still for `m2`.
#[test]
fn bounds_and_overrides_are_respected() {
    let dir = tempfile::tempdir().unwrap();
    let mut case = case_json("two_link.json");
    case["balancing"]["bounds"] = json!({
        "mass": [0, 1.5], "radius": [0, 0.4],
        "stiffness": [5, 50], "anchor_a": [0.1, 0.3], "anchor_b": [0, 0.2]
    });
    case["balancing"]["overrides"] = json!([{ "element": "m2", "radius": [0, 0.2] }]);
    let path = write_case(dir.path(), "two_link.json", &case);
    let doc = run_json(&["partial", &path, "--json"]);
    // m1, m2, K10, K20, K21: 5 sets of one, 10 of two
    assert_eq!(doc["sets"], 15);
    let norm = |v: &Value| {
        v.as_array()
            .unwrap()
            .iter()
            .map(|x| f(x).powi(2))
            .sum::<f64>()
            .sqrt()
    };
    for d in doc["designs"].as_array().unwrap() {
        for s in d["springs"].as_array().unwrap() {
            let k = f(&s["stiffness"]);
            assert!(
                (5.0 * (1.0 - 1e-7)..=50.0 * (1.0 + 1e-7)).contains(&k),
                "{s}"
            );
            let a = norm(&s["anchor_a"]);
            assert!(
                (0.1 * (1.0 - 1e-6)..=0.3 * (1.0 + 1e-6)).contains(&a),
                "{s}"
            );
            assert!(norm(&s["anchor_b"]) <= 0.2 * (1.0 + 1e-6), "{s}");
        }
        for cw in d["counterweights"].as_array().unwrap() {
            let m = f(&cw["mass"]);
            let r = cw["offset"]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| f(v).powi(2))
                .sum::<f64>()
                .sqrt();
            let r_hi = if cw["label"] == "m2" { 0.2 } else { 0.4 };
            assert!((-1e-9..=1.5 * (1.0 + 1e-7)).contains(&m), "{cw}");
            assert!(r <= r_hi * (1.0 + 1e-6), "{cw}");
        }
        // never worse than doing nothing (an empty counterweight is within the bounds)
        assert!(f(&d["total_rms"]) <= f(&doc["unbalanced_total"]) * (1.0 + 1e-9));
        assert!(f(&d["lower_bound"]) <= f(&d["total_rms"]) * (1.0 + 1e-6));
    }
}

/// The table names the exact verdict beside the residual: on the palletizer, `m4` alone
/// balances exactly (with 1829/8 kg at a radius the bounds do not allow: 0.5 m at most), so
/// within the bounds it only reduces the torque.
#[test]
fn the_table_shows_the_exact_verdict_beside_the_residual() {
    let out = counterpoise(&[
        "partial",
        "cases/palletizer.json",
        "--budget",
        "1",
        "--top",
        "1",
        "--counterweights-only",
    ]);
    assert_success(&out);
    let text = stdout(&out);
    let line = text
        .lines()
        .find(|l| l.split_whitespace().nth(1) == Some("m4"))
        .unwrap_or_else(|| panic!("{text}"));
    assert!(line.contains("balanced"), "{line}");
    assert!(text.contains("343 points, 343 used"), "{text}");
}

#[test]
fn bad_options_are_errors_naming_the_option() {
    for (args, needle) in [
        (vec!["--joints", "nope"], "--joints: `nope`"),
        (vec!["--budget", "0"], "--budget must be at least 1"),
        (vec!["--points", "1"], "--points must be at least 2"),
    ] {
        let mut all = vec!["partial", "cases/two_link.json"];
        all.extend(args);
        let out = counterpoise(&all);
        assert_eq!(out.status.code(), Some(1), "{all:?}");
        assert!(stderr(&out).contains(needle), "{all:?}: {}", stderr(&out));
    }
    let dir = tempfile::tempdir().unwrap();
    let mut case = case_json("two_link.json");
    case["balancing"]
        .as_object_mut()
        .unwrap()
        .remove("counterweights");
    let path = write_case(dir.path(), "springs.json", &case);
    let out = counterpoise(&["partial", &path, "--counterweights-only"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains("allows no counterweight (--counterweights-only)"),
        "{}",
        stderr(&out)
    );
    // its springs alone are searched
    let out = counterpoise(&["partial", &path, "--budget", "1"]);
    assert_success(&out);
}

/// `variants` points to `--minimal` and `partial` when nothing balances (the 6-axis arm needs
/// three elements: `cases/arm6.json` at Dmax 1), and not when something does (the pendulum).
#[test]
fn variants_points_to_partial_when_nothing_balances() {
    let hint = "partial CASE --budget 1";
    let out = counterpoise(&["variants", "cases/arm6.json", "--dmax", "1"]);
    assert_success(&out);
    assert!(stdout(&out).contains(hint), "{}", stdout(&out));
    let out = counterpoise(&["variants", "cases/pendulum.json", "--dmax", "1"]);
    assert_success(&out);
    assert!(!stdout(&out).contains(hint), "{}", stdout(&out));
}

/// `run` when no variant is feasible: the pendulum (`τ = 9.81 cos θ`, `m·r = (−1, 0)` balances
/// it) with `m ≤ 2 kg`, `|r| ≤ 0.25 m` and `K ≤ 1 N/m` cannot be balanced within its bounds,
/// so `run` adds the partial balancing at Dmax 1: the closed form of
/// `pendulum_matches_the_closed_form` (half the torque, 2 kg at 0.25 m), but over the run's
/// 5-value task grid widened to the default 7 workspace values. With the case's own (derived)
/// bounds a variant is feasible and no partial file is written.
#[test]
fn run_adds_the_partial_balancing_when_no_variant_is_feasible() {
    let dir = tempfile::tempdir().unwrap();
    let mut case = case_json("pendulum.json");
    case["balancing"]["bounds"] =
        json!({ "mass": [0, 2], "radius": [0, 0.25], "stiffness": [0, 1] });
    let path = write_case(dir.path(), "pendulum.json", &case);
    let out_dir = dir.path().join("out");
    let out = counterpoise(&["run", &path, "--out", out_dir.to_str().unwrap(), "--quiet"]);
    assert_success(&out);
    // The summary is wrapped at 120 columns: compare word by word.
    let text = stdout(&out)
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ");
    let thetas: Vec<f64> = (0..7).map(|i| -1.5 + 0.5 * i as f64).collect();
    let unbalanced = G * (thetas.iter().map(|t| t.cos().powi(2)).sum::<f64>() / 7.0).sqrt();
    // Both variants (m1, K10) balance exactly but not within the bounds.
    assert!(
        text.contains(
            "No feasible variant at Dmax 1: 2 variants of at most 1 element balance exactly"
        ),
        "{text}"
    );
    assert!(
        text.contains(&format!(
            "m1: total {:.3} (-50.0 %; M1 -50.0 %)",
            0.5 * unbalanced
        )),
        "{text}"
    );
    assert!(text.contains("partial.json"), "{text}");
    let doc: Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("partial.json")).unwrap())
            .unwrap();
    assert!(
        close(f(&doc["unbalanced_total"]), unbalanced, 1e-9),
        "{doc}"
    );
    let best = &doc["designs"][0];
    assert!(
        close(f(&best["total_rms"]), 0.5 * unbalanced, 1e-6),
        "{best}"
    );
    assert!(
        close(f(&best["counterweights"][0]["mass"]), 2.0, 1e-5),
        "{best}"
    );
    assert_eq!(doc["smallest_dmax"]["smallest_balanced"], 1);
    // `run`'s partial balancing is of counterweights only: one set, one CSV row under the
    // header.
    let csv = std::fs::read_to_string(out_dir.join("partial.csv")).unwrap();
    assert_eq!(csv.lines().count(), 2, "{csv}");
    assert!(
        csv.lines().nth(1).unwrap().starts_with("1,\"m1\",1,"),
        "{csv}"
    );
    assert_eq!(doc["springs_searched"], false);
    // The note reaches results.json and the reports.
    let results: Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("results.json")).unwrap())
            .unwrap();
    let notes = results["metadata"]["notes"].as_array().unwrap();
    assert!(
        notes.iter().any(|n| n
            .as_str()
            .unwrap()
            .starts_with("No feasible variant at Dmax 1")),
        "{notes:?}"
    );
    let html = std::fs::read_to_string(out_dir.join("report.html")).unwrap();
    assert!(html.contains("No feasible variant at Dmax 1"));

    let feasible_dir = dir.path().join("feasible");
    let out = counterpoise(&[
        "run",
        "cases/pendulum.json",
        "--out",
        feasible_dir.to_str().unwrap(),
        "--quiet",
    ]);
    assert_success(&out);
    assert!(
        !stdout(&out).contains("No feasible variant at Dmax"),
        "{}",
        stdout(&out)
    );
    assert!(!feasible_dir.join("partial.json").exists());
}
