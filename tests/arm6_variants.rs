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
