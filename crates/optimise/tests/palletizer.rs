//! The paper's eleven feasible sets on the palletizer (Table 1), on a reduced task grid
//! (3 × 3 × 3 points, 21 samples per move) to keep the test quick: each is optimised within the
//! case bounds and peak limits or discarded with a reason. Independent references: the case
//! file's bounds and limits, the paper's RMS* formula applied to each variant's indicators, and
//! for the spring-only sets the gravity-free robot evaluated by the dynamics crate.

mod common;

use counterpoise_dynamics::params::ParameterSet;
use counterpoise_dynamics::{EvaluateOptions, Indicators, evaluate_grid};
use counterpoise_optimise::{OptimiseOptions, Status};

const SETS: [&[&str]; 11] = [
    &["m4", "m5"],
    &["m4", "m6"],
    &["K43", "K53"],
    &["K42", "K43"],
    &["K42", "K53"],
    &["m4", "K43"],
    &["m4", "K53"],
    &["m4", "K42"],
    &["m4", "K52"],
    &["m6", "K43"],
    &["m6", "K52"],
];

pub fn reduced_palletizer() -> serde_json::Value {
    let mut json = common::case_json("palletizer.json");
    // Same ranges as the case, three values per actuator.
    for (_, axis) in json["tasks"]["grid"].as_object_mut().unwrap().iter_mut() {
        axis[2] = serde_json::json!(3);
    }
    json["tasks"]["samples"] = serde_json::json!(21);
    json
}

/// RMS* = sqrt(Σ_n RMS_n² / N), each actuator's RMS in its own critical task.
fn rms_star(ind: &Indicators) -> f64 {
    let n = ind.actuators.len() as f64;
    (ind.actuators.iter().map(|a| a.crt_rms.powi(2)).sum::<f64>() / n).sqrt()
}

/// The unbalanced robot without gravity, evaluated by the dynamics crate directly: the motor
/// torques every spring-only variant must have (massless springs that balance gravity
/// exactly leave the inertial torques unchanged).
fn gravity_free(json: &serde_json::Value) -> Indicators {
    let mut json = json.clone();
    json["gravity"] = serde_json::json!([0.0, 0.0, 0.0]);
    let model = common::model(&json);
    let grid = evaluate_grid(
        &model,
        &ParameterSet::unbalanced(&model),
        &EvaluateOptions {
            reactions: false,
            ..EvaluateOptions::default()
        },
    )
    .unwrap();
    grid.indicators[0].clone()
}

fn within(value: f64, range: &serde_json::Value, what: &str) {
    let (lo, hi) = (range[0].as_f64().unwrap(), range[1].as_f64().unwrap());
    let tol = 1e-9 * hi.abs().max(1.0);
    assert!(
        lo - tol <= value && value <= hi + tol,
        "{what} = {value} outside [{lo}, {hi}]"
    );
}

#[test]
fn the_papers_eleven_sets() {
    let json = reduced_palletizer();
    let model = common::model(&json);
    let (_, results) = common::optimise(&model, &SETS, &OptimiseOptions::default());
    assert_eq!(results.len(), 11, "all eleven sets are balanced");
    let bounds = &json["balancing"]["bounds"];
    let limits = json["balancing"]["peak_limits"].as_object().unwrap();
    let inertial = gravity_free(&json);
    let inertial_rms_star = rms_star(&inertial);
    // The gravity-free robot is within every peak limit, so nothing stops a spring-only set.
    for a in &inertial.actuators {
        assert!(a.cpt_peak < limits[&a.name].as_f64().unwrap(), "{}", a.name);
    }
    let tolerance = OptimiseOptions::default().gap_tolerance;
    let mut shortcuts = 0;
    for v in &results {
        // A pass whose recovered point is within the gap tolerance of the relaxation's bound
        // keeps that point unrefined: its recorded gap is the candidate's own relative gap on
        // the working set.
        for it in &v.iterations {
            let gap = it.gap_before_refinement;
            assert!(gap >= 0.0, "{:?}: gap {gap}", v.elements);
            if it.relaxation_status == counterpoise_optimise::ConicStatus::Solved
                && gap <= tolerance
            {
                let own = ((it.objective_working - it.lower_bound) / it.objective_working).max(0.0);
                assert!(
                    (own - gap).abs() <= 1e-6,
                    "{:?}: {own} vs {gap}",
                    v.elements
                );
                shortcuts += 1;
            }
        }
        match v.status {
            Status::Feasible => {
                let obj = v.objective.unwrap();
                let ind = v.indicators.as_ref().unwrap();
                // the objective is RMS* of the variant's own indicators over all tasks
                assert!(
                    (obj - rms_star(ind)).abs() <= 1e-9 * obj,
                    "{:?}: objective {obj} vs RMS* {}",
                    v.elements,
                    rms_star(ind)
                );
                // the case's limits and bounds hold
                for a in &ind.actuators {
                    let limit = limits[&a.name].as_f64().unwrap();
                    assert!(
                        a.cpt_peak <= limit * (1.0 + 1e-9),
                        "{:?} {}",
                        v.elements,
                        a.name
                    );
                }
                for c in &v.counterweights {
                    within(c.mass, &bounds["mass"], &format!("{} mass", c.label));
                    within(
                        c.radius(),
                        &bounds["radius"],
                        &format!("{} radius", c.label),
                    );
                }
                for k in &v.springs {
                    within(k.stiffness, &bounds["stiffness"], &format!("{} K", k.label));
                }
                let gap = v.gap.expect("feasible variants report a gap");
                let bound = v.lower_bound.unwrap();
                assert!(bound <= obj * (1.0 + 1e-9));
                assert!((gap - (obj - bound) / obj).abs() <= 1e-6, "gap {gap}");
                let check = v.verification.as_ref().unwrap();
                assert!(check.passed);
                assert!(check.balance_residual <= 1e-9);
                assert!(check.bound_excess <= 1e-9);
                assert!(!v.iterations.is_empty());
                for fp in &v.free_parameters {
                    let tol = 1e-9 * fp.value.abs().max(1.0);
                    assert!(fp.interval[0] - tol <= fp.value && fp.value <= fp.interval[1] + tol);
                }
                if !v.springs.is_empty() {
                    assert!(v.delta_r_estimate.is_some(), "springs are chosen by ΔR");
                    assert!(!ind.joints.is_empty());
                }
            }
            Status::Discarded | Status::Undecided => {
                assert!(v.reason.as_ref().is_some_and(|r| !r.is_empty()));
            }
            other => panic!("the optimiser gave {other:?}, not one of its verdicts"),
        }
    }
    assert!(shortcuts > 0, "no pass kept its recovered point");
    // Spring-only sets (paper Table 1 realises each within these bounds) are feasible and
    // have the gravity-free robot's RMS*, computed above without the optimiser.
    let springs: Vec<_> = results
        .iter()
        .filter(|v| v.elements.iter().all(|e| e.starts_with('K')))
        .collect();
    assert_eq!(springs.len(), 3);
    for v in springs {
        assert!(v.is_feasible(), "{:?}: {:?}", v.elements, v.reason);
        let obj = v.objective.unwrap();
        assert!(
            (obj - inertial_rms_star).abs() <= 1e-9 * inertial_rms_star,
            "{:?}: {obj} vs gravity-free {inertial_rms_star}",
            v.elements
        );
    }
}

