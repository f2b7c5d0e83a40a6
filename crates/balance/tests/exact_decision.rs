//! The exact balance decision on the palletizer: pinned verdict counts that match an independent
//! exact computation, certificates for the cases floating point got wrong, and the invariants an
//! exact decision must keep (monotone consistency, agreement with confident floating point,
//! verdicts unmoved by a one-ulp change of an input).

mod common;

use std::collections::HashMap;

use common::{find, labels, model_of, palletizer_json, random_configuration, run};

use counterpoise_balance::exact::exact_text;
use counterpoise_balance::linear::{LiftedBasis, numeric_solve};
use counterpoise_balance::{
    Catalogue, Decision, SearchReport, Status, VariantResult, Witness, catalogue_options,
    mechanism_energy, realization_hints,
};
use counterpoise_model::Kinematics;
use counterpoise_model::sampling::SplitMix64;
use counterpoise_symbolic::Rational;
use nalgebra::{DVector, Vector3};

fn counts(report: &SearchReport) -> [usize; 5] {
    Status::SEARCH_VERDICTS.map(|s| report.count(s))
}

fn realizable(v: &VariantResult) -> bool {
    matches!(v.status, Status::Balanced | Status::Degenerate)
}

/// An independent exact computation (rational arithmetic, positivity of masses and stiffnesses,
/// idle springs counted as realizable) finds 103 realizable sets at Dmax 2 and 1325 at Dmax 3.
#[test]
fn palletizer_verdicts_match_the_independent_exact_counts() {
    let model = model_of(&palletizer_json());
    for (dmax, expected_realizable, pinned) in [
        (2, 103, [97, 6, 146, 157, 0]),
        (3, 1325, [1169, 156, 1642, 715, 0]),
    ] {
        let report = run(&model, dmax);
        assert!(
            report
                .variants
                .iter()
                .all(|v| v.decision == Decision::Exact)
        );
        let realizable_count = report.variants.iter().filter(|v| realizable(v)).count();
        assert_eq!(realizable_count, expected_realizable, "Dmax {dmax}");
        // Balanced, degenerate, unrealizable, infeasible, undecided.
        assert_eq!(counts(&report), pinned, "Dmax {dmax}");
        // Every realizable verdict carries a verified witness above the floor; every other
        // verdict carries its reason.
        let hints = realization_hints(&model);
        for v in &report.variants {
            if realizable(v) {
                let w = v.witness.as_ref().expect("witness");
                assert!(v.verification.as_ref().is_some_and(|c| c.passed));
                assert!(
                    w.counterweights
                        .iter()
                        .all(|c| c.mass >= hints.mass_floor())
                );
                assert!(
                    w.springs
                        .iter()
                        .all(|s| s.stiffness >= hints.stiffness_floor())
                );
            } else {
                assert!(v.reason.is_some(), "{:?}", labels(v));
            }
        }
    }
}

/// Sets floating point called infeasible although a subset balances, or balanced with
/// nanonewton springs.
#[test]
fn the_sets_floating_point_got_wrong_are_decided_with_proofs() {
    let report = run(&model_of(&palletizer_json()), 3);
    for set in [
        ["K32", "K54", "K63"],
        ["K63", "K65", "K72"],
        ["K64", "K72", "K73"],
    ] {
        let v = find(&report, &set);
        assert!(realizable(v), "{set:?}: {:?} {:?}", v.status, v.reason);
    }
    // {K32, K63} ⊂ {K32, K54, K63} balances, so the superset is at least consistent.
    assert!(realizable(find(&report, &["K32", "K63"])));
    // K21 + K51 = 0 on every solution: no pair of positive stiffnesses.
    let v = find(&report, &["K21", "K51", "m4"]);
    assert_eq!(v.status, Status::Unrealizable);
    let reason = v.reason.as_deref().unwrap();
    assert!(reason.contains("K21 + K51 = 0 ≤ 0"), "{reason}");
}

