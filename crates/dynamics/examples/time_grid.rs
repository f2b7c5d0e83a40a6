//! Whole-run timing of the palletizer grid: `cargo run --release -p counterpoise-dynamics
//! --example time_grid [-- reactions]`.

use std::time::Instant;

use counterpoise_dynamics::{Counterweight, EvaluateOptions, ParameterSet, Variant, evaluate_grid};
use counterpoise_model::Case;

fn main() {
    let path = format!("{}/../../cases/palletizer.json", env!("CARGO_MANIFEST_DIR"));
    let model = Case::from_path(std::path::Path::new(&path)).unwrap();
    let reactions = std::env::args().any(|a| a == "reactions");
    let columns: usize = std::env::args()
        .filter_map(|a| a.strip_prefix("columns=").map(|v| v.parse().unwrap()))
        .next()
        .unwrap_or(if reactions { 13 } else { 1 });
    let mut variants = vec![Variant::default()];
    for c in 1..columns {
        variants.push(Variant {
            counterweights: vec![Counterweight {
                label: "cw".into(),
                body: model.bodies[c % 7].name.clone(),
                mass: 10.0 * c as f64,
                offset: [-0.3, 0.05 * c as f64, 0.0],
                plane: None,
            }],
            springs: vec![],
        });
    }
    let params = ParameterSet::from_variants(&model, &variants).unwrap();
    let options = EvaluateOptions {
        samples: None,
        reactions,
        shortcut: !std::env::args().any(|a| a == "direct"),
    };
    let ev = counterpoise_dynamics::Evaluator::new(&model).unwrap();
    println!(
        "reaction unknowns {} rank {} fast {}",
        ev.reactions.unknowns(),
        ev.reactions.rank,
        ev.reactions.is_fast()
    );
    let start = Instant::now();
    let grid = evaluate_grid(&model, &params, &options).unwrap();
    let secs = start.elapsed().as_secs_f64();
    let samples = grid.tasks.len() * grid.tasks.samples;
    let threads = rayon::current_num_threads();
    println!(
        "{} tasks × {} samples, {} columns, reactions {}: {:.3} s, {:.0} samples/s/core ({} threads)",
        grid.tasks.len(),
        grid.tasks.samples,
        params.len(),
        reactions,
        secs,
        samples as f64 / secs / threads as f64,
        threads
    );
    println!(
        "QTR {:.4} QIT {:.4} excluded {} cyclic {:?}",
        grid.indicators[0].qtr, grid.indicators[0].qit, grid.excluded.count, grid.cyclic_coordinate
    );
    println!("distinct moves {}", grid.distinct_moves);
    if let Some(j) = grid.indicators[0].joints.first() {
        println!("F_J1 {:.3} M_J1 {:.3}", j.force, j.moment);
    }
}
