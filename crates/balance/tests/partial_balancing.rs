//! Partial balancing with counterweights and springs (`counterpoise_balance::partial`) against
//! values found without it: closed forms worked out by hand on the pendulum, the gravity
//! torques of every design recomputed from the model's kinematics (Jacobians and spring forces,
//! not the energy polynomials the search differentiates), and dense normal equations over
//! those independent torques.

mod common;

use std::sync::OnceLock;

use common::model_of;
use counterpoise_balance::partial::{
    CounterweightLimits, ElementLimits, PartialDesign, PartialOptions, PartialReport, SpringLimits,
    TorqueBasis, Workspace, candidate_entries, counterweight_entries, partial_search,
};
use counterpoise_balance::{Attachment, Catalogue, catalogue_options, mechanism_energy};
use counterpoise_model::{Kinematics, Model};
use nalgebra::{DMatrix, DVector, Vector3};

const G: f64 = 9.81;

fn case(name: &str) -> serde_json::Value {
    let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../cases")
        .join(name);
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// `n` equally spaced values from `from` to `to`.
fn spaced(from: f64, to: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| from + (to - from) * i as f64 / (n - 1) as f64)
        .collect()
}

/// Every combination of the per-coordinate values (first coordinate slowest).
fn grid(axes: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let mut points = vec![Vec::new()];
    for values in axes {
        points = points
            .iter()
            .flat_map(|p: &Vec<f64>| {
                values.iter().map(move |&v| {
                    let mut p = p.clone();
                    p.push(v);
                    p
                })
            })
            .collect();
    }
    points
}

/// A mechanism at configurations `qs` with what every search on them shares: the catalogue
/// and the torque basis (the costly part), built once for all the searches of a test, and once
/// per test binary for the pendulum, which four tests search (see [`pendulum`]).
struct Setup {
    model: Model,
    qs: Vec<Vec<f64>>,
    catalogue: Catalogue,
    basis: TorqueBasis,
}

impl Setup {
    fn new(model: Model, qs: Vec<Vec<f64>>) -> Setup {
        Setup::with(model, qs, false)
    }

    /// The torque basis of the counterweights, and of the springs with `springs`.
    fn with(model: Model, qs: Vec<Vec<f64>>, springs: bool) -> Setup {
        let energy = mechanism_energy(&model);
        let catalogue = Catalogue::build(&energy, &catalogue_options(&model));
        let workspace = Workspace::new(&model, &qs);
        assert_eq!(workspace.len(), qs.len(), "every point regular");
        let wanted = candidate_entries(&catalogue, springs);
        let basis = TorqueBasis::build(&energy, &catalogue, &workspace, &wanted);
        Setup {
            model,
            qs,
            catalogue,
            basis,
        }
    }

    /// The search, every counterweight bounded by `limits`.
    fn search(
        &self,
        limits: CounterweightLimits,
        budget: usize,
        joints: Vec<usize>,
    ) -> PartialReport {
        self.search_with(limits, PartialOptions::new(budget, joints))
    }

    /// [`Self::search`] with every option given.
    fn search_with(&self, limits: CounterweightLimits, options: PartialOptions) -> PartialReport {
        let cws = counterweight_entries(&self.catalogue);
        let bounds: Vec<_> = (0..self.catalogue.len())
            .map(|e| {
                cws.contains(&e)
                    .then_some(ElementLimits::Counterweight(limits))
            })
            .collect();
        partial_search(&self.catalogue, &self.basis, &bounds, &options).unwrap()
    }

    /// The search over the entries labelled in `entries` with their bounds (the others left
    /// out).
    fn search_entries(
        &self,
        entries: &[(&str, ElementLimits)],
        budget: usize,
        joints: Vec<usize>,
    ) -> PartialReport {
        let bounds: Vec<Option<ElementLimits>> = self
            .catalogue
            .entries
            .iter()
            .map(|e| {
                entries
                    .iter()
                    .find(|(label, _)| *label == e.label)
                    .map(|(_, l)| *l)
            })
            .collect();
        assert_eq!(
            bounds.iter().flatten().count(),
            entries.len(),
            "every label in the catalogue"
        );
        let options = PartialOptions::new(budget, joints);
        partial_search(&self.catalogue, &self.basis, &bounds, &options).unwrap()
    }
}

