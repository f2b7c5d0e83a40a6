//! The per-sample dynamics kernel shared by the fast grid path: body wrenches computed
//! directly from each parameter column (no explicit regressor), generalized forces, actuator
//! forces and the reaction right-hand sides.
//!
//! For few parameter columns this is cheaper than forming `Y` and multiplying; it computes the
//! same Newton–Euler expressions as [`crate::regressor`] (the tests compare the two paths).

use counterpoise_symbolic::MAX_VARS;
use nalgebra::{Matrix3, Vector3};

use crate::lu::SmallLu;
use crate::mechanism::{BodyKin, Mechanism};
use crate::params::{BODY_PARAMS, ParameterSet, SPRING_PARAMS};
use crate::regressor::{WrenchRegressor, spring_wrenches};

/// Symmetric inertia from `[Ixx, Iyy, Izz, Ixy, Ixz, Iyz]`.
#[inline]
fn inertia(p: &[f64]) -> Matrix3<f64> {
    Matrix3::new(p[0], p[3], p[4], p[3], p[1], p[5], p[4], p[5], p[2])
}

/// The wrench `(F, N_o)` the world must apply to a body with parameters `pi` (see
/// [`crate::regressor`]), world axes, moment about the body frame origin.
#[inline]
pub fn body_wrench(k: &BodyKin, pi: &[f64], g: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let m = pi[0];
    let h = k.r * Vector3::new(pi[1], pi[2], pi[3]);
    let at = k.a - g;
    let force = at * m + k.alpha.cross(&h) + k.w.cross(&k.w.cross(&h));
    let wb = k.r.tr_mul(&k.w);
    let ab = k.r.tr_mul(&k.alpha);
    let io = inertia(&pi[4..BODY_PARAMS]);
    let nb = io * ab + wb.cross(&(io * wb));
    let moment = h.cross(&at) + k.r * nb;
    (force, moment)
}

/// Required wrenches of every body (inertial minus spring forces) for one column, into `w`
/// (`6L`, `[F; N]` per body).
pub fn required_wrenches(
    mech: &Mechanism,
    pose: &[f64],
    kin: &[BodyKin],
    params: &ParameterSet,
    column: usize,
    w: &mut [f64],
) {
    let col = params.column(column);
    let l = kin.len();
    for (i, k) in kin.iter().enumerate() {
        let (f, n) = body_wrench(
            k,
            &col[BODY_PARAMS * i..BODY_PARAMS * (i + 1)],
            &mech.gravity,
        );
        w[6 * i..6 * i + 3].copy_from_slice(f.as_slice());
        w[6 * i + 3..6 * i + 6].copy_from_slice(n.as_slice());
    }
    for (s, slot) in params.springs.iter().enumerate() {
        let off = BODY_PARAMS * l + SPRING_PARAMS * s;
        let x = &col[off..off + SPRING_PARAMS];
        if x.iter().all(|&v| v == 0.0) {
            continue;
        }
        let (fi, ni, fs, ns) = spring_wrenches(mech, pose, slot, x);
        for r in 0..3 {
            w[6 * slot.body + r] -= fi[r];
            w[6 * slot.body + 3 + r] -= ni[r];
            if let Some(o) = slot.other {
                w[6 * o + r] -= fs[r];
                w[6 * o + 3 + r] -= ns[r];
            }
        }
    }
}

/// Like [`required_wrenches`] from precomputed wrench regressors of the bodies (cheaper when
/// many columns share one motion): `w_i = W_i π_i` minus spring forces.
pub fn required_wrenches_with(
    mech: &Mechanism,
    pose: &[f64],
    regressors: &[WrenchRegressor],
    params: &ParameterSet,
    column: usize,
    w: &mut [f64],
) {
    let col = params.column(column);
    let l = regressors.len();
    for (i, reg) in regressors.iter().enumerate() {
        let pi = &col[BODY_PARAMS * i..BODY_PARAMS * (i + 1)];
        for r in 0..6 {
            let mut acc = 0.0;
            for c in 0..BODY_PARAMS {
                acc += reg[r][c] * pi[c];
            }
            w[6 * i + r] = acc;
        }
    }
    for (s, slot) in params.springs.iter().enumerate() {
        let off = BODY_PARAMS * l + SPRING_PARAMS * s;
        let x = &col[off..off + SPRING_PARAMS];
        if x.iter().all(|&v| v == 0.0) {
            continue;
        }
        let (fi, ni, fs, ns) = spring_wrenches(mech, pose, slot, x);
        for r in 0..3 {
            w[6 * slot.body + r] -= fi[r];
            w[6 * slot.body + 3 + r] -= ni[r];
            if let Some(o) = slot.other {
                w[6 * o + r] -= fs[r];
                w[6 * o + 3 + r] -= ns[r];
            }
        }
    }
}

/// `Q_q = Σ_i J_v,iᵀ F_i + J_ω,iᵀ N_i`, then `Q_u = G⁻ᵀ Q_q` (returned).
pub fn actuator_forces(kin: &[BodyKin], w: &[f64], n: usize, lu: &SmallLu) -> [f64; MAX_VARS] {
    let mut q = [0.0; MAX_VARS];
    for (i, k) in kin.iter().enumerate() {
        let f = Vector3::new(w[6 * i], w[6 * i + 1], w[6 * i + 2]);
        let m = Vector3::new(w[6 * i + 3], w[6 * i + 4], w[6 * i + 5]);
        for j in 0..n {
            q[j] += k.jv[j].dot(&f) + k.jw[j].dot(&m);
        }
    }
    lu.solve_transpose(&mut q);
    q
}
