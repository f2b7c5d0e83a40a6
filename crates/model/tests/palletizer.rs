//! The reference palletizer (docs/palletizer.md): the model built from
//! `cases/palletizer.json` must reproduce the closed forms of the paper's Eqs. 22–26 and the
//! unbalanced potential energy, derived here by hand from the geometry and member tables.

use counterpoise_model::sampling::{SplitMix64, sample_configurations};
use counterpoise_model::{Case, Kinematics, KinematicsError, Model, PayloadMode};
use counterpoise_symbolic::{Monomial, Point};
use nalgebra::{DVector, Matrix3, Vector3};

const D1: f64 = 0.300;
const D2: f64 = 1.200;
const D3: f64 = -0.200;
const D4: f64 = 0.250;
const G: f64 = 9.81;

fn model() -> Model {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../cases/palletizer.json");
    Case::from_path(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// World position of a point given in a body's frame.
fn world(model: &Model, body: &str, local: [f64; 3], at: &Point) -> Vector3<f64> {
    let id = model.body_id(body).unwrap();
    let (r, p) = model.body_pose(id, at);
    p + r * Vector3::from(local)
}

/// A point `(x, y)` of the column's x1y1 plane in world coordinates: `Ry(θ1)·(x, y, 0)`.
fn column_plane(th1: f64, x: f64, y: f64) -> Vector3<f64> {
    Vector3::new(x * th1.cos(), y, -x * th1.sin())
}

fn close(a: &Vector3<f64>, b: &Vector3<f64>, tol: f64, what: &str) {
    assert!((a - b).norm() < tol, "{what}: {a:?} vs {b:?}");
}

#[test]
fn body_order_and_masses_follow_the_reference() {
    let m = model();
    let names: Vec<&str> = m.bodies.iter().map(|b| b.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "column",
            "slider_h",
            "slider_v",
            "upper_arm",
            "front_link",
            "rear_link",
            "forearm",
            "carrier"
        ]
    );
    // 700 + 60 + 70 + 110 + 45 + 20 + 124.875 + 58.75; with the 800 kg base ≈ 1990 kg.
    assert!((m.total_mass() - 1188.625).abs() < 1e-9);
    assert_eq!(m.joints.len(), 11);
    assert_eq!(m.dof(), 3);
}

#[test]
fn pantograph_points_match_the_closed_forms() {
    let m = model();
    for q in sample_configurations(&m.coordinates, 50, 11) {
        let (th1, th2, th3) = (q[0], q[1], q[2]);
        let at = m.point(&q);
        let (c2, s2, c3, s3) = (th2.cos(), th2.sin(), th3.cos(), th3.sin());
        // Closure relations (Eqs. 25–26).
        let rho2 = D3 + D1 * c2 + D4 * c3;
        let rho3 = D2 + D1 * s2 - D4 * s3;
        let u = (c3, s3);
        let v = (c2, -s2);
        let a = (rho2, D2);
        let b = (D3, rho3);
        let c = (b.0 + D4 * u.0, b.1 + D4 * u.1);
        let e = (b.0 + 6.0 * D4 * u.0, b.1 + 6.0 * D4 * u.1);
        let d = (a.0 + 5.0 * D4 * u.0, a.1 + 5.0 * D4 * u.1);
        let p = (e.0 + 6.0 * D1 * v.0, e.1 + 6.0 * D1 * v.1);
        let plane = |pt: (f64, f64)| column_plane(th1, pt.0, pt.1);
        let tol = 1e-12;

        // A: slider_h origin, front_link origin, the far end of the rear link.
        close(
            &world(&m, "slider_h", [0.0; 3], &at),
            &plane(a),
            tol,
            "A (slider_h)",
        );
        close(
            &world(&m, "front_link", [0.0; 3], &at),
            &plane(a),
            tol,
            "A (front_link)",
        );
        close(
            &world(&m, "rear_link", [D1, 0.0, 0.0], &at),
            &plane(a),
            tol,
            "A = C + δ1 v",
        );
        // B: slider_v and upper_arm origins.
        close(
            &world(&m, "slider_v", [0.0; 3], &at),
            &plane(b),
            tol,
            "B (slider_v)",
        );
        close(
            &world(&m, "upper_arm", [0.0; 3], &at),
            &plane(b),
            tol,
            "B (upper_arm)",
        );
        // C, E on the upper arm.
        close(
            &world(&m, "upper_arm", [D4, 0.0, 0.0], &at),
            &plane(c),
            tol,
            "C (upper_arm)",
        );
        close(
            &world(&m, "rear_link", [0.0; 3], &at),
            &plane(c),
            tol,
            "C (rear_link)",
        );
        close(
            &world(&m, "upper_arm", [6.0 * D4, 0.0, 0.0], &at),
            &plane(e),
            tol,
            "E (upper_arm)",
        );
        close(
            &world(&m, "forearm", [0.0; 3], &at),
            &plane(e),
            tol,
            "E (forearm)",
        );
        // D = A + 5δ4 u = E + δ1 v.
        close(
            &world(&m, "front_link", [5.0 * D4, 0.0, 0.0], &at),
            &plane(d),
            tol,
            "D (front_link)",
        );
        close(
            &world(&m, "forearm", [D1, 0.0, 0.0], &at),
            &plane(d),
            tol,
            "D (forearm)",
        );
        // P = E + 6δ1 v = 6A − 5B, carried by the forearm and the carrier.
        let p6a5b = (6.0 * a.0 - 5.0 * b.0, 6.0 * a.1 - 5.0 * b.1);
        close(&plane(p), &plane(p6a5b), 1e-12, "P = 6A - 5B");
        close(
            &world(&m, "forearm", [6.0 * D1, 0.0, 0.0], &at),
            &plane(p),
            tol,
            "P (forearm)",
        );
        close(
            &world(&m, "carrier", [0.0; 3], &at),
            &plane(p),
            tol,
            "P (carrier)",
        );
        // End point, Eqs. 22–24.
        let end = Vector3::new(
            (6.0 * rho2 - 5.0 * D3) * th1.cos(),
            6.0 * D2 - 5.0 * rho3,
            -(6.0 * rho2 - 5.0 * D3) * th1.sin(),
        );
        close(
            &world(&m, "carrier", [0.0; 3], &at),
            &end,
            tol,
            "end point (Eqs. 22-24)",
        );
        // The carrier keeps the column's orientation.
        let (rc, _) = m.body_pose(m.body_id("carrier").unwrap(), &at);
        let (r1, _) = m.body_pose(m.body_id("column").unwrap(), &at);
        assert!((rc - r1).norm() < 1e-14);
        // Actuated coordinates are ρ2, ρ3.
        let kin = Kinematics::new(&m);
        let uq = kin.actuator_values(&DVector::from_vec(q.clone()));
        assert!(
            (uq[0] - th1).abs() < 1e-14
                && (uq[1] - rho2).abs() < 1e-14
                && (uq[2] - rho3).abs() < 1e-14
        );
    }
}

#[test]
fn unbalanced_potential_energy_has_exactly_the_reference_terms() {
    let m = model();
    // By hand from the member table: V = g Σ m·y_com, with y_com in the x1y1 plane
    //   slider_v   ρ3                      → s2: +δ1,        s3: −δ4
    //   upper_arm  ρ3 + 0.70 s3            → s2: +δ1,        s3: −δ4 + 0.70
    //   front_link δ2 + 0.60 s3            →                 s3: +0.60
    //   rear_link  C_y − 0.15 s2           → s2: δ1 − 0.15
    //   forearm    E_y − 0.60 s2           → s2: δ1 − 0.60,  s3: 5δ4
    //   carrier    P_y = 6δ2 − 5ρ3         → s2: −5δ1,       s3: +5δ4
    let alpha2 =
        70.0 * D1 + 110.0 * D1 + 20.0 * (D1 - 0.15) + 124.875 * (D1 - 0.60) + 58.75 * (-5.0 * D1);
    let alpha3 = 70.0 * (-D4)
        + 110.0 * (0.70 - D4)
        + 45.0 * 0.60
        + 124.875 * (5.0 * D4)
        + 58.75 * (5.0 * D4);
    let (g_alpha2, g_alpha3) = (G * alpha2, G * alpha3);
    // The reference values, to their printed precision.
    assert!((g_alpha2 - -672.84).abs() < 0.005 && (g_alpha3 - 2830.49).abs() < 0.005);

    let v = m.potential_energy(PayloadMode::InBalance);
    let non_constant: Vec<(Monomial, f64)> = v
        .terms()
        .filter(|(mono, _)| !mono.is_one())
        .map(|(mono, c)| (*mono, c))
        .collect();
    assert_eq!(non_constant.len(), 2, "V_UB = {v:?}");
    let s2 = v.coefficient(&Monomial::sine(1));
    let s3 = v.coefficient(&Monomial::sine(2));
    assert!(
        ((s2 - g_alpha2) / g_alpha2).abs() < 1e-6,
        "{s2} vs {g_alpha2}"
    );
    assert!(
        ((s3 - g_alpha3) / g_alpha3).abs() < 1e-6,
        "{s3} vs {g_alpha3}"
    );
    // Including the path payload changes nothing here: it is not a model payload.
    assert_eq!(m.potential_energy(PayloadMode::All), v);
}

#[test]
fn gravity_potential_of_a_point_mass() {
    let m = model();
    let q = [0.3, 0.7, 1.1];
    let at = m.point(&q);
    let local = Vector3::new(0.2, -0.1, 0.05);
    let id = m.body_id("forearm").unwrap();
    let v = m.gravity_potential(id, 3.0, &local).eval(&at);
    let p = world(&m, "forearm", [0.2, -0.1, 0.05], &at);
    assert!((v - 3.0 * G * p.y).abs() < 1e-12);
}

fn fd_step(q: &DVector<f64>, k: usize, h: f64) -> (DVector<f64>, DVector<f64>) {
    let mut plus = q.clone();
    let mut minus = q.clone();
    plus[k] += h;
    minus[k] -= h;
    (plus, minus)
}

fn vee(m: &Matrix3<f64>) -> Vector3<f64> {
    Vector3::new(
        m[(2, 1)] - m[(1, 2)],
        m[(0, 2)] - m[(2, 0)],
        m[(1, 0)] - m[(0, 1)],
    ) * 0.5
}

#[test]
fn jacobians_match_finite_differences() {
    let m = model();
    let kin = Kinematics::new(&m);
    let h = 1e-6;
    for q in sample_configurations(&m.coordinates, 20, 5) {
        let q = DVector::from_vec(q);
        for body in 0..kin.body_count() {
            let jac = kin.body_jacobian(body, &q);
            let rt = kin.body_pose(body, &q).rotation.transpose();
            for k in 0..kin.dof() {
                let (plus, minus) = fd_step(&q, k, h);
                let (pp, pm) = (kin.body_pose(body, &plus), kin.body_pose(body, &minus));
                let linear = (pp.position - pm.position) / (2.0 * h);
                let angular = vee(&((pp.rotation - pm.rotation) / (2.0 * h) * rt));
                assert!(
                    (jac.linear.column(k) - linear).norm() < 1e-8,
                    "body {body} q{k} linear"
                );
                assert!(
                    (jac.angular.column(k) - angular).norm() < 1e-8,
                    "body {body} q{k} angular"
                );
            }
        }
        // Actuator Jacobian.
        let g = kin.actuator_jacobian(&q);
        for k in 0..kin.dof() {
            let (plus, minus) = fd_step(&q, k, h);
            let fd = (kin.actuator_values(&plus) - kin.actuator_values(&minus)) / (2.0 * h);
            assert!((g.column(k) - fd).norm() < 1e-8);
        }
    }
}

#[test]
fn accelerations_and_actuator_bias_match_finite_differences() {
    let m = model();
    let kin = Kinematics::new(&m);
    let mut rng = SplitMix64::new(99);
    let h = 1e-5;
    for q0 in sample_configurations(&m.coordinates, 20, 6) {
        let q0 = DVector::from_vec(q0);
        let qd0 = DVector::from_fn(3, |_, _| rng.uniform(-1.0, 1.0));
        let qdd = DVector::from_fn(3, |_, _| rng.uniform(-2.0, 2.0));
        // Along q(t) = q0 + q̇0 t + q̈ t²/2, with q̇(t) = q̇0 + q̈ t.
        let q_at = |t: f64| &q0 + &qd0 * t + &qdd * (0.5 * t * t);
        let qd_at = |t: f64| &qd0 + &qdd * t;
        let zero = DVector::zeros(3);
        for body in 0..kin.body_count() {
            let motion = kin.body_motion(body, &q0, &qd0, &qdd);
            let plus = kin.body_motion(body, &q_at(h), &qd_at(h), &zero);
            let minus = kin.body_motion(body, &q_at(-h), &qd_at(-h), &zero);
            let a_fd = (plus.velocity - minus.velocity) / (2.0 * h);
            let alpha_fd = (plus.angular_velocity - minus.angular_velocity) / (2.0 * h);
            let scale = 1.0 + motion.acceleration.norm();
            assert!(
                (motion.acceleration - a_fd).norm() < 1e-7 * scale,
                "body {body}: a"
            );
            assert!(
                (motion.angular_acceleration - alpha_fd).norm() < 1e-7 * (1.0 + alpha_fd.norm()),
                "body {body}: alpha"
            );
            // Velocities agree with the Jacobians, positions with the poses.
            let jac = kin.body_jacobian(body, &q0);
            assert!((motion.velocity - &jac.linear * &qd0).norm() < 1e-12);
            assert!((motion.angular_velocity - &jac.angular * &qd0).norm() < 1e-12);
            assert_eq!(motion.position, kin.body_pose(body, &q0).position);
        }
        // ü = G q̈ + Ġ q̇, with u̇(t) = G(q(t)) q̇(t).
        let ud = |t: f64| kin.actuator_jacobian(&q_at(t)) * qd_at(t);
        let udd_fd = (ud(h) - ud(-h)) / (2.0 * h);
        let udd = kin.actuator_jacobian(&q0) * &qdd + kin.actuator_bias(&q0, &qd0);
        assert!((udd - &udd_fd).norm() < 1e-7 * (1.0 + udd_fd.norm()));
        // And the inverse: coordinate rates from actuator rates.
        let (qd_back, qdd_back) = kin.coordinate_rates(&q0, &ud(0.0), &udd_fd).unwrap();
        assert!((qd_back - &qd0).norm() < 1e-10);
        assert!((qdd_back - &qdd).norm() < 1e-5);
    }
}

#[test]
fn newton_recovers_every_grid_point() {
    let m = model();
    let kin = Kinematics::new(&m);
    let tasks = m.tasks.as_ref().unwrap();
    let points = tasks.grid_points();
    assert_eq!(points.len(), 343);
    let reference = DVector::from_vec(m.reference_configuration());
    let mut min_sum = f64::INFINITY;
    let mut max_sum = f64::NEG_INFINITY;
    for u in points {
        let u = DVector::from_vec(u);
        let q = kin
            .solve_coordinates(&u, &reference)
            .unwrap_or_else(|e| panic!("u = {u}: {e}"));
        assert!((kin.actuator_values(&q) - &u).amax() < 1e-11);
        for (value, c) in q.iter().zip(&m.coordinates) {
            assert!(c.range[0] <= *value && *value <= c.range[1]);
        }
        min_sum = min_sum.min(q[1] + q[2]);
        max_sum = max_sum.max(q[1] + q[2]);
    }
    // The reference: over the grid θ2 + θ3 stays within about 51°–139°.
    assert!(
        min_sum.to_degrees() > 50.5 && max_sum.to_degrees() < 139.5,
        "{min_sum} {max_sum}"
    );
}

#[test]
fn newton_with_warm_start_follows_a_path_and_hits_the_waypoints() {
    let m = model();
    let kin = Kinematics::new(&m);
    let path = &m.paths[0];
    assert_eq!(path.name, "Lambda");
    // Fig. 8 end-point waypoints in Σ0, mm.
    let expected = [
        ("A", [750.0, 551.0, -1302.0]),
        ("B", [750.0, 451.0, -1302.0]),
        ("C", [750.0, 351.0, -1302.0]),
        ("D", [2546.0, 2051.0, 0.0]),
        ("E", [2546.0, 1951.0, 0.0]),
        ("F", [2546.0, 1851.0, 0.0]),
    ];
    let carrier = m.body_index("carrier").unwrap();
    let mut q = DVector::from_vec(m.reference_configuration());
    for (name, mm) in expected {
        let wp = path.waypoints.iter().find(|w| w.name == name).unwrap();
        let u = DVector::from_vec(wp.u.clone());
        q = kin.solve_coordinates(&u, &q).unwrap();
        let p = kin.body_pose(carrier, &q).position * 1000.0;
        assert!((p - Vector3::from(mm)).norm() < 1e-5, "{name}: {p:?}");
    }
    // Payload picked at C, dropped at F; 5 s in total.
    let payload = path.payload.as_ref().unwrap();
    let names: Vec<&str> = path
        .sequence
        .iter()
        .map(|&i| path.waypoints[i].name.as_str())
        .collect();
    assert_eq!(names, ["A", "C", "B", "E", "F", "D", "A"]);
    assert_eq!((names[payload.pick_at], names[payload.drop_at]), ("C", "F"));
    assert!((path.durations.iter().sum::<f64>() - 5.0).abs() < 1e-12);
    assert_eq!(payload.mass, 150.0);
}

#[test]
fn newton_reports_unreachable_singular_and_out_of_range_targets() {
    let m = model();
    let kin = Kinematics::new(&m);
    let reference = DVector::from_vec(m.reference_configuration());
    // |A − B| ≤ δ1 + δ4 = 0.55 m, so ρ2 = 1.0 m cannot be reached.
    let unreachable = DVector::from_vec(vec![0.5, 1.0, 1.2]);
    match kin.solve_coordinates(&unreachable, &reference) {
        Err(KinematicsError::NotConverged { .. } | KinematicsError::Singular { .. }) => {}
        other => panic!("expected a failure, got {other:?}"),
    }
    // θ2 + θ3 = π: the two pantograph links are aligned and G is singular.
    let singular = DVector::from_vec(vec![0.5, 1.0, std::f64::consts::PI - 1.0]);
    let target = DVector::from_vec(vec![0.5, 0.1, 1.2]);
    assert!(matches!(
        kin.solve_coordinates(&target, &singular),
        Err(KinematicsError::Singular { .. })
    ));
    // Started on the mirrored assembly branch, Newton converges there: outside the ranges.
    let mirrored = DVector::from_vec(vec![0.5, -0.6, -0.9]);
    match kin.solve_coordinates(&target, &mirrored) {
        Err(KinematicsError::OutOfRange { coordinate, .. }) => {
            assert!(coordinate == "th2" || coordinate == "th3")
        }
        other => panic!("expected OutOfRange, got {other:?}"),
    }
}

#[test]
fn newton_wraps_periodic_angles_into_their_ranges() {
    let m = model();
    let kin = Kinematics::new(&m);
    let u = DVector::from_vec(vec![1.0, 0.1, 1.2]);
    let reference = DVector::from_vec(m.reference_configuration());
    let direct = kin.solve_coordinates(&u, &reference).unwrap();
    // th2, th3 enter u only through cos/sin: a guess 2π away lands on the same configuration.
    let mut shifted = reference.clone();
    shifted[1] += std::f64::consts::TAU;
    shifted[2] -= std::f64::consts::TAU;
    let wrapped = kin.solve_coordinates(&u, &shifted).unwrap();
    assert!((wrapped - &direct).amax() < 1e-10);
    // th1 is actuated itself (u1 = th1): a target 2π away is a different motor position.
    let far = DVector::from_vec(vec![1.0 + std::f64::consts::TAU, 0.1, 1.2]);
    assert!(matches!(
        kin.solve_coordinates(&far, &reference),
        Err(KinematicsError::OutOfRange { .. })
    ));
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(64))]
    /// Anywhere in the task box (with the path's slight overshoot in ρ3), Newton from the
    /// reference configuration finds the working assembly branch.
    #[test]
    fn newton_round_trip_in_the_task_box(
        th1 in 0.0f64..std::f64::consts::PI,
        rho2 in 0.0f64..0.266667,
        rho3 in 1.0298f64..1.37,
    ) {
        let m = model();
        let kin = Kinematics::new(&m);
        let u = DVector::from_vec(vec![th1, rho2, rho3]);
        let q = kin.solve_coordinates(&u, &DVector::from_vec(m.reference_configuration())).unwrap();
        proptest::prop_assert!((kin.actuator_values(&q) - &u).amax() < 1e-11);
        let sum = q[1] + q[2];
        proptest::prop_assert!(sum > 0.0 && sum < std::f64::consts::PI);
        // Unique solution on this branch: the closed-form end point matches.
        let end = kin.body_pose(m.body_index("carrier").unwrap(), &q).position;
        proptest::prop_assert!((end.y - (6.0 * D2 - 5.0 * rho3)).abs() < 1e-10);
        proptest::prop_assert!((end.x - (6.0 * rho2 - 5.0 * D3) * th1.cos()).abs() < 1e-10);
    }
}
