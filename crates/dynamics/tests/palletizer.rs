//! The palletizer against independent derivations: the Lagrangian by finite differences, the
//! static actuator forces as ∂V/∂u, whole-mechanism balance of the joint reactions, their
//! minimum-norm property against an SVD null space, and the time-reversal symmetry.

mod common;

use common::case;
use counterpoise_dynamics::runner::Workspace;
use counterpoise_dynamics::{Evaluator, ParameterSet};
use counterpoise_model::sampling::SplitMix64;
use counterpoise_model::{Kinematics, Model, PayloadMode};
use counterpoise_symbolic::Point;
use nalgebra::{DVector, Matrix3, Vector3};

fn rot(m: &counterpoise_symbolic::PolyMat3, at: &Point) -> Matrix3<f64> {
    Matrix3::from_fn(|i, j| m.0[i][j].eval(at))
}

fn vec3(v: &counterpoise_symbolic::PolyVec3, at: &Point) -> Vector3<f64> {
    Vector3::from_fn(|i, _| v.0[i].eval(at))
}

/// Kinetic energy from the symbolic pose polynomials: `Σ ½ m |ṗ_c|² + ½ ω_bᵀ I_c ω_b`.
fn kinetic(model: &Model, q: &[f64], qd: &[f64]) -> f64 {
    let kinds = model.kinds();
    let at = model.point(q);
    let mut t = 0.0;
    for b in &model.bodies {
        let r = rot(&b.rotation, &at);
        let mut rd = Matrix3::zeros();
        let mut vc = Vector3::zeros();
        for k in 0..q.len() {
            let rk = rot(&b.rotation.derivative(k, kinds[k]), &at);
            let pk = vec3(&b.origin.derivative(k, kinds[k]), &at);
            rd += rk * qd[k];
            vc += (pk + rk * b.com) * qd[k];
        }
        let w = rd * r.transpose();
        let wb = r.transpose() * Vector3::new(w[(2, 1)], w[(0, 2)], w[(1, 0)]);
        t += 0.5 * b.mass * vc.norm_squared() + 0.5 * wb.dot(&(b.inertia_com * wb));
    }
    t
}

fn potential(model: &Model, q: &[f64]) -> f64 {
    model
        .potential_energy(PayloadMode::All)
        .eval(&model.point(q))
}

fn random_state(model: &Model, rng: &mut SplitMix64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let q = model
        .coordinates
        .iter()
        .map(|c| {
            let m = c.midpoint();
            let h = 0.3 * (c.range[1] - c.range[0]);
            rng.uniform(m - h, m + h)
        })
        .collect();
    let qd = (0..model.dof()).map(|_| rng.uniform(-1.0, 1.0)).collect();
    let qdd = (0..model.dof()).map(|_| rng.uniform(-2.0, 2.0)).collect();
    (q, qd, qdd)
}

#[test]
fn generalized_forces_match_the_lagrangian() {
    let model = case("palletizer");
    let ev = Evaluator::new(&model).unwrap();
    let params = ParameterSet::unbalanced(&model);
    let n = model.dof();
    let mut rng = SplitMix64::new(7);
    for _ in 0..6 {
        let (q, qd, qdd) = random_state(&model, &mut rng);
        let view = ev.at_state(&q, &qd, &qdd, &params, &[0], false).unwrap();
        let ours = &view.chart_force[0];
        // ∂T/∂q̇_k by central differences (T is exactly quadratic in q̇).
        let dt_dqd = |q: &[f64], qd: &[f64], k: usize| {
            let d = 1e-3;
            let mut p = qd.to_vec();
            let mut m = qd.to_vec();
            p[k] += d;
            m[k] -= d;
            (kinetic(&model, q, &p) - kinetic(&model, q, &m)) / (2.0 * d)
        };
        let mut scale = 0.0f64;
        let mut lagrange = vec![0.0; n];
        for k in 0..n {
            let h = 1e-4;
            let along = |s: f64| -> (Vec<f64>, Vec<f64>) {
                (
                    (0..n)
                        .map(|i| q[i] + qd[i] * s + 0.5 * qdd[i] * s * s)
                        .collect(),
                    (0..n).map(|i| qd[i] + qdd[i] * s).collect(),
                )
            };
            let (qp, qdp) = along(h);
            let (qm, qdm) = along(-h);
            let ddt = (dt_dqd(&qp, &qdp, k) - dt_dqd(&qm, &qdm, k)) / (2.0 * h);
            let e = 1e-5;
            let mut qp = q.clone();
            let mut qm = q.clone();
            qp[k] += e;
            qm[k] -= e;
            let dtdq = (kinetic(&model, &qp, &qd) - kinetic(&model, &qm, &qd)) / (2.0 * e);
            let dvdq = (potential(&model, &qp) - potential(&model, &qm)) / (2.0 * e);
            lagrange[k] = ddt - dtdq + dvdq;
            scale = scale.max(lagrange[k].abs());
        }
        for k in 0..n {
            assert!(
                (ours[k] - lagrange[k]).abs() < 1e-6 * scale,
                "Q_{k}: {} vs Lagrange {} at q = {q:?}",
                ours[k],
                lagrange[k]
            );
        }
    }
}

