//! Numeric kinematics of a validated model: poses, Jacobians, velocities, accelerations and
//! the actuator map, all evaluated from symbolic derivatives computed once.
//!
//! Differentiating the trigonometric polynomials exactly (rather than by finite differences)
//! gives Jacobians and second-order terms with no truncation error, from the same single
//! source of truth as the poses themselves. The derivatives are built once in
//! [`Kinematics::new`]; evaluation at a configuration only evaluates polynomials.

use counterpoise_symbolic::{Point, PolyMat3, PolyVec3, TrigPoly, VarKind};
use nalgebra::{DMatrix, DVector, Matrix3, Matrix3xX, Vector3};

use crate::model::{ActuatorMap, Coordinate, Model};

/// Index of the unordered pair `(k, l)` in packed symmetric storage.
fn packed(k: usize, l: usize) -> usize {
    let (lo, hi) = if k <= l { (k, l) } else { (l, k) };
    hi * (hi + 1) / 2 + lo
}

fn mat(m: &PolyMat3, at: &Point) -> Matrix3<f64> {
    Matrix3::from_fn(|i, j| m.0[i][j].eval(at))
}

fn vec3(v: &PolyVec3, at: &Point) -> Vector3<f64> {
    Vector3::from_fn(|i, _| v.0[i].eval(at))
}

/// `v` with `[v]× = (m − mᵀ)/2` (the rotational part of `m`).
fn vee(m: &Matrix3<f64>) -> Vector3<f64> {
    Vector3::new(
        m[(2, 1)] - m[(1, 2)],
        m[(0, 2)] - m[(2, 0)],
        m[(1, 0)] - m[(0, 1)],
    ) * 0.5
}

fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// A rotation and a position, both in world axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// Body axes → world axes.
    pub rotation: Matrix3<f64>,
    /// World position of the body frame origin.
    pub position: Vector3<f64>,
}

/// Velocity Jacobians of a body frame: `v = linear · q̇`, `ω = angular · q̇` (world axes).
#[derive(Clone, Debug, PartialEq)]
pub struct BodyJacobian {
    pub linear: Matrix3xX<f64>,
    pub angular: Matrix3xX<f64>,
}

/// Full motion of a body frame at `(q, q̇, q̈)`, world axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyMotion {
    pub rotation: Matrix3<f64>,
    pub position: Vector3<f64>,
    /// ω with `[ω]× = Ṙ Rᵀ`.
    pub angular_velocity: Vector3<f64>,
    /// Velocity of the frame origin.
    pub velocity: Vector3<f64>,
    /// α with `[α]× = R̈ Rᵀ − [ω]×²`.
    pub angular_acceleration: Vector3<f64>,
    /// Acceleration of the frame origin.
    pub acceleration: Vector3<f64>,
}

/// A pose and its first and second partial derivatives, as polynomials.
#[derive(Clone, Debug)]
struct PoseTerms {
    rotation: PolyMat3,
    origin: PolyVec3,
    /// `∂/∂q_k`, k = 0..n.
    first: Vec<(PolyMat3, PolyVec3)>,
    /// `∂²/∂q_k∂q_l`, packed symmetric.
    second: Vec<(PolyMat3, PolyVec3)>,
}

#[derive(Clone, Debug)]
struct ActuatorTerms {
    map: ActuatorMap,
    /// `∂f/∂q_k`.
    first: Vec<TrigPoly>,
    /// `∂²f/∂q_k∂q_l`, packed symmetric.
    second: Vec<TrigPoly>,
}

/// Kinematics of one model, with all symbolic derivatives precomputed.
#[derive(Clone, Debug)]
pub struct Kinematics {
    pub(crate) coordinates: Vec<Coordinate>,
    kinds: Vec<VarKind>,
    /// Angles that enter the actuator map only through cos/sin: shifting them by 2π leaves
    /// `u` unchanged, so Newton may wrap them into their ranges.
    pub(crate) periodic: Vec<bool>,
    bodies: Vec<PoseTerms>,
    actuators: Vec<ActuatorTerms>,
}

