use super::*;
use counterpoise_model::sampling::SplitMix64;

/// The lazily constrained solve against the same problem with every row from the start:
/// minimise `u ≥ ‖x − (3, −2)‖` subject to 200 random rows `|c·x + d| ≤ 1`, a few of them
/// binding. Both give the same optimum, and the lazy solution meets every row.
#[test]
fn lazy_peak_rows_reach_the_full_problems_optimum() {
    let mut rng = SplitMix64::new(11);
    let mut uniform = || 2.0 * rng.next_f64() - 1.0;
    let rows: Vec<Affine> = (0..200)
        .map(|_| {
            let mut e = Affine::constant(0.2 * uniform());
            e.add_var(0, 0.4 * uniform());
            e.add_var(1, 0.4 * uniform());
            e
        })
        .collect();
    let build = || {
        let mut cp = ConicProblem::default();
        let x0 = cp.new_variable();
        let x1 = cp.new_variable();
        let u = cp.new_variable();
        cp.objective[u] = 1.0;
        let mut d0 = Affine::var(x0);
        d0.constant -= 3.0;
        let mut d1 = Affine::var(x1);
        d1.constant += 2.0;
        cp.soc(&Affine::var(u), &[d0, d1]);
        cp
    };
    let mut full = build();
    for e in &rows {
        add_peak_row(&mut full, e);
    }
    let reference = full.solve(200);
    assert_eq!(reference.status, ConicStatus::Solved);
    let mut lazy = build();
    let mut added = vec![false; rows.len()];
    let solution = solve_with_peaks_from(&mut lazy, &rows, &mut added, 200);
    // Starting from the rows that solve used gives the same optimum in one round.
    let mut again = build();
    let mut reused = added.clone();
    let first = solve_with_peaks_from(&mut again, &rows, &mut reused, 200);
    assert_eq!(reused, added, "no row beyond the first solve's");
    assert!((first.objective - solution.objective).abs() <= 1e-6 * solution.objective.abs());
    assert_eq!(solution.status, ConicStatus::Solved);
    // The target (3, −2) is outside the feasible set: some row binds.
    assert!(reference.objective > 1e-3);
    assert!(
        (solution.objective - reference.objective).abs() <= 1e-6 * reference.objective,
        "{} vs {}",
        solution.objective,
        reference.objective
    );
    for e in &rows {
        assert!(e.eval(&solution.x).abs() <= 1.0 + 1e-7);
    }
}

/// A task of 51 samples for `actuators` motors and one slot: base torques uniform in ±30 N·m,
/// sensitivities uniform in ±1, drawn from `rng` in that order.
fn random_task(rng: &mut SplitMix64, actuators: usize) -> TaskTorques {
    let samples = 51;
    let mut uniform = || 2.0 * rng.next_f64() - 1.0;
    let base: Vec<f64> = (0..samples * actuators).map(|_| 30.0 * uniform()).collect();
    let sensitivity: Vec<Vec<f64>> = (0..BODY_PARAMS)
        .map(|_| (0..samples * actuators).map(|_| uniform()).collect())
        .collect();
    TaskTorques {
        task: 0,
        samples,
        actuators,
        base,
        sensitivity,
    }
}

/// The compressed tail's norm at the conic point `x` against `w·‖τ_a‖` over the task's
/// samples, τ computed directly from the base torque and the sensitivities, to 1e-12.
fn assert_tail_has_the_sampled_norm(
    task: &TaskTorques,
    a: usize,
    w: f64,
    features: &[Feature],
    tail: &[Affine],
    x: &[f64],
) {
    let na = task.actuators;
    let direct: f64 = (0..task.samples)
        .map(|s| {
            let mut tau = task.base[s * na + a];
            for feat in features {
                let f = feat.expr.eval(x);
                for &(slot, j, c) in &feat.parts {
                    tau += f * c * task.sens(slot, j)[s * na + a];
                }
            }
            (w * tau).powi(2)
        })
        .sum::<f64>()
        .sqrt();
    let compressed = tail.iter().map(|e| e.eval(x).powi(2)).sum::<f64>().sqrt();
    assert!(
        (compressed - direct).abs() <= 1e-12 * direct,
        "{compressed} vs {direct}"
    );
}

