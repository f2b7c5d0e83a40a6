//! `counterpoise variants CASE`: the exact balance search and its results.

use std::path::Path;
use std::time::Instant;

use counterpoise_balance::minimal::{MinimalReport, estimate_tested, minimal_search};
use counterpoise_balance::{
    Arithmetic, Catalogue, Class, Decision, SearchOptions, SearchReport, Status, VariantResult,
    catalogue_options, mechanism_energy, realization_hints, search,
};
use counterpoise_model::limits::{Limit, format_count};
use counterpoise_model::{Model, ModelError, Plane};
use serde_json::json;

use crate::error::{Result, StudyError, invalid};
use crate::guards::located;
use crate::preflight;

/// Version of the `variants --json` schema (documented in README.md).
/// 2: elements are named by catalogue label and body names (1 gave catalogue and body
/// indices).
pub const SCHEMA_VERSION: u32 = 2;

/// `counterpoise variants`: every set of at most Dmax elements decided (or, with `minimal`,
/// the minimal balancing sets), as tables or as the JSON document.
pub fn variants_text(
    path: &Path,
    model: &Model,
    dmax: Option<usize>,
    as_json: bool,
    minimal: bool,
) -> Result<String> {
    let Some(balancing) = &model.balancing else {
        invalid!("{}: the case has no `balancing` section", path.display());
    };
    let source = if dmax.is_some() {
        "--dmax"
    } else {
        "balancing.dmax"
    };
    let dmax = dmax.unwrap_or(balancing.dmax);
    if dmax == 0 {
        invalid!("--dmax must be at least 1");
    }
    if minimal {
        return run_minimal(path, model, dmax, source, as_json);
    }
    if let Err(e) = preflight::variant_guard(model, dmax, source) {
        return Err(refused(path, e));
    }
    let started = Instant::now();
    let energy = mechanism_energy(model);
    let catalogue = Catalogue::build(&energy, &catalogue_options(model));
    if catalogue.is_empty() {
        invalid!(
            "{}: `balancing` allows no counterweight and no spring",
            path.display()
        );
    }
    let report = search(
        &energy,
        catalogue,
        SearchOptions {
            dmax,
            hints: realization_hints(model),
        },
    );
    let elapsed = started.elapsed().as_secs_f64();
    Ok(if as_json {
        format!(
            "{}\n",
            serde_json::to_string_pretty(&to_json(model, dmax, &report, elapsed))?
        )
    } else {
        tables(model, dmax, &report, elapsed)
    })
}

/// The `--json` document.
pub fn to_json(
    model: &Model,
    dmax: usize,
    report: &SearchReport,
    seconds: f64,
) -> serde_json::Value {
    let catalogue: Vec<_> = report
        .catalogue
        .entries
        .iter()
        .map(
            |e| json!({ "label": e.label, "description": e.description, "variables": e.variables }),
        )
        .collect();
    let mut counts = serde_json::Map::new();
    for status in Status::SEARCH_VERDICTS {
        counts.insert(status.name().into(), json!(report.count(status)));
    }
    json!({
        "schema_version": SCHEMA_VERSION,
        "case": model.name,
        "dmax": dmax,
        "seconds": seconds,
        "catalogue": catalogue,
        "field": report.arithmetic,
        "counts": counts,
        "variants": report.variants,
    })
}

/// Magnitude of a body-frame vector and its angle, in `[0, 2π)`, in the element's plane (the
/// case's `plane`, x–y when unrestricted).
fn polar(v: [f64; 3], plane: Option<Plane>) -> (f64, f64) {
    let axes = plane.map_or((0, 1), |p| (p.axes()[0], p.axes()[1]));
    let (_, angle) = counterpoise_report::format::polar(v, axes);
    let angle = angle.rem_euclid(std::f64::consts::TAU);
    let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    // −0 and rounding just below 2π print as 0
    (
        norm,
        if std::f64::consts::TAU - angle < 1e-12 {
            0.0
        } else {
            angle
        },
    )
}

