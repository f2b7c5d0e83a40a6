//! The balance search on the reference palletizer (docs/palletizer.md, paper Sec. 3).

mod common;

use common::{find, palletizer, run};
use counterpoise_balance::verify::element_energy;
use counterpoise_balance::{
    Class, Counterweight, Decision, MechanismEnergy, Spring, Status, Witness, mechanism_energy,
};
use counterpoise_model::Model;
use counterpoise_model::sampling::SplitMix64;
use counterpoise_symbolic::Point;
use std::f64::consts::PI;

/// Energy spread of the unbalanced robot plus `witness` over random configurations, relative to
/// the unbalanced spread — computed here from the model's numeric poses, not by the crate.
fn relative_spread(model: &Model, energy: &MechanismEnergy, witness: &Witness, seed: u64) -> f64 {
    let mut rng = SplitMix64::new(seed);
    let (mut ub, mut total) = (Vec::new(), Vec::new());
    for _ in 0..300 {
        let q: Vec<f64> = model
            .coordinates
            .iter()
            .map(|c| rng.uniform(c.range[0], c.range[1]))
            .collect();
        let at = Point::new(&q, &model.kinds());
        let poses: Vec<_> = (0..model.bodies.len())
            .map(|i| energy.pose(i, &at))
            .collect();
        let v = energy.unbalanced.eval(&at);
        ub.push(v);
        let names: Vec<String> = model.bodies.iter().map(|b| b.name.clone()).collect();
        total.push(v + element_energy(&poses, &names, energy.gravity, witness));
    }
    let spread = |v: &[f64]| {
        v.iter().cloned().fold(f64::NEG_INFINITY, f64::max)
            - v.iter().cloned().fold(f64::INFINITY, f64::min)
    };
    spread(&total) / spread(&ub)
}

/// The paper's eleven feasible sets (Table 1), in the member numbering of palletizer.md.
const PAPER_SETS: [[&str; 2]; 11] = [
    ["m4", "m5"],
    ["m4", "m6"],
    ["K43", "K53"],
    ["K42", "K43"],
    ["K42", "K53"],
    ["m4", "K43"],
    ["m4", "K53"],
    ["m4", "K42"],
    ["m4", "K52"],
    ["m6", "K43"],
    ["m6", "K52"],
];

#[test]
fn unbalanced_energy_has_the_documented_coefficients() {
    let model = palletizer();
    let energy = mechanism_energy(&model);
    let mut terms: Vec<f64> = energy
        .unbalanced
        .terms()
        .filter(|(m, _)| !m.is_one())
        .map(|(_, c)| c)
        .collect();
    terms.sort_by(f64::total_cmp);
    assert_eq!(terms.len(), 2, "only sin θ2 and sin θ3 terms");
    assert!((terms[0] + 672.84).abs() < 0.005, "{terms:?}");
    assert!((terms[1] - 2830.49).abs() < 0.005, "{terms:?}");
}

#[test]
fn the_paper_sets_and_the_single_upper_arm_counterweight_balance() {
    let model = palletizer();
    let energy = mechanism_energy(&model);
    let report = run(&model, 2);
    // paper Eq. A8: L = 7, no base springs, Dmax = 2
    assert_eq!(report.variants.len(), 406);
    assert_eq!(report.catalogue.counts(), (7, 21));
    for set in PAPER_SETS
        .iter()
        .map(|s| s.as_slice())
        .chain([["m4"].as_slice()])
    {
        let v = find(&report, set);
        assert_eq!(v.status, Status::Balanced, "{set:?}: {:?}", v.reason);
        let verification = v
            .verification
            .expect("balanced variants carry a verification");
        assert!(verification.residual < 1e-9 && verification.samples >= 200);
        let witness = v.witness.as_ref().unwrap();
        assert!(witness.counterweights.iter().all(|c| c.mass > 0.0));
        assert!(witness.springs.iter().all(|s| s.stiffness > 0.0));
        let independent = relative_spread(&model, &energy, witness, 0xabc);
        assert!(
            independent < 1e-9,
            "{set:?}: independent spread {independent:e}"
        );
        assert!(!v.relations.is_empty());
    }
    // m4 alone: the sin θ2 term fixes the mass (the upper-arm origin B rides on the vertical slider)
    let m4 = find(&report, &["m4"]);
    let cw = &m4.witness.as_ref().unwrap().counterweights[0];
    assert_eq!(m4.nullity, 0);
    // independent closed form from palletizer.md: g·α2 = −672.84 is cancelled by m·g·δ1 sin θ2
    // (B = (δ3, ρ3), ρ3 = δ2 + δ1 sin θ2 − δ4 sin θ3) ⇒ m = 672.84 / (9.81·0.3)
    assert!((cw.mass - 672.843375 / (9.81 * 0.3)).abs() < 1e-6, "{cw:?}");
}

