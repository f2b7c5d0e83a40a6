//! What the balance search needs to know about a mechanism: the chart, gravity, the symbolic pose
//! of every body that may carry an element, and the unbalanced potential energy.
//!
//! Kept separate from the case model so that tests can build small mechanisms by hand and so that
//! the search depends only on poses and energies, never on how they were described.

use counterpoise_model::{ExactMechanism, SurdMechanism};
use counterpoise_symbolic::{PolyMat3, PolyVec3, TrigPoly, VarKind};

/// The symbolic world pose of one body: `x_world = origin + rotation · x_body`.
#[derive(Clone, Debug)]
pub struct BodyFrame {
    pub name: String,
    pub rotation: PolyMat3,
    pub origin: PolyVec3,
}

/// A mechanism as the balance search sees it.
#[derive(Clone, Debug)]
pub struct MechanismEnergy {
    /// Kind of each chart coordinate.
    pub kinds: Vec<VarKind>,
    /// Range of each chart coordinate, used to sample configurations for verification.
    pub ranges: Vec<(f64, f64)>,
    /// Gravity vector in world axes (m/s²).
    pub gravity: [f64; 3],
    /// Bodies that may carry balancing elements, and those their springs may attach to.
    pub bodies: Vec<BodyFrame>,
    /// Gravitational potential energy of the unbalanced mechanism (J).
    pub unbalanced: TrigPoly,
    /// The same mechanism in exact rationals, or why its numbers cannot be taken exactly (the
    /// search then decides numerically and says so).
    pub exact: Result<ExactMechanism, String>,
    /// The mechanism over ℚ(√2, √3) when `exact` failed (rotations by multiples of π/12), or why
    /// that field cannot hold it either (the search then decides numerically with that reason).
    pub surd: Result<SurdMechanism, String>,
}

impl MechanismEnergy {
    /// Numeric pose `(R, p)` of body `index` at configuration `q`.
    pub fn pose(
        &self,
        index: usize,
        at: &counterpoise_symbolic::Point,
    ) -> ([[f64; 3]; 3], [f64; 3]) {
        let body = &self.bodies[index];
        (body.rotation.eval(at), body.origin.eval(at))
    }
}
