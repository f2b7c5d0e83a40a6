//! The `evaluate` logic: failures are reported, not fatal; results do not depend on the
//! thread count; the report has the documented fields.

mod common;

use common::{case_from_text, coarse_palletizer};
use counterpoise_dynamics::{
    Counterweight, EvaluateOptions, ParameterSet, Spring, Variant, evaluate, evaluate_grid,
    evaluate_unbalanced_grid, task_series, task_series_with,
};
use counterpoise_model::{GridAxis, Model};

#[test]
fn unreachable_tasks_are_excluded_not_fatal() {
    let mut model = coarse_palletizer();
    // ρ2 ∈ {0, 0.3, 0.6} m, ρ3 ∈ {1.03, 1.2, 1.37} m. Points are numbered with M1 slowest, so
    // point i has ρ2 = 0.3·(i / 3 % 3) and ρ3 index i % 3. Which points the arm reaches within
    // its coordinate ranges is decided by the two-link inverse kinematics below, by hand:
    // 0.6 is beyond reach for every ρ3, and (0.3, 1.37) needs θ3 = −0.017 < 0. That leaves 15
    // of 27 points; every task touching one of the other 12 fails and every other task runs:
    // 351 − C(15, 2) = 351 − 105 = 246 excluded tasks.
    model.tasks.as_mut().unwrap().grid[1] = GridAxis {
        from: 0.0,
        to: 0.6,
        n: 3,
    };
    let unreachable = |point: usize| {
        let rho2 = 0.3 * (point / 3 % 3) as f64;
        let rho3 = [1.03, 1.2, 1.37][point % 3];
        !pantograph_reaches(rho2, rho3)
    };
    assert_eq!((0..27).filter(|&p| unreachable(p)).count(), 12);
    let report = evaluate(&model, &EvaluateOptions::default()).unwrap();
    assert_eq!(report.tasks, 351);
    assert_eq!(
        report.excluded.count, 246,
        "{:?}",
        report.excluded.by_reason
    );
    assert_eq!(report.evaluated, 105);
    assert_eq!(report.excluded.by_reason.values().sum::<usize>(), 246);
    assert!(report.indicators.qtr.is_finite() && report.indicators.qit.is_finite());
    for j in &report.indicators.joints {
        assert!(j.force.is_finite() && j.moment.is_finite());
    }
    assert_eq!(
        report.excluded.examples.len(),
        counterpoise_dynamics::evaluate::MAX_FAILURE_EXAMPLES
    );
    for f in &report.excluded.examples {
        let (i, j) = report_pair(&model, f.task);
        assert!(
            unreachable(i) || unreachable(j),
            "task {i}->{j} excluded: {:?}",
            f.reason
        );
    }
    // Task by task: excluded exactly when an end point is unreachable.
    let grid = evaluate_grid(
        &model,
        &ParameterSet::unbalanced(&model),
        &EvaluateOptions {
            reactions: false,
            ..EvaluateOptions::default()
        },
    )
    .unwrap();
    for w in 0..grid.tasks.len() {
        let (i, j) = grid.tasks.pair(w);
        assert_eq!(
            grid.stats(w, 0).is_none(),
            unreachable(i) || unreachable(j),
            "task {i}->{j}"
        );
    }
    // The critical tasks are among those that ran.
    for a in &report.indicators.actuators {
        assert!(!unreachable(a.crt[0]) && !unreachable(a.crt[1]));
    }
    let json = serde_json::to_value(&report).unwrap();
    assert!(
        !json["excluded"]["by_reason"]
            .as_object()
            .unwrap()
            .is_empty()
    );
}

