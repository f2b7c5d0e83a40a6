//! Torques and reactions against hand-derived equations of motion.

mod common;

use common::{assert_close, case, quintic};
use counterpoise_dynamics::runner::Workspace;
use counterpoise_dynamics::{
    Counterweight, Evaluator, ParameterSet, Variant, task_series, task_series_with,
};

const G: f64 = 9.81;

#[test]
fn pendulum_torque_is_j_thetadd_plus_gravity() {
    let model = case("pendulum");
    // grid: 5 points from −1.5 to 1.5; move 0 → 4.
    let s = task_series(&model, 0, 4, Some(41)).unwrap();
    let (m, l, izz) = (2.0, 1.0, 0.1667);
    let j = izz + m * (l / 2.0) * (l / 2.0);
    for (k, &t) in s.t.iter().enumerate() {
        let (th, _, thdd) = quintic(-1.5, 1.5, 1.0, t);
        assert_close(s.q[k][0], th, 1e-10, "theta");
        let tau = j * thdd + m * G * (l / 2.0) * th.cos();
        assert_close(
            s.actuator_force[k][0],
            tau,
            1e-9 * (1.0 + tau.abs()),
            "torque",
        );
        assert_close(s.motor_torque[k][0], 0.01 * tau, 1e-11, "motor torque");
    }
}

#[test]
fn pendulum_pivot_force_is_m_times_a_minus_g() {
    let model = case("pendulum");
    let s = task_series(&model, 1, 3, Some(31)).unwrap();
    let (m, c) = (2.0, 0.5);
    for (k, &t) in s.t.iter().enumerate() {
        let (th, thd, thdd) = quintic(-0.75, 0.75, 1.0, t);
        let ax = c * (-thdd * th.sin() - thd * thd * th.cos());
        let ay = c * (thdd * th.cos() - thd * thd * th.sin());
        let f = m * ((ax).powi(2) + (ay + G).powi(2)).sqrt();
        assert_close(s.joints[0].force[k], f, 1e-9 * f, "pivot force");
        assert!(
            s.joints[0].moment[k].abs() < 1e-9,
            "planar: no moment ⊥ axis"
        );
    }
    assert!(!s.reactions_minimum_norm);
}

#[test]
fn two_link_torques_match_lagrange() {
    let model = case("two_link");
    // Link 2 with its 1 kg tool at L2 (payloads move with their body).
    let l1 = 0.8;
    let (m1, h1, j1) = (4.0, 4.0 * 0.4, 0.2133 + 4.0 * 0.16);
    let (m2, h2, j2) = (
        2.5 + 1.0,
        2.5 * 0.3 + 1.0 * 0.6,
        0.075 + 2.5 * 0.09 + 1.0 * 0.36,
    );
    let _ = m1;
    // grid 3×3: M1 ∈ {−1,0,1}, M2 ∈ {−1.5,0,1.5}; point 0 = (−1,−1.5), point 8 = (1, 1.5)
    for (i, jdx) in [(0usize, 8usize), (2, 6), (1, 5)] {
        let s = task_series(&model, i, jdx, Some(25)).unwrap();
        let grid = |p: usize| [-1.0 + (p / 3) as f64, -1.5 + 1.5 * (p % 3) as f64];
        let (a, b) = (grid(i), grid(jdx));
        for (k, &t) in s.t.iter().enumerate() {
            let (q1, qd1, qdd1) = quintic(a[0], b[0], 1.5, t);
            let (q2, qd2, qdd2) = quintic(a[1], b[1], 1.5, t);
            let c2 = q2.cos();
            let s2 = q2.sin();
            let m11 = j1 + j2 + m2 * l1 * l1 + 2.0 * h2 * l1 * c2;
            let m12 = j2 + h2 * l1 * c2;
            let m22 = j2;
            let g1 = G * (h1 + m2 * l1) * q1.cos() + G * h2 * (q1 + q2).cos();
            let g2 = G * h2 * (q1 + q2).cos();
            let tau1 = m11 * qdd1 + m12 * qdd2 - h2 * l1 * s2 * (2.0 * qd1 * qd2 + qd2 * qd2) + g1;
            let tau2 = m12 * qdd1 + m22 * qdd2 + h2 * l1 * s2 * qd1 * qd1 + g2;
            assert_close(
                s.actuator_force[k][0],
                tau1,
                1e-9 * (1.0 + tau1.abs()),
                "tau1",
            );
            assert_close(
                s.actuator_force[k][1],
                tau2,
                1e-9 * (1.0 + tau2.abs()),
                "tau2",
            );
        }
    }
}

