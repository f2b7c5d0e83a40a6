//! The convex relaxation (a certified lower bound), solved with clarabel.
//!
//! Variables: the free coordinates `z` of the balanced family, and per counterweight the
//! second moment `S` (entries over its plane axes) and `p`, standing for `m^{5/3}`. The torque
//! at every working-set sample is affine in `(m, μ, S, p)`:
//! `I_o = p·J(1 kg) + tr(S)·I − S`. The non-convex identities are relaxed:
//!
//! - `S = μμᵀ/m` → `S_aa·m ≥ μ_a²` per axis, `tr(S)·m ≥ |μ|²`, `dᵀSd·m ≥ (dᵀμ)²` along the
//!   diagonals `d = (e_a ± e_b)/√2`, `S` positive semidefinite per 2×2 block (all rotated or
//!   plain second-order cones), and the linear `r_lo²·m ≤ tr(S) ≤ r_hi²·m` (true because
//!   `tr S = m|r|²`);
//! - `p = m^{5/3}` → `p` above tangents of `m^{5/3}` in the boxes ([`tangent_points`]; the power
//!   cone `p^{3/5} ≥ m` in the relaxation that starts the designs, see [`CylinderInertia`]) and
//!   `p` below the chord of `m^{5/3}` over the mass range;
//! - `|r| ≥ r_lo`, `|a| ≥ a_lo`, `|b| ≥ b_lo` and spring realizability (`K·W = αβᵀ`) are dropped.
//!
//! Anchor boxes from the case's overrides (`lo ≤ a_i ≤ hi` per body-frame axis) are linear in
//! the lifted variables, `lo·K ≤ (K a)_i ≤ hi·K`, and kept exactly.
//!
//! The bounds that are convex in the lifted variables are kept exactly: masses, `|μ| ≤ r_hi·m`,
//! stiffnesses, `|K a| ≤ a_hi·K`, `|K b| ≤ b_hi·K`, `|K a_k b_l| ≤ a_hi·b_hi·K`; the peak limits are linear inequalities at
//! every working-set sample. The objective is RMS* (`min ‖t‖/√N`, `t_n ≥` the RMS of actuator
//! `n` on each working-set task) or, for minimax, `min u`, `u ≥ Σ_n RMS_{n,w}` per task.
//!
//! Every physical point is feasible here with the same objective, so the optimum is a lower
//! bound of the working-set problem; since the working-set objective never exceeds the
//! all-task one, it bounds the true optimum too.

use std::sync::Arc;

use counterpoise_dynamics::params::BODY_PARAMS;
use nalgebra::{DMatrix, DVector};

use crate::certify::node::{Coordinate, NodeBox, square_over_linear_planes};
use crate::clarabel_map::{Affine, ConicProblem, ConicSolution, ConicStatus};
use crate::problem::{Objective, VariantProblem};
use crate::torque::TaskTorques;

/// Relative margin taken off the relaxation's value: clarabel meets its optimality conditions
/// to its tolerance (1e-8 by default), so the dual value may exceed the exact optimum by about
/// that much; the margin is the larger of this and ten times the tolerance of the run.
pub const BOUND_MARGIN: f64 = 1e-7;

/// clarabel's optimality and feasibility tolerance on a branch-and-bound box (instead of its
/// default 1e-8). A box's value is only a bound, taken with a margin of ten times this
/// (1e-5 relative, far inside the 1e-3 gap tolerance), and the last two digits cost about
/// 40 % of the stage's time: on the palletizer's m3 + m5 + K53 at Dmax 3, 400 boxes took 43 s
/// CPU at 1e-8 and 25 s at 1e-6 (the search's path changes, so its gap does too: 7.4 % →
/// 6.0 % there). Retries that clarabel needs use the looser of theirs and this.
pub const BOX_TOLERANCE: f64 = 1e-6;

/// Largest ratio between consecutive masses at which the relaxation takes a tangent of
/// `m^{5/3}` (see [`tangent_points`]): between two of them the tangents stay within 2.25 % of
/// the curve (the largest relative gap is 0.46 % at a ratio of 1.2, 2.25 % at 1.5, 6.4 % at 2,
/// about `(q − 1)²/7` as `q` nears 1).
pub const TANGENT_RATIO: f64 = 1.5;

/// Fraction of the upper mass bound below which the tangents are not spread: a counterweight
/// lighter than a thousandth of its bound has a cylinder inertia below 1e-5 of the largest.
const TANGENT_FLOOR: f64 = 1e-3;

/// The masses at which `p ≥ m^{5/3}` is taken by its tangents over `[lo, hi]`: geometric from
/// `max(lo, TANGENT_FLOOR·hi)` to `hi` with ratios of at most [`TANGENT_RATIO`], and `lo`
/// itself when it is positive and below that floor.
///
/// Why tangents instead of the power cone `p^{3/5} ≥ m`: one power cone makes clarabel take
/// its non-symmetric path (no Nesterov–Todd scaling) for the whole problem, and every box of
/// the branch-and-bound paid for it. Tangents of a convex function lie below it, so the
/// relaxation stays valid; only its bound can be lower, by the inertia the gap between the
/// tangents and the curve leaves out, and a box's own tangents at its mass interval's ends
/// and geometric middle close that gap as the boxes shrink.
pub fn tangent_points(lo: f64, hi: f64) -> Vec<f64> {
    if !(hi > 0.0 && hi.is_finite()) {
        return Vec::new();
    }
    let start = lo.max(TANGENT_FLOOR * hi).min(hi);
    let steps = ((hi / start).ln() / TANGENT_RATIO.ln()).ceil().max(0.0) as usize;
    let mut points: Vec<f64> = Vec::with_capacity(steps + 2);
    if lo > 0.0 && lo < start {
        points.push(lo);
    }
    for i in 0..=steps {
        let t = if steps == 0 {
            hi
        } else {
            start * (hi / start).powf(i as f64 / steps as f64)
        };
        points.push(t);
    }
    points
}

/// `p' ≥` the tangent of `m^{5/3}` at the mass `t`, in the relaxation's normalised variables
/// (`p = M^{5/3}·p'`, `m = M·mn`): `p' − (5/3)·t^{2/3}·(M/M^{5/3})·mn + (2/3)·t^{5/3}/M^{5/3} ≥ 0`.
fn below_five_thirds_tangent(cp: &mut ConicProblem, p: usize, mn: &Affine, big_m: f64, t: f64) {
    let big_p = big_m.powf(5.0 / 3.0);
    let mut cut = mn.scaled(-(5.0 / 3.0) * t.powf(2.0 / 3.0) * big_m / big_p);
    cut.constant += (2.0 / 3.0) * t.powf(5.0 / 3.0) / big_p;
    cut.add_var(p, 1.0);
    cp.nonneg(&cut);
}