/// Lifted consistency is monotone: extra elements may be set to zero, so every superset of a
/// consistent set is consistent and its rank is never lower.
#[test]
fn lifted_consistency_is_monotone_over_every_dmax3_variant() {
    let model = model_of(&palletizer_json());
    let energy = mechanism_energy(&model);
    let catalogue = Catalogue::build(&energy, &catalogue_options(&model));
    let basis = LiftedBasis::build(&energy, &catalogue);
    let exact = basis.exact.as_ref().expect("exact case");
    let sets: Vec<Vec<usize>> =
        counterpoise_balance::enumerate::variants(catalogue.len(), 3).collect();
    let facts: HashMap<Vec<usize>, (bool, usize)> = sets
        .iter()
        .map(|s| {
            let solution = exact.solve(s);
            (s.clone(), (solution.consistent(), solution.rank()))
        })
        .collect();
    let mut checked = 0;
    for (set, &(consistent, rank)) in &facts {
        if set.len() == 3 {
            continue;
        }
        for e in (0..catalogue.len()).filter(|e| !set.contains(e)) {
            let mut superset = set.clone();
            superset.push(e);
            superset.sort_unstable();
            let (super_consistent, super_rank) = facts[&superset];
            assert!(super_rank >= rank, "{set:?} + {e}");
            assert!(!consistent || super_consistent, "{set:?} + {e}");
            checked += 1;
        }
    }
    // Every set of one or two elements has 27 or 26 one-element extensions: 28·27 + 378·26.
    assert_eq!(checked, 28 * 27 + 378 * 26);
}

/// Where the floating-point path is confident (no ambiguous singular value or residual), it
/// agrees with the exact one on consistency and rank.
#[test]
fn floating_point_agrees_with_exact_arithmetic_where_it_is_confident() {
    let model = model_of(&palletizer_json());
    let energy = mechanism_energy(&model);
    let catalogue = Catalogue::build(&energy, &catalogue_options(&model));
    let basis = LiftedBasis::build(&energy, &catalogue);
    let exact = basis.exact.as_ref().expect("exact case");
    let mut confident = 0;
    for set in counterpoise_balance::enumerate::variants(catalogue.len(), 3) {
        let numeric = numeric_solve(&basis, &set);
        if numeric.ambiguity.is_some() {
            continue;
        }
        confident += 1;
        let solution = exact.solve(&set);
        assert_eq!(numeric.consistent, solution.consistent(), "{set:?}");
        assert_eq!(numeric.rank, solution.rank(), "{set:?}");
    }
    // Most variants are clear-cut in floating point too.
    assert!(confident > 3000, "{confident} of 3682 confident");
}

/// A one-ulp change of a decimal input is a different rational, not a flipped threshold: every
/// verdict stays.
#[test]
fn one_ulp_changes_of_inputs_keep_every_verdict() {
    let base = palletizer_json();
    let reference: Vec<(Vec<String>, Status)> = run(&model_of(&base), 2)
        .variants
        .iter()
        .map(|v| (labels(v), v.status))
        .collect();
    // One ulp away from zero for each non-zero decimal: lengths, masses, a centre of mass,
    // gravity.
    let next_up = |x: f64| f64::from_bits(x.to_bits() + 1);
    let inputs = [
        "/parameters/d1",
        "/parameters/d2",
        "/parameters/d3",
        "/parameters/d4",
        "/bodies/0/mass",
        "/bodies/3/mass",
        "/bodies/6/mass",
        "/bodies/3/com/0",
        "/gravity/1",
    ];
    for pointer in inputs {
        let mut case = base.clone();
        let value = case.pointer_mut(pointer).expect("the input exists");
        *value = serde_json::json!(next_up(value.as_f64().unwrap()));
        let verdicts: Vec<(Vec<String>, Status)> = run(&model_of(&case), 2)
            .variants
            .iter()
            .map(|v| (labels(v), v.status))
            .collect();
        assert_eq!(verdicts, reference, "{pointer}");
    }
}

