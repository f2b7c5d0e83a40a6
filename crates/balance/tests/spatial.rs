//! Spatial pitch–roll arm balanced by two zero-free-length springs anchored to the base
//! (Wang & Kong 2019, "A geometric approach to the static balancing of mechanisms constructed
//! using spherical kinematic chain units", Sec. 2.2, Fig. 4(a), Appendix A3).
//!
//! # Kinematics (followed exactly)
//!
//! World frame at the joint intersection O, z vertically up, gravity −z (Appendix A). The centres
//! of mass `{a_i b_i c_i}` are given in the link frames (Eq. 2), and the paper's Appendix A3 gives
//! their world positions:
//!
//! - Eq. (A9) (printed as a second "(A8)"):
//!   `P1 = {−b1·Sθ1 + a1·Cθ1,  c1,  −a1·Sθ1 − b1·Cθ1}`;
//! - Eq. (A10): `P2 = {P2x, −b2·Cθ2 − a2·Sθ2, P2z}` with
//!   `P2x = a2·Cθ2·Cθ1 − b2·Cθ1·Sθ2 − c2·Sθ1`, `P2z = −a2·Sθ1·Cθ2 − c2·Cθ1 + b2·Sθ1·Sθ2`.
//!
//! Reading the rotations off these (they are the DH transfer matrices of Eq. 3 with twist
//! α = −90° and d = l = 0): `R1 = Rx(−π/2)·Rz(θ1)`, `R2 = R1·Rx(−π/2)·Rz(θ2)`. Joint 1 is the world
//! y axis (horizontal: pitch); joint 2 is link 1's y axis, `(−Sθ1, 0, −Cθ1)` in the world, which
//! swings in the vertical xz plane (roll). Both link origins are O. The test
//! `symbolic_poses_follow_eqs_a9_a10` checks the crate-side symbolic poses and the
//! hand-written numeric rotations against the printed Eqs. (A9)/(A10).
//!
//! # Balancing conditions
//!
//! The paper's design (Eqs. A11, A12): spring 1 from the CM of link 1 to `H1 = {0, −s, m1g/k}`,
//! spring 2 from the CM of link 2 to `H2 = {0, 0, m2g/k}`; the total energy is then the constant
//! of Eqs. (A13) + (A14). Appendix B (Eq. B5, Fig. 5(a)) generalises the link anchor to any point
//! `λ·c` on the line from O through the CM with height `h = m·g/(k·λ)` — Eq. (1), `r = (kh/mg)·b`.
//!
//! The search may return any member of the balanced family, so its witness is checked against
//! conditions that every balanced pair must satisfy, written with the lifted products
//! `W_i = K_i·a_i·b_iᵀ` (a_i on link i in link coordinates, b_i on the base in world coordinates).
//! They come from expanding `V = Σ m_i g (R_i c_i)_z + Σ (K_i/2)|R_i a_i − b_i|²`, whose
//! non-constant part is `Σ ⟨R_i, m_i g e_z c_iᵀ − b_i a_iᵀ K_i⟩`, in the independent functions
//! `Cθ1, Sθ1, Cθ2, Sθ2, Cθ1Cθ2, …` of the entries of R1 and R2 above:
//!
//! - link 2 (Eq. 1 for the two CM components normal to the roll axis, which only R2 moves):
//!   `W2[k][l] = m2·g·c2[k]·δ_{l z}` for `k ∈ {x, y}` — so with an off-axis CM the base anchor is
//!   on the vertical through O (`b2 = {0, 0, h2}`, "above the joint intersection") and
//!   `K2·h2·a2[k] = m2·g·c2[k]`;
//! - link 1 (Eq. B5 / Eq. 7 for a horizontal R joint, with the roll-axis components of link 2 —
//!   its CM `c2z` and its spring anchor `a2z`, both fixed to link 1 — as a payload of link 1,
//!   Fig. 5(b)):
//!   `W1[y][x] + W1[x][z] + W2[z][x] = m1·g·c1x` and
//!   `W1[y][z] − W1[x][x] + W2[z][z] = m1·g·c1y + m2·g·c2z`.
//!
//! The paper's own parameters satisfy them (checked below), and the components of the anchors
//! along the joint axes (`a1z`, `b1y`: the paper's free distance s) do not enter.
//!
//! # One spring is not enough
//!
//! Section 2.2 balances the pitch–roll arm with two springs; fewer springs suffice only in the
//! special cases of Eqs. (9)–(10) (CM on the joint axis, or a vertical first axis), neither of which
//! applies here. The conditions above make this precise: without spring 2, link 2's conditions
//! read `m2·g·c2x = m2·g·c2y = 0`; without spring 1, the first link-1 condition reads
//! `W2[z][x] = m1·g·c1x` while link 2's conditions force `b2x = 0`, so `m1·g·c1x = 0`. Generic
//! offsets violate both, so no single spring balances the arm. Without spring 2 the lifted
//! equations are already inconsistent (the search proves `infeasible`); without spring 1 they are
//! consistent, and only the rank-one structure `W2 = K2·a2·b2ᵀ` rules the variant out, which the
//! search cannot prove (it reports `undecided`; the test proves it from the search's relations).