/// Result of the relaxation.
#[derive(Clone, Debug)]
pub struct Relaxed {
    pub solution: ConicSolution,
    /// Free coordinates of the relaxed optimum.
    pub z: DVector<f64>,
    /// The lower bound: the smaller of the primal and dual objective values (the dual value is
    /// the certificate; clarabel's primal value may exceed the optimum by its tolerance).
    pub bound: f64,
    /// Per counterweight, how far the relaxed second moments and `p` are from the physical
    /// `μμᵀ/m` and `m^{5/3}` at the relaxed `(m, μ)`, relative to their scales (0 when solved
    /// exactly; what the branch-and-bound splits to remove).
    pub cw_errors: Vec<f64>,
    /// On a box, the ends of the branching coordinates whose rows the dual weighs (see
    /// [`EndRate`]). Empty without a box or a solved relaxation.
    pub reduced: Vec<EndRate>,
}

/// The dual rate of one end of a box's branching coordinate: every point of the box's
/// relaxation has an objective of at least its bound plus `rate·d`, `d` the coordinate's
/// distance from that end of its interval (weak duality on the end's row, whose value is at
/// least `per_unit·d`; see [`NodeRow`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EndRate {
    /// The coordinate, in [`crate::certify::node::coordinates`] order.
    pub coordinate: usize,
    /// The upper end (else the lower).
    pub upper: bool,
    /// Objective units per unit of the coordinate, > 0.
    pub rate: f64,
}

/// A row of a box that bounds one branching coordinate (in [`crate::certify::node::coordinates`]
/// order) on one side: its value is at least `per_unit` times the coordinate's distance from
/// that end of its interval (`K·(a_i − lo)/A` for an anchor, with `K ≥ K_lo` and `A` the
/// lifted column's scale; `(m − lo)/M` for a mass; `(μ_k − lo)/R` for a first moment; and
/// likewise from the upper end).
#[derive(Clone, Copy, Debug)]
struct NodeRow {
    coordinate: usize,
    upper: bool,
    row: usize,
    per_unit: f64,
}

/// Index of the `S` entry `(a, b)`, `a ≤ b`, among a counterweight's axes pairs.
fn pairs(n: usize) -> Vec<(usize, usize)> {
    let mut v = Vec::new();
    for a in 0..n {
        for b in a..n {
            v.push((a, b));
        }
    }
    v
}

/// The index into `π` of `I_ab` for body axes `a ≤ b`.
fn inertia_index(a: usize, b: usize) -> usize {
    match (a, b) {
        (0, 0) => 4,
        (1, 1) => 5,
        (2, 2) => 6,
        (0, 1) => 7,
        (0, 2) => 8,
        (1, 2) => 9,
        _ => unreachable!(),
    }
}

/// Natural magnitude of each lifted variable (mass bound, `m·r` bound, stiffness bound, …), used
/// to scale rows and the free coordinates so that every quantity clarabel sees is O(1).
fn natural_scales(problem: &VariantProblem) -> Vec<f64> {
    let mut scale = vec![1.0; problem.particular.len()];
    for c in &problem.counterweights {
        let m = c.bounds.mass[1].max(1e-9);
        scale[c.column] = m;
        for k in 0..c.axes.len() {
            scale[c.column + 1 + k] = (m * c.bounds.radius[1]).max(1e-9 * m);
        }
    }
    for s in &problem.springs {
        let k = s.bounds.stiffness[1].max(1e-9);
        let (na, nb) = (s.axes_a.len(), s.axes_b.len());
        let a = s.bounds.anchor_a[1].max(1e-3);
        let b = s.bounds.anchor_b[1].max(1e-3);
        scale[s.column] = k;
        for i in 0..na {
            scale[s.column + 1 + i] = k * a;
        }
        for l in 0..nb {
            scale[s.column + 1 + na + l] = k * b;
        }
        for i in 0..na * nb {
            scale[s.column + 1 + na + nb + i] = k * a * b;
        }
    }
    scale
}

/// A lifted quantity the torque is linear in (a counterweight's `m`, `μ_a`, `S_ab` or `p`),
/// as an affine expression of the conic variables, with its torque columns.
struct Feature {
    expr: Affine,
    /// (slot, π index, coefficient) — torque per unit feature = Σ coef·sens(slot, idx).
    parts: Vec<(usize, usize, f64)>,
}

/// Rows of a compressed RMS tail at or below this fraction of its largest row are left out.
///
/// Where a torque does not depend on some features (a motor the counterweight's body does not
/// load) or depends on them only in fixed combinations (a planar arm sees one moment of
/// inertia), `T` has lower rank than its width, and a column that depends on the columns
/// before it, with no independent column after it, leaves a row of `R` that holds only the
/// QR's rounding (1e-17 to 1e-23 of the largest on the palletizer, against 1e-5 and more for a
/// real row; most motors' tails there shrink from 8 rows to 1–7). Such a row adds a cone
/// dimension that carries nothing but still costs the solver a row of every factorisation.
/// Leaving a row out can only shrink the norm, so the cone is a relaxation of the full one and
/// every bound the search takes from it stays valid.
pub(crate) const NEGLIGIBLE_TAIL_ROW: f64 = 1e-12;

/// The tail of actuator `a`'s RMS cone on one task: expressions whose Euclidean norm is
/// `w·‖τ_a‖` over the task's samples.
///
/// The sampled torque is `τ_a = T e` with `e = (1, f_1, …, f_F)` the features and `T` the
/// `samples × (1 + F)` matrix of the base torque and the feature columns. For the QR
/// factorisation `T = Q R`, `‖T e‖ = ‖R e‖` for every `e`, so the `1 + F` rows of `R e` stand
/// for the 51 sample rows exactly: the same cone, the same optimum, a much smaller problem for
/// the solver (an orthogonal transformation, backward stable).
fn rms_tail(task: &TaskTorques, a: usize, w: f64, features: &[Feature]) -> Vec<Affine> {
    let na = task.actuators;
    let n = task.samples;
    let width = 1 + features.len();
    let mut t = DMatrix::<f64>::zeros(n, width);
    for s in 0..n {
        t[(s, 0)] = w * task.base[s * na + a];
        for (k, f) in features.iter().enumerate() {
            let coef: f64 = f
                .parts
                .iter()
                .map(|&(slot, j, c)| c * task.sens(slot, j)[s * na + a])
                .sum();
            t[(s, 1 + k)] = w * coef;
        }
    }
    let rows = if n > width { t.qr().r() } else { t };
    let largest = (0..rows.nrows())
        .map(|i| rows.row(i).norm())
        .fold(0.0f64, f64::max);
    let tail: Vec<Affine> = (0..rows.nrows())
        .filter(|&i| rows.row(i).norm() > NEGLIGIBLE_TAIL_ROW * largest)
        .map(|i| {
            let mut e = Affine::constant(rows[(i, 0)]);
            for (k, f) in features.iter().enumerate() {
                let c = rows[(i, 1 + k)];
                if c != 0.0 {
                    e.add_scaled(&f.expr, c);
                }
            }
            e
        })
        .collect();
    if tail.is_empty() {
        // A motor that no sample loads: one zero row keeps the cone `t ≥ 0` a proper one.
        return vec![Affine::constant(0.0)];
    }
    tail
}