/// Witness parameters in the units of the paper's Table 1: kg, mm, N/mm, rad.
pub fn witness_lines(model: &Model, v: &VariantResult) -> Vec<String> {
    let Some(w) = &v.witness else {
        return Vec::new();
    };
    let mut lines = Vec::new();
    let (cw_plane, spring_plane) = (model.counterweight_plane(), model.spring_plane());
    for cw in &w.counterweights {
        let (r, phi) = polar(cw.offset, cw_plane);
        lines.push(format!(
            "{:<5} m = {:.3} kg, r = {:.1} mm, φ = {:.4} rad   (on {})",
            cw.label,
            cw.mass,
            r * 1e3,
            phi,
            cw.body
        ));
    }
    for s in &w.springs {
        let (a, alpha) = polar(s.anchor_a, spring_plane);
        let (b, beta) = polar(s.anchor_b, spring_plane);
        lines.push(format!(
            "{:<5} K = {:.4} N/mm, a = {:.1} mm, α = {:.4} rad, b = {:.1} mm, β = {:.4} rad   ({}–{})",
            s.label,
            s.stiffness * 1e-3,
            a * 1e3,
            alpha,
            b * 1e3,
            beta,
            s.body,
            s.other
        ));
    }
    lines
}

/// Which arithmetic decided the variants, in one line: the exact field by name (a case over
/// ℚ(√2, √3) is not "rational"), or floating point and how many variants were still exact.
fn decision_line(report: &SearchReport) -> String {
    let exact = report
        .variants
        .iter()
        .filter(|v| v.decision == Decision::Exact)
        .count();
    match report.arithmetic {
        Arithmetic::Rational if exact == report.variants.len() => {
            "decided in exact rational arithmetic (over ℚ: every number of the case is rational)\n"
                .to_string()
        }
        Arithmetic::Surd if exact == report.variants.len() => {
            "decided in exact arithmetic over ℚ(√2, √3) (numbers q₀ + q₁√2 + q₂√3 + q₃√6 with \
             rational qᵢ: every rotation of the case has its cosine and sine in that field, as multiples \
             of π/12 do; see `check`)\n"
                .to_string()
        }
        _ => format!(
            "decided in floating point with an ambiguous zone ({} of {} exactly): the case has an \
             irrational constant (see `check`)\n",
            exact,
            report.variants.len()
        ),
    }
}

