//! One module per subcommand.

pub mod check;
pub mod design;
pub mod evaluate;
pub mod import_urdf;
pub mod merge;
pub mod partial;
pub mod progress;
pub mod report;
pub mod run;
pub mod shard_file;
pub mod states;
pub mod variants;

use std::path::Path;

use anyhow::Result;
use counterpoise::preflight;
use counterpoise_model::{Case, CaseErrors, Model, ModelError};

/// Loads a case within the limits in force, or prints every validation error (one per line,
/// each naming its JSON path, line and column) and returns `None`.
pub fn load(path: &Path) -> Result<Option<Model>> {
    match Case::from_path_with(path, preflight::limits()) {
        Ok(model) => Ok(Some(model)),
        Err(errors) => {
            print_errors(path, &errors);
            Ok(None)
        }
    }
}

/// Prints errors found in a case file to stderr.
pub fn print_errors(path: &Path, errors: &CaseErrors) {
    eprintln!("{}: {} error(s)", path.display(), errors.len());
    for line in errors.lines() {
        eprintln!("  {line}");
    }
}

/// Errors found after loading (by [`preflight`]), sorted and located in the file's text.
pub fn located(path: &Path, errors: Vec<ModelError>) -> CaseErrors {
    let text = std::fs::read_to_string(path).unwrap_or_default();
    CaseErrors::sorted_and_located(errors, &text)
}

/// Writes a file atomically: a temporary file in the same directory, flushed, then renamed over
/// the target, so a reader never sees a half-written file.
pub fn write_atomic(path: &Path, contents: &[u8]) -> Result<()> {
    use std::io::Write;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => std::path::PathBuf::from("."),
    };
    let name = path
        .file_name()
        .ok_or_else(|| anyhow::anyhow!("{}: not a file path", path.display()))?;
    let tmp = dir.join(format!(".{}.tmp", name.to_string_lossy()));
    let mut file = std::fs::File::create(&tmp)
        .map_err(|e| anyhow::anyhow!("cannot create {}: {e}", tmp.display()))?;
    file.write_all(contents)?;
    file.sync_all()?;
    std::fs::rename(&tmp, path)
        .map_err(|e| anyhow::anyhow!("cannot write {}: {e}", path.display()))?;
    Ok(())
}

/// The guards of `run`, before its first stage: the variant count and the paths (a path found
/// unfollowable only at the end would waste the whole run). Prints the problems; returns
/// whether the run may start.
pub fn before_run(path: &std::path::Path, model: &Model, dmax_given: bool, dmax: usize) -> bool {
    let source = if dmax_given {
        "--dmax"
    } else {
        "balancing.dmax"
    };
    let mut problems: Vec<ModelError> = preflight::variant_guard(model, dmax, source)
        .err()
        .into_iter()
        .collect();
    problems.extend(preflight::path_problems(model));
    if problems.is_empty() {
        return true;
    }
    print_errors(path, &located(path, problems));
    false
}

/// `bounds derived from the mechanism (…)`, naming each bound the case left out, its value and
/// what it comes from; `None` when the case sets them all.
pub fn derived_bounds_note(model: &Model) -> Option<String> {
    let b = model.balancing.as_ref()?;
    if b.derived_bounds.is_empty() {
        return None;
    }
    let scale = counterpoise_model::MechanismScale::of(&model.bodies, model.gravity);
    let g = counterpoise_report::format::compact;
    let parts: Vec<String> = b
        .derived_bounds
        .iter()
        .map(|name| {
            let (range, unit, from) = match *name {
                "mass" => (b.bounds.mass, "kg", "the moving mass"),
                "radius" => (b.bounds.radius, "m", "the reach"),
                "stiffness" => (b.bounds.stiffness, "N/m", "100·M·|g|/reach"),
                "anchor_a" => (b.bounds.anchor_a, "m", "the reach"),
                _ => (b.bounds.anchor_b, "m", "the reach"),
            };
            format!("{name} [{}, {}] {unit} ({from})", g(range[0]), g(range[1]))
        })
        .collect();
    Some(format!(
        "bounds not in the case, derived from the mechanism (moving mass M = {} kg, reach {} m; \
         docs/case-format.md): {}",
        g(scale.moving_mass),
        g(scale.reach),
        parts.join(", ")
    ))
}
