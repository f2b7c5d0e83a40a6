//! `counterpoise check CASE`: validate a case and summarise the mechanism.

use std::path::Path;

use counterpoise_model::{Model, PayloadMode};
use counterpoise_symbolic::VarKind;

use crate::error::{Result, StudyError};
use crate::guards::{derived_bounds_note, located};
use crate::preflight::{self, GridReach};

/// `counterpoise check`'s report on a loaded case: the mechanism's summary, the reach of the
/// task grid and the sections the case lacks; or every problem `variants`, `evaluate` and
/// `run` would otherwise find only later.
pub fn check(path: &Path, model: &Model) -> Result<String> {
    let (problems, reach) = preflight::problems(model);
    let overrides = override_errors(model);
    if !problems.is_empty() || !overrides.is_empty() {
        let mut text = Vec::new();
        if !problems.is_empty() {
            text.push(
                StudyError::Case {
                    path: path.to_path_buf(),
                    errors: located(Some(path), problems),
                }
                .to_string(),
            );
        }
        if !overrides.is_empty() {
            text.push(format!("{}: {} error(s)", path.display(), overrides.len()));
            text.extend(overrides.iter().map(|e| format!("  {e}")));
        }
        return Err(StudyError::Problems(text.join("\n")));
    }
    let mut out = summary(model);
    if let Some(reach) = &reach {
        out.push_str(&reachability(model, reach));
    }
    for missing in missing_sections(model) {
        out.push_str(&format!("note: {missing}\n"));
    }
    Ok(out)
}

/// The optional sections a command needs but the case lacks.
fn missing_sections(model: &Model) -> Vec<&'static str> {
    let mut notes = Vec::new();
    if model.balancing.is_none() {
        notes.push("no `balancing` section: `variants` and `run` need one");
    }
    if model.tasks.is_none() {
        notes.push("no `tasks` section: `evaluate` and `run` need one");
    }
    notes
}

/// Longest description `check` prints, in characters.
const MAX_DESCRIPTION: usize = 400;

/// The description's start, cut at [`MAX_DESCRIPTION`] characters.
fn clipped(description: &str) -> String {
    match description.char_indices().nth(MAX_DESCRIPTION) {
        None => description.to_string(),
        Some((cut, _)) => format!(
            "{}… ({} more characters)",
            &description[..cut],
            description[cut..].chars().count()
        ),
    }
}

/// The errors of `balancing.overrides` (unknown element, a field the element does not have,
/// lo > hi, contradictory anchor constraints), each naming its field path; they need the
/// catalogue of candidate elements, so the model's own validation cannot see them.
pub fn override_errors(model: &Model) -> Vec<String> {
    if model.balancing.is_none() {
        return Vec::new();
    }
    let energy = counterpoise_balance::mechanism_energy(model);
    let catalogue = counterpoise_balance::Catalogue::build(
        &energy,
        &counterpoise_balance::catalogue_options(model),
    );
    match counterpoise_optimise::BoundsTable::new(model, &catalogue) {
        Ok(_) => Vec::new(),
        Err(counterpoise_optimise::OptimiseError::Overrides(errors)) => errors,
        Err(e) => vec![e.to_string()],
    }
}

fn coordinate_names(model: &Model) -> (Vec<&str>, Vec<bool>) {
    (
        model.coordinates.iter().map(|c| c.name.as_str()).collect(),
        model
            .coordinates
            .iter()
            .map(|c| c.kind == VarKind::Angle)
            .collect(),
    )
}