use std::f64::consts::{FRAC_PI_2, PI};

use counterpoise_balance::{
    Attachment, BodyFrame, Catalogue, CatalogueOptions, MechanismEnergy, RealizationHints,
    SearchOptions, SearchReport, Status, VariantResult, search,
};
use counterpoise_symbolic::{LinearAngle, Point, PolyMat3, PolyVec3, TrigPoly, VarKind};

const G: f64 = 9.81;

type Vec3 = [f64; 3];
type Mat3 = [[f64; 3]; 3];

/// Masses and centre-of-mass offsets `{a_i b_i c_i}` (paper Eq. 2) of the two links.
#[derive(Clone, Copy, Debug)]
struct Arm {
    name: &'static str,
    m1: f64,
    c1: Vec3,
    m2: f64,
    c2: Vec3,
}

/// Arbitrary offsets, every component non-zero (not in any coordinate plane of either link).
const ARMS: [Arm; 3] = [
    Arm {
        name: "light forearm",
        m1: 2.0,
        c1: [0.12, -0.07, 0.05],
        m2: 1.5,
        c2: [0.30, 0.08, -0.11],
    },
    Arm {
        name: "heavy upper arm",
        m1: 4.5,
        c1: [-0.20, 0.15, -0.30],
        m2: 0.8,
        c2: [-0.05, 0.40, 0.22],
    },
    Arm {
        name: "long payload",
        m1: 0.6,
        c1: [0.03, 0.25, 0.40],
        m2: 3.2,
        c2: [0.18, -0.27, 0.60],
    },
];

// ---------------------------------------------------------------------------------------------
// Hand-written numeric kinematics and energy (independent of the crate's symbolic algebra and of
// its verification).

/// Eq. (A9): world position of link 1's CM.
fn paper_p1(arm: &Arm, t1: f64) -> Vec3 {
    let (s1, c1) = t1.sin_cos();
    let [a, b, c] = arm.c1;
    [-b * s1 + a * c1, c, -a * s1 - b * c1]
}

/// Eq. (A10): world position of link 2's CM.
fn paper_p2(arm: &Arm, t1: f64, t2: f64) -> Vec3 {
    let (s1, c1) = t1.sin_cos();
    let (s2, c2) = t2.sin_cos();
    let [a, b, c] = arm.c2;
    [
        a * c2 * c1 - b * c1 * s2 - c * s1,
        -b * c2 - a * s2,
        -a * s1 * c2 - c * c1 + b * s1 * s2,
    ]
}

