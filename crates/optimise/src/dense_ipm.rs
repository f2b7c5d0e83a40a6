//! A dense primal–dual interior-point method for small cone programs of nonnegative rows and
//! second-order cones: the branch-and-bound's box relaxations (about 21 variables and 200
//! rows, cones of 2 to 8 rows).
//!
//! Why: clarabel solves these through a sparse quasi-definite KKT system of about 240 rows,
//! factored by its LDL with iterative refinement, about 100 µs per iteration; with only ~21
//! variables the normal equations `Aᵀ W⁻² A Δx = r` are a 21 × 21 Cholesky, a few µs. The
//! method is the classic infeasible-start Mehrotra predictor–corrector with Nesterov–Todd
//! scaling (as in CVXOPT's `coneqp` and ECOS), without the homogeneous embedding. It claims
//! only what it can check: `Solved` under clarabel's own residual and gap tests (its
//! definitions on unscaled data, see [`Tolerances`]), `PrimalInfeasible` with a certificate it
//! checks (`z` in the cone, `bᵀz < 0`, `‖Aᵀz‖∞·max(1, ‖x‖∞)` negligible against `|bᵀz|`, see
//! [`solve`]); every other ending is [`DenseOutcome::Failed`], on which the caller runs
//! clarabel as before.
//!
//! Problems are `min cᵀx` subject to `A x + s = b`, `s ∈ K` (clarabel's form), `K` a product of
//! nonnegative orthants and second-order cones `s₀ ≥ ‖s₁…‖`; the dual is `max −bᵀz` subject to
//! `Aᵀz + c = 0`, `z ∈ K`.

use nalgebra::{Cholesky, DMatrix, DVector, Dyn};

use crate::slots::norm;

/// One block of consecutive rows of the cone `K`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Block {
    /// Rows `start .. start + len`, each `≥ 0`.
    Nonneg { start: usize, len: usize },
    /// Rows `start .. start + len`, `s₀ ≥ ‖s₁…‖`.
    Soc { start: usize, len: usize },
}

impl Block {
    fn range(self) -> std::ops::Range<usize> {
        match self {
            Block::Nonneg { start, len } | Block::Soc { start, len } => start..start + len,
        }
    }

    /// The block's share of the cone's degree (the `ν` of `μ = sᵀz / ν`).
    fn degree(self) -> usize {
        match self {
            Block::Nonneg { len, .. } => len,
            Block::Soc { .. } => 1,
        }
    }
}

/// The problem, borrowed from [`crate::clarabel_map::ConicProblem`]: row `i` of `A` is
/// `terms[row_start[i]..row_start[i + 1]]` as `(variable, coefficient)`.
pub(crate) struct DenseData<'a> {
    pub n: usize,
    pub row_start: &'a [usize],
    pub terms: &'a [(usize, f64)],
    pub b: &'a [f64],
    pub c: &'a [f64],
    pub blocks: &'a [Block],
}

/// clarabel's termination tests (`tol_gap_abs`, `tol_gap_rel`, `tol_feas`; `tol_infeas_abs`,
/// `tol_infeas_rel`), on the unscaled problem.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Tolerances {
    pub gap_abs: f64,
    pub gap_rel: f64,
    pub feas: f64,
    pub infeas_abs: f64,
    pub infeas_rel: f64,
}

impl Tolerances {
    /// clarabel's defaults with the gap and feasibility tolerance `tol`.
    pub(crate) fn with(tol: f64) -> Tolerances {
        Tolerances {
            gap_abs: tol,
            gap_rel: tol,
            feas: tol,
            infeas_abs: 1e-8,
            infeas_rel: 1e-8,
        }
    }
}

/// How a dense solve ended.
#[derive(Clone, Debug)]
pub(crate) enum DenseOutcome {
    Solved {
        x: Vec<f64>,
        z: Vec<f64>,
        primal_objective: f64,
        dual_objective: f64,
        iterations: u32,
    },
    /// `z ∈ K`, `bᵀz < −infeas_abs`, `‖Aᵀz‖∞ < −infeas_rel · bᵀz`, found at an iterate that
    /// is not itself feasible.
    PrimalInfeasible { z: Vec<f64>, iterations: u32 },
    /// No verdict within the iterations (or a numerical failure): the caller solves otherwise.
    Failed,
}