/// Builds and solves the relaxation on the working-set tasks, with `p ≥ m^{5/3}` exact
/// ([`CylinderInertia::PowerCone`]): its optimum is where the critical-task loop starts its
/// designs, and for a variant whose only non-convexity is the cylinder's inertia (a lone
/// counterweight) it is the optimum itself.
pub fn solve_relaxation(
    problem: &VariantProblem,
    tasks: &[Arc<TaskTorques>],
    objective: Objective,
    max_iter: u32,
) -> Relaxed {
    RelaxationBase::with_inertia(problem, tasks, objective, CylinderInertia::PowerCone).solve(
        problem,
        None,
        max_iter,
        &mut Vec::new(),
    )
}

/// How the relaxation takes the cylinder inertia's `p ≥ m^{5/3}`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CylinderInertia {
    /// Exactly, by the power cone `p^{3/5} ≥ m`. clarabel then takes its non-symmetric path
    /// for the whole problem (more iterations, each dearer).
    PowerCone,
    /// By tangents at [`tangent_points`] (and, in a box, at its mass interval's ends and
    /// geometric middle): only second-order and linear cones, for a bound lower by at most the
    /// inertia the tangents' gap (≤ 2.25 % of `m^{5/3}`) leaves out (8.6e-5 of the root bound
    /// of the palletizer's m4 + K72). On the 44 variants of the palletizer that take 100 boxes
    /// or more at Dmax 3, the searches took 100 s of CPU instead of 146 s (3.5 ms per box
    /// instead of 4.7), every gap closed. Denser tangents (ratio 1.2) give up a quarter as
    /// much bound but cost 12 % more time; sparser ones (2.0), 5 % more.
    Tangents,
}

/// [`solve_relaxation`] restricted to a branch-and-bound node's box (see
/// [`crate::certify`]): every split coordinate within its interval (linear rows, exact since
/// `K > 0` and `m > 0`), the spring couplings `W = K a⊗b` between the homogenised McCormick
/// planes of the anchor intervals, and the counterweights' second moments and `m^{5/3}` below
/// the planes through the box's corners. Every physical point in the box is feasible here with
/// its true objective, so the optimum bounds the box from below; as the box shrinks to a point
/// the rows pin the lifted point to a physical one.
pub fn solve_relaxation_in(
    problem: &VariantProblem,
    tasks: &[Arc<TaskTorques>],
    objective: Objective,
    max_iter: u32,
    node: Option<&NodeBox>,
) -> Relaxed {
    RelaxationBase::new(problem, tasks, objective).solve(problem, node, max_iter, &mut Vec::new())
}

/// A relaxation ready to solve: the problem, its lazily added peak rows, the conic variables of
/// the scaled free coordinates `ζ` (`z = D ζ`, `dz` the diagonal of `D`), the torque scale, and
/// the natural magnitude of each lifted variable.
#[derive(Clone)]
struct Built {
    cp: ConicProblem,
    /// The peak rows a solve may add (shared: every box's copy of the base reads the same).
    peaks: Arc<[Affine]>,
    z: Vec<usize>,
    dz: Vec<f64>,
    tau_scale: f64,
    natural: Vec<f64>,
    cw_vars: Vec<CwVars>,
    /// The box's rows that bound its coordinates (empty without a box).
    node_rows: Vec<NodeRow>,
}

/// A counterweight's own conic variables: its normalised second moments (one per pair of plane
/// axes, in [`pairs`] order), `p` standing for `m^{5/3}` (when the shape has inertia), and the
/// second moments' scale `σ`.
#[derive(Clone)]
struct CwVars {
    s_vars: Vec<usize>,
    p: Option<usize>,
    sigma: f64,
}

impl Built {
    /// `x_j / natural_j` as an affine expression of the scaled free coordinates.
    fn xn(&self, problem: &VariantProblem, j: usize) -> Affine {
        let mut e = Affine::constant(problem.particular[j] / self.natural[j]);
        for k in 0..problem.dim() {
            let c = problem.nullspace[(j, k)] * self.dz[k] / self.natural[j];
            if c != 0.0 {
                e.add_var(self.z[k], c);
            }
        }
        e
    }

    /// Solves, with the peak rows added lazily (those marked in `active` from the start;
    /// `active` returns the rows used).
    fn solve(mut self, problem: &VariantProblem, max_iter: u32, active: &mut Vec<bool>) -> Relaxed {
        active.resize(self.peaks.len(), false);
        let solution = solve_with_peaks_from(&mut self.cp, &self.peaks, active, max_iter);
        let zv = DVector::from_iterator(
            problem.dim(),
            self.z
                .iter()
                .zip(&self.dz)
                .map(|(&j, &s)| solution.x[j] * s),
        );
        let x = problem.lifted(&zv);
        let cw_errors = problem
            .counterweights
            .iter()
            .zip(&self.cw_vars)
            .map(|(c, vars)| {
                let m = x[c.column];
                if m.is_nan()
                    || m <= 0.0
                    || solution.x.len() <= vars.s_vars.iter().copied().max().unwrap_or(0)
                {
                    return 0.0;
                }
                let n = c.axes.len();
                let mu: Vec<f64> = (0..n).map(|k| x[c.column + 1 + k]).collect();
                let mut error = 0.0;
                for (idx, &(a, b)) in pairs(n).iter().enumerate() {
                    let relaxed = solution.x[vars.s_vars[idx]] * vars.sigma;
                    error += (relaxed - mu[a] * mu[b] / m).abs() / vars.sigma;
                }
                if let Some(p) = vars.p {
                    let big_p = self.natural[c.column].powf(5.0 / 3.0);
                    error += (solution.x[p] * big_p - m.powf(5.0 / 3.0)).abs() / big_p;
                }
                error
            })
            .collect();
        let reduced = if solution.status == ConicStatus::Solved {
            self.node_rows
                .iter()
                .filter_map(|r| {
                    let rate = self.tau_scale * solution.dual.get(r.row)?.max(0.0) * r.per_unit;
                    (rate > 0.0 && rate.is_finite()).then_some(EndRate {
                        coordinate: r.coordinate,
                        upper: r.upper,
                        rate,
                    })
                })
                .collect()
        } else {
            Vec::new()
        };
        Relaxed {
            bound: self.tau_scale
                * solution.objective.min(solution.dual_objective)
                * (1.0 - BOUND_MARGIN.max(10.0 * solution.tolerance)),
            z: zv,
            solution,
            cw_errors,
            reduced,
        }
    }
}

/// The relaxation of one variant on one set of tasks, built once and solved on many boxes:
/// a node's rows ([`solve_relaxation_in`]) are appended to a copy of it.
#[derive(Clone)]
pub struct RelaxationBase(Built);

impl RelaxationBase {
    /// The relaxation the branch-and-bound's boxes solve: `p ≥ m^{5/3}` by its tangents
    /// ([`CylinderInertia::Tangents`]).
    pub fn new(problem: &VariantProblem, tasks: &[Arc<TaskTorques>], objective: Objective) -> Self {
        Self::with_inertia(problem, tasks, objective, CylinderInertia::Tangents)
    }

    /// The relaxation with `p ≥ m^{5/3}` taken as `inertia` says.
    pub fn with_inertia(
        problem: &VariantProblem,
        tasks: &[Arc<TaskTorques>],
        objective: Objective,
        inertia: CylinderInertia,
    ) -> Self {
        RelaxationBase(build(problem, tasks, objective, inertia))
    }