/// `Rx(−π/2)·Rz(θ)`: the DH transfer rotation of Eq. (3) with α = −90°.
fn joint(t: f64) -> Mat3 {
    let (s, c) = t.sin_cos();
    [[c, -s, 0.0], [0.0, 0.0, 1.0], [-s, -c, 0.0]]
}

fn matmul(x: &Mat3, y: &Mat3) -> Mat3 {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| x[i][k] * y[k][j]).sum()))
}

fn apply(r: &Mat3, v: Vec3) -> Vec3 {
    std::array::from_fn(|i| (0..3).map(|k| r[i][k] * v[k]).sum())
}

fn rot1(t1: f64) -> Mat3 {
    joint(t1)
}

fn rot2(t1: f64, t2: f64) -> Mat3 {
    matmul(&joint(t1), &joint(t2))
}

/// A zero-free-length spring from `anchor_a` on link `body` (link coordinates) to `anchor_b` on
/// the base (world coordinates).
#[derive(Clone, Copy, Debug)]
struct Spring {
    body: usize,
    stiffness: f64,
    anchor_a: Vec3,
    anchor_b: Vec3,
}

/// The bodies of [`energy`]'s mechanism, in order.
const LINKS: [&str; 2] = ["pitch_link", "roll_link"];

impl From<&counterpoise_balance::Spring> for Spring {
    fn from(s: &counterpoise_balance::Spring) -> Spring {
        assert!(s.to_base(), "{s:?}");
        Spring {
            body: LINKS.iter().position(|&l| l == s.body).expect("a link"),
            stiffness: s.stiffness,
            anchor_a: s.anchor_a,
            anchor_b: s.anchor_b,
        }
    }
}

/// Gravity energy `m1·g·P1z + m2·g·P2z` from the printed Eqs. (A9)/(A10).
fn gravity_energy(arm: &Arm, t1: f64, t2: f64) -> f64 {
    arm.m1 * G * paper_p1(arm, t1)[2] + arm.m2 * G * paper_p2(arm, t1, t2)[2]
}

/// Total potential energy: gravity plus `(K/2)|R_i a − b|²` per spring.
fn total_energy(arm: &Arm, springs: &[Spring], t1: f64, t2: f64) -> f64 {
    let rotations = [rot1(t1), rot2(t1, t2)];
    let elastic: f64 = springs
        .iter()
        .map(|s| {
            let p = apply(&rotations[s.body], s.anchor_a);
            let d: Vec3 = std::array::from_fn(|k| p[k] - s.anchor_b[k]);
            0.5 * s.stiffness * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
        })
        .sum();
    gravity_energy(arm, t1, t2) + elastic
}

/// SplitMix64, so the configurations do not come from the crate under test.
struct Rng(u64);

impl Rng {
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        lo + (hi - lo) * ((z >> 11) as f64 / (1u64 << 53) as f64)
    }
}

fn configurations(count: usize, seed: u64) -> Vec<(f64, f64)> {
    let mut rng = Rng(seed);
    (0..count)
        .map(|_| (rng.uniform(-PI, PI), rng.uniform(-PI, PI)))
        .collect()
}

/// `(spread, mean)` of the total energy over 500 random configurations, with the spread relative
/// to that of the unbalanced (gravity-only) energy.
fn energy_spread(arm: &Arm, springs: &[Spring]) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    let (mut glo, mut ghi) = (f64::INFINITY, f64::NEG_INFINITY);
    let mut sum = 0.0;
    let samples = configurations(500, 0x5ba7_11a3);
    for &(t1, t2) in &samples {
        let v = total_energy(arm, springs, t1, t2);
        let g = gravity_energy(arm, t1, t2);
        (lo, hi) = (lo.min(v), hi.max(v));
        (glo, ghi) = (glo.min(g), ghi.max(g));
        sum += v;
    }
    assert!(ghi - glo > 0.1, "the unbalanced arm must not be balanced");
    ((hi - lo) / (ghi - glo), sum / samples.len() as f64)
}

// ---------------------------------------------------------------------------------------------
// The balance conditions in lifted form.

