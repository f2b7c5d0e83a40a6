//! A thin conic-problem builder over clarabel and the explicit mapping of its statuses.
//!
//! Problems are written as `min cᵀx` subject to blocks of rows `A x + s = b`, `s ∈ K`, with `K`
//! a zero cone (equalities), the nonnegative orthant (`Ax ≤ b`), second-order cones
//! (`s₀ ≥ ‖s₁…‖`) or power cones (`s₀^α s₁^(1−α) ≥ |s₂|`). Rows are built as sparse maps and
//! converted once. Only `Solved` counts as success (docs/design.md §3): every other status is returned
//! by name so that the output says exactly why a variant was discarded.

use std::collections::BTreeMap;

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};
use serde::Serialize;

use crate::dense_ipm::{self, Block, DenseData, DenseOutcome, Tolerances};

/// clarabel's termination status, one-to-one.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ConicStatus {
    Solved,
    AlmostSolved,
    PrimalInfeasible,
    AlmostPrimalInfeasible,
    DualInfeasible,
    AlmostDualInfeasible,
    MaxIterations,
    MaxTime,
    NumericalError,
    InsufficientProgress,
    CallbackTerminated,
    Unsolved,
    /// clarabel refused the problem data (dimensions or settings).
    SetupFailed,
}

impl ConicStatus {
    pub fn from_clarabel(s: SolverStatus) -> ConicStatus {
        match s {
            SolverStatus::Solved => ConicStatus::Solved,
            SolverStatus::AlmostSolved => ConicStatus::AlmostSolved,
            SolverStatus::PrimalInfeasible => ConicStatus::PrimalInfeasible,
            SolverStatus::AlmostPrimalInfeasible => ConicStatus::AlmostPrimalInfeasible,
            SolverStatus::DualInfeasible => ConicStatus::DualInfeasible,
            SolverStatus::AlmostDualInfeasible => ConicStatus::AlmostDualInfeasible,
            SolverStatus::MaxIterations => ConicStatus::MaxIterations,
            SolverStatus::MaxTime => ConicStatus::MaxTime,
            SolverStatus::NumericalError => ConicStatus::NumericalError,
            SolverStatus::InsufficientProgress => ConicStatus::InsufficientProgress,
            SolverStatus::CallbackTerminated => ConicStatus::CallbackTerminated,
            SolverStatus::Unsolved => ConicStatus::Unsolved,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            ConicStatus::Solved => "Solved",
            ConicStatus::AlmostSolved => "AlmostSolved",
            ConicStatus::PrimalInfeasible => "PrimalInfeasible",
            ConicStatus::AlmostPrimalInfeasible => "AlmostPrimalInfeasible",
            ConicStatus::DualInfeasible => "DualInfeasible",
            ConicStatus::AlmostDualInfeasible => "AlmostDualInfeasible",
            ConicStatus::MaxIterations => "MaxIterations",
            ConicStatus::MaxTime => "MaxTime",
            ConicStatus::NumericalError => "NumericalError",
            ConicStatus::InsufficientProgress => "InsufficientProgress",
            ConicStatus::CallbackTerminated => "CallbackTerminated",
            ConicStatus::Unsolved => "Unsolved",
            ConicStatus::SetupFailed => "SetupFailed",
        }
    }

    /// Whether the status proves (to clarabel's tolerance) that no point satisfies the
    /// constraints.
    pub fn is_infeasible(self) -> bool {
        matches!(
            self,
            ConicStatus::PrimalInfeasible | ConicStatus::AlmostPrimalInfeasible
        )
    }
}

/// One sparse row: variable → coefficient.
pub type Row = BTreeMap<usize, f64>;

#[derive(Clone, Copy, Debug)]
enum Cone {
    Zero(usize),
    Nonneg(usize),
    Soc(usize),
    Pow(f64),
}

/// An affine expression `Σ c_j x_j + constant`.
#[derive(Clone, Debug, Default)]
pub struct Affine {
    pub terms: Row,
    pub constant: f64,
}

impl Affine {
    pub fn constant(c: f64) -> Affine {
        Affine {
            terms: Row::new(),
            constant: c,
        }
    }

    pub fn var(j: usize) -> Affine {
        let mut terms = Row::new();
        terms.insert(j, 1.0);
        Affine {
            terms,
            constant: 0.0,
        }
    }