    /// Solves the relaxation restricted to `node` (the whole family when `None`). The peak
    /// rows marked in `active` enter from the first round, and `active` returns the rows the
    /// solve used: a search that passes it from box to box saves the rounds of cutting planes
    /// (each round of any set of rows is a valid relaxation, so the bound is the same kind).
    pub fn solve(
        &self,
        problem: &VariantProblem,
        node: Option<&NodeBox>,
        max_iter: u32,
        active: &mut Vec<bool>,
    ) -> Relaxed {
        self.on_node(problem, node).solve(problem, max_iter, active)
    }

    /// This relaxation restricted to `node` (its rows added, solved to [`BOX_TOLERANCE`]), or
    /// the whole family's when `None`.
    fn on_node(&self, problem: &VariantProblem, node: Option<&NodeBox>) -> Built {
        let mut built = self.0.clone();
        if let Some(node) = node {
            add_node_rows(problem, &mut built, node);
            built.cp.set_tolerance(BOX_TOLERANCE);
        }
        built
    }

    /// The conic problem [`RelaxationBase::solve`] solves on `node` with every peak row in
    /// place (its last round).
    #[cfg(test)]
    pub(crate) fn box_problem(&self, problem: &VariantProblem, node: &NodeBox) -> ConicProblem {
        let mut built = self.on_node(problem, Some(node));
        for e in built.peaks.iter() {
            add_peak_row(&mut built.cp, e);
        }
        built.cp
    }

    /// Each row of `node`'s relaxation that bounds one coordinate: its coordinate (in
    /// [`crate::certify::node::coordinates`] order), its side, its `per_unit` and its value at
    /// the free point `z` (the conic variables other than `z`'s at 0).
    #[cfg(test)]
    pub(crate) fn node_row_values(
        &self,
        problem: &VariantProblem,
        node: &NodeBox,
        z: &DVector<f64>,
    ) -> Vec<(usize, bool, f64, f64)> {
        let mut built = self.0.clone();
        add_node_rows(problem, &mut built, node);
        let mut v = vec![0.0; built.cp.variables];
        for (k, (&j, &s)) in built.z.iter().zip(&built.dz).enumerate() {
            v[j] = z[k] / s;
        }
        built
            .node_rows
            .iter()
            .map(|r| {
                (
                    r.coordinate,
                    r.upper,
                    r.per_unit,
                    built.cp.row_value(r.row, &v),
                )
            })
            .collect()
    }

    /// Rows of the conic problem (without a node's rows or peak rows).
    pub fn rows(&self) -> usize {
        self.0.cp.rows()
    }

    /// This relaxation, solved with at most `attempts` of clarabel's runs per solve (see
    /// [`crate::clarabel_map::ConicProblem::limit_attempts`]).
    pub fn limit_attempts(mut self, attempts: u32) -> Self {
        self.0.cp.limit_attempts(attempts);
        self
    }

    /// The range of lifted variable `column` over this relaxation restricted to `node` (an
    /// interval that holds every physical point of the box): two solves, minimising and
    /// maximising it, with the task objective dropped. `None` when either solve does not end
    /// `Solved`; an empty interval when the relaxation is infeasible.
    pub fn lifted_range(
        &self,
        problem: &VariantProblem,
        node: Option<&NodeBox>,
        column: usize,
        max_iter: u32,
    ) -> Option<[f64; 2]> {
        self.combination_range(problem, node, &[(column, 1.0)], max_iter)
    }

    /// [`RelaxationBase::lifted_range`] of a linear combination `Σ c·x_column` of lifted
    /// variables, given as `(column, c)` terms.
    pub fn combination_range(
        &self,
        problem: &VariantProblem,
        node: Option<&NodeBox>,
        terms: &[(usize, f64)],
        max_iter: u32,
    ) -> Option<[f64; 2]> {
        let mut out = [0.0; 2];
        let natural = terms
            .iter()
            .map(|&(j, c)| c.abs() * self.0.natural[j])
            .fold(0.0f64, f64::max)
            .max(1e-300);
        for (side, sign) in [(0, 1.0), (1, -1.0)] {
            let mut built = self.0.clone();
            if let Some(node) = node {
                add_node_rows(problem, &mut built, node);
            }
            built.cp.objective.iter_mut().for_each(|c| *c = 0.0);
            let mut constant = 0.0;
            for &(column, c) in terms {
                for k in 0..problem.dim() {
                    built.cp.objective[built.z[k]] +=
                        sign * c * problem.nullspace[(column, k)] * built.dz[k] / natural;
                }
                constant += sign * c * problem.particular[column] / natural;
            }
            let solution = built.cp.solve(max_iter);
            if solution.status.is_infeasible() {
                return Some([f64::INFINITY, f64::NEG_INFINITY]);
            }
            if solution.status != ConicStatus::Solved {
                return None;
            }
            let low = solution.objective.min(solution.dual_objective) + constant;
            let margin = (BOUND_MARGIN.max(10.0 * solution.tolerance)) * (1.0 + low.abs());
            out[side] = sign * (low - margin) * natural;
        }
        Some(out)
    }

    /// The intervals of each spring's Lagrange vector (see [`lagrange_terms`]) over this
    /// relaxation restricted to `node`, for the springs with a lower anchor norm bound (an
    /// empty list for the others, and for any whose range is unknown).
    pub fn lagrange_ranges(
        &self,
        problem: &VariantProblem,
        node: Option<&NodeBox>,
        max_iter: u32,
    ) -> Vec<Vec<[f64; 2]>> {
        problem
            .springs
            .iter()
            .map(|s| {
                if s.bounds.anchor_a[0] <= 0.0 && s.bounds.anchor_b[0] <= 0.0 {
                    return Vec::new();
                }
                lagrange_terms(s)
                    .iter()
                    .map(|terms| self.combination_range(problem, node, terms, max_iter))
                    .collect::<Option<Vec<_>>>()
                    .filter(|r| r.iter().all(|[lo, hi]| lo <= hi))
                    .unwrap_or_default()
            })
            .collect()
    }