/// The human-readable report.
pub fn tables(model: &Model, dmax: usize, report: &SearchReport, seconds: f64) -> String {
    let mut out = String::new();
    let (cw, springs) = report.catalogue.counts();
    out.push_str(&format!(
        "{}: {} elements ({cw} counterweights, {springs} springs), Dmax {dmax} → {} variants in {:.3} s\n\n",
        model.name,
        report.catalogue.len(),
        report.variants.len(),
        seconds
    ));
    out.push_str(&format!("{:<14}", "status"));
    let classes = [Class::Counterweights, Class::Springs, Class::Hybrid];
    for c in classes {
        out.push_str(&format!("{:>16}", c.name()));
    }
    out.push_str(&format!("{:>10}\n", "total"));
    for status in Status::SEARCH_VERDICTS {
        out.push_str(&format!("{:<14}", status.name()));
        for c in classes {
            out.push_str(&format!("{:>16}", report.count_class(status, c)));
        }
        out.push_str(&format!("{:>10}\n", report.count(status)));
    }
    out.push_str(&format!(
        "realizable (balanced + degenerate): {}\n",
        report.count(Status::Balanced) + report.count(Status::Degenerate)
    ));
    out.push_str(&decision_line(report));
    if report.count(Status::Balanced) + report.count(Status::Degenerate) == 0 {
        // Where a user goes next: how many elements the robot needs, or what a few can do.
        out.push_str(&format!(
            "no variant of at most {dmax} elements balances this mechanism: `variants CASE \
             --minimal --dmax N` gives the smallest Dmax at which one does, `partial CASE \
             --budget {dmax}` the counterweights that leave the least gravity torque\n"
        ));
    }
    out.push('\n');
    for v in report
        .variants
        .iter()
        .filter(|v| v.status == Status::Balanced)
    {
        let labels: Vec<&str> = v.elements.iter().map(|e| e.label.as_str()).collect();
        out.push_str(&format!(
            "{}  {}  free parameters: {}  verification residual {:.1e}\n",
            labels.join(" + "),
            v.class.name(),
            v.nullity,
            v.verification.map_or(f64::NAN, |x| x.residual)
        ));
        if !v.redundant.is_empty() {
            out.push_str(&format!(
                "    redundant (no effect on balance): {}\n",
                v.redundant.join(", ")
            ));
        }
        for line in witness_lines(model, v) {
            out.push_str(&format!("    {line}\n"));
        }
        for r in &v.relations {
            out.push_str(&format!("    relation: {r}\n"));
        }
        for r in &v.ranges {
            out.push_str(&format!(
                "    range: {} ∈ {} {}\n",
                r.variable, r.interval, r.unit
            ));
        }
    }
    let degenerate: Vec<&VariantResult> = report
        .variants
        .iter()
        .filter(|v| v.status == Status::Degenerate)
        .collect();
    if !degenerate.is_empty() {
        out.push_str("\ndegenerate (realizable, but some element can only idle):\n");
        for v in degenerate {
            let labels: Vec<&str> = v.elements.iter().map(|e| e.label.as_str()).collect();
            out.push_str(&format!(
                "{}  idle: {}\n",
                labels.join(" + "),
                v.idle.join(", ")
            ));
        }
    }
    let others: Vec<&VariantResult> = report
        .variants
        .iter()
        .filter(|v| matches!(v.status, Status::Undecided | Status::Unrealizable))
        .collect();
    if !others.is_empty() {
        out.push_str("\nunrealizable or undecided:\n");
        for v in others {
            let labels: Vec<&str> = v.elements.iter().map(|e| e.label.as_str()).collect();
            out.push_str(&format!(
                "{}  {}: {}\n",
                labels.join(" + "),
                v.status.name(),
                v.reason.as_deref().unwrap_or("")
            ));
        }
    }
    out
}

/// Linear tests of the minimal-set walk counted as one variant by the variant guard: a test is
/// one element's columns reduced modulo a prime (about 10 µs on the 6-axis arm), a variant's
/// full decision takes about 10 ms; 100 keeps the walk well under the time a refused variant
/// count would take.
pub const WALK_TESTS_PER_VARIANT: u64 = 100;

/// The variant guard of `--minimal`: the pruned walk's size (the reach pruning alone, an upper
/// estimate of the sets it tests) against the variants limit, instead of `C(n, ≤ Dmax)`.
pub fn minimal_guard(
    exact: &counterpoise_balance::exact::ExactBasis,
    dmax: usize,
    source: &str,
) -> Result<u64, ModelError> {
    let limits = preflight::limits();
    let refuse = |what: String, found: f64, limit: Limit| ModelError::Invalid {
        path: source.to_string(),
        reason: format!(
            "{} {what}; the limit is {}; lower --dmax or restrict the elements, or {}",
            format_count(found),
            format_count(limits.get(limit) as f64),
            limit.hint()
        ),
    };
    if dmax as u64 > limits.dmax {
        return Err(refuse(
            "elements per variant".into(),
            dmax as f64,
            Limit::Dmax,
        ));
    }
    let budget = limits.variants.saturating_mul(WALK_TESTS_PER_VARIANT);
    let estimate = estimate_tested(exact, dmax, budget);
    if estimate > budget {
        // The count stops once past the budget: say so rather than quote the partial count.
        return Err(ModelError::Invalid {
            path: source.to_string(),
            reason: format!(
                "more than {} sets for the minimal-set walk to test at Dmax {dmax}, counted \
                 after pruning ({WALK_TESTS_PER_VARIANT} tests count as one variant); the \
                 limit is {} variants; lower --dmax or restrict the elements, or {}",
                format_count(budget as f64),
                format_count(limits.variants as f64),
                Limit::Variants.hint()
            ),
        });
    }
    Ok(estimate)
}

