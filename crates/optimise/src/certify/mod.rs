//! The certified spring stage: spatial branch-and-bound over the anchors (and counterweights)
//! of one balanced variant (docs/design.md §3, "after the balance stage").
//!
//! A realizable variant is worth building only if a design exists *within the bounds*, and its
//! rank means something only if its optimum is the optimum. Both are questions over a box whose
//! only non-convexities are the spring coupling `W = K a⊗b` (bilinear in the anchors once
//! homogenised by `K`) and the counterweights' `μμᵀ/m` and `m^{5/3}`. The search:
//!
//! - **bounds** each box from below with the convex relaxation restricted to it
//!   ([`crate::relaxation::solve_relaxation_in`]); a box the relaxation proves infeasible (or
//!   whose anchors all lie inside an anchor's lower norm bound) holds no design;
//! - **finds designs** in a box from its relaxed point: counterweights projected and refined
//!   ([`crate::refine`]), springs polished from the relaxed anchors ([`crate::springs`], one
//!   deterministic start); a design counts only when every bound and peak limit holds, and a
//!   new best design that does not close the gap is descended from over the counterweights,
//!   the springs realized again at each step (module `polish`);
//! - **splits** the box at the midpoint of the coordinate that carries the largest relaxation
//!   error (the spring coupling error `|W − αβ/K|` shared by its two anchor components, times
//!   their relative widths; only the part of it that the family cannot remove by moving `W`
//!   alone, module `coupling`) weighted by how much that coordinate's earlier splits raised
//!   the bounds (module `split_history`), or, when the springs' error is negligible, of the
//!   widest counterweight coordinate (springs first while no design is known, or where the
//!   relaxed point promised a better design but none was realized); midpoint splits shrink every
//!   box, so the relaxation converges to the true problem and the search terminates;
//! - **stops** when the best design is within the gap tolerance of the smallest open bound
//!   (certified optimum; before it returns, the relaxed points of the boxes it closed or left
//!   unopened are tried for a better design, module `untried`, and the best is descended), when
//!   no box is left (proved impossible), or at the node budget (the only undecided outcome, a
//!   user-set limit).
//!
//! The order of work is fixed (best bound first, ties by creation order) and every step is
//! deterministic, so the verdict, the design and the bound do not depend on threads or batches.
//! A variant's search in a later pass of the critical-task loop resumes from the boxes the
//! last one left ([`SearchState`]).

pub(crate) mod coupling;
pub mod node;
mod polish;
mod split_history;
mod untried;

use std::sync::Arc;

use nalgebra::{DMatrix, DVector};

use crate::clarabel_map::ConicStatus;
use crate::problem::{CwPhysical, Objective, VariantProblem};
use crate::refine::{
    FEASIBILITY_TOL, counterweight_directions, merit, project_fixed, project_radius, refine,
};
use crate::relaxation::{EndRate, RelaxationBase};
use crate::springs::{Spring, realize_springs};
use crate::torque::TaskTorques;
use coupling::coupling_projectors;
use node::{Coordinate, NodeBox, coordinates};
use split_history::SplitHistory;
use untried::Untried;

/// Boxes per variant and pass by default: enough to close every gap of the palletizer at
/// Dmax 2 and Dmax 3 to the default tolerance (the most one pass needs at Dmax 3 is 2,711, a
/// counterweight with two springs: eleven branching coordinates), with a third to spare for
/// other seeds and paths. It bounds the time of a search that converges slowly (a box is a
/// conic solve of 2–70 ms); only a variant that needs the boxes spends them.
pub const DEFAULT_MAX_NODES: usize = 4000;

/// Settings of the search.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BranchOptions {
    /// Relative gap `(design − bound)/design` at which the search stops.
    pub gap_tolerance: f64,
    /// Boxes solved at most once a design is known (the user-set limit); see
    /// [`BranchOptions::box_limit`].
    pub max_nodes: usize,
    /// clarabel iteration limit per box.
    pub solver_iterations: u32,
    /// Weight a spring coordinate's coupling error by how much its earlier splits in the search
    /// raised the bounds (module `split_history`): on the palletizer at Dmax 3, 40 % fewer
    /// boxes. `false` scores by the error alone.
    pub split_history: bool,
}

/// How many times `max_nodes` a search may spend while it has no design: an `undecided`
/// verdict is worth the extra time to avoid, and a lower `--max-nodes` (set to trade gaps for
/// time) should not cut the proofs short with it. At the default limit it is never reached on
/// the palletizer: the slowest proofs that no design exists take 259–923 boxes at Dmax 3.
pub const NO_DESIGN_BUDGET_FACTOR: usize = 4;

impl BranchOptions {
    /// Boxes the search may solve: `max_nodes` once a design is known, otherwise
    /// [`NO_DESIGN_BUDGET_FACTOR`] times as many.
    pub fn box_limit(&self, has_design: bool) -> usize {
        if has_design {
            self.max_nodes
        } else {
            self.max_nodes.saturating_mul(NO_DESIGN_BUDGET_FACTOR)
        }
    }
}

/// A verified design: every bound and peak limit holds on the tasks searched.
#[derive(Clone, Debug)]
pub struct Design {
    /// The full lifted point (springs realized).
    pub x: DVector<f64>,
    pub cws: Vec<CwPhysical>,
    pub springs: Vec<Spring>,
    /// The objective on the tasks searched, N·m.
    pub value: f64,
}

/// How the search ended.
#[derive(Clone, Debug)]
pub enum Verdict {
    /// The design is within the gap tolerance of the certified lower bound.
    Optimal {
        design: Design,
        lower_bound: f64,
        nodes: usize,
    },
    /// Every box was proved to hold no design.
    Impossible { nodes: usize },
    /// The node budget ran out: the best design so far (if any) and the certified bound.
    Stopped {
        design: Option<Design>,
        lower_bound: f64,
        nodes: usize,
    },
}

/// One open box with its relaxation.
pub(crate) struct Open {
    pub(crate) bound: f64,
    order: usize,
    node: NodeBox,
    /// The relaxed free coordinates, when the relaxation was solved.
    pub(crate) z: Option<DVector<f64>>,
    /// The relaxation's error per counterweight ([`crate::relaxation::Relaxed::cw_errors`]).
    cw_errors: Vec<f64>,
    /// Whether the bound is from an earlier search on fewer tasks (still a lower bound, but
    /// the box is solved again on these tasks before it is split).
    stale: bool,
    /// The box's own relaxation bound and its rates per coordinate end
    /// ([`crate::relaxation::Relaxed::reduced`]); `None` when the box was not solved.
    pub(crate) reduced: Option<(f64, Vec<EndRate>)>,
}

