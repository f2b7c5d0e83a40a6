//! From a parsed [`Case`] to a validated [`Model`].
//!
//! The validator keeps going after a problem so that all of them are reported at once; a
//! check that depends on an earlier failed one (the consistency of a joint whose body has a
//! broken pose) is skipped rather than reported twice.

mod balancing;
mod joint_input;
mod magnitudes;
mod tasks;
mod topology;
mod validator;

pub use magnitudes::*;
pub use tasks::task_count;

use std::collections::{BTreeMap, HashMap};

use counterpoise_symbolic::{ExprContext, MAX_VARS, VarKind};
use nalgebra::{Matrix3, Vector3};

use crate::case::{Case, CoordinateKindSpec, JointKindSpec};
use crate::error::CaseErrors;
pub use crate::inertia::{EIGEN_MAX_ITERATIONS, principal_moments};
use crate::joints;
use crate::limits::{Limit, Limits};
use crate::model::{
    Actuator, Body, BodyId, Bounds, Coordinate, Joint, MechanismScale, Model, Payload,
};
use crate::pose::{Parser, PolyPose};
use crate::reader::too_large;
use crate::sampling::{DEFAULT_SEED, VALIDATION_SAMPLES, sample_configurations};
use balancing::*;
use joint_input::*;
use tasks::*;
use topology::*;
use validator::*;

/// Validates a parsed case into a model with the default [`Limits`], reporting every problem
/// found.
pub fn validate(case: Case) -> Result<Model, CaseErrors> {
    validate_with(case, &Limits::default())
}

