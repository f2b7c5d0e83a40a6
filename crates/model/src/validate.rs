//! From a parsed [`Case`] to a validated [`Model`].
//!
//! The validator keeps going after a problem so that all of them are reported at once; a
//! check that depends on an earlier failed one (the consistency of a joint whose body has a
//! broken pose) is skipped rather than reported twice.

use std::collections::{BTreeMap, HashMap};

use counterpoise_symbolic::{ExprContext, MAX_VARS, Point, TrigPoly, VarKind};
use nalgebra::{Matrix3, SymmetricEigen, Vector3};

use crate::case::{
    BalancingSpec, Case, CoordinateKindSpec, Expr, JointKindSpec, LawSpec, PairsSpec, PlaneSpec,
    Selection, ShapeSpec, TasksSpec,
};
use crate::error::{CaseErrors, ModelError};
use crate::joints::{self, JointInput};
use crate::limits::{Limit, Limits, MAX_POSE_DEGREE};
use crate::model::{
    Actuator, ActuatorMap, Balancing, Body, BodyId, Bounds, Coordinate, CounterweightOptions,
    CounterweightShape, GridAxis, Joint, JointKind, MechanismScale, Model, MotionLaw, PairMode,
    PathPayload, Payload, Plane, SpringOptions, TaskPath, Tasks, Waypoint,
};
use crate::pose::{Parser, PolyPose};
use crate::reader::too_large;
use crate::sampling::{DEFAULT_SEED, VALIDATION_SAMPLES, sample_configurations};

/// Relative tolerance of the joint checks: deviations up to `JOINT_TOLERANCE · (1 + L)` pass,
/// `L` being the characteristic length of the mechanism.
pub const JOINT_TOLERANCE: f64 = 1e-9;

/// Relative tolerance of the check that an actuated coordinate moves like its joint.
pub const ACTUATOR_TOLERANCE: f64 = 1e-8;

/// Largest length a case may give (coordinate ranges, centres of mass, joint points, pose
/// translations, element bounds), m. Bounds like these keep the numerics (SVD, Newton, the
/// dynamics) well conditioned: a link of 1e308 m would otherwise spin in an SVD for minutes.
pub const MAX_LENGTH: f64 = 1e3;
/// Largest angle of a coordinate range, rad.
pub const MAX_ANGLE: f64 = 1e3;
/// Largest mass (bodies, payloads, counterweight bounds), kg.
pub const MAX_MASS: f64 = 1e6;
/// Largest inertia tensor entry, kg·m².
pub const MAX_INERTIA: f64 = 1e6;
/// Largest gravity component, m/s².
pub const MAX_GRAVITY: f64 = 1e3;
/// Largest parameter value (parameters are plain numbers; what they become is bounded where
/// they are used).
pub const MAX_PARAMETER: f64 = 1e9;
/// Largest actuator ratio, peak torque limit (N·m), spring stiffness bound (N/m) and
/// counterweight density (kg/m³).
pub const MAX_RATIO: f64 = 1e6;
pub const MAX_TORQUE: f64 = 1e9;
pub const MAX_STIFFNESS: f64 = 1e9;
pub const MAX_DENSITY: f64 = 1e6;
/// Move and segment durations, s: shorter moves make accelerations overflow, longer ones are
/// not tasks.
pub const DURATION_RANGE: [f64; 2] = [1e-3, 1e6];

/// Smallest norm of a vector used as a direction (a joint axis): shorter ones are refused.
pub const MIN_AXIS_NORM: f64 = 1e-12;

/// The unit vector along `v`, or why `v` gives no direction: it is zero, its norm is below
/// [`MIN_AXIS_NORM`] (it underflows, or is too short to be told from zero), or its norm
/// overflows (a component beyond about 1e154 squares to infinity; normalising by an infinite
/// norm would give the zero vector, and the NaN that follows hangs an SVD). The components
/// are known finite.
pub fn unit_direction(v: &Vector3<f64>) -> Result<Vector3<f64>, String> {
    let largest = v.amax();
    let norm = v.norm();
    if largest == 0.0 {
        return Err("axis must not be zero".into());
    }
    if !norm.is_finite() {
        return Err(format!(
            "the axis's length overflows (a component of magnitude {}): a direction needs components of moderate size, e.g. [0, 0, 1]",
            num(largest)
        ));
    }
    if norm < MIN_AXIS_NORM {
        return Err(format!(
            "the axis's length {} is below {}: too short to give a direction (an axis must not be zero); scale it up, e.g. [0, 0, 1]",
            num(norm.max(largest)),
            num(MIN_AXIS_NORM)
        ));
    }
    Ok(v / norm)
}

