//! The model compiled for the hot loop: body poses with their first and second partial
//! derivatives, and the actuator map with its Jacobian and second derivatives, each as one flat
//! [`PolyBank`]; plus the Newton solve of `f(q) = u`.
//!
//! Everything is derived from the symbolic poses of the model (one source of truth), exactly:
//! Jacobians are derivatives of the pose polynomials, not finite differences. Velocities and
//! accelerations of a body frame follow from
//! `ṗ = Σ p_k q̇_k`, `p̈ = Σ p_k q̈_k + Σ p_kl q̇_k q̇_l`, `[ω]× = Ṙ Rᵀ`, and
//! `[α]× = skew(R̈ Rᵀ)` (since `R̈Rᵀ = [α]× − ṘṘᵀ` and `ṘṘᵀ` is symmetric).

use counterpoise_model::{BodyId, Model};
use counterpoise_symbolic::{MAX_VARS, TrigPoly, VarKind};
use nalgebra::{Matrix3, Vector3};

use crate::compiled::{BankScratch, PolyBank};
use crate::error::{DynamicsError, FailureReason};
use crate::lu::SmallLu;

/// `G` counts as singular when the smallest pivot of its LU falls below this fraction of the
/// larger of its largest pivot and the typical size of `G` over the coordinate ranges (the
/// latter makes the test meaningful for a single actuator, where the pivot ratio is always 1).
pub const SINGULAR_PIVOT_RATIO: f64 = 1e-7;
/// Newton converged when `max |f(q) − u| ≤ NEWTON_TOLERANCE · (1 + max |u|)`.
pub const NEWTON_TOLERANCE: f64 = 1e-12;
const NEWTON_MAX_ITERATIONS: usize = 50;
/// Largest Newton step of an angle (rad): keeps the iteration on its assembly branch.
const MAX_ANGLE_STEP: f64 = 0.5;

/// Index of the unordered pair `(k, l)` in packed symmetric storage.
#[inline]
pub fn packed(k: usize, l: usize) -> usize {
    let (lo, hi) = if k <= l { (k, l) } else { (l, k) };
    hi * (hi + 1) / 2 + lo
}

/// `v` with `[v]× = (m − mᵀ)/2`.
#[inline]
pub fn vee(m: &Matrix3<f64>) -> Vector3<f64> {
    Vector3::new(
        m[(2, 1)] - m[(1, 2)],
        m[(0, 2)] - m[(2, 0)],
        m[(1, 0)] - m[(0, 1)],
    ) * 0.5
}

#[inline]
pub fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// Pose, Jacobians and motion of one body frame at a sample (world axes).
#[derive(Clone, Copy, Debug)]
pub struct BodyKin {
    pub r: Matrix3<f64>,
    pub p: Vector3<f64>,
    /// `∂p/∂q_k` (velocity Jacobian of the origin), `k < n`.
    pub jv: [Vector3<f64>; MAX_VARS],
    /// Angular velocity Jacobian, `vee(∂R/∂q_k Rᵀ)`.
    pub jw: [Vector3<f64>; MAX_VARS],
    pub v: Vector3<f64>,
    pub w: Vector3<f64>,
    pub a: Vector3<f64>,
    pub alpha: Vector3<f64>,
}

impl Default for BodyKin {
    fn default() -> Self {
        BodyKin {
            r: Matrix3::identity(),
            p: Vector3::zeros(),
            jv: [Vector3::zeros(); MAX_VARS],
            jw: [Vector3::zeros(); MAX_VARS],
            v: Vector3::zeros(),
            w: Vector3::zeros(),
            a: Vector3::zeros(),
            alpha: Vector3::zeros(),
        }
    }
}

/// Reusable buffers of one worker.
#[derive(Clone, Debug, Default)]
pub struct Scratch {
    pub bank: BankScratch,
    pub pose: Vec<f64>,
    act: Vec<f64>,
    act2: Vec<f64>,
}

