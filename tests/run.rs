//! End-to-end: `counterpoise run` on the palletizer with a reduced task grid, then `report`.

mod common;

use std::collections::BTreeSet;

use common::{assert_success, counterpoise, num, reduced_palletizer, results, stdout, write_case};

/// Eqs. 17–21 written out here from the paper's definition (a second implementation, not the
/// report crate's): ΔR = Σ_j γ_Fj·max(ΔF_j, 0) + γ_Mj·max(ΔM_j, 0), γ = reference share; a
/// joint with zero reference load contributes (X_SB − 0)/Σ X_UB·100, the weighted term's limit.
fn delta_r(ub: &serde_json::Value, sb: &serde_json::Value) -> f64 {
    let (ub, sb) = (
        ub["joints"].as_array().unwrap(),
        sb["joints"].as_array().unwrap(),
    );
    assert_eq!(ub.len(), sb.len());
    let mut total = 0.0;
    for key in ["force", "moment"] {
        let sum: f64 = ub.iter().map(|j| num(j, key)).sum();
        if sum <= 0.0 {
            continue;
        }
        for (u, s) in ub.iter().zip(sb) {
            let (u, s) = (num(u, key), num(s, key));
            total += (s - u).max(0.0) / sum * 100.0;
        }
    }
    total
}