/// The optimisation problem of the variant made of the catalogue entries `labels`.
fn variant_problem(
    ctx: &counterpoise_optimise::Context,
    labels: &[&str],
) -> counterpoise_optimise::problem::VariantProblem {
    let set: Vec<usize> = labels
        .iter()
        .map(|l| {
            ctx.catalogue
                .entries
                .iter()
                .position(|e| &e.label == l)
                .unwrap()
        })
        .collect();
    counterpoise_optimise::problem::VariantProblem::new(
        &ctx.model,
        &ctx.catalogue,
        &ctx.bounds,
        &set,
        counterpoise_balance::linear::solve(&ctx.basis, &set),
        |b| ctx.torques.slot_of(b),
    )
    .unwrap()
}

/// `m4 + K42` balances only with K42's anchor a at x = 1/4 on the upper arm and b on the
/// slider's y axis (relations `K42 − 4·K42·ax = 0`, `K42·ay = 0`, `K42·bx = 0`), so a physical
/// spring has `K·ax·by = K·by/4` and `K·ax·bx = K·ay·by = 0`. The lifted family alone leaves
/// those products free; optimising there ended at counterweights no spring could complete (and
/// the variant was lost). Checked against the exact relations printed by the balance search,
/// solved by hand for the physical parameters:
/// `m4 − (100/981)·K·by = 1829/8` and `m4·r4x − (100/981)·K·ax·by = −1851/8`, with `ax = 1/4`
/// and `r4y = 0`, on the full task grid's peak limits.
#[test]
fn a_spring_whose_anchor_balance_fixes_is_realized_on_the_restricted_family() {
    let json = common::case_json("palletizer.json");
    let model = common::model(&json);
    let (ctx, results) = common::optimise(&model, &[&["m4", "K42"]], &OptimiseOptions::default());
    // The physical family is two-dimensional (K and K·by fix everything else), the lifted one
    // six-dimensional; the search runs on the restricted one.
    let problem = variant_problem(&ctx, &["m4", "K42"]);
    assert_eq!(problem.solution.nullspace.ncols(), 6);
    assert_eq!(problem.dim(), 2);
    let v = &results[0];
    assert!(v.is_feasible(), "{:?}", v.reason);
    let c = &v.counterweights[0];
    let k = &v.springs[0];
    let (m, rx, ry) = (c.mass, c.offset[0], c.offset[1]);
    let (kk, ax, ay, bx, by) = (
        k.stiffness,
        k.anchor_a[0],
        k.anchor_a[1],
        k.anchor_b[0],
        k.anchor_b[1],
    );
    assert!((ax - 0.25).abs() < 1e-9 && ay.abs() < 1e-9 && bx.abs() < 1e-9);
    assert!(ry.abs() < 1e-9, "r4y = {ry}");
    let g = 100.0 / 981.0;
    assert!(
        (m - g * kk * by - 1829.0 / 8.0).abs() < 1e-6 * m,
        "mass relation"
    );
    assert!(
        (m * rx - g * kk * ax * by + 1851.0 / 8.0).abs() < 1e-6 * m,
        "first-moment relation"
    );
    let limits = json["balancing"]["peak_limits"].as_object().unwrap();
    for a in &v.indicators.as_ref().unwrap().actuators {
        assert!(
            a.cpt_peak <= limits[&a.name].as_f64().unwrap(),
            "{}",
            a.name
        );
    }
}

