//! Balance search on mechanisms whose balancing conditions are known in closed form.

use counterpoise_balance::{
    Attachment, BodyFrame, Catalogue, CatalogueOptions, MechanismEnergy, Plane, RealizationHints,
    SearchOptions, Status, search,
};
use counterpoise_symbolic::{LinearAngle, PolyMat3, PolyVec3, VarKind};

const G: f64 = 9.81;

fn gravity_energy(
    frames: &[BodyFrame],
    masses: &[(usize, f64, [f64; 3])],
) -> counterpoise_symbolic::TrigPoly {
    let mut v = counterpoise_symbolic::TrigPoly::zero();
    for &(body, m, c) in masses {
        let p = frames[body]
            .origin
            .add(&frames[body].rotation.mul_const_vec(c));
        v -= &p.dot_const([0.0, -G, 0.0]).scale(m);
    }
    v
}

/// One link rotating about the base z axis at the origin; gravity −y.
fn pendulum(mass: f64, com: f64) -> MechanismEnergy {
    let frames = vec![BodyFrame {
        name: "link".into(),
        rotation: PolyMat3::rot_z(&LinearAngle::coordinate(0)),
        origin: PolyVec3::zero(),
    }];
    let unbalanced = gravity_energy(&frames, &[(0, mass, [com, 0.0, 0.0])]);
    MechanismEnergy {
        kinds: vec![VarKind::Angle],
        ranges: vec![(-3.2, 3.2)],
        gravity: [0.0, -G, 0.0],
        bodies: frames,
        unbalanced,
        exact: Err("built by hand with numeric coefficients".to_string()),
        surd: Err("built by hand with numeric coefficients".to_string()),
    }
}

fn options(cw: Vec<usize>, springs: Vec<(usize, Attachment)>) -> CatalogueOptions {
    CatalogueOptions {
        counterweight_bodies: cw,
        counterweight_plane: Some(Plane::Xy),
        spring_pairs: springs,
        spring_plane: Some(Plane::Xy),
    }
}

fn run(
    energy: &MechanismEnergy,
    opts: CatalogueOptions,
    dmax: usize,
) -> counterpoise_balance::SearchReport {
    let catalogue = Catalogue::build(energy, &opts);
    search(
        energy,
        catalogue,
        SearchOptions {
            dmax,
            hints: RealizationHints::default(),
        },
    )
}

#[test]
fn pendulum_counterweight_balances_with_m_r_equal_to_minus_m_c() {
    let (mass, com) = (2.0, 0.3);
    let energy = pendulum(mass, com);
    let report = run(&energy, options(vec![0], vec![]), 1);
    assert_eq!(report.variants.len(), 1);
    let v = &report.variants[0];
    assert_eq!(v.status, Status::Balanced, "{v:?}");
    let cw = &v.witness.as_ref().unwrap().counterweights[0];
    // closed form: m·r = −m_link·c along x, nothing along y; m itself is free
    assert!((cw.mass * cw.offset[0] + mass * com).abs() < 1e-9, "{cw:?}");
    assert!((cw.mass * cw.offset[1]).abs() < 1e-9, "{cw:?}");
    assert!(cw.mass > 0.0);
    assert!(v.verification.unwrap().residual < 1e-9);
    assert_eq!(v.nullity, 1, "the mass is the designer's freedom");
    assert!(
        v.relations
            .iter()
            .any(|r| r.starts_with("m1·r1x = -0.6 kg·m")),
        "{:?}",
        v.relations
    );
}

#[test]
fn pendulum_spring_to_base_balances_with_k_a_b_equal_to_m_g_c() {
    // Wang & Kong Eq. 1: a zero-free-length spring from the link to a base point above the pivot
    // balances when K·a·b = m·g·c, with the anchors perpendicular (a·b = 0).
    let (mass, com) = (2.0, 0.3);
    let energy = pendulum(mass, com);
    let report = run(&energy, options(vec![], vec![(0, Attachment::Base)]), 1);
    let v = &report.variants[0];
    assert_eq!(v.elements[0].bodies, vec!["link", "base"]);
    assert_eq!(v.status, Status::Balanced, "{v:?}");
    let s = &v.witness.as_ref().unwrap().springs[0];
    let (a, b) = (s.anchor_a, s.anchor_b);
    let cross = a[0] * b[1] - a[1] * b[0];
    let dot = a[0] * b[0] + a[1] * b[1];
    assert!((s.stiffness * cross - mass * G * com).abs() < 1e-8, "{s:?}");
    assert!((s.stiffness * dot).abs() < 1e-8, "{s:?}");
    assert!(s.stiffness > 0.0);
}