/// Whether the palletizer's arm reaches the actuator values `(ρ2, ρ3)` with θ2 ∈ [−0.1, 1.75]
/// and θ3 ∈ [0, 2.1] (the case's ranges). With `x = ρ2 − δ3 = δ1 cos θ2 + δ4 cos θ3` and
/// `y = ρ3 − δ2 = δ1 sin θ2 − δ4 sin θ3` it is a two-link arm in (θ2, −θ3): the law of cosines
/// gives θ2 + θ3 = ±acos((x² + y² − δ1² − δ4²)/(2 δ1 δ4)), then θ2 follows from atan2.
fn pantograph_reaches(rho2: f64, rho3: f64) -> bool {
    let (d1, d2, d3, d4) = (0.3, 1.2, -0.2, 0.25);
    let (x, y) = (rho2 - d3, rho3 - d2);
    let c = (x * x + y * y - d1 * d1 - d4 * d4) / (2.0 * d1 * d4);
    if c.abs() > 1.0 {
        return false;
    }
    [1.0, -1.0].into_iter().any(|branch: f64| {
        let sum = branch * c.acos(); // θ2 − (−θ3)
        let th2 = y.atan2(x) - (-d4 * sum.sin()).atan2(d1 + d4 * sum.cos());
        let th3 = sum - th2;
        (-0.1..=1.75).contains(&th2) && (0.0..=2.1).contains(&th3)
    })
}

fn report_pair(model: &Model, task: usize) -> (usize, usize) {
    let set = counterpoise_dynamics::TaskSet::new(model.tasks.as_ref().unwrap(), None).unwrap();
    set.pair(task)
}

#[test]
fn singular_actuator_jacobian_is_reported() {
    // u = x³: G = 3x² vanishes at x = 0 (u = 0), a reachable point.
    let model = case_from_text(
        r#"{
        "name": "cubic", "gravity": [0, -9.81, 0],
        "coordinates": [ { "name": "x", "kind": "length", "range": [-2, 2] } ],
        "bodies": [ { "name": "slider", "parent": "base", "pose": [ { "translate": ["x^3", 0, 0] } ],
                      "mass": 1, "com": [0, 0, 0], "inertia": [0.1, 0.1, 0.1, 0, 0, 0] } ],
        "joints": [ { "name": "J1", "kind": "prismatic", "bodies": ["base", "slider"],
                      "point": [0, 0, 0], "axis": [1, 0, 0] } ],
        "actuators": [ { "name": "M1", "joint": "J1", "coordinate": "x^3", "ratio": 1 } ],
        "tasks": { "grid": { "M1": [0, 2, 3] }, "duration": 1, "samples": 11 }
    }"#,
    );
    let report = evaluate(
        &model,
        &EvaluateOptions {
            samples: None,
            reactions: false,
            shortcut: true,
        },
    )
    .unwrap();
    assert_eq!(report.tasks, 3);
    assert_eq!(report.excluded.count, 2, "{:?}", report.excluded);
    assert_eq!(report.excluded.by_reason.get("singular"), Some(&2));
    assert_eq!(report.evaluated, 1);
    assert_eq!(report.indicators.actuators[0].crt, [1, 2]);
    assert!(report.indicators.qtr.is_finite());
    assert!(task_series(&model, 0, 2, None).is_err());
}

#[test]
fn same_results_with_one_and_two_threads() {
    let model = coarse_palletizer();
    let variants = vec![
        Variant::default(),
        Variant {
            counterweights: vec![Counterweight {
                label: "cw".into(),
                body: model.bodies[3].name.clone(),
                mass: 80.0,
                offset: [-0.4, 0.1, 0.0],
                plane: None,
            }],
            springs: vec![Spring {
                label: "spring".into(),
                body: model.bodies[3].name.clone(),
                other: model.bodies[2].name.clone(),
                stiffness: 5000.0,
                anchor_a: [0.5, 0.0, 0.0],
                anchor_b: [0.0, 0.2, 0.0],
                plane: None,
            }],
        },
    ];
    let params = ParameterSet::from_variants(&model, &variants).unwrap();
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| evaluate_grid(&model, &params, &EvaluateOptions::default()).unwrap())
    };
    let one = run(1);
    let two = run(2);
    assert_eq!(one.indicators, two.indicators, "bit-for-bit identical");
    assert_eq!(one.table, two.table);
    assert_eq!(one.excluded, two.excluded);
    assert_eq!(one.excluded.count, 0);
    assert_ne!(one.indicators[0], one.indicators[1]);
}

