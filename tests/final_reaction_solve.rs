//! A study chooses how its final evaluation solves the joint reactions from its whole balance
//! search (`FinalReactionSolve::for_study`), and `run` applies that choice: on the palletizer
//! at Dmax 2 (97 balanced variants, below the palletizer's 120) by substitution. The two ways
//! agree to rounding and differ in the last bits, so the run's joint reaction peaks identify
//! the way taken: they are the bits of the optimiser run with substitution, and not all those
//! of the run with the reaction operator.

mod common;

use std::collections::BTreeMap;

use common::variants::balanced;
use common::{reduced_palletizer, results, run_reduced_palletizer};

use counterpoise_dynamics::{EvaluateOptions, evaluate_unbalanced_grid};
use counterpoise_model::Case;
use counterpoise_optimise::{
    Context, FinalReactionSolve, OptimiseOptions, OptimisedVariant, optimise_all,
};

/// Per feasible variant (its sorted element labels), its joint reaction peaks in joint order,
/// force and moment.
type Peaks = BTreeMap<Vec<String>, Vec<f64>>;

fn optimiser_peaks(optimised: &[OptimisedVariant]) -> Peaks {
    optimised
        .iter()
        .filter(|o| o.is_feasible())
        .map(|o| {
            let mut labels = o.elements.clone();
            labels.sort();
            let joints = &o.indicators.as_ref().expect("indicators").joints;
            let peaks = joints.iter().flat_map(|j| [j.force, j.moment]).collect();
            (labels, peaks)
        })
        .collect()
}

fn run_peaks(results: &serde_json::Value) -> Peaks {
    results["variants"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|v| v["status"] == "feasible")
        .map(|v| {
            let mut labels: Vec<String> = v["elements"]
                .as_array()
                .unwrap()
                .iter()
                .map(|e| e["label"].as_str().unwrap().to_string())
                .collect();
            labels.sort();
            let peaks = v["evaluation"]["joints"]
                .as_array()
                .unwrap()
                .iter()
                .flat_map(|j| [j["force"].as_f64().unwrap(), j["moment"].as_f64().unwrap()])
                .collect();
            (labels, peaks)
        })
        .collect()
}

#[test]
fn run_solves_the_final_reactions_as_its_study_size_chooses() {
    let dir = tempfile::tempdir().unwrap();
    let from_run = run_peaks(&results(&run_reduced_palletizer(dir.path())));

    // the case that run: the palletizer on its reduced grid
    let model = Case::from_json_str(&reduced_palletizer(2, 11).to_string()).unwrap();
    let balanced = balanced(&model, 2);
    assert_eq!(balanced.len(), 97);
    assert_eq!(
        FinalReactionSolve::for_study(&model, balanced.len()),
        FinalReactionSolve::Substitution
    );
    let mut ub = evaluate_unbalanced_grid(&model, &EvaluateOptions::default()).unwrap();
    let ctx = Context::new(&model, Some(ub.indicators.swap_remove(0))).unwrap();
    let optimise = |final_reaction_solve| {
        let options = OptimiseOptions {
            final_reaction_solve,
            ..OptimiseOptions::default()
        };
        optimiser_peaks(&optimise_all(&ctx, &balanced, &options))
    };
    let by_substitution = optimise(FinalReactionSolve::Substitution);
    let by_operator = optimise(FinalReactionSolve::Operator);
    assert!(from_run.len() >= 40, "{} feasible variants", from_run.len());
    // the first peak whose bits differ between two sets of results (variant, joint value)
    let first_difference = |a: &Peaks, b: &Peaks| -> Option<(Vec<String>, usize)> {
        assert_eq!(a.keys().collect::<Vec<_>>(), b.keys().collect::<Vec<_>>());
        a.iter().find_map(|(labels, peaks)| {
            (0..peaks.len())
                .find(|&n| peaks[n].to_bits() != b[labels][n].to_bits())
                .map(|n| (labels.clone(), n))
        })
    };
    assert_eq!(
        first_difference(&from_run, &by_substitution),
        None,
        "run against the optimiser by substitution"
    );
    // the operator's peaks agree to rounding, but not to the last bit everywhere
    assert!(first_difference(&from_run, &by_operator).is_some());
    for (labels, peaks) in &by_operator {
        for (x, y) in peaks.iter().zip(&from_run[labels]) {
            assert!(
                (x - y).abs() <= 1e-12 * x.abs().max(1.0),
                "{labels:?}: {x} {y}"
            );
        }
    }
}