/// What one search leaves for the next on the same variant: the tightened root box and every
/// box not proved empty, with its bound. The critical-task loop adds tasks
/// between searches, and every task only adds torque terms and peak rows, so a box proved
/// empty stays empty and an old bound stays a lower bound: the next search starts from these
/// boxes instead of the root and re-solves each before splitting it.
#[derive(Clone, Debug)]
pub struct SearchState {
    root: NodeBox,
    leaves: Vec<(NodeBox, f64)>,
    /// Per spring, the intervals of its Lagrange vector over the root box
    /// ([`RelaxationBase::lagrange_ranges`]; they hold for every task set).
    lagrange: LagrangeRanges,
}

/// Per spring, the intervals of its Lagrange vector's components (empty for a spring without
/// them; see [`RelaxationBase::lagrange_ranges`]).
type LagrangeRanges = Vec<Vec<[f64; 2]>>;

impl SearchState {
    /// Boxes the next search starts from.
    pub fn boxes(&self) -> usize {
        self.leaves.len()
    }

    /// The smallest bound of the boxes left (+∞ when none is left).
    pub fn smallest_bound(&self) -> f64 {
        self.leaves
            .iter()
            .map(|l| l.1)
            .fold(f64::INFINITY, f64::min)
    }

    /// A new search from this one's first box: the same root and Lagrange ranges (they come
    /// from the bounds alone, so every search of the variant computes the same ones), the root
    /// as the only box, unsolved. A search started from it solves the same boxes as one
    /// started from nothing, without computing the first box again (about forty of clarabel's
    /// solves on a three-element variant).
    pub fn restart(&self) -> SearchState {
        SearchState {
            root: self.root.clone(),
            leaves: vec![(self.root.clone(), f64::NEG_INFINITY)],
            lagrange: self.lagrange.clone(),
        }
    }
}

/// The relaxations a search solves its boxes with: `first`, and where it is given, `fallback`
/// for a box on which `first` ends short of a verdict.
///
/// With the Lagrange cones ([`RelaxationBase::with_lagrange_bounds`]) clarabel sometimes
/// stalls on a box whose relaxation is infeasible or nearly so (on the palletizer at Dmax 3,
/// m5 + K52 + K53: 158 of its 458 boxes ended `InsufficientProgress` or `AlmostSolved` after
/// all four of clarabel's runs, so each kept its parent's bound and was split again). The
/// relaxation without the cones is weaker but valid, and clarabel seldom stalls on it where
/// it stalls with them: so the cones get two of clarabel's runs (the first and the cautious
/// retry, which rescues most boxes of m4 + K32 + K73), and a box they leave undecided is
/// solved without the cones, also with two runs (where that relaxation stalls too, as on some
/// boxes of m3 + m5 + K72, its last two runs rarely succeed either). A box costs at most the
/// four runs it had before; m5 + K52 + K53 closes its gap in 155 boxes instead of 339.
pub(crate) struct Bases<'a> {
    pub(crate) first: &'a RelaxationBase,
    pub(crate) fallback: Option<&'a RelaxationBase>,
}

/// The relaxations of a search ([`Bases`]) from the relaxation without the Lagrange cones
/// and with them: where the cones add rows, they with two of clarabel's runs and the one
/// without them as the fallback, also with two; where they add none (no spring has a lower
/// anchor norm bound, or no cone can cut), that relaxation alone with all of clarabel's runs
/// (a fallback identical to it would only repeat its first two runs).
pub(crate) fn search_relaxations(
    plain: RelaxationBase,
    with_cones: RelaxationBase,
) -> (RelaxationBase, Option<RelaxationBase>) {
    if with_cones.rows() > plain.rows() {
        (with_cones.limit_attempts(2), Some(plain.limit_attempts(2)))
    } else {
        (with_cones, None)
    }
}

/// Solves the relaxation on `node`; `None` when the box is proved to hold no point (the
/// relaxation is infeasible, or an anchor's lower norm bound excludes the whole box).
pub(crate) fn bound_box(
    problem: &VariantProblem,
    bases: &Bases<'_>,
    active: &mut Vec<bool>,
    options: &BranchOptions,
    node: NodeBox,
    parent_bound: f64,
    order: usize,
) -> Option<Open> {
    if node.is_empty() || node.inside_anchor_floor(problem).is_some() {
        return None;
    }
    let mut relaxed = bases
        .first
        .solve(problem, Some(&node), options.solver_iterations, active);
    if let Some(fallback) = bases.fallback
        && relaxed.solution.status != ConicStatus::Solved
        && !relaxed.solution.status.is_infeasible()
    {
        relaxed = fallback.solve(problem, Some(&node), options.solver_iterations, active);
    }
    match relaxed.solution.status {
        ConicStatus::PrimalInfeasible => None,
        ConicStatus::Solved if relaxed.z.iter().all(|v| v.is_finite()) => Some(Open {
            bound: relaxed.bound.max(parent_bound),
            order,
            node,
            z: Some(relaxed.z),
            cw_errors: relaxed.cw_errors,
            stale: false,
            reduced: Some((relaxed.bound, relaxed.reduced)),
        }),
        // Not solved (nor proved infeasible): the box keeps its parent's bound and is split.
        _ => Some(Open {
            bound: parent_bound,
            order,
            node,
            z: None,
            cw_errors: Vec::new(),
            stale: false,
            reduced: None,
        }),
    }
}

/// [`bound_box`] of several boxes (with their orders), solved in parallel on the current rayon
/// pool: the two children of one split. Each starts from the peak rows `active` marks on
/// entry, and `active` returns every row any of them used; so
/// the result does not depend on the thread count or on which box finishes first. (A search
/// on one variant keeps both cores busy where it is the last variant of a pass left running.)
pub(crate) fn bound_boxes(
    problem: &VariantProblem,
    bases: &Bases<'_>,
    active: &mut Vec<bool>,
    options: &BranchOptions,
    boxes: Vec<(NodeBox, usize)>,
    parent_bound: f64,
) -> Vec<Option<Open>> {
    use rayon::prelude::*;
    let start = active.clone();
    let solved: Vec<(Option<Open>, Vec<bool>)> = boxes
        .into_par_iter()
        .with_max_len(1)
        .map(|(node, order)| {
            let mut rows = start.clone();
            let open = bound_box(
                problem,
                bases,
                &mut rows,
                options,
                node,
                parent_bound,
                order,
            );
            (open, rows)
        })
        .collect();
    solved
        .into_iter()
        .map(|(open, rows)| {
            if rows.len() > active.len() {
                active.resize(rows.len(), false);
            }
            for (a, r) in active.iter_mut().zip(rows) {
                *a |= r;
            }
            open
        })
        .collect()
}

/// The design at a full lifted point with realized springs, if it meets every bound and peak
/// limit on the tasks searched (and every counterweight has a positive mass).
pub(crate) fn verified_design(
    problem: &VariantProblem,
    tasks: &[Arc<TaskTorques>],
    objective: Objective,
    springs: Vec<Spring>,
    x_full: DVector<f64>,
) -> Option<Design> {
    let cws = problem.cw_physical(&x_full);
    if cws.iter().any(|c| c.mass.is_nan() || c.mass <= 0.0) {
        return None;
    }
    let e = problem.evaluate(&cws, tasks);
    let worst = problem
        .bound_violations(&x_full)
        .into_iter()
        .fold(problem.peak_excess(&e), f64::max);
    (worst <= FEASIBILITY_TOL).then(|| Design {
        value: e.objective(objective, problem.actuators),
        x: x_full,
        cws,
        springs,
    })
}

