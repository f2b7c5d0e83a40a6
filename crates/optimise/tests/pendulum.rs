//! A pendulum with one counterweight: balance fixes `m·r = −M·L/2`, so the only freedom is the
//! mass `m` (with `|r| = (M L/2)/m ≤ r_max`). The balanced torque is inertial only,
//! `τ = ratio·I(m)·θ̈` with `I(m) = I_rod,o + (M L/2)²/m + J_zz(m)` and the cylinder's
//! `J_zz = ½ m R²`, `R = τ_c t`, `m = ρ π R² t`. RMS* (one actuator) is `ratio·I(m)·A` with `A`
//! the largest RMS of θ̈ over the tasks — here the full-swing move. Both are computed below
//! from these formulas, independently of the crate, and the optimum over `m` is found by a
//! brute-force scan.

mod common;

use counterpoise_optimise::{Objective, OptimiseOptions, Status};

const RATIO: f64 = 0.01;
const M_ROD: f64 = 2.0;
const L: f64 = 1.0;
const I_ROD_COM: f64 = 0.1667;
const DENSITY: f64 = 7850.0;
/// Radius/thickness ratio of the cylinder: not 1, so τ and τ² differ.
const TAU: f64 = 0.5;
const DURATION: f64 = 1.0;
const SAMPLES: usize = 21;

fn case(mass: [f64; 2], radius: [f64; 2], peak: Option<f64>, density: f64) -> serde_json::Value {
    let mut json = common::case_json("pendulum.json");
    let b = &mut json["balancing"];
    b["springs"] = serde_json::Value::Null;
    b.as_object_mut().unwrap().remove("springs");
    b["counterweights"]["shape"] =
        serde_json::json!({ "cylinder": { "radius_to_thickness": TAU, "density": density } });
    b["bounds"] = serde_json::json!({ "mass": mass, "radius": radius });
    if let Some(p) = peak {
        b["peak_limits"] = serde_json::json!({ "M1": p });
    }
    json
}

fn inertia(m: f64, density: f64) -> f64 {
    let mu = M_ROD * L / 2.0;
    let t = (m / (density * std::f64::consts::PI * TAU * TAU)).cbrt();
    let r = TAU * t;
    I_ROD_COM + M_ROD * (L / 2.0) * (L / 2.0) + mu * mu / m + 0.5 * m * r * r
}

/// Largest RMS of θ̈ over the grid's moves: the longest swing (−1.5 → 1.5).
fn accel_rms() -> f64 {
    let delta = 3.0;
    let mut sum = 0.0;
    for k in 0..SAMPLES {
        let s = k as f64 / (SAMPLES - 1) as f64;
        let a = delta / (DURATION * DURATION) * (60.0 * s - 180.0 * s * s + 120.0 * s * s * s);
        sum += a * a;
    }
    (sum / SAMPLES as f64).sqrt()
}

/// Brute-force: the true objective on a fine grid of admissible masses, then a local zoom.
fn scan(lo: f64, hi: f64, density: f64) -> (f64, f64) {
    let f = |m: f64| RATIO * inertia(m, density) * accel_rms();
    let mut best = (lo, f(lo));
    let n = 200_000;
    for k in 0..=n {
        let m = lo + (hi - lo) * k as f64 / n as f64;
        let v = f(m);
        if v < best.1 {
            best = (m, v);
        }
    }
    best
}

fn run(json: &serde_json::Value) -> counterpoise_optimise::OptimisedVariant {
    let model = common::model(json);
    let (_, mut results) = common::optimise(&model, &[&["m1"]], &OptimiseOptions::default());
    assert_eq!(results.len(), 1);
    results.pop().unwrap()
}

#[test]
fn interior_optimum_matches_scan() {
    let v = run(&case([1.0, 100.0], [0.0, 0.5], None, DENSITY));
    assert_eq!(v.status, Status::Feasible, "{:?}", v.reason);
    let (m_star, f_star) = scan(2.0, 100.0, DENSITY);
    let m = v.counterweights[0].mass;
    let obj = v.objective.unwrap();
    assert!(
        (obj - f_star).abs() <= 1e-4 * f_star,
        "objective {obj} vs scan {f_star}"
    );
    assert!(
        (m - m_star).abs() <= 1e-2 * m_star,
        "mass {m} vs scan {m_star}"
    );
    let gap = v.gap.unwrap();
    assert!(gap <= 1e-3, "gap {gap}");
    assert!(v.lower_bound.unwrap() <= obj * (1.0 + 1e-9));
    assert!(v.residual.unwrap() <= 1e-9);
    assert!(v.converged);
}

