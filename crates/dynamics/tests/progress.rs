//! The grid evaluation's progress hook: called once with 0 and once with every count up to the
//! number of units of work (sub-tasks with the cyclic shortcut, tasks without), from inside the
//! parallel loop, and the indicators are the same bits with or without it.

mod common;

use std::sync::Mutex;

use common::coarse_palletizer;
use counterpoise_dynamics::{
    Combination, EvaluateOptions, ParameterSet, Variant, evaluate_grid_indicators_reporting,
    evaluate_grid_indicators_with,
};

/// The `(done, total)` reports of one evaluation, sorted (threads report in any order).
fn reports(options: &EvaluateOptions, threads: usize) -> Vec<(usize, usize)> {
    let model = coarse_palletizer();
    let params = ParameterSet::from_variants(&model, &[Variant::default()]).unwrap();
    let seen = Mutex::new(Vec::new());
    let hook = |done: usize, total: usize| seen.lock().unwrap().push((done, total));
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let reported = pool
        .install(|| {
            evaluate_grid_indicators_reporting(&model, &params, options, Combination::Direct, &hook)
        })
        .unwrap();
    let silent =
        evaluate_grid_indicators_with(&model, &params, options, Combination::Direct).unwrap();
    assert_eq!(reported, silent, "the hook changes no result");
    let mut seen = seen.into_inner().unwrap();
    seen.sort();
    seen
}

/// `0, 1, …, total`, each once, all of `total`.
fn every_count(total: usize) -> Vec<(usize, usize)> {
    (0..=total).map(|d| (d, total)).collect()
}

#[test]
fn the_cyclic_shortcut_reports_every_sub_task_once() {
    // 3 × 3 × 3 grid points; with the base rotation factored out, 9 sub-points and their
    // 9·10/2 = 45 unordered pairs (a sub-point with itself included) are the sub-tasks.
    for threads in [1, 2] {
        for reactions in [false, true] {
            let options = EvaluateOptions {
                reactions,
                ..EvaluateOptions::default()
            };
            assert_eq!(reports(&options, threads), every_count(45));
        }
    }
}

#[test]
fn the_direct_path_reports_every_task_once() {
    // 27 grid points, every unordered pair of distinct points a task: 27·26/2 = 351.
    let options = EvaluateOptions {
        shortcut: false,
        ..EvaluateOptions::default()
    };
    for threads in [1, 2] {
        assert_eq!(reports(&options, threads), every_count(351));
    }
}
