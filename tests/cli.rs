//! End-to-end tests of the command line on the reference cases.

mod common;

use std::process::Output;

use common::{assert_success, case_json, counterpoise, num, results, stderr, stdout, write_case};

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
    let dir = tempfile::tempdir().unwrap();
    let mut case = case_json("pendulum.json");
    case["bodies"][0]["mass"] = serde_json::json!(-1.0);
    case["actuators"][0]["joint"] = serde_json::json!("nope");
    let path = dir.path().join("bad.json");
    write_case(dir.path(), "bad.json", &case);
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
}

#[test]
fn variants_json_lists_every_variant_with_elements_and_status() {
    let out = counterpoise(&["variants", "cases/palletizer.json", "--dmax", "1", "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let doc: serde_json::Value = serde_json::from_str(&stdout(&out)).unwrap();
    assert_eq!(doc["schema_version"], 2);
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
    // The witness names its element and body as the element list does (schema 2).
    let witness = &m4["witness"]["counterweights"][0];
    assert_eq!(witness["label"], "m4");
    assert_eq!(witness["body"], "upper_arm");

    let total: u64 = doc["counts"]
        .as_object()
        .unwrap()
        .values()
        .map(|v| v.as_u64().unwrap())
        .sum();
    assert_eq!(total, 28);
}

/// The witness of `m2 + K10` on the two-link arm names its elements and bodies, and its
/// counterweight carries link 2 alone: `m2·r2 = −(m_link2·c2 + m_tool·L2) = −(2.5·0.3 + 1·0.6)
/// = −1.35 kg·m` along the link (cases/two_link.json), whatever the spring does on link 1.
#[test]
fn a_witness_names_its_elements_and_bodies() {
    let out = counterpoise(&["variants", "cases/two_link.json", "--dmax", "2", "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let doc: serde_json::Value = serde_json::from_str(&stdout(&out)).unwrap();
    let v = doc["variants"]
        .as_array()
        .unwrap()
        .iter()
        .find(|v| v["elements"][0]["label"] == "m2" && v["elements"][1]["label"] == "K10")
        .expect("m2 + K10");
    assert_eq!(v["status"], "balanced");
    let cw = &v["witness"]["counterweights"][0];
    assert_eq!((&cw["label"], &cw["body"]), (&"m2".into(), &"link2".into()));
    let moment = cw["mass"].as_f64().unwrap() * cw["offset"][0].as_f64().unwrap();
    assert!((moment + 1.35).abs() < 1e-9, "{moment}");
    let spring = &v["witness"]["springs"][0];
    assert_eq!(spring["label"], "K10");
    assert_eq!(
        (&spring["body"], &spring["other"]),
        (&"link1".into(), &"base".into())
    );
}

#[test]
fn variants_are_identical_with_one_and_two_threads() {
    let one = counterpoise(&["variants", "cases/palletizer.json", "--json", "--jobs", "1"]);
    let two = counterpoise(&["variants", "cases/palletizer.json", "--json", "--jobs", "2"]);
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
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("series.json");
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
}

/// The pendulum's motor torque by hand: `0.01·((I_zz + m c²) θ̈ + m g c cos θ)` along the
/// quintic move `a → b` in 1 s, sampled at 21 points.
fn pendulum_motor_torque(a: f64, b: f64) -> Vec<f64> {
    let (m, c, g, i_zz, ratio) = (2.0, 0.5, 9.81, 0.1667, 0.01);
    (0..21)
        .map(|k| {
            let t = k as f64 / 20.0;
            let s5 = 10.0 * t.powi(3) - 15.0 * t.powi(4) + 6.0 * t.powi(5);
            let a5 = 60.0 * t - 180.0 * t.powi(2) + 120.0 * t.powi(3);
            let (q, qdd) = (a + (b - a) * s5, (b - a) * a5);
            ratio * ((i_zz + m * c * c) * qdd + m * g * c * q.cos())
        })
        .collect()
}

/// QTR and QIT of the pendulum by hand: the grid is −1.5…1.5 in 5 points, every pair i < j
/// is a task; QTR is the largest RMS over tasks, QIT the largest |τ| (one actuator).
fn pendulum_qtr_qit() -> (f64, f64) {
    let points: Vec<f64> = (0..5).map(|k| -1.5 + 0.75 * k as f64).collect();
    let (mut qtr, mut qit) = (0.0f64, 0.0f64);
    for i in 0..5 {
        for j in i + 1..5 {
            let tau = pendulum_motor_torque(points[i], points[j]);
            let rms = (tau.iter().map(|t| t * t).sum::<f64>() / tau.len() as f64).sqrt();
            qtr = qtr.max(rms);
            qit = tau.iter().fold(qit, |q, t| q.max(t.abs()));
        }
    }
    (qtr, qit)
}

#[test]
fn evaluate_json_of_the_pendulum_matches_a_hand_calculation() {
    let out = counterpoise(&["evaluate", "cases/pendulum.json", "--json"]);
    assert_success(&out);
    let doc: serde_json::Value = serde_json::from_str(&stdout(&out)).unwrap();
    let (qtr, qit) = pendulum_qtr_qit();
    assert!(
        (num(&doc, "qtr") - qtr).abs() < 1e-9 * qtr,
        "QTR {} vs {qtr}",
        doc["qtr"]
    );
    assert!(
        (num(&doc, "qit") - qit).abs() < 1e-9 * qit,
        "QIT {} vs {qit}",
        doc["qit"]
    );
    assert_eq!(doc["points"], 5);
    assert_eq!(doc["tasks"], 10);
    assert_eq!(doc["evaluated"], 10);
    // one actuator: its critical RMS is QTR, its critical peak QIT
    assert!((num(&doc["actuators"][0], "crt_rms") - qtr).abs() < 1e-9 * qtr);
    assert!((num(&doc["actuators"][0], "cpt_peak") - qit).abs() < 1e-9 * qit);
    assert_eq!(doc["joints"].as_array().unwrap().len(), 1);
    assert!(num(&doc["joints"][0], "force") > 0.0);

    // Without reactions: the same motor indicators and no joint peaks.
    let bare = counterpoise(&[
        "evaluate",
        "cases/pendulum.json",
        "--json",
        "--no-reactions",
    ]);
    assert_success(&bare);
    let bare: serde_json::Value = serde_json::from_str(&stdout(&bare)).unwrap();
    assert_eq!(bare["qtr"], doc["qtr"]);
    assert_eq!(bare["qit"], doc["qit"]);
    assert_eq!(bare["actuators"], doc["actuators"]);
    assert!(bare["joints"].as_array().unwrap().is_empty());

    // The plain-text form shows the same QTR.
    let text = counterpoise(&["evaluate", "cases/pendulum.json"]);
    assert_success(&text);
    assert!(
        stdout(&text).contains(&format!("QTR = {qtr:.3} N·m")),
        "{}",
        stdout(&text)
    );
}

/// Runs `run` on the pendulum into a fresh directory with extra arguments.
fn run_pendulum(dir: &std::path::Path, name: &str, extra: &[&str]) -> (Output, serde_json::Value) {
    let out = dir.join(name);
    let mut args = vec!["run", "cases/pendulum.json", "--out", out.to_str().unwrap()];
    args.extend_from_slice(extra);
    let o = counterpoise(&args);
    assert_success(&o);
    let doc = results(&out);
    (o, doc)
}

fn feasible(doc: &serde_json::Value) -> Vec<&serde_json::Value> {
    doc["variants"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|v| v["status"] == "feasible")
        .collect()
}

#[test]
fn run_prints_a_summary_of_what_it_wrote() {
    let dir = tempfile::tempdir().unwrap();
    let (o, doc) = run_pendulum(dir.path(), "out", &[]);
    let text = stdout(&o);
    let variants = doc["variants"].as_array().unwrap().len();
    assert!(
        text.starts_with(&format!(
            "pendulum: {variants} variants examined (Dmax = 1)"
        )),
        "{text}"
    );
    let ranked = feasible(&doc);
    assert!(!ranked.is_empty());
    assert!(
        text.contains(&format!("Ranking (top {}):", ranked.len())),
        "{text}"
    );
    for v in &ranked {
        let name = format!("SB{}", v["rank"]);
        assert!(text.contains(&name), "{name} in {text}");
    }
    for file in ["results.json", "report.html", "report.md", "ranking.csv"] {
        let path = dir.path().join("out").join(file);
        assert!(
            text.contains(&format!("wrote {}", path.display())),
            "{file}: {text}"
        );
    }
}

#[test]
fn minimax_on_one_actuator_ranks_like_rms_star() {
    // One actuator: RMS* (its RMS in its critical task) and QTR (the largest RMS over tasks)
    // are the same function of the parameters, so both objectives give the same variants.
    let dir = tempfile::tempdir().unwrap();
    let (_, rms) = run_pendulum(dir.path(), "rms", &[]);
    let (_, minimax) = run_pendulum(dir.path(), "minimax", &["--minimax"]);
    let (a, b) = (feasible(&rms), feasible(&minimax));
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(&b) {
        assert_eq!(x["elements"], y["elements"]);
        let (dx, dy) = (num(x, "dqtr"), num(y, "dqtr"));
        assert!((dx - dy).abs() < 1e-4 * dx.abs().max(1.0), "{dx} vs {dy}");
    }
}

#[test]
fn usage_errors_exit_with_code_2() {
    for args in [
        &["run"][..],
        &["evaluate", "cases/pendulum.json", "--bogus"],
        &["evaluate", "cases/pendulum.json", "--task", "0,4"],
        &[
            "evaluate",
            "cases/pendulum.json",
            "--task",
            "x",
            "--series",
            "s.json",
        ],
        &["check", "cases/pendulum.json", "--jobs", "0"],
        // `report` and `import-urdf` have no parallel stage, so no --jobs
        &["report", "out/pendulum", "--jobs", "2"],
        &["run", "cases/pendulum.json", "--tolerance", "-1"],
        &["run", "cases/pendulum.json", "--resolution", "fine"],
    ] {
        let out = counterpoise(args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert!(!stderr(&out).is_empty(), "{args:?} explains itself");
        assert!(stdout(&out).is_empty(), "{args:?}");
    }
}

#[test]
fn a_zero_length_task_is_named_as_such() {
    let dir = tempfile::tempdir().unwrap();
    let series = dir.path().join("series.json");
    let series = series.to_str().unwrap();
    let out = counterpoise(&[
        "evaluate",
        "cases/pendulum.json",
        "--task",
        "1,1",
        "--series",
        series,
    ]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(
        err.contains("error: task 1→1 is a zero-length move"),
        "{err}"
    );
    assert_eq!(err.matches("1→1").count(), 1, "named once: {err}");
    // The pendulum's grid has 5 points: index 5 is out of range, and the message says so.
    let out = counterpoise(&[
        "evaluate",
        "cases/pendulum.json",
        "--task",
        "0,5",
        "--series",
        series,
    ]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(
        err.contains("the grid has 5 points (indices 0 to 4)"),
        "{err}"
    );
}

#[test]
fn check_names_the_path_of_the_balance_decision() {
    let out = counterpoise(&["check", "cases/palletizer.json"]);
    assert!(
        stdout(&out).contains("balance decision: exact"),
        "{}",
        stdout(&out)
    );
    let dir = tempfile::tempdir().unwrap();
    let mut case = case_json("palletizer.json");
    case["bodies"][0]["pose"][0]["rot_y"] = serde_json::json!("th1 + 0.3");
    write_case(dir.path(), "turned.json", &case);
    let path = dir.path().join("turned.json");
    let out = counterpoise(&["check", path.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    assert!(text.contains("balance decision: numeric"), "{text}");
    assert!(text.contains("bodies[0].pose[0].rot_y"), "{text}");
    // A quarter turn plus π/6 (cos = −1/2, sin = √3/2), and atan2(√2, 1) (cos = 1/√3,
    // sin = √2/√3): both have cosine and sine in ℚ(√2, √3), so the decision is exact there.
    for turn in ["th1 + 2*pi/3", "th1 + atan2(2*sin(pi/4), 1)"] {
        case["bodies"][0]["pose"][0]["rot_y"] = serde_json::json!(turn);
        write_case(dir.path(), "turned.json", &case);
        let out = counterpoise(&["check", path.to_str().unwrap()]);
        assert!(out.status.success(), "{turn}: {}", stderr(&out));
        let text = stdout(&out);
        assert!(
            text.contains("balance decision: exact over ℚ(√2, √3) (every rotation has its cosine"),
            "{turn}: {text}"
        );
    }
}

#[test]
fn a_case_without_bounds_gets_bounds_from_the_mechanism() {
    // The pendulum: one uniform rod, m = 2 kg, CoM at L/2 = 0.5 m, I = 0.1667 kg·m² about the
    // CoM (m L²/12 with L = 1 m). Moving mass 2 kg; reach |c| + √3·√(I/m) = 0.5 + 0.5 = 1 m.
    let check = counterpoise(&["check", "cases/pendulum.json"]);
    assert_success(&check);
    let text = stdout(&check);
    assert!(
        text.contains(
            "bounds not in the case, derived from the mechanism (moving mass M = 2 kg, reach 1 m"
        ),
        "{text}"
    );
    assert!(text.contains("mass [0, 2] kg (the moving mass)"), "{text}");
    let dir = tempfile::tempdir().unwrap();
    let (o, doc) = run_pendulum(dir.path(), "out", &[]);
    assert!(
        stderr(&o).contains("note: bounds not in the case"),
        "{}",
        stderr(&o)
    );
    // Balance needs m·r = m_rod·L/2 = 1 kg·m. A heavier counterweight closer in adds less
    // inertia (m r² = 1/m), so the optimiser takes the largest mass the bounds allow: 2 kg,
    // hence r = 0.5 m, opposite the rod — not 1000 kg at 1 mm.
    let m1 = feasible(&doc)
        .into_iter()
        .find(|v| v["elements"][0]["label"] == "m1")
        .unwrap();
    let cw = &m1["parameters"]["counterweights"][0];
    assert!((num(cw, "mass") - 2.0).abs() < 1e-6, "{cw}");
    assert!(
        (cw["offset"][0].as_f64().unwrap() + 0.5).abs() < 1e-6,
        "{cw}"
    );
    assert!((num(&m1["practical"], "added_mass_percent") - 100.0).abs() < 1e-4);
    let notes = doc["metadata"]["notes"].as_array().unwrap();
    assert!(
        notes
            .iter()
            .any(|n| n.as_str().unwrap().starts_with("Bounds not in the case"))
    );
}

#[test]
fn progress_is_one_line_per_phase_off_a_terminal_and_quiet_silences_it() {
    let dir = tempfile::tempdir().unwrap();
    let (o, _) = run_pendulum(dir.path(), "loud", &[]);
    let all: Vec<String> = stderr(&o)
        .lines()
        .filter(|l| l.starts_with('['))
        .map(str::to_string)
        .collect();
    // One line as each phase starts, and within the optimisation one as each of its stages
    // starts, with how many variants it has to do (the evaluations, which run their variants
    // together, without).
    let (stages, lines): (Vec<String>, Vec<String>) = all
        .into_iter()
        .partition(|l| l.contains(" into the phase)"));
    assert_eq!(lines.len(), 4, "{lines:?}");
    assert!(lines[0].starts_with("[1/4] Phase 1: unbalanced robot over all tasks (elapsed "));
    assert!(lines[3].starts_with("[4/4] Phase 3: ranking"), "{lines:?}");
    let optimisation = "[3/4] Phase 2: optimisation of the 2 balanced variants: ";
    assert!(lines[2].starts_with(&optimisation[..optimisation.len() - 2]));
    assert!(
        stages[0].starts_with(&format!("{optimisation}critical-task pass 1, 2 to do")),
        "{stages:?}"
    );
    assert!(
        stages.iter().all(|l| l.starts_with(optimisation)),
        "{stages:?}"
    );
    let last_two: Vec<&str> = stages[stages.len() - 2..]
        .iter()
        .map(|l| {
            l[optimisation.len()..]
                .split([',', '('])
                .next()
                .unwrap()
                .trim()
        })
        .collect();
    assert_eq!(
        last_two,
        ["spring choice", "final evaluation"],
        "{stages:?}"
    );
    let (o, _) = run_pendulum(dir.path(), "quiet", &["--quiet"]);
    assert_eq!(stderr(&o), "");
    assert!(stdout(&o).contains("wrote "));
}

/// The partial balancing `run` adds when no variant is feasible is known only after the four
/// counted phases have printed `[n/4]`: it is labelled `[+]`, never `[5/5]`. The pendulum
/// bounded to `m ≤ 2 kg`, `|r| ≤ 0.25 m`, `K ≤ 1 N/m` cannot be balanced (it needs
/// `m·r = 1 kg·m`), so it has no feasible variant.
#[test]
fn the_partial_balancing_phase_is_labelled_outside_the_count() {
    let dir = tempfile::tempdir().unwrap();
    let mut case = case_json("pendulum.json");
    case["balancing"]["bounds"] =
        serde_json::json!({ "mass": [0, 2], "radius": [0, 0.25], "stiffness": [0, 1] });
    let path = write_case(dir.path(), "pendulum.json", &case);
    let out_dir = dir.path().join("out");
    let o = counterpoise(&["run", &path, "--out", out_dir.to_str().unwrap()]);
    assert_success(&o);
    let phases: Vec<String> = stderr(&o)
        .lines()
        .filter(|l| l.starts_with('[') && !l.contains(" into the phase)"))
        .map(|l| l.split(" (elapsed").next().unwrap().to_string())
        .collect();
    assert_eq!(
        phases,
        [
            "[1/4] Phase 1: unbalanced robot over all tasks",
            "[2/4] Phase 2: balance search",
            "[3/4] Phase 2: optimisation of the 2 balanced variants",
            "[4/4] Phase 3: ranking, torque curves, path",
            "[+] Partial balancing (no feasible variant)",
        ],
        "{}",
        stderr(&o)
    );
}

#[test]
fn report_of_a_missing_directory_says_so_once() {
    let out = counterpoise(&["report", "no-such-directory"]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.starts_with("error: no-such-directory/results.json: "),
        "{err}"
    );
    assert_eq!(err.matches("os error 2").count(), 1, "{err}");
}

#[test]
fn report_recomputes_the_recommendation_at_another_tolerance() {
    let dir = tempfile::tempdir().unwrap();
    let (_, doc) = run_pendulum(dir.path(), "out", &["--tolerance", "0.5"]);
    assert_eq!(doc["decision"]["tolerance"], serde_json::json!(0.5));
    let out = dir.path().join("out");
    let o = counterpoise(&["report", out.to_str().unwrap(), "--tolerance", "80"]);
    assert_success(&o);
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    // at 80 pp both pendulum variants are equivalent: the overall line counts two
    assert!(
        md.contains("Of the 2 variants within 80 percentage points"),
        "{md}"
    );
}
