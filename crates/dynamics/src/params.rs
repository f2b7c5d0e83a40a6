//! Parameter vectors: the lifted, linear parameters of every body and spring.
//!
//! Motor torques and joint reactions are linear in these (docs/design.md §3), so a mechanism variant
//! is just a column of numbers and many variants are evaluated together as a matrix `Π`.
//!
//! Per body (10): `π = (m, h = m·c (body frame), I_o)` with `I_o` the inertia about the body
//! frame origin in body axes, stored `[Ixx, Iyy, Izz, Ixy, Ixz, Iyz]`. Counterweights and
//! payloads simply add to their body's `π`.
//!
//! Per spring slot (16): a zero-free-length spring of stiffness `K` between body `i` (anchor
//! `a` in its frame) and body `s` or the base (anchor `b`): `(K, α = K·a, β = K·b, W = K·a·bᵀ)`,
//! `W` row-major. Springs are massless and contribute their static forces only.

use counterpoise_model::{BodyId, CounterweightShape, Model, Plane};
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

use crate::error::DynamicsError;

/// Lifted parameters per body.
pub const BODY_PARAMS: usize = 10;
/// Lifted parameters per spring slot.
pub const SPRING_PARAMS: usize = 16;

/// A body pair that may hold springs: anchor `a` on `body`, anchor `b` on `other` (`None` =
/// the fixed base).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct SpringSlot {
    pub body: usize,
    pub other: Option<usize>,
}

/// A counterweight and a zero-free-length spring are the shared physical-parameter types; they
/// name their bodies, resolved to the model's indices once per column
/// ([`ParameterSet::from_variants`]).
pub use counterpoise_vocabulary::{Counterweight, Spring};

/// A set of balancing elements added to the model (the empty variant is the unbalanced robot):
/// the shared physical parameters of a variant.
pub use counterpoise_vocabulary::PhysicalParameters as Variant;

/// Many parameter columns over the same bodies and spring slots.
#[derive(Clone, Debug, PartialEq)]
pub struct ParameterSet {
    pub bodies: usize,
    pub springs: Vec<SpringSlot>,
    /// Column-major: column `p` is `data[p·rows .. (p+1)·rows]`.
    data: Vec<f64>,
}

/// `π` of a rigid body of mass `m`, CoM `c` and inertia `ic` about the CoM (body axes).
pub fn body_params(m: f64, c: &Vector3<f64>, ic: &Matrix3<f64>) -> [f64; BODY_PARAMS] {
    let io = ic + (Matrix3::identity() * c.norm_squared() - c * c.transpose()) * m;
    [
        m,
        m * c.x,
        m * c.y,
        m * c.z,
        io[(0, 0)],
        io[(1, 1)],
        io[(2, 2)],
        io[(0, 1)],
        io[(0, 2)],
        io[(1, 2)],
    ]
}

/// Centroidal inertia (body axes) of a solid cylinder of mass `m`, radius/thickness ratio
/// `tau` and density `rho`, whose axis is body axis `axis`: `m = ρπR²t`, `R = τt`,
/// `J_axis = mR²/2`, `J_⊥ = m(3R² + t²)/12`.
pub fn cylinder_inertia(m: f64, tau: f64, rho: f64, axis: usize) -> Matrix3<f64> {
    if m <= 0.0 {
        return Matrix3::zeros();
    }
    let t = (m / (rho * std::f64::consts::PI * tau * tau)).cbrt();
    let r = tau * t;
    let along = 0.5 * m * r * r;
    let across = m * (3.0 * r * r + t * t) / 12.0;
    let mut j = Matrix3::from_diagonal_element(across);
    j[(axis, axis)] = along;
    j
}

/// Centroidal inertia of a counterweight under the model's balancing options (a point mass
/// when no shape is given).
pub fn counterweight_inertia(model: &Model, mass: f64) -> Matrix3<f64> {
    let options = model
        .balancing
        .as_ref()
        .and_then(|b| b.counterweights.as_ref());
    match options.and_then(|o| o.shape.map(|s| (s, o.plane))) {
        Some((
            CounterweightShape::Cylinder {
                radius_to_thickness,
                density,
            },
            plane,
        )) => {
            let axis = plane.map(Plane::normal).unwrap_or(2);
            cylinder_inertia(mass, radius_to_thickness, density, axis)
        }
        None => Matrix3::zeros(),
    }
}

/// Lifted parameters `(K, K a, K b, K a bᵀ)` of a spring.
pub fn spring_params(k: f64, a: &[f64; 3], b: &[f64; 3]) -> [f64; SPRING_PARAMS] {
    let mut out = [0.0; SPRING_PARAMS];
    out[0] = k;
    for j in 0..3 {
        out[1 + j] = k * a[j];
        out[4 + j] = k * b[j];
        for l in 0..3 {
            out[7 + 3 * j + l] = k * a[j] * b[l];
        }
    }
    out
}

/// The `π` of every body of the model with its fixed payloads (all of them: the robot carries
/// them whatever the balancing assumes).
pub fn model_body_params(model: &Model) -> Vec<f64> {
    let mut out = Vec::with_capacity(BODY_PARAMS * model.bodies.len());
    for b in &model.bodies {
        out.extend(body_params(b.mass, &b.com, &b.inertia_com));
    }
    for p in &model.payloads {
        let add = body_params(p.mass, &p.com, &p.inertia_com);
        for (x, y) in out[BODY_PARAMS * p.body..].iter_mut().zip(add) {
            *x += y;
        }
    }
    out
}

