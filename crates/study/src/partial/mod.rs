//! `counterpoise partial CASE`: the best partial balancing within a budget of elements — the
//! sets of counterweights and springs and their parameters, within the case's bounds, that
//! leave the least RMS gravity torque over the workspace on the joints that matter, ranked,
//! each beside the exact balance search's verdict on the same set and the gap to its lower
//! bound.

pub mod fallback;

use std::path::Path;
use std::time::Instant;

use counterpoise_balance::linear::LiftedBasis;
use counterpoise_balance::partial::{
    CERTIFY, CounterweightLimits, ElementLimits, PartialDesign, PartialOptions, PartialReport,
    SpringLimits, TorqueBasis, Workspace, candidate_entries, partial_search, set_count,
};
use counterpoise_balance::search::decide;
use counterpoise_balance::{
    Catalogue, Status, VerificationSet, catalogue_options, mechanism_energy, realization_hints,
};
use counterpoise_dynamics::Evaluator;
use counterpoise_model::limits::{Limit, format_count};
use counterpoise_model::{Model, ModelError};
use counterpoise_optimise::{BoundsTable, ElementBounds};
use serde_json::json;

use crate::error::{Result, StudyError, invalid};
use crate::guards::located;

/// Version of the `partial --json` document (documented in README.md).
/// 2: elements are named by catalogue label and body names (1 gave catalogue and body
/// indices).
pub const SCHEMA_VERSION: u32 = 2;

/// Values per varying actuator of the workspace sample when `--points` is not given (fewer
/// when their product would exceed the grid-points limit): 7 values see every harmonic of an
/// arm's gravity torque that a 3-point task grid (both ends and the middle) would not.
pub const DEFAULT_POINTS: usize = 7;

/// Options of the command.
pub struct Options {
    pub budget: Option<usize>,
    /// Actuator or joint names (`None`: every actuator).
    pub joints: Option<Vec<String>>,
    pub points: Option<usize>,
    /// Best designs shown per size.
    pub top: usize,
    pub json: bool,
    /// Sets drawn from the springs too (`--counterweights-only` turns it off).
    pub springs: bool,
}

/// The actuators named by `names` (an actuator's name or its joint's), in actuator order.
fn select_joints(model: &Model, names: Option<&[String]>) -> Result<Vec<usize>> {
    let Some(names) = names else {
        return Ok((0..model.actuators.len()).collect());
    };
    let mut picked = Vec::new();
    for name in names {
        let name = name.trim();
        let found = model.actuators.iter().position(|a| {
            a.name == name || model.joints.get(a.joint).is_some_and(|j| j.name == name)
        });
        match found {
            Some(i) => picked.push(i),
            None => {
                let valid: Vec<String> = model
                    .actuators
                    .iter()
                    .map(|a| {
                        let joint = &model.joints[a.joint].name;
                        if *joint == a.name {
                            a.name.clone()
                        } else {
                            format!("{} (joint {joint})", a.name)
                        }
                    })
                    .collect();
                invalid!(
                    "--joints: `{name}` is neither an actuator nor an actuated joint of the case; \
                     the actuators are {}",
                    valid.join(", ")
                );
            }
        }
    }
    if picked.is_empty() {
        invalid!("--joints: no joint named");
    }
    picked.sort_unstable();
    picked.dedup();
    Ok(picked)
}