/// `W = K·a·bᵀ`, indexed `[link axis][world axis]`.
fn lifted_w(s: &Spring) -> Mat3 {
    std::array::from_fn(|k| std::array::from_fn(|l| s.stiffness * s.anchor_a[k] * s.anchor_b[l]))
}

/// Residuals of the balance conditions of the module documentation (N·m): six for link 2 (rows x
/// and y of `W2` against `m2·g·c2·e_zᵀ`), two for link 1.
fn condition_residuals(arm: &Arm, spring1: &Spring, spring2: &Spring) -> Vec<f64> {
    let (w1, w2) = (lifted_w(spring1), lifted_w(spring2));
    let mut out = Vec::new();
    for (row, c) in w2.iter().zip(arm.c2).take(2) {
        out.extend([row[0], row[1], row[2] - arm.m2 * G * c]);
    }
    out.push(w1[1][0] + w1[0][2] + w2[2][0] - arm.m1 * G * arm.c1[0]);
    out.push(w1[1][2] - w1[0][0] + w2[2][2] - arm.m1 * G * arm.c1[1] - arm.m2 * G * arm.c2[2]);
    out
}

/// Largest `m·g·|c|` of the arm: the scale of the conditions.
fn moment_scale(arm: &Arm) -> f64 {
    let norm = |c: Vec3| (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
    (arm.m1 * G * norm(arm.c1)).max(arm.m2 * G * norm(arm.c2))
}

/// The paper's design, Eqs. (A11)/(A12) generalised by Appendix B: link anchors `λ_i·c_i`, base
/// anchors `H1 = {0, −s, m1g/(k1λ1)}` and `H2 = {0, 0, m2g/(k2λ2)}`.
fn paper_springs(arm: &Arm, k: [f64; 2], lambda: [f64; 2], s: f64) -> [Spring; 2] {
    let scaled = |c: Vec3, l: f64| c.map(|x| l * x);
    [
        Spring {
            body: 0,
            stiffness: k[0],
            anchor_a: scaled(arm.c1, lambda[0]),
            anchor_b: [0.0, -s, arm.m1 * G / (k[0] * lambda[0])],
        },
        Spring {
            body: 1,
            stiffness: k[1],
            anchor_a: scaled(arm.c2, lambda[1]),
            anchor_b: [0.0, 0.0, arm.m2 * G / (k[1] * lambda[1])],
        },
    ]
}

// ---------------------------------------------------------------------------------------------
// The mechanism as the balance search sees it.

fn prune(mut m: PolyMat3) -> PolyMat3 {
    // cos(−π/2) is 6e-17, not 0: drop the residue so the monomial pattern is exact.
    m.prune(1e-15);
    m
}

fn frames() -> Vec<BodyFrame> {
    let twist = PolyMat3::rot_x(&LinearAngle::constant(-FRAC_PI_2));
    let r1 = prune(twist.mul_mat(&PolyMat3::rot_z(&LinearAngle::coordinate(0))));
    let r2 = prune(
        r1.mul_mat(&twist)
            .mul_mat(&PolyMat3::rot_z(&LinearAngle::coordinate(1))),
    );
    vec![
        BodyFrame {
            name: "pitch_link".into(),
            rotation: r1,
            origin: PolyVec3::zero(),
        },
        BodyFrame {
            name: "roll_link".into(),
            rotation: r2,
            origin: PolyVec3::zero(),
        },
    ]
}

fn mechanism(arm: &Arm) -> MechanismEnergy {
    let bodies = frames();
    let gravity = [0.0, 0.0, -G];
    let mut unbalanced = TrigPoly::zero();
    for (frame, (m, c)) in bodies.iter().zip([(arm.m1, arm.c1), (arm.m2, arm.c2)]) {
        let p = frame.origin.add(&frame.rotation.mul_const_vec(c));
        unbalanced -= &p.dot_const(gravity).scale(m);
    }
    MechanismEnergy {
        kinds: vec![VarKind::Angle, VarKind::Angle],
        ranges: vec![(-PI, PI), (-PI, PI)],
        gravity,
        bodies,
        unbalanced,
        exact: Err("built by hand with numeric coefficients".to_string()),
        surd: Err("built by hand with numeric coefficients".to_string()),
    }
}

/// Springs from each link to the base, 3-D anchors, no counterweights; at most two elements.
fn run(arm: &Arm) -> SearchReport {
    let energy = mechanism(arm);
    let options = CatalogueOptions {
        counterweight_bodies: vec![],
        counterweight_plane: None,
        spring_pairs: vec![(0, Attachment::Base), (1, Attachment::Base)],
        spring_plane: None,
    };
    let catalogue = Catalogue::build(&energy, &options);
    search(
        &energy,
        catalogue,
        SearchOptions {
            dmax: 2,
            hints: RealizationHints::default(),
        },
    )
}

fn variant<'a>(report: &'a SearchReport, labels: &[&str]) -> &'a VariantResult {
    report
        .variants
        .iter()
        .find(|v| {
            v.elements
                .iter()
                .map(|e| e.label.as_str())
                .eq(labels.iter().copied())
        })
        .unwrap_or_else(|| panic!("no variant {labels:?}"))
}

