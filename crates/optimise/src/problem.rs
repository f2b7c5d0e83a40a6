//! One balanced variant as an optimisation problem over its balanced family.
//!
//! The balance search gives the lifted solution set `x = x_p + N z` (counterweight: `m`, `m·r`;
//! spring: `K`, `K·a`, `K·b`, `K·a_k·b_l`). Every candidate here is a point of that set, built
//! from `z` in floating point, so balance holds by construction to the accuracy of `x_p` and
//! `N`, whatever the optimiser does.
//!
//! The *true* objective on a set of tasks uses the physical parameters: `m`, `r = μ/m`, the
//! second moment `S = μμᵀ/m` and the cylinder's own inertia `J(m) = m^{5/3} J(1 kg)` — the same
//! `π = (m, m r, I_o)` the dynamics crate builds — and the task torques of [`crate::torque`].

use counterpoise_balance::linear::LinearSolution;
use counterpoise_balance::{Catalogue, Element};
use counterpoise_dynamics::params::{BODY_PARAMS, counterweight_inertia};
use counterpoise_model::Model;
use nalgebra::{DMatrix, DVector, Matrix3};
use serde::{Deserialize, Serialize};

use crate::overrides::BoundsTable;
pub use crate::slots::{CwPhysical, CwSlot, MIN_MASS_FRACTION, SpringSlot, norm};
use crate::torque::TaskTorques;

/// What is minimised.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Objective {
    /// Paper Eq. 11: quadratic mean over actuators of each actuator's RMS torque on its critical
    /// RMS task (over the working set: the largest RMS among its tasks).
    #[default]
    RmsStar,
    /// QTR (Eq. 1): the largest sum over actuators of the per-task RMS torque, over all tasks.
    Minimax,
}

/// A variant's balanced family with its elements and bounds.
#[derive(Clone, Debug)]
pub struct VariantProblem {
    pub set: Vec<usize>,
    pub labels: Vec<String>,
    pub counterweights: Vec<CwSlot>,
    pub springs: Vec<SpringSlot>,
    /// The family searched, `x = x_p + N z`: the balance search's family restricted by the
    /// anchors it fixes ([`crate::anchor_restriction`]); `solution` keeps the unrestricted one.
    pub particular: DVector<f64>,
    pub nullspace: DMatrix<f64>,
    pub solution: LinearSolution,
    /// Peak limit per actuator (N·m).
    pub peak_limits: Vec<Option<f64>>,
    pub actuators: usize,
}

/// Physical counterweight parameters derived from a lifted point.
/// Torque statistics of a point on a set of tasks.
#[derive(Clone, Debug)]
pub struct Evaluation {
    /// Per task (working-set order) and actuator: mean square torque.
    pub mean_square: Vec<Vec<f64>>,
    /// Per task and actuator: peak |τ|.
    pub peak: Vec<Vec<f64>>,
}

impl Evaluation {
    /// RMS* over these tasks: each actuator's largest RMS, then the quadratic mean.
    pub fn rms_star(&self, actuators: usize) -> f64 {
        let mut total = 0.0;
        for a in 0..actuators {
            let worst = self.mean_square.iter().map(|m| m[a]).fold(0.0, f64::max);
            total += worst;
        }
        (total / actuators.max(1) as f64).sqrt()
    }

    /// Largest per-task sum of actuator RMS (QTR over these tasks).
    pub fn qtr(&self) -> f64 {
        self.mean_square
            .iter()
            .map(|m| m.iter().map(|v| v.sqrt()).sum::<f64>())
            .fold(0.0, f64::max)
    }

    pub fn objective(&self, objective: Objective, actuators: usize) -> f64 {
        match objective {
            Objective::RmsStar => self.rms_star(actuators),
            Objective::Minimax => self.qtr(),
        }
    }
}