    /// This relaxation with each spring's anchor lengths bounded through its Lagrange vector:
    /// `v = (K a·b, K a×b)` has `|v| = K|a||b|` (Lagrange's identity `(a·b)² + |a×b|² =
    /// |a|²|b|²`), so the lower norm bound `|a| ≥ a_lo` gives `a_lo·|K b| ≤ |v|`, and
    /// `|v| ≤ Σ_i |v_i|`, each `|v_i|` below its chord over the interval `ranges` gives it
    /// (likewise `b_lo·|K a| ≤ |v|`). Every physical point whose Lagrange vector lies in those
    /// intervals meets these cones. Where balance fixes `v` (a spring that must carry a given
    /// moment) they bound `K b` exactly as the non-convex `|a| ≥ a_lo` does, which the
    /// relaxation otherwise drops and the search recovers only by splitting `a` around its
    /// excluded disc.
    pub fn with_lagrange_bounds(
        mut self,
        problem: &VariantProblem,
        ranges: &[Vec<[f64; 2]>],
    ) -> Self {
        let built = &mut self.0;
        for (s, ranges) in problem.springs.iter().zip(ranges) {
            let terms = lagrange_terms(s);
            if ranges.len() != terms.len() || terms.is_empty() {
                continue;
            }
            let (na, nb) = (s.axes_a.len(), s.axes_b.len());
            let big_k = built.natural[s.column];
            let a_nat = built.natural[s.column + 1] / big_k;
            let b_nat = built.natural[s.column + 1 + na] / big_k;
            let unit = big_k * a_nat * b_nat;
            // Σ_i chord_i(v_i), normalised by K̄·ā·b̄.
            let mut head = Affine::constant(0.0);
            for (component, &[lo, hi]) in terms.iter().zip(ranges) {
                let mut v = Affine::constant(0.0);
                for &(j, c) in component {
                    v.add_scaled(&built.xn(problem, j), c * built.natural[j] / unit);
                }
                let (lo, hi) = (lo / unit, hi / unit);
                if lo >= 0.0 {
                    head.add_scaled(&v, 1.0);
                } else if hi <= 0.0 {
                    head.add_scaled(&v, -1.0);
                } else {
                    let slope = (hi.abs() - lo.abs()) / (hi - lo);
                    head.constant += lo.abs() - slope * lo;
                    head.add_scaled(&v, slope);
                }
            }
            // The head is at least Σ min(|lo_i|, |hi_i|) over the intervals (each term is
            // linear between |lo_i| and |hi_i|).
            let least: f64 = ranges.iter().map(|&[lo, hi]| lo.abs().min(hi.abs())).sum();
            let k_hi = s.bounds.stiffness[1];
            for (floor, nat, first, n, reach) in [
                (
                    s.bounds.anchor_a[0],
                    a_nat,
                    s.column + 1 + na,
                    nb,
                    s.bounds.anchor_b[1],
                ),
                (
                    s.bounds.anchor_b[0],
                    b_nat,
                    s.column + 1,
                    na,
                    s.bounds.anchor_a[1],
                ),
            ] {
                // A cone that cannot cut (its cap above what `|K b| ≤ b_hi·K_hi` allows) is
                // left out: it changes no bound, and clarabel stalls on such far-inactive cones.
                if floor <= 0.0 || n == 0 || least >= floor * reach * k_hi {
                    continue;
                }
                // floor·|K b| / (K̄ ā b̄) = (floor/ā)·|K b|/(K̄ b̄) for the a floor (and b's).
                let tail: Vec<Affine> = (0..n)
                    .map(|i| built.xn(problem, first + i).scaled(floor / nat))
                    .collect();
                built.cp.soc(&head, &tail);
            }
        }
        self
    }
}

/// A spring's Lagrange vector `v = (K a·b, K (a×b)_x, K (a×b)_y, K (a×b)_z)` as linear
/// combinations `(lifted column, coefficient)` of its coupling entries `W_kl = K a_k b_l`
/// (over the body-frame axes the anchors have; components that are identically zero are left
/// out). `|v| = K|a||b|` at every physical point.
pub fn lagrange_terms(s: &crate::slots::SpringSlot) -> Vec<Vec<(usize, f64)>> {
    let (na, nb) = (s.axes_a.len(), s.axes_b.len());
    let column = |k: usize, l: usize| -> Option<usize> {
        let i = s.axes_a.iter().position(|&a| a == k)?;
        let j = s.axes_b.iter().position(|&b| b == l)?;
        Some(s.column + 1 + na + nb + i * nb + j)
    };
    let mut out = Vec::new();
    let dot: Vec<(usize, f64)> = (0..3)
        .filter_map(|d| column(d, d).map(|j| (j, 1.0)))
        .collect();
    if !dot.is_empty() {
        out.push(dot);
    }
    for (k, l) in [(1, 2), (2, 0), (0, 1)] {
        let cross: Vec<(usize, f64)> = [(k, l, 1.0), (l, k, -1.0)]
            .into_iter()
            .filter_map(|(p, q, c)| column(p, q).map(|j| (j, c)))
            .collect();
        if !cross.is_empty() {
            out.push(cross);
        }
    }
    out
}

