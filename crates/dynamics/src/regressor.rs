//! The dynamics regressor: generalized forces and body wrenches linear in the lifted
//! parameters (see [`crate::params`]).
//!
//! Newton–Euler about the body frame origin `o` (world axes), with `ã = a − g`:
//!
//! `F = m ã + α×(R h) + ω×(ω×(R h))`,
//! `N_o = (R h)×ã + R (I_o α_b + ω_b × I_o ω_b)` with `α_b = Rᵀα`, `ω_b = Rᵀω`.
//!
//! This is the wrench the rest of the world must apply to the body (gravity moved to the
//! left-hand side). The chart generalized force is `Q_q = Σ_i J_v,iᵀ F_i + J_ω,iᵀ N_i`, linear
//! in every `π_i`: one `n × 10` block per body. Springs add `∂V/∂q` (static, massless).

use counterpoise_symbolic::MAX_VARS;
use nalgebra::{Matrix3, Vector3};

use crate::mechanism::{BodyKin, Mechanism, skew};
use crate::params::{BODY_PARAMS, SPRING_PARAMS, SpringSlot};
use counterpoise_model::BodyId;

/// `6 × 10` wrench regressor of one body: rows `[F; N_o]`, columns `π`.
pub type WrenchRegressor = [[f64; BODY_PARAMS]; 6];

/// `L(v)` with `I v = L(v) [Ixx, Iyy, Izz, Ixy, Ixz, Iyz]`.
#[inline]
fn inertia_lin(v: &Vector3<f64>) -> [[f64; 6]; 3] {
    [
        [v.x, 0.0, 0.0, v.y, v.z, 0.0],
        [0.0, v.y, 0.0, v.x, 0.0, v.z],
        [0.0, 0.0, v.z, 0.0, v.x, v.y],
    ]
}

/// The wrench regressor of a body in the given motion under gravity `g`.
pub fn wrench_regressor(k: &BodyKin, g: &Vector3<f64>) -> WrenchRegressor {
    let mut w = [[0.0; BODY_PARAMS]; 6];
    let at = k.a - g;
    let wx = skew(&k.w);
    let kf = (skew(&k.alpha) + wx * wx) * k.r;
    let kn = -skew(&at) * k.r;
    let wb = k.r.transpose() * k.w;
    let ab = k.r.transpose() * k.alpha;
    let la = inertia_lin(&ab);
    let lw = inertia_lin(&wb);
    // body-frame inertial moment map: L(α_b) + ω_b× L(ω_b)
    let mut lb = [[0.0; 6]; 3];
    for c in 0..6 {
        let col = Vector3::new(lw[0][c], lw[1][c], lw[2][c]);
        let cr = wb.cross(&col);
        for r in 0..3 {
            lb[r][c] = la[r][c] + cr[r];
        }
    }
    for r in 0..3 {
        w[r][0] = at[r];
        for c in 0..3 {
            w[r][1 + c] = kf[(r, c)];
            w[3 + r][1 + c] = kn[(r, c)];
        }
        for c in 0..6 {
            w[3 + r][4 + c] = (0..3).map(|s| k.r[(r, s)] * lb[s][c]).sum();
        }
    }
    w
}

/// `Y_i = J_vᵀ W_F + J_ωᵀ W_N` (`n × 10`, row-major into `out`).
pub fn body_regressor(k: &BodyKin, w: &WrenchRegressor, n: usize, out: &mut [f64]) {
    for q in 0..n {
        let jv = k.jv[q];
        let jw = k.jw[q];
        for c in 0..BODY_PARAMS {
            out[q * BODY_PARAMS + c] = jv.x * w[0][c]
                + jv.y * w[1][c]
                + jv.z * w[2][c]
                + jw.x * w[3][c]
                + jw.y * w[4][c]
                + jw.z * w[5][c];
        }
    }
}

