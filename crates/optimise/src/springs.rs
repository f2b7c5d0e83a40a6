//! Springs: physical parameters inside the balanced family, within bounds, chosen for low joint
//! reactions.
//!
//! With the counterweights fixed, the springs must supply the rest of the balance:
//! `A_S ℓ(y) = −(b + A_C x_C)`, where `ℓ(y) = (K, K a, K b, K a⊗b)` is the lifted vector of the
//! physical spring parameters `y = (ln K, a, b)` — realizable by construction. Like the balance
//! crate's realization this is a small nonlinear least-squares problem, solved by
//! Levenberg–Marquardt, here with hinge rows for the bounds (`K`, `|a|`, `|b|`, lower bounds
//! included) so that every accepted solution is inside them. Deterministic starts (the lifted
//! optimum first, then pseudo-random points inside the bounds) give several admissible spring
//! sets; since massless springs never change a balanced variant's motor torques, the one with
//! the lowest joint-reaction indicator ΔR (paper Eqs. 17–21) on the reaction tasks is kept.

use counterpoise_model::sampling::SplitMix64;
use nalgebra::{DMatrix, DVector};

use crate::problem::{VariantProblem, norm};

/// The physical parameters of one realized spring: the shared type (named by catalogue label
/// and body names, in the order of the problem's spring slots).
pub use counterpoise_vocabulary::Spring;

/// Relative balance residual accepted from the local solve (the energy sampling is the real
/// check).
const SOLVED_TOL: f64 = 1e-13;
/// Bound excess accepted from the local solve (relative).
const BOUND_TOL: f64 = 1e-12;
/// Consecutive steps that gain less than 0.1 % each after which a local solve stops.
const CREEP_STEPS: usize = 25;
/// The same for the solve pulled towards its start, which only prepares the start of the
/// unpulled solve: its minimum keeps a residual (the pull's), so it ends in a linear creep that
/// took 86 % of the Levenberg–Marquardt steps on the 8 heaviest Dmax 3 variants (44.6 steps per
/// pulled solve, 7.2 per unpulled one). After 8 creeping steps the unpulled solve takes over.
const PULLED_CREEP_STEPS: usize = 8;

pub(crate) struct Layout {
    /// First unknown of each spring in `y`.
    start: Vec<usize>,
    /// Per spring `(ln K_lo, ln K_hi)`, the hinges' bounds on the unknown `ln K` (`ln K_lo` is
    /// unused when `K_lo ≤ 0`): taken once here rather than at every evaluation, where two
    /// logarithms per spring were about 0.7 % of a Dmax 3 run.
    ln_stiffness: Vec<[f64; 2]>,
    /// First unknown of each counterweight (joint mode only): `m/M`, `μ/(M r_hi)`.
    cw_start: Vec<usize>,
    pub(crate) unknowns: usize,
}

/// `(M, R)`: the normalising mass and first-moment scales of a counterweight.
fn cw_scales(c: &crate::problem::CwSlot) -> (f64, f64) {
    let m = c.bounds.mass[1].max(1e-9);
    (m, (m * c.bounds.radius[1]).max(1e-9 * m))
}

/// The unknowns of the local solve: per spring `ln K` and its anchor components, then (with
/// `joint`) per counterweight its scaled mass and first moments.
pub(crate) fn layout(problem: &VariantProblem, joint: bool) -> Layout {
    let mut start = Vec::new();
    let mut cw_start = Vec::new();
    let mut ln_stiffness = Vec::new();
    let mut n = 0;
    for s in &problem.springs {
        start.push(n);
        let [klo, khi] = s.bounds.stiffness;
        ln_stiffness.push([if klo > 0.0 { klo.ln() } else { f64::NAN }, khi.ln()]);
        n += 1 + s.axes_a.len() + s.axes_b.len();
    }
    if joint {
        for c in &problem.counterweights {
            cw_start.push(n);
            n += 1 + c.axes.len();
        }
    }
    Layout {
        start,
        ln_stiffness,
        cw_start,
        unknowns: n,
    }
}

