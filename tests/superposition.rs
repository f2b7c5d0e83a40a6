//! Joint reactions and motor torques by superposition against the direct solve, on every
//! feasible variant of the palletizer at Dmax 2 (issue 29): the dynamics crate's
//! `Combination::Superposition` sums the model's outputs and its elements' unit-row outputs;
//! `Combination::Direct` solves each variant's own right-hand side;
//! `Combination::InertiaSuperposition` solves each variant directly and sums only its inertia
//! group's changes with the rotation speed. They are independent computations of the same
//! linear map, so every peak must agree to rounding.

mod common;

use std::time::Instant;

use common::variants::balanced;

use counterpoise_dynamics::params::ParameterSet;
use counterpoise_dynamics::{
    Combination, Counterweight, EvaluateOptions, Indicators, Spring, Variant, evaluate_grid,
    evaluate_grid_indicators_with,
};
use counterpoise_model::Case;
use counterpoise_optimise::{Context, OptimiseOptions, optimise_all};

/// `|a − b|` relative to `max(|a|, |b|, floor)`: a peak that is exactly zero in one method
/// (a joint the variant leaves unloaded) may be a rounding residue in the other.
fn relative(a: f64, b: f64, floor: f64) -> f64 {
    (a - b).abs() / a.abs().max(b.abs()).max(floor)
}

#[test]
fn every_reaction_peak_of_every_feasible_dmax2_variant_equals_the_direct_solve() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/palletizer.json");
    let model = Case::from_path(&path).expect("the palletizer loads");
    let mut ub = evaluate_grid(
        &model,
        &ParameterSet::unbalanced(&model),
        &EvaluateOptions::default(),
    )
    .expect("phase 1");
    let balanced = balanced(&model, 2);
    let ctx = Context::new(&model, Some(ub.indicators.swap_remove(0))).unwrap();
    let optimised = optimise_all(&ctx, &balanced, &OptimiseOptions::default());
    let variants: Vec<Variant> = optimised
        .iter()
        .filter(|o| o.is_feasible())
        .map(|o| o.physical_parameters())
        .collect();
    // README: 50 feasible variants at Dmax 2, of every class
    assert_eq!(variants.len(), 50);
    assert!(variants.iter().any(|v| v.springs.is_empty()));
    assert!(variants.iter().any(|v| v.counterweights.is_empty()));
    assert!(
        variants
            .iter()
            .any(|v| !v.springs.is_empty() && !v.counterweights.is_empty())
    );
    let params = ParameterSet::from_variants(&model, &variants).unwrap();
    let options = EvaluateOptions::default();
    let run = |combination| -> Vec<Indicators> {
        let started = Instant::now();
        let grid = evaluate_grid_indicators_with(&model, &params, &options, combination)
            .expect("the grid evaluates");
        eprintln!("{combination:?}: {:.2} s", started.elapsed().as_secs_f64());
        assert_eq!(grid.excluded.count, 0);
        grid.indicators
    };
    let direct = run(Combination::Direct);
    let mut worst: f64 = 0.0;
    let mut compared = 0;
    // Every variant summed over the basis, and every variant direct with its inertia group's
    // changes summed.
    for other in [
        Combination::Superposition,
        Combination::InertiaSuperposition,
    ] {
        let superposed = run(other);
        for (d, s) in direct.iter().zip(&superposed) {
            // a peak below 1e-9 of the variant's largest joint force or moment is zero to rounding
            let floor = d
                .joints
                .iter()
                .map(|j| j.force.max(j.moment))
                .fold(0.0, f64::max)
                * 1e-9;
            assert!(floor > 0.0);
            assert_eq!(d.joints.len(), s.joints.len());
            for (a, b) in d.joints.iter().zip(&s.joints) {
                for (x, y) in [(a.force, b.force), (a.moment, b.moment)] {
                    let r = relative(x, y, floor);
                    worst = worst.max(r);
                    compared += 1;
                    assert!(r <= 1e-9, "{}: {x} direct, {y} superposed", a.name);
                }
            }
            // the motor torques are summed the same way (QTR, QIT and each actuator's RMS and peak)
            for (x, y) in [(d.qtr, s.qtr), (d.qit, s.qit)] {
                assert!(relative(x, y, 0.0) <= 1e-9, "{x} direct, {y} superposed");
            }
            for (a, b) in d.actuators.iter().zip(&s.actuators) {
                assert!(relative(a.crt_rms, b.crt_rms, 0.0) <= 1e-9);
                assert!(relative(a.cpt_peak, b.cpt_peak, 0.0) <= 1e-9);
            }
        }
    }
    // 50 variants × 11 joints × (force, moment), two ways
    assert_eq!(compared, 2 * 50 * 11 * 2);
    eprintln!("largest relative difference of a reaction peak: {worst:.1e}");
}