/// The spring part of the generalized-force regressor, `∂V/∂q_k` per lifted parameter, for a
/// slot, from
/// `V = (K/2)|Δp|² + αᵀR_iᵀΔp − βᵀR_sᵀΔp − ⟨W, R_iᵀR_s⟩` (+ const), `Δp = p_i − p_s`.
/// `out` is `n × 16` row-major.
pub fn spring_regressor(mech: &Mechanism, pose: &[f64], slot: &SpringSlot, out: &mut [f64]) {
    let n = mech.n;
    let (ri, pi) = mech.pose_of(pose, BodyId::Body(slot.body));
    let sid = slot.other.map_or(BodyId::Base, BodyId::Body);
    let (rs, ps) = mech.pose_of(pose, sid);
    let dp = pi - ps;
    for k in 0..n {
        let (rik, pik) = mech.pose_derivative(pose, BodyId::Body(slot.body), k);
        let (rsk, psk) = mech.pose_derivative(pose, sid, k);
        let dpk = pik - psk;
        let row = &mut out[k * SPRING_PARAMS..(k + 1) * SPRING_PARAMS];
        row[0] = dp.dot(&dpk);
        let ga = rik.transpose() * dp + ri.transpose() * dpk;
        let gb = -(rsk.transpose() * dp + rs.transpose() * dpk);
        let gw: Matrix3<f64> = -(rik.transpose() * rs + ri.transpose() * rsk);
        for j in 0..3 {
            row[1 + j] = ga[j];
            row[4 + j] = gb[j];
            for l in 0..3 {
                row[7 + 3 * j + l] = gw[(j, l)];
            }
        }
    }
}

/// The pose-dependent part of a spring slot's applied wrenches at one configuration: the two
/// frames, `Δp`, and the linear map from `W` to the moment of the coupling term. Computed once
/// per sample and slot, then applied to every column's lifted parameters
/// ([`SpringFrame::wrenches`]).
#[derive(Clone, Copy, Debug)]
pub struct SpringFrame {
    ri: Matrix3<f64>,
    rs: Matrix3<f64>,
    dp: Vector3<f64>,
    /// `c_k = Σ_jl cross[k][3j + l] W_jl`, the axial vector of `R_i W R_sᵀ − (R_i W R_sᵀ)ᵀ`.
    cross: [[f64; 9]; 3],
}

impl SpringFrame {
    pub fn new(mech: &Mechanism, pose: &[f64], slot: &SpringSlot) -> SpringFrame {
        let (ri, pi) = mech.pose_of(pose, BodyId::Body(slot.body));
        let (rs, ps) = mech.pose_of(pose, slot.other.map_or(BodyId::Base, BodyId::Body));
        // m_ab = Σ_jl R_i[a,j] W_jl R_s[b,l]; the axial vector is (m_12 − m_21, m_20 − m_02,
        // m_01 − m_10).
        let mut cross = [[0.0; 9]; 3];
        for (k, (a, b)) in [(1, 2), (2, 0), (0, 1)].into_iter().enumerate() {
            for j in 0..3 {
                for l in 0..3 {
                    cross[k][3 * j + l] = ri[(a, j)] * rs[(b, l)] - ri[(b, j)] * rs[(a, l)];
                }
            }
        }
        SpringFrame {
            ri,
            rs,
            dp: pi - ps,
            cross,
        }
    }

    /// Applied wrenches of the spring with lifted parameters `x` on its two bodies (world axes,
    /// moments about each body's frame origin): `(F_i, N_i, F_s, N_s)`.
    #[inline]
    pub fn wrenches(&self, x: &[f64]) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>, Vector3<f64>) {
        let k = x[0];
        let alpha = self.ri * Vector3::new(x[1], x[2], x[3]);
        let beta = self.rs * Vector3::new(x[4], x[5], x[6]);
        let w = &x[7..16];
        let axial = |row: &[f64; 9]| row.iter().zip(w).map(|(c, v)| c * v).sum::<f64>();
        let cross = Vector3::new(
            axial(&self.cross[0]),
            axial(&self.cross[1]),
            axial(&self.cross[2]),
        );
        let dp = self.dp;
        let kd = dp * k + alpha - beta;
        (-kd, -alpha.cross(&dp) + cross, kd, beta.cross(&dp) - cross)
    }
}