/// No box on any anchor coordinate.
const FREE: [[f64; 2]; 3] = [[f64::NEG_INFINITY, f64::INFINITY]; 3];

fn spring_limits(stiffness: [f64; 2], anchor_a: [f64; 2], anchor_b: [f64; 2]) -> ElementLimits {
    ElementLimits::Spring(SpringLimits {
        stiffness,
        anchor_a,
        anchor_b,
        box_a: FREE,
        box_b: FREE,
    })
}

/// The pendulum of `cases/pendulum.json` at 7 angles from −1.5 to 1.5 rad (a grid symmetric
/// about 0), set up once for the tests that search it.
fn pendulum() -> &'static Setup {
    static SETUP: OnceLock<Setup> = OnceLock::new();
    SETUP.get_or_init(|| {
        let qs = spaced(-1.5, 1.5, 7).into_iter().map(|t| vec![t]).collect();
        Setup::new(model_of(&case("pendulum.json")), qs)
    })
}

/// The mean of `cos² θ` over the pendulum's angles.
fn pendulum_mean_cos2() -> f64 {
    let qs = &pendulum().qs;
    qs.iter().map(|q| q[0].cos().powi(2)).sum::<f64>() / qs.len() as f64
}

/// Static actuator forces at `q` from the model's kinematics: every body with its payloads that
/// count in the balance, plus point masses `(body, m, r)`, each needing the world wrench
/// `F = −m g`, `N_o = (R c) × F`; `Q_q = Σ J_vᵀ F + J_ωᵀ N_o`, `Q_u = G⁻ᵀ Q_q`.
fn static_forces(model: &Model, q: &[f64], extra: &[(usize, f64, Vector3<f64>)]) -> DVector<f64> {
    static_forces_with(model, q, extra, &[])
}

/// A zero-free-length spring for [`static_forces_with`]: `(body, a, other, b, K)`.
type SpringForce = (usize, Vector3<f64>, Attachment, Vector3<f64>, f64);

/// [`static_forces`] with zero-free-length springs `(body, a, other, b, K)` too: the spring
/// pulls its anchor on `body` (world `p_A = p_i + R_i a`) with `−K(p_A − p_B)`, so holding it
/// needs `F = K(p_A − p_B)` applied at `p_A` (the moment `(R_i a) × F` about the body origin),
/// and `−F` at `p_B` on the other body (nothing on the base).
/// The index of a body the design names.
fn body(model: &Model, name: &str) -> usize {
    model.body_index(name).expect("a body of the model")
}

fn static_forces_with(
    model: &Model,
    q: &[f64],
    extra: &[(usize, f64, Vector3<f64>)],
    springs: &[SpringForce],
) -> DVector<f64> {
    let kin = Kinematics::new(model);
    let qv = DVector::from_column_slice(q);
    let g = model.gravity;
    // (body, point in the body frame, world force needed there)
    let mut forces: Vec<(usize, Vector3<f64>, Vector3<f64>)> = Vec::new();
    for (i, b) in model.bodies.iter().enumerate() {
        forces.push((i, b.com, -g * b.mass));
    }
    for p in model.payloads.iter().filter(|p| p.in_balance) {
        forces.push((p.body, p.com, -g * p.mass));
    }
    for &(body, m, c) in extra {
        forces.push((body, c, -g * m));
    }
    for &(body, a, other, b, k) in springs {
        let pose = kin.body_pose(body, &qv);
        let p_a = pose.position + pose.rotation * a;
        let p_b = match other {
            Attachment::Base => b,
            Attachment::Body(s) => {
                let other = kin.body_pose(s, &qv);
                other.position + other.rotation * b
            }
        };
        let force = (p_a - p_b) * k;
        forces.push((body, a, force));
        if let Attachment::Body(s) = other {
            forces.push((s, b, -force));
        }
    }
    let mut generalized = DVector::zeros(q.len());
    for (body, c, force) in forces {
        let pose = kin.body_pose(body, &qv);
        let jac = kin.body_jacobian(body, &qv);
        let moment = (pose.rotation * c).cross(&force);
        generalized += jac.linear.transpose() * force + jac.angular.transpose() * moment;
    }
    let jacobian = kin.actuator_jacobian(&qv);
    jacobian.transpose().lu().solve(&generalized).unwrap()
}