/// A column's superposed values are the same bits whatever else is in the batch (the basis
/// grows with the batch, but a column sums only its own rows, in their order): the sharded
/// study's requirement. On the palletizer with a 3 × 3 × 3 grid and 11 samples per move.
#[test]
fn a_superposed_column_is_the_same_bits_in_any_batch() {
    let case = common::reduced_palletizer(3, 11);
    let model = Case::from_json_str(&serde_json::to_string(&case).unwrap()).unwrap();
    let cw = |body: &str, mass: f64| Counterweight {
        label: format!("m on {body}"),
        body: body.into(),
        mass,
        offset: [-0.3, 0.01, 0.0],
        plane: None,
    };
    let spring = |body: &str, other: &str, stiffness: f64| Spring {
        label: format!("K {body}–{other}"),
        body: body.into(),
        other: other.into(),
        stiffness,
        anchor_a: [0.3, 0.0, 0.0],
        anchor_b: [-0.2, 0.45, 0.0],
        plane: None,
    };
    let variants = [
        Variant {
            counterweights: vec![cw("upper_arm", 200.0)],
            springs: vec![],
        },
        Variant {
            counterweights: vec![],
            springs: vec![spring("forearm", "slider_h", 4000.0)],
        },
        Variant {
            counterweights: vec![cw("slider_v", 150.0)],
            springs: vec![spring("front_link", "slider_v", 6000.0)],
        },
        Variant {
            counterweights: vec![cw("upper_arm", 120.0), cw("front_link", 80.0)],
            springs: vec![spring("upper_arm", "slider_h", 5000.0)],
        },
    ];
    // With the reactions (the final evaluation) and without (the critical-task loop's
    // all-task torques, `LoopTorques` in the optimiser); every variant summed, or only the
    // inertia groups' changes (`InertiaSuperposition`, the final evaluation of a large study).
    for (reactions, combination) in [
        (true, Combination::Superposition),
        (false, Combination::Superposition),
        (true, Combination::InertiaSuperposition),
        (false, Combination::InertiaSuperposition),
    ] {
        let options = EvaluateOptions {
            reactions,
            ..EvaluateOptions::default()
        };
        let evaluate = |members: &[usize]| -> Vec<Indicators> {
            let batch: Vec<Variant> = members.iter().map(|&k| variants[k].clone()).collect();
            let params = ParameterSet::from_variants(&model, &batch).unwrap();
            evaluate_grid_indicators_with(&model, &params, &options, combination)
                .unwrap()
                .indicators
        };
        let all = evaluate(&[0, 1, 2, 3]);
        for subset in [vec![3], vec![2], vec![1, 3], vec![3, 0], vec![2, 1, 0]] {
            for (&k, ind) in subset.iter().zip(evaluate(&subset)) {
                assert!(
                    ind == all[k],
                    "variant {k} differs in batch {subset:?} ({combination:?}, reactions {reactions})"
                );
            }
        }
        // and the superposition is the direct solve's, to rounding
        let params = ParameterSet::from_variants(&model, &variants).unwrap();
        let direct = evaluate_grid_indicators_with(&model, &params, &options, Combination::Direct)
            .unwrap()
            .indicators;
        for (d, s) in direct.iter().zip(&all) {
            assert_eq!(d.joints.len(), if reactions { 11 } else { 0 });
            for (a, b) in d.joints.iter().zip(&s.joints) {
                assert!(relative(a.force, b.force, 1e-6) <= 1e-9);
                assert!(relative(a.moment, b.moment, 1e-6) <= 1e-9);
            }
            assert!(relative(d.qtr, s.qtr, 0.0) <= 1e-9);
            assert!(relative(d.qit, s.qit, 0.0) <= 1e-9);
            for (a, b) in d.actuators.iter().zip(&s.actuators) {
                assert!(relative(a.crt_rms, b.crt_rms, 0.0) <= 1e-9);
                // (the critical tasks themselves can differ where tasks tie to rounding, as
                // mirrored moves of this grid do)
                assert!(relative(a.cpt_peak, b.cpt_peak, 0.0) <= 1e-9);
            }
        }
    }
}