/// Applied wrenches of a spring with lifted parameters `x` on its two bodies (world axes,
/// moments about each body's frame origin): `(F_i, N_i, F_s, N_s)`.
pub fn spring_wrenches(
    mech: &Mechanism,
    pose: &[f64],
    slot: &SpringSlot,
    x: &[f64],
) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>, Vector3<f64>) {
    SpringFrame::new(mech, pose, slot).wrenches(x)
}

/// Per-sample regressor workspace: body kinematics and `Y` (`n × rows`, row-major).
#[derive(Clone, Debug, Default)]
pub struct SampleRegressor {
    pub kin: Vec<BodyKin>,
    pub wrench: Vec<WrenchRegressor>,
    /// `n × rows` row-major.
    pub y: Vec<f64>,
    block: Vec<f64>,
}

impl SampleRegressor {
    /// Fills the body kinematics, wrench regressors and `Y` for the sample whose poses are in
    /// `pose`.
    pub fn compute(
        &mut self,
        mech: &Mechanism,
        pose: &[f64],
        qd: &[f64],
        qdd: &[f64],
        springs: &[SpringSlot],
    ) {
        let n = mech.n;
        let l = mech.body_count;
        let rows = BODY_PARAMS * l + SPRING_PARAMS * springs.len();
        self.kin.clear();
        self.wrench.clear();
        self.y.resize(n * rows, 0.0);
        self.block.resize(n * SPRING_PARAMS.max(BODY_PARAMS), 0.0);
        for b in 0..l {
            let k = mech.body_kin(pose, b, qd, qdd);
            let w = wrench_regressor(&k, &mech.gravity);
            body_regressor(&k, &w, n, &mut self.block);
            for q in 0..n {
                self.y[q * rows + BODY_PARAMS * b..q * rows + BODY_PARAMS * (b + 1)]
                    .copy_from_slice(&self.block[q * BODY_PARAMS..(q + 1) * BODY_PARAMS]);
            }
            self.kin.push(k);
            self.wrench.push(w);
        }
        for (s, slot) in springs.iter().enumerate() {
            spring_regressor(mech, pose, slot, &mut self.block);
            let off = BODY_PARAMS * l + SPRING_PARAMS * s;
            for q in 0..n {
                self.y[q * rows + off..q * rows + off + SPRING_PARAMS]
                    .copy_from_slice(&self.block[q * SPRING_PARAMS..(q + 1) * SPRING_PARAMS]);
            }
        }
    }

    /// `Q_q = Y π` for one column into `out` (length n): the products summed in row order.
    ///
    /// A spring slot the column does not use (all its parameters zero) only adds zeros, which
    /// leave a non-zero sum's bits unchanged: it is skipped, so that a column costs the same
    /// in a batch whose columns use many slots (the spring choice evaluates the options of
    /// every run in one batch) as on its own. While the sum is still exactly zero every term is
    /// added, so even the sign of a zero is the same.
    pub fn generalized_force(&self, n: usize, column: &[f64], out: &mut [f64; MAX_VARS]) {
        let rows = column.len();
        let body_rows = (BODY_PARAMS * self.kin.len()).min(rows);
        let (body, springs) = column.split_at(body_rows);
        for q in 0..n {
            let row = &self.y[q * rows..q * rows + body_rows];
            out[q] = row.iter().zip(body).map(|(a, b)| a * b).sum();
        }
        for (s, x) in springs.chunks(SPRING_PARAMS).enumerate() {
            let used = x.iter().any(|&v| v != 0.0);
            let off = body_rows + s * SPRING_PARAMS;
            for q in 0..n {
                if used || out[q] == 0.0 {
                    let y = &self.y[q * rows + off..q * rows + off + x.len()];
                    for (a, b) in y.iter().zip(x) {
                        out[q] += a * b;
                    }
                }
            }
        }
    }
}