/// A design from a box's relaxed point, if one meets every bound and limit.
fn design_at(
    problem: &VariantProblem,
    b: &DVector<f64>,
    tasks: &[Arc<TaskTorques>],
    objective: Objective,
    z: &DVector<f64>,
    scale: f64,
) -> Option<Design> {
    let z = project_fixed(problem, z);
    let dirs = counterweight_directions(problem);
    let z = project_radius(problem, &z, &dirs).unwrap_or(z);
    let (_, _, violation) = merit(problem, tasks, objective, &z, scale);
    let z = if violation <= FEASIBILITY_TOL || problem.counterweights.is_empty() {
        z
    } else {
        let refined = refine(problem, tasks, objective, &z, &dirs, scale);
        if !refined.feasible {
            return None;
        }
        refined.z
    };
    let x = problem.lifted(&z);
    let accept = |springs, x_full| verified_design(problem, tasks, objective, springs, x_full);
    let (found, _) = realize_springs(problem, b, &x, 1, false);
    if let Some(d) = found.into_iter().find_map(|(s, xf)| accept(s, xf)) {
        return Some(d);
    }
    if problem.counterweights.is_empty() {
        return None;
    }
    let (joint, _) = realize_springs(problem, b, &x, 1, true);
    joint
        .into_iter()
        .filter_map(|(s, xf)| accept(s, xf))
        .min_by(|p, q| p.value.total_cmp(&q.value))
}

/// How much a spring coordinate's relative width weighs against its relaxation error when the
/// search picks the coordinate to split: the error times the width to this power. The error is
/// what the split removes; the width only tips the choice between errors of similar size (a
/// coordinate half as wide needs 19 % more error to be chosen, against twice as much with the
/// width to the power 1). Measured on the palletizer at Dmax 3
/// (release, 2 cores, one run each): with the width to the power 1 (the error times the
/// width), 35,519 boxes and 118.0 s wall; to the power 0.25, 29,698 boxes and 106.0 s, with the
/// same verdicts and every gap ≤ 1e-3. On the 44 variants that took 100 boxes or more,
/// powers 1, 0.5, 0.35, 0.25, 0.15 and 0 took 29,015, 26,736, 26,309, 23,205, 22,801 and
/// 26,738 boxes: every power below 1 helped there, 0.15–0.25 most (the counts move by ±10 %
/// between neighbouring powers, a search's path being sensitive to any change of rule).
const WIDTH_EXPONENT: f64 = 0.25;

/// Scores within this relative difference are a tie, which the lowest coordinate index wins:
/// symmetric couplings (a pendulum's two cross terms, equal in exact arithmetic) differ only
/// by rounding, and the solver's last bits must not choose the path.
const TIE: f64 = 1e-9;

/// The index of the largest weight of `(index, weight)` pairs taken in increasing index order;
/// a later weight must exceed the best so far by more than [`TIE`] (relative) to replace it.
fn largest_with_ties_to_the_first(weights: impl Iterator<Item = (usize, f64)>) -> Option<usize> {
    weights
        .fold(None, |best: Option<(usize, f64)>, (k, w)| match best {
            Some((_, bw)) if bw * (1.0 + TIE) >= w => best,
            _ => Some((k, w)),
        })
        .map(|(k, _)| k)
}

/// The coordinate to split. The objective depends on the counterweights alone (massless
/// springs never change a balanced variant's motor torques), so when the true objective at the
/// relaxed point exceeds the box's bound by more than the tolerance (`counterweights_first`),
/// the widest counterweight coordinate (relative to the root box); otherwise the largest
/// relaxation error of the springs (couplings and anchor floors), weighted by a power of the
/// relative width ([`WIDTH_EXPONENT`]) and by what the coordinate's earlier splits did to the
/// bounds (module `split_history`); failing both, the widest coordinate of any kind.
fn branching_coordinate(
    problem: &VariantProblem,
    coords: &[Coordinate],
    root: &NodeBox,
    open: &Open,
    counterweights_first: bool,
    coupled: &[DMatrix<f64>],
    history: &SplitHistory,
) -> Option<usize> {
    let relative = |k: usize| {
        let w = open.node.ranges[k][1] - open.node.ranges[k][0];
        let w0 = root.ranges[k][1] - root.ranges[k][0];
        if w0 > 0.0 && w > NodeBox::split_floor(problem, coords[k]) {
            w / w0
        } else {
            0.0
        }
    };
    let mut score = vec![0.0f64; coords.len()];
    if let Some(z) = &open.z {
        let x = problem.lifted(z);
        let mut first = 0;
        for (s, projector) in problem.springs.iter().zip(coupled) {
            let (na, nb) = (s.axes_a.len(), s.axes_b.len());
            let kk = x[s.column];
            let unit = kk.abs().max(1e-300)
                * s.bounds.anchor_a[1].max(1e-3)
                * s.bounds.anchor_b[1].max(1e-3);
            let mut errors = DVector::<f64>::zeros(na * nb);
            for i in 0..na {
                for l in 0..nb {
                    let alpha = x[s.column + 1 + i];
                    let beta = x[s.column + 1 + na + l];
                    let w = x[s.column + 1 + na + nb + i * nb + l];
                    errors[i * nb + l] = (w * kk - alpha * beta) / kk.abs().max(1e-300);
                }
            }
            let errors = projector * errors;
            for i in 0..na {
                for l in 0..nb {
                    let error = errors[i * nb + l].abs() / unit;
                    score[first + i] += error;
                    score[first + na + l] += error;
                }
            }
            // An anchor nearer than its lower norm bound: the relaxation met the bound through
            // the secants of a_i², so the error is each secant's excess (hi − a_i)(a_i − lo),
            // which splitting a_i removes.
            for (offset, n, floor, lifted) in [
                (0, na, s.bounds.anchor_a[0], s.column + 1),
                (na, nb, s.bounds.anchor_b[0], s.column + 1 + na),
            ] {
                if floor <= 0.0 {
                    continue;
                }
                let anchor: Vec<f64> = (0..n).map(|i| x[lifted + i] / kk).collect();
                if crate::problem::norm(&anchor) >= floor {
                    continue;
                }
                for (i, &v) in anchor.iter().enumerate() {
                    let [lo, hi] = open.node.ranges[first + offset + i];
                    score[first + offset + i] += ((hi - v) * (v - lo)).max(0.0) / (floor * floor);
                }
            }
            first += na + nb;
        }
    }
    let pick = |filter: &dyn Fn(usize) -> bool, weight: &dyn Fn(usize) -> f64| {
        let candidates = (0..coords.len())
            .filter(|&k| filter(k) && relative(k) > 0.0)
            .map(|k| (k, weight(k)))
            .filter(|&(_, w)| w > 0.0);
        largest_with_ties_to_the_first(candidates)
    };
    let spring = |k: usize| {
        matches!(
            coords[k],
            Coordinate::AnchorA { .. } | Coordinate::AnchorB { .. }
        )
    };
    let spring_weight = |k: usize| score[k] * relative(k).powf(WIDTH_EXPONENT) * history.effect(k);
    // The counterweight whose relaxation is farthest from physical, and its widest coordinate.
    let worst_cw = (0..open.cw_errors.len())
        .filter(|&c| open.cw_errors[c] > 0.0)
        .max_by(|&p, &q| open.cw_errors[p].total_cmp(&open.cw_errors[q]));
    let of_cw = |k: usize, cw: usize| matches!(coords[k], Coordinate::Mass { cw: c } | Coordinate::Moment { cw: c, .. } if c == cw);
    if counterweights_first {
        worst_cw
            .and_then(|cw| pick(&|k| of_cw(k, cw), &relative))
            .or_else(|| pick(&|k| !spring(k), &relative))
            .or_else(|| pick(&|k| spring(k) && score[k] > 1e-9, &spring_weight))
            .or_else(|| pick(&|_| true, &relative))
    } else {
        pick(&|k| spring(k) && score[k] > 1e-9, &spring_weight)
            .or_else(|| pick(&|k| !spring(k), &relative))
            .or_else(|| pick(&|_| true, &relative))
    }
}

