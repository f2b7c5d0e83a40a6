//! The final checks before a variant is reported feasible: the balance (energy sampled at the
//! balance crate's verification configurations, relative spread ≤ 1e-9), every bound (relative
//! excess ≤ 1e-9) and every peak limit over all tasks (from the final dynamics evaluation).

use counterpoise_balance::VerificationSet;
use counterpoise_dynamics::Indicators;
use counterpoise_vocabulary::PhysicalParameters;
use serde::Serialize;

use crate::problem::{CwPhysical, VariantProblem, norm};
use crate::springs::Spring;

/// Relative tolerance of the bound and peak checks.
pub const CHECK_TOL: f64 = 1e-9;

/// One actuator's peak against its limit.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PeakCheck {
    pub actuator: String,
    /// Largest |motor torque| over all tasks, N·m.
    pub peak: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub limit: Option<f64>,
}

/// Outcome of the checks.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct VerificationReport {
    /// Energy spread of the optimised variant relative to the unbalanced one.
    pub balance_residual: f64,
    pub balance_passed: bool,
    /// Largest relative bound excess (≤ 0 inside every bound).
    pub bound_excess: f64,
    pub bounds_passed: bool,
    pub peaks: Vec<PeakCheck>,
    pub peaks_passed: bool,
    pub passed: bool,
}

fn excess(value: f64, range: [f64; 2]) -> f64 {
    let scale = range[1].abs().max(1e-12);
    ((range[0] - value) / scale).max((value - range[1]) / scale)
}

/// Largest relative bound excess of physical parameters.
pub fn bound_excess(problem: &VariantProblem, cws: &[CwPhysical], springs: &[Spring]) -> f64 {
    let mut worst = f64::NEG_INFINITY;
    for (c, p) in problem.counterweights.iter().zip(cws) {
        worst = worst.max(excess(p.mass, [c.min_mass(), c.bounds.mass[1]]));
        worst = worst.max(excess(p.radius(), c.bounds.radius));
    }
    for (s, v) in problem.springs.iter().zip(springs) {
        worst = worst.max(excess(v.stiffness, s.bounds.stiffness));
        worst = worst.max(excess(norm(&v.anchor_a), s.bounds.anchor_a));
        worst = worst.max(excess(norm(&v.anchor_b), s.bounds.anchor_b));
        for (bx, anchor, reach) in [
            (&s.bounds.box_a, &v.anchor_a, s.bounds.anchor_a[1]),
            (&s.bounds.box_b, &v.anchor_b, s.bounds.anchor_b[1]),
        ] {
            let scale = reach.abs().max(1e-12);
            for (r, &c) in bx.iter().zip(anchor) {
                if r[0].is_finite() {
                    worst = worst.max((r[0] - c) / scale);
                }
                if r[1].is_finite() {
                    worst = worst.max((c - r[1]) / scale);
                }
            }
        }
    }
    worst
}

/// Checks the optimised point: the balance of `elements` (the physical parameters of `cws` and
/// `springs`, named) by energy sampling, the bounds and the peak limits.
pub fn verify(
    problem: &VariantProblem,
    checks: &VerificationSet,
    elements: &PhysicalParameters,
    cws: &[CwPhysical],
    springs: &[Spring],
    indicators: &Indicators,
) -> VerificationReport {
    let balance = checks.verify(elements);
    let bound_excess = bound_excess(problem, cws, springs);
    let peaks: Vec<PeakCheck> = indicators
        .actuators
        .iter()
        .enumerate()
        .map(|(a, ind)| PeakCheck {
            actuator: ind.name.clone(),
            peak: ind.cpt_peak,
            limit: problem.peak_limits.get(a).copied().flatten(),
        })
        .collect();
    let peaks_passed = peaks
        .iter()
        .all(|p| p.limit.is_none_or(|l| p.peak <= l * (1.0 + CHECK_TOL)));
    let balance_passed = balance.residual.is_finite() && balance.residual <= 1e-9;
    let bounds_passed = bound_excess <= CHECK_TOL;
    VerificationReport {
        balance_residual: balance.residual,
        balance_passed,
        bound_excess,
        bounds_passed,
        peaks,
        peaks_passed,
        passed: balance_passed && bounds_passed && peaks_passed,
    }
}