impl VariantProblem {
    pub fn new(
        model: &Model,
        catalogue: &Catalogue,
        bounds: &BoundsTable,
        set: &[usize],
        solution: LinearSolution,
        torque_slot: impl Fn(usize) -> Option<usize>,
    ) -> Result<VariantProblem, String> {
        let mut counterweights = Vec::new();
        let mut springs = Vec::new();
        let j1 = counterweight_inertia(model, 1.0);
        for (k, &e) in set.iter().enumerate() {
            let entry = &catalogue.entries[e];
            let column = solution.offsets[k];
            match &entry.element {
                Element::Counterweight { body, axes } => counterweights.push(CwSlot {
                    entry: e,
                    label: entry.label.clone(),
                    body: *body,
                    axes: axes.clone(),
                    column,
                    torque_slot: torque_slot(*body)
                        .ok_or_else(|| format!("{}: body has no torque slot", entry.label))?,
                    bounds: bounds.counterweight(e),
                    j1,
                }),
                Element::Spring {
                    body,
                    other,
                    axes_a,
                    axes_b,
                } => springs.push(SpringSlot {
                    entry: e,
                    label: entry.label.clone(),
                    body: *body,
                    other: *other,
                    bodies: [entry.bodies[0].clone(), entry.bodies[1].clone()],
                    axes_a: axes_a.clone(),
                    axes_b: axes_b.clone(),
                    column,
                    bounds: bounds.spring(e),
                }),
            }
        }
        let peak_limits = model
            .balancing
            .as_ref()
            .map(|b| b.peak_limits.clone())
            .unwrap_or_default();
        let mut peak_limits = peak_limits;
        peak_limits.resize(model.actuators.len(), None);
        // Search the family restricted by the anchors balance fixes (see `anchor_restriction`).
        let (particular, nullspace) = crate::anchor_restriction::restrict(
            &springs,
            &solution.particular,
            &solution.nullspace,
        )
        .unwrap_or_else(|| (solution.particular.clone(), solution.nullspace.clone()));
        Ok(VariantProblem {
            set: set.to_vec(),
            labels: set
                .iter()
                .map(|&e| catalogue.entries[e].label.clone())
                .collect(),
            counterweights,
            springs,
            particular,
            nullspace,
            solution,
            peak_limits,
            actuators: model.actuators.len(),
        })
    }

    pub fn dim(&self) -> usize {
        self.nullspace.ncols()
    }

    /// `x = x_p + N z`.
    pub fn lifted(&self, z: &DVector<f64>) -> DVector<f64> {
        &self.particular + &self.nullspace * z
    }

    pub fn cw_physical(&self, x: &DVector<f64>) -> Vec<CwPhysical> {
        self.counterweights
            .iter()
            .map(|c| {
                let mut mu = [0.0; 3];
                for (k, &a) in c.axes.iter().enumerate() {
                    mu[a] = x[c.column + 1 + k];
                }
                CwPhysical {
                    mass: x[c.column],
                    mu,
                }
            })
            .collect()
    }

    /// Rows of `x` that belong to counterweights.
    pub fn cw_rows(&self) -> Vec<usize> {
        self.counterweights
            .iter()
            .flat_map(|c| c.column..c.column + 1 + c.axes.len())
            .collect()
    }

    /// Torques on the tasks for physical counterweights (masses must be positive).
    pub fn evaluate(
        &self,
        cws: &[CwPhysical],
        tasks: &[std::sync::Arc<TaskTorques>],
    ) -> Evaluation {
        let params: Vec<([f64; BODY_PARAMS], usize)> = self
            .counterweights
            .iter()
            .zip(cws)
            .map(|(slot, p)| (lifted_body_params(slot, p), slot.torque_slot))
            .collect();
        let na = self.actuators;
        let mut mean_square = Vec::with_capacity(tasks.len());
        let mut peak = Vec::with_capacity(tasks.len());
        let mut tau = Vec::new();
        for t in tasks {
            tau.clear();
            tau.extend_from_slice(&t.base);
            for (pi, slot) in &params {
                for (j, &v) in pi.iter().enumerate() {
                    if v != 0.0 {
                        for (x, s) in tau.iter_mut().zip(t.sens(*slot, j)) {
                            *x += v * s;
                        }
                    }
                }
            }
            let mut ms = vec![0.0; na];
            let mut pk = vec![0.0f64; na];
            for s in 0..t.samples {
                for a in 0..na {
                    let v = tau[s * na + a];
                    ms[a] += v * v;
                    pk[a] = pk[a].max(v.abs());
                }
            }
            for v in &mut ms {
                *v /= t.samples as f64;
            }
            mean_square.push(ms);
            peak.push(pk);
        }
        Evaluation { mean_square, peak }
    }

