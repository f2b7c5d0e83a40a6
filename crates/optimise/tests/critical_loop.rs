//! The critical-task loop's bookkeeping: where it starts (the paper's Proc-5), how many passes
//! it reports, and the stage timings it returns.
//!
//! Independent references: the unbalanced robot's indicators (the start set is defined by
//! them, independently of the loop's code), the wall clock read around the whole call (every
//! stage lies inside it, so the stages' wall times add up to at most the call's), and the
//! per-variant iteration records (a variant records one iteration per pass it was evaluated
//! in, and the variants of the last pass were active in every pass before it).

mod common;

use counterpoise_optimise::{Context, OptimiseOptions, optimise_all_timed};

#[test]
fn stage_times_lie_within_the_call_and_passes_match_the_iterations() {
    let model = common::model(&common::case_json("two_link.json"));
    let balanced = common::balanced_variants(&model);
    assert!(
        !balanced.is_empty(),
        "the two-link arm has balanced variants"
    );
    let ctx = Context::new(&model, None).unwrap();
    let options = OptimiseOptions::default();

    let started = std::time::Instant::now();
    let (results, timings) = optimise_all_timed(&ctx, &balanced, &options);
    let call = started.elapsed().as_secs_f64();

    // Every stage that has work ran for a positive time, inside the call.
    let stages = [
        ("solve", timings.solve),
        ("loop grid", timings.loop_grid),
        ("spring choice", timings.spring_choice),
        ("final grid", timings.final_grid),
        ("records", timings.records),
    ];
    for (name, t) in &stages[..2] {
        assert!(t.wall > 0.0, "{name}: wall {} s", t.wall);
    }
    for (name, t) in &stages {
        assert!(t.wall >= 0.0 && t.cpu >= 0.0, "{name}: {t:?}");
        assert!(t.wall <= call, "{name}: {} s in a {call} s call", t.wall);
    }
    let sum: f64 = stages.iter().map(|(_, t)| t.wall).sum();
    assert!(sum <= call, "stages add up to {sum} s in a {call} s call");

    // Passes: at least as many as the longest iteration record, at most one more (a variant
    // whose last pass failed records nothing for it), never more than allowed.
    let longest = results.iter().map(|r| r.iterations.len()).max().unwrap();
    assert!(longest >= 1, "some variant was evaluated");
    assert!(
        timings.passes >= longest && timings.passes <= longest + 1,
        "{} passes, longest record {longest}",
        timings.passes
    );
    assert!(timings.passes <= options.max_iterations);
}

/// The first pass starts from the unbalanced robot's critical tasks (paper Proc-5): each
/// actuator's CRT for RMS*, and for minimax also the QTR task. Checked on the two-link arm,
/// whose QTR task is not one of its CRTs, so the two objectives start from different sets.
#[test]
fn the_first_pass_starts_from_the_unbalanced_critical_tasks() {
    use counterpoise_optimise::Objective;
    use std::collections::BTreeSet;
    let model = common::model(&common::case_json("two_link.json"));
    for (objective, with_qtr) in [(Objective::RmsStar, false), (Objective::Minimax, true)] {
        let options = OptimiseOptions {
            objective,
            ..OptimiseOptions::default()
        };
        let (ctx, results) = common::optimise(&model, &[], &options);
        // Distinct grid tasks (a pair and its reverse are one task).
        let crts: BTreeSet<usize> = ctx
            .unbalanced
            .actuators
            .iter()
            .map(|a| ctx.task_index(a.crt).unwrap())
            .collect();
        let qtr = ctx.task_index(ctx.unbalanced.qtr_task).unwrap();
        assert!(
            !crts.contains(&qtr),
            "the case must have a QTR task outside the CRTs: {crts:?}, {qtr}"
        );
        let expected = crts.len() + usize::from(with_qtr);
        let first: Vec<usize> = results
            .iter()
            .filter_map(|r| r.iterations.first().map(|i| i.tasks))
            .collect();
        assert!(!first.is_empty());
        assert!(
            first.iter().all(|&n| n == expected),
            "{objective:?}: first-pass task counts {first:?}, expected {expected}"
        );
    }
}
