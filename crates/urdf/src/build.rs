//! From a checked URDF tree to the case document.

use std::collections::{BTreeMap, HashMap};

use nalgebra::{Matrix3, Vector3};
use serde::Serialize;
use serde_json::{Value, json};

use crate::error::UrdfError;
use crate::parse::{Inertial, JointType, Robot};
use crate::steps::{self, AngleExpr, ConstAngle, LengthExpr, Placement};
use crate::tree::Tree;

/// What to import.
#[derive(Clone, Debug, Default)]
pub struct ImportOptions {
    /// The link fixed to the ground (default: the URDF's root link). Links outside its subtree
    /// are left out.
    pub base: Option<String>,
    /// The last link of the chain: joints off the base–tip path are frozen at 0 (clamped into
    /// their limits) and the links beyond them merged into the body they hang on.
    pub tip: Option<String>,
}

/// Most grid points of the default task grid: 3 per joint while the product stays within it
/// (81 points are 3,240 moves: `check` of a 7-joint arm stays well under a second).
pub const GRID_POINTS: usize = 81;

#[derive(Serialize)]
pub struct CaseDoc {
    name: String,
    description: String,
    gravity: [f64; 3],
    coordinates: Vec<CoordinateDoc>,
    bodies: Vec<BodyDoc>,
    joints: Vec<JointDoc>,
    actuators: Vec<ActuatorDoc>,
    balancing: Value,
    #[serde(skip_serializing_if = "Option::is_none")]
    tasks: Option<Value>,
}

#[derive(Serialize)]
struct CoordinateDoc {
    name: String,
    kind: &'static str,
    range: [f64; 2],
}

#[derive(Serialize)]
struct BodyDoc {
    name: String,
    parent: String,
    pose: Vec<Value>,
    mass: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    com: Option<[f64; 3]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    inertia: Option<[f64; 6]>,
}

#[derive(Serialize)]
struct JointDoc {
    name: String,
    kind: &'static str,
    bodies: [String; 2],
    point: [f64; 3],
    axis: [f64; 3],
}

#[derive(Serialize)]
struct ActuatorDoc {
    name: String,
    joint: String,
    coordinate: String,
    ratio: f64,
}

/// Mass properties gathered into one body frame: `(mass, com, inertia about the com)` per part.
#[derive(Default)]
struct Lump {
    parts: Vec<(f64, Vector3<f64>, Matrix3<f64>)>,
}

impl Lump {
    /// Adds a link's `<inertial>`, the link frame being at `placement` in the body frame:
    /// the inertia is rotated into body axes, `I_body = R I Rᵀ`.
    fn add(&mut self, inertial: &Inertial, placement: &Placement) {
        let frame = placement.then(&steps::origin(&inertial.origin));
        let [ixx, iyy, izz, ixy, ixz, iyz] = inertial.inertia;
        let i = Matrix3::new(ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz);
        let r = frame.rotation;
        self.parts
            .push((inertial.mass, frame.translation, r * i * r.transpose()));
    }

    /// Total mass, centre of mass and inertia about it (parallel-axis theorem).
    fn combined(&self) -> (f64, Vector3<f64>, Matrix3<f64>) {
        let mass: f64 = self.parts.iter().map(|p| p.0).sum();
        if mass == 0.0 {
            return (0.0, Vector3::zeros(), Matrix3::zeros());
        }
        if let [(m, c, i)] = self.parts.as_slice() {
            // One part: as written, without the rounding of a weighted mean.
            return (*m, *c, *i);
        }
        let com = self
            .parts
            .iter()
            .fold(Vector3::zeros(), |acc, (m, c, _)| acc + c * *m)
            / mass;
        let inertia = self.parts.iter().fold(Matrix3::zeros(), |acc, (m, c, i)| {
            let d = c - com;
            acc + i + (Matrix3::identity() * d.norm_squared() - d * d.transpose()) * *m
        });
        (mass, com, inertia)
    }
}

