//! The pipeline a user runs, on the palletizer (`cases/palletizer.json`), as criterion benches:
//!
//! - `study/dmax2`: the whole `run` computation at Dmax 2 — Phase 1 (the unbalanced robot over
//!   all 58,653 tasks, with reactions), the balance search, the optimisation of the 97 balanced
//!   variants (critical-task loop, certified spring stage, spring choice, final all-task
//!   evaluation with reactions); no report writing;
//! - `variants/dmax3`, `variants/dmax4`: the exact balance search (`variants --dmax N`);
//! - `grid/unbalanced_reactions`: the full-grid evaluation of the unbalanced robot with joint
//!   reactions (Phase 1);
//! - `final_grid/*`: the final all-task evaluation (torques and reactions) of the 50 feasible
//!   Dmax 2 designs, with the reactions solved per variant (`direct`), by superposition
//!   (`superposition`), and per variant with the inertia groups' changes summed
//!   (`inertia_sums`, a large study's final evaluation); and the same on 200 synthetic three-element variants (about as many
//!   as the lifted rows they touch; Dmax 3 has 785 finalists), over which superposition's
//!   fixed cost (one solve per lifted row the batch touches) is spread. At 11 and 5 samples per move
//!   instead of the case's 51, to keep the set short.
//!
//! `cargo bench` (or `cargo bench --bench pipeline`) runs them all, 10 samples each (the
//! least criterion takes), in under 10 minutes on two cores; `cargo bench -- final_grid` one
//! group. The medians are in the README's Performance section.

use std::time::Duration;

#[path = "../tests/common/variants.rs"]
mod variants;

use variants::balanced;

use counterpoise_dynamics::params::ParameterSet;
use counterpoise_dynamics::{
    Combination, Counterweight, EvaluateOptions, Spring, Variant, evaluate_grid_indicators_with,
    evaluate_unbalanced_grid,
};
use counterpoise_model::{Case, Model};
use counterpoise_optimise::{
    Context, FinalReactionSolve, OptimiseOptions, OptimisedVariant, optimise_all,
};
use criterion::{Criterion, criterion_group, criterion_main};

fn palletizer() -> Model {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/palletizer.json");
    Case::from_path(&path).expect("the palletizer case loads")
}

/// Phase 1, the search and the optimisation, as `run` chains them.
fn study(model: &Model, dmax: usize) -> Vec<OptimisedVariant> {
    let mut ub = evaluate_unbalanced_grid(model, &EvaluateOptions::default()).expect("phase 1");
    let variants = balanced(model, dmax);
    let ctx = Context::new(model, Some(ub.indicators.swap_remove(0))).expect("context");
    // the final evaluation's reaction solve as a study chooses it
    let options = OptimiseOptions {
        final_reaction_solve: FinalReactionSolve::for_study(model, variants.len()),
        ..OptimiseOptions::default()
    };
    optimise_all(&ctx, &variants, &options)
}

/// `count` three-element variants over the bodies and spring slots of the palletizer's
/// feasible designs (a counterweight on one of 5 members and two springs, or two
/// counterweights and one spring), every element with its own parameters, as the finalists of
/// a Dmax 3 study have.
fn synthetic_dmax3(model: &Model, finals: &[Variant], count: usize) -> Vec<Variant> {
    let cw_bodies: Vec<usize> = {
        let mut b: Vec<usize> = finals
            .iter()
            .flat_map(|v| v.counterweights.iter())
            .map(|c| model.body_index(&c.body).expect("a body of the model"))
            .collect();
        b.sort_unstable();
        b.dedup();
        b
    };
    let springs: Vec<Spring> = finals.iter().flat_map(|v| v.springs.clone()).collect();
    assert!(!cw_bodies.is_empty() && !springs.is_empty() && model.bodies.len() > 1);
    (0..count)
        .map(|k| {
            let scale = 1.0 + 0.001 * k as f64;
            let cw = |i: usize| Counterweight {
                label: format!("m{i}"),
                body: model.bodies[cw_bodies[(k + i) % cw_bodies.len()]]
                    .name
                    .clone(),
                mass: 50.0 * scale + 10.0 * i as f64,
                offset: [-0.3 * scale, 0.02 * i as f64, 0.0],
                plane: None,
            };
            let spring = |i: usize| {
                let mut s = springs[(3 * k + 7 * i) % springs.len()].clone();
                s.stiffness *= scale;
                s
            };
            if k % 2 == 0 {
                Variant {
                    counterweights: vec![cw(0)],
                    springs: vec![spring(0), spring(1)],
                }
            } else {
                Variant {
                    counterweights: vec![cw(0), cw(1)],
                    springs: vec![spring(0)],
                }
            }
        })
        .collect()
}

fn pipeline(c: &mut Criterion) {
    let model = palletizer();

    let mut group = c.benchmark_group("study");
    group.sample_size(10);
    group.warm_up_time(Duration::from_secs(1));
    group.measurement_time(Duration::from_secs(60));
    group.bench_function("dmax2", |b| b.iter(|| study(&model, 2)));
    group.finish();

    let mut group = c.benchmark_group("variants");
    group.sample_size(10);
    group.warm_up_time(Duration::from_secs(1));
    group.measurement_time(Duration::from_secs(5));
    group.bench_function("dmax3", |b| b.iter(|| balanced(&model, 3)));
    group.measurement_time(Duration::from_secs(30));
    group.bench_function("dmax4", |b| b.iter(|| balanced(&model, 4)));
    group.finish();

    let mut group = c.benchmark_group("grid");
    group.sample_size(10);
    group.warm_up_time(Duration::from_secs(1));
    group.measurement_time(Duration::from_secs(15));
    group.bench_function("unbalanced_reactions", |b| {
        b.iter(|| evaluate_unbalanced_grid(&model, &EvaluateOptions::default()))
    });
    group.finish();

    // The Dmax 2 designs, optimised once.
    let finals: Vec<Variant> = study(&model, 2)
        .iter()
        .filter(|o| o.is_feasible())
        .map(|o| o.physical_parameters())
        .collect();
    let params = ParameterSet::from_variants(&model, &finals).expect("variants");
    let mut group = c.benchmark_group("final_grid");
    group.sample_size(10);
    group.warm_up_time(Duration::from_secs(1));
    group.measurement_time(Duration::from_secs(20));
    let options = EvaluateOptions {
        samples: Some(11),
        ..EvaluateOptions::default()
    };
    for (name, combination) in [
        ("dmax2_direct", Combination::Direct),
        ("dmax2_superposition", Combination::Superposition),
        ("dmax2_inertia_sums", Combination::InertiaSuperposition),
    ] {
        group.bench_function(name, |b| {
            b.iter(|| evaluate_grid_indicators_with(&model, &params, &options, combination))
        });
    }
    let synthetic = synthetic_dmax3(&model, &finals, 200);
    let params = ParameterSet::from_variants(&model, &synthetic).expect("variants");
    // 5 samples per move: the comparison is per sample
    let options = EvaluateOptions {
        samples: Some(5),
        ..EvaluateOptions::default()
    };
    for (name, combination) in [
        ("synthetic200_direct", Combination::Direct),
        ("synthetic200_superposition", Combination::Superposition),
        (
            "synthetic200_inertia_sums",
            Combination::InertiaSuperposition,
        ),
    ] {
        group.bench_function(name, |b| {
            b.iter(|| evaluate_grid_indicators_with(&model, &params, &options, combination))
        });
    }
    group.finish();
}

criterion_group!(benches, pipeline);
criterion_main!(benches);