/// The lifted ranges solved while the first box narrows, each kept with the box it was
/// solved on: a range asked for again on the same box is not solved again. Each anchor
/// component's interval is a quotient by its spring's stiffness range, so without this the
/// stiffness's two solves were repeated for every component.
#[derive(Default)]
struct KeptRanges {
    /// (column, box, range), at most one per column: the latest.
    kept: Vec<(usize, NodeBox, Option<[f64; 2]>)>,
}

impl KeptRanges {
    /// The range of `column` on `node`: the kept one if it was solved on this box, otherwise
    /// `solve()`, which is then kept in place of the column's older one.
    fn range(
        &mut self,
        column: usize,
        node: &NodeBox,
        solve: impl FnOnce() -> Option<[f64; 2]>,
    ) -> Option<[f64; 2]> {
        if let Some((_, on, r)) = self.kept.iter().find(|(c, _, _)| *c == column)
            && on == node
        {
            return *r;
        }
        let r = solve();
        self.kept.retain(|(c, _, _)| *c != column);
        self.kept.push((column, node.clone(), r));
        r
    }
}

/// The root box narrowed to what the bounds-only relaxation allows (its ranges hold every
/// physical point, so the box keeps every design):
///
/// - each counterweight's mass and first-moment intervals to their lifted range (both are
///   lifted variables, linear in the family): a mass that balance fixes becomes a point, and
///   the corner planes of `μμᵀ/m` start tight;
/// - each anchor component `a_i = (K a_i)/K` to the quotient of its lifted range by the
///   stiffness's (`K > 0`): a component that balance holds at zero (`K·a_y = 0`) becomes the
///   point 0, and one whose lifted value keeps a sign keeps it. Left wide, such a component
///   spoils the anchors' lower norm bound: the secant of `a_y²` over `[−r, r]` is `r²` at
///   `a_y = 0`, so `|a| ≥ a_min` never cuts until the search has split the pinned coordinate.
fn tighten(
    problem: &VariantProblem,
    base: &RelaxationBase,
    mut root: NodeBox,
    options: &BranchOptions,
) -> NodeBox {
    let coords = coordinates(problem);
    // Every anchor component's interval needs its spring's stiffness range (see `KeptRanges`).
    let kept = std::cell::RefCell::new(KeptRanges::default());
    let range = |root: &NodeBox, column: usize| {
        kept.borrow_mut().range(column, root, || {
            base.lifted_range(problem, Some(root), column, options.solver_iterations)
        })
    };
    for (k, c) in coords.iter().enumerate() {
        let narrowed = match *c {
            Coordinate::Mass { cw } => range(&root, problem.counterweights[cw].column),
            Coordinate::Moment { cw, k } => range(&root, problem.counterweights[cw].column + 1 + k),
            Coordinate::AnchorA { spring, i } => {
                anchor_range(problem, &root, spring, 1 + i, &range)
            }
            Coordinate::AnchorB { spring, l } => {
                let na = problem.springs[spring].axes_a.len();
                anchor_range(problem, &root, spring, 1 + na + l, &range)
            }
        };
        if let Some([lo, hi]) = narrowed {
            let r = &mut root.ranges[k];
            if lo > hi {
                // Infeasible: keep the box; its relaxation proves it empty.
                return root;
            }
            r[0] = r[0].max(lo);
            r[1] = r[1].min(hi).max(r[0]);
        }
    }
    root
}

/// The box a first search starts from: the case's bounds ([`NodeBox::root`]) narrowed by
/// the bounds-only relaxation (see `tighten`).
pub fn root_box(problem: &VariantProblem, options: &BranchOptions) -> Result<NodeBox, String> {
    Ok(first_box(problem, options)?.0)
}

/// The first box ([`root_box`]) and each spring's Lagrange ranges over it
/// ([`RelaxationBase::lagrange_ranges`]), both from one bounds-only relaxation.
pub(crate) fn first_box(
    problem: &VariantProblem,
    options: &BranchOptions,
) -> Result<(NodeBox, LagrangeRanges), String> {
    let bounds_only = RelaxationBase::new(problem, &[], Objective::Minimax);
    let root = tighten(problem, &bounds_only, NodeBox::root(problem)?, options);
    let lagrange = bounds_only.lagrange_ranges(problem, Some(&root), options.solver_iterations);
    Ok((root, lagrange))
}

/// The interval of the anchor component held at `offset` in spring `spring`'s lifted block
/// (`K·a_i`), over the bounds-only relaxation on `root`: exactly `[0, 0]` when the family
/// holds `K·a_i` at zero (its particular value and null-space row are zero), otherwise the
/// quotient of `K·a_i`'s range by `K`'s (`K > 0`), `None` when either range is unknown.
pub(crate) fn anchor_range(
    problem: &VariantProblem,
    root: &NodeBox,
    spring: usize,
    offset: usize,
    range: &dyn Fn(&NodeBox, usize) -> Option<[f64; 2]>,
) -> Option<[f64; 2]> {
    let column = problem.springs[spring].column;
    let lifted = column + offset;
    let pinned = problem.particular[lifted] == 0.0
        && (0..problem.dim()).all(|k| problem.nullspace[(lifted, k)] == 0.0);
    if pinned {
        return Some([0.0, 0.0]);
    }
    let [alo, ahi] = range(root, lifted)?;
    let [klo, khi] = range(root, column)?;
    if alo > ahi || klo > khi {
        return Some([f64::INFINITY, f64::NEG_INFINITY]);
    }
    if klo.is_nan() || klo <= 0.0 {
        // K may be near zero: only the sign of K·a_i carries over.
        return Some([
            if alo >= 0.0 { 0.0 } else { f64::NEG_INFINITY },
            if ahi <= 0.0 { 0.0 } else { f64::INFINITY },
        ]);
    }
    // a = α/K over α ∈ [alo, ahi], K ∈ [klo, khi] with 0 < klo.
    let lo = if alo >= 0.0 { alo / khi } else { alo / klo };
    let hi = if ahi >= 0.0 { ahi / klo } else { ahi / khi };
    Some([lo, hi])
}

