//! `counterpoise evaluate CASE`: Phase 1 — the unbalanced mechanism over its task grid.

use std::path::Path;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{Result, bail};
use counterpoise_dynamics::{
    DynamicsError, EvaluateOptions, EvaluationReport, evaluate, task_series,
};

/// Options of the command.
pub struct Options<'a> {
    pub json: bool,
    pub samples: Option<usize>,
    pub no_reactions: bool,
    /// `(i, j)` grid indices and the file to write the series to.
    pub series: Option<((usize, usize), &'a Path)>,
}

pub fn run(path: &Path, options: Options) -> Result<ExitCode> {
    let Some(model) = super::load(path)? else {
        return Ok(ExitCode::FAILURE);
    };
    let Some(tasks) = &model.tasks else {
        bail!("{}: the case has no `tasks` section", path.display());
    };
    if let Err(e) =
        counterpoise::preflight::samples_guard(&model, options.samples.unwrap_or(tasks.samples))
    {
        super::print_errors(path, &super::located(path, vec![e]));
        return Ok(ExitCode::FAILURE);
    }
    if let Some(((i, j), file)) = options.series {
        let series = task_series(&model, i, j, options.samples).map_err(|e| match e {
            // These name the task already.
            DynamicsError::ZeroLengthTask { .. } | DynamicsError::NoSuchTask { .. } => {
                anyhow::Error::new(e)
            }
            e => anyhow::Error::new(e).context(format!("task {i}→{j}")),
        })?;
        let text = serde_json::to_string_pretty(&series)?;
        super::write_atomic(file, text.as_bytes())?;
        eprintln!("wrote the series of task {i}→{j} to {}", file.display());
        return Ok(ExitCode::SUCCESS);
    }
    let started = Instant::now();
    let report = evaluate(
        &model,
        &EvaluateOptions {
            samples: options.samples,
            reactions: !options.no_reactions,
            ..EvaluateOptions::default()
        },
    )?;
    let seconds = started.elapsed().as_secs_f64();
    if options.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print!("{}", summary(&report, seconds));
    }
    Ok(ExitCode::SUCCESS)
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
