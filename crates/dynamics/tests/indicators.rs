//! The paper's indicators (Eqs. 1–3) on hand-built statistics: every expected value below is
//! read off the small tables by hand, not computed by the crate.

use counterpoise_dynamics::indicators::{StatsAccumulator, StatsTable, TaskStats, reduce};

fn stats(
    rms: [f64; 2],
    peak: [f64; 2],
    total: f64,
    force: [f64; 2],
    moment: [f64; 2],
) -> TaskStats {
    TaskStats {
        rms: rms.to_vec(),
        peak: peak.to_vec(),
        total_peak: total,
        force_peak: force.to_vec(),
        moment_peak: moment.to_vec(),
    }
}

fn names(prefix: &str) -> Vec<String> {
    (1..=2).map(|k| format!("{prefix}{k}")).collect()
}

/// Task `w` goes from grid point `w` to grid point `w + 10`, so a wrong task shows.
fn pair(w: usize) -> (usize, usize) {
    (w, w + 10)
}

/// Four tasks, two columns, two actuators, two joints; task 0 never ran.
///
/// Column 0, by task (rms₁ rms₂ | pk₁ pk₂ | Σ|τ| peak | F₁ F₂ | M₁ M₂):
///
/// | task | rms       | peak  | total | force   | moment   |
/// |------|-----------|-------|-------|---------|----------|
/// | 1    | 3.0  1.0  | 5  2  | 6     | 10  0   | 1.0  0   |
/// | 2    | 1.0  3.5  | 5  4  | 7     | 20  0   | 0.5  2   |
/// | 3    | 2.5  2.5  | 4  4  | 7     | 20  0   | 0.5  3   |
///
/// By hand: Σ rms = 4, 4.5, 5, so QTR = 5 at task 3 — a task that is *not* the critical one of
/// either actuator (a maximum of per-actuator maxima would give 3.5, a sum of them 6.5; a
/// minimum over tasks 4 at task 1). QIT = 7, tied between tasks 2 and 3 → task 2. CRT: actuator
/// 1 at task 1 (3.0), actuator 2 at task 2 (3.5). CPT: actuator 1 tied at 5 (tasks 1, 2) →
/// task 1; actuator 2 tied at 4 (tasks 2, 3) → task 2. F₁ = 20 tied → task 2; F₂ is zero
/// everywhere → the first task that ran, task 1 (not the excluded task 0). M₁ = 1 at task 1,
/// M₂ = 3 at task 3.
fn table() -> StatsTable {
    let mut t = StatsTable::new(4, 2, 2, 2);
    // column 1: QTR at task 1 (Σ rms = 20, 2, 2), for the column-selection check
    let other = |r: f64| stats([r, r], [r, r], r, [r, r], [r, r]);
    t.set(
        1,
        &[
            stats([3.0, 1.0], [5.0, 2.0], 6.0, [10.0, 0.0], [1.0, 0.0]),
            other(10.0),
        ],
    );
    t.set(
        2,
        &[
            stats([1.0, 3.5], [5.0, 4.0], 7.0, [20.0, 0.0], [0.5, 2.0]),
            other(1.0),
        ],
    );
    // task 3 through the raw row layout: [rms (2), peak (2), total, force (2), moment (2)] per
    // column
    #[rustfmt::skip]
    let rows = [
        2.5, 2.5, 4.0, 4.0, 7.0, 20.0, 0.0, 0.5, 3.0,
        1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0,
    ];
    t.set_rows(3, &rows);
    t
}