/// Per actuator, the RMS over `qs` of the static forces with the design's counterweights and
/// springs.
fn recomputed_rms(model: &Model, qs: &[Vec<f64>], design: &PartialDesign) -> Vec<f64> {
    let extra: Vec<_> = design
        .counterweights
        .iter()
        .map(|c| (body(model, &c.body), c.mass, Vector3::from(c.offset)))
        .collect();
    let springs: Vec<_> = design
        .springs
        .iter()
        .map(|p| {
            let s = &p.spring;
            let other = if s.to_base() {
                Attachment::Base
            } else {
                Attachment::Body(body(model, &s.other))
            };
            (
                body(model, &s.body),
                Vector3::from(s.anchor_a),
                other,
                Vector3::from(s.anchor_b),
                s.stiffness,
            )
        })
        .collect();
    let mut sum = vec![0.0; model.actuators.len()];
    for q in qs {
        let f = static_forces_with(model, q, &extra, &springs);
        for (s, v) in sum.iter_mut().zip(f.iter()) {
            *s += v * v;
        }
    }
    sum.iter().map(|s| (s / qs.len() as f64).sqrt()).collect()
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + a.abs().max(b.abs()))
}

/// Pendulum of `cases/pendulum.json`: rod of 2 kg with its centre of mass at 0.5 m, gravity
/// −9.81 y, so `τ = 9.81·cos θ`; a counterweight with moment `μ` adds `9.81(μx cos θ − μy sin θ)`.
/// On a grid symmetric about 0, `Σ cos θ sin θ = 0`, so the mean square is
/// `9.81²[(1 + μx)² mean cos² + μy² mean sin²]`: with `|μ| ≤ r_hi·m_hi < 1` the optimum is
/// `μ = (−r_hi·m_hi, 0)` and the RMS `9.81(1 − r_hi·m_hi)·√(mean cos²)`.
#[test]
fn pendulum_with_the_radius_bound_active_matches_the_closed_form() {
    let setup = pendulum();
    let mean_cos2 = pendulum_mean_cos2();
    let report = setup.search(
        CounterweightLimits {
            mass: [0.0, 2.0],
            radius: [0.0, 0.25],
        },
        1,
        vec![0],
    );
    assert!(close(report.unbalanced_total, G * mean_cos2.sqrt(), 1e-12));
    let best = &report.designs[0];
    let cw = &best.counterweights[0];
    // m·r = (−0.5, 0): m at its bound 2 kg, r = (−0.25, 0) m.
    assert!(close(cw.mass, 2.0, 1e-6), "{}", cw.mass);
    assert!(close(cw.offset[0], -0.25, 1e-6), "{:?}", cw.offset);
    assert!(cw.offset[1].abs() < 1e-6, "{:?}", cw.offset);
    let expected = G * 0.5 * mean_cos2.sqrt();
    assert!(
        close(best.total_rms, expected, 1e-6),
        "{} vs {expected}",
        best.total_rms
    );
    assert!(best.lower_bound <= best.total_rms * (1.0 + 1e-6));
    assert!(
        close(best.lower_bound, expected, 1e-5),
        "{}",
        best.lower_bound
    );
    // The torque recomputed from the model's kinematics with that counterweight.
    let rms = recomputed_rms(&setup.model, &setup.qs, best);
    assert!(
        close(rms[0], best.rms[0], 1e-9),
        "{rms:?} vs {:?}",
        best.rms
    );
}

/// With room for `m·r = (−1, 0)` the pendulum balances: zero residual.
#[test]
fn pendulum_balances_when_the_bounds_allow_it() {
    let report = pendulum().search(
        CounterweightLimits {
            mass: [0.0, 4.0],
            radius: [0.0, 1.0],
        },
        1,
        vec![0],
    );
    let best = &report.designs[0];
    assert!(
        best.total_rms < 1e-6 * report.unbalanced_total,
        "{}",
        best.total_rms
    );
    let cw = &best.counterweights[0];
    assert!(close(cw.mass * cw.offset[0], -1.0, 1e-6), "{cw:?}");
    // The lightest of the balancing designs: m·|r| = 1 with |r| ≤ 1 m needs m ≥ 1 kg.
    assert!(close(cw.mass, 1.0, 1e-4), "{cw:?}");
    assert!(close(cw.offset[0], -1.0, 1e-4), "{cw:?}");
}