/// The diagonal added, relative to the largest, when `ḠᵀḠ` does not factor.
const REGULARIZATION: f64 = 1e-13;

/// The size of `x` or `z` past which a run without a verdict is given up.
const DIVERGED: f64 = 1e16;

/// Step fraction towards the cone's boundary.
const STEP_FRACTION: f64 = 0.99;

/// The Nesterov–Todd scaling at `(s, z)`, `W z = W⁻¹ s = λ`, block by block: a nonnegative
/// block's `W = diag(w)`, `w = √(s/z)`; a second-order cone's `W = η W̄`,
/// `W̄ = [[w₀, w₁ᵀ], [w₁, I + w₁w₁ᵀ/(1 + w₀)]]` with `w̄ᵀJw̄ = 1`. Kept in buffers that the
/// iterations reuse.
#[derive(Clone, Debug, Default)]
struct Scaling {
    /// `w` of every row (`w̄` for a cone's rows).
    w: Vec<f64>,
    /// `η` of every block (1 for a nonnegative one).
    eta: Vec<f64>,
}

impl Scaling {
    /// The scaling at the interior point `(s, z)`; `false` when a block of either is not
    /// strictly inside its cone (to rounding).
    fn update(&mut self, blocks: &[Block], s: &[f64], z: &[f64]) -> bool {
        self.w.resize(s.len(), 0.0);
        self.eta.resize(blocks.len(), 1.0);
        for (b, &blk) in blocks.iter().enumerate() {
            let r = blk.range();
            let Some(eta) = block_scaling(blk, &s[r.clone()], &z[r.clone()], &mut self.w[r]) else {
                return false;
            };
            self.eta[b] = eta;
        }
        true
    }

    /// `out = W v` (`inverse`: `W⁻¹ v`) over all blocks.
    fn apply(&self, blocks: &[Block], v: &[f64], out: &mut [f64], inverse: bool) {
        for (&blk, &eta) in blocks.iter().zip(&self.eta) {
            let r = blk.range();
            apply_block(
                blk,
                eta,
                &self.w[r.clone()],
                &v[r.clone()],
                &mut out[r],
                inverse,
            );
        }
    }
}

/// One block's scaling into `w`, returning its `η`; `None` when `s` or `z` is not interior.
fn block_scaling(block: Block, s: &[f64], z: &[f64], w: &mut [f64]) -> Option<f64> {
    match block {
        Block::Nonneg { .. } => {
            for ((wi, &si), &zi) in w.iter_mut().zip(s).zip(z) {
                *wi = (si / zi).sqrt();
                if !(si > 0.0 && zi > 0.0 && wi.is_finite()) {
                    return None;
                }
            }
            Some(1.0)
        }
        Block::Soc { .. } => {
            let s_det = soc_det(s);
            let z_det = soc_det(z);
            if !(s_det > 0.0 && z_det > 0.0 && s[0] > 0.0 && z[0] > 0.0) {
                return None;
            }
            let (s_root, z_root) = (s_det.sqrt(), z_det.sqrt());
            // s̄ = s/√(sᵀJs), z̄ = z/√(zᵀJz), γ = √((1 + s̄ᵀz̄)/2), w̄ = (s̄ + Jz̄)/(2γ).
            let dot: f64 = s.iter().zip(z).map(|(a, b)| a * b).sum::<f64>() / (s_root * z_root);
            let gamma = ((1.0 + dot) / 2.0).sqrt();
            for (k, wk) in w.iter_mut().enumerate().skip(1) {
                *wk = (s[k] / s_root - z[k] / z_root) / (2.0 * gamma);
            }
            // w̄ᵀJw̄ = 1 up to rounding: w₀ from w₁ keeps W̄ exactly a hyperbolic rotation.
            w[0] = (1.0 + w[1..].iter().map(|v| v * v).sum::<f64>()).sqrt();
            let eta = (s_root / z_root).sqrt();
            (eta.is_finite() && w.iter().all(|v| v.is_finite())).then_some(eta)
        }
    }
}