#[test]
fn hand_built_table_reduces_to_the_papers_maxima() {
    let ind = reduce(&table(), 0, &names("M"), &names("J"), pair);
    assert_eq!(
        (ind.qtr, ind.qtr_task),
        (5.0, [3, 13]),
        "QTR = max_w Σ_n RMS"
    );
    assert_eq!(
        (ind.qit, ind.qit_task),
        (7.0, [2, 12]),
        "QIT tie → lowest task"
    );
    let a = &ind.actuators;
    assert_eq!(a.len(), 2);
    assert_eq!((a[0].name.as_str(), a[1].name.as_str()), ("M1", "M2"));
    assert_eq!((a[0].crt_rms, a[0].crt), (3.0, [1, 11]));
    assert_eq!((a[1].crt_rms, a[1].crt), (3.5, [2, 12]));
    assert_eq!(
        (a[0].cpt_peak, a[0].cpt),
        (5.0, [1, 11]),
        "CPT tie → lowest task"
    );
    assert_eq!(
        (a[1].cpt_peak, a[1].cpt),
        (4.0, [2, 12]),
        "CPT tie → lowest task"
    );
    let j = &ind.joints;
    assert_eq!(j.len(), 2);
    assert_eq!((j[0].name.as_str(), j[1].name.as_str()), ("J1", "J2"));
    assert_eq!(
        (j[0].force, j[0].force_task),
        (20.0, [2, 12]),
        "F tie → lowest task"
    );
    assert_eq!(
        (j[1].force, j[1].force_task),
        (0.0, [1, 11]),
        "all zero → first task that ran, not the excluded task 0"
    );
    assert_eq!((j[0].moment, j[0].moment_task), (1.0, [1, 11]));
    assert_eq!((j[1].moment, j[1].moment_task), (3.0, [3, 13]));
}

#[test]
fn each_column_is_reduced_on_its_own() {
    let ind = reduce(&table(), 1, &names("M"), &names("J"), pair);
    assert_eq!((ind.qtr, ind.qtr_task), (20.0, [1, 11]));
    assert_eq!((ind.qit, ind.qit_task), (10.0, [1, 11]));
    assert_eq!(ind.joints[1].moment, 10.0);
}

#[test]
fn rows_round_trip_and_excluded_tasks_have_none() {
    let mut t = table();
    assert_eq!(t.width(), 2 * 2 + 1 + 2 * 2);
    assert!(t.get(0, 0).is_none() && t.row(0, 1).is_none());
    assert_eq!(
        t.get(2, 0).unwrap(),
        stats([1.0, 3.5], [5.0, 4.0], 7.0, [20.0, 0.0], [0.5, 2.0])
    );
    assert_eq!(
        t.get(3, 0).unwrap(),
        stats([2.5, 2.5], [4.0, 4.0], 7.0, [20.0, 0.0], [0.5, 3.0])
    );
    assert_eq!(t.row(2, 1).unwrap(), &[1.0; 9]);
    // copying task 2 onto the excluded task 0 makes it run with task 2's rows
    t.copy_task(2, 0);
    assert!(t.ok[0]);
    assert_eq!(t.row(0, 0).unwrap(), t.row(2, 0).unwrap());
    assert_eq!(t.row(0, 1).unwrap(), t.row(2, 1).unwrap());
    // ... and, being the lowest task now, it takes task 2's ties
    let ind = reduce(&t, 0, &names("M"), &names("J"), pair);
    assert_eq!(ind.qit_task, [0, 10]);
    // copying onto a later task: task 3 takes task 1's rows (and task 1's ties go first)
    let mut t = table();
    t.copy_task(1, 3);
    assert_eq!(t.row(3, 0).unwrap(), t.row(1, 0).unwrap());
    assert_eq!(t.row(3, 1).unwrap(), t.row(1, 1).unwrap());
    assert_eq!(t.get(2, 0).unwrap().total_peak, 7.0, "task 2 untouched");
    // copying an excluded task excludes the target
    let mut t = table();
    t.copy_task(0, 3);
    assert!(!t.ok[3] && t.get(3, 0).is_none());
}