/// The workspace sample in actuator space: per actuator whose task-grid axis varies, `n`
/// equally spaced values over that axis; an axis with one value keeps it.
fn workspace_points(model: &Model, points: Option<usize>) -> Result<(Vec<Vec<f64>>, usize)> {
    let Some(tasks) = &model.tasks else {
        invalid!("the case has no `tasks` grid: partial balancing samples the workspace over it");
    };
    let varying = tasks.grid.iter().filter(|a| a.n > 1).count() as u32;
    let limit = crate::preflight::limits().get(Limit::GridPoints);
    let n = match points {
        Some(n) => {
            if n < 2 {
                invalid!("--points must be at least 2");
            }
            let total = (n as f64).powi(varying as i32);
            if total > limit as f64 {
                invalid!(
                    "--points {n}: {} workspace points ({n}^{varying}); the limit is {}; lower \
                     --points, or {}",
                    format_count(total),
                    format_count(limit as f64),
                    Limit::GridPoints.hint()
                );
            }
            n
        }
        None => (2..=DEFAULT_POINTS)
            .rev()
            .find(|&n| (n as u64).saturating_pow(varying) <= limit)
            .unwrap_or(2),
    };
    let mut grid = vec![Vec::new()];
    for axis in &tasks.grid {
        let values: Vec<f64> = if axis.n > 1 {
            (0..n)
                .map(|i| axis.from + (axis.to - axis.from) * i as f64 / (n - 1) as f64)
                .collect()
        } else {
            vec![axis.from]
        };
        grid = grid
            .iter()
            .flat_map(|p: &Vec<f64>| {
                values.iter().map(move |&v| {
                    let mut p = p.clone();
                    p.push(v);
                    p
                })
            })
            .collect();
    }
    Ok((grid, n))
}

/// Every element's bounds (the case's `bounds` with its overrides).
fn limits(model: &Model, catalogue: &Catalogue) -> Result<Vec<Option<ElementLimits>>> {
    let table = BoundsTable::new(model, catalogue)?;
    Ok(table
        .entries
        .iter()
        .map(|b| {
            Some(match b {
                ElementBounds::Counterweight(c) => {
                    ElementLimits::Counterweight(CounterweightLimits {
                        mass: c.mass,
                        radius: c.radius,
                    })
                }
                ElementBounds::Spring(s) => ElementLimits::Spring(SpringLimits {
                    stiffness: s.stiffness,
                    anchor_a: s.anchor_a,
                    anchor_b: s.anchor_b,
                    box_a: s.box_a,
                    box_b: s.box_b,
                }),
            })
        })
        .collect())
}

/// `counterpoise partial`: the best partial balancings within the budget, as tables or as
/// the JSON document.
pub fn partial_text(path: &Path, model: &Model, options: &Options) -> Result<String> {
    let Some(balancing) = &model.balancing else {
        invalid!("{}: the case has no `balancing` section", path.display());
    };
    let budget = options.budget.unwrap_or(balancing.dmax);
    if budget == 0 {
        invalid!("--budget must be at least 1");
    }
    let joints = select_joints(model, options.joints.as_deref())?;
    let energy = mechanism_energy(model);
    let catalogue = Catalogue::build(&energy, &catalogue_options(model));
    if candidate_entries(&catalogue, options.springs).is_empty() {
        invalid!(
            "{}: `balancing` allows no counterweight{}",
            path.display(),
            if options.springs {
                " and no spring"
            } else {
                " (--counterweights-only)"
            }
        );
    }
    if let Err(e) = set_guard_for(&catalogue, budget, options.springs) {
        return Err(StudyError::Case {
            path: path.to_path_buf(),
            errors: located(Some(path), vec![e]),
        });
    }
    let computed = compute_with(
        model,
        budget,
        joints,
        options.points,
        options.top,
        options.springs,
    )?;
    Ok(if options.json {
        format!(
            "{}\n",
            serde_json::to_string_pretty(&to_json(model, &computed))?
        )
    } else {
        tables(model, &computed)
    })
}

/// The variant limit applied to the number of sets [`compute`] solves (counterweights).
fn set_guard(catalogue: &Catalogue, budget: usize) -> Result<(), ModelError> {
    set_guard_for(catalogue, budget, false)
}

/// [`set_guard`] for the sets of counterweights only when `springs` is false.
fn set_guard_for(catalogue: &Catalogue, budget: usize, springs: bool) -> Result<(), ModelError> {
    let sets = set_count(catalogue, budget, springs);
    let limit = crate::preflight::limits().get(Limit::Variants);
    if sets > u128::from(limit) {
        return Err(ModelError::Invalid {
            path: "--budget".into(),
            reason: format!(
                "{} sets of at most {budget} {}; the limit is {}; lower --budget{}, or {}",
                format_count(sets as f64),
                if springs {
                    "counterweights and springs"
                } else {
                    "counterweights"
                },
                format_count(limit as f64),
                if springs {
                    ", pass --counterweights-only"
                } else {
                    ""
                },
                Limit::Variants.hint()
            ),
        });
    }
    Ok(())
}

