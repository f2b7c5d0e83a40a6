//! The paper's Phase 3 indicators (Martini et al. 2019, Sec. 2.3, Eqs. 15–21).
//!
//! **Sign convention (as in the paper):** every variation is `(balanced − unbalanced) /
//! unbalanced · 100`, so a *reduction is negative*. `ΔQTR = −60 %` means the balanced variant
//! needs 60 % less total RMS motor torque than the unbalanced robot; −100 % is the best possible
//! value. Lower is better for all three indicators.
//!
//! - [`percent_variation`] is Eqs. 15–16 (ΔQTR, ΔQIT) and, unclamped, Eqs. 17–18 (ΔF_j, ΔM_j).
//! - [`delta_r`] is Eqs. 17–21: ΔR = Σ_j γ_Fj·max(ΔF_j, 0) + γ_Mj·max(ΔM_j, 0) with
//!   γ_Fj = F_j,UB / Σ_k F_k,UB and γ_Mj = M_j,UB / Σ_k M_k,UB. Negative variations are set to
//!   zero because the paper wants ΔR to detect only *worsening* (a relieved joint must not hide
//!   an overloaded one); ΔR ≥ 0 and 0 is the best value.
//!
//! Degenerate references. A joint whose unbalanced reaction is zero has γ = 0 and an undefined
//! ΔF_j; its weighted term γ·ΔF_j = (F_SB − F_UB)/Σ_k F_k,UB · 100 is finite, and that
//! continuous extension is what we add (so a spring that loads a previously unloaded joint still
//! counts). If *all* unbalanced reactions of a kind are zero (or none were computed) that half of
//! ΔR is zero. QTR_UB or QIT_UB equal to zero is an error: there is nothing to balance.

use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Why an indicator cannot be computed.
#[derive(Debug, Error, PartialEq)]
pub enum IndicatorError {
    #[error(
        "the unbalanced reference value of {what} is {value}; a percentage variation needs a positive finite reference"
    )]
    BadReference { what: String, value: f64 },
    #[error("{what} is not finite ({value})")]
    NotFinite { what: String, value: f64 },
    #[error(
        "joint lists differ: unbalanced robot has {unbalanced:?}, balanced variant has {balanced:?}"
    )]
    JointMismatch {
        unbalanced: Vec<String>,
        balanced: Vec<String>,
    },
}

/// Peak reaction force `F_j` (N) and moment `M_j` (N·m) of one joint over all tasks (Eq. 3).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct JointReaction {
    pub name: String,
    /// `F_j`, N.
    pub force: f64,
    /// `M_j`, N·m.
    pub moment: f64,
}

/// The joint-by-joint breakdown of ΔR, so a designer can see which joint got worse.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct JointVariation {
    pub name: String,
    /// ΔF_j of Eq. 17 *before* zeroing (percent); `None` when F_j,UB = 0.
    pub dforce: Option<f64>,
    /// ΔM_j of Eq. 18 before zeroing (percent); `None` when M_j,UB = 0.
    pub dmoment: Option<f64>,
    /// γ_Fj (Eq. 20) and γ_Mj (Eq. 21).
    pub gamma_force: f64,
    pub gamma_moment: f64,
    /// This joint's terms of Eq. 19, γ·max(Δ, 0) (percent).
    pub term_force: f64,
    pub term_moment: f64,
}

/// ΔR (Eq. 19, percent) and its per-joint terms.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DeltaR {
    pub value: f64,
    pub joints: Vec<JointVariation>,
}

/// Eqs. 15–18: `(balanced − unbalanced) / unbalanced · 100`; negative = reduction = better.
pub fn percent_variation(
    balanced: f64,
    unbalanced: f64,
    what: &str,
) -> Result<f64, IndicatorError> {
    if !balanced.is_finite() {
        return Err(IndicatorError::NotFinite {
            what: what.to_string(),
            value: balanced,
        });
    }
    if !(unbalanced.is_finite() && unbalanced > 0.0) {
        return Err(IndicatorError::BadReference {
            what: what.to_string(),
            value: unbalanced,
        });
    }
    Ok((balanced - unbalanced) / unbalanced * 100.0)
}