#[test]
fn a_table_without_reactions_has_no_joint_indicators() {
    let mut t = StatsTable::new(2, 1, 1, 0);
    let s = |r: f64, p: f64| TaskStats {
        rms: vec![r],
        peak: vec![p],
        total_peak: p,
        force_peak: Vec::new(),
        moment_peak: Vec::new(),
    };
    t.set(0, &[s(1.0, 4.0)]);
    t.set(1, &[s(2.0, 3.0)]);
    assert_eq!(t.width(), 3);
    let ind = reduce(&t, 0, &["M1".to_string()], &[], |w| (w, w));
    assert!(ind.joints.is_empty());
    assert_eq!((ind.qtr, ind.qtr_task), (2.0, [1, 1]));
    assert_eq!((ind.qit, ind.qit_task), (4.0, [0, 0]));
}

/// Three samples of two motor torques and two joints' reaction magnitudes:
///
/// τ = (3, −1), (−1, 4), (2.5, 3) → RMS₁ = √((9 + 1 + 6.25)/3), RMS₂ = √((1 + 16 + 9)/3);
/// peaks |τ| = (3, 4); Σ|τ| per sample = 4, 5, 5.5 → total peak 5.5 (not 3 + 4 = 7).
#[test]
fn accumulator_matches_hand_sums() {
    let mut acc = StatsAccumulator::new(2, 2);
    for (tau, force, moment) in [
        ([3.0, -1.0], [1.0, 5.0], [0.0, 2.0]),
        ([-1.0, 4.0], [3.0, 2.0], [1.5, 0.0]),
        ([2.5, 3.0], [2.0, 4.0], [1.0, 1.0]),
    ] {
        acc.add_torques(&tau);
        acc.add_reactions(force.into_iter(), moment.into_iter());
    }
    let s = acc.finish(true);
    let close = |a: f64, b: f64| assert!((a - b).abs() <= 1e-15 * b, "{a} vs {b}");
    close(s.rms[0], (16.25f64 / 3.0).sqrt());
    close(s.rms[1], (26.0f64 / 3.0).sqrt());
    assert_eq!(s.peak, [3.0, 4.0]);
    assert_eq!(s.total_peak, 5.5);
    assert_eq!(s.force_peak, [3.0, 5.0]);
    assert_eq!(s.moment_peak, [1.5, 2.0]);
    let without = acc.finish(false);
    assert!(without.force_peak.is_empty() && without.moment_peak.is_empty());
    assert_eq!(without.rms, s.rms);
}

#[test]
fn an_empty_accumulator_gives_zeros_not_nan() {
    let s = StatsAccumulator::new(2, 1).finish(true);
    assert_eq!(s.rms, [0.0, 0.0]);
    assert_eq!(s.peak, [0.0, 0.0]);
    assert_eq!(s.total_peak, 0.0);
    assert_eq!(s.force_peak, [0.0]);
}

/// Three actuators and one joint (with two actuators `2·n` and `2 + n` coincide): the row
/// layout `[rms (3), peak (3), total, force (1), moment (1)]` written by hand is read back
/// field by field.
#[test]
fn row_layout_with_three_actuators() {
    let mut t = StatsTable::new(1, 1, 3, 1);
    assert_eq!(t.width(), 9);
    t.set_rows(0, &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]);
    let s = t.get(0, 0).unwrap();
    assert_eq!(s.rms, [1.0, 2.0, 3.0]);
    assert_eq!(s.peak, [4.0, 5.0, 6.0]);
    assert_eq!(s.total_peak, 7.0);
    assert_eq!(s.force_peak, [8.0]);
    assert_eq!(s.moment_peak, [9.0]);
    // and `set` writes the same layout
    let mut u = StatsTable::new(1, 1, 3, 1);
    u.set(0, std::slice::from_ref(&s));
    assert_eq!(u.row(0, 0).unwrap(), t.row(0, 0).unwrap());
    let actuators = ["M1", "M2", "M3"].map(String::from);
    let ind = reduce(&t, 0, &actuators, &["J1".to_string()], |w| (w, w));
    assert_eq!((ind.qtr, ind.qit), (6.0, 7.0));
    assert_eq!(ind.actuators[2].cpt_peak, 6.0);
    assert_eq!((ind.joints[0].force, ind.joints[0].moment), (8.0, 9.0));
}

