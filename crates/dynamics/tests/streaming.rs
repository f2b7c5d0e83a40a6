//! The streaming grid evaluation (running maxima per column, no per-task table) gives exactly
//! the indicators of the full table's reduction, for any thread count; a batch's reactions by
//! substitution agree with the reaction operator's and do not depend on the batch.

mod common;

use common::coarse_palletizer;
use counterpoise_dynamics::{
    Combination, Counterweight, EvaluateOptions, ParameterSet, Spring, Variant, evaluate_grid,
    evaluate_grid_indicators, evaluate_grid_indicators_with,
};

fn variants(model: &counterpoise_model::Model) -> Vec<Variant> {
    vec![
        Variant::default(),
        Variant {
            counterweights: vec![Counterweight {
                label: "cw".into(),
                body: model.bodies[4].name.clone(),
                mass: 60.0,
                offset: [-0.3, 0.05, 0.0],
                plane: None,
            }],
            springs: vec![Spring {
                label: "spring".into(),
                body: model.bodies[5].name.clone(),
                other: model.bodies[1].name.clone(),
                stiffness: 3000.0,
                anchor_a: [0.2, 0.1, 0.0],
                anchor_b: [0.1, -0.3, 0.0],
                plane: None,
            }],
        },
        Variant {
            counterweights: vec![],
            springs: vec![Spring {
                label: "spring".into(),
                body: model.bodies[6].name.clone(),
                other: model.bodies[2].name.clone(),
                stiffness: 1500.0,
                anchor_a: [0.3, 0.0, 0.1],
                anchor_b: [-0.2, 0.1, 0.0],
                plane: None,
            }],
        },
        // Same inertia as the first column: every value of a column with the same inertia
        // differs from the first by static terms only, so ties between tasks are likely.
        Variant::default(),
    ]
}

#[test]
fn streaming_indicators_equal_the_table_reduction() {
    let model = coarse_palletizer();
    let params = ParameterSet::from_variants(&model, &variants(&model)).unwrap();
    for reactions in [false, true] {
        let options = EvaluateOptions {
            reactions,
            ..EvaluateOptions::default()
        };
        let table = evaluate_grid(&model, &params, &options).unwrap();
        assert!(table.cyclic_coordinate.is_some(), "the shortcut runs");
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let streamed = pool
                .install(|| evaluate_grid_indicators(&model, &params, &options))
                .unwrap();
            assert_eq!(
                streamed.indicators, table.indicators,
                "reactions {reactions}"
            );
            assert_eq!(streamed.excluded, table.excluded);
            assert_eq!(streamed.distinct_moves, table.distinct_moves);
            assert_eq!(
                streamed.reactions_minimum_norm,
                table.reactions_minimum_norm
            );
        }
        // Two identical columns have identical indicators, critical tasks included.
        assert_eq!(table.indicators[0], table.indicators[3]);
    }
}

/// A study's final evaluation may solve a batch's reactions by substitution instead of
/// through the reaction operator (`FinalReactionSolve` in the optimiser). On a batch with
/// three inertia groups, counterweights and springs: every column's joint reaction peaks
/// agree with the operator's to 1e-12 relative (the second method), its motor torque
/// indicators are the same bits (they do not pass through the reaction solve), and each
/// column evaluated alone by substitution has the same bits as in the batch — a shard's
/// figures equal the single run's under either choice.
#[test]
fn a_batch_by_substitution_matches_the_operator_and_each_column_alone() {
    let model = coarse_palletizer();
    let variants = variants(&model);
    let params = ParameterSet::from_variants(&model, &variants).unwrap();
    let options = EvaluateOptions::default();
    let evaluate = |params: &ParameterSet, combination| {
        evaluate_grid_indicators_with(&model, params, &options, combination)
            .unwrap()
            .indicators
    };
    let by_operator = evaluate(&params, Combination::Direct);
    let by_substitution = evaluate(&params, Combination::Substitution);
    let mut loaded = 0;
    for (c, (a, b)) in by_operator.iter().zip(&by_substitution).enumerate() {
        assert_eq!(a.joints.len(), 11);
        for (j, (ja, jb)) in a.joints.iter().zip(&b.joints).enumerate() {
            for (x, y) in [(ja.force, jb.force), (ja.moment, jb.moment)] {
                // (a joint that carries nothing has exact zeros both ways)
                assert!((x - y).abs() <= 1e-12 * x, "{c} {j}: {x} {y}");
                loaded += usize::from(x > 0.0);
            }
        }
        assert_eq!(
            (&a.actuators, a.qtr, a.qtr_task, a.qit, a.qit_task),
            (&b.actuators, b.qtr, b.qtr_task, b.qit, b.qit_task),
            "{c}"
        );
    }
    assert!(loaded >= 4 * 18, "{loaded} loaded joint peaks");
    // the balancing elements change the reactions: three columns, three sets of peaks
    let peaks = |c: usize| -> Vec<f64> {
        let joints = &by_substitution[c].joints;
        joints.iter().flat_map(|j| [j.force, j.moment]).collect()
    };
    assert!(peaks(1) != peaks(0) && peaks(2) != peaks(0) && peaks(1) != peaks(2));
    assert_eq!(peaks(3), peaks(0));
    for (c, variant) in variants.iter().enumerate() {
        let alone = ParameterSet::from_variants(&model, std::slice::from_ref(variant)).unwrap();
        assert_eq!(
            evaluate(&alone, Combination::Substitution)[0],
            by_substitution[c],
            "{c}"
        );
    }
}

