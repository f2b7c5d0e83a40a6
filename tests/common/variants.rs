//! The palletizer study's fixtures shared by the superposition test and the pipeline bench: the
//! balanced variants of the exact search, and the dynamics crate's variant of an optimised
//! record. `benches/pipeline.rs` includes this file by `#[path]`: a bench cannot use
//! `tests/common/mod.rs`, whose helpers need the binary's path that only integration tests are
//! given.

use counterpoise_balance::{
    Catalogue, SearchOptions, Status, VariantResult, catalogue_options, mechanism_energy,
    realization_hints, search,
};
use counterpoise_dynamics::{Counterweight, Spring, Variant};
use counterpoise_model::Model;
use counterpoise_optimise::OptimisedVariant;

/// The variant of `o` for the dynamics crate: bodies by index (`base` for none).
pub fn dynamics_variant(model: &Model, o: &OptimisedVariant) -> Variant {
    let body = |name: &str| model.body_index(name).expect("a body of the model");
    Variant {
        counterweights: o
            .counterweights
            .iter()
            .map(|c| Counterweight {
                body: body(&c.body),
                mass: c.mass,
                position: c.offset,
            })
            .collect(),
        springs: o
            .springs
            .iter()
            .map(|s| Spring {
                body: body(&s.body),
                other: (s.other != "base").then(|| body(&s.other)),
                stiffness: s.stiffness,
                anchor: s.anchor_a,
                other_anchor: s.anchor_b,
            })
            .collect(),
    }
}

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