/// The lifted vector with the springs replaced by `y`.
fn lifted_with(
    problem: &VariantProblem,
    x: &DVector<f64>,
    lay: &Layout,
    y: &DVector<f64>,
) -> DVector<f64> {
    let mut out = x.clone();
    lift_into(problem, lay, y, &mut out);
    out
}

/// Writes `y`'s lifted values into the columns of `out` that `y` sets (the springs', and in
/// joint mode the counterweights').
fn lift_into(problem: &VariantProblem, lay: &Layout, y: &DVector<f64>, out: &mut DVector<f64>) {
    for (k, s) in problem.springs.iter().enumerate() {
        let u = lay.start[k];
        let (na, nb) = (s.axes_a.len(), s.axes_b.len());
        let kk = y[u].exp();
        out[s.column] = kk;
        for i in 0..na {
            out[s.column + 1 + i] = kk * y[u + 1 + i];
        }
        for l in 0..nb {
            out[s.column + 1 + na + l] = kk * y[u + 1 + na + l];
        }
        for i in 0..na {
            for l in 0..nb {
                out[s.column + 1 + na + nb + i * nb + l] = kk * y[u + 1 + i] * y[u + 1 + na + l];
            }
        }
    }
    for (c, &u) in problem.counterweights.iter().zip(&lay.cw_start) {
        let (big_m, big_r) = cw_scales(c);
        out[c.column] = y[u] * big_m;
        for k in 0..c.axes.len() {
            out[c.column + 1 + k] = y[u + 1 + k] * big_r;
        }
    }
}

/// The balance rows' Jacobian (`rows × unknowns`, row-major, in `jac`) at `y`, whose lifted
/// point is `xl`: per spring `∂/∂ ln K` (its own lifted vector) and `∂/∂a_i`, `∂/∂b_l`; per
/// counterweight its scaled mass and first moments.
fn balance_jacobian(
    problem: &VariantProblem,
    lay: &Layout,
    y: &DVector<f64>,
    xl: &DVector<f64>,
    scale: f64,
    jac: &mut [f64],
) {
    let a = &problem.solution.matrix;
    let rows = a.nrows();
    let n_unknowns = lay.unknowns;
    let mut d = vec![0.0; rows];
    for (k, s) in problem.springs.iter().enumerate() {
        let u = lay.start[k];
        let (na, nb) = (s.axes_a.len(), s.axes_b.len());
        // `xl` holds `y`'s lifted values: its `K` is `exp(y[u])`, the same bits.
        let kk = xl[s.column];
        let av = &y.as_slice()[u + 1..u + 1 + na];
        let bv = &y.as_slice()[u + 1 + na..u + 1 + na + nb];
        // d/d ln K: the spring's own lifted vector, `Σ_j a_j x_j` summed over `j` in ascending
        // order per row, column by column (contiguous in the column-major matrix).
        d.fill(0.0);
        for j in s.column..s.column + s.lifted_len() {
            let (c, v) = (a.column(j), xl[j]);
            for row in 0..rows {
                d[row] += c[row] * v;
            }
        }
        for row in 0..rows {
            jac[row * n_unknowns + u] = d[row] * scale;
        }
        for i in 0..na {
            let c0 = a.column(s.column + 1 + i);
            for row in 0..rows {
                d[row] = c0[row] * kk;
            }
            for l in 0..nb {
                let c = a.column(s.column + 1 + na + nb + i * nb + l);
                let f = kk * bv[l];
                for row in 0..rows {
                    d[row] += c[row] * f;
                }
            }
            for row in 0..rows {
                jac[row * n_unknowns + u + 1 + i] = d[row] * scale;
            }
        }
        for l in 0..nb {
            let c0 = a.column(s.column + 1 + na + l);
            for row in 0..rows {
                d[row] = c0[row] * kk;
            }
            for i in 0..na {
                let c = a.column(s.column + 1 + na + nb + i * nb + l);
                let f = kk * av[i];
                for row in 0..rows {
                    d[row] += c[row] * f;
                }
            }
            for row in 0..rows {
                jac[row * n_unknowns + u + 1 + na + l] = d[row] * scale;
            }
        }
    }
    for (c, &u) in problem.counterweights.iter().zip(&lay.cw_start) {
        let (big_m, big_r) = cw_scales(c);
        for row in 0..rows {
            jac[row * n_unknowns + u] = a[(row, c.column)] * big_m * scale;
            for k in 0..c.axes.len() {
                jac[row * n_unknowns + u + 1 + k] = a[(row, c.column + 1 + k)] * big_r * scale;
            }
        }
    }
}