#[test]
fn static_actuator_forces_are_dv_du() {
    let model = case("palletizer");
    let ev = Evaluator::new(&model).unwrap();
    let kin = Kinematics::new(&model);
    let params = ParameterSet::unbalanced(&model);
    let n = model.dof();
    let zeros = vec![0.0; n];
    for u0 in [[0.5, 0.1, 1.2], [2.0, 0.0, 1.03], [0.0, 0.266667, 1.37]] {
        let q = kin
            .solve_coordinates(
                &DVector::from_row_slice(&u0),
                &DVector::from_vec(model.reference_configuration()),
            )
            .unwrap();
        let q: Vec<f64> = q.iter().copied().collect();
        let view = ev
            .at_state(&q, &zeros, &zeros, &params, &[0], true)
            .unwrap();
        for a in 0..n {
            let h = 1e-5;
            let v_at = |d: f64| {
                let mut u = u0;
                u[a] += d;
                let qq = kin
                    .solve_coordinates(&DVector::from_row_slice(&u), &DVector::from_vec(q.clone()))
                    .unwrap();
                potential(&model, qq.as_slice())
            };
            let dvdu = (v_at(h) - v_at(-h)) / (2.0 * h);
            let ours = view.actuator_force[0][a];
            assert!(
                (ours - dvdu).abs() < 1e-5 * (1.0 + dvdu.abs()),
                "actuator {a} at u = {u0:?}: {ours} vs dV/du {dvdu}"
            );
        }
        // M1 drives a rotation about the vertical: no static load
        assert!(view.actuator_force[0][0].abs() < 1e-9);
    }
}

/// Newton–Euler of a body about its CoM from the model crate's kinematics (independent of the
/// dynamics crate): the wrench the world must apply, as (force, moment about the world origin).
fn inertial_wrench(
    model: &Model,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
) -> (Vector3<f64>, Vector3<f64>) {
    let kin = Kinematics::new(model);
    let motions = kin.body_motions(
        &DVector::from_row_slice(q),
        &DVector::from_row_slice(qd),
        &DVector::from_row_slice(qdd),
    );
    let mut force = Vector3::zeros();
    let mut moment = Vector3::zeros();
    for (b, m) in model.bodies.iter().zip(&motions) {
        let r = m.rotation;
        let c = r * b.com;
        let w = m.angular_velocity;
        let al = m.angular_acceleration;
        let ac = m.acceleration + al.cross(&c) + w.cross(&w.cross(&c));
        let f = (ac - model.gravity) * b.mass;
        let iw = r * b.inertia_com * r.transpose();
        let nc = iw * al + w.cross(&(iw * w));
        force += f;
        moment += nc + (m.position + c).cross(&f);
    }
    (force, moment)
}

#[test]
fn reactions_balance_the_whole_mechanism() {
    let model = case("palletizer");
    let ev = Evaluator::new(&model).unwrap();
    assert!(
        ev.reactions.minimum_norm,
        "the pantograph is overconstrained in space"
    );
    let params = ParameterSet::unbalanced(&model);
    let j1 = model.joint_index("J1").unwrap();
    let mut rng = SplitMix64::new(11);
    for _ in 0..6 {
        let (q, qd, qdd) = random_state(&model, &mut rng);
        let view = ev.at_state(&q, &qd, &qdd, &params, &[0], true).unwrap();
        let (force, moment) = inertial_wrench(&model, &q, &qd, &qdd);
        let r = &view.reactions[0];
        // Only J1 and the actuator M1 (a torque about Y0 on J1) connect the robot to the base;
        // J1's point is the world origin.
        let tau = view.actuator_force[0][0];
        let f_base = r.force[j1];
        let m_base = r.moment[j1] + Vector3::y() * tau;
        let scale = force.norm().max(1.0);
        assert!(
            (f_base - force).norm() < 1e-7 * scale,
            "{f_base} vs {force}"
        );
        assert!(
            (m_base - moment).norm() < 1e-7 * moment.norm().max(scale),
            "{m_base} vs {moment}"
        );
        // a revolute joint carries no moment along its axis
        assert!(r.moment[j1].y.abs() < 1e-7 * scale);
    }
}

