//! `counterpoise._counterpoise`: the native half of the `counterpoise` Python module.
//!
//! Every function takes and returns JSON text, and the Python half (`counterpoise/__init__.py`)
//! turns it into typed objects and NumPy arrays: the case, the `variants --json` document and
//! results.json are the documented exchange formats already, so the module speaks them rather
//! than a second, hand-converted object model. Errors raise `CounterpoiseError` with the
//! command line's message (a refused case names each field, line and column).
//!
//! The work runs without the GIL, on a thread with the stack the expression limits need (as
//! the command line's worker thread).

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use counterpoise_model::{Case, Limits, Model};
use counterpoise_report::RankingOptions;
use counterpoise_study::error::with_causes;
use counterpoise_study::{SearchSettings, Silent, Study, StudyError, StudyOptions, preflight};
use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

create_exception!(
    _counterpoise,
    CounterpoiseError,
    PyValueError,
    "A case, an option or a study that counterpoise refuses; the message names the field and the reason."
);

/// Runs `work` without the GIL on a worker thread sized like the command line's.
fn detached<T: Send>(
    py: Python<'_>,
    work: impl FnOnce() -> Result<T, StudyError> + Send,
) -> PyResult<T> {
    let stack = Limits::default().stack_bytes();
    let outcome = py.detach(|| {
        std::thread::scope(|scope| {
            std::thread::Builder::new()
                .name("counterpoise".into())
                .stack_size(stack)
                .spawn_scoped(scope, work)
                .map(|handle| handle.join())
        })
    });
    match outcome {
        Ok(Ok(Ok(value))) => Ok(value),
        Ok(Ok(Err(e))) => Err(CounterpoiseError::new_err(with_causes(&e))),
        Ok(Err(_)) => Err(CounterpoiseError::new_err(
            "internal error: the study panicked",
        )),
        Err(e) => Err(CounterpoiseError::new_err(format!(
            "cannot start the worker thread: {e}"
        ))),
    }
}

/// The validated model of a case given as JSON text (`path`: the file it came from, or a name
/// for messages).
fn model_of(text: &str, path: &Path) -> Result<Model, StudyError> {
    Case::from_json_str_with(text, preflight::limits()).map_err(|errors| StudyError::Case {
        path: path.to_path_buf(),
        errors,
    })
}

/// Validates a case (JSON text) and returns its summary as JSON: name, bodies, coordinates,
/// joints, actuators and the balancing section's Dmax.
#[pyfunction]
fn validate(py: Python<'_>, text: String, path: String) -> PyResult<String> {
    detached(py, move || {
        let model = model_of(&text, Path::new(&path))?;
        let names = |it: &mut dyn Iterator<Item = String>| it.collect::<Vec<_>>();
        Ok(serde_json::json!({
            "name": model.name,
            "bodies": names(&mut model.bodies.iter().map(|b| b.name.clone())),
            "coordinates": names(&mut model.coordinates.iter().map(|c| c.name.clone())),
            "joints": names(&mut model.joints.iter().map(|j| j.name.clone())),
            "actuators": names(&mut model.actuators.iter().map(|a| a.name.clone())),
            "dmax": model.balancing.as_ref().map(|b| b.dmax),
            "tasks": model.tasks.is_some(),
        })
        .to_string())
    })
}

/// `counterpoise variants --json`: every set of at most `dmax` elements with its verdict.
#[pyfunction]
#[pyo3(signature = (text, path, dmax=None))]
fn variants(py: Python<'_>, text: String, path: String, dmax: Option<usize>) -> PyResult<String> {
    detached(py, move || {
        let path = PathBuf::from(path);
        let model = model_of(&text, &path)?;
        counterpoise_study::variants::variants_text(&path, &model, dmax, true, false)
    })
}

/// `counterpoise run`: the whole study; returns results.json's text.
#[pyfunction]
#[pyo3(signature = (text, path, dmax=None, minimax=false, resolution=None, tolerance=None, gap=None, max_nodes=None, seed=None))]
#[allow(clippy::too_many_arguments)]
fn run_study(
    py: Python<'_>,
    text: String,
    path: String,
    dmax: Option<usize>,
    minimax: bool,
    resolution: Option<f64>,
    tolerance: Option<f64>,
    gap: Option<f64>,
    max_nodes: Option<usize>,
    seed: Option<u64>,
) -> PyResult<String> {
    detached(py, move || {
        let path = PathBuf::from(path);
        let model = model_of(&text, &path)?;
        let ranking = RankingOptions::default();
        let search = SearchSettings::default();
        let options = StudyOptions {
            dmax,
            minimax,
            ranking: RankingOptions {
                resolution: resolution.unwrap_or(ranking.resolution),
                tolerance: tolerance.unwrap_or(ranking.tolerance),
            },
            search: SearchSettings {
                gap: gap.unwrap_or(search.gap),
                max_nodes: max_nodes.unwrap_or(search.max_nodes),
                seed,
            },
            case_path: Some(path),
            ..StudyOptions::default()
        };
        let study = Study::new(&model, options)?;
        let outcome = study.run(&mut Silent, &AtomicBool::new(false))?;
        Ok(serde_json::to_string(&outcome.results)?)
    })
}

/// `counterpoise import-urdf`: a case file's JSON text from a URDF description's text.
#[pyfunction]
#[pyo3(signature = (urdf, name, base=None, tip=None))]
fn import_urdf(
    py: Python<'_>,
    urdf: String,
    name: String,
    base: Option<String>,
    tip: Option<String>,
) -> PyResult<String> {
    let options = counterpoise_urdf::ImportOptions { base, tip };
    py.detach(move || counterpoise_urdf::import(&urdf, &options))
        .map(|imported| imported.json)
        .map_err(|e| CounterpoiseError::new_err(format!("{name}: {}", with_causes(&e))))
}

#[pymodule]
fn _counterpoise(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("CounterpoiseError", m.py().get_type::<CounterpoiseError>())?;
    m.add_function(wrap_pyfunction!(validate, m)?)?;
    m.add_function(wrap_pyfunction!(variants, m)?)?;
    m.add_function(wrap_pyfunction!(run_study, m)?)?;
    m.add_function(wrap_pyfunction!(import_urdf, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
