//! The elements of a variant as the optimiser sees them: each counterweight's and spring's
//! place among the lifted variables, its bounds, and a counterweight's physical parameters.
//!
//! The problem (`problem`) is built from these slots and the anchor restriction
//! (`anchor_restriction`) reads them; they are apart so that neither depends on the other.

use counterpoise_balance::Attachment;
use nalgebra::Matrix3;

use crate::overrides::{CounterweightBounds, SpringBounds};

/// Smallest counterweight mass treated as installed, relative to the upper mass bound: a mass
/// that must vanish means the variant is really a smaller one.
pub const MIN_MASS_FRACTION: f64 = 1e-6;

/// A counterweight of the variant.
#[derive(Clone, Debug)]
pub struct CwSlot {
    pub entry: usize,
    pub label: String,
    pub body: usize,
    /// Body-frame axes of `r`.
    pub axes: Vec<usize>,
    /// First lifted variable (`m`) in `x`.
    pub column: usize,
    /// Slot of the body in the torque cache.
    pub torque_slot: usize,
    pub bounds: CounterweightBounds,
    /// Centroidal inertia of a 1 kg counterweight (`J(m) = m^{5/3} J1`).
    pub j1: Matrix3<f64>,
}

impl CwSlot {
    pub fn min_mass(&self) -> f64 {
        self.bounds.mass[0].max(MIN_MASS_FRACTION * self.bounds.mass[1].max(1.0))
    }
}

/// A spring of the variant.
#[derive(Clone, Debug)]
pub struct SpringSlot {
    pub entry: usize,
    pub label: String,
    pub body: usize,
    pub other: Attachment,
    /// The names of `body` and `other` (`base` for the ground), as the spring's physical
    /// parameters name them.
    pub bodies: [String; 2],
    pub axes_a: Vec<usize>,
    pub axes_b: Vec<usize>,
    pub column: usize,
    pub bounds: SpringBounds,
}

impl SpringSlot {
    /// Number of lifted variables.
    pub fn lifted_len(&self) -> usize {
        let (na, nb) = (self.axes_a.len(), self.axes_b.len());
        1 + na + nb + na * nb
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CwPhysical {
    pub mass: f64,
    pub mu: [f64; 3],
}

impl CwPhysical {
    pub fn offset(&self) -> [f64; 3] {
        self.mu.map(|v| v / self.mass)
    }
    pub fn radius(&self) -> f64 {
        norm(&self.mu) / self.mass
    }
}

pub fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}