/// An idle element really contributes nothing: its own energy, computed here from the model's
/// numeric kinematics (not the balance crate), is constant over random configurations.
#[test]
fn idle_elements_contribute_no_energy() {
    let model = model_of(&palletizer_json());
    let report = run(&model, 2);
    let kinematics = Kinematics::new(&model);
    let g = model.gravity;
    let degenerate: Vec<&VariantResult> = report
        .variants
        .iter()
        .filter(|v| v.status == Status::Degenerate)
        .collect();
    assert_eq!(degenerate.len(), 6);
    let mut rng = SplitMix64::new(7);
    for v in degenerate {
        assert!(!v.idle.is_empty());
        let w: &Witness = v.witness.as_ref().unwrap();
        for label in &v.idle {
            let energy_at = |q: &DVector<f64>| -> f64 {
                let poses = kinematics.body_poses(q);
                let body = |name: &str| model.body_index(name).unwrap();
                if let Some(c) = w.counterweights.iter().find(|c| &c.label == label) {
                    let p = &poses[body(&c.body)];
                    let at = p.position + p.rotation * Vector3::from(c.offset);
                    return -c.mass * g.dot(&at);
                }
                let s = w.springs.iter().find(|s| &s.label == label).unwrap();
                let p = &poses[body(&s.body)];
                let a = p.position + p.rotation * Vector3::from(s.anchor_a);
                let b = if s.to_base() {
                    Vector3::from(s.anchor_b)
                } else {
                    let o = &poses[body(&s.other)];
                    o.position + o.rotation * Vector3::from(s.anchor_b)
                };
                0.5 * s.stiffness * (a - b).norm_squared()
            };
            let values: Vec<f64> = (0..100)
                .map(|_| {
                    let q = DVector::from_iterator(
                        model.dof(),
                        model
                            .coordinates
                            .iter()
                            .map(|c| rng.uniform(c.range[0], c.range[1])),
                    );
                    energy_at(&q)
                })
                .collect();
            let (lo, hi) = values
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &x| {
                    (l.min(x), h.max(x))
                });
            assert!(
                hi - lo < 1e-6 * (1.0 + hi.abs()),
                "{label} in {:?}",
                labels(v)
            );
        }
    }
}

/// A spring forced to zero stiffness is unrealizable (not an idle part), with the reason.
#[test]
fn forced_zero_stiffness_is_unrealizable() {
    let report = run(&model_of(&palletizer_json()), 1);
    let v = find(&report, &["K41"]);
    assert_eq!(v.status, Status::Unrealizable);
    assert_eq!(
        v.reason.as_deref(),
        Some("K41: balance forces its stiffness to zero")
    );
}

/// Relations are printed exactly: m4 alone needs m = 672.843375 / (9.81 · 0.3) kg (palletizer.md:
/// the sin θ2 coefficient of V_UB over g·δ1), which is 1829/8.
#[test]
fn relations_are_exact_fractions() {
    let report = run(&model_of(&palletizer_json()), 1);
    let v = find(&report, &["m4"]);
    let expected: f64 = 672.843375 / (9.81 * 0.3);
    assert!((expected - 1829.0 / 8.0).abs() < 1e-9);
    assert_eq!(v.relations[0], "m4 = 1829/8 (228.625) kg");
}

