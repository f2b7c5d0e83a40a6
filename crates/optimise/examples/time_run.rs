//! Timing of the palletizer run by phase, the way `counterpoise run` does it: Phase 1 (the
//! unbalanced robot over all tasks, with reactions), the balance search, the optimiser's context,
//! and each stage of the optimisation (relaxations and refinements, the loop's all-task torque
//! evaluations, the spring choice, the final all-task evaluation, the records).
//!
//! ```text
//! cargo run --release -p counterpoise-optimise --example time_run -- [dmax] [runs]
//! ```
//!
//! Defaults: Dmax = 3, 3 runs. Prints each run's phases, then per phase the median and the range
//! over the runs, and the verdict counts of the last run.

use counterpoise_balance::{
    Catalogue, SearchOptions, Status, catalogue_options, mechanism_energy, realization_hints,
    search,
};
use counterpoise_dynamics::{EvaluateOptions, evaluate_unbalanced_grid};
use counterpoise_model::Case;
use counterpoise_optimise::{
    Context, FinalReactionSolve, LoopTorques, OptimiseOptions, StageTime, Stopwatch,
    optimise_all_timed,
};

fn median_range(mut v: Vec<f64>) -> String {
    v.sort_by(f64::total_cmp);
    format!(
        "{:.2} s [{:.2}–{:.2}]",
        v[v.len() / 2],
        v[0],
        v[v.len() - 1]
    )
}

fn column(stages: &[StageTime], pick: impl Fn(&StageTime) -> f64) -> String {
    median_range(stages.iter().map(pick).collect())
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let dmax: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(3);
    let runs: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(3);
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../cases/palletizer.json");
    let model = Case::from_path(&path).expect("the palletizer case loads");
    let names = [
        "phase 1 (UB, reactions)",
        "balance search",
        "context",
        "optimisation: solve",
        "optimisation: loop grid",
        "optimisation: spring choice",
        "  of which option reactions",
        "optimisation: final grid",
        "optimisation: records",
        "total",
    ];
    let mut table: Vec<Vec<StageTime>> = vec![Vec::new(); names.len()];
    let mut last = Vec::new();
    for run in 0..runs {
        let start = Stopwatch::start();
        let t = Stopwatch::start();
        let mut ub =
            evaluate_unbalanced_grid(&model, &EvaluateOptions::default()).expect("phase 1");
        let phase1 = t.elapsed();
        let t = Stopwatch::start();
        let energy = mechanism_energy(&model);
        let report = search(
            &energy,
            Catalogue::build(&energy, &catalogue_options(&model)),
            SearchOptions {
                dmax,
                hints: realization_hints(&model),
            },
        );
        let searched = t.elapsed();
        let t = Stopwatch::start();
        let ctx = Context::new(&model, Some(ub.indicators.swap_remove(0))).expect("context");
        let context = t.elapsed();
        // as a study sets it, from the whole search
        let balanced = report
            .variants
            .iter()
            .filter(|v| v.status == Status::Balanced)
            .count();
        let options = OptimiseOptions {
            final_reaction_solve: FinalReactionSolve::for_study(&model, balanced),
            loop_torques: LoopTorques::for_study(&model, balanced),
            ..OptimiseOptions::default()
        };
        let (out, stages) = optimise_all_timed(&ctx, &report.variants, &options);
        let total = start.elapsed();
        let row = [
            phase1,
            searched,
            context,
            stages.solve,
            stages.loop_grid,
            stages.spring_choice,
            stages.spring_reactions,
            stages.final_grid,
            stages.records,
            total,
        ];
        eprintln!(
            "run {run}: {} ({} passes, {} variants searched)",
            names
                .iter()
                .zip(row)
                .map(|(n, s)| format!("{n} {:.2} s ({:.2} s CPU)", s.wall, s.cpu))
                .collect::<Vec<_>>()
                .join(", "),
            stages.passes,
            stages.searched
        );
        for (col, s) in table.iter_mut().zip(row) {
            col.push(s);
        }
        last = vec![(balanced, out)];
    }
    println!(
        "palletizer, Dmax = {dmax}, {runs} runs (median [min–max]), wall and CPU (all threads):"
    );
    for (n, col) in names.iter().zip(table) {
        println!(
            "  {n:<30} {}   CPU {}",
            column(&col, |t| t.wall),
            column(&col, |t| t.cpu)
        );
    }
    if let Some((balanced, out)) = last.pop() {
        let feasible = out.iter().filter(|v| v.is_feasible()).count();
        println!(
            "{balanced} balanced variants: {feasible} feasible, {} not",
            out.len() - feasible
        );
    }
}