/// `out = W v` (`inverse`: `W⁻¹ v`) for one block with scaling `(η, w)`.
fn apply_block(block: Block, eta: f64, w: &[f64], v: &[f64], out: &mut [f64], inverse: bool) {
    match block {
        Block::Nonneg { .. } => {
            for ((o, &vi), &wi) in out.iter_mut().zip(v).zip(w) {
                *o = if inverse { vi / wi } else { vi * wi };
            }
        }
        Block::Soc { .. } => {
            // W̄⁻¹ = J W̄ J: the sign of w₁ flips where it meets v₀ and in v₀'s share.
            let sign = if inverse { -1.0 } else { 1.0 };
            let scale = if inverse { 1.0 / eta } else { eta };
            let w1v1: f64 = w[1..].iter().zip(&v[1..]).map(|(a, b)| a * b).sum();
            let head = w[0] * v[0] + sign * w1v1;
            let along = sign * v[0] + w1v1 / (1.0 + w[0]);
            out[0] = scale * head;
            for k in 1..w.len() {
                out[k] = scale * (v[k] + along * w[k]);
            }
        }
    }
}

/// `x₀² − ‖x₁‖²`.
fn soc_det(x: &[f64]) -> f64 {
    let tail = norm(&x[1..]);
    (x[0] - tail) * (x[0] + tail)
}

/// Jordan product `u ∘ v` of one block.
fn jordan(block: Block, u: &[f64], v: &[f64], out: &mut [f64]) {
    match block {
        Block::Nonneg { .. } => {
            for ((o, a), b) in out.iter_mut().zip(u).zip(v) {
                *o = a * b;
            }
        }
        Block::Soc { .. } => {
            out[0] = u.iter().zip(v).map(|(a, b)| a * b).sum();
            for k in 1..u.len() {
                out[k] = u[0] * v[k] + v[0] * u[k];
            }
        }
    }
}

/// `q` with `λ ∘ q = r` for one block (`λ` interior).
fn jordan_solve(block: Block, lambda: &[f64], r: &[f64], out: &mut [f64]) {
    match block {
        Block::Nonneg { .. } => {
            for ((o, l), v) in out.iter_mut().zip(lambda).zip(r) {
                *o = v / l;
            }
        }
        Block::Soc { .. } => {
            let det = soc_det(lambda);
            let l1r1: f64 = lambda[1..].iter().zip(&r[1..]).map(|(a, b)| a * b).sum();
            let q0 = (lambda[0] * r[0] - l1r1) / det;
            out[0] = q0;
            for k in 1..lambda.len() {
                out[k] = (r[k] - q0 * lambda[k]) / lambda[0];
            }
        }
    }
}

/// The largest `α ≥ 0` with `x + α d` in the block's cone (`x` interior); `∞` when none bounds it.
fn max_step(block: Block, x: &[f64], d: &[f64]) -> f64 {
    match block {
        Block::Nonneg { .. } => x
            .iter()
            .zip(d)
            .filter(|&(_, &di)| di < 0.0)
            .map(|(&xi, &di)| -xi / di)
            .fold(f64::INFINITY, f64::min),
        Block::Soc { .. } => {
            // (x₀ + αd₀)² − ‖x₁ + αd₁‖² = aα² + bα + c ≥ 0 with x₀ + αd₀ ≥ 0.
            let a = d[0] * d[0] - d[1..].iter().map(|v| v * v).sum::<f64>();
            let b =
                2.0 * (x[0] * d[0] - x[1..].iter().zip(&d[1..]).map(|(p, q)| p * q).sum::<f64>());
            let c = soc_det(x).max(0.0);
            let mut alpha = if d[0] < 0.0 {
                -x[0] / d[0]
            } else {
                f64::INFINITY
            };
            if a == 0.0 {
                if b < 0.0 {
                    alpha = alpha.min(-c / b);
                }
            } else {
                let disc = b * b - 4.0 * a * c;
                if disc >= 0.0 {
                    let t = -0.5 * (b + b.signum() * disc.sqrt());
                    for root in [t / a, if t != 0.0 { c / t } else { f64::INFINITY }] {
                        if root >= 0.0 {
                            alpha = alpha.min(root);
                        }
                    }
                }
            }
            alpha
        }
    }
}