/// Appends a node's rows (see [`solve_relaxation_in`]).
fn add_node_rows(problem: &VariantProblem, built: &mut Built, node: &NodeBox) {
    let natural = built.natural.clone();
    // Each bound row is recorded with its coordinate's index in `certify::node::coordinates`.
    let coordinates = crate::certify::node::coordinates(problem);
    let index_of = |c: Coordinate| {
        coordinates
            .iter()
            .position(|&x| x == c)
            .expect("every bound row's coordinate is a branching coordinate")
    };
    for (cw, c) in problem.counterweights.iter().enumerate() {
        let vars = built.cw_vars[cw].clone();
        let big_m = natural[c.column];
        let mn = built.xn(problem, c.column);
        let n_ax = c.axes.len();
        let mun: Vec<Affine> = (0..n_ax)
            .map(|k| built.xn(problem, c.column + 1 + k))
            .collect();
        let big_r = if n_ax > 0 { natural[c.column + 1] } else { 1.0 };
        let sigma = vars.sigma;
        let ps = pairs(n_ax);
        let s_of = |a: usize, b: usize| {
            let (a, b) = if a <= b { (a, b) } else { (b, a) };
            vars.s_vars[ps.iter().position(|&p| p == (a, b)).expect("pair")]
        };
        let cp = &mut built.cp;
        let [lo, hi] = node.mass(problem, cw);
        let intervals: Vec<[f64; 2]> = (0..n_ax).map(|k| node.moment(problem, cw, k)).collect();
        // `within` adds the lower side's row, then the upper's.
        for (k, (coordinate, per_unit)) in std::iter::once((Coordinate::Mass { cw }, 1.0 / big_m))
            .chain((0..n_ax).map(|k| (Coordinate::Moment { cw, k }, 1.0 / big_r)))
            .enumerate()
        {
            for upper in [false, true] {
                built.node_rows.push(NodeRow {
                    coordinate: index_of(coordinate),
                    upper,
                    row: cp.rows() + 2 * k + usize::from(upper),
                    per_unit,
                });
            }
        }
        within(cp, &mn, [lo, hi], big_m);
        for (k, &r) in intervals.iter().enumerate() {
            within(cp, &mun[k], r, big_r);
        }
        // S_aa = μ_a²/m below the corner planes; along the diagonals likewise.
        let below = |cp: &mut ConicProblem, s: &Affine, u: &Affine, r: [f64; 2]| {
            for [c0, c1, c2] in square_over_linear_planes(r, [lo, hi]) {
                let mut e = Affine::constant(c0 / sigma);
                e.add_scaled(u, c1 * big_r / sigma);
                e.add_scaled(&mn, c2 * big_m / sigma);
                e.add_scaled(s, -1.0);
                cp.nonneg(&e);
            }
        };
        for ka in 0..n_ax {
            below(cp, &Affine::var(s_of(ka, ka)), &mun[ka], intervals[ka]);
        }
        for ka in 0..n_ax {
            for kb in ka + 1..n_ax {
                let (ia, ib) = (intervals[ka], intervals[kb]);
                let h = std::f64::consts::FRAC_1_SQRT_2;
                for sign in [1.0, -1.0] {
                    let mut sd = Affine::var(s_of(ka, ka)).scaled(0.5);
                    sd.add_var(s_of(kb, kb), 0.5);
                    sd.add_var(s_of(ka, kb), sign);
                    let mut u = mun[ka].scaled(h);
                    u.add_scaled(&mun[kb], sign * h);
                    let r = if sign > 0.0 {
                        [h * (ia[0] + ib[0]), h * (ia[1] + ib[1])]
                    } else {
                        [h * (ia[0] - ib[1]), h * (ia[1] - ib[0])]
                    };
                    below(cp, &sd, &u, r);
                }
            }
        }
        // p = m^{5/3} below its chord over the node's mass interval.
        if let Some(p) = vars.p
            && hi > lo
        {
            let big_p = big_m.powf(5.0 / 3.0);
            let (plo, phi) = (lo.powf(5.0 / 3.0), hi.powf(5.0 / 3.0));
            let slope = (phi - plo) / (hi - lo);
            let mut chord = mn.scaled(slope * big_m / big_p);
            chord.constant += (plo - slope * lo) / big_p;
            chord.add_var(p, -1.0);
            cp.nonneg(&chord);
            for t in [lo, (lo * hi).sqrt(), hi] {
                if t > 0.0 {
                    below_five_thirds_tangent(cp, p, &mn, big_m, t);
                }
            }
        }
    }
    for (spring, s) in problem.springs.iter().enumerate() {
        let k = built.xn(problem, s.column);
        let na = s.axes_a.len();
        let nb = s.axes_b.len();
        let alpha: Vec<Affine> = (0..na)
            .map(|i| built.xn(problem, s.column + 1 + i))
            .collect();
        let beta: Vec<Affine> = (0..nb)
            .map(|i| built.xn(problem, s.column + 1 + na + i))
            .collect();
        let w_of: Vec<Affine> = (0..na * nb)
            .map(|i| built.xn(problem, s.column + 1 + na + nb + i))
            .collect();
        let big_k = natural[s.column];
        let cp = &mut built.cp;
        // The node's anchor intervals: lo ≤ a_i ≤ hi is lo·K ≤ K·a_i ≤ hi·K (exact, K > 0).
        for (first, n, is_b, coords) in [
            (s.column + 1, na, false, &alpha),
            (s.column + 1 + na, nb, true, &beta),
        ] {
            for i in 0..n {
                let [lo, hi] = node.anchor(problem, spring, is_b, i);
                let c_scale = natural[first + i] / big_k;
                // Each row is `K·(a_i − lo)/A` (or `K·(hi − a_i)/A`), at least `K_lo/A` per
                // unit of the distance.
                let k_lo = s.bounds.stiffness[0];
                if k_lo > 0.0 {
                    let coordinate = index_of(if is_b {
                        Coordinate::AnchorB { spring, l: i }
                    } else {
                        Coordinate::AnchorA { spring, i }
                    });
                    for upper in [false, true] {
                        built.node_rows.push(NodeRow {
                            coordinate,
                            upper,
                            row: cp.rows() + usize::from(upper),
                            per_unit: k_lo / natural[first + i],
                        });
                    }
                }
                let mut e = coords[i].clone();
                e.add_scaled(&k, -lo / c_scale);
                cp.nonneg(&e);
                let mut e = k.scaled(hi / c_scale);
                e.add_scaled(&coords[i], -1.0);
                cp.nonneg(&e);
            }
        }
        // A node's McCormick rows: with a_i ∈ [al, ah] and b_l ∈ [bl, bh], each of the four
        // products (a_i − c)(b_l − d) ≥ 0 or ≤ 0 at the corners, multiplied by K > 0, is a
        // linear row in (K, K a_i, K b_l, K a_i b_l).
        {
            let node_box = node;
            // The anchors' lower norm bounds |a| ≥ a_lo: over the box each a_i² is at most its
            // secant (lo + hi)·a_i − lo·hi, so Σ secants ≥ a_lo² holds at every point of the
            // box that meets the bound; times K it is linear in (K, K a).
            for (is_b, first, n, floor, coords) in [
                (false, s.column + 1, na, s.bounds.anchor_a[0], &alpha),
                (true, s.column + 1 + na, nb, s.bounds.anchor_b[0], &beta),
            ] {
                if floor <= 0.0 || n == 0 {
                    continue;
                }
                let unit = floor * floor;
                let mut e = k.scaled(-unit * big_k);
                for i in 0..n {
                    let [lo, hi] = node_box.anchor(problem, spring, is_b, i);
                    e.add_scaled(&coords[i], (lo + hi) * natural[first + i]);
                    e.add_scaled(&k, -lo * hi * big_k);
                }
                cp.nonneg(&e.scaled(1.0 / (unit * big_k)));
            }
            for i in 0..na {
                for l in 0..nb {
                    let [al, ah] = node_box.anchor(problem, spring, false, i);
                    let [bl, bh] = node_box.anchor(problem, spring, true, l);
                    let wj = s.column + 1 + na + nb + i * nb + l;
                    let big_w = natural[wj];
                    let w = w_of[i * nb + l].scaled(natural[wj] / big_w);
                    let alpha_i = alpha[i].scaled(natural[s.column + 1 + i] / big_w);
                    let beta_l = beta[l].scaled(natural[s.column + 1 + na + l] / big_w);
                    let kk = k.scaled(big_k / big_w);
                    // sign·(W − c β − d α + c d K) ≥ 0 for (c, d, sign).
                    for (c, d, sign) in
                        [(al, bl, 1.0), (ah, bh, 1.0), (ah, bl, -1.0), (al, bh, -1.0)]
                    {
                        let mut e = w.clone();
                        e.add_scaled(&beta_l, -c);
                        e.add_scaled(&alpha_i, -d);
                        e.add_scaled(&kk, c * d);
                        cp.nonneg(&e.scaled(sign));
                    }
                }
            }
        }
    }
}