/// A constant rotation of the column about the vertical axis leaves the potential unchanged: by
/// an irrational angle the case takes the numeric path, by atan2(4, 3) it stays exact, and both
/// reach the exact verdicts (the numeric path at most says undecided, never the opposite).
#[test]
fn rotated_column_takes_the_right_path_and_keeps_the_verdicts() {
    let base = palletizer_json();
    let reference = run(&model_of(&base), 2);
    for (angle, decision) in [
        ("th1 + 0.3", Decision::Numeric),
        ("th1 + atan2(4, 3)", Decision::Exact),
    ] {
        let mut case = base.clone();
        case["bodies"][0]["pose"][0]["rot_y"] = serde_json::json!(angle);
        let model = model_of(&case);
        let energy = mechanism_energy(&model);
        assert_eq!(energy.exact.is_ok(), decision == Decision::Exact, "{angle}");
        let report = run(&model, 2);
        let mut undecided = 0;
        for (v, r) in report.variants.iter().zip(&reference.variants) {
            assert_eq!(v.decision, decision);
            if v.status == Status::Undecided {
                undecided += 1;
                continue;
            }
            assert_eq!(
                v.status,
                r.status,
                "{angle}: {:?} {:?}",
                labels(v),
                v.reason
            );
        }
        if decision == Decision::Exact {
            assert_eq!(undecided, 0);
        }
    }
    let mut case = base.clone();
    case["bodies"][0]["pose"][0]["rot_y"] = serde_json::json!("th1 + 0.3");
    let reason = mechanism_energy(&model_of(&case)).exact.unwrap_err();
    assert!(reason.starts_with("bodies[0].pose[0].rot_y"), "{reason}");
}

/// A counterweight on the column cannot change the energy: the column turns about the vertical
/// axis, so every point on it keeps its height (checked here with the model's kinematics). It is
/// flagged redundant, and the variant balances as m4 alone does.
#[test]
fn a_counterweight_on_the_column_is_redundant() {
    let model = model_of(&palletizer_json());
    let kinematics = Kinematics::new(&model);
    let column = model.body_index("column").unwrap();
    let mut rng = SplitMix64::new(11);
    let point = Vector3::new(0.37, -0.21, 0.0);
    let heights: Vec<f64> = (0..50)
        .map(|_| {
            let pose = kinematics.body_pose(column, &random_configuration(&model, &mut rng));
            (pose.position + pose.rotation * point).y
        })
        .collect();
    assert!(heights.iter().all(|h| (h - heights[0]).abs() < 1e-12));
    let report = run(&model, 2);
    let v = find(&report, &["m1", "m4"]);
    assert_eq!(v.status, Status::Balanced);
    assert_eq!(v.redundant, vec!["m1".to_string()]);
    assert_eq!(find(&report, &["m4"]).relations[0], v.relations[0]);
    assert_eq!(find(&report, &["m1"]).status, Status::Infeasible);
}

/// A printed rational: `20`, or `5/9 (0.555556)` with its decimal beside it.
fn parse_exact(text: &str) -> Rational {
    let exact = text.split(" (").next().unwrap();
    exact
        .parse()
        .unwrap_or_else(|_| panic!("not a rational: {text}"))
}

/// Every Farkas certificate the search prints checks by hand: with the multipliers read back
/// from the text, `Σ λ_i h_i(z)` over the heads (masses and stiffnesses as affine functions of
/// the free parameters) has no `z` term left and equals the printed value, which is ≤ 0. Dmax 3
/// has integer multipliers other than 1 (`20·K71`) as well as fractions and plain labels.
#[test]
fn printed_farkas_certificates_check_by_hand() {
    let model = model_of(&palletizer_json());
    let energy = mechanism_energy(&model);
    let catalogue = Catalogue::build(&energy, &catalogue_options(&model));
    let basis = LiftedBasis::build(&energy, &catalogue);
    let exact = basis.exact.as_ref().expect("exact case");
    let report = run(&model, 3);
    let (mut checked, mut integer_multipliers) = (0, 0);
    for v in &report.variants {
        let Some(claim) = v
            .reason
            .as_deref()
            .and_then(|r| r.strip_prefix("no positive masses and stiffnesses balance it: "))
        else {
            continue;
        };
        let (sum, value) = claim
            .strip_prefix("every solution has ")
            .and_then(|c| c.strip_suffix(" ≤ 0"))
            .and_then(|c| c.rsplit_once(" = "))
            .unwrap_or_else(|| panic!("{claim}"));
        let value = parse_exact(value);
        let set: Vec<usize> = v.elements.iter().map(|e| e.entry).collect();
        let heads = exact.solve(&set).heads();
        let zero = Rational::from_integer(0.into());
        let mut constant = zero.clone();
        let mut coefficients = vec![zero.clone(); heads[0].coefficients.len()];
        for term in sum.split(" + ") {
            let (lambda, label) = match term.split_once('·') {
                Some((lambda, label)) => (parse_exact(lambda), label),
                None => (Rational::from_integer(1.into()), term),
            };
            assert!(lambda > zero, "{claim}");
            if lambda.is_integer() && lambda != Rational::from_integer(1.into()) {
                integer_multipliers += 1;
            }
            let k = v.elements.iter().position(|e| e.label == label).unwrap();
            constant += &lambda * &heads[k].constant;
            for (c, h) in coefficients.iter_mut().zip(&heads[k].coefficients) {
                *c += &lambda * h;
            }
        }
        assert!(coefficients.iter().all(|c| *c == zero), "{claim}");
        assert_eq!(constant, value, "{claim}");
        assert!(value <= zero, "{claim}");
        checked += 1;
    }
    assert!(
        checked > 0 && integer_multipliers > 0,
        "{checked} {integer_multipliers}"
    );
}