#[test]
fn counterweight_balancing_the_pendulum_leaves_no_static_torque() {
    let model = case("pendulum");
    // m·r = −m_rod·c: 4 kg at x = −0.25 m.
    let variant = Variant {
        counterweights: vec![Counterweight {
            label: "cw".into(),
            body: model.bodies[0].name.clone(),
            mass: 4.0,
            offset: [-0.25, 0.0, 0.0],
            plane: None,
        }],
        springs: vec![],
    };
    let params = ParameterSet::from_variants(&model, &[Variant::default(), variant]).unwrap();
    let s = task_series_with(&model, &params, 1, 0, 4, Some(21)).unwrap();
    let ub = task_series_with(&model, &params, 0, 0, 4, Some(21)).unwrap();
    // at rest (both ends) the balanced torque vanishes, the unbalanced does not
    for k in [0, s.t.len() - 1] {
        assert!(
            s.actuator_force[k][0].abs() < 1e-10,
            "{}",
            s.actuator_force[k][0]
        );
        assert!(ub.actuator_force[k][0].abs() > 0.5);
    }
}

#[test]
fn base_spring_balancing_the_pendulum() {
    use counterpoise_dynamics::Spring;
    let model = case("pendulum");
    // V_g = m g c sin θ = 9.81 sin θ; a zero-free-length spring from (0, B, 0) on the base to
    // (A, 0, 0) on the rod adds −K A B sin θ: balanced for K A B = 9.81.
    let (k, a, b) = (100.0, 0.1, 0.981);
    let variant = Variant {
        counterweights: vec![],
        springs: vec![Spring {
            label: "spring".into(),
            body: model.bodies[0].name.clone(),
            other: "base".into(),
            stiffness: k,
            anchor_a: [a, 0.0, 0.0],
            anchor_b: [0.0, b, 0.0],
            plane: None,
        }],
    };
    let params = ParameterSet::from_variants(&model, &[Variant::default(), variant]).unwrap();
    let s = task_series_with(&model, &params, 1, 0, 4, Some(21)).unwrap();
    let ub = task_series_with(&model, &params, 0, 0, 4, Some(21)).unwrap();
    let (m, c, izz) = (2.0, 0.5, 0.1667);
    for (i, &t) in s.t.iter().enumerate() {
        let (th, thd, thdd) = quintic(-1.5, 1.5, 1.0, t);
        // balanced: inertial torque only
        let j = izz + m * c * c;
        assert_close(
            s.actuator_force[i][0],
            j * thdd,
            1e-9 * (1.0 + (j * thdd).abs()),
            "balanced torque",
        );
        assert!(ub.actuator_force[i][0].abs() > 0.0);
        // pivot force: m(a_G − g) minus the spring's pull on the rod, K(b − R a)
        let ax = c * (-thdd * th.sin() - thd * thd * th.cos());
        let ay = c * (thdd * th.cos() - thd * thd * th.sin());
        let spring = [k * (0.0 - a * th.cos()), k * (b - a * th.sin())];
        let f = ((m * ax - spring[0]).powi(2) + (m * (ay + G) - spring[1]).powi(2)).sqrt();
        assert_close(
            s.joints[0].force[i],
            f,
            1e-9 * (1.0 + f),
            "pivot force with spring",
        );
    }
}