// ---------------------------------------------------------------------------------------------

#[test]
fn symbolic_poses_follow_eqs_a9_a10() {
    let bodies = frames();
    for arm in &ARMS {
        let energy = mechanism(arm);
        for (t1, t2) in configurations(50, 11) {
            let at = Point::new(&[t1, t2], &[VarKind::Angle, VarKind::Angle]);
            // the numeric rotations reproduce the printed CM positions
            let p1 = apply(&rot1(t1), arm.c1);
            let p2 = apply(&rot2(t1, t2), arm.c2);
            let (e1, e2) = (paper_p1(arm, t1), paper_p2(arm, t1, t2));
            for k in 0..3 {
                assert!((p1[k] - e1[k]).abs() < 1e-14, "{p1:?} vs Eq. A9 {e1:?}");
                assert!((p2[k] - e2[k]).abs() < 1e-14, "{p2:?} vs Eq. A10 {e2:?}");
            }
            // and so do the crate-side symbolic poses
            for (body, numeric) in bodies.iter().zip([rot1(t1), rot2(t1, t2)]) {
                let symbolic = body.rotation.eval(&at);
                for i in 0..3 {
                    for j in 0..3 {
                        assert!((symbolic[i][j] - numeric[i][j]).abs() < 1e-14);
                    }
                }
                assert_eq!(body.origin.eval(&at), [0.0; 3], "links turn about O");
            }
            let v = energy.unbalanced.eval(&at);
            assert!((v - gravity_energy(arm, t1, t2)).abs() < 1e-12);
        }
    }
    // joint 1 is horizontal (world y); joint 2 is link 1's y axis, in the vertical xz plane
    let at = Point::new(&[0.4, -1.1], &[VarKind::Angle, VarKind::Angle]);
    let axis1 = bodies[0].rotation.column(2).eval(&at);
    let axis2 = bodies[1].rotation.column(2).eval(&at);
    let y1 = bodies[0].rotation.column(1).eval(&at);
    assert!((axis1[1] - 1.0).abs() < 1e-15 && axis1[0].abs() < 1e-15 && axis1[2].abs() < 1e-15);
    assert!((0..3).all(|k| (axis2[k] - y1[k]).abs() < 1e-15) && axis2[1].abs() < 1e-15);
}