/// When balance fixes a spring's anchor `a = a₀` (K42 alone: a = (1/4, 0), see tests/palletizer.rs;
/// K53 mirrors it with (−1/4, 0)), a physical spring has `W = a₀ βᵀ`. Those four equations are
/// written here by variable name (`K42·ax·by − a₀x·K42·by = 0`, …) and solved with the variant's
/// balance equations: the mass of m7 they force is the one the search's reason quotes, and it is
/// negative, so the pair is unrealizable.
#[test]
fn a_fixed_anchor_restricts_the_spring_as_written_by_hand() {
    let model = model_of(&palletizer_json());
    let energy = mechanism_energy(&model);
    let catalogue = Catalogue::build(&energy, &catalogue_options(&model));
    let basis = LiftedBasis::build(&energy, &catalogue);
    let exact = basis.exact.as_ref().expect("exact case");
    let report = run(&model, 2);
    let q = |n: i64, d: i64| Rational::new(n.into(), d.into());
    for (spring, a0) in [("K42", [q(1, 4), q(0, 1)]), ("K53", [q(-1, 4), q(0, 1)])] {
        let v = find(&report, &[spring, "m7"]);
        let set: Vec<usize> = v.elements.iter().map(|e| e.entry).collect();
        let names: Vec<&str> = set
            .iter()
            .flat_map(|&e| catalogue.entries[e].variables.iter().map(String::as_str))
            .collect();
        let column = |name: String| names.iter().position(|n| *n == name).unwrap();
        let mut rows = Vec::new();
        for (i, ai) in ["x", "y"].iter().zip(&a0) {
            for j in ["x", "y"] {
                let mut row = vec![q(0, 1); names.len()];
                row[column(format!("{spring}·a{i}·b{j}"))] = q(1, 1);
                row[column(format!("{spring}·b{j}"))] = -ai.clone();
                rows.push(row);
            }
        }
        let restricted = exact.solve_with(&set, &rows);
        assert!(restricted.consistent(), "{spring}");
        let mass = column("m7".to_string());
        assert!(restricted.is_fixed(mass), "{spring}");
        let m7 = &restricted.particular[mass];
        assert!(*m7 < q(0, 1), "{spring}: m7 = {m7}");
        assert_eq!(v.status, Status::Unrealizable);
        let anchor: Vec<String> = a0.iter().map(exact_text).collect();
        assert_eq!(
            v.reason.as_deref(),
            Some(
                format!(
                    "with {spring}'s anchor a = ({}) fixed by balance, m7: balance forces its \
                     mass to {} kg",
                    anchor.join(", "),
                    exact_text(m7)
                )
                .as_str()
            ),
        );
    }
}
