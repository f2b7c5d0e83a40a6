//! The palletizer's full task grid (58,653 tasks × 51 samples ≈ 3.0 M samples):
//! unbalanced motor torques only, and torques + joint reactions for the unbalanced robot plus
//! 12 balanced parameter vectors in one pass. `cargo bench -p counterpoise-dynamics`.

use std::time::Duration;

use counterpoise_dynamics::{
    Counterweight, EvaluateOptions, ParameterSet, Spring, Variant, evaluate_grid,
};
use counterpoise_model::{Case, Model};
use criterion::{Criterion, criterion_group, criterion_main};

fn palletizer() -> Model {
    let path = format!("{}/../../cases/palletizer.json", env!("CARGO_MANIFEST_DIR"));
    Case::from_path(std::path::Path::new(&path)).expect("palletizer case")
}

/// The unbalanced robot plus 12 variants (counterweights on members 1–7 and springs between
/// members), all evaluated together.
fn thirteen_columns(model: &Model) -> ParameterSet {
    let mut variants = vec![Variant::default()];
    for c in 0..7 {
        variants.push(Variant {
            counterweights: vec![Counterweight {
                label: "cw".into(),
                body: model.bodies[c].name.clone(),
                mass: 20.0 + 10.0 * c as f64,
                offset: [-0.3, 0.05, 0.0],
                plane: None,
            }],
            springs: vec![],
        });
    }
    for (i, s) in [(3, 2), (4, 2), (3, 1), (4, 1), (5, 3)] {
        variants.push(Variant {
            counterweights: vec![],
            springs: vec![Spring {
                label: "spring".into(),
                body: model.bodies[i].name.clone(),
                other: model.bodies[s].name.clone(),
                stiffness: 4000.0,
                anchor_a: [0.4, 0.0, 0.0],
                anchor_b: [0.0, 0.3, 0.0],
                plane: None,
            }],
        });
    }
    ParameterSet::from_variants(model, &variants).expect("variants")
}

fn grid(c: &mut Criterion) {
    let model = palletizer();
    let ub = ParameterSet::unbalanced(&model);
    let many = thirteen_columns(&model);
    let mut group = c.benchmark_group("palletizer_full_grid");
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(20));
    group.bench_function("torques_unbalanced", |b| {
        let options = EvaluateOptions {
            reactions: false,
            ..EvaluateOptions::default()
        };
        b.iter(|| evaluate_grid(&model, &ub, &options).expect("grid"))
    });
    group.measurement_time(Duration::from_secs(60));
    group.bench_function("torques_reactions_13_columns", |b| {
        let options = EvaluateOptions::default();
        b.iter(|| evaluate_grid(&model, &many, &options).expect("grid"))
    });
    group.finish();
}

criterion_group!(benches, grid);
criterion_main!(benches);