/// Builds the relaxation (see [`solve_relaxation_in`]).
fn build(
    problem: &VariantProblem,
    tasks: &[Arc<TaskTorques>],
    objective: Objective,
    inertia: CylinderInertia,
) -> Built {
    let mut cp = ConicProblem::default();
    let d = problem.dim();
    let natural = natural_scales(problem);
    // z = D ζ with D chosen so that a unit ζ_k moves no lifted variable by more than its
    // natural magnitude.
    let dz: Vec<f64> = (0..d)
        .map(|k| {
            let worst = (0..natural.len())
                .map(|j| (problem.nullspace[(j, k)] / natural[j]).abs())
                .fold(0.0f64, f64::max);
            if worst > 0.0 { 1.0 / worst } else { 1.0 }
        })
        .collect();
    let z: Vec<usize> = (0..d).map(|_| cp.new_variable()).collect();
    // x_j / natural_j as an affine expression of ζ.
    let xn = |j: usize| {
        let mut e = Affine::constant(problem.particular[j] / natural[j]);
        for k in 0..d {
            let c = problem.nullspace[(j, k)] * dz[k] / natural[j];
            if c != 0.0 {
                e.add_var(z[k], c);
            }
        }
        e
    };

    // Per counterweight: feature expressions (true units) and their torque columns.
    let mut features: Vec<Feature> = Vec::new();
    let mut cw_vars: Vec<CwVars> = Vec::new();
    for c in &problem.counterweights {
        let big_m = natural[c.column];
        let mn = xn(c.column);
        let n_ax = c.axes.len();
        let mun: Vec<Affine> = (0..n_ax).map(|k| xn(c.column + 1 + k)).collect();
        let big_r = if n_ax > 0 { natural[c.column + 1] } else { 1.0 };
        let [rlo, rhi] = c.bounds.radius;
        let sigma = (big_m * rhi * rhi).max(1e-12 * big_m);
        features.push(Feature {
            expr: mn.scaled(big_m),
            parts: vec![(c.torque_slot, 0, 1.0)],
        });
        for (k, &a) in c.axes.iter().enumerate() {
            features.push(Feature {
                expr: mun[k].scaled(big_r),
                parts: vec![(c.torque_slot, 1 + a, 1.0)],
            });
        }
        // Normalised second moments s' = S/σ over the plane axes.
        let ps = pairs(n_ax);
        let s_vars: Vec<usize> = ps.iter().map(|_| cp.new_variable()).collect();
        let s_of = |a: usize, b: usize| {
            let (a, b) = if a <= b { (a, b) } else { (b, a) };
            s_vars[ps.iter().position(|&p| p == (a, b)).expect("pair")]
        };
        for (idx, &(ka, kb)) in ps.iter().enumerate() {
            let (a, b) = (c.axes[ka], c.axes[kb]);
            let mut parts = Vec::new();
            if a == b {
                // S_aa adds to I_bb for every b ≠ a.
                for other in 0..3 {
                    if other != a {
                        parts.push((c.torque_slot, inertia_index(other, other), 1.0));
                    }
                }
            } else {
                parts.push((c.torque_slot, inertia_index(a.min(b), a.max(b)), -1.0));
            }
            features.push(Feature {
                expr: Affine::var(s_vars[idx]).scaled(sigma),
                parts,
            });
        }
        // S·m ≥ μμᵀ (relaxed), in normalised units: s'·m' ≥ μ'² (σ·M = R²).
        let ratio = sigma * big_m / (big_r * big_r);
        let half_m = mn.scaled(0.5 * ratio);
        let mut trace = Affine::default();
        for ka in 0..n_ax {
            trace.add_var(s_of(ka, ka), 1.0);
            cp.rotated_soc(&Affine::var(s_of(ka, ka)), &half_m, &[mun[ka].clone()]);
        }
        cp.rotated_soc(&trace, &half_m, &mun);
        for ka in 0..n_ax {
            for kb in ka + 1..n_ax {
                let mut sum = Affine::var(s_of(ka, ka));
                sum.add_var(s_of(kb, kb), 1.0);
                let mut diff = Affine::var(s_of(ka, ka));
                diff.add_var(s_of(kb, kb), -1.0);
                cp.soc(&sum, &[diff, Affine::var(s_of(ka, kb)).scaled(2.0)]);
                for sign in [1.0, -1.0] {
                    let mut dsd = sum.scaled(0.5);
                    dsd.add_var(s_of(ka, kb), sign);
                    let mut dmu = mun[ka].scaled(std::f64::consts::FRAC_1_SQRT_2);
                    dmu.add_scaled(&mun[kb], sign * std::f64::consts::FRAC_1_SQRT_2);
                    cp.rotated_soc(&dsd, &half_m, &[dmu]);
                }
            }
        }
        // r_lo²·m ≤ tr S ≤ r_hi²·m.
        let mut upper = mn.scaled(rhi * rhi * big_m / sigma);
        upper.add_scaled(&trace, -1.0);
        cp.nonneg(&upper);
        let mut lower = trace.clone();
        lower.add_scaled(&mn, -rlo * rlo * big_m / sigma);
        cp.nonneg(&lower);
        // Mass bounds and |μ| ≤ r_hi m.
        let (mlo, mhi) = (c.min_mass(), c.bounds.mass[1]);
        let mut e = mn.clone();
        e.constant -= mlo / big_m;
        cp.nonneg(&e);
        let mut e = mn.scaled(-1.0);
        e.constant += mhi / big_m;
        cp.nonneg(&e);
        cp.soc(&mn.scaled(rhi * big_m / big_r), &mun);
        // Cylinder inertia: p = P·p', P = M^{5/3}; p above the tangents, below the chord.
        let mut p_var = None;
        let j_norm = c.j1.abs().max();
        if j_norm > 0.0 {
            let big_p = big_m.powf(5.0 / 3.0);
            let p = cp.new_variable();
            match inertia {
                CylinderInertia::PowerCone => {
                    cp.power(&Affine::var(p), &Affine::constant(1.0), &mn, 0.6)
                }
                CylinderInertia::Tangents => {
                    cp.nonneg(&Affine::var(p));
                    for t in tangent_points(mlo, mhi) {
                        below_five_thirds_tangent(&mut cp, p, &mn, big_m, t);
                    }
                }
            }
            if mhi > mlo {
                let (plo, phi) = (mlo.powf(5.0 / 3.0), mhi.powf(5.0 / 3.0));
                let slope = (phi - plo) / (mhi - mlo);
                let mut chord = mn.scaled(slope * big_m / big_p);
                chord.constant += (plo - slope * mlo) / big_p;
                chord.add_var(p, -1.0);
                cp.nonneg(&chord);
            }
            let mut parts = Vec::new();
            for a in 0..3 {
                for b in a..3 {
                    let v = c.j1[(a, b)];
                    if v != 0.0 {
                        parts.push((c.torque_slot, inertia_index(a, b), v));
                    }
                }
            }
            features.push(Feature {
                expr: Affine::var(p).scaled(big_p),
                parts,
            });
            p_var = Some(p);
        }
        cw_vars.push(CwVars {
            s_vars,
            p: p_var,
            sigma,
        });
    }
    // Spring bounds (the convex ones), normalised.
    for s in &problem.springs {
        let k = xn(s.column);
        let na = s.axes_a.len();
        let nb = s.axes_b.len();
        let alpha: Vec<Affine> = (0..na).map(|i| xn(s.column + 1 + i)).collect();
        let beta: Vec<Affine> = (0..nb).map(|i| xn(s.column + 1 + na + i)).collect();
        let big_k = natural[s.column];
        let [klo, khi] = s.bounds.stiffness;
        let mut e = k.clone();
        e.constant -= klo.max(0.0) / big_k;
        cp.nonneg(&e);
        let mut e = k.scaled(-1.0);
        e.constant += khi / big_k;
        cp.nonneg(&e);
        if na > 0 {
            let a_scale = natural[s.column + 1] / big_k;
            cp.soc(&k.scaled(s.bounds.anchor_a[1] / a_scale), &alpha);
        }
        // Anchor boxes: lo ≤ a_i ≤ hi is lo·K ≤ K·a_i ≤ hi·K, linear since K > 0 (exact).
        for (bx, axes, first) in [
            (&s.bounds.box_a, &s.axes_a, s.column + 1),
            (&s.bounds.box_b, &s.axes_b, s.column + 1 + na),
        ] {
            for (i, &axis) in axes.iter().enumerate() {
                let [lo, hi] = bx[axis];
                let coord = xn(first + i);
                let c_scale = natural[first + i] / big_k;
                if lo.is_finite() {
                    let mut e = coord.clone();
                    e.add_scaled(&k, -lo / c_scale);
                    cp.nonneg(&e);
                }
                if hi.is_finite() {
                    let mut e = k.scaled(hi / c_scale);
                    e.add_scaled(&coord, -1.0);
                    cp.nonneg(&e);
                }
            }
        }
        if nb > 0 {
            let b_scale = natural[s.column + 1 + na] / big_k;
            cp.soc(&k.scaled(s.bounds.anchor_b[1] / b_scale), &beta);
        }
        // |W_kl| = K·|a_k b_l| ≤ K·a_hi·b_hi: keeps the coupling terms bounded.
        for i in 0..na * nb {
            let w = xn(s.column + 1 + na + nb + i);
            let w_scale = natural[s.column + 1 + na + nb + i] / big_k;
            let bound = s.bounds.anchor_a[1] * s.bounds.anchor_b[1] / w_scale;
            let mut up = k.scaled(bound);
            up.add_scaled(&w, -1.0);
            cp.nonneg(&up);
            let mut down = k.scaled(bound);
            down.add_scaled(&w, 1.0);
            cp.nonneg(&down);
        }
    }

    // Torque expressions per task, sample, actuator, divided by a torque scale.
    let na = problem.actuators;
    let tau_scale = tasks
        .iter()
        .flat_map(|t| t.base.iter())
        .fold(0.0f64, |a, &b| a.max(b.abs()))
        .max(1e-9);
    let torque = |t: &TaskTorques, s: usize, a: usize| {
        let mut e = Affine::constant(t.base[s * na + a]);
        for f in &features {
            let coef: f64 = f
                .parts
                .iter()
                .map(|&(slot, j, c)| c * t.sens(slot, j)[s * na + a])
                .sum();
            if coef != 0.0 {
                e.add_scaled(&f.expr, coef);
            }
        }
        e
    };
    const { assert!(BODY_PARAMS == 10) };

    let u = cp.new_variable();
    cp.objective[u] = 1.0;
    if tasks.is_empty() {
        // Bounds only: keep the problem bounded (with tasks, the cones already do).
        cp.nonneg(&Affine::var(u));
    }
    match objective {
        Objective::RmsStar => {
            let t: Vec<usize> = (0..na).map(|_| cp.new_variable()).collect();
            let scale = 1.0 / (na.max(1) as f64).sqrt();
            cp.soc(
                &Affine::var(u),
                &t.iter()
                    .map(|&v| Affine::var(v).scaled(scale))
                    .collect::<Vec<_>>(),
            );
            for task in tasks {
                let w = 1.0 / ((task.samples as f64).sqrt() * tau_scale);
                for a in 0..na {
                    cp.soc(&Affine::var(t[a]), &rms_tail(task, a, w, &features));
                }
            }
        }
        Objective::Minimax => {
            for task in tasks {
                let w = 1.0 / ((task.samples as f64).sqrt() * tau_scale);
                let t: Vec<usize> = (0..na).map(|_| cp.new_variable()).collect();
                let mut sum = Affine::var(u);
                for a in 0..na {
                    sum.add_var(t[a], -1.0);
                    cp.soc(&Affine::var(t[a]), &rms_tail(task, a, w, &features));
                }
                cp.nonneg(&sum);
            }
        }
    }
    // Peak limits, relative to each limit: −1 ≤ τ_s/L ≤ 1 at every working-set sample.
    let mut peaks: Vec<Affine> = Vec::new();
    for task in tasks {
        for (a, lim) in problem.peak_limits.iter().enumerate() {
            if let Some(lim) = *lim {
                for s in 0..task.samples {
                    peaks.push(torque(task, s, a).scaled(1.0 / lim));
                }
            }
        }
    }
    Built {
        cp,
        peaks: peaks.into(),
        z,
        dz,
        tau_scale,
        natural,
        cw_vars,
        node_rows: Vec::new(),
    }
}