impl ParameterSet {
    /// Rows of one column.
    pub fn rows(&self) -> usize {
        BODY_PARAMS * self.bodies + SPRING_PARAMS * self.springs.len()
    }

    /// Number of columns.
    pub fn len(&self) -> usize {
        self.data.len() / self.rows().max(1)
    }

    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }

    pub fn column(&self, p: usize) -> &[f64] {
        let r = self.rows();
        &self.data[p * r..(p + 1) * r]
    }

    pub fn column_mut(&mut self, p: usize) -> &mut [f64] {
        let r = self.rows();
        &mut self.data[p * r..(p + 1) * r]
    }

    /// An empty set over the model's bodies and the given spring slots.
    pub fn empty(bodies: usize, springs: Vec<SpringSlot>) -> ParameterSet {
        ParameterSet {
            bodies,
            springs,
            data: Vec::new(),
        }
    }

    /// Appends a raw lifted column (length [`ParameterSet::rows`]).
    pub fn push_column(&mut self, column: &[f64]) -> Result<(), DynamicsError> {
        if column.len() != self.rows() {
            return Err(DynamicsError::BadParameters(format!(
                "column has {} entries, expected {}",
                column.len(),
                self.rows()
            )));
        }
        self.data.extend_from_slice(column);
        Ok(())
    }

    /// The unbalanced model alone (one column).
    pub fn unbalanced(model: &Model) -> ParameterSet {
        ParameterSet {
            bodies: model.bodies.len(),
            springs: Vec::new(),
            data: model_body_params(model),
        }
    }

    /// One column per variant: the model plus that variant's elements. Spring slots are the
    /// distinct pairs used by any variant, ordered by body and then the other body (base
    /// first).
    pub fn from_variants(
        model: &Model,
        variants: &[Variant],
    ) -> Result<ParameterSet, DynamicsError> {
        let l = model.bodies.len();
        let mut slots: Vec<SpringSlot> = Vec::new();
        for v in variants {
            for s in &v.springs {
                let slot = spring_slot(model, s)?;
                if !slots.contains(&slot) {
                    slots.push(slot);
                }
            }
        }
        // In a fixed order, whatever the batch: a column's springs are applied slot after slot,
        // so the order is part of its arithmetic.
        slots.sort_by_key(|s| (s.body, s.other));
        let mut set = ParameterSet::empty(l, slots);
        let base = model_body_params(model);
        for v in variants {
            let mut col = base.clone();
            col.resize(set.rows(), 0.0);
            for c in &v.counterweights {
                let body = model.body_index(&c.body).ok_or_else(|| {
                    DynamicsError::BadParameters(format!(
                        "counterweight {} on body {:?}: no such body",
                        c.label, c.body
                    ))
                })?;
                let inertia = counterweight_inertia(model, c.mass);
                let add = body_params(c.mass, &Vector3::from(c.offset), &inertia);
                for (x, y) in col[BODY_PARAMS * body..].iter_mut().zip(add) {
                    *x += y;
                }
            }
            for s in &v.springs {
                let wanted = spring_slot(model, s)?;
                let slot = set
                    .springs
                    .iter()
                    .position(|x| *x == wanted)
                    .expect("slot registered above");
                let add = spring_params(s.stiffness, &s.anchor_a, &s.anchor_b);
                let off = BODY_PARAMS * l + SPRING_PARAMS * slot;
                for (x, y) in col[off..].iter_mut().zip(add) {
                    *x += y;
                }
            }
            set.data.extend(col);
        }
        Ok(set)
    }
}

/// The slot of a spring: its bodies' indices (`base` is the ground).
fn spring_slot(model: &Model, s: &Spring) -> Result<SpringSlot, DynamicsError> {
    let unknown = |name: &str| {
        DynamicsError::BadParameters(format!("spring {} on body {name:?}: no such body", s.label))
    };
    let body = model.body_index(&s.body).ok_or_else(|| unknown(&s.body))?;
    let other = match model.body_id(&s.other).ok_or_else(|| unknown(&s.other))? {
        BodyId::Base => None,
        BodyId::Body(b) => Some(b),
    };
    Ok(SpringSlot { body, other })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cylinder_matches_its_volume() {
        let (m, tau, rho) = (100.0, 1.0, 7850.0);
        let j = cylinder_inertia(m, tau, rho, 2);
        let t = (m / (rho * std::f64::consts::PI)).cbrt();
        assert!((j[(2, 2)] - 0.5 * m * t * t).abs() < 1e-12);
        assert!((j[(0, 0)] - m * (3.0 * t * t + t * t) / 12.0).abs() < 1e-12);
    }

    #[test]
    fn parallel_axis() {
        let p = body_params(2.0, &Vector3::new(1.0, 0.0, 0.0), &Matrix3::identity());
        assert_eq!(p[0..4], [2.0, 2.0, 0.0, 0.0]);
        assert_eq!(p[4..7], [1.0, 3.0, 3.0]);
    }
}