/// The residual of one point of the local solve, in parts: the balance rows (relative to
/// ‖b‖), the bound hinges `max(value, 0)` with the few gradient entries of each, and the pull
/// rows `w (y − target)` (computed from `y` where needed). The Levenberg–Marquardt loop needs
/// only the cost at a trial step and the normal equations at the points it moves to, so no
/// dense Jacobian of the hinge and pull rows (mostly zeros) is ever built.
#[derive(Clone, Debug, Default)]
pub(crate) struct Residual {
    /// Balance rows, scaled.
    pub(crate) balance: Vec<f64>,
    /// Per hinge: its value (≤ 0 when inactive) and the range of its gradient in `grads` (empty
    /// when inactive).
    hinges: Vec<(f64, usize, usize)>,
    grads: Vec<(usize, f64)>,
    /// ‖balance‖.
    pub(crate) balance_norm: f64,
    /// Largest hinge value, and 0.
    pub(crate) hinge_max: f64,
    /// ‖residual‖: balance, active hinges and pull.
    pub(crate) cost: f64,
}

impl Residual {
    fn clear(&mut self) {
        self.balance.clear();
        self.hinges.clear();
        self.grads.clear();
        self.hinge_max = 0.0;
    }

    /// A bound hinge `max(value, 0)`, with gradient `grad` where it is active.
    fn hinge(&mut self, value: f64, grad: &[(usize, f64)]) {
        self.hinge_max = self.hinge_max.max(value);
        let first = self.grads.len();
        if value > 0.0 {
            self.grads.extend_from_slice(grad);
        }
        self.hinges.push((value, first, self.grads.len()));
    }

    /// The residual rows as one vector: balance, every hinge (zero where inactive), pull.
    #[cfg(test)]
    pub(crate) fn rows(&self, y: &DVector<f64>, pull: Option<(&DVector<f64>, f64)>) -> Vec<f64> {
        let mut out = self.balance.clone();
        out.extend(self.hinges.iter().map(|h| h.0.max(0.0)));
        if let Some((target, weight)) = pull {
            out.extend((0..y.len()).map(|j| weight * (y[j] - target[j])));
        }
        out
    }
}

/// The local solve of one variant's springs (and, in joint mode, counterweights): its residual
/// at a point and the Gauss–Newton normal equations there.
pub(crate) struct LocalSolve<'a> {
    problem: &'a VariantProblem,
    lay: &'a Layout,
    pull: Option<(&'a DVector<f64>, f64)>,
    /// 1/‖b‖.
    scale: f64,
    /// `A x + b` over the lifted columns that `y` does not set.
    fixed: Vec<f64>,
    /// The lifted columns that `y` sets, ascending.
    varying: Vec<usize>,
    /// The lifted point of the last `y` evaluated.
    xl: DVector<f64>,
    /// The balance rows' Jacobian, row-major (reused).
    jac: Vec<f64>,
    /// The upper triangle of `JᵀJ`, row-major (reused).
    upper: Vec<f64>,
}

