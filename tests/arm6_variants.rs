//! `variants` on a 6-axis arm imported from a URDF of the project's own (`cases/arm6.urdf` →
//! `cases/arm6.json`): at Dmax 3 it used to panic in nalgebra's SVD ("Singular value was NaN")
//! on the variant m1 + K61 + K65.

mod common;

use common::{assert_success, counterpoise, stderr};

/// Dmax 3 finishes, with every one of the C(27,1) + C(27,2) + C(27,3) = 27 + 351 + 2925 = 3303
/// variants decided or reported undecided with a reason, and no panic.
#[test]
fn arm6_variants_at_dmax_3_finish_without_a_panic() {
    let out = counterpoise(&["variants", "cases/arm6.json", "--dmax", "3", "--json"]);
    assert_success(&out);
    assert!(!stderr(&out).contains("panicked"), "{}", stderr(&out));
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let variants = doc["variants"].as_array().unwrap();
    assert_eq!(variants.len(), 3303);
    let total: u64 = doc["counts"]
        .as_object()
        .unwrap()
        .values()
        .map(|v| v.as_u64().unwrap())
        .sum();
    assert_eq!(total, 3303);
    for v in variants {
        if v["status"] != "balanced" {
            assert!(v["reason"].is_string(), "{v}");
        }
    }
    let former = variants
        .iter()
        .find(|v| {
            let labels: Vec<&str> = v["elements"]
                .as_array()
                .unwrap()
                .iter()
                .map(|e| e["label"].as_str().unwrap())
                .collect();
            labels == ["m1", "K61", "K65"]
        })
        .expect("m1 + K61 + K65 enumerated");
    assert_eq!(former["status"], "infeasible");
    assert_eq!(former["decision"], "exact");
}

/// `--minimal` at Dmax 6: the 54 minimal sets (27 pairs, 27 triples; the balance crate's test
/// checks them against brute force at Dmax 4), none realizable, and Dmax 3 as the smallest at
/// which a variant balances — the full search at Dmax 2 finds no realizable variant and at
/// Dmax 3 finds 34 (m2 + m3 + m5 among them).
#[test]
fn arm6_minimal_sets_up_to_dmax_6() {
    let out = counterpoise(&[
        "variants",
        "cases/arm6.json",
        "--dmax",
        "6",
        "--minimal",
        "--json",
    ]);
    assert_success(&out);
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let minimal = &doc["minimal"];
    assert_eq!(minimal["smallest_linear"], 2);
    assert_eq!(minimal["smallest_balanced"], 3);
    assert_eq!(minimal["disagreements"], 0);
    // C(27, ≤ 6) = 27 + 351 + 2925 + 17550 + 80730 + 296010.
    assert_eq!(minimal["combinations"], "397593");
    assert!(minimal["tested"].as_u64().unwrap() < 397_593 / 4);
    let sets = doc["variants"].as_array().unwrap();
    assert_eq!(sets.len(), 54);
    assert!(sets.iter().all(|v| v["status"] != "balanced"));
    let first: Vec<Vec<&str>> = minimal["first_balanced"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| {
            v["elements"]
                .as_array()
                .unwrap()
                .iter()
                .map(|e| e["label"].as_str().unwrap())
                .collect()
        })
        .collect();
    assert!(first.contains(&vec!["m2", "m3", "m5"]), "{first:?}");
    assert!(first.iter().all(|s| s.len() == 3));
}

/// The guard of `--minimal` measures the pruned walk, not `C(n, ≤ Dmax)`: at Dmax 6 the full
/// count (397,593) is refused by the default limit of 30,000 variants, the walk is not; with the
/// limit lowered to 10 it is refused too, and says it counted after pruning.
#[test]
fn the_minimal_guard_estimates_the_pruned_walk() {
    let full = counterpoise(&["variants", "cases/arm6.json", "--dmax", "6"]);
    assert_eq!(full.status.code(), Some(1));
    assert!(
        stderr(&full).contains("397,593 variants"),
        "{}",
        stderr(&full)
    );
    let refused = counterpoise(&[
        "--limit",
        "variants=10",
        "variants",
        "cases/arm6.json",
        "--dmax",
        "6",
        "--minimal",
    ]);
    assert_eq!(refused.status.code(), Some(1), "{}", stderr(&refused));
    assert!(
        stderr(&refused).contains("after pruning"),
        "{}",
        stderr(&refused)
    );
}