/// A counterweight the torque cannot see (on the 6-axis arm's shoulder, which turns about the
/// vertical through its own origin) is left out: `m1 + m2` is `m2` with `m1` unused, at the
/// same residual.
#[test]
fn a_counterweight_that_does_nothing_is_left_out() {
    let setup = Setup::new(
        model_of(&case("arm6.json")),
        grid(&[
            vec![0.0],
            spaced(-3.1, 3.1, 5),
            spaced(-3.1, 3.1, 5),
            vec![0.0],
            vec![0.0],
            vec![0.0],
        ]),
    );
    let limits = CounterweightLimits {
        mass: [0.0, 30.0],
        radius: [0.0, 0.5],
    };
    let report = setup.search(limits, 2, vec![1, 2]);
    let find = |labels: &[&str]| {
        report
            .designs
            .iter()
            .find(|d| d.labels == labels)
            .unwrap()
            .clone()
    };
    let alone = find(&["m2"]);
    let pair = find(&["m1", "m2"]);
    assert_eq!(pair.unused, ["m1"]);
    assert_eq!(pair.counterweights[0].mass, 0.0);
    assert!(close(pair.total_rms, alone.total_rms, 1e-6));
    // ranked after the smaller set with the same residual
    let rank = |labels: &[&str]| report.designs.iter().position(|d| d.labels == labels);
    assert!(rank(&["m2"]) < rank(&["m1", "m2"]));
}

/// A radius lower bound (non-convex): mass fixed at 3 kg, `|r| ∈ [0.5, 1]`, so `|μ| ≥ 1.5`
/// while balance needs `μ = (−1, 0)`. Over the annulus the mean square is
/// `(1 + μx)² Σcos² + μy² Σsin²` (× 9.81²/7); at `|μ| = 1.5` along −x it is `0.25·Σcos²`
/// (0.78 on this grid), and any point off the axis pays more `Σsin²` (3.87, against
/// `Σcos²` = 3.13): the optimum is `μ = (−1.5, 0)`, RMS `9.81·0.5·√(mean cos²)`. The convex
/// relaxation (balance, 0) is the lower bound.
#[test]
fn pendulum_radius_lower_bound_is_met_along_the_convex_direction() {
    let setup = pendulum();
    let mean_cos2 = pendulum_mean_cos2();
    let report = setup.search(
        CounterweightLimits {
            mass: [3.0, 3.0],
            radius: [0.5, 1.0],
        },
        1,
        vec![0],
    );
    let best = &report.designs[0];
    let cw = &best.counterweights[0];
    assert!(close(cw.mass, 3.0, 1e-6));
    assert!(close(cw.offset[0], -0.5, 1e-6), "{:?}", cw.offset);
    assert!(best.note.is_some());
    assert!(close(best.total_rms, G * 0.5 * mean_cos2.sqrt(), 1e-6));
    assert!(best.lower_bound < 1e-3, "{}", best.lower_bound);
}

/// The two-link arm of `cases/two_link.json`: link 2 with its tool (2.5 kg at 0.3 m, 1 kg at
/// 0.6 m) needs `m2·r2 = (−1.35, 0)` to take all gravity torque off the elbow. Naming the
/// elbow alone, `m2` does exactly that; naming the shoulder alone the answer changes, and
/// lowers the shoulder's torque below what the elbow's design leaves.
#[test]
fn two_link_joint_selection_changes_the_design() {
    let setup = Setup::new(
        model_of(&case("two_link.json")),
        grid(&[spaced(-1.0, 1.0, 7), spaced(-1.5, 1.5, 7)]),
    );
    let (model, qs) = (&setup.model, &setup.qs);
    let limits = CounterweightLimits {
        mass: [0.0, 20.0],
        radius: [0.0, 1.0],
    };
    let elbow = setup.search(limits, 1, vec![1]);
    let best = &elbow.designs[0];
    assert_eq!(best.labels, ["m2"]);
    assert!(
        best.rms[1] < 1e-6 * elbow.unbalanced_rms[1],
        "{:?}",
        best.rms
    );
    let cw = &best.counterweights[0];
    assert!(close(cw.mass * cw.offset[0], -1.35, 1e-6), "{cw:?}");
    assert!((cw.mass * cw.offset[1]).abs() < 1e-6, "{cw:?}");

    let shoulder = setup.search(limits, 1, vec![0]);
    let best_shoulder = &shoulder.designs[0];
    assert!(
        best_shoulder.rms[0] < best.rms[0] * 0.9,
        "shoulder {:?} vs elbow's design {:?}",
        best_shoulder.rms,
        best.rms
    );
    // Each design recomputed from the kinematics.
    for d in [best, best_shoulder] {
        let rms = recomputed_rms(model, qs, d);
        for (a, b) in rms.iter().zip(&d.rms) {
            assert!(close(*a, *b, 1e-9), "{rms:?} vs {:?}", d.rms);
        }
    }
    // Both joints, two elements: the whole arm balances (m1 takes the shoulder's rest).
    let both = setup.search(limits, 2, vec![0, 1]);
    assert!(both.designs[0].total_rms < 1e-6 * both.unbalanced_total);
    assert_eq!(both.designs[0].labels, ["m1", "m2"]);
}