    pub fn add_scaled(&mut self, other: &Affine, s: f64) {
        for (&j, &c) in &other.terms {
            *self.terms.entry(j).or_insert(0.0) += s * c;
        }
        self.constant += s * other.constant;
    }

    pub fn add_var(&mut self, j: usize, c: f64) {
        *self.terms.entry(j).or_insert(0.0) += c;
    }

    pub fn scaled(&self, s: f64) -> Affine {
        let mut a = Affine::default();
        a.add_scaled(self, s);
        a
    }

    pub fn eval(&self, x: &[f64]) -> f64 {
        self.constant + self.terms.iter().map(|(&j, &c)| c * x[j]).sum::<f64>()
    }
}

/// A conic program under construction.
#[derive(Clone, Debug, Default)]
pub struct ConicProblem {
    pub variables: usize,
    pub objective: Vec<f64>,
    /// The constraint rows, flat: row `i`'s `(variable, coefficient)` terms are
    /// `terms[row_start[i]..row_start[i + 1]]`, variables ascending. One allocation for all
    /// rows, so that the branch-and-bound's copy of a base problem per box is three copies of
    /// memory rather than one tree per row.
    row_start: Vec<usize>,
    terms: Vec<(usize, f64)>,
    rhs: Vec<f64>,
    cones: Vec<Cone>,
    /// Optimality and feasibility tolerance of the first runs, when not clarabel's 1e-8 (see
    /// [`ConicProblem::set_tolerance`]).
    tolerance: Option<f64>,
    /// Solves tried at most (clarabel's first run and its retries, see
    /// [`ConicProblem::solve`]); `None` for all of them.
    attempts: Option<u32>,
    /// Skip the dense interior-point method and solve with clarabel alone (see
    /// [`ConicProblem::clarabel_only`]).
    clarabel_only: bool,
}

/// The outcome of a solve.
#[derive(Clone, Debug)]
pub struct ConicSolution {
    pub status: ConicStatus,
    pub x: Vec<f64>,
    pub objective: f64,
    /// The dual objective: a lower bound on the optimum when the dual is feasible.
    pub dual_objective: f64,
    /// The dual variables, one per row in the order the rows were added (clarabel's `z`): for
    /// a feasible dual, the objective at any feasible point is at least the dual objective
    /// plus `Σ z_r·e_r(x)` over any rows `e_r ≥ 0` (weak duality, every term ≥ 0).
    pub dual: Vec<f64>,
    pub iterations: u32,
    /// Solver runs (1 unless retried).
    pub attempts: u32,
    /// The optimality and feasibility tolerance of the run that produced this solution.
    pub tolerance: f64,
}

/// Solver runs at most (see [`ConicProblem::solve`]).
const ATTEMPTS: u32 = 4;

/// Iterations of the dense method at most: it converges in about 20 on the box relaxations or
/// not at all, and a stalled run should hand over to clarabel soon.
pub const DENSE_ITERATIONS: u32 = 50;

/// clarabel's default gap and feasibility tolerance, the dense method's when the problem sets
/// none.
const CLARABEL_TOLERANCE: f64 = 1e-8;

impl ConicProblem {
    pub fn new_variable(&mut self) -> usize {
        self.variables += 1;
        self.objective.push(0.0);
        self.variables - 1
    }

    /// Cone slack `s = b − A x` from the affine expression `e(x) = c + d·x`: `s = e(x)` means
    /// row `−d`, rhs `c`.
    fn push_expr(&mut self, e: &Affine) {
        if self.row_start.is_empty() {
            self.row_start.push(0);
        }
        self.terms.extend(e.terms.iter().map(|(&j, &c)| (j, -c)));
        self.row_start.push(self.terms.len());
        self.rhs.push(e.constant);
    }

    /// `e(x) = 0`.
    pub fn equal_zero(&mut self, e: &Affine) {
        self.push_expr(e);
        self.cones.push(Cone::Zero(1));
    }

    /// `e(x) ≥ 0`.
    pub fn nonneg(&mut self, e: &Affine) {
        self.push_expr(e);
        self.cones.push(Cone::Nonneg(1));
    }

    /// `head ≥ ‖tail‖`.
    pub fn soc(&mut self, head: &Affine, tail: &[Affine]) {
        self.push_expr(head);
        for t in tail {
            self.push_expr(t);
        }
        self.cones.push(Cone::Soc(1 + tail.len()));
    }