#[test]
fn spring_generalized_force_is_the_gradient_of_its_energy() {
    use counterpoise_dynamics::mechanism::{Mechanism, Scratch};
    use counterpoise_dynamics::params::{SpringSlot, spring_params};
    use counterpoise_dynamics::regressor::spring_regressor;
    let model = case("two_link");
    let mech = Mechanism::new(&model).unwrap();
    let slot = SpringSlot {
        body: 1,
        other: Some(0),
    };
    let (k, a, b) = (750.0, [0.3, -0.1, 0.05], [-0.2, 0.4, 0.0]);
    let x = spring_params(k, &a, &b);
    let energy = |q: &[f64]| {
        let at = model.point(q);
        let pose = |i: usize| {
            let body = &model.bodies[i];
            let r = nalgebra::Matrix3::from_fn(|u, v| body.rotation.0[u][v].eval(&at));
            let p = nalgebra::Vector3::from_fn(|u, _| body.origin.0[u].eval(&at));
            (r, p)
        };
        let (ri, pi) = pose(1);
        let (rs, ps) = pose(0);
        let d = pi + ri * nalgebra::Vector3::from(a) - ps - rs * nalgebra::Vector3::from(b);
        0.5 * k * d.norm_squared()
    };
    let mut scratch = Scratch::default();
    let mut out = vec![0.0; 2 * 16];
    for q in [[0.3, -0.7], [-1.2, 2.0], [2.5, 0.1]] {
        mech.eval_poses(&q, &mut scratch);
        spring_regressor(&mech, &scratch.pose, &slot, &mut out);
        for kq in 0..2 {
            let ours: f64 = (0..16).map(|c| out[kq * 16 + c] * x[c]).sum();
            let h = 1e-6;
            let mut qp = q;
            let mut qm = q;
            qp[kq] += h;
            qm[kq] -= h;
            let fd = (energy(&qp) - energy(&qm)) / (2.0 * h);
            assert_close(ours, fd, 1e-6 * (1.0 + fd.abs()), "dV/dq");
        }
    }
}

/// A cylindrical counterweight with radius/thickness ratio τ = 0.5 (every case file uses τ = 1,
/// where τ and τ² cannot be told apart). From the volume `m/ρ = πR²t = πR³/τ` by hand,
/// `R = (τ m / (ρ π))^(1/3)`, `J_zz = m R²/2` about the cylinder's axis (the normal of the xy
/// plane) and `J_⊥ = m (3R² + t²)/12` with `t = R/τ`. Balanced (m·r = −m_rod·c), the pendulum's
/// torque is inertial only: `(I_rod,O + m r² + J_zz) θ̈`.
#[test]
fn cylinder_counterweight_with_tau_not_one() {
    let (tau, rho, m, r) = (0.5, 7850.0, 4.0, -0.25);
    let radius = (tau * m / (rho * std::f64::consts::PI)).cbrt();
    let thickness = radius / tau;
    let j_axis = 0.5 * m * radius * radius;
    let j_across = m * (3.0 * radius * radius + thickness * thickness) / 12.0;

    let j = counterpoise_dynamics::params::cylinder_inertia(m, tau, rho, 0);
    assert_close(j[(0, 0)], j_axis, 1e-15, "J along the axis");
    assert_close(j[(1, 1)], j_across, 1e-15, "J across");
    assert_close(j[(2, 2)], j_across, 1e-15, "J across");
    assert_eq!(j[(0, 1)], 0.0);

    let mut json: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(format!(
            "{}/../../cases/pendulum.json",
            env!("CARGO_MANIFEST_DIR")
        ))
        .unwrap(),
    )
    .unwrap();
    json["balancing"]["counterweights"]["shape"] =
        serde_json::json!({ "cylinder": { "radius_to_thickness": tau, "density": rho } });
    let model = common::case_from_text(&json.to_string());
    let variant = Variant {
        counterweights: vec![Counterweight {
            label: "cw".into(),
            body: model.bodies[0].name.clone(),
            mass: m,
            offset: [r, 0.0, 0.0],
            plane: None,
        }],
        springs: vec![],
    };
    let params = ParameterSet::from_variants(&model, &[variant]).unwrap();
    let s = task_series_with(&model, &params, 0, 0, 4, Some(21)).unwrap();
    let inertia = 0.1667 + 2.0 * 0.25 + m * r * r + j_axis;
    for (k, &t) in s.t.iter().enumerate() {
        let (_, _, thdd) = quintic(-1.5, 1.5, 1.0, t);
        let expected = inertia * thdd;
        assert_close(
            s.actuator_force[k][0],
            expected,
            1e-9 * (1.0 + expected.abs()),
            "balanced torque with a τ = 0.5 cylinder",
        );
    }
}