/// A partial search with what its tables need: the ranking, the workspace it was measured on,
/// the designs shown and the exact search's verdict on each.
pub struct Computed {
    pub report: PartialReport,
    /// Whether the sets were drawn from the springs too.
    pub springs: bool,
    sample: Sample,
    /// Indices into `report.designs` of the designs shown (see [`shown`]).
    pub shown: Vec<usize>,
    /// The exact balance search's verdict on each shown set.
    pub verdicts: Vec<Status>,
    pub seconds: f64,
}

/// Solves every set of at most `budget` counterweights of the case for the least RMS gravity
/// torque on `joints` (actuator indices) over the workspace sample (`points` values per varying
/// actuator), and decides the `top` best sets of each size exactly. Counterweights only: this
/// is `run`'s fallback ([`fallback`]), whose files and tests predate the spring sets; the
/// command itself calls [`compute_with`].
pub fn compute(
    model: &Model,
    budget: usize,
    joints: Vec<usize>,
    points: Option<usize>,
    top: usize,
) -> Result<Computed> {
    compute_with(model, budget, joints, points, top, false)
}

/// [`compute`], with the sets drawn from the springs too when `springs` is true.
pub fn compute_with(
    model: &Model,
    budget: usize,
    joints: Vec<usize>,
    points: Option<usize>,
    top: usize,
    springs: bool,
) -> Result<Computed> {
    let started = Instant::now();
    let energy = mechanism_energy(model);
    let catalogue = Catalogue::build(&energy, &catalogue_options(model));
    let candidates = candidate_entries(&catalogue, springs);
    let bounds = limits(model, &catalogue)?;
    let (targets, per_axis) = workspace_points(model, points)?;
    let evaluator = Evaluator::new(model)?;
    let mut configurations = Vec::with_capacity(targets.len());
    let mut unreachable = 0;
    for u in &targets {
        match evaluator.solve_point(u) {
            Ok(q) => configurations.push(q),
            Err(_) => unreachable += 1,
        }
    }
    let workspace = Workspace::new(model, &configurations);
    if workspace.is_empty() {
        invalid!(
            "none of the {} workspace points is reachable with a regular actuator Jacobian",
            targets.len()
        );
    }
    let basis = TorqueBasis::build(&energy, &catalogue, &workspace, &candidates);
    let report = partial_search(
        &catalogue,
        &basis,
        &bounds,
        &PartialOptions {
            springs,
            ..PartialOptions::new(budget, joints)
        },
    )?;
    // The exact verdict of the sets shown: does the set balance at all, whatever the bounds?
    let shown = shown(&report, top);
    let lifted = LiftedBasis::build(&energy, &catalogue);
    let checks = VerificationSet::new(&energy);
    let hints = realization_hints(model);
    let verdicts: Vec<Status> = shown
        .iter()
        .map(|&i| {
            decide(
                &energy,
                &catalogue,
                &lifted,
                &checks,
                &report.designs[i].entries,
                hints,
            )
            .status
        })
        .collect();
    Ok(Computed {
        report,
        springs,
        sample: Sample {
            requested: targets.len(),
            per_axis,
            unreachable,
            singular: workspace.singular,
        },
        shown,
        verdicts,
        seconds: started.elapsed().as_secs_f64(),
    })
}

/// How the workspace was sampled.
struct Sample {
    requested: usize,
    per_axis: usize,
    unreachable: usize,
    singular: usize,
}

/// Indices (into the ranking) of the designs shown: the best `top` of each size, in rank order,
/// leaving out designs with an unused element (the smaller set is ranked on its own).
fn shown(report: &PartialReport, top: usize) -> Vec<usize> {
    let mut per_size = vec![0usize; report.budget + 1];
    let mut out = Vec::new();
    for (i, d) in report.designs.iter().enumerate() {
        let size = d.entries.len();
        if d.unused.is_empty() && per_size[size] < top {
            per_size[size] += 1;
            out.push(i);
        }
    }
    out
}

