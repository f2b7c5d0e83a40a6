//! `counterpoise check CASE`: validate a case and summarise the mechanism.

use std::path::Path;
use std::process::ExitCode;

use anyhow::Result;
use counterpoise_model::{Kinematics, Model, PayloadMode};
use counterpoise_symbolic::VarKind;
use nalgebra::DVector;

pub fn run(path: &Path) -> Result<ExitCode> {
    let Some(model) = super::load(path)? else {
        return Ok(ExitCode::FAILURE);
    };
    let errors = override_errors(&model);
    if !errors.is_empty() {
        eprintln!("{}: {} error(s)", path.display(), errors.len());
        for e in &errors {
            eprintln!("  {e}");
        }
        return Ok(ExitCode::FAILURE);
    }
    print!("{}", summary(&model));
    Ok(ExitCode::SUCCESS)
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
        line(&mut out, format!("  {d}"));
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
    if let Some(tasks) = &model.tasks {
        out.push_str(&reachability(model, tasks));
    }
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
    }
    out
}

/// Solves the chart coordinates at every grid point and reports the coordinate ranges reached.
fn reachability(model: &Model, tasks: &counterpoise_model::Tasks) -> String {
    let kinematics = Kinematics::new(model);
    let points = tasks.grid_points();
    let mut guess = DVector::from_vec(model.reference_configuration());
    let mut reached: Vec<(f64, f64)> = vec![(f64::INFINITY, f64::NEG_INFINITY); model.dof()];
    let mut failures = Vec::new();
    for (index, u) in points.iter().enumerate() {
        let target = DVector::from_column_slice(u);
        // warm start from the previous grid point, then from the reference configuration
        let solved = kinematics.solve_coordinates(&target, &guess).or_else(|_| {
            kinematics
                .solve_coordinates(&target, &DVector::from_vec(model.reference_configuration()))
        });
        match solved {
            Ok(q) => {
                for (k, r) in reached.iter_mut().enumerate() {
                    *r = (r.0.min(q[k]), r.1.max(q[k]));
                }
                guess = q;
            }
            Err(e) => failures.push(format!("    grid point {index} u = {u:?}: {e}")),
        }
    }
    let sizes: Vec<String> = tasks.grid.iter().map(|g| g.n.to_string()).collect();
    let mut out = format!(
        "task grid: {} = {} points, {} reachable\n",
        sizes.join(" × "),
        points.len(),
        points.len() - failures.len()
    );
    for (c, r) in model.coordinates.iter().zip(&reached) {
        if r.0.is_finite() {
            out.push_str(&format!(
                "  {:<10} reached [{:.6}, {:.6}] {}\n",
                c.name,
                r.0,
                r.1,
                c.unit()
            ));
        }
    }
    for f in failures.iter().take(10) {
        out.push_str(f);
        out.push('\n');
    }
    if failures.len() > 10 {
        out.push_str(&format!("    … and {} more\n", failures.len() - 10));
    }
    out
}