/// The pantograph makes the reaction unknowns non-unique; the solver must return the
/// minimum-norm set. A solution of `Aλ = b` has minimum norm exactly when it is orthogonal to
/// the null space of `A` — here found by an SVD of the equations (8 self-equilibrated internal
/// wrench sets), independently of the normal-equation factorisation the solver uses.
#[test]
fn reactions_are_the_minimum_norm_solution() {
    use counterpoise_dynamics::mechanism::Scratch;
    let model = case("palletizer");
    let ev = Evaluator::new(&model).unwrap();
    let params = ParameterSet::unbalanced(&model);
    let mut rng = SplitMix64::new(23);
    for _ in 0..4 {
        let (q, qd, qdd) = random_state(&model, &mut rng);
        let view = ev.at_state(&q, &qd, &qdd, &params, &[0], true).unwrap();
        let reactions = &view.reactions[0];
        let mut scratch = Scratch::default();
        ev.mech.eval_poses(&q, &mut scratch);
        let kin: Vec<_> = (0..ev.mech.body_count)
            .map(|b| ev.mech.body_frame(&scratch.pose, b))
            .collect();
        let frames = ev.reactions.frames(&ev.mech, &scratch.pose);
        let a = ev.reactions.matrix(&frames, &kin);
        // λ in the solver's unknown order: per joint, the force then the moment components
        // along the frame's directions (orthonormal within each group)
        let lambda: Vec<f64> = frames
            .iter()
            .enumerate()
            .flat_map(|(j, f)| {
                let force = reactions.force[j];
                let moment = reactions.moment[j];
                f.forces()
                    .iter()
                    .map(move |e| e.dot(&force))
                    .chain(f.moments().iter().map(move |e| e.dot(&moment)))
                    .collect::<Vec<_>>()
            })
            .collect();
        assert_eq!(lambda.len(), a.ncols());
        let lambda = DVector::from_vec(lambda);
        // the directions span every component the joints carry: nothing is lost
        let carried: f64 = reactions
            .force
            .iter()
            .chain(&reactions.moment)
            .map(|v| v.norm_squared())
            .sum();
        assert!((lambda.norm_squared() - carried).abs() < 1e-9 * carried);
        // zero rows pad A to square so that the SVD returns the whole of V (nalgebra's is thin)
        let mut square = nalgebra::DMatrix::zeros(a.ncols(), a.ncols());
        square.rows_mut(0, a.nrows()).copy_from(&a);
        let unknowns = a.ncols();
        let svd = square.svd(false, true);
        let v_t = svd.v_t.unwrap();
        let smax = svd.singular_values.max();
        let mut null_dims = 0;
        for (k, &sigma) in svd.singular_values.iter().enumerate() {
            if sigma > 1e-9 * smax {
                continue;
            }
            null_dims += 1;
            let along = v_t.row(k).transpose().dot(&lambda);
            assert!(
                along.abs() < 1e-9 * lambda.norm(),
                "component {along} along a null direction (|λ| = {})",
                lambda.norm()
            );
        }
        // 53 unknowns, rank 45 (module doc of the reactions)
        assert_eq!(null_dims + ev.reactions.rank, unknowns);
        assert!(null_dims > 0);
    }
}