    /// `2·u·v ≥ ‖w‖²`, `u, v ≥ 0` (rotated cone) as `u + v ≥ ‖(u − v, √2·w)‖`.
    pub fn rotated_soc(&mut self, u: &Affine, v: &Affine, w: &[Affine]) {
        let mut head = u.clone();
        head.add_scaled(v, 1.0);
        let mut diff = u.clone();
        diff.add_scaled(v, -1.0);
        let mut tail = vec![diff];
        tail.extend(w.iter().map(|e| e.scaled(std::f64::consts::SQRT_2)));
        self.soc(&head, &tail);
    }

    /// `x^α y^(1−α) ≥ |z|`, `x, y ≥ 0`.
    pub fn power(&mut self, x: &Affine, y: &Affine, z: &Affine, alpha: f64) {
        self.push_expr(x);
        self.push_expr(y);
        self.push_expr(z);
        self.cones.push(Cone::Pow(alpha));
    }

    /// Solves to `tol` (gap and feasibility) instead of clarabel's 1e-8; the retries use the
    /// looser of theirs and this. For a problem whose value is only used as a bound with a
    /// margin of ten times the tolerance (a branch-and-bound box, see
    /// [`crate::relaxation::BOUND_MARGIN`]), the last two digits are wasted work.
    pub fn set_tolerance(&mut self, tol: f64) {
        self.tolerance = Some(tol);
    }

    /// Tries at most `attempts` of the solves [`ConicProblem::solve`] would try (at least one):
    /// for a problem whose caller has a cheaper fallback than the cautious retries.
    pub fn limit_attempts(&mut self, attempts: u32) {
        self.attempts = Some(attempts.max(1));
    }

    /// Solves with clarabel alone, never with the dense method of [`ConicProblem::solve`]: for
    /// comparisons between the two.
    pub fn clarabel_only(&mut self) {
        self.clarabel_only = true;
    }

    pub fn rows(&self) -> usize {
        self.rhs.len()
    }

    /// The value of row `i`'s expression `e(x)` (the cone slack `b − A x`) at `x`.
    #[cfg(test)]
    pub(crate) fn row_value(&self, i: usize, x: &[f64]) -> f64 {
        let terms = &self.terms[self.row_start[i]..self.row_start[i + 1]];
        self.rhs[i] - terms.iter().map(|&(j, d)| d * x[j]).sum::<f64>()
    }

    /// Solves a problem of nonnegative rows and second-order cones first with the dense
    /// interior-point method of [`crate::dense_ipm`] (at most [`DENSE_ITERATIONS`] iterations),
    /// which reports only what passes clarabel's own tests; when it ends without a verdict,
    /// and for any other problem, solves with clarabel (quiet, deterministic); when clarabel
    /// stops short of `Solved` without proving infeasibility, retries with more iterations and
    /// a more cautious step, then with a stronger regularization and more equilibration and
    /// optimality tolerances of 1e-7, then 1e-6 (recorded in [`ConicSolution::tolerance`]) —
    /// the first `Solved` wins, otherwise the last status is returned.
    pub fn solve(&self, max_iter: u32) -> ConicSolution {
        if let Some(solution) = self.solve_dense(max_iter) {
            return solution;
        }
        let mut last = self.solve_attempt(max_iter, 0);
        for attempt in 1..self.attempts.unwrap_or(ATTEMPTS).min(ATTEMPTS) {
            if last.status == ConicStatus::Solved
                || last.status.is_infeasible()
                || last.status == ConicStatus::SetupFailed
            {
                break;
            }
            let retry = self.solve_attempt(max_iter, attempt);
            last = ConicSolution {
                attempts: attempt + 1,
                ..retry
            };
        }
        last
    }

    /// The cone as the dense method's blocks (consecutive nonnegative rows merged); `None`
    /// when it holds an equality or a power cone.
    fn dense_blocks(&self) -> Option<Vec<Block>> {
        let mut blocks: Vec<Block> = Vec::with_capacity(self.cones.len());
        let mut start = 0;
        for cone in &self.cones {
            match *cone {
                Cone::Nonneg(k) => {
                    match blocks.last_mut() {
                        Some(Block::Nonneg { len, .. }) => *len += k,
                        _ => blocks.push(Block::Nonneg { start, len: k }),
                    }
                    start += k;
                }
                Cone::Soc(k) => {
                    blocks.push(Block::Soc { start, len: k });
                    start += k;
                }
                Cone::Zero(_) | Cone::Pow(_) => return None,
            }
        }
        Some(blocks)
    }

