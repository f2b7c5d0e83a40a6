//! The validated mechanism model: everything later stages need, in typed and resolved form.
//!
//! A [`Model`] is only produced by validation ([`crate::Case::from_json_str`]), so its names are
//! unique, its references resolve, its inertias are PSD and its joints are consistent. The fields
//! are public for reading; editing them bypasses those checks.

use counterpoise_symbolic::{Point, PolyMat3, PolyVec3, TrigPoly, VarKind};
use nalgebra::{Matrix3, Vector3};

use crate::case::Case;

/// A reference to a body or to the fixed base.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum BodyId {
    Base,
    /// Index into [`Model::bodies`] (file order).
    Body(usize),
}

impl BodyId {
    /// The body index, or `None` for the base.
    pub fn index(self) -> Option<usize> {
        match self {
            BodyId::Base => None,
            BodyId::Body(i) => Some(i),
        }
    }
}

/// A chart coordinate.
#[derive(Clone, Debug, PartialEq)]
pub struct Coordinate {
    pub name: String,
    pub kind: VarKind,
    /// `[min, max]` with `min < max` (rad or m): the region the mechanism works in.
    pub range: [f64; 2],
}

impl Coordinate {
    pub fn midpoint(&self) -> f64 {
        0.5 * (self.range[0] + self.range[1])
    }

    /// Unit used when printing a value of this coordinate.
    pub fn unit(&self) -> &'static str {
        match self.kind {
            VarKind::Angle => "rad",
            VarKind::Length => "m",
        }
    }
}

/// A rigid body with its world pose as trigonometric polynomials in the chart.
#[derive(Clone, Debug, PartialEq)]
pub struct Body {
    pub name: String,
    /// The frame its pose steps are expressed in (not necessarily its kinematic parent).
    pub parent: BodyId,
    /// kg; zero for a massless link.
    pub mass: f64,
    /// Centre of mass in the body frame, m.
    pub com: Vector3<f64>,
    /// Inertia tensor about the centre of mass in body axes, kg·m² (symmetric PSD).
    pub inertia_com: Matrix3<f64>,
    /// World rotation `R_i(q)` (body axes → world axes).
    pub rotation: PolyMat3,
    /// World position `p_i(q)` of the body frame origin.
    pub origin: PolyVec3,
}

impl Body {
    /// First moment `h = m·c` in the body frame.
    pub fn first_moment(&self) -> Vector3<f64> {
        self.com * self.mass
    }

    /// Inertia about the body frame origin, body axes: `I_c + m(|c|²·1 − c cᵀ)`.
    pub fn inertia_origin(&self) -> Matrix3<f64> {
        let c = self.com;
        self.inertia_com + (Matrix3::identity() * c.norm_squared() - c * c.transpose()) * self.mass
    }
}

/// A mass carried by a body (a load), possibly counted in the balancing.
#[derive(Clone, Debug, PartialEq)]
pub struct Payload {
    pub name: String,
    pub body: usize,
    pub mass: f64,
    /// Centre of mass in the carrying body's frame.
    pub com: Vector3<f64>,
    pub inertia_com: Matrix3<f64>,
    /// Whether the balancing treats the payload as part of its body.
    pub in_balance: bool,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum JointKind {
    Revolute,
    Prismatic,
    Spherical,
    Universal,
    Fixed,
    /// Relative rotation fixed, translation free (a parallelogram orientation linkage); its
    /// reactions are moments only.
    Orientation,
}

impl JointKind {
    pub fn name(self) -> &'static str {
        match self {
            JointKind::Revolute => "revolute",
            JointKind::Prismatic => "prismatic",
            JointKind::Spherical => "spherical",
            JointKind::Universal => "universal",
            JointKind::Fixed => "fixed",
            JointKind::Orientation => "orientation",
        }
    }

    /// Whether the kind has an `axis` (in the first body's frame).
    pub fn has_axis(self) -> bool {
        matches!(
            self,
            JointKind::Revolute | JointKind::Prismatic | JointKind::Universal
        )
    }
}

