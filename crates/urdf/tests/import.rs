//! Imported URDF robots against closed forms, hand calculations and the same arm written by hand.

use counterpoise_balance::{
    Catalogue, SearchOptions, Status, catalogue_options, mechanism_energy, realization_hints,
    search,
};
use counterpoise_model::{Case, Kinematics, Model};
use counterpoise_urdf::{ImportOptions, UrdfError, import};
use nalgebra::{DVector, Matrix3, Vector3};

const G: f64 = 9.81;

fn data(name: &str) -> String {
    let path = format!("{}/tests/data/{name}", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

fn imported(name: &str) -> counterpoise_urdf::Imported {
    import(&data(name), &ImportOptions::default()).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Gravitational potential energy from the model's world poses, payloads included.
fn potential(model: &Model, q: &[f64]) -> f64 {
    let kin = Kinematics::new(model);
    let poses = kin.body_poses(&DVector::from_column_slice(q));
    let g = Vector3::from(model.gravity);
    let mut v = 0.0;
    for (body, pose) in model.bodies.iter().zip(&poses) {
        v -= body.mass * g.dot(&(pose.position + pose.rotation * body.com));
    }
    for p in &model.payloads {
        let pose = &poses[p.body];
        v -= p.mass * g.dot(&(pose.position + pose.rotation * p.com));
    }
    v
}

/// Gravity torques `∂V/∂q` by central differences (h = 1e-6: error ~1e-10 here).
fn gravity_torques(model: &Model, q: &[f64]) -> Vec<f64> {
    (0..q.len())
        .map(|k| {
            let h = 1e-6;
            let (mut up, mut down) = (q.to_vec(), q.to_vec());
            up[k] += h;
            down[k] -= h;
            (potential(model, &up) - potential(model, &down)) / (2.0 * h)
        })
        .collect()
}

/// Deterministic pseudo-random configurations inside the coordinate ranges.
fn configurations(model: &Model, n: usize) -> Vec<Vec<f64>> {
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n)
        .map(|_| {
            model
                .coordinates
                .iter()
                .map(|c| c.range[0] + (c.range[1] - c.range[0]) * next())
                .collect()
        })
        .collect()
}

#[test]
fn two_link_arm_has_the_closed_form_gravity_torques() {
    let model = imported("two_link.urdf").model;
    assert_eq!(model.bodies.len(), 2);
    assert_eq!(model.bodies[0].name, "link1");
    assert_eq!(model.coordinates[1].name, "elbow");
    assert_eq!(model.coordinates[1].range, [-2.5, 2.5]);
    let (m1, m2, l1, c1, c2, z0) = (4.0, 2.5, 0.8, 0.4, 0.3, 0.5);
    for q in configurations(&model, 20) {
        let (t1, t2) = (q[0], q[1]);
        // About −y, a positive angle lifts the x axis: heights z0 + c·sin(angle).
        let v = G * (m1 * (z0 + c1 * t1.sin()) + m2 * (z0 + l1 * t1.sin() + c2 * (t1 + t2).sin()));
        let tau1 = G * ((m1 * c1 + m2 * l1) * t1.cos() + m2 * c2 * (t1 + t2).cos());
        let tau2 = G * m2 * c2 * (t1 + t2).cos();
        assert!((potential(&model, &q) - v).abs() < 1e-12, "{q:?}");
        let tau = gravity_torques(&model, &q);
        assert!((tau[0] - tau1).abs() < 1e-7, "{q:?}: {tau:?} vs {tau1}");
        assert!((tau[1] - tau2).abs() < 1e-7, "{q:?}: {tau:?} vs {tau2}");
    }
    // The energy polynomial the balance search uses agrees too (exact derivative).
    let energy = mechanism_energy(&model);
    let kin = Kinematics::new(&model);
    let q = [0.7, -1.1];
    let at = kin.point(&DVector::from_column_slice(&q));
    let dv = energy
        .unbalanced
        .derivative(0, counterpoise_symbolic::VarKind::Angle)
        .eval(&at);
    let tau1 = G * ((m1 * c1 + m2 * l1) * q[0].cos() + m2 * c2 * (q[0] + q[1]).cos());
    assert!((dv - tau1).abs() < 1e-12, "{dv} vs {tau1}");
}

#[test]
fn two_link_arm_actuators_grid_and_balancing_follow_the_urdf() {
    let imported = imported("two_link.urdf");
    let model = &imported.model;
    let names: Vec<&str> = model.actuators.iter().map(|a| a.name.as_str()).collect();
    assert_eq!(names, ["shoulder", "elbow"]);
    assert!(model.actuators.iter().all(|a| a.ratio == 1.0));
    let balancing = model.balancing.as_ref().unwrap();
    assert_eq!(balancing.peak_limits, vec![Some(120.0), Some(40.0)]);
    assert_eq!(
        balancing.counterweights.as_ref().unwrap().bodies,
        vec![0, 1]
    );
    let springs = balancing.springs.as_ref().unwrap();
    assert!(springs.include_base);
    assert_eq!(springs.pairs().len(), 3, "K10, K20, K21");
    let grid = &model.tasks.as_ref().unwrap().grid;
    assert_eq!(grid.len(), 2);
    assert_eq!((grid[0].from, grid[0].to, grid[0].n), (-1.5, 1.5, 3));
    assert_eq!((grid[1].from, grid[1].to, grid[1].n), (-2.5, 2.5, 3));
    // Every angle is a quarter turn or a coordinate: the exact decision runs.
    assert!(counterpoise_model::exact_mechanism(model).is_ok());
}

#[test]
fn balance_search_finds_the_counterweight_pair_on_the_imported_two_link_arm() {
    let model = imported("two_link.urdf").model;
    let energy = mechanism_energy(&model);
    let catalogue = Catalogue::build(&energy, &catalogue_options(&model));
    let report = search(
        &energy,
        catalogue,
        SearchOptions {
            dmax: 2,
            hints: realization_hints(&model),
        },
    );
    let labels = |v: &counterpoise_balance::VariantResult| -> Vec<String> {
        v.elements.iter().map(|e| e.label.clone()).collect()
    };
    let pair = report
        .variants
        .iter()
        .find(|v| labels(v) == ["m1", "m2"])
        .expect("the counterweight pair is a candidate");
    assert_eq!(pair.status, Status::Balanced, "{pair:?}");
    // Closed form: the counterweight on link 2 cancels its first moment, m2'·r2' = −m2·c2 along
    // x; the one on link 1 cancels link 1 and everything it carries at the elbow.
    let w = pair.witness.as_ref().unwrap();
    let (cw1, cw2) = (&w.counterweights[0], &w.counterweights[1]);
    assert!(
        (cw2.mass * cw2.offset[0] + 2.5 * 0.3).abs() < 1e-9,
        "{cw2:?}"
    );
    let carried = 2.5 + cw2.mass;
    assert!(
        (cw1.mass * cw1.offset[0] + 4.0 * 0.4 + carried * 0.8).abs() < 1e-9,
        "{cw1:?}"
    );
    // A single counterweight on link 1 cannot hold link 2 at every elbow angle.
    let alone = report
        .variants
        .iter()
        .find(|v| labels(v) == ["m1"])
        .unwrap();
    assert_ne!(alone.status, Status::Balanced);
}

#[test]
fn fixed_joints_merge_mass_com_and_inertia_by_the_parallel_axis_theorem() {
    let model = imported("fixed_merge.urdf").model;
    assert_eq!(
        model.bodies.len(),
        1,
        "bracket, motor and flange merge into arm"
    );
    let arm = &model.bodies[0];
    // Hand calculation (see fixed_merge.urdf): arm 2 kg at (0.5, 0, 0); bracket 1 kg at
    // (1, 0, 0.1), inertia diag(0.01, 0.03, 0.02) turned a quarter about z → diag(0.03, 0.01,
    // 0.02); motor 1 kg at (1, 0, 0.3), diag(0.004, 0.005, 0.006) turned a quarter about y →
    // diag(0.006, 0.005, 0.004). Total 4 kg at (0.75, 0, 0.1); the offsets from it add
    // xx 0.02 + 0 + 0.04, yy 0.145 + 0.0625 + 0.1025, zz 0.125 + 0.0625 + 0.0625, xz −0.05 − 0.05.
    assert_eq!(arm.mass, 4.0);
    assert!(
        (arm.com - Vector3::new(0.75, 0.0, 0.1)).norm() < 1e-15,
        "{}",
        arm.com
    );
    let expected = Matrix3::new(0.106, 0.0, -0.1, 0.0, 0.525, 0.0, -0.1, 0.0, 0.474);
    assert!(
        (arm.inertia_com - expected).norm() < 1e-14,
        "{}",
        arm.inertia_com
    );
}

#[test]
fn arm_with_offset_rpy_and_tilted_axis_matches_the_same_arm_written_by_hand() {
    let urdf = imported("three_dof.urdf").model;
    let hand = Case::from_json_str(&data("three_dof.json")).expect("hand-written case");
    assert_eq!(urdf.bodies.len(), 3, "the tool merges into l3");
    for q in configurations(&hand, 40) {
        let (a, b) = (potential(&urdf, &q), potential(&hand, &q));
        assert!((a - b).abs() < 1e-12, "{q:?}: {a} vs {b}");
        let (ta, tb) = (gravity_torques(&urdf, &q), gravity_torques(&hand, &q));
        for k in 0..3 {
            assert!((ta[k] - tb[k]).abs() < 1e-7, "{q:?}: {ta:?} vs {tb:?}");
        }
        // The body frames agree too, so inertia and dynamics do.
        let kin_u = Kinematics::new(&urdf);
        let kin_h = Kinematics::new(&hand);
        let qv = DVector::from_column_slice(&q);
        for (pu, ph) in kin_u.body_poses(&qv).iter().zip(kin_h.body_poses(&qv)) {
            assert!((pu.rotation - ph.rotation).norm() < 1e-12);
            assert!((pu.position - ph.position).norm() < 1e-12);
        }
    }
    // l2's inertial frame is turned 0.5 rad about z: I = Rz·diag(0.002, 0.06, 0.06)·Rzᵀ.
    let (c, s) = (0.5_f64.cos(), 0.5_f64.sin());
    let i = urdf.bodies[1].inertia_com;
    assert!((i[(0, 0)] - (c * c * 0.002 + s * s * 0.06)).abs() < 1e-15);
    assert!((i[(1, 1)] - (s * s * 0.002 + c * c * 0.06)).abs() < 1e-15);
    assert!((i[(0, 1)] - c * s * (0.002 - 0.06)).abs() < 1e-15);
    assert!((i[(2, 2)] - 0.06).abs() < 1e-15);
    // rpy 0.3 is not a quarter turn: the case takes the numeric path.
    assert!(counterpoise_model::exact_mechanism(&urdf).is_err());
}

#[test]
fn quarter_turns_are_written_exactly_and_other_angles_as_decimals() {
    let text = imported("three_dof.urdf").json;
    assert!(text.contains("\"pi/2\""), "{text}");
    assert!(text.contains("\"rot_x\": 0.3"), "{text}");
    assert!(!text.contains("1.5707963"), "{text}");
    // A quarter turn off by 2e-9 is not snapped.
    let off = data("two_link.urdf").replace(
        "<origin xyz=\"0.8 0 0\"/>",
        "<origin xyz=\"0.8 0 0\" rpy=\"1.570796328794897 0 0\"/>",
    );
    let imported = import(&off, &ImportOptions::default()).unwrap();
    assert!(imported.json.contains("1.570796328794897"));
    assert!(counterpoise_model::exact_mechanism(&imported.model).is_err());
    // Within 1e-9 it is.
    let near = data("two_link.urdf").replace(
        "<origin xyz=\"0.8 0 0\"/>",
        "<origin xyz=\"0.8 0 0\" rpy=\"3.1415926538 0 0\"/>",
    );
    let imported = import(&near, &ImportOptions::default()).unwrap();
    assert!(
        imported.json.contains("\"rot_x\": \"pi\""),
        "{}",
        imported.json
    );
    assert!(counterpoise_model::exact_mechanism(&imported.model).is_ok());
}

#[test]
fn tip_freezes_the_joints_beyond_it_and_base_cuts_the_links_above() {
    let options = ImportOptions {
        base: None,
        tip: Some("l2".into()),
    };
    let model = import(&data("three_dof.urdf"), &options).unwrap().model;
    assert_eq!(model.bodies.len(), 2);
    assert_eq!(model.coordinates.len(), 2);
    // l3 and the tool are frozen at j3 = 0 and carried by l2: 2 + 1.5 + 0.5 kg.
    assert_eq!(model.bodies[1].mass, 4.0);
    for q in configurations(&model, 10) {
        let value = |joint: &str| match joint {
            "j1" => q[0],
            "j2" => q[1],
            _ => 0.0,
        };
        let expected = urdf_potential(&data("three_dof.urdf"), &value);
        assert!((potential(&model, &q) - expected).abs() < 1e-11, "{q:?}");
    }
    // Frozen at a value clamped into the limits: j3 ∈ [0.5, 2.5] freezes at 0.5.
    let shifted = data("three_dof.urdf").replace(
        "<limit lower=\"-2.5\" upper=\"2.5\" effort=\"30\"",
        "<limit lower=\"0.5\" upper=\"2.5\" effort=\"30\"",
    );
    let model = import(&shifted, &options_tip()).unwrap().model;
    for q in configurations(&model, 10) {
        let value = |joint: &str| match joint {
            "j1" => q[0],
            "j2" => q[1],
            _ => 0.5,
        };
        let expected = urdf_potential(&shifted, &value);
        assert!((potential(&model, &q) - expected).abs() < 1e-11, "{q:?}");
    }
    let options = ImportOptions {
        base: Some("l1".into()),
        tip: None,
    };
    let model = import(&data("three_dof.urdf"), &options).unwrap().model;
    let names: Vec<&str> = model.bodies.iter().map(|b| b.name.as_str()).collect();
    assert_eq!(names, ["l2", "l3"]);
}

fn options_tip() -> ImportOptions {
    ImportOptions {
        base: None,
        tip: Some("l2".into()),
    }
}

fn error_of(urdf: &str) -> String {
    match import(urdf, &ImportOptions::default()) {
        Err(e) => e.to_string(),
        Ok(_) => panic!("accepted:\n{urdf}"),
    }
}

#[test]
fn malformed_urdf_is_refused_naming_the_element() {
    let two = data("two_link.urdf");
    let negative = two.replace("<mass value=\"2.5\"/>", "<mass value=\"-2.5\"/>");
    assert_eq!(
        error_of(&negative),
        "link `link2`.inertial.mass.value: negative mass -2.5 kg"
    );
    let unknown = two.replace("<parent link=\"link1\"/>", "<parent link=\"link9\"/>");
    assert_eq!(
        error_of(&unknown),
        "joint `elbow`.parent: parent link `link9` does not exist"
    );
    let two_roots = two.replace(
        "<link name=\"world\"/>",
        "<link name=\"world\"/><link name=\"spare\"/>",
    );
    assert!(
        error_of(&two_roots).contains("two root links, `world` and `spare`"),
        "{}",
        error_of(&two_roots)
    );
    let cycle = two.replace(
        "</robot>",
        "<link name=\"a\"/><link name=\"b\"/>\
         <joint name=\"ab\" type=\"fixed\"><parent link=\"a\"/><child link=\"b\"/></joint>\
         <joint name=\"ba\" type=\"fixed\"><parent link=\"b\"/><child link=\"a\"/></joint></robot>",
    );
    assert!(
        error_of(&cycle).contains("form a cycle"),
        "{}",
        error_of(&cycle)
    );
    let closed = two.replace(
        "</robot>",
        "<joint name=\"loop\" type=\"fixed\"><parent link=\"world\"/><child link=\"link2\"/></joint></robot>",
    );
    assert!(
        error_of(&closed)
            .starts_with("joint `loop`: link `link2` is already the child of joint `elbow`"),
        "{}",
        error_of(&closed)
    );
    let floating = two.replace(
        "type=\"revolute\">\n    <parent link=\"link1\"",
        "type=\"floating\">\n    <parent link=\"link1\"",
    );
    assert!(
        error_of(&floating).starts_with("joint `elbow`.type: `floating`"),
        "{}",
        error_of(&floating)
    );
    let no_limit = two.replace(
        "<limit lower=\"-2.5\" upper=\"2.5\" effort=\"40\" velocity=\"2\"/>",
        "",
    );
    assert!(
        error_of(&no_limit).starts_with("joint `elbow`.limit:"),
        "{}",
        error_of(&no_limit)
    );
    let mimic = two.replace(
        "<limit lower=\"-2.5\"",
        "<mimic joint=\"shoulder\" multiplier=\"0.5\"/><limit lower=\"-2.5\"",
    );
    assert!(
        error_of(&mimic).starts_with("joint `elbow`.mimic: revolute joint mimicking revolute joint `shoulder` with multiplier 0.5"),
        "{}",
        error_of(&mimic)
    );
    assert!(matches!(
        import("<robot><link", &ImportOptions::default()),
        Err(UrdfError::Xml(_))
    ));
}

/// An axis is checked by its norm: `0 -1e308 0` is a finite vector whose norm overflows (its
/// square is past f64::MAX), `0 -1e-308 0` one whose norm underflows to zero, and `0 0 0` has
/// none; each is refused at the joint's `axis.xyz`.
#[test]
fn an_axis_whose_norm_overflows_or_vanishes_is_refused() {
    let two = data("two_link.urdf");
    let elbow = two.rfind("<axis xyz=\"0 -1 0\"/>").unwrap();
    let with = |xyz: &str| {
        format!(
            "{}<axis xyz=\"{xyz}\"/>{}",
            &two[..elbow],
            &two[elbow + "<axis xyz=\"0 -1 0\"/>".len()..]
        )
    };
    let huge = error_of(&with("0 -1e308 0"));
    assert!(
        huge.starts_with("joint `elbow`.axis.xyz: the axis's length overflows"),
        "{huge}"
    );
    let tiny = error_of(&with("0 -1e-308 0"));
    assert!(
        tiny.starts_with("joint `elbow`.axis.xyz: the axis's length 1e-308 is below 1e-12"),
        "{tiny}"
    );
    assert_eq!(
        error_of(&with("0 0 0")),
        "joint `elbow`.axis.xyz: axis must not be zero"
    );
    // A long axis whose norm stays finite is a direction like any other.
    assert!(import(&with("0 -1e150 0"), &ImportOptions::default()).is_ok());
}

#[test]
fn a_linear_mimic_follows_its_joint() {
    // The elbow mimics the shoulder twice over: link 2's angle is 3·shoulder.
    let two = data("two_link.urdf").replace(
        "<limit lower=\"-2.5\"",
        "<mimic joint=\"shoulder\" multiplier=\"2\"/><limit lower=\"-2.5\"",
    );
    let model = import(&two, &ImportOptions::default()).unwrap().model;
    assert_eq!(model.coordinates.len(), 1);
    assert_eq!(model.actuators.len(), 1);
    let t = 0.4_f64;
    let v = G * (4.0 * (0.5 + 0.4 * t.sin()) + 2.5 * (0.5 + 0.8 * t.sin() + 0.3 * (3.0 * t).sin()));
    assert!((potential(&model, &[t]) - v).abs() < 1e-12);
}

/// The potential energy by the URDF's own forward kinematics (nalgebra isometries, joint after
/// joint from the parsed file): an independent second method for the imported poses.
fn urdf_potential(urdf: &str, q_of: &dyn Fn(&str) -> f64) -> f64 {
    use nalgebra::{Isometry3, Translation3, Unit, UnitQuaternion};
    let robot = counterpoise_urdf::parse::parse(urdf).unwrap();
    let iso = |o: &counterpoise_urdf::parse::Origin| {
        Isometry3::from_parts(
            Translation3::new(o.xyz[0], o.xyz[1], o.xyz[2]),
            UnitQuaternion::from_euler_angles(o.rpy[0], o.rpy[1], o.rpy[2]),
        )
    };
    let mut world: std::collections::HashMap<String, Isometry3<f64>> = Default::default();
    let child_links: Vec<&str> = robot.joints.iter().map(|j| j.child.as_str()).collect();
    let root = robot
        .links
        .iter()
        .find(|l| !child_links.contains(&l.name.as_str()))
        .unwrap();
    world.insert(root.name.clone(), Isometry3::identity());
    while world.len() < robot.links.len() {
        for j in &robot.joints {
            let Some(parent) = world.get(&j.parent).copied() else {
                continue;
            };
            let axis = Unit::new_normalize(Vector3::from(j.axis));
            let motion = match j.kind {
                counterpoise_urdf::parse::JointType::Fixed => Isometry3::identity(),
                counterpoise_urdf::parse::JointType::Prismatic => Isometry3::from_parts(
                    Translation3::from(axis.into_inner() * q_of(&j.name)),
                    UnitQuaternion::identity(),
                ),
                _ => Isometry3::from_parts(
                    Translation3::identity(),
                    UnitQuaternion::from_axis_angle(&axis, q_of(&j.name)),
                ),
            };
            world.insert(j.child.clone(), parent * iso(&j.origin) * motion);
        }
    }
    robot
        .links
        .iter()
        .filter_map(|l| l.inertial.map(|i| (l, i)))
        .map(|(l, i)| {
            let com = world[&l.name] * nalgebra::Point3::from(i.origin.xyz);
            i.mass * G * com.z
        })
        .sum()
}

#[test]
fn imported_energy_matches_urdf_forward_kinematics_on_every_test_robot() {
    // The two-link arm on a slide along the tilted axis (0.6, 0, 0.8) instead of its shoulder.
    let slide = data("two_link.urdf")
        .replace(
            "name=\"shoulder\" type=\"revolute\"",
            "name=\"shoulder\" type=\"prismatic\"",
        )
        .replacen("<axis xyz=\"0 -1 0\"/>", "<axis xyz=\"0.6 0 0.8\"/>", 1);
    let robots = [
        ("two_link.urdf", data("two_link.urdf")),
        ("three_dof.urdf", data("three_dof.urdf")),
        ("seven_dof.urdf", data("seven_dof.urdf")),
        ("fixed_merge.urdf", data("fixed_merge.urdf")),
        ("slide", slide),
    ];
    for (name, text) in robots {
        let model = import(&text, &ImportOptions::default()).unwrap().model;
        for q in configurations(&model, 25) {
            let value = |joint: &str| {
                model
                    .coordinates
                    .iter()
                    .position(|c| c.name == joint)
                    .map_or(0.0, |k| q[k])
            };
            let expected = urdf_potential(&text, &value);
            let got = potential(&model, &q);
            assert!(
                (got - expected).abs() < 1e-11,
                "{name} at {q:?}: {got} vs {expected}"
            );
        }
        if name == "slide" {
            assert_eq!(
                model.coordinates[0].kind,
                counterpoise_symbolic::VarKind::Length
            );
        }
    }
}

#[test]
fn seven_dof_arm_is_exact_with_the_hand_merged_into_the_last_link() {
    let imported = imported("seven_dof.urdf");
    let model = &imported.model;
    assert_eq!(model.bodies.len(), 7);
    assert_eq!(model.coordinates.len(), 7);
    // link7 0.74 kg at z 0.08 and the hand 0.73 kg at z 0.107 + 0.02 (turned about z only).
    let last = &model.bodies[6];
    assert!((last.mass - 1.47).abs() < 1e-15);
    let z = (0.74 * 0.08 + 0.73 * 0.127) / 1.47;
    assert!((last.com.z - z).abs() < 1e-15, "{}", last.com);
    // Every rpy is a quarter turn: no decimal angle in the file, the exact decision runs.
    assert!(!imported.json.contains("1.5707963"));
    assert!(counterpoise_model::exact_mechanism(model).is_ok());
    // 3 points on the first four joints, the wrist at mid-range: 81 points.
    let grid = &model.tasks.as_ref().unwrap().grid;
    let points: usize = grid.iter().map(|a| a.n).product();
    assert_eq!(points, 81);
    assert_eq!((grid[6].from, grid[6].n), (0.0, 1));
}
