//! Optimises the balanced variants of a case whose element labels match the arguments and
//! prints each record (status, reason, passes, parameters, indicators) as JSON: a tool to look
//! at one variant's optimisation without running the whole study.
//!
//! `MAX_NODES` in the environment sets the branch-and-bound's box limit, `SEED` the local
//! search's start seed (as `run --seed`), `GAP` the relative gap tolerance (as `run --gap`).
//!
//! ```text
//! cargo run --release -p counterpoise-optimise --example one_variant -- CASE DMAX m4+K42 [K32+K42 …]
//! ```

use counterpoise_balance::{
    Catalogue, SearchOptions, catalogue_options, mechanism_energy, realization_hints, search,
};
use counterpoise_model::Case;
use counterpoise_optimise::{Context, OptimiseOptions, optimise_all};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 4 {
        eprintln!("usage: one_variant CASE DMAX LABELS…  (LABELS like m4+K42)");
        std::process::exit(2);
    }
    let model = Case::from_path(std::path::Path::new(&args[1])).expect("the case loads");
    let dmax: usize = args[2].parse().expect("DMAX is a number");
    let energy = mechanism_energy(&model);
    let report = search(
        &energy,
        Catalogue::build(&energy, &catalogue_options(&model)),
        SearchOptions {
            dmax,
            hints: realization_hints(&model),
        },
    );
    let wanted: Vec<&String> = args[3..].iter().collect();
    let chosen: Vec<_> = report
        .variants
        .into_iter()
        .filter(|v| {
            let label = v
                .elements
                .iter()
                .map(|e| e.label.as_str())
                .collect::<Vec<_>>()
                .join("+");
            wanted.iter().any(|w| **w == label)
        })
        .collect();
    let ctx = Context::new(&model, None).expect("context");
    let mut options = OptimiseOptions::default();
    if let Some(n) = std::env::var("MAX_NODES").ok().and_then(|v| v.parse().ok()) {
        options.max_nodes = n;
    }
    if let Some(gap) = std::env::var("GAP").ok().and_then(|v| v.parse().ok()) {
        options.gap_tolerance = gap;
    }
    if let Some(seed) = std::env::var("SEED").ok().and_then(|v| v.parse().ok()) {
        options.start_seed = seed;
    }
    for out in optimise_all(&ctx, &chosen, &options) {
        println!(
            "{}",
            serde_json::to_string_pretty(&out).expect("records serialise")
        );
    }
}