/// A joint between two bodies, with its geometry expressed in both bodies' frames.
#[derive(Clone, Debug, PartialEq)]
pub struct Joint {
    pub name: String,
    pub kind: JointKind,
    pub bodies: [BodyId; 2],
    /// The joint point in the frame of `bodies[0]` and of `bodies[1]`. For a prismatic joint the
    /// second one is where the point sits at the reference configuration (the range midpoint);
    /// for an orientation joint the point only locates the reaction moments.
    pub points: [Vector3<f64>; 2],
    /// Unit axis in both bodies' frames (revolute, prismatic, universal).
    pub axes: Option<[Vector3<f64>; 2]>,
    /// Second unit axis of a universal joint, in the frame of `bodies[1]`.
    pub axis2: Option<Vector3<f64>>,
}

/// An actuated coordinate `u = f(q)`: a linear combination of angle coordinates plus a
/// trigonometric polynomial.
///
/// The linear part exists because an angle itself (`u = θ1` for a motor on a revolute joint)
/// is not a trigonometric polynomial in `cos θ`, `sin θ`; its derivative, however, is.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct ActuatorMap {
    /// `(coordinate index, coefficient)` of angle coordinates entering linearly.
    pub linear: Vec<(usize, f64)>,
    pub poly: TrigPoly,
}

impl ActuatorMap {
    /// `f(q)`; `at` must be the [`Point`] of `q`.
    pub fn eval(&self, q: &[f64], at: &Point) -> f64 {
        self.poly.eval(at) + self.linear.iter().map(|&(k, c)| c * q[k]).sum::<f64>()
    }

    /// `∂f/∂q_var` (a trigonometric polynomial).
    pub fn derivative(&self, var: usize, kind: VarKind) -> TrigPoly {
        let mut d = self.poly.derivative(var, kind);
        for &(k, c) in &self.linear {
            if k == var {
                d = d + TrigPoly::constant(c);
            }
        }
        d
    }
}

/// A motor driving one joint along the actuated coordinate `u = f(q)`.
#[derive(Clone, Debug, PartialEq)]
pub struct Actuator {
    pub name: String,
    /// Index into [`Model::joints`] (a revolute or prismatic joint).
    pub joint: usize,
    pub coordinate: ActuatorMap,
    /// The expression as written in the case.
    pub source: String,
    /// Motor torque per unit generalized force (N·m per N·m or per N).
    pub ratio: f64,
}

/// A plane of a body frame to which balancing vectors are restricted (the shared vocabulary).
pub use counterpoise_vocabulary::Plane;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CounterweightShape {
    /// Solid steel-like cylinder whose axis is the plane normal (or body z without a plane).
    Cylinder {
        radius_to_thickness: f64,
        density: f64,
    },
}

#[derive(Clone, Debug, PartialEq)]
pub struct CounterweightOptions {
    /// Bodies that may carry a counterweight, ascending (file order).
    pub bodies: Vec<usize>,
    pub plane: Option<Plane>,
    /// `None`: point masses (no centroidal inertia).
    pub shape: Option<CounterweightShape>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct SpringOptions {
    /// Bodies that may carry spring ends, ascending (file order).
    pub bodies: Vec<usize>,
    pub include_base: bool,
    pub plane: Option<Plane>,
}

impl SpringOptions {
    /// Candidate spring pairs `(i, s)`: for each selected body `i` in file order, first the
    /// base (when included), then every selected body before it. `a` is anchored on `i`, `b`
    /// on `s` — the paper's `K_is` with `i > s`.
    pub fn pairs(&self) -> Vec<(BodyId, BodyId)> {
        let mut pairs = Vec::new();
        for (n, &i) in self.bodies.iter().enumerate() {
            if self.include_base {
                pairs.push((BodyId::Body(i), BodyId::Base));
            }
            for &s in &self.bodies[..n] {
                pairs.push((BodyId::Body(i), BodyId::Body(s)));
            }
        }
        pairs
    }
}

/// `[lo, hi]` bounds of the balancing element parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    /// Counterweight mass, kg.
    pub mass: [f64; 2],
    /// Counterweight CoM distance |r| from the body origin, m.
    pub radius: [f64; 2],
    /// Spring stiffness, N/m.
    pub stiffness: [f64; 2],
    /// |a|: spring anchor on the first body of the pair, m.
    pub anchor_a: [f64; 2],
    /// |b|: spring anchor on the second body (or the base), m.
    pub anchor_b: [f64; 2],
}

