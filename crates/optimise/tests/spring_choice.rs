//! The springs are chosen by ΔR, with the same definition of ΔR the ranking uses.
//!
//! Expected values are hand calculations of Eqs. 17–21 (Martini et al. 2019); the choice is
//! checked on score lists whose best entry is known by construction.

use counterpoise_dynamics::{ActuatorIndicators, Indicators, JointIndicators};
use counterpoise_optimise::{delta_r, lowest_delta_r};

fn unbalanced(joints: &[(f64, f64)]) -> Indicators {
    Indicators {
        qtr: 1.0,
        qtr_task: [0, 1],
        qit: 1.0,
        qit_task: [0, 1],
        actuators: vec![ActuatorIndicators {
            name: "M1".into(),
            crt: [0, 1],
            crt_rms: 1.0,
            cpt: [0, 1],
            cpt_peak: 1.0,
        }],
        joints: joints
            .iter()
            .enumerate()
            .map(|(k, &(force, moment))| JointIndicators {
                name: format!("J{}", k + 1),
                force,
                force_task: [0, 1],
                moment,
                moment_task: [0, 1],
            })
            .collect(),
    }
}

#[test]
fn delta_r_weighs_only_increases() {
    // F_UB = (100, 300), M_UB = (10, 30): γ_F = (0.25, 0.75), γ_M = (0.25, 0.75).
    // Variant: F = (150, 240) → ΔF = (+50 %, −20 % → 0); M = (10, 36) → ΔM = (0, +20 %).
    // ΔR = 0.25·50 + 0.75·20 = 12.5 + 15 = 27.5 %.
    let ub = unbalanced(&[(100.0, 10.0), (300.0, 30.0)]);
    let dr = delta_r(&ub, &[150.0, 240.0], &[10.0, 36.0]).unwrap();
    assert!((dr - 27.5).abs() < 1e-12, "ΔR = {dr}");
}

#[test]
fn a_joint_idle_in_the_unbalanced_robot_counts_when_it_gets_loaded() {
    // J2 carries no force in the unbalanced robot: γ_F2 = 0 and ΔF_2 is undefined, but the
    // weighted term γ·ΔF = (F − F_UB)/ΣF_UB·100 is finite: (50 − 0)/200·100 = 25 %.
    // Moments unchanged. ΔR = 25 %. (Skipping the idle joint would give 0.)
    let ub = unbalanced(&[(200.0, 10.0), (0.0, 10.0)]);
    let dr = delta_r(&ub, &[200.0, 50.0], &[10.0, 10.0]).unwrap();
    assert!((dr - 25.0).abs() < 1e-12, "ΔR = {dr}");
    // The ranking's own function agrees (one definition).
    let j = |name: &str, force: f64, moment: f64| counterpoise_vocabulary::JointReaction {
        name: name.into(),
        force,
        moment,
    };
    let report = counterpoise_vocabulary::delta_r(
        &[j("J1", 200.0, 10.0), j("J2", 0.0, 10.0)],
        &[j("J1", 200.0, 10.0), j("J2", 50.0, 10.0)],
    )
    .unwrap();
    assert_eq!(report.value, dr);
}

/// Peaks that do not match the unbalanced robot's joints one for one have no ΔR: one value
/// too many (forces or moments) or a robot without reaction peaks.
#[test]
fn delta_r_needs_one_peak_per_joint() {
    let ub = unbalanced(&[(100.0, 10.0), (300.0, 30.0)]);
    assert!(delta_r(&ub, &[150.0, 240.0], &[10.0, 36.0]).is_some());
    assert_eq!(delta_r(&ub, &[150.0, 240.0, 1.0], &[10.0, 36.0]), None);
    assert_eq!(delta_r(&ub, &[150.0, 240.0], &[10.0, 36.0, 1.0]), None);
    assert_eq!(delta_r(&ub, &[150.0], &[10.0, 36.0]), None);
    assert_eq!(delta_r(&unbalanced(&[]), &[], &[]), None);
}

#[test]
fn the_spring_option_with_the_lowest_delta_r_is_kept() {
    // Three realizations with ΔR 12, 3 and 40 %: the second is the one to keep, whichever
    // position the best one holds.
    assert_eq!(
        lowest_delta_r(&[Some(12.0), Some(3.0), Some(40.0)]),
        Some(1)
    );
    assert_eq!(
        lowest_delta_r(&[Some(3.0), Some(12.0), Some(40.0)]),
        Some(0)
    );
    assert_eq!(
        lowest_delta_r(&[Some(40.0), Some(12.0), Some(3.0)]),
        Some(2)
    );
    // An option without a score (its reactions could not be evaluated) is never preferred.
    assert_eq!(lowest_delta_r(&[None, Some(7.0)]), Some(1));
    // Ties go to the earliest option (the realization from the lifted optimum).
    assert_eq!(lowest_delta_r(&[Some(5.0), Some(5.0)]), Some(0));
    assert_eq!(lowest_delta_r(&[]), None);
}