impl<'a> LocalSolve<'a> {
    pub(crate) fn new(
        problem: &'a VariantProblem,
        b: &DVector<f64>,
        x: &DVector<f64>,
        lay: &'a Layout,
        pull: Option<(&'a DVector<f64>, f64)>,
    ) -> LocalSolve<'a> {
        let a = &problem.solution.matrix;
        let mut set = vec![false; x.len()];
        for s in &problem.springs {
            set[s.column..s.column + s.lifted_len()].fill(true);
        }
        if !lay.cw_start.is_empty() {
            for c in &problem.counterweights {
                set[c.column..c.column + 1 + c.axes.len()].fill(true);
            }
        }
        let mut fixed = b.as_slice().to_vec();
        for (j, &moves) in set.iter().enumerate() {
            if !moves && x[j] != 0.0 {
                for (f, &ajr) in fixed.iter_mut().zip(a.column(j).iter()) {
                    *f += ajr * x[j];
                }
            }
        }
        LocalSolve {
            problem,
            lay,
            pull,
            scale: 1.0 / b.norm().max(f64::MIN_POSITIVE),
            fixed,
            varying: (0..x.len()).filter(|&j| set[j]).collect(),
            xl: x.clone(),
            jac: Vec::new(),
            upper: Vec::new(),
        }
    }

    /// The residual at `y`, into `out` (its buffers reused).
    pub(crate) fn evaluate(&mut self, y: &DVector<f64>, out: &mut Residual) {
        lift_into(self.problem, self.lay, y, &mut self.xl);
        let a = &self.problem.solution.matrix;
        out.clear();
        out.balance.extend_from_slice(&self.fixed);
        for &j in &self.varying {
            let v = self.xl[j];
            for (r, &ajr) in out.balance.iter_mut().zip(a.column(j).iter()) {
                *r += ajr * v;
            }
        }
        for r in out.balance.iter_mut() {
            *r *= self.scale;
        }
        bound_hinges(self.problem, self.lay, y, out);
        let mut squares: f64 = out.balance.iter().map(|r| r * r).sum();
        out.balance_norm = squares.sqrt();
        squares += out.hinges.iter().map(|h| h.0.max(0.0).powi(2)).sum::<f64>();
        if let Some((target, weight)) = self.pull {
            squares += (0..y.len())
                .map(|j| (weight * (y[j] - target[j])).powi(2))
                .sum::<f64>();
        }
        out.cost = squares.sqrt();
    }

    /// The Gauss–Newton normal equations `(JᵀJ, Jᵀr)` at `y`, whose residual is `res`: the
    /// balance block dense, each active hinge's outer product from its few entries, the pull's
    /// diagonal.
    pub(crate) fn normal_equations(
        &mut self,
        y: &DVector<f64>,
        res: &Residual,
    ) -> (DMatrix<f64>, DVector<f64>) {
        let n = self.lay.unknowns;
        let rows = res.balance.len();
        lift_into(self.problem, self.lay, y, &mut self.xl);
        self.jac.clear();
        self.jac.resize(rows * n, 0.0);
        balance_jacobian(
            self.problem,
            self.lay,
            y,
            &self.xl,
            self.scale,
            &mut self.jac,
        );
        // The upper triangle of `JᵀJ` accumulated row by row of `J` into a row-major buffer
        // (contiguous in `j`), then mirrored.
        self.upper.clear();
        self.upper.resize(n * n, 0.0);
        let mut g = DVector::zeros(n);
        for (row, &r) in self.jac.chunks_exact(n).zip(&res.balance) {
            for i in 0..n {
                let ji = row[i];
                if ji == 0.0 {
                    continue;
                }
                g[i] += ji * r;
                for (acc, &rj) in self.upper[i * n + i..(i + 1) * n].iter_mut().zip(&row[i..]) {
                    *acc += ji * rj;
                }
            }
        }
        let upper = &self.upper;
        let mut jtj = DMatrix::from_fn(n, n, |i, j| {
            if i <= j {
                upper[i * n + j]
            } else {
                upper[j * n + i]
            }
        });
        for &(value, first, last) in &res.hinges {
            if value <= 0.0 {
                continue;
            }
            let grad = &res.grads[first..last];
            for &(i, gi) in grad {
                g[i] += gi * value;
                for &(j, gj) in grad {
                    jtj[(i, j)] += gi * gj;
                }
            }
        }
        if let Some((target, weight)) = self.pull {
            for j in 0..n {
                jtj[(j, j)] += weight * weight;
                g[j] += weight * weight * (y[j] - target[j]);
            }
        }
        (jtj, g)
    }
}

