//! Helpers shared by the balance crate's tests on the palletizer.

#![allow(dead_code)] // each test binary uses its own subset

use std::path::PathBuf;

use counterpoise_balance::{
    Catalogue, SearchOptions, SearchReport, VariantResult, catalogue_options, mechanism_energy,
    realization_hints, search,
};
use counterpoise_model::sampling::SplitMix64;
use counterpoise_model::{Case, Model};
use nalgebra::DVector;

/// `cases/palletizer.json` as JSON, for tests that edit it.
pub fn palletizer_json() -> serde_json::Value {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../cases/palletizer.json");
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

pub fn model_of(json: &serde_json::Value) -> Model {
    Case::from_json_str(&json.to_string()).expect("valid case")
}

pub fn palletizer() -> Model {
    model_of(&palletizer_json())
}

/// The whole balance search at `dmax`.
pub fn run(model: &Model, dmax: usize) -> SearchReport {
    let energy = mechanism_energy(model);
    let catalogue = Catalogue::build(&energy, &catalogue_options(model));
    search(
        &energy,
        catalogue,
        SearchOptions {
            dmax,
            hints: realization_hints(model),
        },
    )
}

/// A variant's labels, sorted.
pub fn labels(v: &VariantResult) -> Vec<String> {
    let mut l: Vec<String> = v.elements.iter().map(|e| e.label.clone()).collect();
    l.sort();
    l
}

/// The variant with exactly these elements, in any order.
pub fn find<'a>(report: &'a SearchReport, wanted: &[&str]) -> &'a VariantResult {
    let mut wanted: Vec<String> = wanted.iter().map(|s| s.to_string()).collect();
    wanted.sort();
    report
        .variants
        .iter()
        .find(|v| labels(v) == wanted)
        .unwrap_or_else(|| panic!("{wanted:?} not enumerated"))
}

/// A random configuration inside the coordinate ranges.
pub fn random_configuration(model: &Model, rng: &mut SplitMix64) -> DVector<f64> {
    DVector::from_iterator(
        model.dof(),
        model
            .coordinates
            .iter()
            .map(|c| rng.uniform(c.range[0], c.range[1])),
    )
}
