//! Timing of the optimisation stage on the palletizer: every balanced variant at Dmax = 2,
//! optimised with the critical-task loop over the case's task grid.
//!
//! ```text
//! cargo run --release -p counterpoise-optimise --example time_palletizer -- [runs] [grid-n] [samples]
//! ```
//!
//! `grid-n` replaces the number of grid values per actuator (default: the case's 7 — the full
//! 58,653-move grid); `samples` the samples per move. Phase 1 (the unbalanced indicators with
//! reactions) is timed once, separately; each run then builds the context from them and
//! optimises all balanced variants. Prints the per-run times, their median and a summary.

use std::time::Instant;

use counterpoise_balance::{
    Catalogue, SearchOptions, Status, catalogue_options, mechanism_energy, realization_hints,
    search,
};
use counterpoise_dynamics::{EvaluateOptions, evaluate_unbalanced_grid};
use counterpoise_model::Case;
use counterpoise_optimise::{
    Context, FinalReactionSolve, LoopTorques, OptimiseOptions, optimise_all,
};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let runs: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(3);
    let grid_n: Option<usize> = args.get(2).and_then(|s| s.parse().ok());
    let samples: Option<usize> = args.get(3).and_then(|s| s.parse().ok());
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../cases/palletizer.json");
    let mut json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    if let Some(n) = grid_n {
        for (_, axis) in json["tasks"]["grid"].as_object_mut().unwrap().iter_mut() {
            axis[2] = serde_json::json!(n);
        }
    }
    if let Some(s) = samples {
        json["tasks"]["samples"] = serde_json::json!(s);
    }
    let model = Case::from_json_str(&json.to_string()).unwrap();
    let energy = mechanism_energy(&model);
    let report = search(
        &energy,
        Catalogue::build(&energy, &catalogue_options(&model)),
        SearchOptions {
            dmax: 2,
            hints: realization_hints(&model),
        },
    );
    let balanced: Vec<_> = report
        .variants
        .iter()
        .filter(|v| v.status == Status::Balanced)
        .cloned()
        .collect();
    let t0 = Instant::now();
    let mut ub = evaluate_unbalanced_grid(&model, &EvaluateOptions::default()).unwrap();
    let phase1 = t0.elapsed().as_secs_f64();
    let ub = ub.indicators.swap_remove(0);
    eprintln!(
        "palletizer: {} tasks × {} samples, {} balanced variants; phase 1 (UB with reactions) {phase1:.2} s",
        counterpoise_dynamics::TaskSet::new(model.tasks.as_ref().unwrap(), None)
            .unwrap()
            .len(),
        model.tasks.as_ref().unwrap().samples,
        balanced.len()
    );
    let mut times = Vec::new();
    let mut last = Vec::new();
    for run in 0..runs {
        let t = Instant::now();
        let ctx = Context::new(&model, Some(ub.clone())).unwrap();
        // the final evaluation's reaction solve as a study chooses it
        let options = OptimiseOptions {
            final_reaction_solve: FinalReactionSolve::for_study(&model, balanced.len()),
            loop_torques: LoopTorques::for_study(&model, balanced.len()),
            ..OptimiseOptions::default()
        };
        last = optimise_all(&ctx, &balanced, &options);
        let s = t.elapsed().as_secs_f64();
        eprintln!("run {run}: {s:.2} s");
        times.push(s);
    }
    times.sort_by(f64::total_cmp);
    let median = times[times.len() / 2];
    let feasible = last.iter().filter(|v| v.is_feasible()).count();
    println!(
        "median {median:.2} s over {runs} runs; {feasible} feasible of {} balanced",
        last.len()
    );
    for v in &last {
        println!(
            "{:<12} {:<10} obj {:>9} gap {:>9} passes {} {}",
            v.elements.join(","),
            format!("{:?}", v.status),
            v.objective.map_or("-".into(), |o| format!("{o:.4}")),
            v.gap.map_or("-".into(), |g| format!("{g:.2e}")),
            v.iterations.len(),
            v.reason.clone().unwrap_or_default()
        );
    }
}
