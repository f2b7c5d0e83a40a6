//! Joint geometry and the joint-consistency check.
//!
//! A joint is written once, in the frame of its first body. Its description in the second
//! body's frame is *derived* at the reference configuration; then, at sampled configurations,
//! both descriptions must still agree (a revolute joint's point and axis coincide, a prismatic
//! joint only slides along its axis, …). A disagreement means the poses and the joints describe
//! different mechanisms — a modelling error that would silently corrupt joint reactions — so it
//! is reported with the joint, the size of the deviation and the configuration.

use counterpoise_symbolic::{Point, VarKind};
use nalgebra::{Matrix3, Vector3};

use crate::error::ModelError;
use crate::model::{ActuatorMap, BodyId, Coordinate, Joint, JointKind};
use crate::pose::PolyPose;
use crate::sampling::describe_configuration;

/// Numeric pose of a body (identity for the base).
pub(crate) fn eval_pose(
    poses: &[PolyPose],
    id: BodyId,
    at: &Point,
) -> (Matrix3<f64>, Vector3<f64>) {
    match id {
        BodyId::Base => (Matrix3::identity(), Vector3::zeros()),
        BodyId::Body(i) => (
            Matrix3::from(poses[i].rotation.eval(at)).transpose(),
            Vector3::from(poses[i].origin.eval(at)),
        ),
    }
}

/// `v` such that `[v]× = (m − mᵀ)/2`.
pub(crate) fn vee(m: &Matrix3<f64>) -> Vector3<f64> {
    Vector3::new(
        m[(2, 1)] - m[(1, 2)],
        m[(0, 2)] - m[(2, 0)],
        m[(1, 0)] - m[(0, 1)],
    ) * 0.5
}

/// Rotation angle of a (near-)rotation matrix, robust near 0 and π.
fn rotation_angle(m: &Matrix3<f64>) -> f64 {
    let s = vee(m).norm();
    let c = 0.5 * (m.trace() - 1.0);
    s.atan2(c)
}

/// Angle between two directions.
fn angle_between(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}

/// A value with four significant digits, in plain notation when that is readable.
fn significant(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        format!("{x}")
    } else if !(1e-3..1e4).contains(&x.abs()) {
        format!("{x:.3e}")
    } else {
        let digits = (3 - x.abs().log10().floor() as i32).clamp(0, 6) as usize;
        format!("{x:.digits$}")
    }
}

/// A joint as written: geometry in the first body's frame.
pub(crate) struct JointInput {
    pub name: String,
    pub path: String,
    pub kind: JointKind,
    pub bodies: [BodyId; 2],
    pub point: Vector3<f64>,
    /// Unit axis in the first body's frame.
    pub axis: Option<Vector3<f64>>,
    /// Unit second axis (universal) in the second body's frame.
    pub axis2: Option<Vector3<f64>>,
}

/// Worst violation of one kind of agreement over the samples.
struct Worst {
    what: &'static str,
    /// Whether the deviation is a length (m) rather than an angle (rad).
    is_length: bool,
    value: f64,
    sample: usize,
}

impl Worst {
    fn new(what: &'static str, is_length: bool) -> Self {
        Worst {
            what,
            is_length,
            value: 0.0,
            sample: 0,
        }
    }

    fn record(&mut self, value: f64, sample: usize) {
        if value > self.value || value.is_nan() {
            self.value = value;
            self.sample = sample;
        }
    }
}

/// Derives the second body's view of the joint at `samples[0]` (the reference configuration)
/// and checks agreement at every sample with tolerance `tol`.
pub(crate) fn derive_and_check(
    input: &JointInput,
    poses: &[PolyPose],
    coordinates: &[Coordinate],
    samples: &[Vec<f64>],
    tol: f64,
) -> Result<Joint, Vec<ModelError>> {
    let kinds: Vec<VarKind> = coordinates.iter().map(|c| c.kind).collect();
    let [b0, b1] = input.bodies;
    let reference = Point::new(&samples[0], &kinds);
    let (r0, o0) = eval_pose(poses, b0, &reference);
    let (r1, o1) = eval_pose(poses, b1, &reference);
    let world_point = o0 + r0 * input.point;
    let point1 = r1.transpose() * (world_point - o1);
    let axis1 = input.axis.map(|a| r1.transpose() * (r0 * a));
    let relative_rotation = r0.transpose() * r1;
    let relative_position = r0.transpose() * (o1 - o0);

    let mut points = Worst::new("points differ by", true);
    let mut axes = Worst::new("axes differ by", false);
    let mut rotation = Worst::new("relative rotation changes by", false);
    let mut position = Worst::new("relative position changes by", true);
    let mut slide = Worst::new("the second body's point leaves the axis by", true);
    let mut perpendicular = Worst::new("axis and axis2 are off perpendicular by", false);

    for (n, q) in samples.iter().enumerate() {
        let at = Point::new(q, &kinds);
        let (r0, o0) = eval_pose(poses, b0, &at);
        let (r1, o1) = eval_pose(poses, b1, &at);
        let p0w = o0 + r0 * input.point;
        let p1w = o1 + r1 * point1;
        let rot_dev = || rotation_angle(&(relative_rotation.transpose() * r0.transpose() * r1));
        match input.kind {
            JointKind::Revolute => {
                points.record((p0w - p1w).norm(), n);
                let (a0, a1) = (input.axis.unwrap(), axis1.unwrap());
                axes.record(angle_between(&(r0 * a0), &(r1 * a1)), n);
            }
            JointKind::Prismatic => {
                rotation.record(rot_dev(), n);
                let a = r0 * input.axis.unwrap();
                let d = p1w - p0w;
                slide.record((d - a * d.dot(&a)).norm(), n);
            }
            JointKind::Spherical => points.record((p0w - p1w).norm(), n),
            JointKind::Universal => {
                points.record((p0w - p1w).norm(), n);
                let a = r0 * input.axis.unwrap();
                let b = r1 * input.axis2.unwrap();
                perpendicular.record(
                    (std::f64::consts::FRAC_PI_2 - angle_between(&a, &b)).abs(),
                    n,
                );
            }
            JointKind::Fixed => {
                rotation.record(rot_dev(), n);
                position.record((r0.transpose() * (o1 - o0) - relative_position).norm(), n);
            }
            JointKind::Orientation => rotation.record(rot_dev(), n),
        }
    }

    let mut errors = Vec::new();
    for worst in [points, axes, rotation, position, slide, perpendicular] {
        if worst.value > tol || worst.value.is_nan() {
            let amount = if worst.is_length {
                format!("{} m", significant(worst.value))
            } else {
                format!(
                    "{} rad ({}°)",
                    significant(worst.value),
                    significant(worst.value.to_degrees())
                )
            };
            errors.push(ModelError::JointInconsistent {
                path: input.path.clone(),
                joint: input.name.clone(),
                deviation: format!("{} {amount}", worst.what),
                configuration: describe_configuration(coordinates, &samples[worst.sample]),
            });
        }
    }
    if !errors.is_empty() {
        return Err(errors);
    }
    Ok(Joint {
        name: input.name.clone(),
        kind: input.kind,
        bodies: input.bodies,
        points: [input.point, point1],
        axes: input.axis.zip(axis1).map(|(a, b)| [a, b.normalize()]),
        axis2: input.axis2,
    })
}

