//! The final all-task evaluation of a study's feasible designs, timed per way of combining
//! the reactions: `cargo run --release -p counterpoise-dynamics --example time_final --
//! RESULTS.json [direct|superposition|substitution|inertia] [samples=N] [torques] [step=K] [dump=PATH]` (the palletizer case; `torques`
//! leaves the reactions out; prints the wall time and a checksum of every peak, to compare
//! the ways; `dump` writes the peaks).

use std::time::Instant;

use counterpoise_dynamics::{
    Combination, EvaluateOptions, ParameterSet, Variant, evaluate_grid_indicators_with,
};
use counterpoise_model::Case;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let results: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&args[1]).expect("results.json reads"))
            .expect("results.json parses");
    let combination = match args.get(2).map(String::as_str) {
        Some("superposition") => Combination::Superposition,
        Some("substitution") => Combination::Substitution,
        Some("inertia") => Combination::InertiaSuperposition,
        _ => Combination::Direct,
    };
    let samples = args.iter().find_map(|a| {
        a.strip_prefix("samples=")
            .map(|v| v.parse().expect("a count"))
    });
    // `step=K` keeps every K-th design (a smaller batch of the same kinds).
    let step = args
        .iter()
        .find_map(|a| a.strip_prefix("step=").map(|v| v.parse().expect("a count")))
        .unwrap_or(1);
    let path = format!("{}/../../cases/palletizer.json", env!("CARGO_MANIFEST_DIR"));
    let model = Case::from_path(std::path::Path::new(&path)).expect("the palletizer loads");
    let variants: Vec<Variant> = results["variants"]
        .as_array()
        .expect("variants")
        .iter()
        .filter(|v| v["status"] == "feasible")
        .map(|v| serde_json::from_value(v["parameters"].clone()).expect("parameters"))
        .step_by(step)
        .collect();
    let params = ParameterSet::from_variants(&model, &variants).expect("variants");
    let options = EvaluateOptions {
        samples,
        reactions: !args.iter().any(|a| a == "torques"),
        ..EvaluateOptions::default()
    };
    let start = Instant::now();
    let grid = evaluate_grid_indicators_with(&model, &params, &options, combination)
        .expect("the grid evaluates");
    let secs = start.elapsed().as_secs_f64();
    let mut checksum = 0.0;
    for ind in &grid.indicators {
        checksum += ind.qtr + ind.qit;
        for j in &ind.joints {
            checksum += j.force + j.moment;
        }
    }
    println!(
        "{} variants, {combination:?}: {secs:.2} s, checksum {checksum:.15e}",
        variants.len()
    );
    if let Some(dump) = args.iter().find_map(|a| a.strip_prefix("dump=")) {
        let peaks: Vec<Vec<f64>> = grid
            .indicators
            .iter()
            .map(|ind| {
                let mut v = vec![ind.qtr, ind.qit];
                v.extend(ind.joints.iter().flat_map(|j| [j.force, j.moment]));
                v
            })
            .collect();
        std::fs::write(dump, serde_json::to_string(&peaks).expect("peaks")).expect("dump");
    }
}