#[test]
fn report_fields() {
    let model = coarse_palletizer();
    let report = evaluate(&model, &EvaluateOptions::default()).unwrap();
    assert_eq!(report.points, 27);
    assert_eq!(report.tasks, 351);
    assert!(report.reactions_minimum_norm);
    let json = serde_json::to_value(&report).unwrap();
    for key in [
        "qtr",
        "qit",
        "qtr_task",
        "qit_task",
        "actuators",
        "joints",
        "excluded",
    ] {
        assert!(json.get(key).is_some(), "missing {key}");
    }
    assert_eq!(json["actuators"][0]["crt"].as_array().unwrap().len(), 2);
    assert_eq!(report.indicators.joints.len(), model.joints.len());
    // M1 turns about the vertical: its torque is inertial only, far below M3's gravity load
    assert!(report.indicators.actuators[0].crt_rms < report.indicators.actuators[2].crt_rms);
    // the QTR task's total RMS is the largest, and QIT ≥ every actuator's peak
    for a in &report.indicators.actuators {
        assert!(report.indicators.qit >= a.cpt_peak);
    }
    let s = task_series(
        &model,
        report.indicators.qtr_task[0],
        report.indicators.qtr_task[1],
        None,
    )
    .unwrap();
    assert_eq!(s.t.len(), 11);
    let rms: f64 = (0..3)
        .map(|a| (s.motor_torque.iter().map(|m| m[a] * m[a]).sum::<f64>() / 11.0).sqrt())
        .sum();
    assert!(
        (rms - report.indicators.qtr).abs() < 1e-9 * report.indicators.qtr,
        "{rms} vs {}",
        report.indicators.qtr
    );
}