impl Default for Bounds {
    /// Defaults documented in `docs/case-format.md`.
    fn default() -> Self {
        Bounds {
            mass: [0.0, 1000.0],
            radius: [0.0, 1.0],
            stiffness: [0.0, 1.0e5],
            anchor_a: [0.0, 1.0],
            anchor_b: [0.0, 1.0],
        }
    }
}

/// What the default bounds are derived from: the mechanism's moving mass and reach.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MechanismScale {
    /// Sum of the bodies' masses (every body moves), kg.
    pub moving_mass: f64,
    /// Largest body reach, m: for each body, the distance of its centre of mass from its frame
    /// origin plus √3 times its largest radius of gyration about the centre of mass (a uniform
    /// rod of length ℓ has k = ℓ/√12, so √3·k = ℓ/2: the reach of a rod hung at one end is its
    /// length).
    pub reach: f64,
    /// |g|, m/s².
    pub gravity: f64,
}

impl MechanismScale {
    /// The scale of `bodies` under `gravity`.
    pub fn of(bodies: &[Body], gravity: Vector3<f64>) -> MechanismScale {
        let reach = bodies
            .iter()
            .map(|b| {
                let k = if b.mass > 0.0 {
                    // The trace bounds the largest moment of a positive semi-definite
                    // tensor: the fallback if the capped eigensolver gives up.
                    let largest = crate::inertia::principal_moments(&b.inertia_com)
                        .map_or(b.inertia_com.trace(), |e| {
                            e.iter().fold(0.0f64, |m, x| m.max(*x))
                        });
                    (largest / b.mass).max(0.0).sqrt()
                } else {
                    0.0
                };
                b.com.norm() + 3f64.sqrt() * k
            })
            .fold(0.0f64, f64::max);
        MechanismScale {
            moving_mass: bodies.iter().map(|b| b.mass).sum(),
            reach,
            gravity: gravity.norm(),
        }
    }
}

