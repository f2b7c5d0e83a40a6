//! Micro-benchmark of the per-sample reaction factorisation and multi-RHS solve.

use std::time::Instant;

use counterpoise_dynamics::Evaluator;
use counterpoise_dynamics::lu::SmallLu;
use counterpoise_dynamics::mechanism::Scratch;
use counterpoise_dynamics::reactions::ReactionWork;
use counterpoise_model::Case;

fn main() {
    let path = format!("{}/../../cases/palletizer.json", env!("CARGO_MANIFEST_DIR"));
    let model = Case::from_path(std::path::Path::new(&path)).unwrap();
    let ev = Evaluator::new(&model).unwrap();
    let mech = &ev.mech;
    let q = model.reference_configuration();
    let mut scratch = Scratch::default();
    mech.eval_poses(&q, &mut scratch);
    let pose = scratch.pose.clone();
    let kin: Vec<_> = (0..mech.body_count)
        .map(|b| mech.body_frame(&pose, b))
        .collect();
    let mut u = [0.0; 12];
    let mut g = [0.0; 144];
    mech.actuator_map(&q, &mut scratch, &mut u, &mut g);
    let lu = SmallLu::new(&g, mech.n);
    let mut work = ReactionWork::default();
    let reps = 500;
    for m in [3usize, 39] {
        let mut best_prep = f64::INFINITY;
        let mut best_solve = f64::INFINITY;
        let mut out = vec![0.0; 66 * m];
        for _ in 0..200 {
            let t = Instant::now();
            for _ in 0..reps {
                ev.reactions.prepare(mech, &pose, &kin, &lu, &mut work);
            }
            best_prep = best_prep.min(t.elapsed().as_secs_f64() / reps as f64);
            let mut b = vec![1.0; 48 * m];
            let t = Instant::now();
            for _ in 0..reps {
                ev.reactions.solve_prepared(&mut work, &mut b, m, &mut out);
            }
            best_solve = best_solve.min(t.elapsed().as_secs_f64() / reps as f64);
        }
        println!(
            "m = {m}: prepare {:.2} µs, solve {:.2} µs",
            best_prep * 1e6,
            best_solve * 1e6
        );
    }
}