/// The iterate's scaled Newton system: the scaling, `Ḡ = W⁻¹A`, `ḠᵀḠ` and its Cholesky
/// factor; buffers reused from one iteration to the next.
struct Newton {
    scaling: Scaling,
    gbar: DMatrix<f64>,
    gbar_t: DMatrix<f64>,
    h: DMatrix<f64>,
    chol: Option<Cholesky<f64, Dyn>>,
}

impl DenseData<'_> {
    fn m(&self) -> usize {
        self.b.len()
    }

    fn row(&self, i: usize) -> &[(usize, f64)] {
        &self.terms[self.row_start[i]..self.row_start[i + 1]]
    }

    /// `A x`.
    fn a_mul(&self, x: &[f64]) -> Vec<f64> {
        (0..self.m())
            .map(|i| self.row(i).iter().map(|&(j, a)| a * x[j]).sum())
            .collect()
    }

    /// `Aᵀ z`.
    fn at_mul(&self, z: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; self.n];
        for (i, &zi) in z.iter().enumerate() {
            for &(j, a) in self.row(i) {
                out[j] += a * zi;
            }
        }
        out
    }

    /// `A` dense.
    fn dense(&self) -> DMatrix<f64> {
        let mut a = DMatrix::zeros(self.m(), self.n);
        for i in 0..self.m() {
            for &(j, v) in self.row(i) {
                a[(i, j)] += v;
            }
        }
        a
    }

    /// The Newton system at `(s, z)` into `newton`; `false` when a block is not interior or
    /// `ḠᵀḠ` is not positive definite.
    fn newton(&self, a: &DMatrix<f64>, s: &[f64], z: &[f64], newton: &mut Newton) -> bool {
        if !newton.scaling.update(self.blocks, s, z) {
            return false;
        }
        for j in 0..self.n {
            newton.scaling.apply(
                self.blocks,
                a.column(j).as_slice(),
                newton.gbar.column_mut(j).as_mut_slice(),
                true,
            );
        }
        newton.gbar.transpose_to(&mut newton.gbar_t);
        newton.gbar_t.mul_to(&newton.gbar, &mut newton.h);
        // Near the optimum `W⁻²` spans many orders and `ḠᵀḠ` can lose definiteness to
        // rounding: the retry adds a diagonal at the rounding level of its largest entry. The
        // direction is then inexact, which the iteration tolerates; the termination tests use
        // the true residuals.
        let h = &newton.h;
        newton.chol = Cholesky::new(h.clone()).or_else(|| {
            let largest = h.diagonal().iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let mut regularized = h.clone();
            for j in 0..self.n {
                regularized[(j, j)] += REGULARIZATION * largest;
            }
            Cholesky::new(regularized)
        });
        newton.chol.is_some()
    }

    /// The scaled Newton direction `(Δx, W⁻¹Δs, WΔz)` for the residuals `rx = Aᵀz + c`,
    /// `rz = Ax + s − b` and the complementarity right-hand side `q = λ ⋄ r`: from
    /// `AᵀΔz = −rx`, `AΔx + Δs = −rz`, `WΔz + W⁻¹Δs = q`.
    fn direction(
        &self,
        newton: &Newton,
        rx: &[f64],
        rz: &[f64],
        q: &[f64],
    ) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let mut scaled_rz = vec![0.0; rz.len()];
        newton.scaling.apply(self.blocks, rz, &mut scaled_rz, true);
        let t = DVector::from_iterator(q.len(), q.iter().zip(&scaled_rz).map(|(a, b)| a + b));
        let rhs = -(DVector::from_column_slice(rx) + newton.gbar.tr_mul(&t));
        let dx = newton.chol.as_ref().expect("factored").solve(&rhs);
        let dz = &t + &newton.gbar * &dx;
        let ds: Vec<f64> = q.iter().zip(dz.iter()).map(|(a, b)| a - b).collect();
        (dx.as_slice().to_vec(), ds, dz.as_slice().to_vec())
    }

    /// The largest `α` keeping `λ + α ds` and `λ + α dz` in the cone (`∞` when none bounds it).
    fn step(&self, lambda: &[f64], ds: &[f64], dz: &[f64]) -> f64 {
        self.blocks
            .iter()
            .map(|&blk| {
                let r = blk.range();
                max_step(blk, &lambda[r.clone()], &ds[r.clone()]).min(max_step(
                    blk,
                    &lambda[r.clone()],
                    &dz[r],
                ))
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// Shifts `v` into the cone's interior as CVXOPT's starting point does: by `(1 + t)·e`
    /// when its least eigenvalue `−t` is not positive.
    fn shift_inside(&self, v: &mut [f64]) {
        let t = self
            .blocks
            .iter()
            .map(|&blk| {
                let x = &v[blk.range()];
                match blk {
                    Block::Nonneg { .. } => x.iter().map(|&a| -a).fold(f64::NEG_INFINITY, f64::max),
                    Block::Soc { .. } => norm(&x[1..]) - x[0],
                }
            })
            .fold(f64::NEG_INFINITY, f64::max);
        if t >= -1e-8 * norm(v).max(1.0) {
            self.identity_into(v, 1.0 + t);
        }
    }

    /// `out += scale·e`, `e` the cone's identity (1 on every nonnegative row, `(1, 0, …)` per
    /// second-order cone).
    fn identity_into(&self, out: &mut [f64], scale: f64) {
        for &blk in self.blocks {
            match blk {
                Block::Nonneg { start, len } => {
                    out[start..start + len].iter_mut().for_each(|a| *a += scale)
                }
                Block::Soc { start, .. } => out[start] += scale,
            }
        }
    }

    /// `op(block, u, v, out)` on each block's rows of `u` and `v`, into a new vector.
    fn blockwise(
        &self,
        u: &[f64],
        v: &[f64],
        op: fn(Block, &[f64], &[f64], &mut [f64]),
    ) -> Vec<f64> {
        let mut out = vec![0.0; u.len()];
        for &blk in self.blocks {
            let r = blk.range();
            op(blk, &u[r.clone()], &v[r.clone()], &mut out[r]);
        }
        out
    }
}

fn inf_norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, a| m.max(a.abs()))
}