    /// Largest peak excess over the limits, relative to each limit (≤ 0 when all are met).
    pub fn peak_excess(&self, e: &Evaluation) -> f64 {
        let mut worst = f64::NEG_INFINITY;
        for pk in &e.peak {
            for (a, lim) in self.peak_limits.iter().enumerate() {
                if let Some(lim) = lim {
                    worst = worst.max((pk[a] - lim) / lim);
                }
            }
        }
        worst
    }

    /// Relative violations of the convex lifted bounds at `x` (each ≤ 0 when met): masses,
    /// radii (both sides: `r_lo·m ≤ |μ| ≤ r_hi·m`), stiffnesses and the anchor upper bounds
    /// `|K a| ≤ a_hi K`, `|K b| ≤ b_hi K` (the anchor lower bounds are checked on the realized
    /// springs; so are the anchor boxes, which the relaxation meets only to its tolerance).
    pub fn bound_violations(&self, x: &DVector<f64>) -> Vec<f64> {
        let mut v = Vec::new();
        for c in &self.counterweights {
            let m = x[c.column];
            let [lo, hi] = c.bounds.mass;
            let scale = hi.max(1e-9);
            v.push((c.min_mass() - m) / scale);
            v.push((m - hi) / scale);
            let mu: Vec<f64> = (0..c.axes.len()).map(|k| x[c.column + 1 + k]).collect();
            let mu_n = norm(&mu);
            let [rlo, rhi] = c.bounds.radius;
            // Relative to the radius bound at this mass, as the final verification measures the
            // radius |μ|/m: at a small mass a violation that is tiny against `r_hi·m_hi` is a
            // large one of the radius.
            let rscale = (rhi * m.max(c.min_mass())).max(1e-9 * hi.max(1e-9));
            v.push((mu_n - rhi * m) / rscale);
            v.push((rlo * m - mu_n) / rscale);
            let _ = lo;
        }
        for s in &self.springs {
            let k = x[s.column];
            let [klo, khi] = s.bounds.stiffness;
            let kscale = khi.max(1e-9);
            v.push((klo - k) / kscale);
            v.push((k - khi) / kscale);
            let na = s.axes_a.len();
            let nb = s.axes_b.len();
            let alpha: Vec<f64> = (0..na).map(|i| x[s.column + 1 + i]).collect();
            let beta: Vec<f64> = (0..nb).map(|i| x[s.column + 1 + na + i]).collect();
            v.push(
                (norm(&alpha) - s.bounds.anchor_a[1] * k)
                    / (kscale * s.bounds.anchor_a[1].max(1e-3)),
            );
            v.push(
                (norm(&beta) - s.bounds.anchor_b[1] * k)
                    / (kscale * s.bounds.anchor_b[1].max(1e-3)),
            );
        }
        v
    }
}

/// `π = (m, μ, I_o)` with `I_o = J(m) + tr(S) I − S`, `S = μμᵀ/m` (body axes).
pub fn lifted_body_params(slot: &CwSlot, p: &CwPhysical) -> [f64; BODY_PARAMS] {
    let m = p.mass;
    let mu = nalgebra::Vector3::from(p.mu);
    let s = mu * mu.transpose() / m;
    let j = slot.j1 * m.powf(5.0 / 3.0);
    let io = j + Matrix3::identity() * s.trace() - s;
    [
        m,
        mu.x,
        mu.y,
        mu.z,
        io[(0, 0)],
        io[(1, 1)],
        io[(2, 2)],
        io[(0, 1)],
        io[(0, 2)],
        io[(1, 2)],
    ]
}