#[test]
fn a_lone_upper_arm_to_slider_spring_is_proven_unrealizable() {
    // K42 alone: balance fixes a = (1/4, 0) (the spring's |d|² term), K·b = (0, β_y) and the
    // required K·(a×b); a rank-one spring then misses K·(a×b) by a fixed multiple of K, which is
    // exactly the sin θ3 coefficient of V_UB (2830.49 N·m) that the spring would have to cancel.
    let model = palletizer();
    let report = run(&model, 1);
    let k42 = find(&report, &["K42"]);
    assert_eq!(k42.status, Status::Unrealizable, "{k42:?}");
    assert_eq!(k42.decision, Decision::Exact);
    let reason = k42.reason.as_deref().unwrap();
    // The certificate quotes the residual exactly: `K·W − α·βᵀ = -N/D (…)·K`, zero only at K = 0.
    assert!(reason.contains("zero only at K = 0 N/m"), "{reason}");
    let fraction = reason
        .split("K·W − α·βᵀ = ")
        .nth(1)
        .and_then(|rest| rest.split(' ').next())
        .unwrap_or_else(|| panic!("no residual in {reason}"));
    let (num, den) = fraction.split_once('/').expect("an exact fraction");
    let value = num.parse::<f64>().unwrap() / den.parse::<f64>().unwrap();
    // palletizer.md: V_UB = −672.843·sin θ2 + 2830.492·sin θ3 (three decimals).
    assert!((value + 2830.492).abs() < 5e-4, "{value}");
}

fn polar(r: f64, angle: f64) -> [f64; 3] {
    [r * angle.cos(), r * angle.sin(), 0.0]
}

fn cw(model: &Model, body: &str, mass: f64, r_mm: f64, phi: f64) -> Counterweight {
    assert!(model.body_index(body).is_some(), "{body}");
    Counterweight {
        label: format!("m on {body}"),
        body: body.into(),
        mass,
        offset: polar(r_mm * 1e-3, phi),
        plane: None,
    }
}

#[allow(clippy::too_many_arguments)]
fn spring(
    model: &Model,
    i: &str,
    s: &str,
    k: f64,
    a: f64,
    alpha: f64,
    b: f64,
    beta: f64,
) -> Spring {
    assert!(
        model.body_index(i).is_some() && model.body_index(s).is_some(),
        "{i} {s}"
    );
    Spring {
        label: format!("K {i}–{s}"),
        body: i.into(),
        other: s.into(),
        stiffness: k * 1e3,
        anchor_a: polar(a * 1e-3, alpha),
        anchor_b: polar(b * 1e-3, beta),
        plane: None,
    }
}