/// Eqs. 17–21 over joints given in the same order for the unbalanced robot and the variant.
pub fn delta_r(
    unbalanced: &[JointReaction],
    balanced: &[JointReaction],
) -> Result<DeltaR, IndicatorError> {
    let same_joints = unbalanced.len() == balanced.len()
        && unbalanced
            .iter()
            .zip(balanced)
            .all(|(u, b)| u.name == b.name);
    if !same_joints {
        return Err(IndicatorError::JointMismatch {
            unbalanced: unbalanced.iter().map(|j| j.name.clone()).collect(),
            balanced: balanced.iter().map(|j| j.name.clone()).collect(),
        });
    }
    for (set, joints) in [("unbalanced", unbalanced), ("balanced", balanced)] {
        for j in joints {
            for (kind, v) in [("F", j.force), ("M", j.moment)] {
                if !(v.is_finite() && v >= 0.0) {
                    return Err(IndicatorError::NotFinite {
                        what: format!("{set} {kind}_j of joint {}", j.name),
                        value: v,
                    });
                }
            }
        }
    }
    let sum_force: f64 = unbalanced.iter().map(|j| j.force).sum();
    let sum_moment: f64 = unbalanced.iter().map(|j| j.moment).sum();
    let mut value = 0.0;
    let joints = unbalanced
        .iter()
        .zip(balanced)
        .map(|(u, b)| {
            let (dforce, gamma_force, term_force) = weighted_term(u.force, b.force, sum_force);
            let (dmoment, gamma_moment, term_moment) =
                weighted_term(u.moment, b.moment, sum_moment);
            value += term_force + term_moment;
            JointVariation {
                name: u.name.clone(),
                dforce,
                dmoment,
                gamma_force,
                gamma_moment,
                term_force,
                term_moment,
            }
        })
        .collect();
    Ok(DeltaR { value, joints })
}