    /// The dense method's verdict ([`ConicProblem::solve`]), `None` when it has none.
    pub(crate) fn solve_dense(&self, max_iter: u32) -> Option<ConicSolution> {
        if self.clarabel_only {
            return None;
        }
        let blocks = self.dense_blocks()?;
        let tolerance = self.tolerance.unwrap_or(CLARABEL_TOLERANCE);
        let data = DenseData {
            n: self.variables,
            row_start: &self.row_start,
            terms: &self.terms,
            b: &self.rhs,
            c: &self.objective,
            blocks: &blocks,
        };
        let outcome = dense_ipm::solve(
            &data,
            Tolerances::with(tolerance),
            max_iter.min(DENSE_ITERATIONS),
        );
        let solution = |status, x, objective, dual_objective, dual, iterations| ConicSolution {
            status,
            x,
            objective,
            dual_objective,
            dual,
            iterations,
            attempts: 1,
            tolerance,
        };
        match outcome {
            DenseOutcome::Solved {
                x,
                z,
                primal_objective,
                dual_objective,
                iterations,
            } => Some(solution(
                ConicStatus::Solved,
                x,
                primal_objective,
                dual_objective,
                z,
                iterations,
            )),
            DenseOutcome::PrimalInfeasible { z, iterations } => Some(solution(
                ConicStatus::PrimalInfeasible,
                vec![f64::NAN; self.variables],
                f64::INFINITY,
                f64::INFINITY,
                z,
                iterations,
            )),
            DenseOutcome::Failed => None,
        }
    }