/// Reduction of `value` against `reference`, in % (negative = less torque).
fn change(value: f64, reference: f64) -> f64 {
    if reference > 0.0 {
        100.0 * (value / reference - 1.0)
    } else {
        0.0
    }
}

/// Metres in millimetres rounded to 0.1 mm, a value that rounds to zero shown as `0.0` (not
/// `-0.0`: the solver's −4e-5 mm is no direction).
fn millimetres(metres: f64) -> f64 {
    let mm = (metres * 1e4).round() / 10.0;
    if mm == 0.0 { 0.0 } else { mm }
}

/// The name of a spring's second body, or `base`.
/// `(x, y, z)` in mm, rounded to 0.1 mm.
fn point_mm(p: &[f64; 3]) -> String {
    format!(
        "({:.1}, {:.1}, {:.1}) mm",
        millimetres(p[0]),
        millimetres(p[1]),
        millimetres(p[2])
    )
}

fn design_line(d: &PartialDesign) -> String {
    let springs = d.springs.iter().map(|p| {
        let s = &p.spring;
        if d.unused.contains(&s.label) {
            format!("{}: unused (0 N/m)", s.label)
        } else {
            format!(
                "{}: K = {:.1} N/m, a = {} on {}, b = {} on {}, its torque {:.3} RMS",
                s.label,
                s.stiffness,
                point_mm(&s.anchor_a),
                s.body,
                point_mm(&s.anchor_b),
                s.other,
                p.torque_rms
            )
        }
    });
    d.counterweights
        .iter()
        .map(|c| {
            let label = &c.label;
            if d.unused.contains(label) {
                format!("{label}: unused (0 kg)")
            } else {
                let r = c.offset.iter().map(|v| v * v).sum::<f64>().sqrt();
                format!(
                    "{label}: m = {:.3} kg at r = ({:.1}, {:.1}, {:.1}) mm (|r| = {:.1} mm, on {})",
                    c.mass,
                    millimetres(c.offset[0]),
                    millimetres(c.offset[1]),
                    millimetres(c.offset[2]),
                    r * 1e3,
                    c.body
                )
            }
        })
        .chain(springs)
        .collect::<Vec<_>>()
        .join("; ")
}

/// The lower bound and whether the design meets it, in one line.
fn bound_line(d: &PartialDesign, unbalanced: f64) -> String {
    if d.certified {
        format!(
            "certified optimal: lower bound {:.3} (gap {:.3}, within {} % of the unbalanced \
             total)",
            d.lower_bound,
            d.gap,
            CERTIFY * 100.0
        )
    } else if d.lower_bound.is_nan() {
        "no lower bound (the relaxation failed)".to_string()
    } else {
        format!(
            "not certified: lower bound {:.3}, gap {:.3} ({:.2} % of the unbalanced total)",
            d.lower_bound,
            d.gap,
            100.0 * d.gap / unbalanced.max(f64::MIN_POSITIVE)
        )
    }
}

