//! The paper's eleven feasible sets on the palletizer (Table 1), on a reduced task grid
//! (3 × 3 × 3 points, 21 samples per move) to keep the test quick: each is optimised within the
//! case bounds and peak limits or discarded with a reason, and every feasible one reports its
//! relaxation gap and passes verification.

mod common;

use counterpoise_optimise::{OptimiseOptions, OptimisedStatus, display_rows};

const SETS: [&[&str]; 11] = [
    &["m4", "m5"],
    &["m4", "m6"],
    &["K43", "K53"],
    &["K42", "K43"],
    &["K42", "K53"],
    &["m4", "K43"],
    &["m4", "K53"],
    &["m4", "K42"],
    &["m4", "K52"],
    &["m6", "K43"],
    &["m6", "K52"],
];

pub fn reduced_palletizer() -> serde_json::Value {
    let mut json = common::case_json("palletizer.json");
    // Same ranges as the case, three values per actuator.
    for (_, axis) in json["tasks"]["grid"].as_object_mut().unwrap().iter_mut() {
        axis[2] = serde_json::json!(3);
    }
    json["tasks"]["samples"] = serde_json::json!(21);
    json
}

#[test]
fn the_papers_eleven_sets() {
    let model = common::model(&reduced_palletizer());
    let (_, results) = common::optimise(&model, &SETS, &OptimiseOptions::default());
    assert_eq!(results.len(), 11, "all eleven sets are balanced");
    for v in &results {
        let rows = display_rows(v);
        eprintln!(
            "{:?} {:?} objective {:?} bound {:?} gap {:?} passes {} reason {:?}",
            v.elements,
            v.status,
            v.objective,
            v.lower_bound,
            v.gap,
            v.iterations.len(),
            v.reason
        );
        for r in rows {
            eprintln!("    {r:?}");
        }
        match v.status {
            OptimisedStatus::Feasible => {
                let gap = v.gap.expect("feasible variants report a gap");
                assert!((0.0..=1.0).contains(&gap));
                let check = v.verification.as_ref().unwrap();
                assert!(check.passed);
                assert!(check.balance_residual <= 1e-9);
                assert!(check.bound_excess <= 1e-9);
                assert!(!v.iterations.is_empty());
                assert!(v.lower_bound.unwrap() <= v.objective.unwrap() * (1.0 + 1e-9));
                for fp in &v.free_parameters {
                    eprintln!(
                        "    free {:?}: {} in {:?}",
                        fp.components, fp.value, fp.interval
                    );
                    let tol = 1e-9 * fp.value.abs().max(1.0);
                    assert!(fp.interval[0] - tol <= fp.value && fp.value <= fp.interval[1] + tol);
                }
                if !v.springs.is_empty() {
                    assert!(v.delta_r_estimate.is_some(), "springs are chosen by ΔR");
                    assert!(!v.indicators.as_ref().unwrap().joints.is_empty());
                }
            }
            OptimisedStatus::Discarded | OptimisedStatus::Undecided => {
                assert!(v.reason.as_ref().is_some_and(|r| !r.is_empty()));
            }
        }
    }
    // Spring-only variants are dynamically identical: the same objective.
    let springs: Vec<f64> = results
        .iter()
        .filter(|v| v.is_feasible() && v.counterweights.is_empty())
        .map(|v| v.objective.unwrap())
        .collect();
    for w in springs.windows(2) {
        assert!((w[0] - w[1]).abs() <= 1e-9 * w[0]);
    }
    let json = serde_json::to_string(&results).unwrap();
    assert!(json.contains("\"status\""));
}