/// Most iterations of the symmetric eigensolver on a 3 × 3 inertia: it converges in a few for
/// any finite tensor (nalgebra scales it first, so huge and subnormal entries are alike), and
/// nalgebra's default is no cap at all.
pub const EIGEN_MAX_ITERATIONS: usize = 1000;

/// The principal moments of a symmetric 3 × 3 tensor, or `None` when the capped eigensolver
/// does not converge (never seen for finite entries; the cap is there so that it cannot hang).
pub fn principal_moments(m: &Matrix3<f64>) -> Option<Vector3<f64>> {
    if !m.iter().all(|x| x.is_finite()) {
        return None;
    }
    SymmetricEigen::try_new(*m, f64::EPSILON, EIGEN_MAX_ITERATIONS).map(|e| e.eigenvalues)
}

/// A number for a message: plain when moderate, in exponent form when huge or tiny (`1e308`
/// is not printed as 309 digits).
fn num(x: f64) -> String {
    if x != 0.0 && x.is_finite() && !(1e-4..1e9).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// Names the expression language reserves.
const RESERVED: [&str; 3] = ["pi", "cos", "sin"];

fn is_identifier(name: &str) -> bool {
    let mut chars = name.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

struct Validator {
    errors: Vec<ModelError>,
    limits: Limits,
}

impl Validator {
    /// Checks `|value| ≤ max` (the value is already known finite or reported).
    fn magnitude(&mut self, value: f64, max: f64, path: &str, unit: &str) -> bool {
        let unit = if unit.is_empty() {
            String::new()
        } else {
            format!(" {unit}")
        };
        if value.abs() > max {
            self.invalid(
                path,
                format!(
                    "{}{unit} is beyond the supported magnitude ±{}{unit}",
                    num(value),
                    num(max)
                ),
            );
            return false;
        }
        true
    }

    /// Every entry finite and within `±max`.
    fn bounded(&mut self, values: &[f64], max: f64, path: &str, unit: &str) -> bool {
        let mut ok = true;
        for (k, &v) in values.iter().enumerate() {
            let item = format!("{path}[{k}]");
            if !v.is_finite() {
                self.invalid(item, format!("{v} is not a finite number"));
                ok = false;
            } else {
                ok &= self.magnitude(v, max, &item, unit);
            }
        }
        ok
    }

    /// A duration within [`DURATION_RANGE`].
    fn duration(&mut self, value: f64, path: &str) -> bool {
        let [lo, hi] = DURATION_RANGE;
        if !(value.is_finite() && (lo..=hi).contains(&value)) {
            self.invalid(
                path,
                format!(
                    "must be a duration between {lo} and {hi} s (found {})",
                    num(value)
                ),
            );
            return false;
        }
        true
    }

    /// A list no longer than the list limit.
    fn list_size(&mut self, len: usize, path: &str) -> bool {
        if len as u64 > self.limits.list_items {
            self.push(too_large(
                path,
                "entries",
                len as f64,
                Limit::ListItems,
                self.limits.list_items,
            ));
            return false;
        }
        true
    }

    fn push(&mut self, error: ModelError) {
        self.errors.push(error);
    }

    fn invalid(&mut self, path: impl Into<String>, reason: impl Into<String>) {
        self.errors.push(ModelError::invalid(path, reason));
    }

    fn unknown(&mut self, path: impl Into<String>, what: &'static str, name: &str) {
        self.errors.push(ModelError::UnknownName {
            path: path.into(),
            what,
            name: name.to_string(),
        });
    }

    /// Records a name in `seen`, reporting a duplicate; returns whether it was new.
    fn unique(
        &mut self,
        seen: &mut HashMap<String, String>,
        name: &str,
        path: String,
        what: &'static str,
    ) -> bool {
        if let Some(first) = seen.get(name) {
            self.push(ModelError::Duplicate {
                path,
                what,
                name: name.to_string(),
                first: first.clone(),
            });
            false
        } else {
            seen.insert(name.to_string(), path);
            true
        }
    }

    fn name(&mut self, name: &str, path: &str) {
        if name.trim().is_empty() {
            self.invalid(path, "must not be empty");
        }
    }

    fn finite(&mut self, values: &[f64], path: &str) -> bool {
        let mut ok = true;
        for (k, v) in values.iter().enumerate() {
            if !v.is_finite() {
                self.invalid(
                    format!("{path}[{k}]"),
                    format!("{v} is not a finite number"),
                );
                ok = false;
            }
        }
        ok
    }

    fn positive(&mut self, value: f64, path: &str) -> bool {
        if !(value.is_finite() && value > 0.0) {
            self.invalid(
                path,
                format!("must be a finite number > 0 (found {})", num(value)),
            );
            return false;
        }
        true
    }

    /// `0 < value ≤ max`.
    fn positive_at_most(&mut self, value: f64, max: f64, path: &str, unit: &str) -> bool {
        self.positive(value, path) && self.magnitude(value, max, path, unit)
    }

    fn non_negative(&mut self, value: f64, path: &str) -> bool {
        if !(value.is_finite() && value >= 0.0) {
            self.invalid(
                path,
                format!("must be a finite number ≥ 0 (found {})", num(value)),
            );
            return false;
        }
        true
    }

    /// `0 ≤ value ≤ max`.
    fn non_negative_at_most(&mut self, value: f64, max: f64, path: &str, unit: &str) -> bool {
        self.non_negative(value, path) && self.magnitude(value, max, path, unit)
    }

    /// A constant vector of lengths within [`MAX_LENGTH`].
    fn length_vec(&mut self, value: Option<[f64; 3]>, path: &str) -> Option<[f64; 3]> {
        let value = value?;
        self.bounded(&value, MAX_LENGTH, path, "m").then_some(value)
    }

    /// The inertia tensor from `[Ixx, Iyy, Izz, Ixy, Ixz, Iyz]`, checked positive semi-definite.
    fn inertia(&mut self, v: &[f64; 6], path: &str) -> Option<Matrix3<f64>> {
        if !self.bounded(v, MAX_INERTIA, path, "kg·m²") {
            return None;
        }
        let [ixx, iyy, izz, ixy, ixz, iyz] = *v;
        let m = Matrix3::new(ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz);
        let Some(eigenvalues) = principal_moments(&m) else {
            self.invalid(
                path,
                format!(
                    "the principal moments of this inertia could not be computed in {EIGEN_MAX_ITERATIONS} iterations"
                ),
            );
            return None;
        };
        let trace = m.trace();
        if eigenvalues.iter().any(|&e| e < -1e-9 * trace.abs()) {
            let mut e: Vec<f64> = eigenvalues.iter().copied().collect();
            e.sort_by(f64::total_cmp);
            self.invalid(
                path,
                format!(
                    "inertia is not positive semi-definite (principal moments {:.6}, {:.6}, {:.6} kg·m²)",
                    e[0], e[1], e[2]
                ),
            );
            return None;
        }
        Some(m)
    }

    /// A unit axis from a constant 3-vector, checked by its norm (its components are only
    /// known finite): a zero vector, a norm below [`MIN_AXIS_NORM`] (it underflows, or is too
    /// short to give a direction) or one that overflows is an error naming the field.
    fn axis(&mut self, parser: &Parser, exprs: &[Expr; 3], path: &str) -> Option<Vector3<f64>> {
        let v = Vector3::from(parser.constant_vec(exprs, path, &mut self.errors)?);
        match unit_direction(&v) {
            Ok(unit) => Some(unit),
            Err(reason) => {
                self.invalid(path, reason);
                None
            }
        }
    }

    fn interval(&mut self, v: [f64; 2], max: f64, unit: &str, path: &str) -> Option<[f64; 2]> {
        if !self.bounded(&v, max, path, unit) {
            return None;
        }
        if v[0] < 0.0 || v[0] > v[1] {
            self.invalid(
                path,
                format!(
                    "must be [lo, hi] with 0 ≤ lo ≤ hi (found [{}, {}])",
                    v[0], v[1]
                ),
            );
            return None;
        }
        Some(v)
    }
}

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

/// Reports every cycle of the parent relation once (at its first body in file order) and
/// returns which bodies lie on or hang from a cycle (they have no world pose).
fn find_cycles(v: &mut Validator, case: &Case, parents: &[Option<BodyId>]) -> Vec<bool> {
    #[derive(Clone, Copy, PartialEq)]
    enum State {
        New,
        Active,
        Done(bool),
    }
    let n = parents.len();
    let mut state = vec![State::New; n];
    for start in 0..n {
        let mut chain = Vec::new();
        let mut current = start;
        let broken = loop {
            match state[current] {
                State::Done(b) => break b,
                State::Active => {
                    let at = chain.iter().position(|&c| c == current).unwrap_or(0);
                    let cycle = &chain[at..];
                    let first = *cycle.iter().min().unwrap_or(&current);
                    let mut names: Vec<&str> = cycle
                        .iter()
                        .map(|&c| case.bodies[c].name.as_str())
                        .collect();
                    names.push(&case.bodies[current].name);
                    v.push(ModelError::Cycle {
                        path: format!("bodies[{first}].parent"),
                        cycle: names.join(" → "),
                    });
                    break true;
                }
                State::New => {
                    state[current] = State::Active;
                    chain.push(current);
                    match parents[current] {
                        Some(BodyId::Body(p)) => current = p,
                        Some(BodyId::Base) | None => break false,
                    }
                }
            }
        };
        for c in chain {
            state[c] = State::Done(broken);
        }
    }
    state.into_iter().map(|s| s == State::Done(true)).collect()
}

/// World poses `parent world · relative`, or `None` where a pose step, a parent, or a cycle
/// prevents it. Iterative (a chain of thousands of bodies must not deepen the call stack), and
/// a composition whose degree would pass [`MAX_POSE_DEGREE`] is refused at the body's pose.
fn world_poses(
    v: &mut Validator,
    parents: &[Option<BodyId>],
    relative: &[Option<PolyPose>],
    on_cycle: &[bool],
) -> Vec<Option<PolyPose>> {
    let n = parents.len();
    let mut memo: Vec<Option<Option<PolyPose>>> = vec![None; n];
    for start in 0..n {
        // Walk up to a resolved body or the base, then resolve the chain back down.
        let mut chain = Vec::new();
        let mut current = start;
        while memo[current].is_none() {
            chain.push(current);
            match parents[current] {
                Some(BodyId::Body(p)) if !on_cycle[current] => current = p,
                _ => break,
            }
        }
        for &i in chain.iter().rev() {
            let pose = if on_cycle[i] {
                None
            } else {
                let parent = match parents[i] {
                    None => None,
                    Some(BodyId::Base) => Some(PolyPose::identity()),
                    Some(BodyId::Body(p)) => memo[p].clone().flatten(),
                };
                parent.zip(relative[i].as_ref()).and_then(|(parent, rel)| {
                    let degree = parent.degree() + rel.degree();
                    if degree > MAX_POSE_DEGREE {
                        v.invalid(
                            format!("bodies[{i}].pose"),
                            format!(
                                "the world pose reaches degree {degree} in one coordinate; at most {MAX_POSE_DEGREE} is supported"
                            ),
                        );
                        return None;
                    }
                    let mut pose = parent.compose(rel);
                    pose.prune();
                    Some(pose)
                })
            };
            memo[i] = Some(pose);
        }
    }
    memo.into_iter().map(Option::flatten).collect()
}

/// Checks a body's relative pose: translations within [`MAX_LENGTH`] and degree within
/// [`MAX_POSE_DEGREE`].
fn pose_in_bounds(v: &mut Validator, pose: &PolyPose, path: &str) -> bool {
    let degree = pose.degree();
    if degree > MAX_POSE_DEGREE {
        v.invalid(
            path,
            format!("the pose reaches degree {degree} in one coordinate; at most {MAX_POSE_DEGREE} is supported"),
        );
        return false;
    }
    let largest = pose
        .origin
        .0
        .iter()
        .map(TrigPoly::max_abs_coefficient)
        .fold(0.0, f64::max);
    if !largest.is_finite() || largest > MAX_LENGTH {
        v.invalid(
            path,
            format!(
                "its translations reach {} m, beyond the supported magnitude ±{} m",
                num(largest),
                num(MAX_LENGTH)
            ),
        );
        return false;
    }
    true
}

/// The length scale of joint tolerances: the largest distance of a body origin from the base
/// origin at the reference configuration, or of a joint point from its first body's origin.
fn characteristic_length(
    case: &Case,
    coordinates: &[Coordinate],
    world: &[Option<PolyPose>],
    parser: &Parser,
    coordinates_ok: bool,
) -> f64 {
    let mut length: f64 = 0.0;
    if coordinates_ok {
        let q: Vec<f64> = coordinates.iter().map(Coordinate::midpoint).collect();
        let kinds: Vec<VarKind> = coordinates.iter().map(|c| c.kind).collect();
        let at = Point::new(&q, &kinds);
        for pose in world.iter().flatten() {
            length = length.max(Vector3::from(pose.origin.eval(&at)).norm());
        }
    }
    for j in &case.joints {
        if let Some(point) = &j.point {
            let mut ignored = Vec::new();
            if let Some(p) = parser.constant_vec(point, "", &mut ignored) {
                length = length.max(Vector3::from(p).norm());
            }
        }
    }
    if length.is_finite() { length } else { 0.0 }
}

/// Resolves a body that carries something (a payload): the base cannot.
fn carried_body(
    v: &mut Validator,
    body_id: &dyn Fn(&str) -> Option<BodyId>,
    name: &str,
    path: &str,
) -> Option<usize> {
    match body_id(name) {
        None => {
            v.unknown(path, "body", name);
            None
        }
        Some(BodyId::Base) => {
            v.invalid(
                path,
                "a payload must be carried by a moving body, not the base",
            );
            None
        }
        Some(BodyId::Body(i)) => Some(i),
    }
}

/// Checks a joint's fields and returns its geometry in the first body's frame.
fn joint(
    v: &mut Validator,
    parser: &Parser,
    body_id: &dyn Fn(&str) -> Option<BodyId>,
    j: &crate::case::JointSpec,
    path: &str,
) -> Option<JointInput> {
    let kind = match j.kind {
        JointKindSpec::Revolute => JointKind::Revolute,
        JointKindSpec::Prismatic => JointKind::Prismatic,
        JointKindSpec::Spherical => JointKind::Spherical,
        JointKindSpec::Universal => JointKind::Universal,
        JointKindSpec::Fixed => JointKind::Fixed,
        JointKindSpec::Orientation => JointKind::Orientation,
    };
    let mut ok = true;
    let mut bodies = [BodyId::Base; 2];
    for (k, name) in j.bodies.iter().enumerate() {
        match body_id(name) {
            Some(id) => bodies[k] = id,
            None => {
                v.unknown(format!("{path}.bodies[{k}]"), "body", name);
                ok = false;
            }
        }
    }
    if ok && bodies[0] == bodies[1] {
        v.invalid(
            format!("{path}.bodies"),
            "a joint must connect two different bodies",
        );
        ok = false;
    }
    let point = match &j.point {
        Some(e) => {
            let point_path = format!("{path}.point");
            let point = parser.constant_vec(e, &point_path, &mut v.errors);
            v.length_vec(point, &point_path)
        }
        None if kind == JointKind::Orientation => Some([0.0; 3]),
        None => {
            v.invalid(
                format!("{path}.point"),
                format!("required for a {} joint", kind.name()),
            );
            None
        }
    };
    let axis = match (&j.axis, kind.has_axis()) {
        (Some(e), true) => v.axis(parser, e, &format!("{path}.axis")),
        (None, true) => {
            v.invalid(
                format!("{path}.axis"),
                format!("required for a {} joint", kind.name()),
            );
            None
        }
        (Some(_), false) => {
            v.invalid(
                format!("{path}.axis"),
                format!("a {} joint has no axis", kind.name()),
            );
            None
        }
        (None, false) => None,
    };
    let axis2 = match (&j.axis2, kind == JointKind::Universal) {
        (Some(e), true) => v.axis(parser, e, &format!("{path}.axis2")),
        (None, true) => {
            v.invalid(format!("{path}.axis2"), "required for a universal joint");
            None
        }
        (Some(_), false) => {
            v.invalid(format!("{path}.axis2"), "only a universal joint has axis2");
            None
        }
        (None, false) => None,
    };
    let axis_ok = !kind.has_axis() || axis.is_some();
    let axis2_ok = kind != JointKind::Universal || axis2.is_some();
    (ok && axis_ok && axis2_ok).then_some(())?;
    Some(JointInput {
        name: j.name.clone(),
        path: path.to_string(),
        kind,
        bodies,
        point: Vector3::from(point?),
        axis,
        axis2,
    })
}

/// An actuated coordinate: a trigonometric polynomial, or else an angle expression (an integer
/// combination of angle coordinates plus a constant, e.g. `th1`).
fn actuator_map(context: &ExprContext, expr: &Expr, path: &str) -> Result<ActuatorMap, ModelError> {
    let src = match expr {
        Expr::Number(_) => {
            return Err(ModelError::invalid(
                path,
                "an actuated coordinate must depend on the coordinates",
            ));
        }
        Expr::Text(s) => s,
    };
    let map = match context.parse_poly(src) {
        Ok(poly) => ActuatorMap {
            linear: Vec::new(),
            poly,
        },
        Err(poly_error) => match context.parse_angle(src) {
            Ok(angle) => ActuatorMap {
                linear: angle
                    .terms
                    .iter()
                    .map(|&(k, n)| (k, f64::from(n)))
                    .collect(),
                poly: TrigPoly::constant(angle.offset),
            },
            Err(_) => {
                return Err(ModelError::Expression {
                    path: path.to_string(),
                    source: poly_error,
                });
            }
        },
    };
    if map.poly.terms().any(|(_, c)| !c.is_finite()) {
        return Err(ModelError::invalid(path, "expression is not finite"));
    }
    if map.linear.is_empty() && map.poly.is_constant() {
        return Err(ModelError::invalid(
            path,
            "an actuated coordinate must depend on the coordinates",
        ));
    }
    Ok(map)
}

/// Resolves a body selection to ascending body indices.
fn selection(
    v: &mut Validator,
    case: &Case,
    selection: &Selection,
    path: &str,
    base_hint: &str,
) -> Option<Vec<usize>> {
    match selection {
        Selection::All => Some((0..case.bodies.len()).collect()),
        Selection::Names(names) => {
            let mut out = Vec::new();
            let mut ok = true;
            let mut seen = HashMap::new();
            for (k, name) in names.iter().enumerate() {
                let item = format!("{path}[{k}]");
                if name == "base" {
                    v.invalid(&item, base_hint);
                    ok = false;
                } else if let Some(i) = case.bodies.iter().position(|b| b.name == *name) {
                    if v.unique(&mut seen, name, item, "body") {
                        out.push(i);
                    }
                } else {
                    v.unknown(item, "body", name);
                    ok = false;
                }
            }
            out.sort_unstable();
            ok.then_some(out)
        }
    }
}

fn plane(p: Option<PlaneSpec>) -> Option<Plane> {
    p.map(|p| match p {
        PlaneSpec::Xy => Plane::Xy,
        PlaneSpec::Yz => Plane::Yz,
        PlaneSpec::Xz => Plane::Xz,
    })
}

fn balancing(
    v: &mut Validator,
    b: &BalancingSpec,
    case: &Case,
    actuator_index: &dyn Fn(&str) -> Option<usize>,
) -> Option<Balancing> {
    let start = v.errors.len();
    if b.dmax < 1 {
        v.invalid("balancing.dmax", "must be an integer ≥ 1");
    } else if u64::from(b.dmax) > v.limits.dmax {
        v.push(too_large(
            "balancing.dmax",
            "elements per variant",
            f64::from(b.dmax),
            Limit::Dmax,
            v.limits.dmax,
        ));
    }
    let counterweights = b.counterweights.as_ref().and_then(|c| {
        let bodies = selection(
            v,
            case,
            &c.bodies,
            "balancing.counterweights.bodies",
            "the base cannot carry a counterweight",
        );
        let shape = c.shape.as_ref().map(|ShapeSpec::Cylinder(cyl)| {
            v.positive_at_most(
                cyl.radius_to_thickness,
                1e3,
                "balancing.counterweights.shape.cylinder.radius_to_thickness",
                "",
            );
            v.positive_at_most(
                cyl.density,
                MAX_DENSITY,
                "balancing.counterweights.shape.cylinder.density",
                "kg/m³",
            );
            CounterweightShape::Cylinder {
                radius_to_thickness: cyl.radius_to_thickness,
                density: cyl.density,
            }
        });
        Some(CounterweightOptions {
            bodies: bodies?,
            plane: plane(c.plane),
            shape,
        })
    });
    let springs = b.springs.as_ref().and_then(|s| {
        let bodies = selection(
            v,
            case,
            &s.bodies,
            "balancing.springs.bodies",
            "list moving bodies only; set include_base for springs to the base",
        );
        Some(SpringOptions {
            bodies: bodies?,
            include_base: s.include_base,
            plane: plane(s.plane),
        })
    });
    let defaults = Bounds::default();
    let spec = b.bounds.clone().unwrap_or_default();
    let mut bound = |value: Option<[f64; 2]>, default: [f64; 2], name: &str, max, unit| match value
    {
        Some(x) => v
            .interval(x, max, unit, &format!("balancing.bounds.{name}"))
            .unwrap_or(default),
        None => default,
    };
    let bounds = Bounds {
        mass: bound(spec.mass, defaults.mass, "mass", MAX_MASS, "kg"),
        radius: bound(spec.radius, defaults.radius, "radius", MAX_LENGTH, "m"),
        stiffness: bound(
            spec.stiffness,
            defaults.stiffness,
            "stiffness",
            MAX_STIFFNESS,
            "N/m",
        ),
        anchor_a: bound(
            spec.anchor_a,
            defaults.anchor_a,
            "anchor_a",
            MAX_LENGTH,
            "m",
        ),
        anchor_b: bound(
            spec.anchor_b,
            defaults.anchor_b,
            "anchor_b",
            MAX_LENGTH,
            "m",
        ),
    };
    let mut peak_limits = vec![None; case.actuators.len()];
    for (name, &limit) in b.peak_limits.iter() {
        let path = format!("balancing.peak_limits.{name}");
        match actuator_index(name) {
            None => v.unknown(&path, "actuator", name),
            Some(k) => {
                if v.positive_at_most(limit, MAX_TORQUE, &path, "N·m") {
                    peak_limits[k] = Some(limit);
                }
            }
        }
    }
    (v.errors.len() == start).then(|| Balancing {
        dmax: b.dmax as usize,
        counterweights,
        springs,
        bounds,
        derived_bounds: [
            ("mass", spec.mass),
            ("radius", spec.radius),
            ("stiffness", spec.stiffness),
            ("anchor_a", spec.anchor_a),
            ("anchor_b", spec.anchor_b),
        ]
        .iter()
        .filter(|(_, given)| given.is_none())
        .map(|(name, _)| *name)
        .collect(),
        peak_limits,
        overrides: b.overrides.clone(),
    })
}

fn tasks(
    v: &mut Validator,
    t: &TasksSpec,
    case: &Case,
    actuator_index: &dyn Fn(&str) -> Option<usize>,
) -> Option<Tasks> {
    let start = v.errors.len();
    let mut grid: Vec<Option<GridAxis>> = vec![None; case.actuators.len()];
    for (name, &[from, to, n]) in t.grid.iter() {
        let path = format!("tasks.grid.{name}");
        let Some(k) = actuator_index(name) else {
            v.unknown(&path, "actuator", name);
            continue;
        };
        if !v.bounded(&[from, to], MAX_LENGTH.max(MAX_ANGLE), &path, "") || !v.finite(&[n], &path) {
            continue;
        }
        if n < 1.0 || n.fract() != 0.0 {
            v.invalid(
                format!("{path}[2]"),
                format!("the number of values must be an integer ≥ 1 (found {n})"),
            );
            continue;
        }
        if n > v.limits.grid_points as f64 {
            v.push(too_large(
                &format!("{path}[2]"),
                "values on one axis",
                n,
                Limit::GridPoints,
                v.limits.grid_points,
            ));
            continue;
        }
        grid[k] = Some(GridAxis {
            from,
            to,
            n: n as usize,
        });
    }
    let missing: Vec<&str> = case
        .actuators
        .iter()
        .zip(&grid)
        .filter(|(_, g)| g.is_none())
        .map(|(a, _)| a.name.as_str())
        .collect();
    if !missing.is_empty() && v.errors.len() == start {
        v.invalid(
            "tasks.grid",
            format!(
                "every actuator needs a grid axis; missing: {}",
                missing.join(", ")
            ),
        );
    }
    if v.errors.len() == start {
        grid_size(v, &grid, t);
    }
    v.duration(t.duration, "tasks.duration");
    if t.samples < 2 {
        v.invalid(
            "tasks.samples",
            format!("must be ≥ 2 (found {})", t.samples),
        );
    } else if u64::from(t.samples) > v.limits.samples {
        v.push(too_large(
            "tasks.samples",
            "samples per task",
            f64::from(t.samples),
            Limit::Samples,
            v.limits.samples,
        ));
    }
    (v.errors.len() == start).then(|| Tasks {
        grid: grid.into_iter().map(|g| g.expect("checked")).collect(),
        pairs: match t.pairs {
            PairsSpec::All => PairMode::All,
            PairsSpec::Ordered => PairMode::Ordered,
        },
        law: match t.law {
            LawSpec::Quintic => MotionLaw::Quintic,
        },
        duration: t.duration,
        samples: t.samples as usize,
    })
}

/// The number of tasks of a grid of `points` points (computed in floating point: it must not
/// overflow before it is compared with a limit).
pub fn task_count(points: f64, pairs: PairMode) -> f64 {
    match pairs {
        PairMode::All => points * (points - 1.0) / 2.0,
        PairMode::Ordered => points * (points - 1.0),
    }
}

/// Checks the grid's point count, task count and evaluations against the limits, from the axis
/// sizes alone (the grid is not built), and refuses a grid of one point: a task moves between
/// two points.
fn grid_size(v: &mut Validator, grid: &[Option<GridAxis>], t: &TasksSpec) {
    let sizes: Vec<f64> = grid.iter().flatten().map(|g| g.n as f64).collect();
    let points: f64 = sizes.iter().product();
    if points > v.limits.grid_points as f64 {
        v.push(too_large(
            "tasks.grid",
            "grid points",
            points,
            Limit::GridPoints,
            v.limits.grid_points,
        ));
        return;
    }
    if points < 2.0 {
        v.invalid(
            "tasks.grid",
            "the grid has a single point (every axis has n = 1), so there is no move between two points: give some actuator n ≥ 2",
        );
        return;
    }
    let pairs = match t.pairs {
        PairsSpec::All => PairMode::All,
        PairsSpec::Ordered => PairMode::Ordered,
    };
    let evaluations = task_count(points, pairs) * f64::from(t.samples.max(2));
    if evaluations > v.limits.task_samples as f64 {
        v.push(too_large(
            "tasks",
            &format!(
                "evaluations ({} tasks × {} samples)",
                crate::limits::format_count(task_count(points, pairs)),
                t.samples
            ),
            evaluations,
            Limit::TaskSamples,
            v.limits.task_samples,
        ));
    }
}

fn task_paths(
    v: &mut Validator,
    case: &Case,
    parser: &Parser,
    body_id: &dyn Fn(&str) -> Option<BodyId>,
) -> Option<Vec<TaskPath>> {
    let start = v.errors.len();
    let mut names = HashMap::new();
    let mut out = Vec::new();
    for (i, p) in case.paths.iter().enumerate() {
        let path = format!("paths[{i}]");
        v.name(&p.name, &format!("{path}.name"));
        v.unique(&mut names, &p.name, format!("{path}.name"), "path");
        let mut waypoints = Vec::new();
        let sizes_ok = v.list_size(p.waypoints.len(), &format!("{path}.waypoints"))
            & v.list_size(p.sequence.len(), &format!("{path}.sequence"))
            & v.list_size(p.durations.len(), &format!("{path}.durations"));
        if !sizes_ok {
            continue;
        }
        for (name, u) in p.waypoints.iter() {
            let wp = format!("{path}.waypoints.{name}");
            if u.len() != case.actuators.len() {
                v.invalid(
                    &wp,
                    format!(
                        "needs one value per actuator ({}), found {}",
                        case.actuators.len(),
                        u.len()
                    ),
                );
            }
            v.bounded(u, MAX_LENGTH.max(MAX_ANGLE), &wp, "");
            waypoints.push(Waypoint {
                name: name.to_string(),
                u: u.clone(),
            });
        }
        let mut sequence = Vec::new();
        for (k, name) in p.sequence.iter().enumerate() {
            match waypoints.iter().position(|w| w.name == *name) {
                Some(w) => sequence.push(w),
                None => v.unknown(format!("{path}.sequence[{k}]"), "waypoint", name),
            }
        }
        if p.sequence.len() < 2 {
            v.invalid(format!("{path}.sequence"), "needs at least two waypoints");
        }
        if p.durations.len() + 1 != p.sequence.len() {
            v.invalid(
                format!("{path}.durations"),
                format!(
                    "needs one duration per segment ({}), found {}",
                    p.sequence.len().saturating_sub(1),
                    p.durations.len()
                ),
            );
        }
        for (k, &d) in p.durations.iter().enumerate() {
            v.duration(d, &format!("{path}.durations[{k}]"));
        }
        let payload = p.payload.as_ref().and_then(|pl| {
            let pp = format!("{path}.payload");
            let body = carried_body(v, body_id, &pl.body, &format!("{pp}.body"));
            v.positive_at_most(pl.mass, MAX_MASS, &format!("{pp}.mass"), "kg");
            let com = parser.constant_vec(&pl.com, &format!("{pp}.com"), &mut v.errors);
            let com = v.length_vec(com, &format!("{pp}.com"));
            let inertia = v.inertia(&pl.inertia.unwrap_or([0.0; 6]), &format!("{pp}.inertia"));
            let pick = p.sequence.iter().position(|s| *s == pl.pick_at);
            if pick.is_none() {
                v.unknown(
                    format!("{pp}.pick_at"),
                    "waypoint of the sequence",
                    &pl.pick_at,
                );
            }
            let drop = pick.and_then(|k| {
                let found = p.sequence[k + 1..]
                    .iter()
                    .position(|s| *s == pl.drop_at)
                    .map(|d| d + k + 1);
                if found.is_none() {
                    v.invalid(
                        format!("{pp}.drop_at"),
                        format!(
                            "`{}` must occur in the sequence after pick_at `{}`",
                            pl.drop_at, pl.pick_at
                        ),
                    );
                }
                found
            });
            Some(PathPayload {
                body: body?,
                mass: pl.mass,
                com: Vector3::from(com?),
                inertia_com: inertia?,
                pick_at: pick?,
                drop_at: drop?,
            })
        });
        out.push(TaskPath {
            name: p.name.clone(),
            waypoints,
            sequence,
            durations: p.durations.clone(),
            payload,
        });
    }
    (v.errors.len() == start).then_some(out)
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