/// The conic optimum against dense normal equations over torques computed independently (per
/// unit mass and per unit moment, from the kinematics), on the 6-axis arm of `cases/arm6.json`
/// with the shoulder and elbow named: the conic residual is never below the unconstrained
/// least-squares one, and equal to it when the conic design is strictly inside its bounds.
#[test]
fn arm6_conic_optimum_matches_the_normal_equations() {
    // shoulder_lift and elbow over their task range, the first wrist at two values.
    let setup = Setup::new(
        model_of(&case("arm6.json")),
        grid(&[
            vec![0.3],
            spaced(-3.1, 3.1, 7),
            spaced(-3.1, 3.1, 7),
            vec![-1.0, 0.5],
            vec![0.0],
            vec![0.0],
        ]),
    );
    let (model, qs) = (&setup.model, &setup.qs);
    let joints = vec![1, 2];
    let limits = CounterweightLimits {
        mass: [0.0, 1e3],
        radius: [0.0, 10.0],
    };
    // The least residual alone: the lightest design of the same residual is on the bounds.
    let report = setup.search_with(
        limits,
        PartialOptions {
            lightest: false,
            ..PartialOptions::new(2, joints.clone())
        },
    );
    let unbalanced: Vec<DVector<f64>> = qs.iter().map(|q| static_forces(model, q, &[])).collect();
    let mut checked = 0;
    for design in &report.designs {
        // Columns: per counterweight, m at the origin and unit moments along x, y, z.
        let mut columns: Vec<Vec<f64>> = Vec::new();
        for c in &design.counterweights {
            for r in [Vector3::zeros(), Vector3::x(), Vector3::y(), Vector3::z()] {
                let mut col = Vec::new();
                for (q, ub) in qs.iter().zip(&unbalanced) {
                    let f = static_forces(model, q, &[(body(model, &c.body), 1.0, r)]) - ub;
                    col.extend(joints.iter().map(|&j| f[j]));
                }
                columns.push(col);
            }
        }
        let rows = qs.len() * joints.len();
        // Unit mass at r is m + μ: the moment columns are the differences.
        let a = DMatrix::from_fn(rows, columns.len(), |r, c| {
            if c % 4 == 0 {
                columns[c][r]
            } else {
                columns[c][r] - columns[c - c % 4][r]
            }
        });
        let b = DVector::from_iterator(
            rows,
            unbalanced
                .iter()
                .flat_map(|ub| joints.iter().map(move |&j| -ub[j])),
        );
        // Normal equations AᵀA x = Aᵀb, with a pseudo-inverse for the columns that do
        // nothing (a mass on a fixed point, a moment along a joint axis).
        let ata = a.transpose() * &a;
        let atb = a.transpose() * &b;
        let x = ata.clone().pseudo_inverse(1e-10 * ata.amax()).unwrap() * atb;
        let residual = ((&a * &x) - &b).norm() / (qs.len() as f64).sqrt();
        // The conic design strictly inside its bounds: then it is a minimum of the
        // unconstrained convex quadratic too, so both methods must reach the same residual.
        let inside = design.counterweights.iter().all(|c| {
            let r = c.offset.iter().map(|v| v * v).sum::<f64>().sqrt();
            c.mass > 1e-3 && c.mass < 1e3 * (1.0 - 1e-6) && r < 10.0 * (1.0 - 1e-6)
        });
        assert!(
            design.total_rms >= residual * (1.0 - 1e-6) - 1e-9,
            "{:?}: {} < {residual}",
            design.labels,
            design.total_rms
        );
        if inside {
            assert!(
                close(design.total_rms, residual, 1e-6),
                "{:?}: conic {} vs normal equations {residual}",
                design.labels,
                design.total_rms
            );
            checked += 1;
        }
        let rms = recomputed_rms(model, qs, design);
        for j in &joints {
            assert!(
                close(rms[*j], design.rms[*j], 1e-9),
                "{rms:?} vs {:?} {design:?}",
                design.rms
            );
        }
    }
    // m2 + m3 and m1 + m2 (the shoulder's counterweight sits on the axis and is free).
    assert!(checked >= 2, "only {checked} sets had an interior optimum");
    assert_eq!(setup.catalogue.counts().0, 6);
}