/// The lifted radius check measures what the final verification measures, the radius
/// `|μ|/m` against its bound: a counterweight at its smallest mass whose radius exceeds the
/// bound by 1e-6 (relative) is a violation of 1e-6 in both, not 1e-6·m/m_hi in the first
/// (which accepted such points and left the variant undecided at the verification).
#[test]
fn the_lifted_radius_check_is_relative_to_the_counterweights_own_mass() {
    let json = common::case_json("palletizer.json");
    let model = common::model(&json);
    let ctx = counterpoise_optimise::Context::new(&model, None).unwrap();
    let problem = variant_problem(&ctx, &["m4", "m7", "K62"]);
    let m7 = &problem.counterweights[1];
    assert_eq!(m7.label, "m7");
    let rhi = m7.bounds.radius[1];
    let m = m7.min_mass();
    let mut x = nalgebra::DVector::zeros(problem.particular.len());
    // m4 inside its bounds, m7 at its smallest mass and 1e-6 beyond its radius.
    let m4 = &problem.counterweights[0];
    x[m4.column] = 250.0;
    x[m4.column + 1] = 250.0 * 0.1;
    x[m7.column] = m;
    x[m7.column + 1] = m * rhi * (1.0 + 1e-6);
    // K62 in the middle of its stiffness range, anchors at the frames' origins.
    x[problem.springs[0].column] = 5000.0;
    let worst = problem
        .bound_violations(&x)
        .into_iter()
        .fold(f64::NEG_INFINITY, f64::max);
    assert!((worst - 1e-6).abs() < 1e-9, "largest violation {worst}");
}

/// The spring choice's first start (`springs_from_bounds`), by hand: m4 + K42 + K53's springs
/// get the geometric middle of [1000, 10000] N/m, √1e7 = 3162.28 N/m, and zero anchors in every
/// other lifted column, m4's columns unchanged; with a lower bound of 0 the range is taken as
/// [K_max·1e-3, K_max], so [0, 5000] N/m gives √(5·5000) = 158.11 N/m.
#[test]
fn the_spring_choice_starts_from_springs_set_by_the_bounds() {
    use counterpoise_optimise::springs::springs_from_bounds;
    let model = common::model(&common::case_json("palletizer.json"));
    let ctx = counterpoise_optimise::Context::new(&model, None).unwrap();
    let mut problem = variant_problem(&ctx, &["m4", "K42", "K53"]);
    let x = nalgebra::DVector::from_fn(problem.particular.len(), |i, _| 1.0 + i as f64);
    let start = springs_from_bounds(&problem, &x);
    let mut spring_columns = Vec::new();
    for s in &problem.springs {
        assert_eq!(s.bounds.stiffness, [1000.0, 10000.0]);
        assert!((start[s.column] - 3162.2776601683795).abs() < 1e-9);
        for c in s.column + 1..s.column + s.lifted_len() {
            assert_eq!(start[c], 0.0, "column {c}");
        }
        spring_columns.extend(s.column..s.column + s.lifted_len());
    }
    for c in (0..x.len()).filter(|c| !spring_columns.contains(c)) {
        assert_eq!(start[c], x[c], "column {c}");
    }
    problem.springs[0].bounds.stiffness = [0.0, 5000.0];
    let start = springs_from_bounds(&problem, &x);
    assert!((start[problem.springs[0].column] - 158.11388300841898).abs() < 1e-9);
}

/// The spring choice runs four times the starts of the critical-task pass for the same
/// counterweights and takes the pass's local solves instead of repeating them: the admissible
/// spring sets found are the same bits as from scratch, the seven starts after the first are
/// reused, and a record for other counterweights (or for the joint search) is not.
#[test]
fn spring_starts_of_the_pass_are_reused_by_the_choice_exactly() {
    use counterpoise_optimise::springs::realize_springs_reusing;
    let json = common::case_json("palletizer.json");
    let model = common::model(&json);
    let ctx = counterpoise_optimise::Context::new(&model, None).unwrap();
    let problem = variant_problem(&ctx, &["m4", "K42"]);
    let b = &ctx.basis.unbalanced;
    let x = problem.particular.clone();
    let (pass, _, record) = realize_springs_reusing(&problem, b, &x, 8, false, None);
    assert_eq!(record.reused(), 0);
    let (fresh, _, _) = realize_springs_reusing(&problem, b, &x, 32, false, None);
    let (reusing, _, again) = realize_springs_reusing(&problem, b, &x, 32, false, Some(&record));
    assert_eq!(again.reused(), 7);
    assert!(!fresh.is_empty() && fresh.len() >= pass.len());
    assert_eq!(format!("{fresh:?}"), format!("{reusing:?}"));
    // other counterweights: the record does not apply
    let mut moved = x.clone();
    let cw = problem.counterweights[0].column;
    moved[cw] *= 1.5;
    let (fresh, _, _) = realize_springs_reusing(&problem, b, &moved, 16, false, None);
    let (reusing, _, other) =
        realize_springs_reusing(&problem, b, &moved, 16, false, Some(&record));
    assert_eq!(other.reused(), 0);
    assert_eq!(format!("{fresh:?}"), format!("{reusing:?}"));
    let (_, _, joint) = realize_springs_reusing(&problem, b, &x, 16, true, Some(&record));
    assert_eq!(joint.reused(), 0);
    // nor one whose first start drew a stiffness the other did not (lifted K = 0: the
    // pseudo-random stream is one draw ahead from the second start on)
    let column = problem.springs[0].column;
    let (mut positive, mut zero) = (x.clone(), x.clone());
    positive[column] = 5000.0;
    zero[column] = 0.0;
    let (_, _, record_positive) = realize_springs_reusing(&problem, b, &positive, 8, false, None);
    let (_, _, record_zero) = realize_springs_reusing(&problem, b, &zero, 8, false, None);
    for (point, previous) in [(&positive, &record_zero), (&zero, &record_positive)] {
        let (fresh, _, _) = realize_springs_reusing(&problem, b, point, 16, false, None);
        let (reusing, _, other) =
            realize_springs_reusing(&problem, b, point, 16, false, Some(previous));
        assert_eq!(other.reused(), 0);
        assert_eq!(format!("{fresh:?}"), format!("{reusing:?}"));
    }
    // nor does the joint search's record for the springs alone
    let (fresh, _, _) = realize_springs_reusing(&problem, b, &x, 16, false, None);
    let (reusing, _, after_joint) =
        realize_springs_reusing(&problem, b, &x, 16, false, Some(&joint));
    assert_eq!(after_joint.reused(), 0);
    assert_eq!(format!("{fresh:?}"), format!("{reusing:?}"));
}