/// `variants --minimal`: the minimal balancing sets up to Dmax, each decided in full.
fn run_minimal(
    path: &Path,
    model: &Model,
    dmax: usize,
    source: &str,
    as_json: bool,
) -> Result<String> {
    let started = Instant::now();
    let energy = mechanism_energy(model);
    let catalogue = Catalogue::build(&energy, &catalogue_options(model));
    if catalogue.is_empty() {
        invalid!(
            "{}: `balancing` allows no counterweight and no spring",
            path.display()
        );
    }
    let exact = match &energy.exact {
        Ok(mechanism) => counterpoise_balance::exact::ExactBasis::build(mechanism, &catalogue),
        Err(reason) => invalid!(
            "{}: minimal sets need an exact case (every number rational); this one is decided \
             in floating point: {reason}",
            path.display()
        ),
    };
    if let Err(e) = minimal_guard(&exact, dmax, source) {
        return Err(refused(path, e));
    }
    let report = minimal_search(
        &energy,
        catalogue,
        SearchOptions {
            dmax,
            hints: realization_hints(model),
        },
    )?;
    let elapsed = started.elapsed().as_secs_f64();
    Ok(if as_json {
        format!(
            "{}\n",
            serde_json::to_string_pretty(&minimal_json(model, dmax, &report, elapsed))?
        )
    } else {
        minimal_tables(model, dmax, &report, elapsed)
    })
}

/// The `variants --minimal --json` document.
pub fn minimal_json(
    model: &Model,
    dmax: usize,
    report: &MinimalReport,
    seconds: f64,
) -> serde_json::Value {
    let catalogue: Vec<_> = report
        .catalogue
        .entries
        .iter()
        .map(
            |e| json!({ "label": e.label, "description": e.description, "variables": e.variables }),
        )
        .collect();
    let mut counts = serde_json::Map::new();
    for status in Status::SEARCH_VERDICTS {
        let n = report.sets.iter().filter(|v| v.status == status).count();
        counts.insert(status.name().into(), json!(n));
    }
    json!({
        "schema_version": SCHEMA_VERSION,
        "case": model.name,
        "dmax": dmax,
        "seconds": seconds,
        "catalogue": catalogue,
        "minimal": {
            "smallest_linear": report.smallest_linear,
            "smallest_balanced": report.smallest_balanced,
            "smallest_balanced_note": report.smallest_balanced_note,
            "tested": report.tested,
            "estimate": report.estimate,
            "combinations": report.combinations.to_string(),
            "supersets_decided": report.supersets_decided,
            "first_balanced": report.first_balanced,
            "disagreements": report.disagreements,
            "counts": counts,
        },
        "variants": report.sets,
    })
}

