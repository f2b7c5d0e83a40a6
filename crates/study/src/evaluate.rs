//! `counterpoise evaluate CASE`: Phase 1 — the unbalanced mechanism over its task grid.

use std::path::Path;
use std::time::Instant;

use counterpoise_dynamics::{
    DynamicsError, EvaluateOptions, EvaluationReport, evaluate, task_series,
};
use counterpoise_model::Model;

use crate::error::{Result, StudyError, invalid};
use crate::guards::located;
use crate::preflight;

/// Options of `counterpoise evaluate`.
pub struct Options {
    pub json: bool,
    pub samples: Option<usize>,
    pub no_reactions: bool,
}

/// The guards of the command: a task grid, and samples within the limit.
fn checked(path: &Path, model: &Model, samples: Option<usize>) -> Result<()> {
    let Some(tasks) = &model.tasks else {
        invalid!("{}: the case has no `tasks` section", path.display());
    };
    if let Err(e) = preflight::samples_guard(model, samples.unwrap_or(tasks.samples)) {
        return Err(StudyError::Case {
            path: path.to_path_buf(),
            errors: located(Some(path), vec![e]),
        });
    }
    Ok(())
}

/// The time series of task `i→j` (grid indices) as JSON.
pub fn series_json(
    path: &Path,
    model: &Model,
    (i, j): (usize, usize),
    samples: Option<usize>,
) -> Result<String> {
    checked(path, model, samples)?;
    let series = task_series(model, i, j, samples).map_err(|e| match e {
        // These name the task already.
        DynamicsError::ZeroLengthTask { .. } | DynamicsError::NoSuchTask { .. } => {
            StudyError::from(e)
        }
        e => StudyError::Invalid(format!("task {i}→{j}: {e}")),
    })?;
    Ok(serde_json::to_string_pretty(&series)?)
}

/// Phase 1 of the unbalanced mechanism: its indicators as a summary, or as JSON.
pub fn evaluate_text(path: &Path, model: &Model, options: &Options) -> Result<String> {
    checked(path, model, options.samples)?;
    let started = Instant::now();
    let report = evaluate(
        model,
        &EvaluateOptions {
            samples: options.samples,
            reactions: !options.no_reactions,
            ..EvaluateOptions::default()
        },
    )?;
    let seconds = started.elapsed().as_secs_f64();
    Ok(if options.json {
        format!("{}\n", serde_json::to_string_pretty(&report)?)
    } else {
        summary(&report, seconds)
    })
}

/// A task as every view writes it: `from→to`.
fn task(t: [usize; 2]) -> String {
    counterpoise_report::format::task(t)
}

fn summary(r: &EvaluationReport, seconds: f64) -> String {
    let ind = &r.indicators;
    let mut out = format!(
        "{}: {} grid points, {} tasks ({} pairs) × {} samples over {} s — evaluated {} in {:.2} s\n",
        r.case, r.points, r.tasks, r.pairs, r.samples, r.duration, r.evaluated, seconds
    );
    if r.excluded.count > 0 {
        out.push_str(&format!(
            "excluded tasks: {} {:?}\n",
            r.excluded.count, r.excluded.by_reason
        ));
    }
    out.push_str(&format!(
        "QTR = {:.3} N·m (task {})   QIT = {:.3} N·m (task {})\n\n",
        ind.qtr,
        task(ind.qtr_task),
        ind.qit,
        task(ind.qit_task)
    ));
    out.push_str(&format!(
        "{:<8} {:>12} {:>12} {:>12} {:>12}\n",
        "actuator", "RMS N·m", "CRT", "peak N·m", "CPT"
    ));
    for a in &ind.actuators {
        out.push_str(&format!(
            "{:<8} {:>12.3} {:>12} {:>12.3} {:>12}\n",
            a.name,
            a.crt_rms,
            task(a.crt),
            a.cpt_peak,
            task(a.cpt)
        ));
    }
    if !ind.joints.is_empty() {
        out.push_str(&format!(
            "\n{:<8} {:>14} {:>14}\n",
            "joint", "F_j N", "M_j N·m"
        ));
        for j in &ind.joints {
            out.push_str(&format!(
                "{:<8} {:>14.1} {:>14.1}\n",
                j.name, j.force, j.moment
            ));
        }
        if r.reactions_minimum_norm {
            out.push_str(
                "(the mechanism is overconstrained: reactions are the minimum-norm solution)\n",
            );
        }
    }
    out
}
