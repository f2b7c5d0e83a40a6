//! Detection of a cyclic chart coordinate: one whose value changes nothing but the mechanism's
//! orientation about a gravity-parallel axis (the palletizer's θ1, the column rotation).
//!
//! Coordinate `c` is cyclic when
//! 1. it is an angle driven by exactly one actuator `a`, with `u_a = k·q_c + const` (`k ≠ 0`),
//!    and no other actuator depends on `q_c` — so `f(q) = u` splits into `q_c` from `u_a` and
//!    the other coordinates from the other actuators;
//! 2. shifting `q_c` by `δ` moves every body by one rigid motion `(W(δ), w(δ))` independent of
//!    the configuration: `R_i(q + δe_c) = W R_i(q)`, `p_i(q + δe_c) = W p_i(q) + w`;
//! 3. that motion leaves gravity and the base side of every joint to the base unchanged
//!    (`W g = g`, `W x + w = x` for the joint point, `W e = e` for its axis).
//!
//! Then kinetic and potential energy, the actuator map's Jacobian, and the joint reaction
//! magnitudes (world wrenches rotate by `W`, their norms do not change) are independent of
//! `q_c`: the dynamics depends on `q_c` only through `q̇_c`, `q̈_c`. Condition 2 is checked
//! numerically at several configurations and shifts (relative tolerance 1e-9), which is a
//! test, not a proof — the grid evaluation built on it is compared against the direct
//! evaluation in the tests. Springs to the base break condition 3 and disable the shortcut.

use counterpoise_model::{BodyId, Model};
use counterpoise_symbolic::VarKind;
use nalgebra::{Matrix3, Vector3};

use crate::mechanism::{Mechanism, Scratch};

/// A cyclic coordinate and its actuator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cyclic {
    pub coordinate: usize,
    pub actuator: usize,
    /// `k = ∂u_a/∂q_c`.
    pub scale: f64,
}

const TOL: f64 = 1e-9;

/// The first cyclic coordinate of the model, if any.
pub fn detect_cyclic(model: &Model, mech: &Mechanism) -> Option<Cyclic> {
    (0..mech.n).find_map(|c| check(model, mech, c))
}

fn check(model: &Model, mech: &Mechanism, c: usize) -> Option<Cyclic> {
    if mech.kinds[c] != VarKind::Angle {
        return None;
    }
    let depends = |a: usize| {
        let map = &model.actuators[a].coordinate;
        map.linear.iter().any(|&(k, v)| k == c && v != 0.0) || map.poly.variables().contains(&c)
    };
    let drivers: Vec<usize> = (0..model.actuators.len()).filter(|&a| depends(a)).collect();
    let [a] = drivers[..] else { return None };
    let map = &model.actuators[a].coordinate;
    if !map.poly.variables().is_empty() || map.linear.len() != 1 || map.linear[0].0 != c {
        return None;
    }
    let scale = map.linear[0].1;
    let mut rng = counterpoise_model::sampling::SplitMix64::new(0x6379_636c_6963);
    let mut scratch = Scratch::default();
    for delta in [0.37, -1.1, 2.3] {
        let mut reference: Option<(Matrix3<f64>, Vector3<f64>)> = None;
        for _ in 0..3 {
            let q: Vec<f64> = mech
                .ranges
                .iter()
                .map(|r| rng.uniform(r[0], r[1]))
                .collect();
            let mut shifted = q.clone();
            shifted[c] += delta;
            mech.eval_poses(&q, &mut scratch);
            let before: Vec<_> = (0..mech.body_count)
                .map(|b| mech.pose_of(&scratch.pose, BodyId::Body(b)))
                .collect();
            mech.eval_poses(&shifted, &mut scratch);
            let after: Vec<_> = (0..mech.body_count)
                .map(|b| mech.pose_of(&scratch.pose, BodyId::Body(b)))
                .collect();
            let scale_p = before.iter().fold(1.0f64, |m, (_, p)| m.max(p.norm()));
            let (w_rot, w_tr) = match reference {
                Some(r) => r,
                None => {
                    let (r0, p0) = before.first().copied()?;
                    let (r1, p1) = after[0];
                    let w = r1 * r0.transpose();
                    let r = (w, p1 - w * p0);
                    reference = Some(r);
                    r
                }
            };
            for ((r0, p0), (r1, p1)) in before.iter().zip(&after) {
                if (r1 - w_rot * r0).amax() > TOL || (p1 - w_rot * p0 - w_tr).amax() > TOL * scale_p
                {
                    return None;
                }
            }
            let g = mech.gravity;
            if (w_rot * g - g).amax() > TOL * g.norm().max(1.0) {
                return None;
            }
            for j in &model.joints {
                for side in 0..2 {
                    if j.bodies[side] != BodyId::Base {
                        continue;
                    }
                    let x = j.points[side];
                    if (w_rot * x + w_tr - x).amax() > TOL * scale_p {
                        return None;
                    }
                    if let Some(axes) = j.axes {
                        let e = axes[side];
                        if (w_rot * e - e).amax() > TOL {
                            return None;
                        }
                    }
                }
            }
        }
    }
    Some(Cyclic {
        coordinate: c,
        actuator: a,
        scale,
    })
}
