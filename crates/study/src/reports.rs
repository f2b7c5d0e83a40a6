//! `counterpoise report DIR`: rewrites the reports from `DIR/results.json`. The model is
//! rebuilt from the case echo in the results, so what the reports compute from it (the
//! bounds of each element) is there for results written by earlier versions too; a case echo
//! that no longer validates leaves those parts out, with a note on stderr.

use std::path::{Path, PathBuf};

use counterpoise_model::{Case, Model};
use counterpoise_report as report;

use crate::error::{Result, invalid};
use crate::figures::{
    add_practical_figures, add_torque_charts, path_configurations, path_simulation,
    shown_mechanisms_of_results,
};
use crate::{design, preflight};

/// The reports written again, and what the user should know about them.
pub struct Rewritten {
    pub written: Vec<PathBuf>,
    /// Why parts were left out (the case echo no longer validates).
    pub notes: Vec<String>,
}

/// Rewrites the reports, with the decision recomputed (at `tolerance` when one is given, else
/// at the tolerance the results were decided at: the idle elements are marked anew, and the
/// recommendation never holds one).
pub fn rewrite_reports(dir: &Path, tolerance: Option<f64>, draw: &[String]) -> Result<Rewritten> {
    let mut results = report::read_results(dir)?;
    let mut notes = Vec::new();
    let model = model_of(&results, &mut notes);
    if let Some(model) = &model
        && results.element_bounds.is_empty()
    {
        results.element_bounds = design::element_bounds(model)?;
    }
    if let Some(model) = &model
        && lacks_spring_lengths(&results)
    {
        // Written before the shortest spring lengths were recorded: measure them again (the
        // same configurations as `run`), so the spring specifications can be given.
        let path = if model.paths.is_empty() {
            Vec::new()
        } else {
            path_configurations(model, 0)?
        };
        add_practical_figures(model, &mut results, path)?;
    }
    let tolerance = tolerance
        .or_else(|| results.decision.as_ref().map(|d| d.tolerance))
        .unwrap_or(report::decision::DEFAULT_TOLERANCE);
    results.redecide(tolerance);
    match &model {
        Some(model) => {
            if charts_are_stale(&results) {
                // The decision picked variants the stored curves do not show (another
                // --tolerance, or idle elements marked): compute them again.
                let m = shown_mechanisms_of_results(model, &results)?;
                add_torque_charts(model, &mut results, &m)?;
                if !model.paths.is_empty() {
                    results.path = Some(path_simulation(model, &m, 0)?.0);
                }
                results.finalize_path()?;
            }
            results.schematics = design::schematics(model, &results, draw)?;
            results.energy = design::energy_chart(model, &results)?;
        }
        None if !draw.is_empty() => {
            invalid!("--draw needs the model, and the case echo in results.json does not validate")
        }
        None => {}
    }
    let written = report::write_reports(dir, &results)?;
    Ok(Rewritten { written, notes })
}

/// The model of the case echo, or `None` (said in `notes`) when it does not validate.
pub fn model_of(results: &report::RunResults, notes: &mut Vec<String>) -> Option<Model> {
    let text = serde_json::to_string(&results.case).ok()?;
    match Case::from_json_str_with(&text, preflight::limits()) {
        Ok(model) => Some(model),
        Err(errors) => {
            notes.push(format!(
                "the case echo in results.json does not validate ({} error(s)); the reports \
                 leave out what needs the model",
                errors.len()
            ));
            None
        }
    }
}

/// Whether some ranked variant's spring has no recorded shortest length.
fn lacks_spring_lengths(results: &report::RunResults) -> bool {
    results.ranked().iter().any(|v| {
        v.practical
            .as_ref()
            .is_some_and(|p| p.springs.iter().any(|s| s.shortest.is_none()))
    })
}

/// Whether the stored torque curves miss a variant the report now shows.
fn charts_are_stale(results: &report::RunResults) -> bool {
    let shown: Vec<usize> = results.shown_variants().iter().map(|v| v.id).collect();
    let drawn: Vec<usize> = results
        .torque_charts
        .first()
        .map(|c| c.curves.iter().filter_map(|k| k.variant).collect())
        .unwrap_or_default();
    shown.iter().any(|id| !drawn.contains(id)) || drawn.iter().any(|id| !shown.contains(id))
}