/// The human-readable report of `--minimal`.
pub fn minimal_tables(model: &Model, dmax: usize, report: &MinimalReport, seconds: f64) -> String {
    let mut out = String::new();
    let (cw, springs) = report.catalogue.counts();
    out.push_str(&format!(
        "{}: {} elements ({cw} counterweights, {springs} springs), minimal balancing sets up to \
         Dmax {dmax}: {} in {:.3} s\n",
        model.name,
        report.catalogue.len(),
        report.sets.len(),
        seconds
    ));
    out.push_str(&format!(
        "pruned walk: {} sets tested (estimate {}) instead of all {} combinations; every set \
         confirmed in exact arithmetic\n",
        report.tested, report.estimate, report.combinations
    ));
    if report.disagreements > 0 {
        out.push_str(&format!(
            "warning: the modular screen and the exact confirmation disagreed on {} sets\n",
            report.disagreements
        ));
    }
    match report.smallest_linear {
        None => out.push_str(&format!(
            "no set of at most {dmax} elements balances this mechanism, even at the linear level\n"
        )),
        Some(d) => out.push_str(&format!(
            "smallest Dmax with solvable balance equations: {d}\n"
        )),
    }
    match (report.smallest_balanced, &report.smallest_balanced_note) {
        (Some(d), None) => out.push_str(&format!(
            "smallest Dmax at which a variant balances (verified witness): {d}\n"
        )),
        (Some(d), Some(note)) => out.push_str(&format!(
            "smallest Dmax at which a variant balances: at most {d} ({note})\n"
        )),
        (None, note) => out.push_str(&format!(
            "no variant of at most {dmax} elements balances with verified physical parameters{}\n",
            note.as_ref().map_or(String::new(), |n| format!(" ({n})"))
        )),
    }
    if report.supersets_decided > 0 {
        out.push_str(&format!(
            "({} non-minimal balancing sets decided in full to find it)\n",
            report.supersets_decided
        ));
    }
    if !report.first_balanced.is_empty() {
        out.push_str(&format!(
            "balanced at that size, each a minimal set plus what makes it realizable ({}):\n",
            report.first_balanced.len()
        ));
        for v in &report.first_balanced {
            let labels: Vec<&str> = v.elements.iter().map(|e| e.label.as_str()).collect();
            out.push_str(&format!("  {}  {}\n", labels.join(" + "), v.class.name()));
        }
    }
    out.push('\n');
    out.push_str(&format!("{:<6}", "size"));
    for status in Status::SEARCH_VERDICTS {
        out.push_str(&format!("{:>14}", status.name()));
    }
    out.push_str(&format!("{:>10}\n", "total"));
    let largest = report
        .sets
        .iter()
        .map(|v| v.elements.len())
        .max()
        .unwrap_or(0);
    for d in 1..=largest {
        let of_size: Vec<&VariantResult> = report
            .sets
            .iter()
            .filter(|v| v.elements.len() == d)
            .collect();
        if of_size.is_empty() {
            continue;
        }
        out.push_str(&format!("{d:<6}"));
        for status in Status::SEARCH_VERDICTS {
            let n = of_size.iter().filter(|v| v.status == status).count();
            out.push_str(&format!("{n:>14}"));
        }
        out.push_str(&format!("{:>10}\n", of_size.len()));
    }
    out.push('\n');
    for v in &report.sets {
        let labels: Vec<&str> = v.elements.iter().map(|e| e.label.as_str()).collect();
        out.push_str(&format!(
            "{}  {}  {}",
            labels.join(" + "),
            v.class.name(),
            v.status.name()
        ));
        match v.status {
            Status::Balanced => out.push_str(&format!("  free parameters: {}\n", v.nullity)),
            _ => out.push_str(&format!(": {}\n", v.reason.as_deref().unwrap_or(""))),
        }
        if v.status == Status::Balanced {
            for line in witness_lines(model, v) {
                out.push_str(&format!("    {line}\n"));
            }
        }
    }
    out
}

/// A guard's refusal, located in the case file.
fn refused(path: &Path, e: ModelError) -> StudyError {
    StudyError::Case {
        path: path.to_path_buf(),
        errors: located(Some(path), vec![e]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn report(arithmetic: Arithmetic) -> SearchReport {
        SearchReport {
            catalogue: Catalogue {
                entries: Vec::new(),
            },
            variants: Vec::new(),
            arithmetic,
        }
    }

    /// The line names the field the search used: a case decided over ℚ(√2, √3) (the three-chain
    /// leg at 120°) was once said to be decided "in exact rational arithmetic".
    #[test]
    fn the_decision_line_names_the_field() {
        let surd = decision_line(&report(Arithmetic::Surd));
        assert!(surd.contains("exact arithmetic over ℚ(√2, √3)"), "{surd}");
        assert!(!surd.contains("rational arithmetic"), "{surd}");
        let rational = decision_line(&report(Arithmetic::Rational));
        assert!(rational.starts_with("decided in exact rational arithmetic (over ℚ"));
        let float = decision_line(&report(Arithmetic::Float));
        assert!(float.starts_with("decided in floating point"), "{float}");
        // The JSON names it too, in ASCII.
        assert_eq!(
            serde_json::to_value(Arithmetic::Surd).unwrap(),
            json!("Q(sqrt2,sqrt3)")
        );
    }
}