/// The ranking is by total residual, and the answer does not depend on the thread count.
#[test]
fn ranking_is_ordered_and_thread_independent() {
    let model = model_of(&case("two_link.json"));
    let qs = grid(&[spaced(-1.0, 1.0, 5), spaced(-1.5, 1.5, 5)]);
    let limits = CounterweightLimits {
        mass: [0.0, 2.0],
        radius: [0.0, 0.3],
    };
    let many = Setup::new(model.clone(), qs.clone()).search(limits, 2, vec![0, 1]);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    // the set-up too on one thread: the torque basis is built in parallel
    let one = pool.install(|| Setup::new(model, qs).search(limits, 2, vec![0, 1]));
    assert_eq!(many.designs.len(), 3);
    for w in many.designs.windows(2) {
        assert!(w[0].total_rms <= w[1].total_rms);
    }
    for (a, b) in many.designs.iter().zip(&one.designs) {
        assert_eq!(a.labels, b.labels);
        assert_eq!(a.total_rms.to_bits(), b.total_rms.to_bits());
    }
    // Bounds respected by every design.
    for d in &many.designs {
        for c in &d.counterweights {
            let r = c.offset.iter().map(|v| v * v).sum::<f64>().sqrt();
            assert!(c.mass <= 2.0 * (1.0 + 1e-7) && c.mass >= -1e-9, "{c:?}");
            assert!(r <= 0.3 * (1.0 + 1e-6), "{c:?}");
        }
    }
}

/// A mass bound of zero allows no counterweight: every one is reported unused and the residual
/// is the unbalanced torque.
#[test]
fn a_zero_mass_bound_leaves_the_mechanism_as_it_is() {
    let report = pendulum().search(
        CounterweightLimits {
            mass: [0.0, 0.0],
            radius: [0.0, 0.0],
        },
        1,
        vec![0],
    );
    let best = &report.designs[0];
    assert_eq!(best.unused, ["m1"]);
    assert_eq!(best.counterweights[0].mass, 0.0);
    assert_eq!(best.counterweights[0].offset, [0.0; 3]);
    assert!(close(best.total_rms, report.unbalanced_total, 1e-12));
}

/// The pendulum of [`pendulum`] with the torque basis of its spring `K10` too.
fn pendulum_with_springs() -> &'static Setup {
    static SETUP: OnceLock<Setup> = OnceLock::new();
    SETUP.get_or_init(|| {
        let qs = spaced(-1.5, 1.5, 7).into_iter().map(|t| vec![t]).collect();
        Setup::with(model_of(&case("pendulum.json")), qs, true)
    })
}

/// `a × b` (z) and `a · b` in the plane.
fn cross_dot(a: &[f64; 3], b: &[f64; 3]) -> (f64, f64) {
    (a[0] * b[1] - a[1] * b[0], a[0] * b[0] + a[1] * b[1])
}

