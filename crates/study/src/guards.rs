//! What every command checks or says about a case before its costly stages: refused fields
//! located in the case file's text, and the note on the bounds derived from the mechanism.

use std::path::Path;

use counterpoise_model::{CaseErrors, Model, ModelError};

/// Errors found after loading (by [`crate::preflight`]), sorted and located in the file's text
/// (without a file, by their JSON paths alone).
pub fn located(path: Option<&Path>, errors: Vec<ModelError>) -> CaseErrors {
    let text = path
        .and_then(|p| std::fs::read_to_string(p).ok())
        .unwrap_or_default();
    CaseErrors::sorted_and_located(errors, &text)
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