#[test]
fn run_writes_every_output_and_report_regenerates_them() {
    let dir = tempfile::tempdir().unwrap();
    // the palletizer on a 3 × 3 × 3 grid (351 tasks) with 11 samples per task
    let samples = 11;
    let case = reduced_palletizer(3, samples);
    let case_path = write_case(dir.path(), "palletizer-small.json", &case);
    let out = dir.path().join("out");

    let run = counterpoise(&["run", &case_path, "--out", out.to_str().unwrap()]);
    assert_success(&run);
    for file in ["results.json", "report.html", "report.md", "ranking.csv"] {
        assert!(out.join(file).is_file(), "{file} missing");
        assert!(
            stdout(&run).contains(&format!("wrote {}", out.join(file).display())),
            "stdout names {file}"
        );
    }
    let results = results(&out);
    assert_eq!(results["schema_version"], 2);
    // docs/palletizer.md: 1990 kg in all with the 800 kg base, which does not move
    assert_eq!(results["moving_mass"], serde_json::json!(1188.625));
    let variants = results["variants"].as_array().unwrap();
    assert_eq!(variants.len(), 406, "paper Eq. A8");
    let counted: u64 = results["counts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["total"].as_u64().unwrap())
        .sum();
    assert_eq!(counted, 406);

    // A second method for the spring-only variants: springs are massless and balance gravity
    // exactly, so their motor torques are the unbalanced robot's without gravity.
    let mut no_gravity = case.clone();
    no_gravity["gravity"] = serde_json::json!([0.0, 0.0, 0.0]);
    let no_gravity_path = write_case(dir.path(), "no-gravity.json", &no_gravity);
    let inertial = counterpoise(&["evaluate", &no_gravity_path, "--json", "--no-reactions"]);
    assert_success(&inertial);
    let inertial: serde_json::Value = serde_json::from_str(&stdout(&inertial)).unwrap();
    let ub = &results["unbalanced"];
    let (qtr_ub, qit_ub) = (num(ub, "qtr"), num(ub, "qit"));
    let spring_dqtr = (num(&inertial, "qtr") - qtr_ub) / qtr_ub * 100.0;
    let spring_dqit = (num(&inertial, "qit") - qit_ub) / qit_ub * 100.0;

    let feasible: Vec<_> = variants
        .iter()
        .filter(|v| v["status"] == "feasible")
        .collect();
    let springs: Vec<_> = feasible
        .iter()
        .filter(|v| v["class"] == "springs")
        .collect();
    assert!(feasible.len() >= 2 && !springs.is_empty());
    for v in &feasible {
        for field in ["dqtr", "dqit", "dr", "rank", "class_rank"] {
            assert!(!v[field].is_null(), "{field} missing in {v}");
        }
        assert!(num(v, "verification_residual") <= 1e-9);
        // Eqs. 15, 16 and 17–21 from the stored indicators
        let ev = &v["evaluation"];
        let dqtr = (num(ev, "qtr") - qtr_ub) / qtr_ub * 100.0;
        let dqit = (num(ev, "qit") - qit_ub) / qit_ub * 100.0;
        assert!((num(v, "dqtr") - dqtr).abs() < 1e-9, "{dqtr} in {v}");
        assert!((num(v, "dqit") - dqit).abs() < 1e-9, "{dqit} in {v}");
        let dr = delta_r(ub, ev);
        assert!(
            (num(v, "dr") - dr).abs() < 1e-9 * (1.0 + dr),
            "ΔR {dr} in {v}"
        );
        // balanced: the motor torque is inertial only, below the unbalanced robot's
        assert!(num(v, "dqtr") < 0.0);
        // Practical figures from the parameters: masses add, a zero-free-length spring's
        // force is K times its stretch, shares are of the moving mass.
        let p = &v["practical"];
        let params = &v["parameters"];
        let masses: f64 = params["counterweights"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| num(c, "mass"))
            .sum();
        assert!((num(p, "added_mass") - masses).abs() < 1e-9, "{p}");
        assert!((num(p, "added_mass_percent") - masses / 1188.625 * 100.0).abs() < 1e-9);
        assert_eq!(
            p["elements"].as_u64().unwrap() as usize,
            v["elements"].as_array().unwrap().len()
        );
        let springs = params["springs"].as_array().unwrap();
        let peaks = p["springs"].as_array().cloned().unwrap_or_default();
        for (s, peak) in springs.iter().zip(&peaks) {
            assert_eq!(s["label"], peak["label"]);
            let expected = num(s, "stiffness") * num(peak, "elongation");
            assert!(
                (num(peak, "force") - expected).abs() < 1e-9 * expected,
                "{peak}"
            );
            // the anchors' distance can never exceed |a| + |b| plus the body origins' spread
            // (2 m on this robot), nor be negative
            assert!(num(peak, "elongation") > 0.0 && num(peak, "elongation") < 10.0);
        }
        assert_eq!(
            p["springs"].as_array().map_or(0, |a| a.len()),
            springs.len()
        );
    }
    assert!(
        results["spring_peaks_basis"]
            .as_str()
            .unwrap()
            .contains("27 task-grid points")
    );
    // The decision: an overall pick among the variants equivalent to rank 1.
    let overall = &results["decision"]["overall"];
    let rank1 = feasible.iter().find(|v| v["rank"] == 1).unwrap();
    assert_eq!(overall["leader"], rank1["id"]);
    let chosen = feasible
        .iter()
        .find(|v| v["id"] == overall["chosen"])
        .unwrap();
    assert!(num(chosen, "dqtr") <= num(rank1, "dqtr") + 0.5);
    assert!(num(chosen, "dqit") <= num(rank1, "dqit") + 0.5);
    for v in &springs {
        assert!(
            (num(v, "dqtr") - spring_dqtr).abs() < 1e-6,
            "ΔQTR {} vs gravity-free {spring_dqtr}",
            v["dqtr"]
        );
        assert!((num(v, "dqit") - spring_dqit).abs() < 1e-6);
    }

    // Ranks are 1..n; the lexicographic order means no variant more than one resolution
    // (0.01 pp) better in ΔQTR than the next-ranked one per tie-chain step follows it.
    let mut by_rank: Vec<_> = feasible.iter().collect();
    by_rank.sort_by_key(|v| v["rank"].as_u64().unwrap());
    let ranks: Vec<u64> = by_rank
        .iter()
        .map(|v| v["rank"].as_u64().unwrap())
        .collect();
    assert_eq!(ranks, (1..=feasible.len() as u64).collect::<Vec<_>>());
    let best_dqtr = feasible
        .iter()
        .map(|v| num(v, "dqtr"))
        .fold(f64::INFINITY, f64::min);
    assert!(num(by_rank[0], "dqtr") < best_dqtr + 0.01 * feasible.len() as f64);
    let csv = std::fs::read_to_string(out.join("ranking.csv")).unwrap();
    assert_eq!(
        csv.lines().count(),
        1 + feasible.len(),
        "header and one row each"
    );

    // The torque charts draw the unbalanced robot, per class the variant ranked first in it
    // (every class present among the feasible variants has its winner in every chart), and
    // the recommended variants.
    let winners: BTreeSet<u64> = feasible
        .iter()
        .filter(|v| v["class_rank"] == 1)
        .map(|v| v["id"].as_u64().unwrap())
        .collect();
    let classes: BTreeSet<&str> = feasible
        .iter()
        .map(|v| v["class"].as_str().unwrap())
        .collect();
    assert_eq!(winners.len(), classes.len(), "one winner per class");
    let decision = &results["decision"];
    let recommended = std::iter::once(&decision["overall"])
        .chain(decision["classes"].as_array().unwrap())
        .map(|r| r["chosen"].as_u64().unwrap());
    let winners: BTreeSet<u64> = winners.iter().copied().chain(recommended).collect();
    let charts = results["torque_charts"].as_array().unwrap();
    assert!(!charts.is_empty());
    for chart in charts {
        let curves = chart["curves"].as_array().unwrap();
        assert_eq!(curves[0]["label"], "UB");
        assert!(curves[0]["variant"].is_null());
        let shown: BTreeSet<u64> = curves[1..]
            .iter()
            .map(|c| c["variant"].as_u64().unwrap())
            .collect();
        assert_eq!(shown, winners, "curves of {}", chart["actuator"]);
        for c in curves {
            assert_eq!(
                c["values"].as_array().unwrap().len(),
                samples,
                "a value per sample"
            );
        }
    }

    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(html.contains("<svg"));
    assert!(
        results["path"]["dynamic_run"].is_object(),
        "the case's path Λ is simulated"
    );

    std::fs::remove_file(out.join("report.html")).unwrap();
    let report = counterpoise(&["report", out.to_str().unwrap()]);
    assert_success(&report);
    assert_eq!(
        std::fs::read_to_string(out.join("report.html")).unwrap(),
        html
    );
}

/// A ranked variant: rank, ΔQTR, ΔR, class and element labels (`m4 + K43`).
#[derive(Debug, PartialEq)]
struct Ranked {
    rank: u64,
    dqtr: f64,
    dr: f64,
    class: String,
    label: String,
}

/// Feasible variants of a results document, best first.
fn ranked(doc: &serde_json::Value) -> Vec<Ranked> {
    let mut v: Vec<_> = doc["variants"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|v| v["status"] == "feasible")
        .map(|v| Ranked {
            rank: v["rank"].as_u64().unwrap(),
            dqtr: num(v, "dqtr"),
            dr: num(v, "dr"),
            class: v["class"].as_str().unwrap().to_string(),
            label: v["elements"]
                .as_array()
                .unwrap()
                .iter()
                .map(|e| e["label"].as_str().unwrap())
                .collect::<Vec<_>>()
                .join(" + "),
        })
        .collect();
    v.sort_by_key(|x| x.rank);
    v
}

/// `run` with one and with two worker threads gives the same results.json apart from the
/// run's date, timings and thread count, and the same ranking.csv; `--resolution` changes
/// which differences count in the ranking.
#[test]
fn run_is_identical_with_one_and_two_threads_and_resolution_decides_ties() {
    let dir = tempfile::tempdir().unwrap();
    // 2 × 2 × 2 grid (28 tasks), 11 samples: seconds, not minutes
    let case_path = write_case(dir.path(), "tiny.json", &reduced_palletizer(2, 11));
    // `global` goes before the subcommand, `options` after it
    let run = |name: &str, global: &[&str], options: &[&str]| {
        let out = dir.path().join(name);
        let mut args = global.to_vec();
        args.extend(["run", &case_path, "--out", out.to_str().unwrap()]);
        args.extend_from_slice(options);
        let o = counterpoise(&args);
        assert_success(&o);
        let csv = std::fs::read_to_string(out.join("ranking.csv")).unwrap();
        (results(&out), csv)
    };
    let strip = |mut doc: serde_json::Value, jobs: u64| {
        let meta = doc["metadata"].as_object_mut().unwrap();
        assert_eq!(meta["jobs"], serde_json::json!(jobs));
        for volatile in ["jobs", "date", "timings"] {
            meta.remove(volatile);
        }
        doc
    };
    let (one, one_csv) = run("one", &[], &["--jobs", "1"]);
    let (two, two_csv) = run("two", &[], &["--jobs", "2"]);
    let one = strip(one, 1);
    assert_eq!(one, strip(two, 2));
    assert_eq!(one_csv, two_csv);

    // Default resolution (0.01 pp): ΔQTR decides first, so it never improves by more than the
    // resolution from one rank to the next. Spring-only variants have identical motor torques
    // (the robot's without gravity), so they tie on ΔQTR and ΔQIT and ΔR orders them.
    let fine = ranked(&one);
    assert!(fine.len() >= 2, "{fine:?}");
    for w in fine.windows(2) {
        assert!(w[1].dqtr >= w[0].dqtr - 0.01, "ΔQTR decides: {fine:?}");
    }
    let springs: Vec<&Ranked> = fine.iter().filter(|v| v.class == "springs").collect();
    assert!(springs.len() >= 2);
    for w in springs.windows(2) {
        assert!(
            w[0].dr <= w[1].dr + 0.01,
            "ΔR orders the springs: {springs:?}"
        );
    }
    // At 10⁶ pp every criterion ties (consecutive values are chained), so the element labels
    // alone give the order.
    let (coarse, _) = run("coarse", &[], &["--resolution", "1e6"]);
    let coarse = ranked(&coarse);
    for w in coarse.windows(2) {
        assert!(w[0].label < w[1].label, "labels decide: {coarse:?}");
    }
    assert_ne!(
        fine, coarse,
        "the resolution changes the order on this case"
    );
}