/// The compiled mechanism.
#[derive(Clone, Debug)]
pub struct Mechanism {
    pub n: usize,
    pub kinds: Vec<VarKind>,
    pub coordinate_names: Vec<String>,
    pub ranges: Vec<[f64; 2]>,
    pub body_count: usize,
    pub gravity: Vector3<f64>,
    /// Per body `12·(1 + n + n(n+1)/2)` values: `[R (row-major), p]` then its `∂/∂q_k`, then
    /// its `∂²/∂q_k∂q_l` (packed).
    pose_bank: PolyBank,
    /// `f_a` polynomial parts (n), then `G` row-major (n·n).
    act_bank: PolyBank,
    act_linear: Vec<Vec<(usize, f64)>>,
    /// Per actuator, `∂²f_a/∂q_k∂q_l` packed.
    act2_bank: PolyBank,
    /// Largest `|G_ij|` over the reference configuration and 32 sampled configurations.
    pub g_scale: f64,
}

impl Mechanism {
    pub fn new(model: &Model) -> Result<Mechanism, DynamicsError> {
        let kinds = model.kinds();
        let n = kinds.len();
        if model.actuators.len() != n {
            return Err(DynamicsError::NotSquare {
                actuators: model.actuators.len(),
                coordinates: n,
            });
        }
        let np = n * (n + 1) / 2;
        let mut pose_polys: Vec<TrigPoly> = Vec::new();
        for b in &model.bodies {
            let entries: Vec<TrigPoly> = b
                .rotation
                .0
                .iter()
                .flat_map(|row| row.iter().cloned())
                .chain(b.origin.0.iter().cloned())
                .collect();
            let first: Vec<Vec<TrigPoly>> = (0..n)
                .map(|k| entries.iter().map(|e| e.derivative(k, kinds[k])).collect())
                .collect();
            let mut second: Vec<Vec<TrigPoly>> = vec![Vec::new(); np];
            for l in 0..n {
                for k in 0..=l {
                    second[packed(k, l)] =
                        first[k].iter().map(|e| e.derivative(l, kinds[l])).collect();
                }
            }
            pose_polys.extend(entries);
            for f in first {
                pose_polys.extend(f);
            }
            for s in second {
                pose_polys.extend(s);
            }
        }
        let mut act_polys: Vec<TrigPoly> = model
            .actuators
            .iter()
            .map(|a| a.coordinate.poly.clone())
            .collect();
        let mut act2_polys = Vec::new();
        for a in &model.actuators {
            let first: Vec<TrigPoly> = (0..n)
                .map(|k| a.coordinate.derivative(k, kinds[k]))
                .collect();
            let mut second = vec![TrigPoly::zero(); np];
            for l in 0..n {
                for k in 0..=l {
                    second[packed(k, l)] = first[k].derivative(l, kinds[l]);
                }
            }
            act_polys.extend(first);
            act2_polys.extend(second);
        }
        let mut mech = Mechanism {
            n,
            kinds: kinds.clone(),
            coordinate_names: model.coordinates.iter().map(|c| c.name.clone()).collect(),
            ranges: model.coordinates.iter().map(|c| c.range).collect(),
            body_count: model.bodies.len(),
            gravity: model.gravity,
            pose_bank: PolyBank::new(&pose_polys, &kinds),
            act_bank: PolyBank::new(&act_polys, &kinds),
            act_linear: model
                .actuators
                .iter()
                .map(|a| a.coordinate.linear.clone())
                .collect(),
            act2_bank: PolyBank::new(&act2_polys, &kinds),
            g_scale: 0.0,
        };
        let mut rng = counterpoise_model::sampling::SplitMix64::new(0x6475_6e61_6d69_6373);
        let mut scratch = Scratch::default();
        let mut u = [0.0; MAX_VARS];
        let mut g = [0.0; MAX_VARS * MAX_VARS];
        let mut scale = 0.0f64;
        for s in 0..33 {
            let q: Vec<f64> = if s == 0 {
                model.reference_configuration()
            } else {
                mech.ranges
                    .iter()
                    .map(|r| rng.uniform(r[0], r[1]))
                    .collect()
            };
            mech.actuator_map(&q, &mut scratch, &mut u, &mut g);
            scale = g[..n * n].iter().fold(scale, |m, x| m.max(x.abs()));
        }
        mech.g_scale = if scale > 0.0 { scale } else { 1.0 };
        Ok(mech)
    }