fn dot(u: &[f64], v: &[f64]) -> f64 {
    u.iter().zip(v).map(|(a, b)| a * b).sum()
}

/// Solves `data` in at most `max_iter` iterations.
pub(crate) fn solve(data: &DenseData<'_>, tol: Tolerances, max_iter: u32) -> DenseOutcome {
    let (n, m) = (data.n, data.m());
    let degree: usize = data.blocks.iter().map(|b| b.degree()).sum();
    if m == 0 || degree == 0 || data.blocks.iter().map(|b| b.range().len()).sum::<usize>() != m {
        return DenseOutcome::Failed;
    }
    let a = data.dense();
    let (norm_b, norm_c) = (inf_norm(data.b), inf_norm(data.c));

    // Start (CVXOPT's): x minimising ‖b − Ax‖, z the least-norm solution of Aᵀz + c = 0, both
    // slacks shifted into the cone.
    let Some(chol) = Cholesky::new(a.tr_mul(&a)) else {
        return DenseOutcome::Failed;
    };
    let bv = DVector::from_column_slice(data.b);
    let mut x = chol.solve(&a.tr_mul(&bv)).as_slice().to_vec();
    let mut s: Vec<f64> = (bv - &a * DVector::from_column_slice(&x))
        .as_slice()
        .to_vec();
    let mut z: Vec<f64> = (-(&a * chol.solve(&DVector::from_column_slice(data.c))))
        .as_slice()
        .to_vec();
    data.shift_inside(&mut s);
    data.shift_inside(&mut z);

    let mut newton = Newton {
        scaling: Scaling::default(),
        gbar: DMatrix::zeros(m, n),
        gbar_t: DMatrix::zeros(n, m),
        h: DMatrix::zeros(n, n),
        chol: None,
    };
    for iteration in 0..max_iter {
        let ax = data.a_mul(&x);
        let rz: Vec<f64> = (0..m).map(|i| ax[i] + s[i] - data.b[i]).collect();
        let atz = data.at_mul(&z);
        let rx: Vec<f64> = (0..n).map(|j| atz[j] + data.c[j]).collect();
        let primal_objective = dot(data.c, &x);
        let dual_objective = -dot(data.b, &z);
        let (norm_x, norm_s, norm_z) = (inf_norm(&x), inf_norm(&s), inf_norm(&z));
        let res_primal = inf_norm(&rz) / (norm_b + norm_x + norm_s).max(1.0);
        let res_dual = inf_norm(&rx) / (norm_c + norm_x + norm_z).max(1.0);
        let gap_abs = (primal_objective - dual_objective).abs();
        let gap_rel = gap_abs / primal_objective.abs().min(dual_objective.abs()).max(1.0);
        if (gap_abs < tol.gap_abs || gap_rel < tol.gap_rel)
            && res_primal < tol.feas
            && res_dual < tol.feas
        {
            return DenseOutcome::Solved {
                x,
                z,
                primal_objective,
                dual_objective,
                iterations: iteration,
            };
        }
        let bz = dot(data.b, &z);
        // `z ∈ K` proves that no feasible `x` has `‖x‖₁ < −bᵀz / ‖Aᵀz‖∞` (`zᵀs = bᵀz −
        // xᵀAᵀz ≥ 0`): a bound `1 / infeas_rel` times the iterate's own size (and at least
        // that, the variables being at their natural scale) is taken as a proof. (Dividing
        // `‖Aᵀz‖` by `‖z‖`, as clarabel does with its normalised embedding, would pass any
        // large optimal dual of a thin box here, where `Aᵀz ≈ −c`.)
        if bz < -tol.infeas_abs && inf_norm(&atz) * norm_x.max(1.0) < -tol.infeas_rel * bz {
            return DenseOutcome::PrimalInfeasible {
                z,
                iterations: iteration,
            };
        }
        // Iterates beyond `DIVERGED` without a verdict belong to an infeasible or unbounded
        // problem this method will not settle: clarabel's embedding does.
        if ![primal_objective, dual_objective, res_primal, res_dual]
            .iter()
            .all(|v| v.is_finite())
            || norm_x.max(norm_z) > DIVERGED
        {
            return DenseOutcome::Failed;
        }

        if !data.newton(&a, &s, &z, &mut newton) {
            return DenseOutcome::Failed;
        }
        let mut lambda = vec![0.0; m];
        newton.scaling.apply(data.blocks, &z, &mut lambda, false);
        let mu = dot(&s, &z) / degree as f64;

        // Predictor: λ ∘ (WΔz + W⁻¹Δs) = −λ ∘ λ, so q = −λ.
        let q_affine: Vec<f64> = lambda.iter().map(|v| -v).collect();
        let (_, ds_a, dz_a) = data.direction(&newton, &rx, &rz, &q_affine);
        let alpha_affine = data.step(&lambda, &ds_a, &dz_a).min(1.0);
        let sigma = (1.0 - alpha_affine).powi(3).clamp(0.0, 1.0);

        // Corrector: −λ ∘ λ − Δs_a ∘ Δz_a + σμe.
        let mut r = data.blockwise(&lambda, &lambda, jordan);
        let cross = data.blockwise(&ds_a, &dz_a, jordan);
        for (ri, ci) in r.iter_mut().zip(&cross) {
            *ri = -*ri - ci;
        }
        data.identity_into(&mut r, sigma * mu);
        let q = data.blockwise(&lambda, &r, jordan_solve);
        let (dx, ds, dz) = data.direction(&newton, &rx, &rz, &q);
        let alpha = (STEP_FRACTION * data.step(&lambda, &ds, &dz)).min(1.0);
        if !(alpha > 0.0 && alpha.is_finite()) {
            return DenseOutcome::Failed;
        }
        let (mut ds_unscaled, mut dz_unscaled) = (vec![0.0; m], vec![0.0; m]);
        newton
            .scaling
            .apply(data.blocks, &ds, &mut ds_unscaled, false);
        newton
            .scaling
            .apply(data.blocks, &dz, &mut dz_unscaled, true);
        let (ds, dz) = (ds_unscaled, dz_unscaled);
        for (xi, d) in x.iter_mut().zip(&dx) {
            *xi += alpha * d;
        }
        for (si, d) in s.iter_mut().zip(&ds) {
            *si += alpha * d;
        }
        for (zi, d) in z.iter_mut().zip(&dz) {
            *zi += alpha * d;
        }
    }
    DenseOutcome::Failed
}

#[cfg(test)]
mod tests;