    fn solve_attempt(&self, max_iter: u32, attempt: u32) -> ConicSolution {
        let n = self.variables;
        let m = self.rhs.len();
        // Column-major CSC from the rows (within a column, rows ascending; zeros left out).
        let rows = || {
            self.row_start
                .windows(2)
                .enumerate()
                .flat_map(|(i, w)| self.terms[w[0]..w[1]].iter().map(move |&(j, c)| (i, j, c)))
                .filter(|&(_, _, c)| c != 0.0)
        };
        let mut colptr = vec![0usize; n + 1];
        for (_, j, _) in rows() {
            colptr[j + 1] += 1;
        }
        for j in 0..n {
            colptr[j + 1] += colptr[j];
        }
        let nnz = colptr[n];
        let mut next = colptr.clone();
        let (mut rowval, mut nzval) = (vec![0usize; nnz], vec![0.0; nnz]);
        for (i, j, c) in rows() {
            rowval[next[j]] = i;
            nzval[next[j]] = c;
            next[j] += 1;
        }
        let a = CscMatrix::new(m, n, colptr, rowval, nzval);
        let p = CscMatrix::zeros((n, n));
        let cones: Vec<SupportedConeT<f64>> = self
            .cones
            .iter()
            .map(|c| match *c {
                Cone::Zero(k) => SupportedConeT::ZeroConeT(k),
                Cone::Nonneg(k) => SupportedConeT::NonnegativeConeT(k),
                Cone::Soc(k) => SupportedConeT::SecondOrderConeT(k),
                Cone::Pow(a) => SupportedConeT::PowerConeT(a),
            })
            .collect();
        let mut settings = DefaultSettings {
            // Diagnostics only: COUNTERPOISE_CLARABEL_VERBOSE=1 prints clarabel's log.
            verbose: std::env::var_os("COUNTERPOISE_CLARABEL_VERBOSE").is_some(),
            max_iter,
            ..DefaultSettings::default()
        };
        if let Some(tol) = self.tolerance {
            settings.tol_gap_abs = tol;
            settings.tol_gap_rel = tol;
            settings.tol_feas = tol;
        }
        if attempt >= 1 {
            settings.max_iter = max_iter.saturating_mul(3);
            settings.max_step_fraction = 0.9;
            settings.equilibrate_max_iter = 50;
        }
        if attempt >= 2 {
            let tol: f64 = if attempt >= 3 { 1e-6 } else { 1e-7 };
            let tol = tol.max(self.tolerance.unwrap_or(0.0));
            settings.tol_gap_abs = tol;
            settings.tol_gap_rel = tol;
            settings.tol_feas = tol;
            settings.static_regularization_constant = 1e-7;
            settings.iterative_refinement_max_iter = 50;
            settings.equilibrate_min_scaling = 1e-6;
            settings.equilibrate_max_scaling = 1e6;
        }
        let failed = || ConicSolution {
            status: ConicStatus::SetupFailed,
            x: vec![0.0; n],
            objective: f64::NAN,
            dual_objective: f64::NAN,
            dual: vec![0.0; m],
            iterations: 0,
            attempts: 1,
            tolerance: f64::NAN,
        };
        let settings_tol = settings.tol_gap_rel;
        let Ok(mut solver) =
            DefaultSolver::new(&p, &self.objective, &a, &self.rhs, &cones, settings)
        else {
            return failed();
        };
        solver.solve();
        let s = &solver.solution;
        ConicSolution {
            status: ConicStatus::from_clarabel(s.status),
            x: s.x.clone(),
            objective: s.obj_val,
            dual_objective: s.obj_val_dual,
            dual: s.z.clone(),
            iterations: s.iterations,
            attempts: 1,
            tolerance: settings_tol,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// min t s.t. t ≥ ‖(x − 1, y − 2)‖, x + y = 0: the distance from (1, 2) to the line, 3/√2.
    fn distance_to_line() -> ConicProblem {
        let mut p = ConicProblem::default();
        let (x, y, t) = (p.new_variable(), p.new_variable(), p.new_variable());
        p.objective[t] = 1.0;
        let mut sum = Affine::var(x);
        sum.add_var(y, 1.0);
        p.equal_zero(&sum);
        let mut dx = Affine::var(x);
        dx.constant = -1.0;
        let mut dy = Affine::var(y);
        dy.constant = -2.0;
        p.soc(&Affine::var(t), &[dx, dy]);
        p
    }

    #[test]
    fn small_socp() {
        let s = distance_to_line().solve(100);
        assert_eq!(s.status, ConicStatus::Solved);
        assert!((s.objective - 3.0 / 2f64.sqrt()).abs() < 1e-7);
    }

    #[test]
    fn limited_attempts_stop_the_retries() {
        // `distance_to_line` with one iteration per run: no run can reach the optimum, so every
        // allowed run is tried.
        let p = distance_to_line();
        let all = p.solve(1);
        assert_ne!(all.status, ConicStatus::Solved);
        assert_eq!(all.attempts, ATTEMPTS);
        for limit in [1, 2] {
            let mut q = p.clone();
            q.limit_attempts(limit);
            let s = q.solve(1);
            assert_ne!(s.status, ConicStatus::Solved);
            assert_eq!(s.attempts, limit);
        }
        // A limit of zero still runs clarabel once; a limit never adds runs.
        let mut q = p.clone();
        q.limit_attempts(0);
        assert_eq!(q.solve(1).attempts, 1);
        let mut q = p.clone();
        q.limit_attempts(ATTEMPTS + 3);
        assert_eq!(q.solve(1).attempts, ATTEMPTS);
        // With iterations enough, the limited problem solves on its first run as before.
        let mut q = p.clone();
        q.limit_attempts(1);
        let s = q.solve(100);
        assert_eq!(s.status, ConicStatus::Solved);
        assert!((s.objective - 3.0 / 2f64.sqrt()).abs() < 1e-7);
    }

    #[test]
    fn power_cone_and_infeasible() {
        // min p s.t. p^(3/5) ≥ m, m = 8 → p = 32.
        let mut p = ConicProblem::default();
        let (pv, m) = (p.new_variable(), p.new_variable());
        p.objective[pv] = 1.0;
        let mut e = Affine::var(m);
        e.constant = -8.0;
        p.equal_zero(&e);
        p.power(
            &Affine::var(pv),
            &Affine::constant(1.0),
            &Affine::var(m),
            0.6,
        );
        let s = p.solve(100);
        assert_eq!(s.status, ConicStatus::Solved);
        assert!((s.x[pv] - 32.0).abs() < 1e-5, "{}", s.x[pv]);

        let mut q = ConicProblem::default();
        let x = q.new_variable();
        q.nonneg(&Affine::var(x).scaled(-1.0).tap_const(-1.0));
        q.nonneg(&Affine::var(x));
        let s = q.solve(100);
        assert!(s.status.is_infeasible(), "{:?}", s.status);
    }

    trait TapConst {
        fn tap_const(self, c: f64) -> Self;
    }
    impl TapConst for Affine {
        fn tap_const(mut self, c: f64) -> Self {
            self.constant += c;
            self
        }
    }
}