/// Where a link sits: the body (or the base, `None`) it belongs to and its frame there.
struct Seat {
    body: Option<usize>,
    placement: Placement,
}

/// A coordinate name from a joint name: an identifier, not `pi`/`cos`/`sin`, unique.
fn identifier(name: &str, taken: &mut Vec<String>) -> String {
    let mut id: String = name
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    if !id.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_') {
        id = format!("q_{id}");
    }
    if matches!(id.as_str(), "pi" | "cos" | "sin" | "atan2") {
        id = format!("q_{id}");
    }
    let mut unique = id.clone();
    let mut n = 2;
    while taken.contains(&unique) {
        unique = format!("{id}_{n}");
        n += 1;
    }
    taken.push(unique.clone());
    unique
}

fn inertia6(i: &Matrix3<f64>) -> [f64; 6] {
    let clean = |x: f64| if x.abs() < 1e-300 { 0.0 } else { x };
    [
        clean(i[(0, 0)]),
        clean(i[(1, 1)]),
        clean(i[(2, 2)]),
        clean(i[(0, 1)]),
        clean(i[(0, 2)]),
        clean(i[(1, 2)]),
    ]
}

/// The range of a joint: its limits, or `[-π, π]` for a continuous joint.
fn range(robot: &Robot, j: usize) -> Result<[f64; 2], UrdfError> {
    let joint = &robot.joints[j];
    if joint.kind == JointType::Continuous {
        return Ok([-std::f64::consts::PI, std::f64::consts::PI]);
    }
    let element = format!("joint `{}`.limit", joint.name);
    let limit = joint.limit.ok_or_else(|| {
        UrdfError::invalid(
            &element,
            format!("a {} joint needs <limit lower upper>", joint.kind.name()),
        )
    })?;
    if limit.lower >= limit.upper {
        return Err(UrdfError::invalid(
            element,
            format!(
                "lower {} is not below upper {}: the joint cannot move",
                limit.lower, limit.upper
            ),
        ));
    }
    Ok([limit.lower, limit.upper])
}

