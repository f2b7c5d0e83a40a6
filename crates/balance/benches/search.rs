//! Criterion benches of the balance decision on the palletizer: the exact linear stage alone
//! (every variant's exact elimination) and the whole search (exact decision, proofs,
//! realization and verification), at Dmax = 2 and 3.

use std::path::PathBuf;

use counterpoise_balance::exact::ExactBasis;
use counterpoise_balance::{
    Catalogue, SearchOptions, catalogue_options, mechanism_energy, realization_hints, search,
};
use criterion::{Criterion, criterion_group, criterion_main};
use rayon::prelude::*;

fn palletizer() -> counterpoise_model::Model {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../cases/palletizer.json");
    counterpoise_model::Case::from_path(&path).expect("valid case")
}

fn benches(c: &mut Criterion) {
    let model = palletizer();
    let energy = mechanism_energy(&model);
    let catalogue = Catalogue::build(&energy, &catalogue_options(&model));
    let mut group = c.benchmark_group("palletizer");
    group.sample_size(10);
    for dmax in [2usize, 3] {
        group.bench_function(format!("exact_stage_dmax{dmax}"), |b| {
            b.iter(|| {
                let mechanism = energy.exact.as_ref().expect("the palletizer is exact");
                let basis = ExactBasis::build(mechanism, &catalogue);
                let sets: Vec<Vec<usize>> =
                    counterpoise_balance::enumerate::variants(catalogue.len(), dmax).collect();
                sets.par_iter()
                    .filter(|s| basis.solve(s).consistent())
                    .count()
            })
        });
        group.bench_function(format!("whole_search_dmax{dmax}"), |b| {
            b.iter(|| {
                search(
                    &energy,
                    catalogue.clone(),
                    SearchOptions {
                        dmax,
                        hints: realization_hints(&model),
                    },
                )
                .variants
                .len()
            })
        });
    }
    group.finish();
}

criterion_group!(search_benches, benches);
criterion_main!(search_benches);
