//! The reports' partial-balancing section (issue 27): when `run` finds nothing feasible, its
//! table carries partial.json's numbers (read back from the file and formatted here), the chart
//! and the smallest-Dmax statement are in report.html, `report DIR` keeps the section, and a
//! study with a feasible variant has no such section.

mod common;

use common::{assert_success, counterpoise, stdout};
use serde_json::Value;

/// A change in % as the reports write it: one decimal, a sign on a rise, no negative zero.
fn change(value: f64, reference: f64) -> String {
    let c = 100.0 * (value / reference - 1.0);
    let s = format!("{c:.1}");
    let s = if s == "-0.0" { "0.0".to_string() } else { s };
    if c > 0.0 && s != "0.0" {
        format!("+{s} %")
    } else {
        format!("{s} %")
    }
}

/// The cells of the Markdown table under `## Partial balancing`, without emphasis or escapes.
fn partial_table(md: &str) -> Vec<Vec<String>> {
    let section = md
        .split("## Partial balancing (no feasible variant)")
        .nth(1)
        .expect("a partial-balancing section in report.md");
    let section = section.split("\n## ").next().unwrap();
    section
        .lines()
        .filter(|l| l.starts_with('|'))
        .map(|l| {
            l.trim_matches('|')
                .split(" | ")
                .map(|c| c.trim().trim_matches('*').replace('\\', ""))
                .collect()
        })
        .collect()
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap()
}

#[test]
fn the_partial_section_shows_partial_json_and_only_when_nothing_is_feasible() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("arm6");
    let out = counterpoise(&[
        "run",
        "cases/arm6.json",
        "--out",
        out_dir.to_str().unwrap(),
        "--quiet",
    ]);
    assert_success(&out);
    let doc: Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("partial.json")).unwrap())
            .unwrap();
    let md = std::fs::read_to_string(out_dir.join("report.md")).unwrap();
    let rows = partial_table(&md);
    let actuators: Vec<&str> = doc["actuators"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a.as_str().unwrap())
        .collect();
    let unbalanced: Vec<f64> = doc["unbalanced_rms"]
        .as_array()
        .unwrap()
        .iter()
        .map(f)
        .collect();
    let designs = doc["designs"].as_array().unwrap();
    // A column per actuator that carries gravity torque somewhere (the arm's vertical pan axis
    // and last wrist joint carry none).
    let loaded: Vec<usize> = (0..actuators.len())
        .filter(|&j| unbalanced[j] > 0.0 || designs.iter().any(|d| f(&d["rms"][j]) > 0.0))
        .collect();
    assert_eq!(loaded.len(), 4, "{unbalanced:?}");
    let header = &rows[0];
    for (k, &j) in loaded.iter().enumerate() {
        assert_eq!(header[5 + k], format!("Δ {}", actuators[j]));
    }
    // Header, alignment row, the unbalanced robot, then every design (21 ≤ 30 rows shown).
    assert_eq!(rows.len(), 3 + designs.len(), "{md}");
    let total = f(&doc["unbalanced_total"]);
    assert_eq!(rows[2][3], format!("{total:.3}"));
    for (k, &j) in loaded.iter().enumerate() {
        assert_eq!(rows[2][5 + k], format!("{:.3} N·m", unbalanced[j]));
    }
    let exact: Vec<(u64, &str)> = doc["exact"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| (e["rank"].as_u64().unwrap(), e["status"].as_str().unwrap()))
        .collect();
    for (i, d) in designs.iter().enumerate() {
        let row = &rows[3 + i];
        let labels: Vec<&str> = d["labels"]
            .as_array()
            .unwrap()
            .iter()
            .map(|l| l.as_str().unwrap())
            .collect();
        assert_eq!(row[0], (i + 1).to_string());
        assert_eq!(row[1], labels.join(" + "));
        assert_eq!(row[3], format!("{:.3}", f(&d["total_rms"])));
        assert_eq!(row[4], change(f(&d["total_rms"]), total));
        for (k, &j) in loaded.iter().enumerate() {
            assert_eq!(
                row[5 + k],
                change(f(&d["rms"][j]), unbalanced[j]),
                "{row:?}"
            );
        }
        for (cw, label) in d["counterweights"].as_array().unwrap().iter().zip(&labels) {
            let unused = d["unused"]
                .as_array()
                .is_some_and(|u| u.iter().any(|x| x == label));
            let expected = if unused {
                format!("{label} on ")
            } else {
                format!("{:.3} kg", f(&cw["mass"]))
            };
            assert!(row[2].contains(&expected), "{expected} in {row:?}");
        }
        let verdict = exact
            .iter()
            .find(|(rank, _)| *rank == i as u64 + 1)
            .map_or("", |(_, s)| *s);
        assert_eq!(row[row.len() - 1], verdict);
    }
    // Two counterweights on the arm leave 2.115 of 32.843 (README).
    assert_eq!(rows[3][3], "2.115");
    assert_eq!(rows[3][4], "-93.6 %");

    let html = std::fs::read_to_string(out_dir.join("report.html")).unwrap();
    assert!(html.contains("<h2 id=\"partial\">"));
    assert!(html.contains("the smallest Dmax at which one does is 3"));
    // The chart's unbalanced bar of the shoulder, in N·m, and a bar of the best pair.
    assert!(
        html.contains(&format!(
            "shoulder_lift unbalanced: {:.3} N·m",
            unbalanced[1]
        )),
        "no unbalanced shoulder bar"
    );
    assert!(html.contains(&format!(
        "shoulder_lift m2 + m3 (best of 2 counterweights, rank 1): {:.3} N·m",
        f(&designs[0]["rms"][1])
    )));
    // results.json carries the section, so `report DIR` draws it again.
    std::fs::remove_file(out_dir.join("report.md")).unwrap();
    assert_success(&counterpoise(&["report", out_dir.to_str().unwrap()]));
    let again = std::fs::read_to_string(out_dir.join("report.md")).unwrap();
    assert_eq!(partial_table(&again), rows);

    let feasible = dir.path().join("pendulum");
    let out = counterpoise(&[
        "run",
        "cases/pendulum.json",
        "--out",
        feasible.to_str().unwrap(),
        "--quiet",
    ]);
    assert_success(&out);
    assert!(!stdout(&out).contains("No feasible variant"));
    let md = std::fs::read_to_string(feasible.join("report.md")).unwrap();
    let html = std::fs::read_to_string(feasible.join("report.html")).unwrap();
    assert!(!md.contains("Partial balancing"));
    assert!(!html.contains("id=\"partial\""));
    let results: Value =
        serde_json::from_str(&std::fs::read_to_string(feasible.join("results.json")).unwrap())
            .unwrap();
    assert!(results.get("partial").is_none());
}