/// The bound hinges at `y`: per spring `ln K` within its stiffness bounds, each anchor's length
/// within its range and each anchor component within its box; per counterweight (joint mode)
/// its scaled mass and radius within their bounds.
fn bound_hinges(problem: &VariantProblem, lay: &Layout, y: &DVector<f64>, out: &mut Residual) {
    for (k, s) in problem.springs.iter().enumerate() {
        let u = lay.start[k];
        let (na, nb) = (s.axes_a.len(), s.axes_b.len());
        let [ln_klo, ln_khi] = lay.ln_stiffness[k];
        if s.bounds.stiffness[0] > 0.0 {
            out.hinge(ln_klo - y[u], &[(u, -1.0)]);
        }
        out.hinge(y[u] - ln_khi, &[(u, 1.0)]);
        for (range, offset, n) in [(s.bounds.anchor_a, 1, na), (s.bounds.anchor_b, 1 + na, nb)] {
            let v = &y.as_slice()[u + offset..u + offset + n];
            let len = norm(v);
            let l = range[1].max(1e-3);
            let mut low = [(0usize, 0.0f64); 3];
            let mut high = [(0usize, 0.0f64); 3];
            for i in 0..n {
                let unit = if len > 0.0 { v[i] / len } else { 0.0 };
                low[i] = (u + offset + i, -unit / l);
                high[i] = (u + offset + i, unit / l);
            }
            out.hinge((range[0] - len) / l, &low[..n]);
            out.hinge((len - range[1]) / l, &high[..n]);
        }
        // Anchor boxes per body-frame axis.
        for (bx, axes, offset, reach) in [
            (&s.bounds.box_a, &s.axes_a, 1, s.bounds.anchor_a[1]),
            (&s.bounds.box_b, &s.axes_b, 1 + na, s.bounds.anchor_b[1]),
        ] {
            let l = reach.max(1e-3);
            for (i, &axis) in axes.iter().enumerate() {
                let [lo, hi] = bx[axis];
                let c = y[u + offset + i];
                if lo.is_finite() {
                    out.hinge((lo - c) / l, &[(u + offset + i, -1.0 / l)]);
                }
                if hi.is_finite() {
                    out.hinge((c - hi) / l, &[(u + offset + i, 1.0 / l)]);
                }
            }
        }
    }
    for (c, &u) in problem.counterweights.iter().zip(&lay.cw_start) {
        let (big_m, big_r) = cw_scales(c);
        let n = c.axes.len();
        let mu = &y.as_slice()[u + 1..u + 1 + n];
        let len = norm(mu);
        let unit = |k: usize| if len > 0.0 { mu[k] / len } else { 0.0 };
        let [mlo, mhi] = [c.min_mass() / big_m, c.bounds.mass[1] / big_m];
        out.hinge(mlo - y[u], &[(u, -1.0)]);
        out.hinge(y[u] - mhi, &[(u, 1.0)]);
        let hi = c.bounds.radius[1] * big_m / big_r;
        let lo = c.bounds.radius[0] * big_m / big_r;
        let mut grad = [(0usize, 0.0f64); 4];
        for k in 0..n {
            grad[k] = (u + 1 + k, unit(k));
        }
        grad[n] = (u, -hi);
        out.hinge(len - hi * y[u], &grad[..n + 1]);
        for k in 0..n {
            grad[k] = (u + 1 + k, -unit(k));
        }
        grad[n] = (u, lo);
        out.hinge(lo * y[u] - len, &grad[..n + 1]);
    }
}