#[test]
fn reversed_task_has_the_same_rms_and_peaks() {
    let model = case("palletizer");
    let ev = Evaluator::new(&model).unwrap();
    let params = ParameterSet::unbalanced(&model);
    let mut ws = Workspace::default();
    let a = [0.0, 0.0, 1.03];
    let b = [2.5, 0.2, 1.3];
    let c = [1.0, 0.266667, 1.1];
    for (from, to) in [(a, b), (b, c), (a, c)] {
        let mut q1 = ev.solve_point(&from).unwrap();
        let mut q2 = ev.solve_point(&to).unwrap();
        let fwd = ev
            .move_stats(&from, &to, 2.5, 51, &mut q1, &params, true, &mut ws)
            .unwrap();
        let rev = ev
            .move_stats(&to, &from, 2.5, 51, &mut q2, &params, true, &mut ws)
            .unwrap();
        let (f, r) = (&fwd[0], &rev[0]);
        let close = |x: f64, y: f64| (x - y).abs() <= 1e-9 * (1.0 + x.abs());
        for i in 0..3 {
            assert!(
                close(f.rms[i], r.rms[i]),
                "rms {i}: {} {}",
                f.rms[i],
                r.rms[i]
            );
            assert!(close(f.peak[i], r.peak[i]), "peak {i}");
        }
        assert!(close(f.total_peak, r.total_peak));
        for j in 0..f.force_peak.len() {
            assert!(close(f.force_peak[j], r.force_peak[j]), "F_{j}");
            assert!(close(f.moment_peak[j], r.moment_peak[j]), "M_{j}");
        }
        assert!(f.rms[2] > 1.0, "M3 carries gravity");
    }
}

/// A single counterweight on the upper arm that balances the palletizer exactly, derived from
/// the model's potential `V = g(α2 sin θ2 + α3 sin θ3)`: the arm's origin B is at height
/// `δ2 + δ1 sin θ2 − δ4 sin θ3`, so a mass `m` at `(r_x, 0)` in its frame adds
/// `m g (δ1 sin θ2 + (r_x − δ4) sin θ3)`. At rest every actuator force vanishes.
#[test]
fn balanced_witness_has_no_static_torque() {
    use counterpoise_dynamics::{Counterweight, Variant};
    use counterpoise_symbolic::Monomial;
    let model = case("palletizer");
    let v = model.potential_energy(PayloadMode::All);
    let (g_a2, g_a3) = (
        v.coefficient(&Monomial::sine(1)),
        v.coefficient(&Monomial::sine(2)),
    );
    assert!(
        (g_a2 + 672.84).abs() < 0.01 && (g_a3 - 2830.49).abs() < 0.01,
        "{g_a2} {g_a3}"
    );
    let (d1, d4, g) = (0.3, 0.25, 9.81);
    let m = -g_a2 / (g * d1);
    let rx = d4 - g_a3 / (m * g);
    let arm = model.body_index("upper_arm").unwrap();
    let variant = Variant {
        counterweights: vec![Counterweight {
            label: "cw".into(),
            body: model.bodies[arm].name.clone(),
            mass: m,
            offset: [rx, 0.0, 0.0],
            plane: None,
        }],
        springs: vec![],
    };
    let params = ParameterSet::from_variants(&model, &[Variant::default(), variant]).unwrap();
    let ev = Evaluator::new(&model).unwrap();
    let zeros = vec![0.0; 3];
    let mut rng = SplitMix64::new(5);
    for _ in 0..5 {
        let (q, _, _) = random_state(&model, &mut rng);
        let view = ev
            .at_state(&q, &zeros, &zeros, &params, &[0, 1], true)
            .unwrap();
        let ub = view.actuator_force[0];
        let bal = view.actuator_force[1];
        assert!(
            ub[2].abs() > 1000.0,
            "the unbalanced M3 carries the weight: {}",
            ub[2]
        );
        for a in 0..3 {
            assert!(
                bal[a].abs() < 1e-9 * ub[2].abs(),
                "actuator {a}: {} (unbalanced {})",
                bal[a],
                ub[a]
            );
        }
    }
}

/// The reaction equations of the palletizer factored at a random configuration (the state
/// `rng` draws next), as the grid evaluation prepares a sample.
fn prepared_sample(
    model: &Model,
    ev: &Evaluator,
    rng: &mut SplitMix64,
) -> counterpoise_dynamics::reactions::ReactionWork {
    use counterpoise_dynamics::lu::SmallLu;
    use counterpoise_dynamics::mechanism::Scratch;
    let mech = &ev.mech;
    let (q, _, _) = random_state(model, rng);
    let mut scratch = Scratch::default();
    mech.eval_poses(&q, &mut scratch);
    let pose = scratch.pose.clone();
    let kin: Vec<_> = (0..mech.body_count)
        .map(|b| mech.body_frame(&pose, b))
        .collect();
    let mut u = vec![0.0; 12];
    let mut g = vec![0.0; 144];
    mech.actuator_map(&q, &mut scratch, &mut u, &mut g);
    let lu = SmallLu::new(&g, mech.n);
    let mut work = Default::default();
    ev.reactions.prepare(mech, &pose, &kin, &lu, &mut work);
    work
}