/// The free parameters of `{m3, m5}` against the case's bounds by hand (mass ≤ 500 kg, radius
/// ≤ 0.5 m): each free direction moves one lifted coordinate with the others held, so
/// - along `m5` (mass, first moment `μ5` held) the mass may range over
///   `[|μ5| / 0.5, 500]` (the radius `|μ5|/m` reaches 0.5 m at the lower end);
/// - along `m3·r3x` (mass `m3` and `μ3y` held) `|μ3| ≤ 0.5·m3` gives
///   `μ3x ∈ ±√((0.5·m3)² − μ3y²)`, and likewise along `m3·r3y` (also for `{m3, K43}`).
///
/// The values are the coordinates of the optimum, and every direction moves a counterweight.
/// For `{m3, K43}` the directions made of spring coordinates alone do not. (Each direction
/// is labelled from its own column: labels taken from the balance search's report, which may
/// list its directions in another order, once named `m5`'s interval `m3·r3y`.)
#[test]
fn free_parameter_intervals_match_the_bounds_by_hand() {
    let json = common::case_json("palletizer.json");
    let model = common::model(&json);
    let (_, results) = common::optimise(
        &model,
        &[&["m3", "m5"], &["m3", "K43"]],
        &OptimiseOptions::default(),
    );
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-6 * b.abs().max(1.0);
    let mut checked = 0;
    for v in &results {
        assert_eq!(v.status, Status::Feasible, "{:?}", v.elements);
        let cw = |label: &str| v.counterweights.iter().find(|c| c.label == label);
        let (m3, mu3) = {
            let c = cw("m3").unwrap();
            (c.mass, [c.mass * c.offset[0], c.mass * c.offset[1]])
        };
        for fp in &v.free_parameters {
            let names: Vec<&str> = fp.components.iter().map(|(n, _)| n.as_str()).collect();
            let spring_only = names.iter().all(|n| n.starts_with('K'));
            assert_eq!(fp.moves_counterweights, !spring_only, "{names:?}");
            let expected = match names.as_slice() {
                ["m5"] => {
                    let c = cw("m5").unwrap();
                    let mu = (c.mass * c.offset[0]).hypot(c.mass * c.offset[1]);
                    Some((c.mass, [mu / 0.5, 500.0]))
                }
                ["m3·r3x"] => {
                    let half = (0.25 * m3 * m3 - mu3[1] * mu3[1]).sqrt();
                    Some((mu3[0], [-half, half]))
                }
                ["m3·r3y"] => {
                    let half = (0.25 * m3 * m3 - mu3[0] * mu3[0]).sqrt();
                    Some((mu3[1], [-half, half]))
                }
                _ => None,
            };
            if let Some((value, [lo, hi])) = expected {
                assert!(close(fp.value, value), "{names:?}: {} vs {value}", fp.value);
                assert!(
                    close(fp.interval[0], lo),
                    "{names:?}: {:?} vs {lo}",
                    fp.interval
                );
                assert!(
                    close(fp.interval[1], hi),
                    "{names:?}: {:?} vs {hi}",
                    fp.interval
                );
                checked += 1;
            }
        }
    }
    // m5, m3·r3x, m3·r3y of {m3, m5}; m3·r3y of {m3, K43} (its m3·r3x direction also moves
    // spring coordinates)
    assert_eq!(checked, 4);
}

/// Two ways the pass recovers when the spring realization finds nothing at the motors' best
/// counterweights, each turning a variant that would otherwise be undecided into a verified
/// one:
/// - `{K72, K75}` with one spring start per pass: the first start finds no admissible springs,
///   the pass retries with four times as many starts and finds them;
/// - `{m4, K72}` (default starts): no admissible K72 exists for the motors' best m4 even from
///   32 starts, so the counterweight moves together with the spring (the joint search).
#[test]
fn the_spring_realization_recovers_by_more_starts_and_by_moving_the_counterweights() {
    let json = common::case_json("palletizer.json");
    let model = common::model(&json);
    let one_start = OptimiseOptions {
        spring_starts: 1,
        ..OptimiseOptions::default()
    };
    let (_, retried) = common::optimise(&model, &[&["K72", "K75"]], &one_start);
    let (_, joint) = common::optimise(&model, &[&["m4", "K72"]], &OptimiseOptions::default());
    for v in retried.iter().chain(&joint) {
        assert_eq!(
            v.status,
            Status::Feasible,
            "{:?}: {:?}",
            v.elements,
            v.reason
        );
        assert!(v.verification.as_ref().unwrap().passed);
        assert!(!v.springs.is_empty() && v.springs.iter().all(|s| s.stiffness > 0.0));
    }
    assert_eq!((retried.len(), joint.len()), (1, 1));
}