impl Kinematics {
    pub fn new(model: &Model) -> Kinematics {
        let kinds = model.kinds();
        let n = kinds.len();
        let bodies = model
            .bodies
            .iter()
            .map(|b| {
                let first: Vec<_> = (0..n)
                    .map(|k| {
                        (
                            b.rotation.derivative(k, kinds[k]),
                            b.origin.derivative(k, kinds[k]),
                        )
                    })
                    .collect();
                let mut second = Vec::with_capacity(n * (n + 1) / 2);
                for (l, &kind) in kinds.iter().enumerate() {
                    for (r, p) in first.iter().take(l + 1) {
                        second.push((r.derivative(l, kind), p.derivative(l, kind)));
                    }
                }
                PoseTerms {
                    rotation: b.rotation.clone(),
                    origin: b.origin.clone(),
                    first,
                    second,
                }
            })
            .collect();
        let actuators = model
            .actuators
            .iter()
            .map(|a| {
                let first: Vec<_> = (0..n)
                    .map(|k| a.coordinate.derivative(k, kinds[k]))
                    .collect();
                let mut second = Vec::with_capacity(n * (n + 1) / 2);
                for (l, &kind) in kinds.iter().enumerate() {
                    for f in first.iter().take(l + 1) {
                        second.push(f.derivative(l, kind));
                    }
                }
                ActuatorTerms {
                    map: a.coordinate.clone(),
                    first,
                    second,
                }
            })
            .collect();
        let periodic = (0..n)
            .map(|k| {
                kinds[k] == VarKind::Angle
                    && model
                        .actuators
                        .iter()
                        .all(|a| a.coordinate.linear.iter().all(|&(j, c)| j != k || c == 0.0))
            })
            .collect();
        Kinematics {
            coordinates: model.coordinates.clone(),
            kinds,
            periodic,
            bodies,
            actuators,
        }
    }

    /// Number of chart coordinates.
    pub fn dof(&self) -> usize {
        self.kinds.len()
    }

    pub fn body_count(&self) -> usize {
        self.bodies.len()
    }

    pub fn coordinates(&self) -> &[Coordinate] {
        &self.coordinates
    }

    /// Trigonometric values of `q`, shared by every evaluation at `q`.
    pub fn point(&self, q: &DVector<f64>) -> Point {
        assert_eq!(
            q.len(),
            self.dof(),
            "configuration has the wrong number of coordinates"
        );
        Point::new(q.as_slice(), &self.kinds)
    }

    pub fn body_pose(&self, body: usize, q: &DVector<f64>) -> Pose {
        self.pose_at(body, &self.point(q))
    }

    /// Poses of all bodies (file order).
    pub fn body_poses(&self, q: &DVector<f64>) -> Vec<Pose> {
        let at = self.point(q);
        (0..self.bodies.len())
            .map(|i| self.pose_at(i, &at))
            .collect()
    }

    fn pose_at(&self, body: usize, at: &Point) -> Pose {
        let b = &self.bodies[body];
        Pose {
            rotation: mat(&b.rotation, at),
            position: vec3(&b.origin, at),
        }
    }

    pub fn body_jacobian(&self, body: usize, q: &DVector<f64>) -> BodyJacobian {
        let at = self.point(q);
        let b = &self.bodies[body];
        let rt = mat(&b.rotation, &at).transpose();
        let n = self.dof();
        let mut linear = Matrix3xX::zeros(n);
        let mut angular = Matrix3xX::zeros(n);
        for (k, (dr, dp)) in b.first.iter().enumerate() {
            linear.set_column(k, &vec3(dp, &at));
            angular.set_column(k, &vee(&(mat(dr, &at) * rt)));
        }
        BodyJacobian { linear, angular }
    }

    /// Motion of one body at `(q, q̇, q̈)`.
    pub fn body_motion(
        &self,
        body: usize,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        qdd: &DVector<f64>,
    ) -> BodyMotion {
        self.motion_at(body, &self.point(q), qd, qdd)
    }

    /// Motions of all bodies at `(q, q̇, q̈)` (file order).
    pub fn body_motions(
        &self,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        qdd: &DVector<f64>,
    ) -> Vec<BodyMotion> {
        let at = self.point(q);
        (0..self.bodies.len())
            .map(|i| self.motion_at(i, &at, qd, qdd))
            .collect()
    }