/// Branch-and-bound for the variant on `tasks`, starting from an optional design found
/// otherwise (its value is the first upper bound) and from the boxes an earlier search on a
/// subset of `tasks` left (`warm`; from the root box when `None`). Returns the verdict and
/// what this search leaves for the next.
pub fn branch_and_bound(
    problem: &VariantProblem,
    b: &DVector<f64>,
    tasks: &[Arc<TaskTorques>],
    objective: Objective,
    options: &BranchOptions,
    incumbent: Option<Design>,
    warm: Option<SearchState>,
) -> Result<(Verdict, SearchState), String> {
    let (root, leaves, lagrange) = match warm {
        Some(w) => (w.root, Some(w.leaves), w.lagrange),
        None => {
            let (root, lagrange) = first_box(problem, options)?;
            (root, None, lagrange)
        }
    };
    let plain = RelaxationBase::new(problem, tasks, objective);
    let with_cones = plain.clone().with_lagrange_bounds(problem, &lagrange);
    let (base, fallback) = search_relaxations(plain, with_cones);
    let bases = Bases {
        first: &base,
        fallback: fallback.as_ref(),
    };
    // Peak rows found active in any box so far: every later box starts with them.
    let mut active = Vec::new();
    let coords = coordinates(problem);
    // Per spring, the projector onto the coupling error only a split can remove (`coupling`).
    let coupled = coupling_projectors(problem);
    let scale = objective_scale(tasks);
    let mut best = incumbent;
    let mut history = SplitHistory::new(coords.len());
    let mut nodes = 0;
    let mut open: Vec<Open> = Vec::new();
    let mut order = 0;
    match leaves {
        Some(leaves) => {
            for (node, bound) in leaves {
                order += 1;
                open.push(Open {
                    bound,
                    order,
                    node,
                    z: None,
                    cw_errors: Vec::new(),
                    stale: true,
                    reduced: None,
                });
            }
        }
        None => {
            nodes += 1;
            if let Some(o) = bound_box(
                problem,
                &bases,
                &mut active,
                options,
                root.clone(),
                f64::NEG_INFINITY,
                order,
            ) {
                open.push(o);
            }
        }
    }
    // Boxes too small to split that hold no design: their bounds stay in the global one.
    let mut stuck: Vec<(NodeBox, f64)> = Vec::new();
    // The boxes closed because their bound came within the tolerance of the best design (their
    // bounds are part of the certified lower bound).
    let mut pruned: Vec<(NodeBox, f64)> = Vec::new();
    // The relaxed points of the boxes closed unopened (module `untried`).
    let mut untried = Untried::default();
    let closes = |bound: f64, best: &Option<Design>| {
        best.as_ref().is_some_and(|d| {
            d.value - bound <= options.gap_tolerance * d.value.abs().max(f64::MIN_POSITIVE)
        })
    };
    loop {
        let lowest = open
            .iter()
            .map(|o| o.bound)
            .chain(stuck.iter().chain(&pruned).map(|b| b.1))
            .fold(f64::INFINITY, f64::min);
        let finish = |open: Vec<Open>, stuck: Vec<(NodeBox, f64)>, pruned: Vec<(NodeBox, f64)>| {
            let mut leaves: Vec<(NodeBox, f64)> =
                open.into_iter().map(|o| (o.node, o.bound)).collect();
            leaves.extend(stuck);
            leaves.extend(pruned);
            SearchState {
                root: root.clone(),
                leaves,
                lagrange: lagrange.clone(),
            }
        };
        if open.is_empty() || closes(lowest, &best) {
            let mut untried = std::mem::take(&mut untried);
            for o in &open {
                if let Some(z) = &o.z {
                    untried.push(o.bound, o.order, z);
                }
            }
            let state = finish(open, stuck.clone(), pruned);
            return Ok((
                match best {
                    Some(design) if stuck.is_empty() || closes(lowest, &Some(design.clone())) => {
                        // The gap closed; the relaxed points left untried are tried (module
                        // `untried`), and the best design goes down to where a descent stops
                        // (see [`descended`]).
                        let design =
                            best_of_untried(problem, b, tasks, objective, design, untried, scale);
                        let design = descended(problem, b, tasks, objective, design, scale);
                        let lower_bound = lowest.min(design.value);
                        Verdict::Optimal {
                            design,
                            lower_bound,
                            nodes,
                        }
                    }
                    None if stuck.is_empty() => Verdict::Impossible { nodes },
                    design => Verdict::Stopped {
                        design,
                        lower_bound: lowest,
                        nodes,
                    },
                },
                state,
            ));
        }
        if nodes >= options.box_limit(best.is_some()) {
            let state = finish(open, stuck, pruned);
            return Ok((
                Verdict::Stopped {
                    design: best,
                    lower_bound: lowest,
                    nodes,
                },
                state,
            ));
        }
        // Best bound first; among bounds within half the gap tolerance of the lowest (a tie:
        // for a springs-only variant every box has the same bound), the newest box, so that
        // the search dives to boxes small enough to hold a design before it widens.
        let tie = lowest + 0.5 * options.gap_tolerance * lowest.abs();
        let at = (0..open.len())
            .filter(|&p| open[p].bound <= tie)
            .max_by_key(|&p| open[p].order)
            .unwrap_or_else(|| {
                (0..open.len())
                    .min_by(|&p, &q| open[p].bound.total_cmp(&open[q].bound))
                    .expect("open is not empty")
            });
        let current = open.swap_remove(at);
        if current.stale {
            nodes += 1;
            if let Some(o) = bound_box(
                problem,
                &bases,
                &mut active,
                options,
                current.node,
                current.bound,
                current.order,
            ) {
                if closes(o.bound, &best) {
                    pruned.push((o.node, o.bound));
                } else {
                    open.push(o);
                }
            }
            continue;
        }
        // A design is sought where it could improve on the best one: where the relaxed point's
        // true objective is below it (the refinement only moves to feasibility nearby).
        let promising = |z: &DVector<f64>| {
            best.as_ref()
                .is_none_or(|d| promises(problem, tasks, objective, z, scale, d.value))
        };
        let was_promising = current.z.as_ref().is_some_and(&promising);
        let found = match &current.z {
            Some(z) if promising(z) => design_at(problem, b, tasks, objective, z, scale),
            _ => None,
        };
        // Springs first where a design could improve on the best but none was realized here
        // (or none is known at all): the spring coupling is what keeps designs out of the box.
        let springs_block = best.is_none() || (was_promising && found.is_none());
        if let Some(d) = found
            && best.as_ref().is_none_or(|bd| d.value < bd.value)
        {
            // A design that does not close the gap on its own is descended from before it is
            // kept (see [`polish`]): the boxes only propose designs near their relaxed points.
            let d = if closes(lowest, &Some(d.clone())) {
                d
            } else {
                descended(problem, b, tasks, objective, d, scale)
            };
            best = Some(d);
        }
        if closes(current.bound, &best) {
            pruned.push((current.node, current.bound));
            continue;
        }
        let mut current = current;
        if let (Some(d), Some((own, rates))) = (best.as_ref(), current.reduced.as_ref()) {
            pruned.extend(reduced_cost_cuts(
                &mut current.node,
                *own,
                rates,
                d.value,
                options.gap_tolerance,
            ));
        }
        let counterweights_first = !springs_block
            && current.z.as_ref().is_some_and(|z| {
                let (_, value, _) = merit(problem, tasks, objective, z, scale);
                value - current.bound > options.gap_tolerance * value.abs()
            });
        let Some(k) = branching_coordinate(
            problem,
            &coords,
            &root,
            &current,
            counterweights_first,
            &coupled,
            &history,
        ) else {
            stuck.push((current.node, current.bound));
            continue;
        };
        // One split, at the coordinate chosen above. Strong branching (solving the best spring
        // split too where the counterweights come first, and keeping the pair of children whose
        // rises above the parent bound have the larger product) was the rule until the search
        // got its budget to close every gap: its choice follows bound rises of the order of the
        // solver's tolerance, so a change at that level (the tails' negligible rows left out)
        // sent m3 + m5 + K42 from 82 boxes to over 6,000 at Dmax 3, and over the 117 variants
        // that take 100 boxes or more it cost 234 CPU s against 189 s for the one split.
        let boxes: Vec<(NodeBox, usize)> = current
            .node
            .split(k)
            .into_iter()
            .enumerate()
            .map(|(n, child)| (child, child_order(order, n)))
            .collect();
        nodes += boxes.len();
        let children = bound_boxes(problem, &bases, &mut active, options, boxes, current.bound);
        if let Some(d) = best.as_ref().filter(|_| options.split_history) {
            let bound = |c: &Option<Open>| c.as_ref().map(|o| o.bound);
            history.record(
                k,
                current.bound,
                d.value,
                options.gap_tolerance,
                [bound(&children[0]), bound(&children[1])],
            );
        }
        order += 2;
        for o in children.into_iter().flatten() {
            if closes(o.bound, &best) {
                if let Some(z) = &o.z {
                    untried.push(o.bound, o.order, z);
                }
                pruned.push((o.node, o.bound));
            } else {
                open.push(o);
            }
        }
    }
}