/// m3 + m5 + K42 at Dmax 3 (the case's bounds: `|a| ∈ [0.25, 1]` m): the relaxed K42 anchor
/// sits inside its lower norm bound while the counterweights' corner planes are loose too.
/// Splitting the counterweights first once left a 6.4 % gap after 3,200 boxes (best design
/// 12.43 N·m), and a search that follows bound rises at the solver's tolerance can still take
/// thousands of boxes here; the search must split the anchor and certify the optimum within
/// the default box limit, with a design no worse than that one.
#[test]
fn a_hybrid_whose_relaxed_anchor_is_inside_its_floor_closes_its_gap() {
    let model = palletizer_dmax3();
    let (_, results) =
        common::optimise(&model, &[&["m3", "m5", "K42"]], &OptimiseOptions::default());
    let v = &results[0];
    assert_eq!(v.status, Status::Feasible, "{:?}", v.reason);
    assert!(v.gap.unwrap() <= 1e-3, "gap {:?}", v.gap);
    assert!(v.objective.unwrap() < 12.43, "objective {:?}", v.objective);
    assert!(v.residual.unwrap() <= 1e-9);
}

/// m4 + K53 + K54 at Dmax 3: the boxes propose designs near their relaxed points, where the
/// two springs cannot be realized, and the realization that moves the counterweight too kept
/// a design at 12.144 N·m. Two other search paths (16 starts of that joint realization per
/// box; clarabel's iterative refinement loosened, which adds a critical task) each find a
/// verified design at 11.848 N·m, so one exists; the descent from each new best design must
/// reach at least that, above the certified bound and balanced.
#[test]
fn a_hybrid_whose_boxes_propose_poor_designs_is_descended_to_a_better_one() {
    let model = palletizer_dmax3();
    let (_, results) = common::optimise(
        &model,
        &[&["m4", "K53", "K54"]],
        &OptimiseOptions::default(),
    );
    let v = &results[0];
    assert_eq!(v.status, Status::Feasible, "{:?}", v.reason);
    let (value, bound) = (v.objective.unwrap(), v.lower_bound.unwrap());
    assert!(value <= 11.849, "objective {value}");
    assert!(bound <= value, "bound {bound} above the design {value}");
    assert!(v.residual.unwrap() <= 1e-9);
    assert!(v.verification.as_ref().unwrap().passed);
}

/// m4 + K42 + K65 at Dmax 3, the heaviest search of the study without the split history
/// (1,735 boxes): near the optimum the coupling error stays large on K65's anchor components,
/// whose splits raise no bound, while K42's `b_y` splits close most of their children (410
/// boxes with the history). Weighted by what its splits did, the search must close the same
/// gap in at most half the boxes, each design within the gap tolerance of the other search's
/// certified bound, both verified.
#[test]
fn the_split_history_halves_the_heaviest_search() {
    let model = palletizer_dmax3();
    let labels: &[&str] = &["m4", "K42", "K65"];
    let run = |split_history: bool| {
        let options = OptimiseOptions {
            split_history,
            ..OptimiseOptions::default()
        };
        let (_, mut results) = common::optimise(&model, &[labels], &options);
        let v = results.pop().unwrap();
        assert_eq!(v.status, Status::Feasible, "{:?}", v.reason);
        assert!(v.residual.unwrap() <= 1e-9);
        assert!(v.gap.unwrap() <= 1e-3, "gap {:?}", v.gap);
        let boxes: usize = v.iterations.iter().map(|i| i.boxes).sum();
        (v.objective.unwrap(), v.lower_bound.unwrap(), boxes)
    };
    let (with, without) = (run(true), run(false));
    assert!(
        with.0 - without.1 <= 1e-3 * with.0,
        "{with:?} against {without:?}"
    );
    assert!(
        without.0 - with.1 <= 1e-3 * without.0,
        "{without:?} against {with:?}"
    );
    assert!(
        2 * with.2 <= without.2,
        "{} boxes with the history against {} without",
        with.2,
        without.2
    );
}

