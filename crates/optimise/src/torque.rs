//! Motor torques of a balanced variant on selected tasks, as an affine function of the
//! counterweights' lifted inertial parameters.
//!
//! Once a variant is balanced its total potential energy is constant, so gravity and springs
//! cancel exactly and the motor torque is inertial only (docs/design.md §3): `τ(t) = τ₀(t) + Σ_c Y_c(t) π_c`
//! where `τ₀` is the inertial torque of the bodies and all payloads and `π_c` the 10 lifted
//! parameters `(m, m·r, I_o)` of counterweight `c` on its body. The inertial parts come from the
//! dynamics crate's evaluator on a *gravity-free* copy of the model; payloads that the balance
//! leaves out (`in_balance: false`) keep their static torque, added from the full model. Unit
//! parameter columns give `Y_c` exactly (the torque is linear and homogeneous in `π`), so one
//! move run per task serves every variant.

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};

use counterpoise_dynamics::params::{BODY_PARAMS, ParameterSet, body_params, model_body_params};
use counterpoise_dynamics::runner::Workspace;
use counterpoise_dynamics::{Evaluator, TaskSet};
use counterpoise_model::Model;
use rayon::prelude::*;

/// Torques of one task: `samples × actuators`, row-major per sample.
#[derive(Clone, Debug)]
pub struct TaskTorques {
    pub task: usize,
    pub samples: usize,
    pub actuators: usize,
    /// `τ₀`.
    pub base: Vec<f64>,
    /// Per counterweight-capable body slot and lifted parameter `j` (0..10): torque per unit.
    pub sensitivity: Vec<Vec<f64>>,
}

impl TaskTorques {
    pub fn sens(&self, slot: usize, j: usize) -> &[f64] {
        &self.sensitivity[slot * BODY_PARAMS + j]
    }
}

/// Lazily computed, shared torque bases of tasks.
pub struct TorqueCache {
    gravity_free: Model,
    /// Lifted parameters of payloads not in the balance (`None` when there are none).
    unbalanced_payloads: Option<Vec<f64>>,
    /// Bodies that may carry a counterweight (slot order).
    pub bodies: Vec<usize>,
    cache: Mutex<BTreeMap<usize, Arc<TaskTorques>>>,
}

impl TorqueCache {
    pub fn new(model: &Model, bodies: Vec<usize>) -> TorqueCache {
        let mut gravity_free = model.clone();
        gravity_free.gravity = nalgebra::Vector3::zeros();
        let l = model.bodies.len();
        let mut nib = vec![0.0; BODY_PARAMS * l];
        let mut any = false;
        for p in model.payloads.iter().filter(|p| !p.in_balance) {
            any = true;
            let add = body_params(p.mass, &p.com, &p.inertia_com);
            for (x, y) in nib[BODY_PARAMS * p.body..].iter_mut().zip(add) {
                *x += y;
            }
        }
        TorqueCache {
            gravity_free,
            unbalanced_payloads: any.then_some(nib),
            bodies,
            cache: Mutex::new(BTreeMap::new()),
        }
    }

    pub fn slot_of(&self, body: usize) -> Option<usize> {
        self.bodies.iter().position(|&b| b == body)
    }

    /// The torques of the given tasks, computing (in parallel) those not cached yet. Tasks
    /// whose kinematics fail are left out of the returned list, with their failure.
    pub fn get(
        &self,
        model: &Model,
        tasks: &TaskSet,
        wanted: &[usize],
    ) -> (Vec<Arc<TaskTorques>>, Vec<(usize, String)>) {
        let missing: Vec<usize> = {
            let cache = self.cache.lock().expect("torque cache poisoned");
            let mut m: Vec<usize> = wanted
                .iter()
                .copied()
                .filter(|w| !cache.contains_key(w))
                .collect();
            m.sort_unstable();
            m.dedup();
            m
        };
        let mut failures = Vec::new();
        if !missing.is_empty() {
            let computed = self.compute(model, tasks, &missing);
            let mut cache = self.cache.lock().expect("torque cache poisoned");
            for (w, r) in missing.iter().zip(computed) {
                match r {
                    Ok(t) => {
                        cache.insert(*w, Arc::new(t));
                    }
                    Err(e) => failures.push((*w, e)),
                }
            }
        }
        let cache = self.cache.lock().expect("torque cache poisoned");
        let found = wanted
            .iter()
            .filter_map(|w| cache.get(w).cloned())
            .collect();
        (found, failures)
    }