/// The largest magnitude of the tasks' unbalanced torque samples (at least 1e-9): the scale of
/// the refinement's constraint penalty.
pub(crate) fn objective_scale(tasks: &[Arc<TaskTorques>]) -> f64 {
    tasks
        .iter()
        .flat_map(|t| t.base.iter())
        .fold(0.0f64, |a, &v| a.max(v.abs()))
        .max(1e-9)
}

/// `design`, or the better verified design a descent from it reaches ([`polish::descend`]).
///
/// A search stops as soon as its best design is within the gap of its bound, wherever in the
/// flat valley of near-optimal designs its path met it; two paths (another `--seed`, another
/// sibling's design) then end at counterweights that differ by far more than their values
/// do. Descending the design that closes the gap to where the descent stops (a local minimum
/// to the simplex's tolerance, 1e-14 of the value) takes both to the same bottom wherever the
/// valley has one: on the palletizer at Dmax 3 the m6 family's designs of two seeds, 11.615360
/// and 11.615343 N·m (m6 5.17 and 4.53 kg), both became 11.615296 N·m to 4e-10 and their ΔQTR
/// agree to 1e-5 percentage points. The bound and the verdict keep their meaning: the design
/// is only ever replaced by a better verified one.
pub(crate) fn descended(
    problem: &VariantProblem,
    b: &DVector<f64>,
    tasks: &[Arc<TaskTorques>],
    objective: Objective,
    design: Design,
    scale: f64,
) -> Design {
    polish::descend(problem, b, tasks, objective, &design.x, scale)
        .filter(|p| p.value < design.value)
        .unwrap_or(design)
}

/// Whether the relaxed point `z` promises a design below `value`: its own objective (fixed
/// coordinates projected) is. A box's point is tried for a design only then (the refinement
/// only moves to feasibility nearby).
fn promises(
    problem: &VariantProblem,
    tasks: &[Arc<TaskTorques>],
    objective: Objective,
    z: &DVector<f64>,
    scale: f64,
    value: f64,
) -> bool {
    let (_, own, _) = merit(problem, tasks, objective, &project_fixed(problem, z), scale);
    own < value
}

/// The best of `design` and the verified designs found at the `untried` relaxed points (module
/// `untried`), tried in bound order where a point's own objective is below the best design's
/// so far; a design found replaces the best only when it is strictly better.
fn best_of_untried(
    problem: &VariantProblem,
    b: &DVector<f64>,
    tasks: &[Arc<TaskTorques>],
    objective: Objective,
    design: Design,
    untried: Untried,
    scale: f64,
) -> Design {
    untried
        .in_bound_order()
        .into_iter()
        .fold(design, |best, z| {
            if !promises(problem, tasks, objective, &z, scale, best.value) {
                return best;
            }
            match design_at(problem, b, tasks, objective, &z, scale) {
                Some(d) if d.value < best.value => d,
                _ => best,
            }
        })
}

/// The last pass's design (lifted point `x`, springs `springs`) carried to this pass's tasks:
/// descended from ([`descended`]) where it still meets every bound and limit on them, else the
/// best verified design a descent from it reaches (`None` when the descent meets none).
///
/// A pass that adds tasks starts a new search, whose first design comes from the fast path,
/// which realizes springs from seeded starts: two runs whose last passes ended at the same
/// design then began the next pass from different ones and could end in different valleys
/// within the gap of each other (m5 + K32 + K73 at Dmax 3 on the palletizer, after both seeds'
/// first passes met at 11.6801716 N·m: 11.680181 or 11.681675 N·m). Carrying the last design
/// gives every run the same start where the last passes agree.
pub(crate) fn carried(
    problem: &VariantProblem,
    b: &DVector<f64>,
    tasks: &[Arc<TaskTorques>],
    objective: Objective,
    x: &DVector<f64>,
    springs: &[Spring],
) -> Option<Design> {
    let scale = objective_scale(tasks);
    match verified_design(problem, tasks, objective, springs.to_vec(), x.clone()) {
        Some(d) => Some(descended(problem, b, tasks, objective, d, scale)),
        None => polish::descend(problem, b, tasks, objective, x, scale),
    }
}