/// The parallelogram's springs K54, K64, K65, K74, K75 and K76 (anchors that differ by a
/// translation) with m6 and K53 admit nearly the same best counterweights, but each search ends
/// at the design within the gap tolerance its own path met (on this build 11.61530 N·m for K75
/// and up to 11.62039 for K74). Sharing designs between siblings (`critical::siblings`) gives
/// each a sibling's better design where its springs admit one: never worse than its own, each
/// still verified and within the gap of its own bound, and each within the gap tolerance of the
/// family's best alone; at least half of them improve, and those name the sibling. (Which
/// sibling's design a variant's springs admit depends on where the siblings' paths ended: on
/// this build K64 takes K75's 11.61530, K65, K74 and K76 take K54's 11.61536.) The run holds
/// every m6 variant with springs, as the study does: dozens of them reach the m6 optimum
/// (11.6101 N·m) with springs the family cannot use, and their designs, lower than the family's
/// best and not below the family's bounds, come first by objective alone; the siblings that share
/// K53 must be tried before them.
#[test]
fn siblings_with_the_same_counterweight_share_the_best_design_their_springs_admit() {
    let model = palletizer_dmax3();
    let group: Vec<Vec<String>> = common::balanced_variants(&model)
        .into_iter()
        .map(|v| {
            v.elements
                .iter()
                .map(|e| e.label.clone())
                .collect::<Vec<_>>()
        })
        .filter(|labels| {
            let masses: Vec<&String> = labels.iter().filter(|l| l.starts_with('m')).collect();
            masses == ["m6"] && labels.len() > 1
        })
        .collect();
    assert!(group.len() > 40, "{group:?}");
    let group_refs: Vec<Vec<&str>> = group
        .iter()
        .map(|g| g.iter().map(String::as_str).collect())
        .collect();
    let sets: Vec<&[&str]> = group_refs.iter().map(Vec::as_slice).collect();
    let family: Vec<[&str; 3]> = ["K54", "K64", "K65", "K74", "K75", "K76"]
        .iter()
        .map(|&k| ["m6", "K53", k])
        .collect();
    let run = |siblings: bool| {
        let options = OptimiseOptions {
            siblings,
            ..OptimiseOptions::default()
        };
        let (_, results) = common::optimise(&model, &sets, &options);
        assert_eq!(results.len(), group.len());
        family
            .iter()
            .map(|f| {
                let v = results.iter().find(|v| v.elements == f).unwrap().clone();
                assert_eq!(v.status, Status::Feasible, "{:?}", v.reason);
                assert!(v.residual.unwrap() <= 1e-9);
                assert!(v.gap.unwrap() <= 1e-3, "gap {:?}", v.gap);
                v
            })
            .collect::<Vec<_>>()
    };
    let (alone, shared) = (run(false), run(true));
    let options_gap = OptimiseOptions::default().gap_tolerance;
    let best = alone
        .iter()
        .map(|v| v.objective.unwrap())
        .fold(f64::INFINITY, f64::min);
    let mut improved = 0;
    for (a, s) in alone.iter().zip(&shared) {
        let (own, with) = (a.objective.unwrap(), s.objective.unwrap());
        assert!(
            with <= own * (1.0 + 1e-9),
            "{:?}: {with} against {own}",
            s.elements
        );
        assert!(
            with - best <= options_gap * best,
            "{:?}: {with} against the best {best}",
            s.elements
        );
        if with < own * (1.0 - 1e-4) {
            improved += 1;
            // The pass that took a sibling's design names it.
            let from = s
                .iterations
                .iter()
                .find_map(|i| i.design_from.clone())
                .unwrap();
            assert!(from.starts_with("m6 + "), "{from}");
        }
    }
    assert!(improved >= 3, "{improved} improved: {alone:?}");
}

/// The palletizer case at Dmax 3.
fn palletizer_dmax3() -> counterpoise_model::Model {
    let mut json = common::case_json("palletizer.json");
    json["balancing"]["dmax"] = serde_json::json!(3);
    common::model(&json)
}

/// A Dmax 3 variant of the palletizer, optimised with the default options: its result, its
/// problem, the index of its spring `spring`, and the first box its search starts from.
fn dmax3_variant(
    labels: &[&str],
    spring: &str,
) -> (
    counterpoise_optimise::OptimisedVariant,
    counterpoise_optimise::problem::VariantProblem,
    usize,
    counterpoise_optimise::certify::node::NodeBox,
) {
    use counterpoise_optimise::certify::root_box;
    let model = palletizer_dmax3();
    let (ctx, mut results) = common::optimise(&model, &[labels], &OptimiseOptions::default());
    let problem = variant_problem(&ctx, labels);
    let index = problem
        .springs
        .iter()
        .position(|s| s.label == spring)
        .unwrap();
    let root = root_box(&problem, &OptimiseOptions::default().branch_options()).unwrap();
    assert_eq!(results.len(), 1);
    (results.pop().unwrap(), problem, index, root)
}