fn levenberg_marquardt(
    problem: &VariantProblem,
    b: &DVector<f64>,
    x: &DVector<f64>,
    lay: &Layout,
    mut y: DVector<f64>,
    pull: Option<(&DVector<f64>, f64)>,
) -> (DVector<f64>, f64, f64) {
    let mut solve = LocalSolve::new(problem, b, x, lay, pull);
    let mut res = Residual::default();
    let mut trial = Residual::default();
    solve.evaluate(&y, &mut res);
    let mut lambda = 1e-3;
    let mut slow = 0;
    // A start creeping along (less than 0.1 % per step for `CREEP_STEPS` steps) is heading for
    // a solution outside the bounds or at infinity: give it up. A pulled solve only prepares
    // the start of the unpulled one, so its creep ends it sooner.
    let creep = if pull.is_some() {
        PULLED_CREEP_STEPS
    } else {
        CREEP_STEPS
    };
    for _ in 0..300 {
        if slow >= creep {
            break;
        }
        if pull.is_none() && res.balance_norm <= SOLVED_TOL && res.hinge_max <= BOUND_TOL {
            break;
        }
        let (jtj, g) = solve.normal_equations(&y, &res);
        let mut improved = false;
        for _ in 0..12 {
            let mut damped = jtj.clone();
            for i in 0..lay.unknowns {
                damped[(i, i)] += lambda * (jtj[(i, i)] + 1e-12);
            }
            let Some(ch) = damped.cholesky() else {
                lambda *= 10.0;
                continue;
            };
            let mut cand = -&g;
            ch.solve_mut(&mut cand);
            cand += &y;
            for &u in &lay.start {
                cand[u] = cand[u].clamp(-30.0, 30.0);
            }
            solve.evaluate(&cand, &mut trial);
            let c2 = trial.cost;
            if c2.is_finite() && c2 < res.cost {
                let gain = (res.cost - c2) / res.cost.max(f64::MIN_POSITIVE);
                y = cand;
                std::mem::swap(&mut res, &mut trial);
                lambda = (lambda / 3.0).max(1e-15);
                improved = gain > 1e-15;
                slow = if gain < 1e-3 { slow + 1 } else { 0 };
                break;
            }
            lambda *= 4.0;
        }
        if !improved {
            break;
        }
    }
    (y, res.balance_norm, res.hinge_max)
}

/// Physical springs at `y`.
fn values(problem: &VariantProblem, lay: &Layout, y: &DVector<f64>) -> Vec<Spring> {
    problem
        .springs
        .iter()
        .enumerate()
        .map(|(k, s)| {
            let u = lay.start[k];
            let na = s.axes_a.len();
            let mut anchor_a = [0.0; 3];
            let mut anchor_b = [0.0; 3];
            for (i, &ax) in s.axes_a.iter().enumerate() {
                anchor_a[ax] = y[u + 1 + i];
            }
            for (l, &ax) in s.axes_b.iter().enumerate() {
                anchor_b[ax] = y[u + 1 + na + l];
            }
            Spring {
                label: s.label.clone(),
                body: s.bodies[0].clone(),
                other: s.bodies[1].clone(),
                stiffness: y[u].exp(),
                anchor_a,
                anchor_b,
                plane: None,
            }
        })
        .collect()
}

/// One admissible spring set and the full lifted point with it.
pub type Realized = (Vec<Spring>, DVector<f64>);

/// The local solves of one [`realize_springs_reusing`] call: the lifted point they ran for and,
/// per start, the point reached with its balance residual and bound excess.
#[derive(Clone, Debug)]
pub struct StartRecord {
    x: DVector<f64>,
    joint: bool,
    seed: u64,
    outcomes: Vec<(DVector<f64>, f64, f64)>,
    reused: usize,
}

impl StartRecord {
    /// Starts whose local solve was taken from the previous record.
    pub fn reused(&self) -> usize {
        self.reused
    }

