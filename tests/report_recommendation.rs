//! The report follows the recommendation (issue 31, item 5): the torque charts and the path
//! simulation show the recommended variants beside the best-ranked of each class, and name
//! them as recommended. On the palletizer with a 2 × 2 × 2 task grid (seconds).

mod common;

use std::collections::BTreeSet;

use common::{assert_success, counterpoise, results, run_reduced_palletizer};

#[test]
fn torque_charts_and_path_show_the_recommended_variants() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_reduced_palletizer(dir.path());
    let doc = results(&out);
    let decision = &doc["decision"];
    let recommended: BTreeSet<u64> = std::iter::once(&decision["overall"])
        .chain(decision["classes"].as_array().unwrap())
        .map(|r| r["chosen"].as_u64().unwrap())
        .collect();
    let best: BTreeSet<u64> = doc["variants"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|v| v["class_rank"] == 1)
        .map(|v| v["id"].as_u64().unwrap())
        .collect();
    assert!(!recommended.is_empty() && !best.is_empty());
    let expected: BTreeSet<u64> = recommended.union(&best).copied().collect();

    // Every torque chart: UB first, then exactly the best-ranked and the recommended variants,
    // the recommended ones named so.
    let charts = doc["torque_charts"].as_array().unwrap();
    assert!(!charts.is_empty());
    for chart in charts {
        let curves = chart["curves"].as_array().unwrap();
        assert_eq!(curves[0]["label"], "UB");
        let ids: BTreeSet<u64> = curves[1..]
            .iter()
            .map(|c| c["variant"].as_u64().unwrap())
            .collect();
        assert_eq!(ids, expected, "{}", chart["actuator"]);
        for c in &curves[1..] {
            let id = c["variant"].as_u64().unwrap();
            let label = c["label"].as_str().unwrap();
            assert_eq!(
                label.ends_with(", recommended"),
                recommended.contains(&id),
                "{label}"
            );
        }
    }
    // The path simulation and its table cover the same mechanisms.
    let path = &doc["path"];
    let mechanisms: BTreeSet<u64> = path["dynamic_run"]["mechanisms"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|m| m["variant"].as_u64())
        .collect();
    assert_eq!(mechanisms, expected);
    let table: BTreeSet<&str> = path["table"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["mechanism"].as_str().unwrap())
        .collect();
    assert_eq!(table.len(), 1 + expected.len(), "UB and each shown variant");
    // The HTML highlights the recommended variants' rows.
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(html.contains("<tr class=\"rec\">") || html.contains("<tr class=\"g rec\">"));
}

/// `report DIR --tolerance` re-decides, and the torque curves follow the new recommendation
/// (issue 31, item 9): at tolerance 0 every scope's recommendation is its best-ranked variant.
#[test]
fn report_with_another_tolerance_redraws_the_curves() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_reduced_palletizer(dir.path());
    let doc = results(&out);
    assert_success(&counterpoise(&[
        "report",
        out.to_str().unwrap(),
        "--tolerance",
        "0",
    ]));
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    // Tolerance 0: only variants no worse on ΔQTR and ΔQIT than the leader are equivalent;
    // the overall leader (SB1) is one, so the overall recommendation is among them. Every
    // class's best-ranked variant that no other of its class beats on ΔQIT is recommended;
    // at least SB1's own class leader is, and it is named "recommended" in the torque charts.
    let sb1 = doc["variants"]
        .as_array()
        .unwrap()
        .iter()
        .find(|v| v["rank"] == 1)
        .unwrap();
    let labels: Vec<&str> = sb1["elements"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["label"].as_str().unwrap())
        .collect();
    // At the default tolerance SB1 was not recommended (so its curves were unlabelled).
    let before: Vec<&serde_json::Value> = std::iter::once(&doc["decision"]["overall"])
        .chain(doc["decision"]["classes"].as_array().unwrap())
        .map(|r| &r["chosen"])
        .collect();
    assert!(!before.contains(&&sb1["id"]), "SB1 was already recommended");
    let name = format!("SB1 ({}), recommended", labels.join(" + "));
    let torque = &html[html.find("Motor torques on the critical tasks").unwrap()..];
    assert!(torque.contains(&name), "{name} not in the torque charts");
}
