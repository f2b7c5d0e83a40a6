//! The streaming grid evaluation (running maxima per column, no per-task table) gives exactly
//! the indicators of the full table's reduction, for any thread count.

mod common;

use common::coarse_palletizer;
use counterpoise_dynamics::{
    Counterweight, EvaluateOptions, ParameterSet, Spring, Variant, evaluate_grid,
    evaluate_grid_indicators,
};

fn variants() -> Vec<Variant> {
    vec![
        Variant::default(),
        Variant {
            counterweights: vec![Counterweight {
                body: 4,
                mass: 60.0,
                position: [-0.3, 0.05, 0.0],
            }],
            springs: vec![Spring {
                body: 5,
                other: Some(1),
                stiffness: 3000.0,
                anchor: [0.2, 0.1, 0.0],
                other_anchor: [0.1, -0.3, 0.0],
            }],
        },
        Variant {
            counterweights: vec![],
            springs: vec![Spring {
                body: 6,
                other: Some(2),
                stiffness: 1500.0,
                anchor: [0.3, 0.0, 0.1],
                other_anchor: [-0.2, 0.1, 0.0],
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
    let params = ParameterSet::from_variants(&model, &variants()).unwrap();
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