/// `m4 + K32 + K73` balances only with `K73·ay = 0` and `K32 + 20·K73·ax = 0` (the relations
/// the balance search prints), so every physical spring has K73's anchor on its body's x axis
/// at `ax = −K32/(20·K73)`: with both stiffnesses in `[1000, 10000]` N/m, `ax ∈ [−0.5, −0.005]`
/// m. The case's bounds alone give `[−1, 1]` m (the anchor's reach) for both components; the
/// search's first box must be narrowed to `ay = 0` (up to the relaxation's margin) and into
/// that interval (and still hold the design the run finds).
#[test]
fn the_first_box_holds_an_anchor_component_balance_fixes_at_its_value() {
    let (v, problem, k73, root) = dmax3_variant(&["m4", "K32", "K73"], "K73");
    assert_eq!(problem.springs[k73].axes_a, vec![0, 1]);
    let wide = counterpoise_optimise::certify::node::NodeBox::root(&problem).unwrap();
    assert_eq!(wide.anchor(&problem, k73, false, 0), [-1.0, 1.0]);
    assert_eq!(wide.anchor(&problem, k73, false, 1), [-1.0, 1.0]);
    // ay's range is 0 widened by the relaxation's relative margin (1e-6 of the reach).
    let [ylo, yhi] = root.anchor(&problem, k73, false, 1);
    assert!(
        ylo <= 0.0 && 0.0 <= yhi && yhi - ylo <= 4e-6,
        "ay ∈ [{ylo}, {yhi}]"
    );
    let [lo, hi] = root.anchor(&problem, k73, false, 0);
    // The hand interval, to the relaxation's margin (its ranges are widened by 1e-6 relative).
    assert!(
        (lo + 0.5).abs() < 1e-5 && (hi + 0.005).abs() < 1e-6,
        "ax ∈ [{lo}, {hi}]"
    );
    assert!(v.is_feasible(), "{:?}", v.reason);
    let spring = v.springs.iter().find(|s| s.label == "K73").unwrap();
    let ax = spring.anchor_a[0];
    assert!(
        lo <= ax && ax <= hi,
        "the design's ax = {ax} outside [{lo}, {hi}]"
    );
    let k32 = v.springs.iter().find(|s| s.label == "K32").unwrap();
    assert!((k32.stiffness + 20.0 * spring.stiffness * ax).abs() < 1e-6 * k32.stiffness);
    // Every anchor component of the design, a and b of both springs, lies in the first box.
    for (k, slot) in problem.springs.iter().enumerate() {
        let design = v.springs.iter().find(|s| s.label == slot.label).unwrap();
        for (is_b, axes, anchor) in [
            (false, &slot.axes_a, design.anchor_a),
            (true, &slot.axes_b, design.anchor_b),
        ] {
            for (i, &axis) in axes.iter().enumerate() {
                let [lo, hi] = root.anchor(&problem, k, is_b, i);
                let x = anchor[axis];
                assert!(
                    lo <= x && x <= hi,
                    "{} anchor {} axis {axis}: {x} outside [{lo}, {hi}]",
                    slot.label,
                    if is_b { "b" } else { "a" }
                );
            }
        }
    }
}

/// `m5 + K63 + K65` balances only with `K63·(ax·bx + ay·by) = 0` and
/// `K63·(ax·by − ay·bx) = 5382747/8000` N·m (the relations the balance search prints): K63
/// must carry a fixed moment, so its Lagrange vector `(K a·b, K (a×b)_z)` is the point
/// `(0, 672.843…)`, and with `|a| ≥ 0.25` m (the case's lower anchor bound) `K·|b| ≤
/// 672.843/0.25 = 2691.37` N — which caps the counterweight's moment through
/// `m5·r5x = −9233/32 + (25/981)·K63·by`. The relaxation without that cap stopped at a 2.3 %
/// gap after 800 boxes; with it the search closes the gap.
#[test]
fn a_spring_that_carries_a_fixed_moment_bounds_its_anchor_through_the_lower_norm_bound() {
    use counterpoise_optimise::relaxation::{RelaxationBase, lagrange_terms};
    let (v, problem, k63, root) = dmax3_variant(&["m5", "K63", "K65"], "K63");
    assert_eq!(lagrange_terms(&problem.springs[k63]).len(), 2);
    let ranges = RelaxationBase::new(&problem, &[], counterpoise_optimise::Objective::Minimax)
        .lagrange_ranges(&problem, Some(&root), 200);
    let moment = 5382747.0 / 8000.0;
    let [dot, cross] = [ranges[k63][0], ranges[k63][1]];
    // Each range is the point widened by the relaxation's margin, about 1e-6 of the natural
    // size K_max·|a|_max·|b|_max = 5000 N·m on each side.
    assert!(
        dot[0] <= 0.0 && 0.0 <= dot[1] && dot[1] - dot[0] < 2e-2,
        "K a·b ∈ {dot:?}"
    );
    assert!(
        cross[0] <= moment && moment <= cross[1] && cross[1] - cross[0] < 2e-2,
        "K (a×b)_z ∈ {cross:?}"
    );
    assert!(v.is_feasible(), "{:?}", v.reason);
    let (objective, lower) = (v.objective.unwrap(), v.lower_bound.unwrap());
    let gap = (objective - lower) / objective;
    assert!(gap <= 1e-3, "gap {gap:e}");
    let s = v.springs.iter().find(|s| s.label == "K63").unwrap();
    let (a, b) = (s.anchor_a, s.anchor_b);
    let cross_z = s.stiffness * (a[0] * b[1] - a[1] * b[0]);
    assert!(
        (cross_z - moment).abs() < 1e-6 * moment,
        "K (a×b)_z = {cross_z}"
    );
    let b_norm = (b[0] * b[0] + b[1] * b[1]).sqrt();
    assert!(s.stiffness * b_norm <= moment / 0.25 * (1.0 + 1e-6));
}

