//! The palletizer study's fixtures shared by the superposition test and the pipeline bench: the
//! balanced variants of the exact search. `benches/pipeline.rs` includes this file by `#[path]`: a bench cannot use
//! `tests/common/mod.rs`, whose helpers need the binary's path that only integration tests are
//! given.

use counterpoise_balance::{
    Catalogue, SearchOptions, Status, VariantResult, catalogue_options, mechanism_energy,
    realization_hints, search,
};
use counterpoise_model::Model;

/// The variants the exact balance search finds balanced at `dmax`, as `variants --dmax N`
/// lists them.
pub fn balanced(model: &Model, dmax: usize) -> Vec<VariantResult> {
    let energy = mechanism_energy(model);
    search(
        &energy,
        Catalogue::build(&energy, &catalogue_options(model)),
        SearchOptions {
            dmax,
            hints: realization_hints(model),
        },
    )
    .variants
    .into_iter()
    .filter(|v| v.status == Status::Balanced)
    .collect()
}