#[test]
fn paper_springs_keep_energy_constant_eqs_a13_a14() {
    for arm in &ARMS {
        // Eqs. (A11)-(A12) as printed: one stiffness k, springs on the CMs (λ = 1)
        let (k, s) = (650.0, 0.37);
        let springs = paper_springs(arm, [k, k], [1.0, 1.0], s);
        let (spread, mean) = energy_spread(arm, &springs);
        assert!(spread < 1e-9, "{}: relative spread {spread:e}", arm.name);
        let [a1, b1, c1] = arm.c1;
        let [a2, b2, c2] = arm.c2;
        let (m1, m2) = (arm.m1, arm.m2);
        let k2 = k * k;
        let v1 = (a1 * a1 * k2
            + b1 * b1 * k2
            + c1 * c1 * k2
            + G * G * m1 * m1
            + 2.0 * c1 * s * k2
            + s * s * k2)
            / (2.0 * k);
        let v2 = (a2 * a2 * k2 + b2 * b2 * k2 + c2 * c2 * k2 + G * G * m2 * m2) / (2.0 * k);
        for (t1, t2) in configurations(200, 3) {
            let v = total_energy(arm, &springs, t1, t2);
            assert!(
                (v - (v1 + v2)).abs() <= 1e-9 * (v1 + v2).abs(),
                "{}: V = {v} but Eqs. A13 + A14 give {}",
                arm.name,
                v1 + v2
            );
        }
        assert!((mean - (v1 + v2)).abs() <= 1e-9 * (v1 + v2).abs());
        let residuals = condition_residuals(arm, &springs[0], &springs[1]);
        let tol = 1e-12 * moment_scale(arm);
        assert!(residuals.iter().all(|r| r.abs() < tol), "{residuals:?}");

        // Appendix B / Fig. 5(a): any point λ·c on the line through O and the CM, height
        // m·g/(kλ), different stiffnesses, another s — still constant, still the conditions
        for (kk, lambda, s) in [
            ([420.0, 1900.0], [0.5, 1.7], -0.2),
            ([3000.0, 75.0], [2.5, 0.3], 1.1),
        ] {
            let springs = paper_springs(arm, kk, lambda, s);
            let (spread, _) = energy_spread(arm, &springs);
            assert!(spread < 1e-9, "{}: λ = {lambda:?}: {spread:e}", arm.name);
            let residuals = condition_residuals(arm, &springs[0], &springs[1]);
            assert!(residuals.iter().all(|r| r.abs() < tol), "{residuals:?}");
        }

        // and perturbing the paper's height of either spring breaks the balance (Eq. 8)
        for body in 0..2 {
            let mut wrong = paper_springs(arm, [k, k], [1.0, 1.0], s);
            wrong[body].anchor_b[2] *= 1.01;
            let (spread, _) = energy_spread(arm, &wrong);
            assert!(spread > 1e-4, "{}: body {body}: {spread:e}", arm.name);
        }
    }
}