#[test]
fn active_mass_bound() {
    let v = run(&case([1.0, 8.0], [0.0, 0.5], None, DENSITY));
    assert_eq!(v.status, Status::Feasible, "{:?}", v.reason);
    let (m_star, f_star) = scan(2.0, 8.0, DENSITY);
    assert!((m_star - 8.0).abs() < 1e-9);
    let m = v.counterweights[0].mass;
    assert!(m <= 8.0 * (1.0 + 1e-9), "mass {m} above its bound");
    assert!(
        (m - 8.0).abs() <= 1e-6 * 8.0,
        "mass {m} should sit on the bound"
    );
    assert!((v.objective.unwrap() - f_star).abs() <= 1e-4 * f_star);
}

#[test]
fn active_radius_bound() {
    // |r| ≤ 0.05 m ⇒ m ≥ 20 kg, above the unconstrained optimum (≈ 16 kg with τ = 0.5).
    let v = run(&case([1.0, 100.0], [0.0, 0.05], None, DENSITY));
    assert_eq!(v.status, Status::Feasible, "{:?}", v.reason);
    let (_, f_star) = scan(20.0, 100.0, DENSITY);
    let c = &v.counterweights[0];
    assert!(c.radius() <= 0.05 * (1.0 + 1e-9), "radius {}", c.radius());
    assert!(
        (c.radius() - 0.05).abs() <= 1e-6 * 0.05,
        "radius {} should be on the bound",
        c.radius()
    );
    assert!((v.objective.unwrap() - f_star).abs() <= 1e-4 * f_star);
}

/// Largest |θ̈| over the samples of the grid's moves: the longest swing (−1.5 → 1.5).
fn accel_peak() -> f64 {
    let delta = 3.0;
    (0..SAMPLES)
        .map(|k| {
            let s = k as f64 / (SAMPLES - 1) as f64;
            (delta / (DURATION * DURATION) * (60.0 * s - 180.0 * s * s + 120.0 * s * s * s)).abs()
        })
        .fold(0.0, f64::max)
}

#[test]
fn peak_limit_at_the_smallest_achievable_peak() {
    // With one counterweight the peak motor torque is `ratio·I(m)·max|θ̈|`, the same function of
    // m as the objective up to a constant: the smallest achievable peak is at the RMS optimum
    // m*, so a peak limit cannot trade objective for peak here (two_link.rs does that). What
    // it can do is decide feasibility at exactly that smallest peak, derived by hand: a limit
    // 0.1 % above it is feasible with the peak between the two, 0.1 % below it is not.
    let (m_star, f_star) = scan(2.0, 100.0, DENSITY);
    let min_peak = RATIO * inertia(m_star, DENSITY) * accel_peak();
    let above = min_peak * 1.001;
    let v = run(&case([1.0, 100.0], [0.0, 0.5], Some(above), DENSITY));
    assert_eq!(v.status, Status::Feasible, "{:?}", v.reason);
    let peak = v.indicators.as_ref().unwrap().actuators[0].cpt_peak;
    assert!(
        min_peak * (1.0 - 1e-9) <= peak && peak <= above,
        "peak {peak} outside [{min_peak}, {above}]"
    );
    let obj = v.objective.unwrap();
    assert!(
        (obj - f_star).abs() <= 1e-4 * f_star,
        "objective {obj} vs {f_star}"
    );

    let below = min_peak * 0.999;
    let tight = run(&case([1.0, 100.0], [0.0, 0.5], Some(below), DENSITY));
    assert_eq!(tight.status, Status::Discarded);
    let reason = tight.reason.unwrap();
    assert!(
        reason.contains("peak") || reason.contains("infeasible"),
        "{reason}"
    );
    assert!(tight.objective.is_none());
}

#[test]
fn infeasible_bounds_are_discarded() {
    // m ≤ 5 kg and |r| ≤ 0.1 m cannot give m·r = 1 kg·m.
    let v = run(&case([1.0, 5.0], [0.0, 0.1], None, DENSITY));
    assert_eq!(v.status, Status::Discarded);
    let reason = v.reason.unwrap();
    // The binding bound in the designer's words (m·r = 1 kg·m: 10 kg at 0.1 m, or 0.2 m at 5 kg).
    assert!(reason.contains("m1 would need"), "{reason}");
    assert!(v.objective.is_none());
}

#[test]
fn minimax_on_one_actuator_equals_rms_optimum() {
    let model = common::model(&case([1.0, 100.0], [0.0, 0.5], None, DENSITY));
    let options = OptimiseOptions {
        objective: Objective::Minimax,
        ..OptimiseOptions::default()
    };
    let (_, results) = common::optimise(&model, &[&["m1"]], &options);
    let v = &results[0];
    assert_eq!(v.status, Status::Feasible, "{:?}", v.reason);
    let (_, f_star) = scan(2.0, 100.0, DENSITY);
    // one actuator: QTR = RMS* = the same function of m
    assert!((v.objective.unwrap() - f_star).abs() <= 1e-4 * f_star);
}