impl Bounds {
    /// Default bounds derived from the mechanism (docs/case-format.md, `bounds`): counterweight
    /// mass up to the moving mass, offsets and anchor distances up to the reach, stiffness up
    /// to the value whose force at 1 % of the reach carries the whole moving weight
    /// (`100·M·|g|/reach`). A scale that is zero (no mass, no extent, no gravity) keeps the
    /// fixed default of [`Bounds::default`] for that entry.
    pub fn derived(scale: &MechanismScale) -> Bounds {
        let fixed = Bounds::default();
        let pick = |v: f64, fallback: [f64; 2]| {
            if v.is_finite() && v > 0.0 {
                [0.0, v]
            } else {
                fallback
            }
        };
        let length = |fallback| pick(scale.reach, fallback);
        Bounds {
            mass: pick(scale.moving_mass, fixed.mass),
            radius: length(fixed.radius),
            stiffness: if scale.reach > 0.0 {
                pick(
                    100.0 * scale.moving_mass * scale.gravity / scale.reach,
                    fixed.stiffness,
                )
            } else {
                fixed.stiffness
            },
            anchor_a: length(fixed.anchor_a),
            anchor_b: length(fixed.anchor_b),
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Balancing {
    /// Most elements per variant (≥ 1).
    pub dmax: usize,
    pub counterweights: Option<CounterweightOptions>,
    pub springs: Option<SpringOptions>,
    pub bounds: Bounds,
    /// Which `bounds` entries the case left out and were derived from the mechanism
    /// ([`Bounds::derived`]), e.g. `["mass", "radius"]`; `check` and `run` name them.
    pub derived_bounds: Vec<&'static str>,
    /// Peak motor torque limit per actuator (index = actuator), N·m.
    pub peak_limits: Vec<Option<f64>>,
    /// Raw, not yet interpreted (a later issue defines them).
    pub overrides: Vec<serde_json::Value>,
}

/// One axis of the task grid: `n` equally spaced values from `from` to `to`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridAxis {
    pub from: f64,
    pub to: f64,
    pub n: usize,
}

impl GridAxis {
    pub fn values(&self) -> Vec<f64> {
        if self.n == 1 {
            return vec![self.from];
        }
        (0..self.n)
            .map(|k| self.from + (self.to - self.from) * k as f64 / (self.n - 1) as f64)
            .collect()
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PairMode {
    /// Every unordered pair of grid points, one move each (from the lower to the higher index).
    All,
    /// Every ordered pair: both directions.
    Ordered,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MotionLaw {
    /// Rest-to-rest quintic polynomial in actuator space.
    Quintic,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Tasks {
    /// One axis per actuator, in actuator order.
    pub grid: Vec<GridAxis>,
    pub pairs: PairMode,
    pub law: MotionLaw,
    /// Seconds per move.
    pub duration: f64,
    /// Time samples per move, including both ends (≥ 2).
    pub samples: usize,
}

impl Tasks {
    /// All grid points in actuator space, the first actuator varying slowest.
    pub fn grid_points(&self) -> Vec<Vec<f64>> {
        let mut points = vec![Vec::new()];
        for axis in &self.grid {
            let values = axis.values();
            points = points
                .iter()
                .flat_map(|p| {
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
}

#[derive(Clone, Debug, PartialEq)]
pub struct Waypoint {
    pub name: String,
    /// Actuator values, in actuator order.
    pub u: Vec<f64>,
}

/// A payload carried along part of a path.
#[derive(Clone, Debug, PartialEq)]
pub struct PathPayload {
    pub body: usize,
    pub mass: f64,
    pub com: Vector3<f64>,
    pub inertia_com: Matrix3<f64>,
    /// Index into [`TaskPath::sequence`] where the payload is picked.
    pub pick_at: usize,
    /// Index into [`TaskPath::sequence`] (after `pick_at`) where it is dropped.
    pub drop_at: usize,
}

/// A named multi-segment move through waypoints (e.g. the paper's path Λ).
#[derive(Clone, Debug, PartialEq)]
pub struct TaskPath {
    pub name: String,
    pub waypoints: Vec<Waypoint>,
    /// Indices into `waypoints`.
    pub sequence: Vec<usize>,
    /// Seconds per segment (`sequence.len() − 1` of them).
    pub durations: Vec<f64>,
    pub payload: Option<PathPayload>,
}

/// Which payloads [`Model::potential_energy`] counts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PayloadMode {
    /// Only payloads with `in_balance: true` (what the balancing sees).
    InBalance,
    All,
    None,
}

/// A validated mechanism.
#[derive(Clone, Debug, PartialEq)]
pub struct Model {
    pub name: String,
    pub description: Option<String>,
    /// m/s², base frame.
    pub gravity: Vector3<f64>,
    /// Named constants, file order.
    pub parameters: Vec<(String, f64)>,
    pub coordinates: Vec<Coordinate>,
    pub bodies: Vec<Body>,
    pub payloads: Vec<Payload>,
    pub joints: Vec<Joint>,
    pub actuators: Vec<Actuator>,
    pub balancing: Option<Balancing>,
    pub tasks: Option<Tasks>,
    pub paths: Vec<TaskPath>,
    /// The case as written (for echoing into results).
    pub case: Case,
}

impl Model {
    /// Number of chart coordinates.
    pub fn dof(&self) -> usize {
        self.coordinates.len()
    }

    pub fn kinds(&self) -> Vec<VarKind> {
        self.coordinates.iter().map(|c| c.kind).collect()
    }

    /// The reference configuration: the midpoint of every coordinate range.
    pub fn reference_configuration(&self) -> Vec<f64> {
        self.coordinates.iter().map(Coordinate::midpoint).collect()
    }

    /// Precomputed trigonometric values of `q` for evaluating the model's polynomials.
    pub fn point(&self, q: &[f64]) -> Point {
        Point::new(q, &self.kinds())
    }

    /// The plane the case restricts counterweight offsets to, if any (the reports give the
    /// offsets in polar form in it).
    pub fn counterweight_plane(&self) -> Option<Plane> {
        self.balancing
            .as_ref()
            .and_then(|b| b.counterweights.as_ref())
            .and_then(|c| c.plane)
    }

    /// The plane the case restricts spring anchors to, if any.
    pub fn spring_plane(&self) -> Option<Plane> {
        self.balancing
            .as_ref()
            .and_then(|b| b.springs.as_ref())
            .and_then(|s| s.plane)
    }

    pub fn body_index(&self, name: &str) -> Option<usize> {
        self.bodies.iter().position(|b| b.name == name)
    }

    /// Like [`Model::body_index`] but also resolves `"base"`.
    pub fn body_id(&self, name: &str) -> Option<BodyId> {
        if name == "base" {
            Some(BodyId::Base)
        } else {
            self.body_index(name).map(BodyId::Body)
        }
    }

    pub fn body_name(&self, id: BodyId) -> &str {
        match id {
            BodyId::Base => "base",
            BodyId::Body(i) => &self.bodies[i].name,
        }
    }

    pub fn coordinate_index(&self, name: &str) -> Option<usize> {
        self.coordinates.iter().position(|c| c.name == name)
    }

    pub fn joint_index(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    pub fn actuator_index(&self, name: &str) -> Option<usize> {
        self.actuators.iter().position(|a| a.name == name)
    }

    /// Total mass of the moving bodies (payloads excluded), kg.
    pub fn total_mass(&self) -> f64 {
        self.bodies.iter().map(|b| b.mass).sum()
    }

    /// Numeric world pose `(R, p)` of a body (identity for the base) at `at`.
    pub fn body_pose(&self, id: BodyId, at: &Point) -> (Matrix3<f64>, Vector3<f64>) {
        match id {
            BodyId::Base => (Matrix3::identity(), Vector3::zeros()),
            BodyId::Body(i) => {
                let b = &self.bodies[i];
                (
                    Matrix3::from(b.rotation.eval(at)).transpose(),
                    Vector3::from(b.origin.eval(at)),
                )
            }
        }
    }

    /// Gravitational potential `−m g·(p_i + R_i c)` of a point mass `m` at `local_point` in the
    /// frame of `body` (J, as a trigonometric polynomial in the chart).
    pub fn gravity_potential(
        &self,
        body: BodyId,
        mass: f64,
        local_point: &Vector3<f64>,
    ) -> TrigPoly {
        let g = [self.gravity.x, self.gravity.y, self.gravity.z];
        let c = [local_point.x, local_point.y, local_point.z];
        let world = match body {
            BodyId::Base => PolyVec3::constant(c),
            BodyId::Body(i) => {
                let b = &self.bodies[i];
                b.origin.add(&b.rotation.mul_const_vec(c))
            }
        };
        world.dot_const(g).scale(-mass)
    }

    /// Gravitational potential of all bodies, plus payloads as selected by `payloads`.
    pub fn potential_energy(&self, payloads: PayloadMode) -> TrigPoly {
        let mut v = TrigPoly::zero();
        for (i, b) in self.bodies.iter().enumerate() {
            if b.mass != 0.0 {
                v = v + self.gravity_potential(BodyId::Body(i), b.mass, &b.com);
            }
        }
        for p in &self.payloads {
            let counted = match payloads {
                PayloadMode::InBalance => p.in_balance,
                PayloadMode::All => true,
                PayloadMode::None => false,
            };
            if counted {
                v = v + self.gravity_potential(BodyId::Body(p.body), p.mass, &p.com);
            }
        }
        v
    }
}
