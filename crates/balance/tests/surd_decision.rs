//! The exact decision over ℚ(√2, √3): a three-chain leg whose chains are 120° apart
//! (cos = −1/2, sin = √3/2) and a chain tilted by 45° take the exact path, with hand-derived
//! verdicts, and the exact and numeric paths agree on random multiples of π/12.

mod common;

use std::path::PathBuf;

use common::{find, labels, model_of, run};
use counterpoise_balance::{
    Catalogue, Decision, SearchOptions, SearchReport, Status, catalogue_options, mechanism_energy,
    realization_hints, search,
};
use counterpoise_model::Model;
use counterpoise_model::sampling::SplitMix64;

fn leg_json() -> serde_json::Value {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/three_chain_leg.json");
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The search with the exact fields withheld: the numeric path on the same mechanism.
fn run_numeric(model: &Model, dmax: usize) -> SearchReport {
    let mut energy = mechanism_energy(model);
    energy.exact = Err("withheld by the test".into());
    energy.surd = Err("withheld by the test".into());
    let catalogue = Catalogue::build(&energy, &catalogue_options(model));
    search(
        &energy,
        catalogue,
        SearchOptions {
            dmax,
            hints: realization_hints(model),
        },
    )
}

fn inter_chain_spring(label: &str) -> bool {
    // K21, K31, K32: springs between two chains (K10, K20, K30 go to the base).
    label.starts_with('K') && !label.ends_with('0')
}

/// By hand: chain k's potential is `m g 0.25 sin q_k` in its own angle only, so a set balances
/// only if every chain carries one of its own elements (its counterweight `mk` or its base
/// spring `Kk0`; a pendulum is balanced by either). Among counterweights and base springs at
/// Dmax 3 that is one element per chain: 2³ = 8 sets, all realizable; the other 41 − 8 = 33
/// leave a chain without an element and are infeasible. None may stay undecided.
#[test]
fn the_120_degree_leg_is_decided_exactly_over_the_surd_field() {
    let model = model_of(&leg_json());
    let energy = mechanism_energy(&model);
    let reason = energy.exact.as_ref().unwrap_err();
    assert!(reason.contains("π/2"), "{reason}");
    assert!(energy.surd.is_ok(), "{:?}", energy.surd.as_ref().err());
    let report = run(&model, 3);
    assert_eq!(report.variants.len(), 9 + 36 + 84);
    assert!(
        report
            .variants
            .iter()
            .all(|v| v.decision == Decision::Exact)
    );
    let simple: Vec<_> = report
        .variants
        .iter()
        .filter(|v| !labels(v).iter().any(|l| inter_chain_spring(l)))
        .collect();
    assert_eq!(simple.len(), 6 + 15 + 20);
    let realizable = simple
        .iter()
        .filter(|v| matches!(v.status, Status::Balanced | Status::Degenerate))
        .count();
    let infeasible = simple
        .iter()
        .filter(|v| v.status == Status::Infeasible)
        .count();
    assert_eq!((realizable, infeasible), (8, 33));
    // m·r_x·g·sin q cancels 1.2·9.81·0.25·sin q: m·r_x = −0.3 kg·m on every chain, the √3 of
    // chains 2 and 3 cancelling exactly.
    let all_masses = find(&report, &["m1", "m2", "m3"]);
    assert_eq!(all_masses.status, Status::Balanced);
    for k in 1..=3 {
        let relation = format!("m{k}·r{k}x = -3/10 (-0.3) kg·m");
        assert!(
            all_masses.relations.contains(&relation),
            "{:?}",
            all_masses.relations
        );
    }
    assert_eq!(
        find(&report, &["K10", "K20", "K30"]).status,
        Status::Balanced
    );
}

/// m1 + K32: chain 1 by its counterweight, chains 2 and 3 by one spring between them. The cross
/// terms `cos q2 cos q3`, … come from K32 alone; with the chains' x axes 120° apart
/// (e₂·e₃ = −1/2) they force, by hand, `−½ax·bx + az·bz = 0`, `−½ax·bz − az·bx = 0`,
/// `−½az·bx − ax·bz = 0`, `−½az·bz + ax·bx = 0` (the x–z block of K·a·bᵀ), whose only solution
/// is that block zero: a's x, z or b's x, z vanish, and then K32 cannot torque chain 3 (or 2).
#[test]
fn a_spring_between_two_chains_cannot_balance_both() {
    let report = run(&model_of(&leg_json()), 2);
    let v = find(&report, &["m1", "K32"]);
    assert_eq!(v.status, Status::Unrealizable, "{:?}", v.reason);
    let reason = v.reason.as_deref().unwrap();
    assert!(
        reason.starts_with("K32: balance makes K·a_i·b_j = 0 for i ∈ {x, z}, j ∈ {x, z}"),
        "{reason}"
    );
    assert!(reason.contains("with a's x, z zero, the balance equations have no solution"));
}

/// A chain tilted by 45°: `rot_x(pi/4)` then `rot_y(q)`, CoM 0.25 m along x. Its height is
/// `−0.25 sin q · cos 45°`, so V = −1.2·9.81·0.25·(√2/2)·sin q and a counterweight balances it
/// with m·r_x = −0.3 kg·m, m·r_z = 0 (the √2/2 divides out).
#[test]
fn a_chain_at_45_degrees_is_exact_over_the_surd_field() {
    check_tilted_chain("pi/4");
}

/// The same chain with its tilt written `atan2(1, 1)`, and as `atan2` of field numbers
/// (`atan2(2*sin(pi/4), 2*cos(pi/4))` = atan2(√2, √2)): the same angle π/4 by hand, so the same
/// exact decision and relations.
#[test]
fn a_tilt_written_as_atan2_of_field_numbers_is_exact() {
    check_tilted_chain("atan2(1, 1)");
    check_tilted_chain("atan2(2*sin(pi/4), 2*cos(pi/4))");
}

/// A tilt whose cosine is outside ℚ(√2, √3), `atan2(1, 2)` (cos = 2/√5), takes the numeric path
/// with a reason naming the pose and the field.
#[test]
fn a_tilt_outside_the_field_is_refused_naming_the_field() {
    // R_x(t)·(0, 1, 0) = (0, cos t, sin t) ∥ (0, 2, 1).
    let model = model_of(&tilted_chain_about(
        "atan2(1, 2)",
        serde_json::json!([0, 2, 1]),
    ));
    let energy = mechanism_energy(&model);
    let reason = energy.surd.as_ref().unwrap_err();
    assert!(reason.starts_with("bodies[0].pose"), "{reason}");
    assert!(
        reason.contains("ℚ(√2, √3)") && reason.contains("√(5)"),
        "{reason}"
    );
    assert_eq!(run(&model, 1).variants[0].decision, Decision::Numeric);
}

/// One link tilted by `tilt` about x, then turning about its y axis; the joint axis is given for
/// a tilt of π/4 unless `axis` says otherwise.
fn tilted_chain(tilt: &str) -> serde_json::Value {
    tilted_chain_about(tilt, serde_json::json!([0, "cos(pi/4)", "sin(pi/4)"]))
}

fn tilted_chain_about(tilt: &str, axis: serde_json::Value) -> serde_json::Value {
    let mut case = leg_json();
    case["bodies"] = serde_json::json!([
        { "name": "link1", "parent": "base",
          "pose": [ { "rot_x": tilt }, { "rot_y": "q1" } ],
          "mass": 1.2, "com": [0.25, 0, 0], "inertia": [0.001, 0.01, 0.01, 0, 0, 0] }
    ]);
    case["coordinates"] = serde_json::json!([
        { "name": "q1", "kind": "angle", "range": [-1.5, 1.5] }
    ]);
    case["joints"] = serde_json::json!([
        { "name": "J1", "kind": "revolute", "bodies": ["base", "link1"], "point": [0, 0, 0],
          "axis": axis }
    ]);
    case["actuators"] = serde_json::json!([
        { "name": "M1", "joint": "J1", "coordinate": "q1", "ratio": 0.01 }
    ]);
    case
}

fn check_tilted_chain(tilt: &str) {
    let model = model_of(&tilted_chain(tilt));
    let energy = mechanism_energy(&model);
    assert!(energy.exact.is_err());
    assert!(energy.surd.is_ok());
    let report = run(&model, 2);
    let m1 = find(&report, &["m1"]);
    assert_eq!(m1.decision, Decision::Exact);
    assert_eq!(m1.status, Status::Balanced);
    assert!(
        m1.relations
            .contains(&"m1·r1x = -3/10 (-0.3) kg·m".to_string()),
        "{:?}",
        m1.relations
    );
    assert!(m1.relations.contains(&"m1·r1z = 0 kg·m".to_string()));
    assert!(
        report
            .variants
            .iter()
            .all(|v| v.status != Status::Undecided)
    );
}

/// Property: on legs whose chains sit at random multiples of π/12 (random tilts and CoMs too),
/// the exact path over ℚ(√2, √3) and the numeric path never contradict each other: where the
/// numeric path reaches a verdict it is the exact one (a numeric witness is verified by sampling
/// the energy, so it also checks every exact proof of unrealizability).
#[test]
fn exact_and_numeric_paths_agree_on_random_twelfths() {
    let mut rng = SplitMix64::new(2026);
    let mut compared = 0;
    for _ in 0..3 {
        let mut case = leg_json();
        for b in 0..3 {
            let turn = (rng.next_u64() % 24) as i64 - 12;
            let tilt = (rng.next_u64() % 5) as i64 - 2;
            let com = 0.1 + 0.05 * (rng.next_u64() % 5) as f64;
            case["bodies"][b]["pose"] = serde_json::json!([
                { "rot_z": format!("{turn}*pi/12") },
                { "translate": [0.3, 0, 0] },
                { "rot_x": format!("{tilt}*pi/12") },
                { "rot_y": format!("q{}", b + 1) }
            ]);
            case["bodies"][b]["com"] = serde_json::json!([com, 0, 0]);
            // The joint in base axes: point R_z(θ)·(0.3, 0, 0), axis R_z(θ)·R_x(φ)·(0, 1, 0).
            let (t, p) = (format!("{turn}*pi/12"), format!("{tilt}*pi/12"));
            case["joints"][b]["point"] =
                serde_json::json!([format!("0.3*cos({t})"), format!("0.3*sin({t})"), 0]);
            case["joints"][b]["axis"] = serde_json::json!([
                format!("-sin({t})*cos({p})"),
                format!("cos({t})*cos({p})"),
                format!("sin({p})")
            ]);
        }
        let model = model_of(&case);
        let exact = run(&model, 2);
        let numeric = run_numeric(&model, 2);
        for (e, n) in exact.variants.iter().zip(&numeric.variants) {
            assert_eq!(labels(e), labels(n));
            assert_eq!(e.decision, Decision::Exact);
            assert_eq!(n.decision, Decision::Numeric);
            if e.status == Status::Undecided || n.status == Status::Undecided {
                continue;
            }
            compared += 1;
            assert_eq!(
                e.status,
                n.status,
                "{:?} in {}: exact {:?}, numeric {:?}",
                labels(e),
                case["bodies"],
                e.reason,
                n.reason
            );
        }
    }
    assert!(compared >= 3 * 30, "only {compared} verdicts compared");
}

/// A spherical 3R chain, each axis tilted 45° from the previous one, with counterweights and
/// every spring (base springs too) at Dmax 3: exact over ℚ(√2, √3) with nothing undecided, and
/// the numeric path on the same mechanism contradicts none of its verdicts (its verified
/// witnesses would expose a wrong proof of unrealizability, its exact-consistency facts a wrong
/// infeasibility).
#[test]
fn the_spherical_chain_is_decided_with_nothing_undecided() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/spherical_3r.json");
    let case: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let model = model_of(&case);
    let exact = run(&model, 3);
    assert_eq!(exact.variants.len(), 129);
    assert!(exact.variants.iter().all(|v| v.decision == Decision::Exact));
    let undecided: Vec<_> = exact
        .variants
        .iter()
        .filter(|v| v.status == Status::Undecided)
        .map(labels)
        .collect();
    assert!(undecided.is_empty(), "{undecided:?}");
    // Three masses, one per link, balance any serial chain (each counterweight cancels its
    // link's first moment, the chain's own and those of the links it carries).
    assert_eq!(find(&exact, &["m1", "m2", "m3"]).status, Status::Balanced);
    let numeric = run_numeric(&model, 3);
    let mut compared = 0;
    for (e, n) in exact.variants.iter().zip(&numeric.variants) {
        if n.status != Status::Undecided {
            compared += 1;
            assert_eq!(
                e.status,
                n.status,
                "{:?}: {:?} / {:?}",
                labels(e),
                e.reason,
                n.reason
            );
        }
    }
    // The 110 infeasible sets and the balanced ones at least are decided numerically too.
    assert!(compared >= 120, "only {compared} numeric verdicts");
}

