//! The streaming grid evaluation (running maxima per column, no per-task table) gives exactly
//! the indicators of the full table's reduction, for any thread count.

mod common;

use common::coarse_palletizer;
use counterpoise_dynamics::{
    Counterweight, EvaluateOptions, ParameterSet, Spring, Variant, evaluate_grid,
    evaluate_grid_indicators,
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