/// The pendulum on a tilted axis, driven through the coordinate `u = 2θ`: the rod turns by
/// φ = 2θ = u about `u_J = R·z = (0.48, −0.6, 0.64)`, `R = R_y(atan2(3, 4)) R_x(atan2(3, 4))`,
/// so both perpendiculars of the joint axis mix the world axes, and the chart coordinate θ is
/// not the actuated one (the grid moves u from −1.5 to 1.5). By hand, with the rod's COM at
/// `p = R R_z(φ) c`
/// (c = L/2 along x) and its inertia about the pivot diagonal with the rotation axis a
/// principal axis (`L_O = J φ̇ u_J`, `J = I_zz + m c²`):
/// - pivot force `F = m (a − g)`, `a = φ̈ u_J × p + φ̇² u_J × (u_J × p)`;
/// - moment `dL_O/dt − p × m g = J φ̈ u_J − p × m g`: the actuator takes the part along
///   `u_J`, the joint the rest, `|(p × m g)_⊥|`;
/// - actuator force on u: `J φ̈ − u_J·(p × m g)` (δu = δφ), and θ = u/2.
#[test]
fn tilted_pendulum_driven_through_a_scaled_coordinate() {
    let text = std::fs::read_to_string(format!(
        "{}/../../cases/pendulum.json",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
    let mut json: serde_json::Value = serde_json::from_str(&text).unwrap();
    json["bodies"][0]["pose"] = serde_json::json!([{ "rot_y": "atan2(3, 4)" }, { "rot_x": "atan2(3, 4)" }, { "rot_z": "2*th" }]);
    json["joints"][0]["axis"] = serde_json::json!([0.48, -0.6, 0.64]);
    json["actuators"][0]["coordinate"] = serde_json::json!("2*th");
    let model = common::case_from_text(&json.to_string());
    let (m, c, izz) = (2.0, 0.5, 0.1667);
    let j = izz + m * c * c;
    // R = R_y(β) R_x(α) with sin = 3/5, cos = 4/5 for both.
    let (sn, cs) = (0.6, 0.8);
    let rotation = [
        [cs, sn * sn, sn * cs],
        [0.0, cs, -sn],
        [-sn, cs * sn, cs * cs],
    ];
    let rotate = |v: [f64; 3]| -> [f64; 3] {
        std::array::from_fn(|r| (0..3).map(|k| rotation[r][k] * v[k]).sum())
    };
    let u = rotate([0.0, 0.0, 1.0]);
    assert_eq!(u.map(|v| (v * 100.0).round() / 100.0), [0.48, -0.6, 0.64]);
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let weight = [0.0, -m * G, 0.0];
    // The reactions as vectors (world axes): the force and moment the base exerts on the rod.
    let ev = Evaluator::new(&model).unwrap();
    let params = ParameterSet::from_variants(&model, &[Variant::default()]).unwrap();
    let mut q = ev.solve_point(&[-1.5]).unwrap();
    let mut samples = 0;
    let mut largest_x_moment = 0.0f64;
    ev.run_move(
        &[-1.5],
        &[1.5],
        1.0,
        41,
        &mut q,
        &params,
        &[0],
        true,
        &mut Workspace::default(),
        |_, view| {
            samples += 1;
            let (phi, phid, phidd) = quintic(-1.5, 1.5, 1.0, view.t);
            assert_close(view.q[0], phi / 2.0, 1e-10, "theta");
            let p = rotate([c * phi.cos(), c * phi.sin(), 0.0]);
            let u_p = cross(u, p);
            let u_u_p = cross(u, u_p);
            let gravity_moment = cross(p, weight);
            let along = dot(u, gravity_moment);
            let reaction = &view.reactions[0];
            for r in 0..3 {
                let a = phidd * u_p[r] + phid * phid * u_u_p[r];
                let force = m * a - weight[r];
                assert_close(reaction.force[0][r], force, 1e-9 * (1.0 + force.abs()), "F");
                let moment = -(gravity_moment[r] - along * u[r]);
                assert_close(
                    reaction.moment[0][r],
                    moment,
                    1e-9 * (1.0 + moment.abs()),
                    "M",
                );
            }
            largest_x_moment = f64::max(largest_x_moment, (gravity_moment[0] - along * u[0]).abs());
            let tau = j * phidd - along;
            assert_close(
                view.actuator_force[0][0],
                tau,
                1e-9 * (1.0 + tau.abs()),
                "actuator force",
            );
        },
    )
    .unwrap();
    assert_eq!(samples, 41);
    // the moment across the axis has components on all three world axes
    assert!(largest_x_moment > 0.1, "{largest_x_moment}");
}