/// The substitution solve takes its right-hand sides in chunks of 32, 16 and 8 (then the
/// rest); every lane receives the same operations in any chunk, so a right-hand side's joint
/// wrenches are the same bits solved alone as in a batch of 61 (32 + 16 + 8 + 5), at any
/// position. The second method is the reaction operator of the same factorisation (its own
/// products, to 1e-12 of the largest wrench).
#[test]
fn substitution_solve_bits_do_not_depend_on_the_batch() {
    let model = case("palletizer");
    let ev = Evaluator::new(&model).unwrap();
    let mut rng = SplitMix64::new(43);
    let rows = 6 * ev.mech.body_count;
    let out_rows = 6 * ev.reactions.joint_count();
    let mut work = prepared_sample(&model, &ev, &mut rng);
    let m = 61;
    let b: Vec<f64> = (0..rows * m).map(|_| rng.uniform(-100.0, 100.0)).collect();
    let mut batch = vec![0.0; out_rows * m];
    ev.reactions
        .solve_prepared(&mut work, &mut b.clone(), m, &mut batch);
    // every chunk: the quad (0–31), the pair (32–47), the single (48–55), the rest (56–60)
    for p in [0, 9, 31, 32, 40, 47, 48, 55, 56, 60] {
        let mut column: Vec<f64> = (0..rows).map(|r| b[r * m + p]).collect();
        let mut alone = vec![0.0; out_rows];
        ev.reactions
            .solve_prepared(&mut work, &mut column, 1, &mut alone);
        for r in 0..out_rows {
            assert_eq!(alone[r].to_bits(), batch[r * m + p].to_bits(), "{p} {r}");
        }
    }
    ev.reactions.prepare_operator(&mut work);
    let mut applied = vec![0.0; out_rows * m];
    ev.reactions.apply_operator(&work, &b, m, m, &mut applied);
    let scale = batch.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    assert!(scale > 1.0);
    for (x, y) in batch.iter().zip(&applied) {
        assert!((x - y).abs() <= 1e-12 * scale, "{x} vs {y}");
    }
}

/// The reaction operator of the grid evaluation (`O`, solved once per sample for the unit
/// right-hand sides) against the substitution solve of every right-hand side: the same joint
/// wrenches to rounding; and applied to one column alone or to a block of 20 inside wider rows,
/// the same bits as within a batch of 37 (the tiles of the product differ with the batch
/// width, the value may not).
#[test]
fn reaction_operator_matches_the_substitution_solve() {
    let model = case("palletizer");
    let ev = Evaluator::new(&model).unwrap();
    let mut rng = SplitMix64::new(41);
    let rows = 6 * ev.mech.body_count;
    let out_rows = 6 * ev.reactions.joint_count();
    for _ in 0..3 {
        let mut work = prepared_sample(&model, &ev, &mut rng);
        let m = 37;
        let b: Vec<f64> = (0..rows * m).map(|_| rng.uniform(-100.0, 100.0)).collect();
        let mut solved = vec![0.0; out_rows * m];
        ev.reactions
            .solve_prepared(&mut work, &mut b.clone(), m, &mut solved);
        ev.reactions.prepare_operator(&mut work);
        let mut applied = vec![0.0; out_rows * m];
        ev.reactions.apply_operator(&work, &b, m, m, &mut applied);
        let scale = solved.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        assert!(scale > 1.0);
        for (x, y) in solved.iter().zip(&applied) {
            assert!((x - y).abs() <= 1e-12 * scale, "{x} vs {y}");
        }
        for p in [0, 16, 36] {
            let column: Vec<f64> = (0..rows).map(|r| b[r * m + p]).collect();
            let mut alone = vec![0.0; out_rows];
            ev.reactions
                .apply_operator(&work, &column, 1, 1, &mut alone);
            for r in 0..out_rows {
                assert_eq!(alone[r].to_bits(), applied[r * m + p].to_bits());
            }
        }
        // a block of columns inside wider rows (rows `m` apart)
        let mut block = vec![0.0; out_rows * m];
        ev.reactions
            .apply_operator(&work, &b[3..], m, 20, &mut block[3..]);
        for r in 0..out_rows {
            for p in 3..23 {
                assert_eq!(block[r * m + p].to_bits(), applied[r * m + p].to_bits());
            }
        }
    }
}