/// The cyclic-coordinate decomposition (θ1 of the palletizer) against running every task
/// directly: same statistics for every task and column, with springs and counterweights.
#[test]
fn cyclic_shortcut_matches_direct_evaluation() {
    let model = coarse_palletizer();
    let variants = vec![
        Variant::default(),
        Variant {
            counterweights: vec![Counterweight {
                label: "cw".into(),
                body: model.bodies[4].name.clone(),
                mass: 60.0,
                offset: [-0.3, 0.05, 0.0],
                plane: None,
            }],
            springs: vec![Spring {
                label: "spring".into(),
                body: model.bodies[5].name.clone(),
                other: model.bodies[1].name.clone(),
                stiffness: 3000.0,
                anchor_a: [0.2, 0.1, 0.0],
                anchor_b: [0.1, -0.3, 0.0],
                plane: None,
            }],
        },
        // More than two columns (the shared-regressor path) and more reaction right-hand
        // sides per sample than one lane chunk of the solver, the last chunk partial.
        Variant {
            counterweights: vec![Counterweight {
                label: "cw".into(),
                body: model.bodies[2].name.clone(),
                mass: 25.0,
                offset: [0.1, -0.2, 0.05],
                plane: None,
            }],
            springs: vec![],
        },
        Variant {
            counterweights: vec![Counterweight {
                label: "cw".into(),
                body: model.bodies[6].name.clone(),
                mass: 40.0,
                offset: [-0.2, 0.0, 0.1],
                plane: None,
            }],
            springs: vec![],
        },
        // Spring-only variants: the unbalanced robot's inertia, so they share its Δ = ±1
        // evaluations and differ from it by static terms only.
        Variant {
            counterweights: vec![],
            springs: vec![Spring {
                label: "spring".into(),
                body: model.bodies[5].name.clone(),
                other: model.bodies[1].name.clone(),
                stiffness: 5000.0,
                anchor_a: [-0.1, 0.2, 0.0],
                anchor_b: [0.0, 0.3, 0.05],
                plane: None,
            }],
        },
        Variant {
            counterweights: vec![],
            springs: vec![Spring {
                label: "spring".into(),
                body: model.bodies[6].name.clone(),
                other: model.bodies[2].name.clone(),
                stiffness: 1500.0,
                anchor_a: [0.3, 0.0, 0.1],
                anchor_b: [-0.2, 0.1, 0.0],
                plane: None,
            }],
        },
    ];
    let params = ParameterSet::from_variants(&model, &variants).unwrap();
    let fast = evaluate_grid(&model, &params, &EvaluateOptions::default()).unwrap();
    let direct = evaluate_grid(
        &model,
        &params,
        &EvaluateOptions {
            shortcut: false,
            ..EvaluateOptions::default()
        },
    )
    .unwrap();
    assert_eq!(fast.cyclic_coordinate.as_deref(), Some("th1"));
    assert_eq!(direct.cyclic_coordinate, None);
    assert_eq!(direct.distinct_moves, direct.tasks.len());
    // 3 θ1 values × 9 sub-points: Δθ1 = 0 with 36 sub-point pairs, and Δθ1 of one or two
    // steps with any of the 9 × 9 ordered sub-point pairs — 198 moves instead of 351
    assert_eq!(fast.distinct_moves, 36 + 81 + 81);
    assert_eq!(fast.excluded.count, 0);
    assert_eq!(direct.excluded.count, 0);
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-8 * (1.0 + a.abs().max(b.abs()));
    for w in 0..fast.tasks.len() {
        for c in 0..params.len() {
            let (f, d) = (fast.stats(w, c).unwrap(), direct.stats(w, c).unwrap());
            for a in 0..3 {
                assert!(
                    close(f.rms[a], d.rms[a]),
                    "task {w} col {c} rms {a}: {} {}",
                    f.rms[a],
                    d.rms[a]
                );
                assert!(close(f.peak[a], d.peak[a]), "task {w} col {c} peak {a}");
            }
            assert!(close(f.total_peak, d.total_peak));
            for j in 0..f.force_peak.len() {
                assert!(
                    close(f.force_peak[j], d.force_peak[j]),
                    "task {w} col {c} F{j}: {} {}",
                    f.force_peak[j],
                    d.force_peak[j]
                );
                assert!(
                    close(f.moment_peak[j], d.moment_peak[j]),
                    "task {w} col {c} M{j}: {} {}",
                    f.moment_peak[j],
                    d.moment_peak[j]
                );
            }
        }
    }
    for (f, d) in fast.indicators.iter().zip(&direct.indicators) {
        assert!(close(f.qtr, d.qtr) && close(f.qit, d.qit));
        // critical tasks may differ only between tasks with identical statistics (the same
        // move rotated about the vertical axis)
        for (fa, da) in f.actuators.iter().zip(&d.actuators) {
            assert!(close(fa.crt_rms, da.crt_rms) && close(fa.cpt_peak, da.cpt_peak));
        }
        for (fj, dj) in f.joints.iter().zip(&d.joints) {
            assert!(close(fj.force, dj.force) && close(fj.moment, dj.moment));
        }
    }
}