/// Planar two-link arm: link 1 about the base z axis, link 2 about z at the tip of link 1.
fn two_link(l1: f64, m1: f64, c1: f64, m2: f64, c2: f64) -> MechanismEnergy {
    let r1 = PolyMat3::rot_z(&LinearAngle::coordinate(0));
    let r2 = PolyMat3::rot_z(&LinearAngle {
        terms: vec![(0, 1), (1, 1)],
        offset: 0.0,
    });
    let frames = vec![
        BodyFrame {
            name: "link1".into(),
            rotation: r1.clone(),
            origin: PolyVec3::zero(),
        },
        BodyFrame {
            name: "link2".into(),
            rotation: r2,
            origin: r1.mul_const_vec([l1, 0.0, 0.0]),
        },
    ];
    let unbalanced = gravity_energy(&frames, &[(0, m1, [c1, 0.0, 0.0]), (1, m2, [c2, 0.0, 0.0])]);
    MechanismEnergy {
        kinds: vec![VarKind::Angle, VarKind::Angle],
        ranges: vec![(-3.2, 3.2), (-3.2, 3.2)],
        gravity: [0.0, -G, 0.0],
        bodies: frames,
        unbalanced,
        exact: Err("built by hand with numeric coefficients".to_string()),
        surd: Err("built by hand with numeric coefficients".to_string()),
    }
}

#[test]
fn two_link_arm_needs_counterweights_on_both_links() {
    let (l1, m1, c1, m2, c2) = (1.0, 3.0, 0.5, 2.0, 0.4);
    let energy = two_link(l1, m1, c1, m2, c2);
    let report = run(&energy, options(vec![0, 1], vec![]), 2);
    // enumeration order: {m1}, {m2}, {m1, m2}
    let labels: Vec<Vec<&str>> = report
        .variants
        .iter()
        .map(|v| v.elements.iter().map(|e| e.label.as_str()).collect())
        .collect();
    assert_eq!(labels, vec![vec!["m1"], vec!["m2"], vec!["m1", "m2"]]);
    assert_eq!(report.variants[0].status, Status::Infeasible);
    assert!(
        report.variants[0].linear_residual > 0.1,
        "{:?}",
        report.variants[0]
    );
    // Link 2 alone: the lifted equations do have a solution, but only with a negative mass,
    // m·l1 = −(m1·c1 + m2·l1), the counterweight's share of lifting link 1 — a proof that no
    // physical counterweight on link 2 alone balances the arm.
    let alone = &report.variants[1];
    assert_eq!(alone.status, Status::Unrealizable, "{alone:?}");
    let forced = -(m1 * c1 + m2 * l1) / l1;
    let reason = alone.reason.as_deref().unwrap();
    assert!(reason.contains(&format!("({forced:.4} kg)")), "{reason}");
    let both = &report.variants[2];
    assert_eq!(both.status, Status::Balanced, "{both:?}");
    let w = both.witness.as_ref().unwrap();
    let (cw1, cw2) = (&w.counterweights[0], &w.counterweights[1]);
    // closed form: link 2 balanced about its joint, then link 1 carries link 2 + its counterweight
    assert!((cw2.mass * cw2.offset[0] + m2 * c2).abs() < 1e-9, "{cw2:?}");
    assert!((cw2.mass * cw2.offset[1]).abs() < 1e-9);
    let expected = -(m1 * c1 + (m2 + cw2.mass) * l1);
    assert!(
        (cw1.mass * cw1.offset[0] - expected).abs() < 1e-8,
        "{cw1:?} expected {expected}"
    );
    assert!((cw1.mass * cw1.offset[1]).abs() < 1e-9);
}