/// Builds the case document.
pub fn build(robot: &Robot, tree: &Tree, options: &ImportOptions) -> Result<CaseDoc, UrdfError> {
    let find_link = |name: &str, option: &str| {
        tree.link_index
            .get(name)
            .copied()
            .ok_or_else(|| UrdfError::invalid(format!("--{option}"), format!("no link `{name}`")))
    };
    let base = match &options.base {
        Some(name) => find_link(name, "base")?,
        None => tree.root,
    };
    let path = match &options.tip {
        Some(name) => {
            let tip = find_link(name, "tip")?;
            Some(tree.path(base, tip).ok_or_else(|| {
                UrdfError::invalid(
                    "--tip",
                    format!(
                        "link `{name}` is not below the base `{}`",
                        robot.links[base].name
                    ),
                )
            })?)
        }
        None => None,
    };
    let subtree = tree.subtree(base);
    let moving = |j: usize| {
        robot.joints[j].kind != JointType::Fixed
            && path.as_ref().is_none_or(|p: &Vec<usize>| p.contains(&j))
    };

    // Coordinates first (a mimic joint may refer to a joint met later in the walk).
    let mut taken = Vec::new();
    let mut coordinate_of: HashMap<usize, usize> = HashMap::new();
    let mut coordinates = Vec::new();
    let mut actuators = Vec::new();
    let mut peak_limits = BTreeMap::new();
    let mut grid_joints = Vec::new();
    for &l in &subtree[1..] {
        let j = tree.parent_joint[l].expect("a non-base link of the subtree has a parent");
        let joint = &robot.joints[j];
        if !moving(j) || joint.mimic.is_some() {
            continue;
        }
        let range = range(robot, j)?;
        let name = identifier(&joint.name, &mut taken);
        coordinate_of.insert(j, coordinates.len());
        coordinates.push(CoordinateDoc {
            name: name.clone(),
            kind: if joint.kind.is_angular() {
                "angle"
            } else {
                "length"
            },
            range,
        });
        actuators.push(ActuatorDoc {
            name: joint.name.clone(),
            joint: joint.name.clone(),
            coordinate: name,
            ratio: 1.0,
        });
        if let Some(effort) = joint.limit.and_then(|l| l.effort).filter(|&e| e > 0.0) {
            peak_limits.insert(joint.name.clone(), effort);
        }
        grid_joints.push((joint.name.clone(), range));
    }

    let mut seats: HashMap<usize, Seat> = HashMap::new();
    seats.insert(
        base,
        Seat {
            body: None,
            placement: Placement::identity(),
        },
    );
    let mut bodies: Vec<BodyDoc> = Vec::new();
    let mut lumps: Vec<Lump> = Vec::new();
    let mut joints = Vec::new();
    let mut merged: Vec<String> = Vec::new();
    let body_name = |b: Option<usize>, bodies: &[BodyDoc]| match b {
        None => "base".to_string(),
        Some(i) => bodies[i].name.clone(),
    };
    for &l in &subtree[1..] {
        let j = tree.parent_joint[l].expect("a non-base link of the subtree has a parent");
        let joint = &robot.joints[j];
        let parent = &seats[&tree.ends[j].0];
        let at_joint = parent.placement.then(&steps::origin(&joint.origin));
        let seat = if moving(j) {
            let motion = motion_steps(robot, j, &coordinate_of, &coordinates)?;
            let mut pose = at_joint.steps.clone();
            pose.extend(motion);
            let name = if joint.child == "base" {
                "base (link)".to_string()
            } else {
                joint.child.clone()
            };
            let axis = at_joint.rotation * steps::unit_axis(joint.axis);
            joints.push(JointDoc {
                name: joint.name.clone(),
                kind: if joint.kind.is_angular() {
                    "revolute"
                } else {
                    "prismatic"
                },
                bodies: [body_name(parent.body, &bodies), name.clone()],
                point: at_joint.translation.into(),
                axis: axis.into(),
            });
            bodies.push(BodyDoc {
                name,
                parent: body_name(parent.body, &bodies),
                pose,
                mass: 0.0,
                com: None,
                inertia: None,
            });
            lumps.push(Lump::default());
            Seat {
                body: Some(bodies.len() - 1),
                placement: Placement::identity(),
            }
        } else {
            let placement = if joint.kind == JointType::Fixed {
                at_joint
            } else {
                let value = robot.joints[j]
                    .limit
                    .map_or(0.0, |l| 0f64.clamp(l.lower, l.upper));
                at_joint.then(&steps::frozen_motion(
                    joint.axis,
                    joint.kind.is_angular(),
                    value,
                ))
            };
            merged.push(format!(
                "`{}` into `{}`",
                joint.child,
                body_name(parent.body, &bodies)
            ));
            Seat {
                body: parent.body,
                placement,
            }
        };
        if let (Some(b), Some(inertial)) = (seat.body, &robot.links[l].inertial) {
            lumps[b].add(inertial, &seat.placement);
        }
        seats.insert(l, seat);
    }
    if bodies.is_empty() {
        return Err(UrdfError::invalid(
            format!("link `{}`", robot.links[base].name),
            "no revolute, continuous or prismatic joint below the base: nothing moves",
        ));
    }
    for (body, lump) in bodies.iter_mut().zip(&lumps) {
        let (mass, com, inertia) = lump.combined();
        body.mass = mass;
        if mass > 0.0 {
            body.com = Some(com.into());
            body.inertia = Some(inertia6(&inertia));
        }
    }

    let mut description = format!(
        "Imported from the URDF robot `{}` by `counterpoise import-urdf`. Base link `{}` (its frame is the world frame; gravity along -z, the URDF convention). Bodies are the URDF links that move, named as in the URDF; joints and actuators keep the URDF joint names, actuators drive their joint directly (ratio 1) and the effort limits are the peak limits.",
        robot.name, robot.links[base].name
    );
    if !merged.is_empty() {
        description.push_str(&format!(
            " Links merged into the body they are fixed to: {}.",
            merged.join(", ")
        ));
    }
    let grid = default_grid(&grid_joints);
    let mut balancing = json!({
        "dmax": 2,
        "counterweights": { "bodies": "all" },
        "springs": { "bodies": "all", "include_base": true }
    });
    if !peak_limits.is_empty() {
        balancing["peak_limits"] = json!(peak_limits);
    }
    Ok(CaseDoc {
        name: robot.name.clone(),
        description,
        gravity: [0.0, 0.0, -9.81],
        coordinates,
        bodies,
        joints,
        actuators,
        balancing,
        tasks: Some(json!({ "grid": grid, "pairs": "all", "duration": 2.0, "samples": 21 })),
    })
}

