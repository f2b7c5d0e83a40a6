//! Energy curves (issue 31, item 2): the potential energy drawn for a balanced variant is
//! constant to 1e-9 relative along the motion, and the unbalanced mechanism's is not — it
//! changes by the hand-computed difference between the motion's ends.

mod common;

use common::{assert_success, counterpoise, results, root, run_reduced_palletizer};

/// (max − min) of a curve.
fn spread(values: &[f64]) -> f64 {
    let max = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let min = values.iter().copied().fold(f64::INFINITY, f64::min);
    max - min
}

/// The energy chart of a run: (UB's values, each variant's (label, values)).
fn curves(doc: &serde_json::Value) -> (Vec<f64>, Vec<(String, Vec<f64>)>) {
    let e = &doc["energy"];
    let values = |c: &serde_json::Value| -> Vec<f64> {
        c["values"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    let all = e["curves"].as_array().unwrap();
    assert_eq!(all[0]["label"], "UB");
    let variants = all[1..]
        .iter()
        .map(|c| (c["label"].as_str().unwrap().to_string(), values(c)))
        .collect();
    (values(&all[0]), variants)
}

/// Balanced curves flat to 1e-9 of the unbalanced one's swing; the unbalanced one is not.
fn assert_flat_against_unbalanced(doc: &serde_json::Value) {
    let (ub, variants) = curves(doc);
    let swing = spread(&ub);
    assert!(swing > 1.0, "UB energy swing {swing} J");
    assert!(!variants.is_empty());
    for (label, v) in &variants {
        assert_eq!(v.len(), ub.len());
        let s = spread(v);
        assert!(
            s <= 1e-9 * swing,
            "{label}: energy spread {s} J, UB {swing} J"
        );
    }
    // The recommended variants are the ones drawn.
    let recommended = std::iter::once(&doc["decision"]["overall"])
        .chain(doc["decision"]["classes"].as_array().unwrap())
        .map(|r| r["chosen"].as_u64().unwrap())
        .collect::<std::collections::BTreeSet<_>>();
    let drawn = doc["energy"]["curves"].as_array().unwrap()[1..]
        .iter()
        .map(|c| c["variant"].as_u64().unwrap())
        .collect::<std::collections::BTreeSet<_>>();
    assert_eq!(drawn, recommended);
}

#[test]
fn two_link_energy_is_flat_when_balanced_and_swings_by_hand_when_not() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let case = root().join("cases/two_link.json");
    assert_success(&counterpoise(&[
        "run",
        case.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]));
    let doc = results(&out);
    assert_flat_against_unbalanced(&doc);
    // Without a path the motion is the unbalanced robot's QTR task; its ends are grid points
    // (3 × 3 grid, M1 slowest: index = 3·i1 + i2, M1 in {−1, 0, 1}, M2 in {−1.5, 0, 1.5},
    // u = q). By hand, V = g·[(4·0.4 + 2.5·0.8 + 1·0.8)·sin q1 + (2.5·0.3 + 1·0.6)·sin(q1+q2)]
    // = 9.81·[4.4·sin q1 + 1.35·sin(q1 + q2)] (links, and the tool payload counted by the
    // balancing).
    let task = &doc["unbalanced"]["qtr_task"];
    let q = |k: u64| {
        let (i1, i2) = (k / 3, k % 3);
        (-1.0 + i1 as f64, -1.5 + 1.5 * i2 as f64)
    };
    let v = |(q1, q2): (f64, f64)| 9.81 * (4.4 * q1.sin() + 1.35 * (q1 + q2).sin());
    let (from, to) = (task[0].as_u64().unwrap(), task[1].as_u64().unwrap());
    let expected = v(q(to)) - v(q(from));
    let (ub, _) = curves(&doc);
    assert!(ub[0] == 0.0);
    let last = *ub.last().unwrap();
    assert!(
        (last - expected).abs() <= 1e-9 * expected.abs(),
        "UB energy change {last} J, by hand {expected} J"
    );
    assert!(
        doc["energy"]["along"]
            .as_str()
            .unwrap()
            .starts_with(&format!("task {from}→{to}"))
    );
}

#[test]
fn palletizer_energy_along_its_path_is_flat_when_balanced() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_reduced_palletizer(dir.path());
    let doc = results(&out);
    assert!(
        doc["energy"]["along"]
            .as_str()
            .unwrap()
            .starts_with("path ")
    );
    assert_flat_against_unbalanced(&doc);
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(html.contains("The proof: potential energy"));
}
