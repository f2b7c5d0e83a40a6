//! The commands that load a case and print a text or JSON document: `check`, `variants`,
//! `partial`, `evaluate` (and its `--task`/`--series` and `--states` forms), `report`.

use std::path::Path;
use std::process::ExitCode;

use counterpoise_study::{check, evaluate, partial, reports, states, variants};

pub fn check(path: &Path) -> ExitCode {
    let Some(model) = super::load(path) else {
        return ExitCode::FAILURE;
    };
    super::print_or_fail(check::check(path, &model))
}

pub fn variants(path: &Path, dmax: Option<usize>, json: bool, minimal: bool) -> ExitCode {
    let Some(model) = super::load(path) else {
        return ExitCode::FAILURE;
    };
    super::print_or_fail(variants::variants_text(path, &model, dmax, json, minimal))
}

pub fn partial(path: &Path, options: partial::Options) -> ExitCode {
    let Some(model) = super::load(path) else {
        return ExitCode::FAILURE;
    };
    super::print_or_fail(partial::partial_text(path, &model, &options))
}

pub fn evaluate(
    path: &Path,
    options: evaluate::Options,
    series: Option<((usize, usize), &Path)>,
) -> ExitCode {
    let Some(model) = super::load(path) else {
        return ExitCode::FAILURE;
    };
    let Some(((i, j), file)) = series else {
        return super::print_or_fail(evaluate::evaluate_text(path, &model, &options));
    };
    let written = evaluate::series_json(path, &model, (i, j), options.samples)
        .and_then(|text| counterpoise_study::write_file(file, text.as_bytes()));
    match written {
        Ok(()) => {
            eprintln!("wrote the series of task {i}→{j} to {}", file.display());
            ExitCode::SUCCESS
        }
        Err(e) => super::failed(e),
    }
}

pub fn states(case: &Path, states: &Path) -> ExitCode {
    let Some(model) = super::load(case) else {
        return ExitCode::FAILURE;
    };
    super::print_or_fail(states::states_json(&model, states))
}

pub fn report(dir: &Path, tolerance: Option<f64>, draw: &[String]) -> ExitCode {
    match reports::rewrite_reports(dir, tolerance, draw) {
        Ok(done) => {
            for note in &done.notes {
                eprintln!("note: {note}");
            }
            for f in &done.written {
                println!("wrote {}", f.display());
            }
            ExitCode::SUCCESS
        }
        Err(e) => super::failed(e),
    }
}