#[test]
fn search_balances_pitch_roll_arm_with_two_base_springs() {
    for arm in &ARMS {
        let report = run(arm);
        assert_eq!(report.variants.len(), 3, "{{K10}}, {{K20}}, {{K10, K20}}");
        let v = variant(&report, &["K10", "K20"]);
        assert_eq!(
            v.status,
            Status::Balanced,
            "{}: {:?} {:?} {:#?}",
            arm.name,
            v.status,
            v.reason,
            v.relations
        );
        let verification = v.verification.expect("a balanced variant is verified");
        assert!(verification.residual < 1e-9, "{verification:?}");
        let witness = v.witness.as_ref().unwrap();
        assert!(witness.counterweights.is_empty());
        assert_eq!(witness.springs.len(), 2);
        let spring = |body: usize| -> Spring {
            Spring::from(
                witness
                    .springs
                    .iter()
                    .find(|s| s.body == LINKS[body])
                    .expect("one spring per link"),
            )
        };
        let (s1, s2) = (spring(0), spring(1));
        assert!(s1.stiffness > 0.0 && s2.stiffness > 0.0);

        // independently of the crate's verification: the witness's energy is constant
        let (spread, _) = energy_spread(arm, &[s1, s2]);
        assert!(
            spread < 1e-9,
            "{}: own relative spread {spread:e}",
            arm.name
        );

        // the closed-form conditions (Eq. 1 for link 2, Eq. B5 for link 1 with link 2's roll-axis
        // terms as payload)
        let residuals = condition_residuals(arm, &s1, &s2);
        let tol = 1e-8 * moment_scale(arm);
        assert!(
            residuals.iter().all(|r| r.abs() < tol),
            "{}: residuals {residuals:?} (tol {tol:e})",
            arm.name
        );
        // link 2's base anchor is on the vertical through the joint intersection, and
        // K2·h2·a2 = m2·g·c2 across the roll axis (Eq. 1 / A12)
        let b2 = s2.anchor_b;
        let h2 = b2[2];
        assert!(
            b2[0].abs() < 1e-8 * h2.abs() && b2[1].abs() < 1e-8 * h2.abs(),
            "{}: spring 2 not anchored on the vertical through O: {b2:?}",
            arm.name
        );
        for k in 0..2 {
            let lhs = s2.stiffness * h2 * s2.anchor_a[k];
            let rhs = arm.m2 * G * arm.c2[k];
            assert!(
                (lhs - rhs).abs() < tol,
                "{}: axis {k}: {lhs} vs {rhs}",
                arm.name
            );
        }
        // Above, not below: (a2, b2) → (−a2, −b2) leaves the spring's energy unchanged, so a
        // witness anchored below O has a mirror image anchored above it.
        let above = if h2 > 0.0 {
            s2
        } else {
            Spring {
                anchor_a: s2.anchor_a.map(|x| -x),
                anchor_b: s2.anchor_b.map(|x| -x),
                ..s2
            }
        };
        assert!(above.anchor_b[2] > 0.0);
        let (spread, _) = energy_spread(arm, &[s1, above]);
        assert!(spread < 1e-9, "{}: {spread:e}", arm.name);
        eprintln!(
            "{}: h2 = {h2:.4} m, max condition residual / scale = {:e}, own spread {spread:e}",
            arm.name,
            residuals.iter().fold(0.0f64, |m, r| m.max(r.abs())) / moment_scale(arm)
        );
    }
}

/// Lifted values `name → value` from the search's readable relations (`K20·ax·bz = 4.4145 N·m`).
fn relation_values(v: &VariantResult) -> Vec<(String, f64)> {
    v.relations
        .iter()
        .map(|r| {
            let (name, rhs) = r.split_once(" = ").expect("relation `name = value unit`");
            let value = rhs.split_whitespace().next().unwrap().parse().unwrap();
            (name.to_string(), value)
        })
        .collect()
}