/// `lo ≤ value·scale ≤ hi` for the normalised expression `value`.
fn within(cp: &mut ConicProblem, value: &Affine, [lo, hi]: [f64; 2], scale: f64) {
    let mut e = value.clone();
    e.constant -= lo / scale;
    cp.nonneg(&e);
    let mut e = value.scaled(-1.0);
    e.constant += hi / scale;
    cp.nonneg(&e);
}

/// Below this relative level a peak row is far enough from active to be left out of a round.
const PEAK_ROW_INACTIVE: f64 = 0.98;
/// Rounds of the peak-row cutting planes before every row is added.
const PEAK_ROUNDS: usize = 8;

/// Adds `−1 ≤ e ≤ 1` to the problem.
fn add_peak_row(cp: &mut ConicProblem, e: &Affine) {
    let mut up = e.scaled(-1.0);
    up.constant += 1.0;
    cp.nonneg(&up);
    let mut down = e.clone();
    down.constant += 1.0;
    cp.nonneg(&down);
}

/// Solves `cp` with the peak rows `−1 ≤ e ≤ 1` added lazily (cutting planes).
///
/// A working set of a few tasks has thousands of peak rows (51 samples × actuators × tasks,
/// two each), most of them far from active, and they dominate the solver's work. Each round
/// solves with the rows known to matter, then adds every row the solution violates or nearly
/// meets (above [`PEAK_ROW_INACTIVE`]). The problem of any round is a relaxation of the full
/// one, so its bound is a valid lower bound and its infeasibility proves the full problem's;
/// the last round's solution meets every row left out with a margin, so it is the full
/// problem's optimum. A round that clarabel does not solve, or too many rounds, fall back to
/// the full problem, solved as it always was.
///
/// The rows `added` marks are in the problem from the first round (a branch-and-bound node
/// starts from the rows its search found active); `added` returns every row the solve used.
fn solve_with_peaks_from(
    cp: &mut ConicProblem,
    peaks: &[Affine],
    added: &mut [bool],
    max_iter: u32,
) -> ConicSolution {
    for (k, e) in peaks.iter().enumerate() {
        if added[k] {
            add_peak_row(cp, e);
        }
    }
    for _ in 0..PEAK_ROUNDS {
        let solution = cp.solve(max_iter);
        if solution.status.is_infeasible() {
            return solution;
        }
        if solution.status != ConicStatus::Solved {
            break;
        }
        let mut any = false;
        for (k, e) in peaks.iter().enumerate() {
            if !added[k] && e.eval(&solution.x).abs() > PEAK_ROW_INACTIVE {
                add_peak_row(cp, e);
                added[k] = true;
                any = true;
            }
        }
        if !any {
            return solution;
        }
    }
    for (k, e) in peaks.iter().enumerate() {
        if !added[k] {
            add_peak_row(cp, e);
        }
    }
    cp.solve(max_iter)
}

/// The relaxation of the bounds alone (no tasks, no objective): its infeasibility proves that no
/// parameters within the bounds balance the variant.
pub fn solve_bounds_only(problem: &VariantProblem, max_iter: u32) -> Relaxed {
    solve_relaxation(problem, &[], Objective::Minimax, max_iter)
}

#[cfg(test)]
mod tests;