/// `m5 + K52 + K53` balances only with `K53 + 4·K53·ax = 0`, `K53·ay = 0`, `K53·bx = 0` and
/// `K53·by = 1794249/800` N (the relations the balance search prints): K53's anchors are
/// `a = (−0.25, 0)` m and `b = (0, 2242.81125/K53)`, so `|b| ≤ 0.5` m needs
/// `K53 ≥ 1794249/400 = 4485.6225` N/m, and the Lagrange vector is the point
/// `(0, −0.25·2242.81125)`. The optimum sits on that cap (`by = 0.5` m). With the Lagrange
/// cones clarabel stalls on many of this variant's boxes near the cap (158 of 458 undecided
/// after all four of its runs, each box then split with its parent's bound: 339 boxes to close
/// the gap); a box the cones leave undecided is now solved without them, and the gap closes
/// within 250 boxes.
#[test]
fn a_box_the_lagrange_cones_leave_undecided_is_bounded_without_them() {
    let model = palletizer_dmax3();
    let options = OptimiseOptions {
        max_nodes: 250,
        ..OptimiseOptions::default()
    };
    let (_, results) = common::optimise(&model, &[&["m5", "K52", "K53"]], &options);
    let v = &results[0];
    assert_eq!(v.status, Status::Feasible, "{:?}", v.reason);
    let (objective, lower) = (v.objective.unwrap(), v.lower_bound.unwrap());
    let gap = (objective - lower) / objective;
    assert!((0.0..=1e-3).contains(&gap), "gap {gap:e}");
    assert!(v.verification.as_ref().unwrap().passed);
    let s = v.springs.iter().find(|s| s.label == "K53").unwrap();
    let (a, b, k) = (s.anchor_a, s.anchor_b, s.stiffness);
    assert!((a[0] + 0.25).abs() < 1e-9 && a[1].abs() < 1e-9, "a = {a:?}");
    assert!(b[0].abs() < 1e-9, "b = {b:?}");
    assert!(
        (k * b[1] - 1794249.0 / 800.0).abs() < 1e-6 * k,
        "K·by = {}",
        k * b[1]
    );
    assert!(k >= 1794249.0 / 400.0 * (1.0 - 1e-9), "K53 = {k}");
    assert!(b[1] <= 0.5 * (1.0 + 1e-9), "by = {}", b[1]);
}

/// The Dmax 3 variant `labels` optimised under each start seed of `seeds`, each checked
/// feasible, within the gap tolerance and verified.
fn feasible_under_seeds(
    labels: &[&str],
    seeds: &[u64],
) -> Vec<counterpoise_optimise::OptimisedVariant> {
    let model = palletizer_dmax3();
    seeds
        .iter()
        .map(|&seed| {
            let options = OptimiseOptions {
                start_seed: seed,
                ..OptimiseOptions::default()
            };
            let (_, mut results) = common::optimise(&model, &[labels], &options);
            let v = results.pop().unwrap();
            assert_eq!(v.status, Status::Feasible, "seed {seed}: {:?}", v.reason);
            assert!(v.gap.unwrap() <= 1e-3, "seed {seed}: gap {:?}", v.gap);
            assert!(v.verification.as_ref().unwrap().passed, "seed {seed}");
            v
        })
        .collect()
}

/// `m5 + K32 + K73` at Dmax 3 has two valleys within the gap tolerance of each other: a
/// 210.9 kg m5 at 11.680172 N·m, and a 202.0 kg m5 at 11.681715 N·m. The default seed used to
/// end near the first (11.680181 N·m) and `--seed 12345` in the second: their paths met
/// different boxes, and the second pass began from the fast path's seeded design. With the
/// untried relaxed points tried before a search returns, and each pass starting from the last
/// one's design, both seeds must end in the lower valley at the same objective, within the gap
/// of the certified bound.
#[test]
fn two_seeds_end_a_variant_with_two_valleys_in_the_same_one() {
    let designs = feasible_under_seeds(
        &["m5", "K32", "K73"],
        &[counterpoise_optimise::springs::DEFAULT_SEED, 12345],
    );
    let (a, b) = (&designs[0], &designs[1]);
    let (va, vb) = (a.objective.unwrap(), b.objective.unwrap());
    // The lower valley (the upper one is 11.6817).
    assert!(va < 11.6802 && vb < 11.6802, "{va} and {vb}");
    assert!((va - vb).abs() <= 1e-9 * va, "{va} and {vb}");
    // The valley's floor is flat to 1e-10 over a few grams of m5 (210.9203 and 210.9208 kg
    // at the default descent tolerance); the other valley's m5 is 9 kg lighter.
    let (ma, mb) = (a.counterweights[0].mass, b.counterweights[0].mass);
    assert!((ma - mb).abs() <= 1e-5 * ma, "m5 {ma} and {mb} kg");
}

/// `K31 + K61 + K63` at Dmax 3 (springs alone): no start of the spring choice realizes its
/// springs within the bounds, so its one option used to be the candidate's own springs, which
/// the fast path's seeded starts had realized (ΔR 14.22 % under the default seed, 15.44 % under
/// `--seed 12345`). The option is now the first design of a search from the first box without
/// an incumbent: the same springs, hence the same ΔR, under every seed.
#[test]
fn a_springs_only_variant_gets_the_same_springs_under_every_seed() {
    let runs = feasible_under_seeds(
        &["K31", "K61", "K63"],
        &[counterpoise_optimise::springs::DEFAULT_SEED, 12345, 7],
    );
    for v in &runs[1..] {
        for (s, t) in v.springs.iter().zip(&runs[0].springs) {
            assert_eq!(s.stiffness.to_bits(), t.stiffness.to_bits(), "{}", s.label);
            assert_eq!(s.anchor_a.map(f64::to_bits), t.anchor_a.map(f64::to_bits));
            assert_eq!(s.anchor_b.map(f64::to_bits), t.anchor_b.map(f64::to_bits));
        }
        assert_eq!(
            v.delta_r_estimate.map(f64::to_bits),
            runs[0].delta_r_estimate.map(f64::to_bits)
        );
    }
}
