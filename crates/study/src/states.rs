//! `counterpoise evaluate CASE --states FILE`: inverse dynamics of the unbalanced mechanism at
//! given states, so a user can compare the model with their own dynamics library.
//!
//! Per state `(q, q̇, q̈)` (chart coordinates): every body (with the payloads it carries) needs
//! the world wrench `F = m(a_c − g)`, `N_o = R I_c Rᵀ α + ω × (R I_c Rᵀ ω) + r_c × F` about its
//! frame origin; the generalized forces are `Q_q = Σ J_vᵀ F + J_ωᵀ N_o`, the actuator forces
//! `Q_u = G⁻ᵀ Q_q` (`G = ∂u/∂q`) and the motor torques `ratio · Q_u`. The potential energy is
//! `V = −Σ m g·(p + R c)`. Written by Newton–Euler from the model's kinematics, independently of
//! the task evaluator.

use std::path::Path;

use crate::error::{Result, StudyError, invalid};
use counterpoise_model::{Kinematics, Model};
use nalgebra::{DVector, Matrix3, Vector3};
use serde::Deserialize;
use serde_json::json;

/// One state of the states file.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct State {
    q: Vec<f64>,
    /// Default zeros.
    #[serde(default)]
    qd: Option<Vec<f64>>,
    /// Default zeros.
    #[serde(default)]
    qdd: Option<Vec<f64>>,
}

/// Mass, centre of mass and inertia about it (body axes) of one body and its payloads.
fn lumped(model: &Model, body: usize) -> (f64, Vector3<f64>, Matrix3<f64>) {
    let b = &model.bodies[body];
    let mut parts = vec![(b.mass, b.com, b.inertia_com)];
    for p in model.payloads.iter().filter(|p| p.body == body) {
        parts.push((p.mass, p.com, p.inertia_com));
    }
    let mass: f64 = parts.iter().map(|p| p.0).sum();
    if mass == 0.0 {
        return (0.0, Vector3::zeros(), Matrix3::zeros());
    }
    let com = parts
        .iter()
        .fold(Vector3::zeros(), |a, (m, c, _)| a + c * *m)
        / mass;
    let inertia = parts.iter().fold(Matrix3::zeros(), |a, (m, c, i)| {
        let d = c - com;
        a + i + (Matrix3::identity() * d.norm_squared() - d * d.transpose()) * *m
    });
    (mass, com, inertia)
}

/// Inverse dynamics of `model` at the states in the file `states`, as the JSON document
/// `counterpoise evaluate --states` prints.
pub fn states_json(model: &Model, states: &Path) -> Result<String> {
    let text = std::fs::read_to_string(states)
        .map_err(|e| StudyError::io(format!("cannot read {}", states.display()), e))?;
    let list: Vec<State> = serde_json::from_str(&text).map_err(|e| {
        StudyError::Invalid(format!(
            "{}: expected a JSON array of {{\"q\": [..], \"qd\": [..], \"qdd\": [..]}}: {e}",
            states.display()
        ))
    })?;
    let n = model.coordinates.len();
    let kin = Kinematics::new(model);
    let lumps: Vec<_> = (0..model.bodies.len()).map(|b| lumped(model, b)).collect();
    let g = model.gravity;
    let mut out = Vec::with_capacity(list.len());
    for (s, state) in list.iter().enumerate() {
        let vector = |field: &str, v: &Option<Vec<f64>>| -> Result<DVector<f64>> {
            let v = v.clone().unwrap_or_else(|| vec![0.0; n]);
            if v.len() != n {
                invalid!(
                    "{}: states[{s}].{field}: {} values for {n} coordinates",
                    states.display(),
                    v.len()
                );
            }
            if let Some(bad) = v.iter().find(|x| !x.is_finite()) {
                invalid!(
                    "{}: states[{s}].{field}: {bad} is not finite",
                    states.display()
                );
            }
            Ok(DVector::from_vec(v))
        };
        let q = vector("q", &Some(state.q.clone()))?;
        let qd = vector("qd", &state.qd)?;
        let qdd = vector("qdd", &state.qdd)?;
        let motions = kin.body_motions(&q, &qd, &qdd);
        let mut generalized = DVector::zeros(n);
        let mut potential = 0.0;
        for (b, (motion, &(m, c, ic))) in motions.iter().zip(&lumps).enumerate() {
            if m == 0.0 {
                continue;
            }
            let r = motion.rotation;
            let rc = r * c;
            let w = motion.angular_velocity;
            let alpha = motion.angular_acceleration;
            let acc_c = motion.acceleration + alpha.cross(&rc) + w.cross(&w.cross(&rc));
            let force = (acc_c - g) * m;
            let iw = r * ic * r.transpose();
            let moment = iw * alpha + w.cross(&(iw * w)) + rc.cross(&force);
            let jac = kin.body_jacobian(b, &q);
            generalized += jac.linear.transpose() * force + jac.angular.transpose() * moment;
            potential -= m * g.dot(&(motion.position + rc));
        }
        let jacobian = kin.actuator_jacobian(&q);
        let Some(forces) = jacobian.transpose().lu().solve(&generalized) else {
            invalid!(
                "{}: states[{s}]: the actuator Jacobian is singular at this q",
                states.display()
            );
        };
        let torques: Vec<f64> = forces
            .iter()
            .zip(&model.actuators)
            .map(|(f, a)| f * a.ratio)
            .collect();
        out.push(json!({
            "q": q.as_slice(),
            "qd": qd.as_slice(),
            "qdd": qdd.as_slice(),
            "u": kin.actuator_values(&q).as_slice(),
            "actuator_forces": forces.as_slice(),
            "motor_torques": torques,
            "potential_energy": potential,
        }));
    }
    let doc = json!({
        "case": model.name,
        "coordinates": model.coordinates.iter().map(|c| &c.name).collect::<Vec<_>>(),
        "actuators": model.actuators.iter().map(|a| &a.name).collect::<Vec<_>>(),
        "states": out,
    });
    Ok(format!("{}\n", serde_json::to_string_pretty(&doc)?))
}