/// The sums by superposition against the direct solve, on the batch above (two inertia
/// groups, counterweights and springs): the final evaluation of a large study sums its
/// inertia groups' changes with the rotation speed (`Combination::InertiaSuperposition`), and
/// its critical-task loop sums every column's torques (`Combination::Superposition` without
/// reactions). Every joint reaction peak and every motor torque figure agrees with the direct
/// solve's to 1e-12 relative (the second method), and each column evaluated alone has the same
/// bits as in the batch.
#[test]
fn the_sums_by_superposition_match_the_direct_solve_and_each_column_alone() {
    let model = coarse_palletizer();
    let variants = variants(&model);
    let params = ParameterSet::from_variants(&model, &variants).unwrap();
    // relative to the larger of the two, or to `floor` (a joint that carries nothing is an
    // exact zero one way and a rounding residue the other)
    let near =
        |x: f64, y: f64, floor: f64| (x - y).abs() <= 1e-12 * x.abs().max(y.abs()).max(floor);
    let close = |x: f64, y: f64| near(x, y, 0.0);
    for (reactions, combination) in [
        (true, Combination::InertiaSuperposition),
        (false, Combination::Superposition),
        (true, Combination::Superposition),
    ] {
        let options = EvaluateOptions {
            reactions,
            ..EvaluateOptions::default()
        };
        let evaluate = |params: &ParameterSet, combination| {
            evaluate_grid_indicators_with(&model, params, &options, combination)
                .unwrap()
                .indicators
        };
        let direct = evaluate(&params, Combination::Direct);
        let summed = evaluate(&params, combination);
        for (c, (a, b)) in direct.iter().zip(&summed).enumerate() {
            assert_eq!(a.joints.len(), if reactions { 11 } else { 0 });
            let floor = a
                .joints
                .iter()
                .map(|j| j.force.max(j.moment))
                .fold(0.0, f64::max);
            for (ja, jb) in a.joints.iter().zip(&b.joints) {
                for (x, y) in [(ja.force, jb.force), (ja.moment, jb.moment)] {
                    assert!(near(x, y, floor), "{combination:?} {c}: {x} {y}");
                }
            }
            assert!(
                close(a.qtr, b.qtr) && close(a.qit, b.qit),
                "{combination:?} {c}"
            );
            for (x, y) in a.actuators.iter().zip(&b.actuators) {
                for (u, v) in [(x.crt_rms, y.crt_rms), (x.cpt_peak, y.cpt_peak)] {
                    assert!(close(u, v), "{combination:?} {c}: {u} {v}");
                }
            }
        }
        // the elements change the figures: the comparison is not of three copies
        assert!(summed[1].qtr != summed[0].qtr && summed[2].qtr != summed[0].qtr);
        for (c, variant) in variants.iter().enumerate() {
            let alone = ParameterSet::from_variants(&model, std::slice::from_ref(variant)).unwrap();
            assert_eq!(
                evaluate(&alone, combination)[0],
                summed[c],
                "{combination:?} {c}"
            );
        }
    }
}