fn norm(v: &[f64; 3]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// The pendulum (2 kg at 0.5 m: `τ = 9.81 cos θ`) with the spring `K10`, anchor a on the rod and
/// anchor b on the base: `V = ½K|R(θ)a − b|² = const − K·bᵀR(θ)a`, and `bᵀR(θ)a =
/// |a||b| sin(θ + φ)` with `φ` the angle from b's direction to a's plus 90°; the torque is
/// `−K|a||b|(cos φ cos θ − sin φ sin θ)`. On the symmetric grid the `sin θ` part only adds, so
/// the best spring has `φ = 0` (b a quarter turn ahead of a: straight above the pivot for a
/// along the rod) and the largest `K|a||b|` up to `m g l = 9.81`. With `K ≤ 100 N/m`,
/// `|a| ≤ 0.1 m`, `|b| ≤ 0.5 m` that is 5 N·m: the residual RMS is `(9.81 − 5)·√(mean cos²)`,
/// 49.0 % of the unbalanced torque, and the spring's own torque `5·√(mean cos²)`. In the plane
/// the relaxation (the nuclear norm of `W`) is exact, so the design is certified.
#[test]
fn pendulum_spring_below_balance_matches_the_closed_form() {
    let setup = pendulum_with_springs();
    let mean_cos = pendulum_mean_cos2().sqrt();
    let report = setup.search_entries(
        &[("K10", spring_limits([0.0, 100.0], [0.0, 0.1], [0.0, 0.5]))],
        1,
        vec![0],
    );
    let best = &report.designs[0];
    assert_eq!(best.labels, ["K10"]);
    let expected = (G - 5.0) * mean_cos;
    assert!(
        close(best.total_rms, expected, 1e-6),
        "{} vs {expected}",
        best.total_rms
    );
    assert!(close(
        best.total_rms / report.unbalanced_total,
        (G - 5.0) / G,
        1e-6
    ));
    let (s, torque_rms) = (&best.springs[0].spring, best.springs[0].torque_rms);
    assert!(s.to_base(), "{s:?}");
    // every bound active: only K = 100 N/m, |a| = 0.1 m, |b| = 0.5 m give 5 N·m
    assert!(close(s.stiffness, 100.0, 1e-5), "{s:?}");
    assert!(close(norm(&s.anchor_a), 0.1, 1e-5), "{s:?}");
    assert!(close(norm(&s.anchor_b), 0.5, 1e-5), "{s:?}");
    let (cross, dot) = cross_dot(&s.anchor_a, &s.anchor_b);
    assert!(close(cross, 0.05, 1e-5) && dot.abs() < 1e-6, "{s:?}");
    assert!(close(torque_rms, 5.0 * mean_cos, 1e-5), "{s:?}");
    assert!(best.certified, "{best:?}");
    assert!(best.lower_bound <= best.total_rms * (1.0 + 1e-9));
    assert!(close(best.lower_bound, expected, 1e-5), "{best:?}");
    // the torque recomputed from the kinematics and the spring's force
    let rms = recomputed_rms(&setup.model, &setup.qs, best);
    assert!(
        close(rms[0], best.rms[0], 1e-9),
        "{rms:?} vs {:?}",
        best.rms
    );
    assert!(close(rms[0], expected, 1e-6), "{rms:?}");
}

/// With `|a| ≤ 0.2 m` the spring can give 10 N·m ≥ 9.81: the pendulum balances, and the
/// lightest (least stiff) balancing spring has `K·0.2·0.5 = 9.81`, `K = 98.1 N/m`.
#[test]
fn pendulum_spring_balances_when_the_bounds_allow_it() {
    let setup = pendulum_with_springs();
    let report = setup.search_entries(
        &[("K10", spring_limits([0.0, 100.0], [0.0, 0.2], [0.0, 0.5]))],
        1,
        vec![0],
    );
    let best = &report.designs[0];
    assert!(best.total_rms < 1e-6 * report.unbalanced_total, "{best:?}");
    assert!(best.certified);
    let s = &best.springs[0].spring;
    let (cross, _) = cross_dot(&s.anchor_a, &s.anchor_b);
    assert!(close(s.stiffness * cross, G, 1e-6), "{s:?}");
    assert!(close(s.stiffness, 98.1, 1e-4), "{s:?}");
    let rms = recomputed_rms(&setup.model, &setup.qs, best);
    assert!(rms[0] < 1e-6 * report.unbalanced_total, "{rms:?}");
}

/// The two-link arm with its counterweights and springs, two elements: on every set the
/// relaxation's bound is at most the design's residual, every design is within its bounds,
/// its torques recomputed from the kinematics and spring forces agree, and the ranking is the
/// same bits on one thread.
#[test]
fn two_link_springs_bound_below_and_recomputed() {
    let model = model_of(&case("two_link.json"));
    let qs = grid(&[spaced(-1.0, 1.0, 5), spaced(-1.5, 1.5, 5)]);
    let cw = ElementLimits::Counterweight(CounterweightLimits {
        mass: [0.0, 2.0],
        radius: [0.0, 0.3],
    });
    let spring = spring_limits([10.0, 200.0], [0.05, 0.3], [0.0, 0.2]);
    let search = |setup: &Setup| {
        let entries: Vec<(&str, ElementLimits)> = setup
            .catalogue
            .entries
            .iter()
            .map(|e| {
                let l = if e.label.starts_with('m') { cw } else { spring };
                (e.label.as_str(), l)
            })
            .collect();
        setup.search_entries(&entries, 2, vec![0, 1])
    };
    let setup = Setup::with(model.clone(), qs.clone(), true);
    let report = search(&setup);
    let (cws, springs) = setup.catalogue.counts();
    assert!(springs >= 3, "{springs} springs");
    let n = cws + springs;
    assert_eq!(report.designs.len(), n + n * (n - 1) / 2);
    let mut with_springs = 0;
    for d in &report.designs {
        assert!(
            d.lower_bound <= d.total_rms * (1.0 + 1e-6) + 1e-9,
            "{:?}: bound {} above {}",
            d.labels,
            d.lower_bound,
            d.total_rms
        );
        for s in d.springs.iter().map(|p| &p.spring) {
            with_springs += 1;
            assert!(
                (10.0 * (1.0 - 1e-7)..=200.0 * (1.0 + 1e-7)).contains(&s.stiffness),
                "{s:?}"
            );
            let (a, b) = (norm(&s.anchor_a), norm(&s.anchor_b));
            assert!(
                (0.05 * (1.0 - 1e-6)..=0.3 * (1.0 + 1e-6)).contains(&a),
                "{s:?}"
            );
            assert!(b <= 0.2 * (1.0 + 1e-6), "{s:?}");
        }
        let rms = recomputed_rms(&model, &qs, d);
        for (x, y) in rms.iter().zip(&d.rms) {
            assert!(
                close(*x, *y, 1e-9),
                "{:?}: {rms:?} vs {:?}",
                d.labels,
                d.rms
            );
        }
    }
    assert!(with_springs > 0);
    for w in report.designs.windows(2) {
        assert!(w[0].total_rms <= w[1].total_rms);
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let one = pool.install(|| search(&Setup::with(model, qs, true)));
    for (a, b) in report.designs.iter().zip(&one.designs) {
        assert_eq!(a.labels, b.labels);
        assert_eq!(a.total_rms.to_bits(), b.total_rms.to_bits());
    }
}

/// The palletizer's springs-only variant `K42 + K43` balances exactly (the balance search's
/// `balanced`, and `run` finds it feasible within the case's bounds: K ∈ [1000, 10000] N/m,
/// |a| ∈ [0.25, 1] m, |b| ≤ 0.5 m), so within those bounds the partial search reaches no
/// residual on any joint; either spring alone does not.
#[test]
fn palletizer_spring_pair_balances_within_the_bounds() {
    let json = common::palletizer_json();
    let model = model_of(&json);
    let qs = grid(&[vec![0.5], spaced(0.0, 1.6, 5), spaced(0.2, 2.0, 5)]);
    let setup = Setup::with(model, qs, true);
    let l = spring_limits([1000.0, 10000.0], [0.25, 1.0], [0.0, 0.5]);
    let report = setup.search_entries(&[("K42", l), ("K43", l)], 2, vec![0, 1, 2]);
    let best = &report.designs[0];
    assert_eq!(best.labels, ["K42", "K43"]);
    assert!(
        best.total_rms < 1e-5 * report.unbalanced_total,
        "{} of {}",
        best.total_rms,
        report.unbalanced_total
    );
    assert!(best.certified);
    let rms = recomputed_rms(&setup.model, &setup.qs, best);
    for r in &rms {
        assert!(*r < 1e-5 * report.unbalanced_total, "{rms:?}");
    }
    for d in &report.designs[1..] {
        assert!(d.total_rms > 1e-2 * report.unbalanced_total, "{d:?}");
    }
}