/// Two paths to the joint reactions agree on every task: the grid evaluation (one reaction
/// operator per sample applied to every column, buffers reused from sample to sample) and the
/// per-task series (each sample solved by substitution into fresh buffers). A spring to the
/// base rules out the cyclic shortcut, so θ1 itself is sampled.
#[test]
fn grid_reaction_peaks_match_the_per_task_series() {
    let model = coarse_palletizer();
    let variant = Variant {
        counterweights: vec![],
        springs: vec![Spring {
            label: "spring".into(),
            body: model.bodies[3].name.clone(),
            other: "base".into(),
            stiffness: 5000.0,
            anchor_a: [0.5, 0.0, 0.0],
            anchor_b: [0.0, 0.0, 0.5],
            plane: None,
        }],
    };
    let params = ParameterSet::from_variants(&model, &[variant]).unwrap();
    let grid = evaluate_grid(&model, &params, &EvaluateOptions::default()).unwrap();
    assert_eq!(grid.cyclic_coordinate, None);
    assert_eq!(grid.excluded.count, 0);
    let mut compared = 0;
    for w in 0..grid.tasks.len() {
        let (i, j) = grid.tasks.pair(w);
        let stats = grid.stats(w, 0).unwrap();
        let series = task_series_with(&model, &params, 0, i, j, Some(11)).unwrap();
        for (n, joint) in series.joints.iter().enumerate() {
            let force = joint.force.iter().copied().fold(0.0, f64::max);
            let moment = joint.moment.iter().copied().fold(0.0, f64::max);
            for (grid_peak, series_peak) in
                [(stats.force_peak[n], force), (stats.moment_peak[n], moment)]
            {
                assert!(
                    (grid_peak - series_peak).abs() <= 1e-9 * series_peak.max(1.0),
                    "task {i}→{j}, joint {n}: {grid_peak} vs {series_peak}"
                );
                compared += 1;
            }
        }
    }
    assert_eq!(compared, 351 * 2 * model.joints.len());
}

/// Phase 1's unbalanced grid solves its few right-hand sides per sample by substitution
/// (`Combination::Substitution`); the operator path of every other batch is the second method.
/// Every task's reaction peaks agree to 1e-12 of the joint's peak over the grid, and so do
/// the indicators; a peak's task may be another task only where the operator's table has the
/// same value there to that tolerance (tasks that share a static end pose tie). The motor
/// torques do not pass through the reaction solve: they are the same bits.
#[test]
fn the_unbalanced_grid_by_substitution_matches_the_reaction_operator() {
    let model = coarse_palletizer();
    let options = EvaluateOptions::default();
    let by_operator = evaluate_grid(&model, &ParameterSet::unbalanced(&model), &options).unwrap();
    let by_substitution = evaluate_unbalanced_grid(&model, &options).unwrap();
    assert!(by_operator.cyclic_coordinate.is_some(), "the cyclic path");
    let (a, b) = (&by_operator.indicators[0], &by_substitution.indicators[0]);
    assert_eq!(a.joints.len(), 11);
    let close = |x: f64, y: f64, scale: f64| (x - y).abs() <= 1e-12 * scale;
    let task_of = |pair: [usize; 2]| {
        (0..by_operator.tasks.len())
            .find(|&w| by_operator.tasks.pair(w) == (pair[0], pair[1]))
            .unwrap()
    };
    for (j, (ja, jb)) in a.joints.iter().zip(&b.joints).enumerate() {
        assert!(close(ja.force, jb.force, ja.force), "{j}: {ja:?} {jb:?}");
        assert!(close(ja.moment, jb.moment, ja.moment), "{j}: {ja:?} {jb:?}");
        let at = by_operator.stats(task_of(jb.force_task), 0).unwrap();
        assert!(close(at.force_peak[j], ja.force, ja.force), "{j}");
        let at = by_operator.stats(task_of(jb.moment_task), 0).unwrap();
        assert!(close(at.moment_peak[j], ja.moment, ja.moment), "{j}");
        for w in 0..by_operator.tasks.len() {
            let (sa, sb) = (
                by_operator.stats(w, 0).unwrap(),
                by_substitution.stats(w, 0).unwrap(),
            );
            assert!(
                close(sa.force_peak[j], sb.force_peak[j], ja.force),
                "{j} {w}"
            );
            assert!(
                close(sa.moment_peak[j], sb.moment_peak[j], ja.moment),
                "{j} {w}"
            );
        }
    }
    for w in 0..by_operator.tasks.len() {
        let (sa, sb) = (
            by_operator.stats(w, 0).unwrap(),
            by_substitution.stats(w, 0).unwrap(),
        );
        assert_eq!((&sa.rms, &sa.peak), (&sb.rms, &sb.peak), "{w}");
    }
    assert_eq!((a.qtr, a.qit), (b.qtr, b.qit));
}
