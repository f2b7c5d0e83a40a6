//! Edge cases of the Phase 3 indicators and the ranking, each against a value written out by
//! hand or a fixed external name (the results.json schema, the report's class headings).

use std::cmp::Ordering;

use counterpoise_report::ranking::compare_at;
use counterpoise_report::{
    Class, IndicatorError, JointReaction, RankItem, RankingError, RankingOptions, delta_r, rank,
};

fn joint(name: &str, force: f64, moment: f64) -> JointReaction {
    JointReaction {
        name: name.into(),
        force,
        moment,
    }
}

#[test]
fn negative_or_infinite_reactions_are_errors() {
    // A peak reaction is a magnitude: finite and ≥ 0, in either set, force or moment.
    let ok = [joint("J1", 10.0, 1.0)];
    for bad in [-1.0, f64::INFINITY, f64::NEG_INFINITY, f64::NAN] {
        for (ub, sb) in [
            ([joint("J1", bad, 1.0)], ok.clone()),
            (ok.clone(), [joint("J1", 10.0, bad)]),
        ] {
            let err = delta_r(&ub, &sb).unwrap_err();
            assert!(
                matches!(err, IndicatorError::NotFinite { .. }),
                "{bad}: {err:?}"
            );
        }
    }
    // zero is a valid magnitude
    assert_eq!(delta_r(&[joint("J1", 0.0, 0.0)], &ok).unwrap().value, 0.0);
}

#[test]
fn joint_lists_must_match_in_length_and_names() {
    let two = [joint("J1", 1.0, 1.0), joint("J2", 1.0, 1.0)];
    let one = [joint("J1", 1.0, 1.0)];
    assert!(matches!(
        delta_r(&two, &one),
        Err(IndicatorError::JointMismatch { .. })
    ));
    assert!(matches!(
        delta_r(&one, &two),
        Err(IndicatorError::JointMismatch { .. })
    ));
    let swapped = [joint("J2", 1.0, 1.0), joint("J1", 1.0, 1.0)];
    assert!(matches!(
        delta_r(&two, &swapped),
        Err(IndicatorError::JointMismatch { .. })
    ));
}

#[test]
fn class_names_are_the_results_json_schema() {
    // docs/results-schema.md: "class" is `counterweights`, `springs` or `hybrid`; the serialised
    // form and the name used in CSV must agree with it.
    let expected = ["counterweights", "springs", "hybrid"];
    for (class, name) in Class::ALL.into_iter().zip(expected) {
        assert_eq!(class.name(), name);
        assert_eq!(serde_json::to_value(class).unwrap(), name);
    }
    // the report headings: the paper's three classes (Sec. 2.3: "only-counterweights,
    // only-springs and hybrid"), worded as the README's tables show them
    let titles: Vec<&str> = Class::ALL.iter().map(|c| c.title()).collect();
    assert_eq!(titles, ["Counterweights only", "Springs only", "Hybrid"]);
}

#[test]
fn compare_at_compares_cells_of_the_resolution_grid() {
    // Resolution 0.5: a value's cell is round(v / 0.5), half-way away from zero. Worked by
    // hand with values exact in binary:
    // 1.0 → 2, 1.2 → 2.4 → 2: same cell, a tie.
    assert_eq!(compare_at(1.0, 1.2, 0.5), Ordering::Equal);
    // 1.0 → 2, 1.5 → 3: one resolution apart, a difference, either way round.
    assert_eq!(compare_at(1.0, 1.5, 0.5), Ordering::Less);
    assert_eq!(compare_at(1.5, 1.0, 0.5), Ordering::Greater);
    // 1.2 → 2 and 1.3 → 2.6 → 3: only 0.1 apart but on either side of 1.25, the half-way
    // point between 1.0 and 1.5, so the lower value wins (the stated price of a fixed grid).
    assert_eq!(compare_at(1.2, 1.3, 0.5), Ordering::Less);
    // 0.75 → 1.5 → 2 (away from zero), the same cell as 1.0; likewise −0.75 and −1.0 (−2).
    assert_eq!(compare_at(0.75, 1.0, 0.5), Ordering::Equal);
    assert_eq!(compare_at(-0.75, -1.0, 0.5), Ordering::Equal);
    // −0.2 → −0.4 → −0 and 0.2 → 0.4 → 0: the zero cell is one cell, whatever the sign.
    assert_eq!(compare_at(-0.2, 0.2, 0.5), Ordering::Equal);
    // Resolution 0: exact.
    assert_eq!(compare_at(2.0, 2.0, 0.0), Ordering::Equal);
    assert_eq!(compare_at(2.0, 2.0 + 1e-15, 0.0), Ordering::Less);
}

#[test]
fn resolution_must_be_finite_and_not_negative() {
    for bad in [f64::INFINITY, f64::NAN, -0.5] {
        assert!(matches!(
            rank(
                &[],
                &RankingOptions {
                    resolution: bad,
                    ..Default::default()
                }
            ),
            Err(RankingError::BadResolution(_))
        ));
    }
    let item = |dqtr, dqit, dr| RankItem {
        key: "x".into(),
        class: Class::Springs,
        dqtr,
        dqit,
        dr,
    };
    for (k, bad) in [
        item(f64::INFINITY, 0.0, 0.0),
        item(0.0, f64::NAN, 0.0),
        item(0.0, 0.0, f64::NEG_INFINITY),
    ]
    .into_iter()
    .enumerate()
    {
        let err = rank(&[bad], &RankingOptions::default()).unwrap_err();
        let criterion = ["ΔQTR", "ΔQIT", "ΔR"][k];
        assert!(
            matches!(err, RankingError::NotFinite { criterion: c, .. } if c == criterion),
            "{err:?}"
        );
    }
}

#[test]
fn class_ranks_count_each_class_separately() {
    // Global order by ΔQTR: h1 (−60), c1 (−50), s1 (−40), c2 (−30), h2 (−20), s2 (−10).
    // Within each class: counterweights c1 = 1, c2 = 2; springs s1 = 1, s2 = 2; hybrid
    // h1 = 1, h2 = 2.
    let item = |key: &str, class, dqtr| RankItem {
        key: key.into(),
        class,
        dqtr,
        dqit: 0.0,
        dr: 0.0,
    };
    let items = [
        item("s2", Class::Springs, -10.0),
        item("c1", Class::Counterweights, -50.0),
        item("h2", Class::Hybrid, -20.0),
        item("s1", Class::Springs, -40.0),
        item("c2", Class::Counterweights, -30.0),
        item("h1", Class::Hybrid, -60.0),
    ];
    let r = rank(&items, &RankingOptions::default()).unwrap();
    assert_eq!(r.order, [5, 1, 3, 4, 2, 0]);
    assert_eq!(r.rank, [6, 2, 5, 3, 4, 1]);
    assert_eq!(r.class_rank, [2, 1, 2, 1, 2, 1]);
    assert!(r.tie_groups.is_empty());
}