/// `rms_tail` against the sample-by-sample norm it replaces: for random feature values the
/// norm of the compressed rows equals `w·‖τ‖` over the samples, τ computed directly from
/// the base torque and the sensitivities.
#[test]
fn compressed_rms_tail_has_the_norm_of_the_sampled_torque() {
    let actuators = 3;
    let mut rng = SplitMix64::new(7);
    let task = random_task(&mut rng, actuators);
    let mut uniform = || 2.0 * rng.next_f64() - 1.0;
    // Three features over two conic variables: m, μ_x (parts on π 0 and 1) and a mixed one.
    let features = vec![
        Feature {
            expr: Affine::var(0).scaled(100.0),
            parts: vec![(0, 0, 1.0)],
        },
        Feature {
            expr: Affine::var(1).scaled(20.0),
            parts: vec![(0, 1, 1.0)],
        },
        Feature {
            expr: {
                let mut e = Affine::var(0);
                e.add_var(1, -0.5);
                e.constant = 0.3;
                e
            },
            parts: vec![(0, 4, 1.0), (0, 7, -2.0)],
        },
    ];
    let w = 0.37;
    for a in 0..actuators {
        let tail = rms_tail(&task, a, w, &features);
        assert_eq!(tail.len(), 1 + features.len());
        for _ in 0..5 {
            let x = [uniform(), uniform()];
            assert_tail_has_the_sampled_norm(&task, a, w, &features, &tail, &x);
        }
    }
}

/// A torque that sees its features only through fewer independent columns than it has
/// features leaves rows of rounding alone in `R`, and the tail drops them. The features are a
/// column `s`, a column `s₉` that is zero for actuator 0, and `s` doubled: actuator 0's `T`
/// is `[base, s, 0, 2s]`, rank 2, and actuator 1's `[base, s, s₉, 2s]`, rank 3 (by
/// construction), so the tails have 2 and 3 rows, not 4, and keep the norm of the sampled
/// torque.
#[test]
fn a_rank_deficient_rms_tail_keeps_only_its_independent_rows() {
    let actuators = 2;
    let mut rng = SplitMix64::new(11);
    let mut task = random_task(&mut rng, actuators);
    // π 9 loads actuator 1 only.
    for s in 0..task.samples {
        task.sensitivity[9][s * actuators] = 0.0;
    }
    let mut uniform = || 2.0 * rng.next_f64() - 1.0;
    let features = vec![
        Feature {
            expr: Affine::var(0),
            parts: vec![(0, 2, 1.0)],
        },
        Feature {
            expr: Affine::var(2),
            parts: vec![(0, 9, 1.0)],
        },
        Feature {
            expr: Affine::var(1).scaled(3.0),
            parts: vec![(0, 2, 2.0)],
        },
    ];
    // The rows dropped are negligible against the largest at any scale of the torque.
    for (a, rank, w) in [
        (0, 2, 0.5),
        (1, 3, 0.5),
        (0, 2, 1e6),
        (1, 3, 1e6),
        (1, 3, 1e-6),
    ] {
        let tail = rms_tail(&task, a, w, &features);
        assert_eq!(tail.len(), rank, "actuator {a}, weight {w}");
        for _ in 0..5 {
            let x = [uniform(), uniform(), uniform()];
            assert_tail_has_the_sampled_norm(&task, a, w, &features, &tail, &x);
        }
    }
}

/// A motor that no sample loads (zero base torque, zero sensitivities) keeps one zero row, so
/// its cone stays `t ≥ |0|`, as with the full tail of zeros, not a cone of dimension one.
#[test]
fn an_unloaded_motor_keeps_one_zero_row() {
    let (samples, actuators) = (51, 1);
    let task = TaskTorques {
        task: 0,
        samples,
        actuators,
        base: vec![0.0; samples],
        sensitivity: vec![vec![0.0; samples]; BODY_PARAMS],
    };
    let features = vec![Feature {
        expr: Affine::var(0),
        parts: vec![(0, 1, 1.0)],
    }];
    let tail = rms_tail(&task, 0, 1.0, &features);
    assert_eq!(tail.len(), 1);
    assert_eq!(tail[0].eval(&[3.0]), 0.0);
}