/// The leg's potential energy written out by hand from the case file, independent of the
/// crate's formulas: chain k's frame has origin `p_k = 0.3·(cos θ_k, sin θ_k, 0)` and rotation
/// `R_k = R_z(θ_k)·R_y(q_k)` (θ = 0, 120°, −120°), its link 1.2 kg at (0.25, 0, 0); gravity
/// 9.81 along −z; a counterweight adds `m g z`, a spring `K/2·|p_i + R_i a − p_j − R_j b|²` (the
/// base: `p = 0`, `R = I`).
fn leg_energy(witness: &counterpoise_balance::Witness, q: &[f64; 3]) -> f64 {
    // The chains of tests/data/three_chain_leg.json, by name.
    let chain = |name: &str| {
        ["link1", "link2", "link3"]
            .iter()
            .position(|&l| l == name)
            .unwrap()
    };
    let theta = [
        0.0,
        2.0 * std::f64::consts::PI / 3.0,
        -2.0 * std::f64::consts::PI / 3.0,
    ];
    let frame = |k: usize, x: [f64; 3]| -> [f64; 3] {
        let (sq, cq) = q[k].sin_cos();
        // R_y(q): (x, y, z) ↦ (x cos q + z sin q, y, −x sin q + z cos q).
        let (u, v, w) = (x[0] * cq + x[2] * sq, x[1], -x[0] * sq + x[2] * cq);
        let (st, ct) = theta[k].sin_cos();
        [0.3 * ct + u * ct - v * st, 0.3 * st + u * st + v * ct, w]
    };
    let g = 9.81;
    let mut energy: f64 = (0..3)
        .map(|k| 1.2 * g * frame(k, [0.25, 0.0, 0.0])[2])
        .sum();
    for c in &witness.counterweights {
        energy += c.mass * g * frame(chain(&c.body), c.offset)[2];
    }
    for s in &witness.springs {
        let a = frame(chain(&s.body), s.anchor_a);
        let b = if s.to_base() {
            s.anchor_b
        } else {
            frame(chain(&s.other), s.anchor_b)
        };
        let d2: f64 = (0..3).map(|i| (a[i] - b[i]).powi(2)).sum();
        energy += 0.5 * s.stiffness * d2;
    }
    energy
}