/// Validates a parsed case into a model, reporting every problem found.
pub fn validate_with(case: Case, limits: &Limits) -> Result<Model, CaseErrors> {
    let mut v = Validator {
        errors: Vec::new(),
        limits: *limits,
    };

    v.name(&case.name, "name");
    v.bounded(&case.gravity, MAX_GRAVITY, "gravity", "m/s²");
    if case.parameters.len() as u64 > limits.parameters {
        v.push(too_large(
            "parameters",
            "parameters",
            case.parameters.len() as f64,
            Limit::Parameters,
            limits.parameters,
        ));
        return Err(CaseErrors::new(v.errors));
    }

    // ---- parameters and coordinates: the names expressions may use
    let mut names: HashMap<String, String> = HashMap::new();
    let mut parameters = BTreeMap::new();
    for (name, &value) in case.parameters.iter() {
        let path = format!("parameters.{name}");
        if !is_identifier(name) || RESERVED.contains(&name) {
            v.invalid(
                &path,
                format!(
                    "`{name}` is not a valid parameter name (an identifier other than pi, cos, sin)"
                ),
            );
        }
        if !value.is_finite() {
            v.invalid(&path, format!("{value} is not a finite number"));
        } else {
            v.magnitude(value, MAX_PARAMETER, &path, "");
        }
        names.insert(name.to_string(), path);
        parameters.insert(name.to_string(), value);
    }
    if case.coordinates.len() > MAX_VARS {
        v.invalid(
            "coordinates",
            format!(
                "at most {MAX_VARS} coordinates are supported (found {})",
                case.coordinates.len()
            ),
        );
        return Err(CaseErrors::new(v.errors));
    }
    let mut coordinates = Vec::new();
    let mut coordinates_ok = true;
    for (i, c) in case.coordinates.iter().enumerate() {
        let path = format!("coordinates[{i}]");
        if !is_identifier(&c.name) || RESERVED.contains(&c.name.as_str()) {
            v.invalid(
                format!("{path}.name"),
                format!(
                    "`{}` is not a valid coordinate name (an identifier other than pi, cos, sin)",
                    c.name
                ),
            );
            coordinates_ok = false;
        }
        coordinates_ok &= v.unique(&mut names, &c.name, format!("{path}.name"), "name");
        let range_path = format!("{path}.range");
        let (max, unit) = match c.kind {
            CoordinateKindSpec::Angle => (MAX_ANGLE, "rad"),
            CoordinateKindSpec::Length => (MAX_LENGTH, "m"),
        };
        if !v.bounded(&c.range, max, &range_path, unit) {
            coordinates_ok = false;
        } else if c.range[0] >= c.range[1] {
            v.invalid(
                &range_path,
                format!("min must be < max (found [{}, {}])", c.range[0], c.range[1]),
            );
            coordinates_ok = false;
        }
        coordinates.push(Coordinate {
            name: c.name.clone(),
            kind: match c.kind {
                CoordinateKindSpec::Angle => VarKind::Angle,
                CoordinateKindSpec::Length => VarKind::Length,
            },
            range: c.range,
        });
    }
    let context = ExprContext::new(
        parameters,
        coordinates
            .iter()
            .map(|c| (c.name.clone(), c.kind))
            .collect(),
    );
    let context = context.with_limits(limits.expressions());
    let parser = Parser { context: &context };

    // ---- bodies: names, parents, inertial data, poses
    let mut body_names: HashMap<String, String> = HashMap::new();
    for (i, b) in case.bodies.iter().enumerate() {
        let path = format!("bodies[{i}].name");
        v.name(&b.name, &path);
        if b.name == "base" {
            v.invalid(&path, "`base` is reserved for the fixed frame");
        } else {
            v.unique(&mut body_names, &b.name, path, "body");
        }
    }
    let body_id = |name: &str| -> Option<BodyId> {
        if name == "base" {
            Some(BodyId::Base)
        } else {
            case.bodies
                .iter()
                .position(|b| b.name == name)
                .map(BodyId::Body)
        }
    };
    let mut parents = Vec::new();
    for (i, b) in case.bodies.iter().enumerate() {
        let parent = body_id(&b.parent);
        if parent.is_none() {
            v.unknown(format!("bodies[{i}].parent"), "body", &b.parent);
        }
        parents.push(parent);
    }
    let on_cycle = find_cycles(&mut v, &case, &parents);

    let mut relative = Vec::new();
    let mut inertial = Vec::new();
    for (i, b) in case.bodies.iter().enumerate() {
        let path = format!("bodies[{i}]");
        let pose_path = format!("{path}.pose");
        relative.push(
            v.list_size(b.pose.len(), &pose_path)
                .then(|| parser.pose(&b.pose, &pose_path, &mut v.errors))
                .flatten()
                .map(|mut pose| {
                    pose.prune();
                    pose
                })
                .filter(|pose| pose_in_bounds(&mut v, pose, &pose_path)),
        );
        v.non_negative_at_most(b.mass, MAX_MASS, &format!("{path}.mass"), "kg");
        let com = match &b.com {
            Some(e) => {
                let com_path = format!("{path}.com");
                let value = parser.constant_vec(e, &com_path, &mut v.errors);
                v.length_vec(value, &com_path).map(Vector3::from)
            }
            None if b.mass > 0.0 => {
                v.invalid(format!("{path}.com"), "required when mass > 0");
                None
            }
            None => Some(Vector3::zeros()),
        };
        let inertia = match &b.inertia {
            Some(values) => v.inertia(values, &format!("{path}.inertia")),
            None if b.mass > 0.0 => {
                v.invalid(format!("{path}.inertia"), "required when mass > 0");
                None
            }
            None => Some(Matrix3::zeros()),
        };
        inertial.push((com, inertia));
    }
    let world = world_poses(&mut v, &parents, &relative, &on_cycle);

    // ---- payloads
    let mut payloads = Vec::new();
    for (i, p) in case.payloads.iter().enumerate() {
        let path = format!("payloads[{i}]");
        let body = carried_body(&mut v, &body_id, &p.body, &format!("{path}.body"));
        v.non_negative_at_most(p.mass, MAX_MASS, &format!("{path}.mass"), "kg");
        let com = parser.constant_vec(&p.com, &format!("{path}.com"), &mut v.errors);
        let com = v.length_vec(com, &format!("{path}.com"));
        let inertia = v.inertia(&p.inertia.unwrap_or([0.0; 6]), &format!("{path}.inertia"));
        if let (Some(body), Some(com), Some(inertia)) = (body, com, inertia) {
            payloads.push(Payload {
                name: p
                    .name
                    .clone()
                    .unwrap_or_else(|| format!("payload {}", i + 1)),
                body,
                mass: p.mass,
                com: Vector3::from(com),
                inertia_com: inertia,
                in_balance: p.in_balance,
            });
        }
    }

    // ---- joints: shape first, then consistency at sampled configurations
    let samples = sample_configurations(&coordinates, VALIDATION_SAMPLES, DEFAULT_SEED);
    // Bodies without a pose (already reported) stand at the origin; no joint touching one is
    // checked.
    let poses: Vec<PolyPose> = world
        .iter()
        .map(|p| p.clone().unwrap_or_else(PolyPose::identity))
        .collect();
    let length = characteristic_length(&case, &coordinates, &world, &parser, coordinates_ok);
    let tolerance = JOINT_TOLERANCE * (1.0 + length);
    let mut joint_names = HashMap::new();
    let mut joints: Vec<Option<Joint>> = Vec::new();
    for (i, j) in case.joints.iter().enumerate() {
        let path = format!("joints[{i}]");
        v.name(&j.name, &format!("{path}.name"));
        v.unique(&mut joint_names, &j.name, format!("{path}.name"), "joint");
        joints.push(
            joint(&mut v, &parser, &body_id, j, &path).and_then(|input| {
                let posed = input
                    .bodies
                    .iter()
                    .all(|b| b.index().is_none_or(|k| world[k].is_some()));
                if !(posed && coordinates_ok) {
                    return None;
                }
                match joints::derive_and_check(&input, &poses, &coordinates, &samples, tolerance) {
                    Ok(joint) => Some(joint),
                    Err(errors) => {
                        v.errors.extend(errors);
                        None
                    }
                }
            }),
        );
    }

    // ---- actuators
    let mut actuator_names = HashMap::new();
    let mut actuators = Vec::new();
    for (i, a) in case.actuators.iter().enumerate() {
        let path = format!("actuators[{i}]");
        v.name(&a.name, &format!("{path}.name"));
        v.unique(
            &mut actuator_names,
            &a.name,
            format!("{path}.name"),
            "actuator",
        );
        let joint_index = case.joints.iter().position(|j| j.name == a.joint);
        match joint_index {
            None => v.unknown(format!("{path}.joint"), "joint", &a.joint),
            Some(k)
                if !matches!(
                    case.joints[k].kind,
                    JointKindSpec::Revolute | JointKindSpec::Prismatic
                ) =>
            {
                v.invalid(
                    format!("{path}.joint"),
                    format!("actuated joint `{}` must be revolute or prismatic", a.joint),
                );
            }
            Some(_) => {}
        }
        let map = actuator_map(&context, &a.coordinate, &format!("{path}.coordinate"));
        let map = match map {
            Ok(m) => Some(m),
            Err(e) => {
                v.push(e);
                None
            }
        };
        v.positive_at_most(a.ratio, MAX_RATIO, &format!("{path}.ratio"), "");
        if let (Some(map), Some(k)) = (map, joint_index) {
            if let Some(Some(joint)) = joints.get(k)
                && let Some(problem) = joints::check_actuator_follows_joint(
                    &map,
                    joint,
                    &poses,
                    &coordinates,
                    &samples,
                    ACTUATOR_TOLERANCE,
                )
            {
                v.invalid(
                    format!("{path}.coordinate"),
                    format!(
                        "u = {} does not follow its joint: {problem}",
                        a.coordinate.source()
                    ),
                );
            }
            actuators.push(Actuator {
                name: a.name.clone(),
                joint: k,
                coordinate: map,
                source: a.coordinate.source(),
                ratio: a.ratio,
            });
        }
    }
    if case.actuators.len() != case.coordinates.len() {
        v.invalid(
            "actuators",
            format!(
                "{} actuators for {} coordinates: the actuator Jacobian must be square (one actuator per coordinate)",
                case.actuators.len(),
                case.coordinates.len()
            ),
        );
    }
    let actuator_index =
        |name: &str| -> Option<usize> { case.actuators.iter().position(|a| a.name == name) };

    let balancing = case
        .balancing
        .as_ref()
        .and_then(|b| balancing(&mut v, b, &case, &actuator_index));
    let tasks = case
        .tasks
        .as_ref()
        .and_then(|t| tasks(&mut v, t, &case, &actuator_index));
    let paths = task_paths(&mut v, &case, &parser, &body_id);

    if !v.errors.is_empty() {
        return Err(CaseErrors::new(v.errors));
    }
    let bodies = case
        .bodies
        .iter()
        .zip(world)
        .zip(inertial)
        .zip(parents)
        .map(|(((b, pose), (com, inertia)), parent)| {
            let pose = pose.expect("validated");
            Body {
                name: b.name.clone(),
                parent: parent.expect("validated"),
                mass: b.mass,
                com: com.expect("validated"),
                inertia_com: inertia.expect("validated"),
                rotation: pose.rotation,
                origin: pose.origin,
            }
        })
        .collect::<Vec<Body>>();
    let mut balancing = balancing;
    if let Some(b) = &mut balancing {
        // The entries the case left out: derived from the mechanism, not fixed numbers (a
        // 1000 kg counterweight on a 2 kg rod is the optimiser's answer to a bound nobody set).
        let derived = Bounds::derived(&MechanismScale::of(&bodies, Vector3::from(case.gravity)));
        for name in &b.derived_bounds {
            match *name {
                "mass" => b.bounds.mass = derived.mass,
                "radius" => b.bounds.radius = derived.radius,
                "stiffness" => b.bounds.stiffness = derived.stiffness,
                "anchor_a" => b.bounds.anchor_a = derived.anchor_a,
                "anchor_b" => b.bounds.anchor_b = derived.anchor_b,
                _ => {}
            }
        }
    }
    Ok(Model {
        name: case.name.clone(),
        description: case.description.clone(),
        gravity: Vector3::from(case.gravity),
        parameters: case.parameters.0.clone(),
        coordinates,
        bodies,
        payloads,
        joints: joints.into_iter().map(|j| j.expect("validated")).collect(),
        actuators,
        balancing,
        tasks,
        paths: paths.expect("validated"),
        case,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Directions by hand: a 3-4-5 triangle gives (0.6, 0.8, 0) at any scale whose squares stay
    /// finite; a norm that overflows (a component past √f64::MAX ≈ 1.34e154 squares to ∞) or
    /// falls below MIN_AXIS_NORM (1e-308 squares to 0) is refused with the reason.
    #[test]
    fn unit_direction_is_checked_by_the_norm() {
        for scale in [1.0, 1e-7, 3e150 / 3.0] {
            let unit = unit_direction(&Vector3::new(3.0 * scale, 4.0 * scale, 0.0)).unwrap();
            assert!(
                (unit - Vector3::new(0.6, 0.8, 0.0)).amax() < 1e-15,
                "{scale}: {unit}"
            );
        }
        let err = unit_direction(&Vector3::new(0.0, -1e308, 0.0)).unwrap_err();
        assert!(err.contains("overflows") && err.contains("1e308"), "{err}");
        let err = unit_direction(&Vector3::new(1.4e154, 0.0, 0.0)).unwrap_err();
        assert!(err.contains("overflows"), "{err}");
        for tiny in [1e-308, 5e-324, -2.5e-320, 1e-13] {
            let err = unit_direction(&Vector3::new(tiny, 0.0, 0.0)).unwrap_err();
            assert!(err.contains("too short"), "{tiny}: {err}");
        }
        for zero in [[0.0, 0.0, 0.0], [-0.0, 0.0, -0.0]] {
            let err = unit_direction(&Vector3::from(zero)).unwrap_err();
            assert_eq!(err, "axis must not be zero");
        }
    }

    /// [[2, 1, 0], [1, 2, 0], [0, 0, 5]] has eigenvalues 2 ± 1 and 5 (characteristic polynomial
    /// by hand); the same tensor scaled by 1e300 or by 1e-310 (subnormal entries) has them
    /// scaled; a NaN gives none (nalgebra's uncapped solver would not return).
    #[test]
    fn principal_moments_of_extreme_tensors() {
        let m = Matrix3::new(2.0, 1.0, 0.0, 1.0, 2.0, 0.0, 0.0, 0.0, 5.0);
        for scale in [1.0, 1e300, 1e-310] {
            let mut e: Vec<f64> = principal_moments(&(m * scale))
                .unwrap()
                .iter()
                .map(|x| x / scale)
                .collect();
            e.sort_by(f64::total_cmp);
            let tol = if scale < 1e-300 { 1e-9 } else { 1e-12 };
            for (got, want) in e.iter().zip([1.0, 3.0, 5.0]) {
                assert!((got - want).abs() < tol, "{scale}: {e:?}");
            }
        }
        let mut nan = m;
        nan[(0, 1)] = f64::NAN;
        assert_eq!(principal_moments(&nan), None);
    }
}