/// 3 points per joint over its limits, the last joints getting fewer (2, then 1: the middle of
/// the range) while the grid has more than [`GRID_POINTS`] points.
fn default_grid(joints: &[(String, [f64; 2])]) -> BTreeMap<String, Value> {
    let mut counts = vec![3usize; joints.len()];
    let mut k = joints.len();
    while counts.iter().product::<usize>() > GRID_POINTS && k > 0 {
        k -= 1;
        while counts[k] > 1 && counts.iter().product::<usize>() > GRID_POINTS {
            counts[k] -= 1;
        }
    }
    joints
        .iter()
        .zip(counts)
        .map(|((name, [lo, hi]), n)| {
            let axis = if n == 1 {
                let mid = 0.5 * (lo + hi);
                json!([mid, mid, 1])
            } else {
                json!([lo, hi, n])
            };
            (name.clone(), axis)
        })
        .collect()
}

/// The motion steps of a moving joint: its coordinate, or the coordinate it mimics.
fn motion_steps(
    robot: &Robot,
    j: usize,
    coordinate_of: &HashMap<usize, usize>,
    coordinates: &[CoordinateDoc],
) -> Result<Vec<Value>, UrdfError> {
    let joint = &robot.joints[j];
    let (source, multiplier, offset) = match &joint.mimic {
        None => (j, 1.0, 0.0),
        Some(m) => {
            let element = format!("joint `{}`.mimic", joint.name);
            let source = robot
                .joints
                .iter()
                .position(|o| o.name == m.joint)
                .ok_or_else(|| {
                    UrdfError::invalid(&element, format!("no joint `{}` to mimic", m.joint))
                })?;
            if !coordinate_of.contains_key(&source) {
                return Err(UrdfError::invalid(
                    &element,
                    format!(
                        "joint `{}` is not a moving joint of the imported chain (a mimic of a fixed, frozen or mimic joint is not supported)",
                        m.joint
                    ),
                ));
            }
            let source_angular = robot.joints[source].kind.is_angular();
            let linear_in_chart = if joint.kind.is_angular() {
                source_angular && m.multiplier.fract() == 0.0
            } else {
                !source_angular
            };
            if !linear_in_chart {
                return Err(UrdfError::invalid(
                    &element,
                    format!(
                        "{} joint mimicking {} joint `{}` with multiplier {}: not a trigonometric polynomial of the chart (supported: an integer multiplier between angles, any multiplier between lengths)",
                        joint.kind.name(),
                        robot.joints[source].kind.name(),
                        m.joint,
                        m.multiplier
                    ),
                ));
            }
            (source, m.multiplier, m.offset)
        }
    };
    let coordinate = coordinates[coordinate_of[&source]].name.clone();
    Ok(if joint.kind.is_angular() {
        steps::revolute_steps(
            joint.axis,
            &AngleExpr {
                coordinate,
                factor: multiplier as i64,
                offset: ConstAngle::Decimal(offset),
            },
        )
    } else {
        steps::prismatic_steps(
            joint.axis,
            &LengthExpr {
                coordinate,
                factor: multiplier,
                offset,
            },
        )
    })
}