/// The five sets with springs between chains that the witness search once left undecided
/// (`m1 + K21 + K31`, …) are realizable, by hand: a spring whose anchor sits on another chain's
/// joint axis (a point that never moves) acts on its own chain like a base spring, and a base
/// spring balances a pendulum (`−K·d·a_z = m g 0.25` with `d` the anchor's horizontal offset).
/// E.g. m3 + K31 + K32: K31 and K32 anchored on chain 3's axis balance chains 1 and 2, m3
/// balances chain 3. Each must end balanced with a witness whose energy, evaluated by
/// [`leg_energy`] at random poses, is constant to 1e-9 of the unbalanced energy's spread; and
/// the whole leg at Dmax 3 leaves nothing undecided.
#[test]
fn the_leg_s_inter_chain_sets_are_realized_by_anchors_on_a_joint_axis() {
    let report = run(&model_of(&leg_json()), 3);
    let undecided: Vec<_> = report
        .variants
        .iter()
        .filter(|v| v.status == Status::Undecided)
        .map(|v| (labels(v), v.reason.clone()))
        .collect();
    assert!(undecided.is_empty(), "{undecided:?}");
    let mut rng = SplitMix64::new(120);
    let poses: Vec<[f64; 3]> = (0..64)
        .map(|_| std::array::from_fn(|_| rng.uniform(-1.5, 1.5)))
        .collect();
    let bare = counterpoise_balance::Witness::default();
    let spread = |f: &dyn Fn(&[f64; 3]) -> f64| {
        let values: Vec<f64> = poses.iter().map(f).collect();
        let max = values.iter().cloned().fold(f64::MIN, f64::max);
        let min = values.iter().cloned().fold(f64::MAX, f64::min);
        max - min
    };
    let unbalanced = spread(&|q| leg_energy(&bare, q));
    assert!(unbalanced > 1.0, "{unbalanced}"); // 2.94 J amplitude per chain
    for set in [
        ["m1", "K21", "K31"],
        ["m2", "K21", "K32"],
        ["m2", "K31", "K32"],
        ["m3", "K31", "K32"],
        ["K10", "K21", "K31"],
    ] {
        let v = find(&report, &set);
        assert_eq!(v.status, Status::Balanced, "{set:?}: {:?}", v.reason);
        let w = v
            .witness
            .as_ref()
            .expect("a balanced variant has a witness");
        assert_eq!(w.counterweights.len() + w.springs.len(), 3);
        let left = spread(&|q| leg_energy(w, q));
        assert!(left <= 1e-9 * unbalanced, "{set:?}: spread {left:e} J");
    }
}