/// Smallest share of a coordinate's width that a reduced-cost cut must remove to be made: each
/// part cut off is a box that the next search on more tasks solves again, so slivers are not
/// worth it.
const CUT_SHARE: f64 = 0.1;

/// Share of the gap tolerance below the best design's value at which the reduced-cost cuts
/// aim: a part cut off gets this target as its bound, which closes the gap
/// (`target ≥ value·(1 − gap)`) and is kept off the tolerance's very edge so that the certified
/// bound does not sink to it. Measured on the palletizer at Dmax 3 (release, one run each):
/// 17,511 boxes without the cuts; with them 16,431 at 0.9 and a cut share of 0.1, 16,820 at
/// 0.5 and 0.1, 16,841 at 0.5 and 0.02, 16,646 at 0.99 and 0.05, 16,465 at 0.9 and 0.3 (the
/// counts move by ±2 % with any change of a search's path); the same verdicts and every gap
/// ≤ 1e-3 in each.
const TARGET_SHARE: f64 = 0.9;

/// Cuts from the box `node` the parts where no point of its relaxation reaches below the target
/// `value − TARGET_SHARE·gap·|value|`, `value` the best design's (reduced-cost bound
/// tightening). A coordinate end whose row has the dual rate `r` (see
/// [`crate::relaxation::Relaxed::reduced`]) keeps the coordinate within `(target − b)/r` of
/// that end, `b` the box's own bound: every point of the relaxation has an objective of at
/// least `b + r·d` at distance `d` from the end, so the part beyond holds no design below the
/// target. Returns the parts cut off, each with the target as its bound (they close the gap,
/// and a next search on more tasks solves them again like every box this one leaves); the box
/// keeps the rest. A cut must take at least [`CUT_SHARE`] of the coordinate's width.
///
/// The rates only weigh the rows that bound one coordinate; the box's other rows (the
/// McCormick planes, the secants) depend on its ranges too, but not on one coordinate's
/// distance alone, so most of the dual weight is not used: on the palletizer at Dmax 3 the
/// cuts save about 6 % of the boxes (see [`TARGET_SHARE`]).
pub(crate) fn reduced_cost_cuts(
    node: &mut NodeBox,
    own: f64,
    rates: &[EndRate],
    value: f64,
    gap: f64,
) -> Vec<(NodeBox, f64)> {
    let target = value - TARGET_SHARE * gap * value.abs();
    if target.partial_cmp(&own) != Some(std::cmp::Ordering::Greater) {
        return Vec::new();
    }
    let mut cut = Vec::new();
    for &EndRate {
        coordinate: k,
        upper,
        rate,
    } in rates
    {
        // A little farther than the exact reach: the part cut off is then certainly above the
        // target, whatever the rounding of this quotient.
        let reach = (target - own) / rate * (1.0 + 1e-9);
        let [lo, hi] = node.ranges[k];
        let width = hi - lo;
        if !(reach.is_finite() && width > 0.0 && reach < (1.0 - CUT_SHARE) * width) {
            continue;
        }
        let mut far = node.clone();
        if upper {
            far.ranges[k][1] = hi - reach;
            node.ranges[k][0] = hi - reach;
        } else {
            far.ranges[k][0] = lo + reach;
            node.ranges[k][1] = lo + reach;
        }
        cut.push((far, target));
    }
    cut
}

/// The order of the `n`-th child box of a split made when the orders given so far end at
/// `order` (each split takes two: the loop adds 2 after it). Every child is newer than every
/// box before the split, so that among tied bounds the search dives into the boxes it just
/// made; within a split the upper half (`n` = 1) is newer than the lower (`n` = 0).
fn child_order(order: usize, n: usize) -> usize {
    order + 1 + n
}

/// The bounds a design must meet, in words, for a certificate: each spring's stiffness and
/// anchor ranges, each counterweight's mass and offset ranges.
pub fn bounds_in_words(problem: &VariantProblem) -> String {
    const AXIS: [&str; 3] = ["x", "y", "z"];
    let mut parts = Vec::new();
    for s in &problem.springs {
        let mut p = format!(
            "{}: K ∈ [{}, {}] N/m, |a| ∈ [{}, {}] m, |b| ∈ [{}, {}] m",
            s.label,
            s.bounds.stiffness[0],
            s.bounds.stiffness[1],
            s.bounds.anchor_a[0],
            s.bounds.anchor_a[1],
            s.bounds.anchor_b[0],
            s.bounds.anchor_b[1]
        );
        for (name, bx) in [("a", &s.bounds.box_a), ("b", &s.bounds.box_b)] {
            for (axis, r) in bx.iter().enumerate() {
                if r[0].is_finite() || r[1].is_finite() {
                    p.push_str(&format!(", {name}_{} ∈ [{}, {}] m", AXIS[axis], r[0], r[1]));
                }
            }
        }
        parts.push(p);
    }
    for c in &problem.counterweights {
        parts.push(format!(
            "{}: m ∈ [{}, {}] kg, |r| ∈ [{}, {}] m",
            c.label, c.bounds.mass[0], c.bounds.mass[1], c.bounds.radius[0], c.bounds.radius[1]
        ));
    }
    parts.join("; ")
}

#[cfg(test)]
mod tests {
    use super::{
        CUT_SHARE, KeptRanges, NodeBox, TARGET_SHARE, child_order, largest_with_ties_to_the_first,
        reduced_cost_cuts,
    };
    use crate::relaxation::EndRate;

    /// The penalty's scale is the largest unbalanced torque magnitude over every task and
    /// sample (3.5 here, a negative sample of the first task), never below 1e-9.
    #[test]
    fn the_objective_scale_is_the_largest_unbalanced_torque() {
        use crate::torque::TaskTorques;
        use std::sync::Arc;
        let task = |task: usize, base: Vec<f64>| {
            Arc::new(TaskTorques {
                task,
                samples: base.len(),
                actuators: 1,
                base,
                sensitivity: Vec::new(),
            })
        };
        let tasks = [task(0, vec![1.0, -3.5]), task(1, vec![2.0, 0.5])];
        assert_eq!(super::objective_scale(&tasks), 3.5);
        assert_eq!(super::objective_scale(&[task(2, vec![0.0, 0.0])]), 1e-9);
        assert_eq!(super::objective_scale(&[]), 1e-9);
    }

    /// Weights within 1e-9 of each other are a tie the first index wins, whichever comes
    /// larger by rounding; a weight larger by 1e-6 wins wherever it stands.
    #[test]
    fn the_split_rule_gives_a_tie_to_the_first_coordinate() {
        let pick = |w: &[f64]| largest_with_ties_to_the_first(w.iter().copied().enumerate());
        assert_eq!(pick(&[1.0, 1.0 + 1e-12, 0.5]), Some(0));
        assert_eq!(pick(&[1.0 + 1e-12, 1.0, 0.5]), Some(0));
        assert_eq!(pick(&[0.5, 1.0, 1.0 - 1e-12]), Some(1));
        assert_eq!(pick(&[1.0, 1.0 + 1e-6]), Some(1));
        assert_eq!(pick(&[1.0 + 1e-6, 1.0]), Some(0));
        assert_eq!(pick(&[]), None);
    }