    fn motion_at(
        &self,
        body: usize,
        at: &Point,
        qd: &DVector<f64>,
        qdd: &DVector<f64>,
    ) -> BodyMotion {
        let n = self.dof();
        assert!(
            qd.len() == n && qdd.len() == n,
            "velocity/acceleration size differs from the coordinates"
        );
        let b = &self.bodies[body];
        let rotation = mat(&b.rotation, at);
        let position = vec3(&b.origin, at);
        let mut r_dot = Matrix3::zeros();
        let mut r_ddot = Matrix3::zeros();
        let mut velocity = Vector3::zeros();
        let mut acceleration = Vector3::zeros();
        for (k, (dr, dp)) in b.first.iter().enumerate() {
            if qd[k] == 0.0 && qdd[k] == 0.0 {
                continue;
            }
            let (dr, dp) = (mat(dr, at), vec3(dp, at));
            r_dot += dr * qd[k];
            r_ddot += dr * qdd[k];
            velocity += dp * qd[k];
            acceleration += dp * qdd[k];
        }
        for l in 0..n {
            for k in 0..=l {
                let w = qd[k] * qd[l] * if k == l { 1.0 } else { 2.0 };
                if w == 0.0 {
                    continue;
                }
                let (drr, dpp) = &b.second[packed(k, l)];
                r_ddot += mat(drr, at) * w;
                acceleration += vec3(dpp, at) * w;
            }
        }
        let rt = rotation.transpose();
        let angular_velocity = vee(&(r_dot * rt));
        let w = skew(&angular_velocity);
        // [ω]×² is symmetric, so `vee` drops it; it is kept to state the identity in full.
        let angular_acceleration = vee(&(r_ddot * rt - w * w));
        BodyMotion {
            rotation,
            position,
            angular_velocity,
            velocity,
            angular_acceleration,
            acceleration,
        }
    }

    /// Actuated coordinates `u = f(q)`.
    pub fn actuator_values(&self, q: &DVector<f64>) -> DVector<f64> {
        let at = self.point(q);
        self.values_at(q, &at)
    }

    pub(crate) fn values_at(&self, q: &DVector<f64>, at: &Point) -> DVector<f64> {
        DVector::from_iterator(
            self.actuators.len(),
            self.actuators.iter().map(|a| a.map.eval(q.as_slice(), at)),
        )
    }

    /// Actuator Jacobian `G = ∂f/∂q` (actuators × coordinates).
    pub fn actuator_jacobian(&self, q: &DVector<f64>) -> DMatrix<f64> {
        self.jacobian_at(&self.point(q))
    }

    pub(crate) fn jacobian_at(&self, at: &Point) -> DMatrix<f64> {
        DMatrix::from_fn(self.actuators.len(), self.dof(), |i, k| {
            self.actuators[i].first[k].eval(at)
        })
    }

    /// The velocity-product term `Ġ q̇ = Σ_kl ∂²f/∂q_k∂q_l q̇_k q̇_l`, so that `ü = G q̈ + Ġ q̇`.
    pub fn actuator_bias(&self, q: &DVector<f64>, qd: &DVector<f64>) -> DVector<f64> {
        let at = self.point(q);
        self.bias_at(&at, qd)
    }

    fn bias_at(&self, at: &Point, qd: &DVector<f64>) -> DVector<f64> {
        let n = self.dof();
        assert_eq!(qd.len(), n, "velocity size differs from the coordinates");
        DVector::from_iterator(
            self.actuators.len(),
            self.actuators.iter().map(|a| {
                let mut sum = 0.0;
                for l in 0..n {
                    for k in 0..=l {
                        let w = qd[k] * qd[l] * if k == l { 1.0 } else { 2.0 };
                        if w != 0.0 {
                            sum += a.second[packed(k, l)].eval(at) * w;
                        }
                    }
                }
                sum
            }),
        )
    }

    /// Coordinate velocity and acceleration from actuator ones: `q̇ = G⁻¹u̇`,
    /// `q̈ = G⁻¹(ü − Ġq̇)`. Fails where `G` is singular (see [`crate::NewtonOptions`]).
    pub fn coordinate_rates(
        &self,
        q: &DVector<f64>,
        ud: &DVector<f64>,
        udd: &DVector<f64>,
    ) -> Result<(DVector<f64>, DVector<f64>), crate::KinematicsError> {
        let at = self.point(q);
        let g = self.jacobian_at(&at);
        let lu =
            crate::jacobian_lu::checked_lu(&g, q, crate::NewtonOptions::default().max_condition)?;
        let qd = lu.solve(ud).expect("checked non-singular");
        let qdd = lu
            .solve(&(udd - self.bias_at(&at, &qd)))
            .expect("checked non-singular");
        Ok((qd, qdd))
    }
}
