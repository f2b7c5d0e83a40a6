#![allow(dead_code)]
//! Shared helpers of the integration tests.

use counterpoise_model::{Case, Model};

pub fn case(name: &str) -> Model {
    let path = format!("{}/../../cases/{name}.json", env!("CARGO_MANIFEST_DIR"));
    Case::from_path(std::path::Path::new(&path)).unwrap_or_else(|e| panic!("{path}: {e}"))
}

pub fn case_from_text(text: &str) -> Model {
    Case::from_json_str(text).unwrap_or_else(|e| panic!("{e}"))
}

/// Quintic law by hand: position, velocity, acceleration of a move a → b in T at t.
pub fn quintic(a: f64, b: f64, big_t: f64, t: f64) -> (f64, f64, f64) {
    let x = t / big_t;
    let d = b - a;
    (
        a + d * (10.0 * x.powi(3) - 15.0 * x.powi(4) + 6.0 * x.powi(5)),
        d * (30.0 * x.powi(2) - 60.0 * x.powi(3) + 30.0 * x.powi(4)) / big_t,
        d * (60.0 * x - 180.0 * x.powi(2) + 120.0 * x.powi(3)) / (big_t * big_t),
    )
}

pub fn assert_close(a: f64, b: f64, tol: f64, what: &str) {
    assert!(
        (a - b).abs() <= tol,
        "{what}: {a} vs {b} (diff {:.3e}, tol {tol:.1e})",
        (a - b).abs()
    );
}

/// The palletizer on a coarse 3×3×3 grid (351 tasks) with 11 samples per task (θ1 is cyclic,
/// so the cyclic decomposition runs).
pub fn coarse_palletizer() -> Model {
    let mut model = case("palletizer");
    let tasks = model.tasks.as_mut().unwrap();
    for axis in &mut tasks.grid {
        axis.n = 3;
    }
    tasks.samples = 11;
    model
}