    fn end(coordinate: usize, upper: bool, rate: f64) -> EndRate {
        EndRate {
            coordinate,
            upper,
            rate,
        }
    }

    /// By hand: a box [0, 1] × [−2, 2] with bound 10, the best design at 10.02 and a gap of
    /// 1e-3 aim at 10.02 − 0.9·1e-3·10.02 = 10.010982. A rate of 100 per unit at coordinate 0's
    /// lower end keeps it within 0.010982/100 = 1.0982e-4 of 0; a rate of 1 at coordinate 1's
    /// upper end keeps it within 0.010982 of 2; a rate of 0.0122 at coordinate 0's upper end
    /// keeps it within 0.010982/0.0122 = 0.9 of 1.0982e-4, more than the width left after the
    /// first cut, so it cuts nothing. (The reach is rounded outwards by 1e-9 relative.)
    #[test]
    fn reduced_cost_cuts_keep_each_coordinate_within_its_reach() {
        assert_eq!(TARGET_SHARE, 0.9);
        let target = 10.02 - 0.9 * 1e-3 * 10.02;
        let mut node = NodeBox {
            ranges: vec![[0.0, 1.0], [-2.0, 2.0]],
        };
        let rates = [
            end(0, false, 100.0),
            end(1, true, 1.0),
            end(0, true, 0.0122),
        ];
        let cut = reduced_cost_cuts(&mut node, 10.0, &rates, 10.02, 1e-3);
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-8 * (1.0 + b.abs());
        assert_eq!(cut.len(), 2, "{cut:?}");
        let reach0 = (target - 10.0) / 100.0;
        let reach1 = target - 10.0;
        assert!(close(reach0, 1.0982e-4) && close(reach1, 0.010982));
        // The box keeps [0, reach0] × [2 − reach1, 2]; the parts cut off are the rest of
        // coordinate 0, then the rest of coordinate 1 within the kept coordinate 0.
        let kept = &node.ranges;
        assert!(kept[0][0] == 0.0 && close(kept[0][1], reach0), "{kept:?}");
        assert!(
            close(kept[1][0], 2.0 - reach1) && kept[1][1] == 2.0,
            "{kept:?}"
        );
        let (first, second) = (&cut[0], &cut[1]);
        assert!(close(first.0.ranges[0][0], reach0) && first.0.ranges[0][1] == 1.0);
        assert_eq!(first.0.ranges[1], [-2.0, 2.0]);
        assert!(close(second.0.ranges[0][1], reach0) && second.0.ranges[0][0] == 0.0);
        assert!(second.0.ranges[1][0] == -2.0 && close(second.0.ranges[1][1], 2.0 - reach1));
        // Every part cut off holds the target as its bound, which closes the gap.
        for (_, bound) in &cut {
            assert!(close(*bound, target));
            assert!(10.02 - bound <= 1e-3 * 10.02);
        }
        // The reach is rounded outwards: the cut never comes nearer the end than the exact
        // reach.
        assert!(kept[0][1] >= reach0 && 2.0 - kept[1][0] >= reach1);
    }

    /// No cut where the box's bound already reaches the target, or where the reach leaves
    /// more than `1 − CUT_SHARE` of the width.
    #[test]
    fn reduced_cost_cuts_need_a_box_below_the_target_and_a_real_cut() {
        let target = 10.02 - 0.9 * 1e-3 * 10.02;
        let unit = || NodeBox {
            ranges: vec![[0.0, 1.0]],
        };
        let rates = [end(0, false, 100.0)];
        assert!(reduced_cost_cuts(&mut unit(), target + 1e-9, &rates, 10.02, 1e-3).is_empty());
        assert_eq!(
            reduced_cost_cuts(&mut unit(), 10.0, &rates, 10.02, 1e-3).len(),
            1
        );
        // Reach 0.010982 / r against a width of 1: cut at r just above 0.010982/(1 − share),
        // not just below.
        let edge = (target - 10.0) / (1.0 - CUT_SHARE);
        let cuts = reduced_cost_cuts(
            &mut unit(),
            10.0,
            &[end(0, false, edge * 1.001)],
            10.02,
            1e-3,
        );
        assert_eq!(cuts.len(), 1);
        let mut sliver = unit();
        let none = reduced_cost_cuts(
            &mut sliver,
            10.0,
            &[end(0, false, edge * 0.999)],
            10.02,
            1e-3,
        );
        assert!(none.is_empty());
        assert_eq!(sliver.ranges, vec![[0.0, 1.0]]);
    }

    /// A range is solved again exactly when its column was not solved on this box: counted
    /// by hand over a sequence of requests on two boxes and three columns.
    #[test]
    fn a_kept_range_is_reused_only_on_the_box_it_was_solved_on() {
        let wide = NodeBox {
            ranges: vec![[-1.0, 1.0], [0.0, 2.0]],
        };
        let narrow = NodeBox {
            ranges: vec![[-0.5, 1.0], [0.0, 2.0]],
        };
        let mut kept = KeptRanges::default();
        let mut solves = 0;
        // (column, box, solved now?, the range a solve gives)
        let requests = [
            (3, &wide, true, 1.0),
            (3, &wide, false, 2.0),
            (5, &wide, true, 3.0),
            (3, &wide, false, 4.0),
            (3, &narrow, true, 5.0),
            (3, &narrow, false, 6.0),
            (5, &wide, false, 7.0),
            (5, &narrow, true, 8.0),
            (3, &wide, true, 9.0),
            (7, &narrow, true, 10.0),
            (3, &wide, false, 11.0),
        ];
        let mut latest = std::collections::BTreeMap::new();
        for (n, &(column, node, fresh, value)) in requests.iter().enumerate() {
            let before = solves;
            let r = kept.range(column, node, || {
                solves += 1;
                Some([value, value])
            });
            assert_eq!(solves > before, fresh, "request {n}");
            if fresh {
                latest.insert(column, value);
            }
            assert_eq!(r, Some([latest[&column]; 2]), "request {n}");
        }
        assert_eq!(solves, 6);
    }

    /// The search picks the newest of the boxes whose bounds tie: a split's children must be
    /// newer than every box before it, the upper half newer than the lower, and the next
    /// split's children newer than this one's.
    #[test]
    fn children_are_numbered_after_every_box_before_them() {
        for order in [0, 1, 2, 7, 400] {
            let c: Vec<usize> = (0..2).map(|n| child_order(order, n)).collect();
            assert!(c[0] > order, "order {order}: {c:?}");
            assert!(c[1] > c[0], "order {order}: {c:?}");
            assert!(child_order(order + 2, 0) > c[1], "order {order}: {c:?}");
        }
    }
}