fn tables(model: &Model, computed: &Computed) -> String {
    let Computed {
        report,
        springs,
        sample,
        shown,
        verdicts,
        seconds,
    } = computed;
    let names: Vec<&str> = model.actuators.iter().map(|a| a.name.as_str()).collect();
    let selected: Vec<&str> = report.joints.iter().map(|&j| names[j]).collect();
    let mut out = format!(
        "{}: partial balancing with at most {} {}: {} sets in {:.2} s\n",
        model.name,
        report.budget,
        if *springs {
            "counterweight(s) and spring(s)"
        } else {
            "counterweight(s) (--counterweights-only)"
        },
        report.sets,
        seconds
    );
    out.push_str(&format!(
        "workspace: {} values per varying actuator over the task grid's range → {} points, {} \
         used ({} unreachable, {} with a singular actuator Jacobian)\n",
        sample.per_axis, sample.requested, report.points, sample.unreachable, sample.singular
    ));
    out.push_str(&format!(
        "minimised: total RMS gravity torque of {} = √(Σ RMS²) over the workspace (actuator \
         forces before the ratio, N·m or N)\n",
        selected.join(", ")
    ));
    out.push_str("unbalanced RMS: ");
    out.push_str(
        &names
            .iter()
            .zip(&report.unbalanced_rms)
            .map(|(n, v)| format!("{n} {v:.3}"))
            .collect::<Vec<_>>()
            .join(", "),
    );
    out.push_str(&format!("; total {:.3}\n\n", report.unbalanced_total));
    out.push_str(&format!(
        "{:>4}  {:<24} {:>10} {:>8}  {:<12}",
        "rank", "set", "total", "Δ [%]", "exact"
    ));
    for n in &names {
        out.push_str(&format!(" {:>12}", format!("{n} Δ[%]")));
    }
    out.push('\n');
    if shown.is_empty() {
        out.push_str(
            "      (none: every set's best design leaves its counterweights at 0 kg; see the \
             bounds)\n",
        );
    }
    for (&i, verdict) in shown.iter().zip(verdicts) {
        let d = &report.designs[i];
        out.push_str(&format!(
            "{:>4}  {:<24} {:>10.3} {:>8.2}  {:<12}",
            i + 1,
            d.labels.join(" + "),
            d.total_rms,
            change(d.total_rms, report.unbalanced_total),
            verdict.name()
        ));
        for (j, v) in d.rms.iter().enumerate() {
            out.push_str(&format!(" {:>12.2}", change(*v, report.unbalanced_rms[j])));
        }
        out.push('\n');
        out.push_str(&format!("      {}\n", design_line(d)));
        if d.status != "Solved" {
            out.push_str(&format!("      solver status: {}\n", d.status));
        }
        if let Some(note) = &d.note {
            out.push_str(&format!("      {note}\n"));
        }
        out.push_str(&format!(
            "      {}\n",
            bound_line(d, report.unbalanced_total)
        ));
    }
    out.push_str(
        "\ntotal: RMS over the selected joints; Δ: change against the unbalanced mechanism \
         (negative = less torque); exact: the balance search's verdict on the set, whatever the \
         bounds (balanced = some parameters balance it perfectly; infeasible = no parameters do, \
         on every joint); a set whose best design leaves a counterweight at 0 kg is not shown (the \
         smaller set is). A design with springs comes from alternating convex programs (one \
         anchor of every spring fixed) from several starts; its lower bound is a convex \
         relaxation's, so it is certified optimal only when it meets that bound.\n",
    );
    out
}

/// The `partial --json` document (also `run`'s partial.json).
pub fn to_json(model: &Model, computed: &Computed) -> serde_json::Value {
    let Computed {
        report,
        springs,
        sample,
        shown,
        verdicts,
        seconds,
    } = computed;
    let names: Vec<&str> = model.actuators.iter().map(|a| a.name.as_str()).collect();
    let designs = serde_json::to_value(&report.designs).unwrap_or_default();
    let exact: Vec<serde_json::Value> = shown
        .iter()
        .zip(verdicts)
        .map(|(&i, v)| json!({ "rank": i + 1, "status": v.name() }))
        .collect();
    json!({
        "schema_version": SCHEMA_VERSION,
        "case": model.name,
        "budget": report.budget,
        "seconds": seconds,
        "actuators": names,
        "joints": report.joints.iter().map(|&j| names[j]).collect::<Vec<_>>(),
        "workspace": {
            "per_axis": sample.per_axis,
            "requested": sample.requested,
            "points": report.points,
            "unreachable": sample.unreachable,
            "singular": sample.singular,
        },
        "unbalanced_rms": report.unbalanced_rms,
        "unbalanced_total": report.unbalanced_total,
        "sets": report.sets,
        "springs_searched": springs,
        "certify_fraction": CERTIFY,
        "exact": exact,
        "designs": designs,
    })
}

#[cfg(test)]
mod tests {
    use super::millimetres;

    /// 0.4255 m is 425.5 mm; −4·10⁻⁸ m (a solver's zero) prints as `0.0`, not `-0.0`; −0.7 mm
    /// keeps its sign.
    #[test]
    fn millimetres_round_to_a_tenth_without_a_negative_zero() {
        assert_eq!(format!("{:.1}", millimetres(0.4255)), "425.5");
        assert_eq!(format!("{:.1}", millimetres(-4e-8)), "0.0");
        assert_eq!(format!("{:.1}", millimetres(-0.0007)), "-0.7");
    }
}