    /// Whether an LU of `G` is singular (see [`SINGULAR_PIVOT_RATIO`]); returns the ratio.
    pub fn singularity(&self, lu: &SmallLu) -> Result<(), FailureReason> {
        let ratio = lu.min_pivot / lu.max_pivot.max(self.g_scale);
        if ratio >= SINGULAR_PIVOT_RATIO {
            Ok(())
        } else {
            Err(FailureReason::Singular { pivot_ratio: ratio })
        }
    }

    /// Values per body in the pose bank.
    pub fn block_len(&self) -> usize {
        12 * (1 + self.n + self.n * (self.n + 1) / 2)
    }

    /// Evaluates all body poses and their derivatives at `q` into `scratch.pose`.
    pub fn eval_poses(&self, q: &[f64], scratch: &mut Scratch) {
        scratch.pose.resize(self.pose_bank.len(), 0.0);
        self.pose_bank.eval(q, &mut scratch.bank, &mut scratch.pose);
    }

    #[inline]
    fn slot<'a>(&self, pose: &'a [f64], body: usize, slot: usize) -> &'a [f64] {
        let off = body * self.block_len() + 12 * slot;
        &pose[off..off + 12]
    }

    #[inline]
    fn rot(s: &[f64]) -> Matrix3<f64> {
        Matrix3::new(s[0], s[1], s[2], s[3], s[4], s[5], s[6], s[7], s[8])
    }

    /// `(R, p)` of a body (identity for the base) from evaluated poses.
    pub fn pose_of(&self, pose: &[f64], id: BodyId) -> (Matrix3<f64>, Vector3<f64>) {
        match id {
            BodyId::Base => (Matrix3::identity(), Vector3::zeros()),
            BodyId::Body(b) => {
                let s = self.slot(pose, b, 0);
                (Self::rot(s), Vector3::new(s[9], s[10], s[11]))
            }
        }
    }

    /// `(∂R/∂q_k, ∂p/∂q_k)` of a body (zero for the base).
    pub fn pose_derivative(
        &self,
        pose: &[f64],
        id: BodyId,
        k: usize,
    ) -> (Matrix3<f64>, Vector3<f64>) {
        match id {
            BodyId::Base => (Matrix3::zeros(), Vector3::zeros()),
            BodyId::Body(b) => {
                let s = self.slot(pose, b, 1 + k);
                (Self::rot(s), Vector3::new(s[9], s[10], s[11]))
            }
        }
    }

    /// Pose, Jacobians, velocity and acceleration of body `b` from evaluated poses.
    pub fn body_kin(&self, pose: &[f64], b: usize, qd: &[f64], qdd: &[f64]) -> BodyKin {
        let mut out = self.body_frame(pose, b);
        self.set_motion(pose, b, &mut out, qd, qdd);
        out
    }

    /// Pose and Jacobians of body `b` (velocities and accelerations left zero).
    pub fn body_frame(&self, pose: &[f64], b: usize) -> BodyKin {
        let s0 = self.slot(pose, b, 0);
        let r = Self::rot(s0);
        let mut out = BodyKin {
            r,
            p: Vector3::new(s0[9], s0[10], s0[11]),
            ..BodyKin::default()
        };
        let rt = r.transpose();
        for k in 0..self.n {
            let s = self.slot(pose, b, 1 + k);
            out.jv[k] = Vector3::new(s[9], s[10], s[11]);
            out.jw[k] = vee(&(Self::rot(s) * rt));
        }
        out
    }

    /// Fills the velocity and acceleration of a body whose frame came from
    /// [`Mechanism::body_frame`].
    pub fn set_motion(&self, pose: &[f64], b: usize, k: &mut BodyKin, qd: &[f64], qdd: &[f64]) {
        let n = self.n;
        let mut rdd = Matrix3::zeros();
        let mut a = Vector3::zeros();
        let mut v = Vector3::zeros();
        let mut w = Vector3::zeros();
        for j in 0..n {
            let s = self.slot(pose, b, 1 + j);
            v += k.jv[j] * qd[j];
            w += k.jw[j] * qd[j];
            rdd += Self::rot(s) * qdd[j];
            a += k.jv[j] * qdd[j];
        }
        for l in 0..n {
            for j in 0..=l {
                let weight = if j == l {
                    qd[j] * qd[j]
                } else {
                    2.0 * qd[j] * qd[l]
                };
                if weight == 0.0 {
                    continue;
                }
                let s = self.slot(pose, b, 1 + n + packed(j, l));
                rdd += Self::rot(s) * weight;
                a += Vector3::new(s[9], s[10], s[11]) * weight;
            }
        }
        k.v = v;
        k.w = w;
        k.a = a;
        k.alpha = vee(&(rdd * k.r.transpose()));
    }

    /// `f(q)` into `u`, and `G = ∂f/∂q` (row-major) into `g` when given.
    pub fn actuator_map(&self, q: &[f64], scratch: &mut Scratch, u: &mut [f64], g: &mut [f64]) {
        let n = self.n;
        scratch.act.resize(self.act_bank.len(), 0.0);
        self.act_bank.eval(q, &mut scratch.bank, &mut scratch.act);
        for a in 0..n {
            u[a] = scratch.act[a]
                + self.act_linear[a]
                    .iter()
                    .map(|&(k, c)| c * q[k])
                    .sum::<f64>();
        }
        g[..n * n].copy_from_slice(&scratch.act[n..n + n * n]);
    }

    /// `Ġ q̇ = Σ_kl ∂²f/∂q_k∂q_l q̇_k q̇_l` into `out`.
    pub fn actuator_bias(&self, q: &[f64], qd: &[f64], scratch: &mut Scratch, out: &mut [f64]) {
        let n = self.n;
        let np = n * (n + 1) / 2;
        scratch.act2.resize(self.act2_bank.len(), 0.0);
        self.act2_bank.eval(q, &mut scratch.bank, &mut scratch.act2);
        for a in 0..n {
            let mut acc = 0.0;
            for l in 0..n {
                for k in 0..=l {
                    let w = if k == l {
                        qd[k] * qd[k]
                    } else {
                        2.0 * qd[k] * qd[l]
                    };
                    acc += w * scratch.act2[a * np + packed(k, l)];
                }
            }
            out[a] = acc;
        }
    }

    /// Solves `f(q) = u` by damped Newton from `q` (updated in place). On success the angles
    /// are shifted by multiples of 2π into their ranges and `q` is checked against the ranges.
    pub fn solve(
        &self,
        u: &[f64],
        q: &mut [f64],
        scratch: &mut Scratch,
    ) -> Result<(), FailureReason> {
        let n = self.n;
        let scale = 1.0 + u[..n].iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let tol = NEWTON_TOLERANCE * scale;
        let mut f = [0.0; MAX_VARS];
        let mut g = [0.0; MAX_VARS * MAX_VARS];
        let residual_of = |f: &[f64]| -> (f64, f64) {
            let mut max = 0.0f64;
            let mut sq = 0.0;
            for a in 0..n {
                let r = f[a] - u[a];
                max = max.max(r.abs());
                sq += r * r;
            }
            (max, sq.sqrt())
        };
        self.actuator_map(q, scratch, &mut f, &mut g);
        let (mut rmax, mut rnorm) = residual_of(&f);
        let mut iterations = 0;
        while rmax > tol || rmax.is_nan() {
            if iterations == NEWTON_MAX_ITERATIONS || !rmax.is_finite() {
                return Err(FailureReason::NotConverged { residual: rmax });
            }
            iterations += 1;
            let lu = SmallLu::new(&g, n);
            self.singularity(&lu)?;
            let mut step = [0.0; MAX_VARS];
            for a in 0..n {
                step[a] = u[a] - f[a];
            }
            lu.solve(&mut step);
            let mut limit_scale = 1.0f64;
            for k in 0..n {
                let half = 0.5 * (self.ranges[k][1] - self.ranges[k][0]);
                let limit = match self.kinds[k] {
                    VarKind::Angle => half.min(MAX_ANGLE_STEP),
                    VarKind::Length => half,
                };
                if step[k].abs() > limit {
                    limit_scale = limit_scale.min(limit / step[k].abs());
                }
            }
            let mut t = limit_scale;
            let mut candidate = [0.0; MAX_VARS];
            loop {
                for k in 0..n {
                    candidate[k] = q[k] + t * step[k];
                }
                self.actuator_map(&candidate[..n], scratch, &mut f, &mut g);
                let (m, norm) = residual_of(&f);
                if norm <= (1.0 - 1e-4 * t) * rnorm || m <= tol {
                    q[..n].copy_from_slice(&candidate[..n]);
                    rmax = m;
                    rnorm = norm;
                    break;
                }
                t *= 0.5;
                if t < 1e-6 {
                    return Err(FailureReason::NotConverged { residual: rmax });
                }
            }
        }
        self.into_ranges(q)
    }

    /// Shifts angles by multiples of 2π into their ranges; fails for a coordinate outside
    /// (with a relative slack of 1e-9 of the range width for values on the boundary).
    pub fn into_ranges(&self, q: &mut [f64]) -> Result<(), FailureReason> {
        let tau = std::f64::consts::TAU;
        for k in 0..self.n {
            let [lo, hi] = self.ranges[k];
            let slack = 1e-9 * (hi - lo).abs().max(1.0);
            if self.kinds[k] == VarKind::Angle {
                let shifted = q[k] - tau * ((q[k] - lo + slack) / tau).floor();
                if shifted <= hi + slack {
                    q[k] = shifted;
                }
            }
            if q[k] < lo - slack || q[k] > hi + slack {
                return Err(FailureReason::OutOfRange {
                    coordinate: self.coordinate_names[k].clone(),
                    value: q[k],
                    range: [lo, hi],
                });
            }
        }
        Ok(())
    }

    /// Kinematic state of a sample: `q` solved from `u` (warm-started from `q`), then
    /// `q̇ = G⁻¹u̇` and `q̈ = G⁻¹(ü − Ġq̇)`. Returns the LU of `G` for mapping forces back.
    pub fn sample_state(
        &self,
        u: &[f64],
        ud: &[f64],
        udd: &[f64],
        q: &mut [f64],
        qd: &mut [f64],
        qdd: &mut [f64],
        scratch: &mut Scratch,
    ) -> Result<SmallLu, FailureReason> {
        let n = self.n;
        self.solve(u, q, scratch)?;
        let mut f = [0.0; MAX_VARS];
        let mut g = [0.0; MAX_VARS * MAX_VARS];
        self.actuator_map(q, scratch, &mut f, &mut g);
        let lu = SmallLu::new(&g, n);
        self.singularity(&lu)?;
        qd[..n].copy_from_slice(&ud[..n]);
        lu.solve(qd);
        let mut bias = [0.0; MAX_VARS];
        self.actuator_bias(q, qd, scratch, &mut bias);
        for a in 0..n {
            qdd[a] = udd[a] - bias[a];
        }
        lu.solve(qdd);
        Ok(lu)
    }
}