/// The tangents of `m^{5/3}` that replace the power cone, through the conic rows the
/// relaxation adds: minimising `p'` at a fixed mass gives the highest tangent there, which must
/// lie below the curve (the relaxation stays valid) and within the gap the tangent ratio allows.
/// That gap is derived apart: between tangents at `t` and `1.5·t` the largest relative distance
/// to the curve is 0.02247 (a sweep of the two closed-form tangents, `t^{5/3} + (5/3)·t^{2/3}·
/// (m − t)`, over `[t, 1.5·t]`; it does not depend on `t` since the curve is homogeneous).
#[test]
fn the_tangents_of_the_cylinder_inertia_lie_below_it_within_the_ratios_gap() {
    let five_thirds = |m: f64| m.powf(5.0 / 3.0);
    // The gap at the ratio, from the closed-form tangents.
    let q = TANGENT_RATIO;
    let tangent = |t: f64, m: f64| five_thirds(t) + (5.0 / 3.0) * t.powf(2.0 / 3.0) * (m - t);
    let swept = (0..=10_000)
        .map(|i| 1.0 + (q - 1.0) * i as f64 / 10_000.0)
        .map(|m| 1.0 - tangent(1.0, m).max(tangent(q, m)) / five_thirds(m))
        .fold(0.0f64, f64::max);
    assert!((swept - 0.02247).abs() < 5e-5, "{swept}");
    // No tangent without a positive, finite upper bound.
    assert!(tangent_points(0.0, 0.0).is_empty());
    assert!(tangent_points(1.0, f64::INFINITY).is_empty());
    for (lo, hi) in [
        (1.0, 100.0),
        (5e-4, 500.0),
        (30.0, 40.0),
        (0.0, 12.0),
        (7.0, 7.0),
    ] {
        let points = tangent_points(lo, hi);
        let floor = lo.max(1e-3 * hi);
        assert_eq!(*points.last().unwrap(), hi, "[{lo}, {hi}]");
        let geometric: Vec<f64> = points.iter().copied().filter(|&t| t >= floor).collect();
        assert!(
            (geometric[0] - floor).abs() <= 1e-12 * floor,
            "[{lo}, {hi}]: {points:?}"
        );
        for w in geometric.windows(2) {
            assert!(
                w[1] > w[0] && w[1] / w[0] <= q * (1.0 + 1e-12),
                "{points:?}"
            );
        }
        // Below the floor, only the lower bound itself (when positive).
        let below: Vec<f64> = points.iter().copied().filter(|&t| t < floor).collect();
        assert_eq!(
            below,
            if lo > 0.0 && lo < floor {
                vec![lo]
            } else {
                vec![]
            }
        );
        // Through the conic rows, with a natural mass scale that is not the bound.
        let big_m = 0.7 * hi;
        for i in 0..=40 {
            let m = floor + (hi - floor) * i as f64 / 40.0;
            let mut cp = ConicProblem::default();
            let mn = cp.new_variable();
            let p = cp.new_variable();
            cp.objective[p] = 1.0;
            let mut at = Affine::var(mn);
            at.constant -= m / big_m;
            cp.nonneg(&at);
            cp.nonneg(&at.scaled(-1.0));
            cp.nonneg(&Affine::var(p));
            for &t in &points {
                below_five_thirds_tangent(&mut cp, p, &Affine::var(mn), big_m, t);
            }
            let solution = cp.solve(200);
            assert_eq!(solution.status, ConicStatus::Solved);
            let relaxed = solution.x[p] * five_thirds(big_m);
            let highest = points.iter().map(|&t| tangent(t, m)).fold(0.0f64, f64::max);
            // clarabel's absolute tolerance (1e-8) on the normalised p' = p/M^{5/3}.
            let tol = 1e-7 * five_thirds(big_m);
            assert!(
                (relaxed - highest).abs() <= tol,
                "m = {m}: {relaxed} vs {highest}"
            );
            assert!(
                relaxed <= five_thirds(m) + tol,
                "m = {m}: {relaxed} above the curve"
            );
            assert!(
                relaxed >= (1.0 - 0.02247) * five_thirds(m) - tol,
                "m = {m}: {relaxed} against {}",
                five_thirds(m)
            );
        }
    }
}