    /// Whether start `start` (≥ 1) of a call for `x` would repeat the recorded one exactly:
    /// starts after the first draw their points from the same pseudo-random stream when the
    /// first start drew the same numbers (it draws a stiffness for each spring whose lifted
    /// `K` is not positive), and the local solve reads `x` only outside the springs' columns.
    fn repeats(&self, problem: &VariantProblem, x: &DVector<f64>, joint: bool, seed: u64) -> bool {
        if joint || self.joint || x.len() != self.x.len() || seed != self.seed {
            return false;
        }
        let mut spring_column = vec![false; x.len()];
        for s in &problem.springs {
            if (x[s.column] > 0.0) != (self.x[s.column] > 0.0) {
                return false;
            }
            for c in s.column..s.column + s.lifted_len() {
                spring_column[c] = true;
            }
        }
        (0..x.len()).all(|c| spring_column[c] || x[c].to_bits() == self.x[c].to_bits())
    }
}

/// Admissible spring sets for the lifted point `x` (its counterweight part is kept), from
/// `starts` deterministic starts; distinct solutions only, in order of discovery.
///
/// With `joint`, the counterweights move too (starting from, and pulled towards, their values
/// in `x`): the fallback when the counterweights that are best for the motors leave no
/// admissible springs.
pub fn realize_springs(
    problem: &VariantProblem,
    b: &DVector<f64>,
    x: &DVector<f64>,
    starts: usize,
    joint: bool,
) -> (Vec<Realized>, String) {
    let (found, note, _) = realize_springs_reusing(problem, b, x, starts, joint, None);
    (found, note)
}

/// [`realize_springs`] that takes the local solves of starts after the first from `previous`
/// where they would repeat exactly (see [`StartRecord`]), and records its own. The result is
/// the same bits as without `previous`: the spring choice runs four times the starts of the
/// critical-task pass for the same counterweights, and the pass's starts need not run twice.
pub fn realize_springs_reusing(
    problem: &VariantProblem,
    b: &DVector<f64>,
    x: &DVector<f64>,
    starts: usize,
    joint: bool,
    previous: Option<&StartRecord>,
) -> (Vec<Realized>, String, StartRecord) {
    realize_springs_seeded(problem, b, x, starts, joint, previous, DEFAULT_SEED)
}

/// The lifted point `x` with every spring's columns replaced by a spring that depends on the
/// bounds alone: the stiffness at the geometric middle of its range (of `[K_max·1e-3, K_max]`
/// when the lower bound is 0), both anchors at the origin. Realized from this point, the first
/// start of [`realize_springs_reusing`] no longer reads the springs a search happened to
/// realize, so the realizations depend on the counterweights alone; its stiffness is positive,
/// so that start draws nothing from the stream and the later starts are those of `x`.
pub fn springs_from_bounds(problem: &VariantProblem, x: &DVector<f64>) -> DVector<f64> {
    let mut out = x.clone();
    for s in &problem.springs {
        let [klo, khi] = s.bounds.stiffness;
        let klo = if klo > 0.0 { klo } else { khi * 1e-3 };
        out[s.column] = (klo * khi).sqrt();
        for c in s.column + 1..s.column + s.lifted_len() {
            out[c] = 0.0;
        }
    }
    out
}

/// The seed of the starts after the first (the first start is the lifted point itself).
pub const DEFAULT_SEED: u64 = 0x5917_6e55_0000_0001;

