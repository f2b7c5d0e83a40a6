//! Static gravity torques over a sampled workspace, linear in the lifted parameters.
//!
//! The total potential energy is `V(q) = V_UB(q) + Σ_e x_eᵀ φ_e(q)` (see [`crate::element`]).
//! At rest the actuators hold the mechanism with the generalized forces `Q_q = ∂V/∂q` on the
//! chart coordinates, that is `Q_u = G⁻ᵀ ∂V/∂q` on the actuated coordinates (`G = ∂u/∂q`, before
//! the motor ratio). Both are linear in `x`: per sample point, `τ(x) = τ_UB + Σ_e T_e x_e`, with
//! `T_e` the gradients of the element's energy polynomials mapped through `G⁻ᵀ`. They are
//! computed once per element from the same polynomials the balance search uses, so a set that
//! balances exactly has zero torque here too.

use counterpoise_model::{Kinematics, Model};
use counterpoise_symbolic::{Point, TrigPoly, VarKind};
use nalgebra::DVector;
use rayon::prelude::*;

use crate::element::Catalogue;
use crate::energy::MechanismEnergy;

/// The sample points of the workspace, in chart coordinates, with the map from chart
/// generalized forces to actuator forces at each.
#[derive(Clone, Debug)]
pub struct Workspace {
    /// Chart configurations `q`.
    pub points: Vec<Vec<f64>>,
    /// Per point, `G⁻ᵀ` row-major (actuators × coordinates).
    pub to_actuator: Vec<Vec<f64>>,
    pub actuators: usize,
    pub coordinates: usize,
    /// Points left out because `G` is singular (or not finite) there.
    pub singular: usize,
}

/// `G` is taken as singular when its condition number (in the max-abs-entry sense of LU
/// pivots) exceeds this: a static torque through it would mean nothing.
const MAX_PIVOT_RATIO: f64 = 1e12;

impl Workspace {
    /// The workspace of `configurations` (chart coordinates) of `model`; points where the
    /// actuator Jacobian is singular are dropped and counted.
    pub fn new(model: &Model, configurations: &[Vec<f64>]) -> Workspace {
        let kin = Kinematics::new(model);
        let n = model.coordinates.len();
        let a = model.actuators.len();
        let mut points = Vec::new();
        let mut to_actuator = Vec::new();
        let mut singular = 0;
        for q in configurations {
            let g = kin.actuator_jacobian(&DVector::from_column_slice(q));
            if !g.iter().all(|v| v.is_finite()) {
                singular += 1;
                continue;
            }
            // Q_q = Gᵀ Q_u, so Q_u = (Gᵀ)⁻¹ Q_q: (Gᵀ)⁻¹ is actuators × coordinates.
            let lu = g.transpose().full_piv_lu();
            let diag: Vec<f64> = (0..n.min(a)).map(|i| lu.u()[(i, i)].abs()).collect();
            let (hi, lo) = diag
                .iter()
                .fold((0.0f64, f64::INFINITY), |(h, l), &d| (h.max(d), l.min(d)));
            let inverse = if a == n && lo > 0.0 && hi / lo < MAX_PIVOT_RATIO {
                lu.try_inverse()
            } else {
                None
            };
            match inverse {
                Some(inv) if inv.iter().all(|v| v.is_finite()) => {
                    let mut row_major = Vec::with_capacity(a * n);
                    for j in 0..a {
                        for c in 0..n {
                            row_major.push(inv[(j, c)]);
                        }
                    }
                    points.push(q.clone());
                    to_actuator.push(row_major);
                }
                _ => singular += 1,
            }
        }
        Workspace {
            points,
            to_actuator,
            actuators: a,
            coordinates: n,
            singular,
        }
    }

    pub fn len(&self) -> usize {
        self.points.len()
    }

    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }
}

/// Actuator torques per unit of every lifted variable, and of the unbalanced mechanism, at every
/// workspace point. Layout: a column per variable, `point · actuators + actuator` within it.
#[derive(Clone, Debug)]
pub struct TorqueBasis {
    pub points: usize,
    pub actuators: usize,
    /// `τ_UB` (N·m or N).
    pub unbalanced: Vec<f64>,
    /// Per catalogue entry, one column per lifted variable (empty for entries not built).
    pub entries: Vec<Vec<Vec<f64>>>,
}

/// The actuator torques of `poly`'s gradient at every workspace point.
fn torque_column(
    poly: &TrigPoly,
    kinds: &[VarKind],
    workspace: &Workspace,
    points: &[Point],
) -> Vec<f64> {
    let n = workspace.coordinates;
    let a = workspace.actuators;
    let gradient: Vec<TrigPoly> = (0..n).map(|c| poly.derivative(c, kinds[c])).collect();
    let mut column = vec![0.0; workspace.len() * a];
    let mut grad = vec![0.0; n];
    for (k, at) in points.iter().enumerate() {
        for (c, d) in gradient.iter().enumerate() {
            grad[c] = if d.is_zero() { 0.0 } else { d.eval(at) };
        }
        let map = &workspace.to_actuator[k];
        for j in 0..a {
            column[k * a + j] = (0..n).map(|c| map[j * n + c] * grad[c]).sum();
        }
    }
    column
}

impl TorqueBasis {
    /// The torque columns of the unbalanced mechanism and of the catalogue entries `wanted`
    /// (the others stay empty), in parallel over the variables; deterministic.
    pub fn build(
        energy: &MechanismEnergy,
        catalogue: &Catalogue,
        workspace: &Workspace,
        wanted: &[usize],
    ) -> TorqueBasis {
        let kinds = &energy.kinds;
        let points: Vec<Point> = workspace
            .points
            .iter()
            .map(|q| Point::new(q, kinds))
            .collect();
        let unbalanced = torque_column(&energy.unbalanced, kinds, workspace, &points);
        let jobs: Vec<(usize, usize)> = wanted
            .iter()
            .flat_map(|&e| (0..catalogue.entries[e].energy.len()).map(move |v| (e, v)))
            .collect();
        let columns: Vec<Vec<f64>> = jobs
            .par_iter()
            .map(|&(e, v)| {
                torque_column(&catalogue.entries[e].energy[v], kinds, workspace, &points)
            })
            .collect();
        let mut entries = vec![Vec::new(); catalogue.len()];
        for ((e, _), column) in jobs.into_iter().zip(columns) {
            entries[e].push(column);
        }
        TorqueBasis {
            points: workspace.len(),
            actuators: workspace.actuators,
            unbalanced,
            entries,
        }
    }

    /// RMS over the points of each actuator's torque `τ_UB + Σ columns·x`.
    pub fn rms(&self, columns: &[&[f64]], x: &[f64]) -> Vec<f64> {
        let a = self.actuators;
        let mut sum = vec![0.0; a];
        for k in 0..self.points {
            for (j, s) in sum.iter_mut().enumerate() {
                let row = k * a + j;
                let t = self.unbalanced[row]
                    + columns
                        .iter()
                        .zip(x)
                        .map(|(c, xi)| c[row] * xi)
                        .sum::<f64>();
                *s += t * t;
            }
        }
        let p = self.points.max(1) as f64;
        sum.into_iter().map(|s| (s / p).sqrt()).collect()
    }
}