#[test]
fn the_paper_table_1_parameters_balance_the_model_to_table_precision() {
    // Paper Table 1 (m kg, r mm, φ rad; K N/mm, a mm, α rad, b mm, β rad), a second, independent
    // check of the model and of the element energy conventions: the published four-digit values
    // leave a residual of table precision, far above 1e-9 but far below a wrong model.
    let model = palletizer();
    let energy = mechanism_energy(&model);
    let (ua, fa, rl, sv, sh) = (
        "upper_arm",
        "front_link",
        "rear_link",
        "slider_v",
        "slider_h",
    );
    let sets: Vec<(&str, Witness)> = vec![
        (
            "SB1",
            Witness {
                counterweights: vec![
                    cw(&model, ua, 228.6, 81.3, 0.0),
                    cw(&model, fa, 500.0, 500.0, PI),
                ],
                springs: vec![],
            },
        ),
        (
            "SB2",
            Witness {
                counterweights: vec![
                    cw(&model, ua, 384.7, 500.0, PI),
                    cw(&model, rl, 234.2, 500.0, 0.0),
                ],
                springs: vec![],
            },
        ),
        (
            "SB3",
            Witness {
                counterweights: vec![],
                springs: vec![
                    spring(&model, ua, sv, 5.669, 998.9, 0.0, 499.9, PI / 2.0),
                    spring(&model, fa, sv, 4.486, 250.0, PI, 499.9, PI / 2.0),
                ],
            },
        ),
        (
            "SB4",
            Witness {
                counterweights: vec![],
                springs: vec![
                    spring(&model, ua, sh, 5.000, 250.0, 0.0, 448.5, 1.5 * PI),
                    spring(&model, ua, sv, 5.711, 995.6, 0.0, 497.8, PI / 2.0),
                ],
            },
        ),
        // SB5 {K42, K53} is left out: its published values (K 4.898 and 7.143 N/mm, a 476.9 and
        // 264.1 mm, b 271.1 and 499.8 mm) leave a relative spread of 0.23 or more under every
        // reading of the angles and of the row order of the extracted table, so they cannot be
        // checked against this model. The search itself finds {K42, K53} balanced (test above).
        (
            "SB6",
            Witness {
                counterweights: vec![cw(&model, ua, 228.6, 347.1, 0.0)],
                springs: vec![spring(&model, ua, sv, 6.334, 989.0, 0.0, 486.7, PI / 2.0)],
            },
        ),
        (
            "SB7",
            Witness {
                counterweights: vec![cw(&model, ua, 418.1, 440.1, PI)],
                springs: vec![spring(&model, fa, sv, 4.228, 250.0, PI, 439.0, 1.5 * PI)],
            },
        ),
        (
            "SB8",
            Witness {
                counterweights: vec![cw(&model, ua, 384.7, 500.0, PI)],
                springs: vec![spring(&model, ua, sh, 3.064, 250.0, 0.0, 500.0, PI / 2.0)],
            },
        ),
        (
            "SB9",
            Witness {
                counterweights: vec![cw(&model, ua, 228.6, 402.3, 0.0)],
                springs: vec![spring(&model, fa, sh, 7.930, 800.0, 0.0, 500.0, PI / 2.0)],
            },
        ),
        (
            "SB10",
            Witness {
                counterweights: vec![cw(&model, rl, 181.5, 77.8, PI)],
                springs: vec![spring(&model, ua, sv, 5.727, 994.0, 0.0, 497.0, PI / 2.0)],
            },
        ),
        (
            "SB11",
            Witness {
                counterweights: vec![cw(&model, rl, 500.0, 163.0, 0.0)],
                springs: vec![spring(&model, fa, sh, 7.077, 800.0, 0.0, 500.0, PI / 2.0)],
            },
        ),
    ];
    let spreads: Vec<(&str, f64)> = sets
        .iter()
        .map(|(name, witness)| (*name, relative_spread(&model, &energy, witness, 0x5eb)))
        .collect();
    for (name, spread) in &spreads {
        assert!(*spread < 5e-3, "{name}: relative spread {spread:e}");
    }
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    let model = palletizer();
    let in_pool = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let report = pool.install(|| run(&model, 2));
        serde_json::to_string(&report.variants).unwrap()
    };
    assert_eq!(in_pool(1), in_pool(2));
}

/// Classes by counting (paper Eqs. A6–A8, L = 7, no base springs): 7 counterweights and
/// C(7, 2) = 21 springs give, at Dmax 2, C(7,1) + C(7,2) = 28 counterweight-only variants,
/// C(21,1) + C(21,2) = 231 spring-only ones and 7·21 = 147 hybrids (28 + 231 + 147 = 406).
#[test]
fn variant_classes_and_per_class_counts_follow_the_combinatorics() {
    let report = run(&palletizer(), 2);
    assert_eq!(report.catalogue.counts(), (7, 21));
    let expected = [
        (Class::Counterweights, 28),
        (Class::Springs, 231),
        (Class::Hybrid, 147),
    ];
    for (class, count) in expected {
        let members = report.variants.iter().filter(|v| v.class == class).count();
        assert_eq!(members, count, "{class:?}");
        // The per-status counts of a class add up to the class, whatever the verdicts.
        let by_status: usize = Status::SEARCH_VERDICTS
            .iter()
            .map(|&s| report.count_class(s, class))
            .sum();
        assert_eq!(by_status, count, "{class:?}");
    }
    // And the per-class counts of a status add up to that status's count (pinned, for these
    // verdicts, against an independent exact computation in tests/exact_decision.rs).
    for status in Status::SEARCH_VERDICTS {
        let by_class: usize = expected
            .iter()
            .map(|&(c, _)| report.count_class(status, c))
            .sum();
        assert_eq!(by_class, report.count(status), "{status:?}");
    }
    // One variant of each class, named by hand.
    assert_eq!(find(&report, &["m4", "m5"]).class, Class::Counterweights);
    assert_eq!(find(&report, &["K43", "K53"]).class, Class::Springs);
    assert_eq!(find(&report, &["m4", "K43"]).class, Class::Hybrid);
    assert_eq!(find(&report, &["m4"]).class, Class::Counterweights);
    assert_eq!(find(&report, &["K43"]).class, Class::Springs);
}
