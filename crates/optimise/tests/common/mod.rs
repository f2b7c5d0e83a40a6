//! Shared helpers of the integration tests.
#![allow(dead_code)]

use counterpoise_balance::{
    Catalogue, SearchOptions, SearchReport, Status, catalogue_options, mechanism_energy,
    realization_hints, search,
};
use counterpoise_model::{Case, Model};
use counterpoise_optimise::{Context, OptimiseOptions, OptimisedVariant, optimise_all};

pub fn case_path(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../cases")
        .join(name)
}

/// The case file as JSON, for editing.
pub fn case_json(name: &str) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(case_path(name)).unwrap()).unwrap()
}

pub fn model(json: &serde_json::Value) -> Model {
    Case::from_json_str(&json.to_string()).unwrap()
}

pub fn balance_search(model: &Model) -> SearchReport {
    let energy = mechanism_energy(model);
    let catalogue = Catalogue::build(&energy, &catalogue_options(model));
    search(
        &energy,
        catalogue,
        SearchOptions {
            dmax: model.balancing.as_ref().unwrap().dmax,
            hints: realization_hints(model),
        },
    )
}

/// The balanced variants of the case's balance search.
pub fn balanced_variants(model: &Model) -> Vec<counterpoise_balance::VariantResult> {
    balance_search(model)
        .variants
        .into_iter()
        .filter(|v| v.status == Status::Balanced)
        .collect()
}

/// Runs the search and optimises the balanced variants whose label sets are in `wanted`
/// (all balanced ones when empty).
pub fn optimise(
    model: &Model,
    wanted: &[&[&str]],
    options: &OptimiseOptions,
) -> (Context, Vec<OptimisedVariant>) {
    let chosen: Vec<_> = balanced_variants(model)
        .into_iter()
        .filter(|v| {
            wanted.is_empty()
                || wanted.iter().any(|w| {
                    w.len() == v.elements.len()
                        && w.iter().all(|l| v.elements.iter().any(|e| &e.label == l))
                })
        })
        .collect();
    let ctx = Context::new(model, None).unwrap();
    let results = optimise_all(&ctx, &chosen, options);
    (ctx, results)
}