/// Checks that an actuated coordinate moves exactly like its joint: `∂u/∂q_k` must equal the
/// joint's relative rotation rate about its axis (revolute) or sliding rate along it
/// (prismatic) per unit `q̇_k`, so that the actuator's generalized force is the joint's axial
/// torque or force. Returns a description of the worst mismatch beyond `tol`.
pub(crate) fn check_actuator_follows_joint(
    map: &ActuatorMap,
    joint: &Joint,
    poses: &[PolyPose],
    coordinates: &[Coordinate],
    samples: &[Vec<f64>],
    tol: f64,
) -> Option<String> {
    let kinds: Vec<VarKind> = coordinates.iter().map(|c| c.kind).collect();
    let n = coordinates.len();
    let [b0, b1] = joint.bodies;
    let [a0, _] = joint.axes?;
    let derivative = |id: BodyId, k: usize| -> Option<PolyPose> {
        id.index().map(|i| PolyPose {
            rotation: poses[i].rotation.derivative(k, kinds[k]),
            origin: poses[i].origin.derivative(k, kinds[k]),
        })
    };
    let d0: Vec<Option<PolyPose>> = (0..n).map(|k| derivative(b0, k)).collect();
    let d1: Vec<Option<PolyPose>> = (0..n).map(|k| derivative(b1, k)).collect();
    let du: Vec<_> = (0..n).map(|k| map.derivative(k, kinds[k])).collect();
    let eval_d = |d: &Option<PolyPose>, at: &Point| match d {
        None => (Matrix3::zeros(), Vector3::zeros()),
        Some(p) => (
            Matrix3::from(p.rotation.eval(at)).transpose(),
            Vector3::from(p.origin.eval(at)),
        ),
    };
    let mut worst: Option<(f64, String)> = None;
    for q in samples {
        let at = Point::new(q, &kinds);
        let (r0, o0) = eval_pose(poses, b0, &at);
        let (r1, o1) = eval_pose(poses, b1, &at);
        for k in 0..n {
            let (dr0, do0) = eval_d(&d0[k], &at);
            let (dr1, do1) = eval_d(&d1[k], &at);
            let joint_rate = match joint.kind {
                JointKind::Revolute => {
                    let w0 = vee(&(dr0 * r0.transpose()));
                    let w1 = vee(&(dr1 * r1.transpose()));
                    (r0 * a0).dot(&(w1 - w0))
                }
                JointKind::Prismatic => {
                    // s = a0 · R0ᵀ (o1 + R1 p1 − o0 − R0 p0)
                    let d = o1 + r1 * joint.points[1] - o0 - r0 * joint.points[0];
                    let dd = do1 + dr1 * joint.points[1] - do0 - dr0 * joint.points[0];
                    a0.dot(&(dr0.transpose() * d + r0.transpose() * dd))
                }
                _ => return None,
            };
            let u_rate = du[k].eval(&at);
            let dev = (u_rate - joint_rate).abs();
            if dev > tol * (1.0 + u_rate.abs().max(joint_rate.abs()))
                && worst.as_ref().is_none_or(|(w, _)| dev > *w)
            {
                worst = Some((
                    dev,
                    format!(
                        "∂u/∂{} = {u_rate:.6} but joint `{}` moves {joint_rate:.6} per unit {} at {}",
                        coordinates[k].name,
                        joint.name,
                        coordinates[k].name,
                        describe_configuration(coordinates, q)
                    ),
                ));
            }
        }
    }
    worst.map(|(_, s)| s)
}