#[test]
fn one_spring_alone_does_not_balance_generic_offsets() {
    const AXES: [&str; 3] = ["x", "y", "z"];
    for arm in &ARMS {
        let report = run(arm);

        // Spring on link 1 only: link 2's CM components across the roll axis cannot be balanced
        // (m2·g·c2x = m2·g·c2y = 0 would be needed): the lifted equations are inconsistent.
        let v = variant(&report, &["K10"]);
        assert_eq!(
            v.status,
            Status::Infeasible,
            "{}: {:?} {:?}",
            arm.name,
            v.status,
            v.reason
        );
        assert!(v.linear_residual > 0.1, "{}: {v:?}", arm.name);

        // Spring on link 2 only: the lifted equations are consistent and fix all eight products
        // that enter — exactly the module documentation's conditions with W1 = 0 —
        let v = variant(&report, &["K20"]);
        assert_ne!(v.status, Status::Balanced, "{}: {v:?}", arm.name);
        assert!(v.linear_residual < 1e-9, "{}: {v:?}", arm.name);
        assert_eq!((v.rank, v.nullity), (8, 8), "{}", arm.name);
        let mut w2 = [[0.0; 3]; 3];
        w2[0][2] = arm.m2 * G * arm.c2[0];
        w2[1][2] = arm.m2 * G * arm.c2[1];
        w2[2][0] = arm.m1 * G * arm.c1[0];
        w2[2][2] = arm.m1 * G * arm.c1[1] + arm.m2 * G * arm.c2[2];
        let values = relation_values(v);
        assert_eq!(values.len(), 8, "{:?}", v.relations);
        for (name, value) in &values {
            let (k, l) = (0..3)
                .flat_map(|k| (0..3).map(move |l| (k, l)))
                .find(|&(k, l)| *name == format!("K20·a{}·b{}", AXES[k], AXES[l]))
                .unwrap_or_else(|| panic!("unexpected relation {name}"));
            // the relations print four decimals
            assert!(
                (value - w2[k][l]).abs() < 1e-4,
                "{}: {name} = {value}, expected {}",
                arm.name,
                w2[k][l]
            );
        }
        // — but no physical spring has these products: W2 = K2·a2·b2ᵀ has rank one, so its
        // minor W[x][z]·W[z][x] − W[x][x]·W[z][z] vanishes, while here it is
        // m2·g·c2x · m1·g·c1x ≠ 0 (link 2's rows put b2 on the vertical through O, where the
        // roll-axis anchor a2z cannot produce the moment m1·g·c1x that link 1 needs).
        let minor = w2[0][2] * w2[2][0] - w2[0][0] * w2[2][2];
        assert!(
            minor.abs() > 1e-3 * moment_scale(arm).powi(2),
            "{}: {minor}",
            arm.name
        );
        // The crate cannot prove rank-one contradictions, so it gives up rather than proving
        // impossibility; either way the variant is not balanced.
        assert!(
            matches!(v.status, Status::Undecided | Status::Unrealizable),
            "{}: {:?} {:?}",
            arm.name,
            v.status,
            v.reason
        );
    }
}

/// Control for the previous test: the single spring fails because of the generic offset
/// `c1x ≠ 0`, not because of the search. With link 1's CM in the plane of the two joint axes
/// (`c1x = 0`), the minor above vanishes and one spring on link 2, anchored above O, carries both
/// links: `K2·h2·a2 = {m2·g·c2x, m2·g·c2y, m1·g·c1y + m2·g·c2z}` (link 1's moment enters through
/// the anchor component along the roll axis, which is fixed to link 1 — the payload idea of
/// Fig. 5(b)).
#[test]
fn one_spring_on_link_2_suffices_when_link_1_cm_is_in_the_axes_plane() {
    let arm = Arm {
        name: "link-1 CM in the plane of the joint axes",
        m1: 4.5,
        c1: [0.0, 0.15, -0.30],
        m2: 0.8,
        c2: [-0.05, 0.40, 0.22],
    };
    let report = run(&arm);
    let v = variant(&report, &["K20"]);
    assert_eq!(v.status, Status::Balanced, "{:?} {:?}", v.status, v.reason);
    assert!(v.verification.unwrap().residual < 1e-9);
    let s2 = Spring::from(&v.witness.as_ref().unwrap().springs[0]);
    let h2 = s2.anchor_b[2];
    assert!(s2.anchor_b[0].abs() < 1e-8 * h2.abs() && s2.anchor_b[1].abs() < 1e-8 * h2.abs());
    let target = [
        arm.m2 * G * arm.c2[0],
        arm.m2 * G * arm.c2[1],
        arm.m1 * G * arm.c1[1] + arm.m2 * G * arm.c2[2],
    ];
    for (a, target) in s2.anchor_a.iter().zip(target) {
        let lhs = s2.stiffness * h2 * a;
        assert!(
            (lhs - target).abs() < 1e-8 * moment_scale(&arm),
            "{lhs} vs {target}"
        );
    }
    let (spread, _) = energy_spread(&arm, &[s2]);
    assert!(spread < 1e-9, "{spread:e}");
    // the spring on link 1 alone still cannot balance link 2
    assert_eq!(variant(&report, &["K10"]).status, Status::Infeasible);
}