/// (Δ unclamped, γ, γ·max(Δ, 0)) of one reaction; see the module doc for zero references.
fn weighted_term(ub: f64, sb: f64, sum_ub: f64) -> (Option<f64>, f64, f64) {
    if sum_ub <= 0.0 {
        return (None, 0.0, 0.0);
    }
    let gamma = ub / sum_ub;
    if ub > 0.0 {
        let delta = (sb - ub) / ub * 100.0;
        (Some(delta), gamma, gamma * delta.max(0.0))
    } else {
        (None, gamma, (sb - ub).max(0.0) / sum_ub * 100.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn j(name: &str, force: f64, moment: f64) -> JointReaction {
        JointReaction {
            name: name.into(),
            force,
            moment,
        }
    }

    fn close(a: f64, b: f64) {
        assert!((a - b).abs() < 1e-12 * (1.0 + b.abs()), "{a} vs {b}");
    }

    #[test]
    fn percent_variation_is_negative_for_a_reduction() {
        // QTR 40 → 16: (16 − 40)/40·100 = −60 %.
        close(percent_variation(16.0, 40.0, "QTR").unwrap(), -60.0);
        // QIT 50 → 55: +10 %.
        close(percent_variation(55.0, 50.0, "QIT").unwrap(), 10.0);
        // Complete removal is −100 %.
        close(percent_variation(0.0, 7.5, "QTR").unwrap(), -100.0);
    }

    #[test]
    fn percent_variation_rejects_bad_references() {
        assert!(matches!(
            percent_variation(1.0, 0.0, "QTR"),
            Err(IndicatorError::BadReference { .. })
        ));
        assert!(matches!(
            percent_variation(f64::NAN, 1.0, "QIT"),
            Err(IndicatorError::NotFinite { .. })
        ));
    }

    /// Hand calculation, three joints:
    /// F_UB = (100, 300, 600) → ΣF = 1000, γ_F = (0.1, 0.3, 0.6);
    /// M_UB = (50, 150, 0)   → ΣM = 200,  γ_M = (0.25, 0.75, 0).
    /// F_SB = (150, 240, 660) → ΔF = (+50, −20, +10) %, zeroed → (50, 0, 10);
    /// M_SB = (40, 180, 0)    → ΔM = (−20, +20, undefined) %, zeroed → (0, 20, –).
    /// ΔR = 0.1·50 + 0.3·0 + 0.6·10 + 0.25·0 + 0.75·20 + 0 = 5 + 6 + 15 = 26 %.
    #[test]
    fn delta_r_matches_hand_calculation() {
        let ub = [
            j("J1", 100.0, 50.0),
            j("J2", 300.0, 150.0),
            j("J3", 600.0, 0.0),
        ];
        let sb = [
            j("J1", 150.0, 40.0),
            j("J2", 240.0, 180.0),
            j("J3", 660.0, 0.0),
        ];
        let r = delta_r(&ub, &sb).unwrap();
        close(r.value, 26.0);
        let g: Vec<f64> = r.joints.iter().map(|v| v.gamma_force).collect();
        close(g[0], 0.1);
        close(g[1], 0.3);
        close(g[2], 0.6);
        close(r.joints[0].gamma_moment, 0.25);
        close(r.joints[1].gamma_moment, 0.75);
        close(r.joints[2].gamma_moment, 0.0);
        // Raw variations are kept for the report; only the terms are zeroed.
        close(r.joints[1].dforce.unwrap(), -20.0);
        close(r.joints[1].term_force, 0.0);
        close(r.joints[0].dmoment.unwrap(), -20.0);
        close(r.joints[0].term_moment, 0.0);
        close(r.joints[2].term_force, 6.0);
        close(r.joints[1].term_moment, 15.0);
        assert_eq!(r.joints[2].dmoment, None);
    }

    #[test]
    fn reductions_alone_give_zero() {
        // Every joint relieved: without the zeroing ΔR would be negative.
        let ub = [j("J1", 100.0, 10.0), j("J2", 200.0, 20.0)];
        let sb = [j("J1", 50.0, 5.0), j("J2", 100.0, 1.0)];
        assert_eq!(delta_r(&ub, &sb).unwrap().value, 0.0);
    }

    #[test]
    fn a_relieved_joint_does_not_hide_an_overloaded_one() {
        // Plain weighted sum: 0.5·(−50) + 0.5·(+50) = 0; the paper's ΔR: 0.5·50 = 25 %.
        let ub = [j("J1", 100.0, 0.0), j("J2", 100.0, 0.0)];
        let sb = [j("J1", 50.0, 0.0), j("J2", 150.0, 0.0)];
        close(delta_r(&ub, &sb).unwrap().value, 25.0);
    }

    #[test]
    fn weights_emphasise_the_large_reactions() {
        // The same +100 % on a small joint (γ = 0.01) and on a large joint (γ = 0.99).
        let ub = [j("small", 10.0, 0.0), j("large", 990.0, 0.0)];
        let small = delta_r(&ub, &[j("small", 20.0, 0.0), j("large", 990.0, 0.0)]).unwrap();
        let large = delta_r(&ub, &[j("small", 10.0, 0.0), j("large", 1980.0, 0.0)]).unwrap();
        close(small.value, 1.0);
        close(large.value, 99.0);
    }

    #[test]
    fn a_joint_unloaded_in_the_reference_counts_by_continuity() {
        // F_UB = (0, 100): γ = (0, 1); J1 goes to 20 N → term = 20/100·100 = 20 %.
        let ub = [j("J1", 0.0, 0.0), j("J2", 100.0, 0.0)];
        let sb = [j("J1", 20.0, 0.0), j("J2", 100.0, 0.0)];
        let r = delta_r(&ub, &sb).unwrap();
        close(r.value, 20.0);
        assert_eq!(r.joints[0].dforce, None);
    }

    #[test]
    fn no_joints_give_zero_and_mismatches_are_errors() {
        assert_eq!(delta_r(&[], &[]).unwrap().value, 0.0);
        let err = delta_r(&[j("J1", 1.0, 1.0)], &[j("J2", 1.0, 1.0)]).unwrap_err();
        assert!(matches!(err, IndicatorError::JointMismatch { .. }));
        let err = delta_r(&[j("J1", 1.0, 1.0)], &[j("J1", f64::NAN, 1.0)]).unwrap_err();
        assert!(matches!(err, IndicatorError::NotFinite { .. }));
    }
}