/// [`realize_springs_reusing`] with the starts after the first drawn from `seed`'s stream.
/// The certified stage makes the verdicts and optima independent of it; `run --seed` sets it to
/// show that.
pub fn realize_springs_seeded(
    problem: &VariantProblem,
    b: &DVector<f64>,
    x: &DVector<f64>,
    starts: usize,
    joint: bool,
    previous: Option<&StartRecord>,
    seed: u64,
) -> (Vec<Realized>, String, StartRecord) {
    let lay = layout(problem, joint);
    let mut record = StartRecord {
        x: x.clone(),
        joint,
        seed,
        outcomes: Vec::new(),
        reused: 0,
    };
    if lay.unknowns == 0 {
        return (vec![(Vec::new(), x.clone())], String::new(), record);
    }
    let reuse = previous.filter(|p| p.repeats(problem, x, joint, seed));
    let mut rng = SplitMix64::new(seed);
    let mut found: Vec<Realized> = Vec::new();
    let mut best = (f64::INFINITY, f64::INFINITY);
    for start in 0..starts.max(1) {
        let mut y0 = DVector::zeros(lay.unknowns);
        for (k, s) in problem.springs.iter().enumerate() {
            let u = lay.start[k];
            let (na, nb) = (s.axes_a.len(), s.axes_b.len());
            let [klo, khi] = s.bounds.stiffness;
            let klo_eff = if klo > 0.0 { klo } else { khi * 1e-3 };
            let kk = if start == 0 && x[s.column] > 0.0 {
                x[s.column].clamp(klo_eff, khi)
            } else {
                (rng.uniform(klo_eff.ln(), khi.ln())).exp()
            };
            y0[u] = kk.ln();
            for (offset, n, range, lifted) in [
                (1, na, s.bounds.anchor_a, s.column + 1),
                (1 + na, nb, s.bounds.anchor_b, s.column + 1 + na),
            ] {
                if start == 0 {
                    for i in 0..n {
                        y0[u + offset + i] = x[lifted + i] / kk;
                    }
                } else {
                    let len = rng.uniform(range[0], range[1]);
                    let dir: Vec<f64> = (0..n).map(|_| rng.uniform(-1.0, 1.0)).collect();
                    let dn = norm(&dir).max(1e-12);
                    for i in 0..n {
                        y0[u + offset + i] = dir[i] / dn * len;
                    }
                }
            }
            // Start inside the anchor boxes.
            for (bx, axes, offset) in [
                (&s.bounds.box_a, &s.axes_a, 1),
                (&s.bounds.box_b, &s.axes_b, 1 + na),
            ] {
                for (i, &axis) in axes.iter().enumerate() {
                    let [lo, hi] = bx[axis];
                    y0[u + offset + i] = y0[u + offset + i].clamp(lo, hi);
                }
            }
        }
        for (c, &u) in problem.counterweights.iter().zip(&lay.cw_start) {
            let (big_m, big_r) = cw_scales(c);
            y0[u] = x[c.column] / big_m;
            for k in 0..c.axes.len() {
                y0[u + 1 + k] = x[c.column + 1 + k] / big_r;
            }
        }
        let recorded = reuse
            .and_then(|p| p.outcomes.get(start))
            .filter(|_| start > 0);
        let (y, bal, hinge) = match recorded {
            Some(outcome) => {
                record.reused += 1;
                outcome.clone()
            }
            None => {
                let target = y0.clone();
                let pull = Some((&target, 1e-3));
                let (y1, _, _) = levenberg_marquardt(problem, b, x, &lay, y0, pull);
                levenberg_marquardt(problem, b, x, &lay, y1, None)
            }
        };
        record.outcomes.push((y.clone(), bal, hinge));
        if bal < best.0 {
            best = (bal, hinge);
        }
        if bal <= SOLVED_TOL && hinge <= BOUND_TOL {
            let v = values(problem, &lay, &y);
            let duplicate = found.iter().any(|(f, _)| {
                f.iter().zip(&v).all(|(p, q)| {
                    (p.stiffness - q.stiffness).abs() <= 1e-6 * q.stiffness
                        && (0..3).all(|i| {
                            (p.anchor_a[i] - q.anchor_a[i]).abs() < 1e-6
                                && (p.anchor_b[i] - q.anchor_b[i]).abs() < 1e-6
                        })
                })
            });
            if !duplicate {
                let xl = lifted_with(problem, x, &lay, &y);
                found.push((v, xl));
            }
        }
    }
    let note = if found.is_empty() {
        format!(
            "no spring parameters within the bounds balance the variant with these counterweights \
             ({} starts; best relative balance residual {:.2e}, bound excess {:.2e})",
            starts.max(1),
            best.0,
            best.1
        )
    } else {
        String::new()
    };
    (found, note, record)
}