/// The text `check` prints for a valid case.
pub fn summary(model: &Model) -> String {
    let mut out = String::new();
    let line = |out: &mut String, s: String| {
        out.push_str(&s);
        out.push('\n');
    };
    line(&mut out, format!("case: {}", model.name));
    if let Some(d) = &model.description {
        line(&mut out, format!("  {}", clipped(d)));
    }
    line(
        &mut out,
        format!("coordinates ({}):", model.coordinates.len()),
    );
    for c in &model.coordinates {
        line(
            &mut out,
            format!(
                "  {:<10} {:<6} [{:.6}, {:.6}] {}",
                c.name,
                if c.kind == VarKind::Angle {
                    "angle"
                } else {
                    "length"
                },
                c.range[0],
                c.range[1],
                c.unit()
            ),
        );
    }
    line(
        &mut out,
        format!(
            "bodies ({}), total mass {:.3} kg:",
            model.bodies.len(),
            model.total_mass()
        ),
    );
    for b in &model.bodies {
        line(
            &mut out,
            format!(
                "  {:<12} {:>10.3} kg  com [{:.4}, {:.4}, {:.4}] m  frame of {}",
                b.name,
                b.mass,
                b.com.x,
                b.com.y,
                b.com.z,
                model.body_name(b.parent)
            ),
        );
    }
    for p in &model.payloads {
        line(
            &mut out,
            format!(
                "  payload on {}: {:.3} kg{}",
                model.bodies[p.body].name,
                p.mass,
                if p.in_balance {
                    " (counted in balancing)"
                } else {
                    ""
                }
            ),
        );
    }
    line(
        &mut out,
        format!(
            "joints ({}): all consistent over the coordinate ranges",
            model.joints.len()
        ),
    );
    for j in &model.joints {
        line(
            &mut out,
            format!(
                "  {:<6} {:<12} {} – {}",
                j.name,
                j.kind.name(),
                model.body_name(j.bodies[0]),
                model.body_name(j.bodies[1])
            ),
        );
    }
    line(&mut out, format!("actuators ({}):", model.actuators.len()));
    for a in &model.actuators {
        line(
            &mut out,
            format!(
                "  {:<6} on {:<6} u = {}   ratio {}",
                a.name, model.joints[a.joint].name, a.source, a.ratio
            ),
        );
    }
    let (names, is_angle) = coordinate_names(model);
    let energy = model.potential_energy(PayloadMode::InBalance);
    let varying = energy.format_with(&names, &is_angle, 2, true);
    let varying = match varying.strip_prefix('−') {
        Some(rest) => format!("− {rest}"),
        None => format!("+ {varying}"),
    };
    line(
        &mut out,
        format!("unbalanced potential energy: V = const {varying} J"),
    );
    if let Some(b) = &model.balancing {
        let cw = b.counterweights.as_ref().map_or(0, |c| c.bodies.len());
        let springs = b.springs.as_ref().map_or(0, |s| s.pairs().len());
        let count = counterpoise_balance::enumerate::variant_count(
            cw as u64,
            springs as u64,
            b.dmax as u64,
        );
        line(
            &mut out,
            format!(
                "balancing: {cw} counterweights, {springs} springs, Dmax {} → {count} variants",
                b.dmax
            ),
        );
        // The search's order: ℚ, then ℚ(√2, √3), then floating point.
        let decision = match counterpoise_model::exact_mechanism(model) {
            Ok(_) => "exact over ℚ (every number of the case is rational)".to_string(),
            Err(_) => {
                match counterpoise_model::exact_mechanism_in::<counterpoise_symbolic::Surd>(model) {
                    Ok(_) => "exact over ℚ(√2, √3) (every rotation has its cosine and sine in that field: \
                         multiples of π/12, or atan2 of field numbers such as atan2(√2, 1))".to_string(),
                    Err(e) => format!(
                        "numeric: {e} (floating point, with an ambiguous zone reported as undecided)"
                    ),
                }
            }
        };
        line(&mut out, format!("balance decision: {decision}"));
        if let Some(note) = derived_bounds_note(model) {
            line(&mut out, note);
        }
    }
    out
}

/// The task grid as `evaluate` and `run` see it: the tasks they evaluate and those they leave
/// out, from the same evaluation (without reactions).
fn reachability(model: &Model, reach: &GridReach) -> String {
    let tasks = model.tasks.as_ref().expect("a grid reach needs tasks");
    let sizes: Vec<String> = tasks.grid.iter().map(|g| g.n.to_string()).collect();
    let mut out = format!(
        "task grid: {} = {} points, {} reachable; {} tasks, {} evaluable\n",
        sizes.join(" × "),
        reach.points,
        reach.reached_points,
        reach.tasks,
        reach.evaluable
    );
    if reach.evaluable < reach.tasks {
        let reasons: Vec<String> = reach
            .by_reason
            .iter()
            .map(|(k, n)| format!("{k} {n}"))
            .collect();
        out.push_str(&format!(
            "  {} tasks are left out by evaluate and run ({}), e.g.\n",
            reach.tasks - reach.evaluable,
            reasons.join(", ")
        ));
        let points = tasks.grid_points();
        for (i, j, reason) in &reach.examples {
            out.push_str(&format!(
                "    task {i}→{j} (u = {:?} → {:?}): {reason}\n",
                points[*i], points[*j]
            ));
        }
    }
    out
}