    fn compute(
        &self,
        model: &Model,
        tasks: &TaskSet,
        which: &[usize],
    ) -> Vec<Result<TaskTorques, String>> {
        let l = model.bodies.len();
        let (ev0, ev) = match (Evaluator::new(&self.gravity_free), Evaluator::new(model)) {
            (Ok(a), Ok(b)) => (a, b),
            (Err(e), _) | (_, Err(e)) => return which.iter().map(|_| Err(e.to_string())).collect(),
        };
        let mut params = ParameterSet::empty(l, Vec::new());
        params
            .push_column(&model_body_params(model))
            .expect("column length");
        if let Some(nib) = &self.unbalanced_payloads {
            params.push_column(nib).expect("column length");
        }
        let first_unit = params.len();
        for &b in &self.bodies {
            for j in 0..BODY_PARAMS {
                let mut col = vec![0.0; BODY_PARAMS * l];
                col[BODY_PARAMS * b + j] = 1.0;
                params.push_column(&col).expect("column length");
            }
        }
        let mut nib_only = ParameterSet::empty(l, Vec::new());
        if let Some(nib) = &self.unbalanced_payloads {
            nib_only.push_column(nib).expect("column length");
        }
        let columns: Vec<usize> = (0..params.len()).collect();
        let na = model.actuators.len();
        which
            .par_iter()
            .map_init(Workspace::default, |ws, &w| {
                let (i, j) = tasks.pair(w);
                let q0 = ev0
                    .solve_point(&tasks.points[i])
                    .map_err(|e| format!("{e:?}"))?;
                let k = tasks.samples;
                let mut base = vec![0.0; k * na];
                let mut sensitivity = vec![vec![0.0; k * na]; self.bodies.len() * BODY_PARAMS];
                let mut q = q0.clone();
                ev0.run_move(
                    &tasks.points[i],
                    &tasks.points[j],
                    tasks.duration,
                    k,
                    &mut q,
                    &params,
                    &columns,
                    false,
                    ws,
                    |s, view| {
                        for a in 0..na {
                            base[s * na + a] = view.motor_torque[0][a];
                            if self.unbalanced_payloads.is_some() {
                                // remove the inertial part counted twice below
                                base[s * na + a] -= view.motor_torque[1][a];
                            }
                            for (c, sens) in sensitivity.iter_mut().enumerate() {
                                sens[s * na + a] = view.motor_torque[first_unit + c][a];
                            }
                        }
                    },
                )
                .map_err(|(s, e)| format!("sample {s}: {e:?}"))?;
                if self.unbalanced_payloads.is_some() {
                    // full-gravity torque of the unbalanced payloads (inertial + static)
                    let mut q = q0;
                    ev.run_move(
                        &tasks.points[i],
                        &tasks.points[j],
                        tasks.duration,
                        k,
                        &mut q,
                        &nib_only,
                        &[0],
                        false,
                        ws,
                        |s, view| {
                            for a in 0..na {
                                base[s * na + a] += view.motor_torque[0][a];
                            }
                        },
                    )
                    .map_err(|(s, e)| format!("sample {s}: {e:?}"))?;
                }
                Ok(TaskTorques {
                    task: w,
                    samples: k,
                    actuators: na,
                    base,
                    sensitivity,
                })
            })
            .collect()
    }
}