/// `(largest value, its task)` per reduced quantity.
type Maxima = Vec<(f64, usize)>;

/// The reduction written out plainly over `TaskStats` (a second implementation): per quantity
/// the first task that ran with the largest value.
fn plain_reduce(tasks: &[Option<TaskStats>]) -> (Maxima, Maxima) {
    let argmax = |value: &dyn Fn(&TaskStats) -> f64| {
        let mut best: Option<(f64, usize)> = None;
        for (w, s) in tasks.iter().enumerate() {
            if let Some(s) = s {
                let v = value(s);
                if best.is_none_or(|b| v > b.0) {
                    best = Some((v, w));
                }
            }
        }
        best.unwrap()
    };
    let (na, nj) = (3, 2);
    let mut motor = vec![argmax(&|s| s.rms.iter().sum()), argmax(&|s| s.total_peak)];
    for a in 0..na {
        motor.push(argmax(&|s| s.rms[a]));
        motor.push(argmax(&|s| s.peak[a]));
    }
    let mut joints = Vec::new();
    for j in 0..nj {
        joints.push(argmax(&|s| s.force_peak[j]));
        joints.push(argmax(&|s| s.moment_peak[j]));
    }
    (motor, joints)
}

proptest::proptest! {
    /// Random tables (3 actuators, 2 joints, 6 tasks, some excluded, two columns): the crate's
    /// reduction agrees with the plain one above on every value and critical task.
    #[test]
    fn reduction_agrees_with_a_plain_implementation(
        values in proptest::collection::vec(0.0f64..100.0, 6 * 2 * 11),
        ran in proptest::collection::vec(proptest::bool::weighted(0.8), 6),
        column in 0usize..2,
    ) {
        proptest::prop_assume!(ran.iter().any(|&r| r));
        let mut table = StatsTable::new(6, 2, 3, 2);
        let mut plain = Vec::new();
        for w in 0..6 {
            let stats: Vec<TaskStats> = (0..2)
                .map(|c| {
                    let v = &values[(w * 2 + c) * 11..][..11];
                    TaskStats {
                        rms: v[0..3].to_vec(),
                        peak: v[3..6].to_vec(),
                        total_peak: v[6],
                        force_peak: v[7..9].to_vec(),
                        moment_peak: v[9..11].to_vec(),
                    }
                })
                .collect();
            if ran[w] {
                table.set(w, &stats);
            }
            plain.push(ran[w].then(|| stats[column].clone()));
        }
        let actuators = ["M1", "M2", "M3"].map(String::from);
        let joints = ["J1", "J2"].map(String::from);
        let ind = reduce(&table, column, &actuators, &joints, pair);
        let (motor, joint) = plain_reduce(&plain);
        let task = |w: usize| [w, w + 10];
        proptest::prop_assert_eq!((ind.qtr, ind.qtr_task), (motor[0].0, task(motor[0].1)));
        proptest::prop_assert_eq!((ind.qit, ind.qit_task), (motor[1].0, task(motor[1].1)));
        for a in 0..3 {
            let (crt, cpt) = (motor[2 + 2 * a], motor[3 + 2 * a]);
            let got = &ind.actuators[a];
            proptest::prop_assert_eq!((got.crt_rms, got.crt), (crt.0, task(crt.1)));
            proptest::prop_assert_eq!((got.cpt_peak, got.cpt), (cpt.0, task(cpt.1)));
        }
        for j in 0..2 {
            let (f, m) = (joint[2 * j], joint[2 * j + 1]);
            let got = &ind.joints[j];
            proptest::prop_assert_eq!((got.force, got.force_task), (f.0, task(f.1)));
            proptest::prop_assert_eq!((got.moment, got.moment_task), (m.0, task(m.1)));
        }
    }
}
