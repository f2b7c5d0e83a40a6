//! The critical-task iteration (paper Proc-5…8) over many variants at once.
//!
//! Every variant starts from the unbalanced robot's critical tasks (each actuator's CRT, the
//! CPT of each actuator with a peak limit; for minimax also the QTR task). A pass solves the
//! relaxation on the working set (lower bound), refines the recovered point with the exact
//! objective, realizes the springs, and then *all* tasks are evaluated with the dynamics crate
//! — one batched grid evaluation for every variant still iterating. Tasks that are now critical
//! and not yet in the working set are added and the variant is solved again; it stops when no
//! new critical task appears (converged) or after `max_iterations` passes.
//!
//! Working-set objective: each actuator's largest RMS over the working-set tasks (RMS*) or the
//! largest per-task total RMS (minimax). It never exceeds the all-task objective at the same
//! point, so the relaxation's bound on the final working set bounds the true optimum.

mod finish;
mod grid;
mod peaks;
mod siblings;
mod state;
mod twin_runs;

use std::collections::BTreeSet;

use counterpoise_balance::linear::solve;
use counterpoise_balance::{Status, VariantResult};
use nalgebra::DVector;
use rayon::prelude::*;

use crate::certify::{BranchOptions, Design, SearchState, Verdict, branch_and_bound};
use crate::context::Context;
use crate::problem::{Objective, VariantProblem};
use crate::progress::{ProgressSink, ShareCounter, StageCounter};
use crate::refine::{
    FEASIBILITY_TOL, counterweight_directions, merit, project_fixed, project_radius, refine,
};
use crate::relaxation::{solve_bounds_only, solve_relaxation};
use crate::result::{Iteration, OptimisedVariant};
use crate::springs::{StartRecord, realize_springs_seeded};
use crate::timing::Stopwatch;
use finish::*;
use grid::*;
use state::*;

pub use grid::objective_of;
pub use peaks::{delta_r, lowest_delta_r};
pub use siblings::sibling_group;
pub use state::{FinalReactionSolve, LoopTorques, OptimiseOptions, StageTimings};

/// Optimises one balanced variant (see [`optimise_all`]).
pub fn optimise_variant(
    ctx: &Context,
    variant: &VariantResult,
    options: &OptimiseOptions,
) -> OptimisedVariant {
    optimise_all(ctx, std::slice::from_ref(variant), options)
        .pop()
        .expect("one result per balanced variant")
}

/// Optimises every `balanced` variant of `variants` (others are skipped), in parallel on the
/// current rayon pool; results are in input order and do not depend on the thread count.
pub fn optimise_all(
    ctx: &Context,
    variants: &[VariantResult],
    options: &OptimiseOptions,
) -> Vec<OptimisedVariant> {
    optimise_all_timed(ctx, variants, options).0
}

/// [`optimise_all`] with the wall and CPU time of each stage.
pub fn optimise_all_timed(
    ctx: &Context,
    variants: &[VariantResult],
    options: &OptimiseOptions,
) -> (Vec<OptimisedVariant>, StageTimings) {
    optimise_all_reporting(ctx, variants, options, &crate::progress::silent)
}

/// [`optimise_all_timed`] that reports its progress to `progress` as variants finish each stage.
pub fn optimise_all_reporting(
    ctx: &Context,
    variants: &[VariantResult],
    options: &OptimiseOptions,
    progress: ProgressSink<'_>,
) -> (Vec<OptimisedVariant>, StageTimings) {
    let mut timings = StageTimings::default();
    let balanced: Vec<&VariantResult> = variants
        .iter()
        .filter(|v| v.status == Status::Balanced)
        .collect();
    let twins = if options.twins {
        crate::twins::spring_twins(&ctx.basis, &ctx.catalogue, &ctx.bounds)
    } else {
        Vec::new()
    };
    let leaders = twin_runs::leaders(&balanced, &twins, ctx);
    let mut leader_runs: Vec<Run> = leaders
        .variants
        .iter()
        .map(|v| new_run(ctx, v, options))
        .collect();
    timings.searched = leader_runs.len();
    critical_task_loop(ctx, &mut leader_runs, options, &mut timings, progress);
    let runs: Vec<Run> = balanced
        .iter()
        .zip(&leaders.of)
        .map(|(v, &k)| {
            let leader = &leader_runs[k];
            let own = leader
                .elements
                .iter()
                .eq(v.elements.iter().map(|e| &e.label));
            if own {
                return leader.clone();
            }
            let member = new_run(ctx, v, options);
            twin_runs::follow(ctx, &twins, leader, member).unwrap_or_else(|| {
                // No counterpart for some slot: search the variant itself.
                let mut alone = vec![new_run(ctx, v, options)];
                timings.searched += 1;
                critical_task_loop(ctx, &mut alone, options, &mut timings, progress);
                alone.pop().expect("one run")
            })
        })
        .collect();
    let out = finish(ctx, runs, options, &mut timings, progress);
    (out, timings)
}

/// The runs `active` in the order a pass starts them: those with counterweights first (their
/// relaxations are larger, and on the palletizer at Dmax 2 they take 0.02–0.66 s against
/// 0.01–0.03 s for two springs), each group in index order. A pass hands them out one at a
/// time in this order (`par_bridge`), so a long variant starts early instead of last in a
/// thread's half of the range while the other thread idles. Each outcome depends on its run
/// alone: the order changes when a variant is solved, never what it gets.
fn heaviest_first(runs: &[Run], active: &[usize]) -> Vec<usize> {
    let counterweights = |k: usize| {
        runs[k]
            .problem
            .as_ref()
            .map_or(0, |p| p.counterweights.len())
    };
    let mut order = active.to_vec();
    order.sort_by_key(|&k| (std::cmp::Reverse(counterweights(k)), k));
    order
}

/// The passes of the critical-task loop (Proc-5…8): every run leaves it converged, stopped
/// after `max_iterations` passes, discarded or undecided.
fn critical_task_loop(
    ctx: &Context,
    runs: &mut [Run],
    options: &OptimiseOptions,
    timings: &mut StageTimings,
    progress: ProgressSink<'_>,
) {
    for _pass in 0..options.max_iterations.max(1) {
        let active: Vec<usize> = (0..runs.len())
            .filter(|&k| runs[k].state == State::Running)
            .collect();
        if active.is_empty() {
            break;
        }
        let union: Vec<usize> = active
            .iter()
            .flat_map(|&k| runs[k].working.iter().copied())
            .collect::<BTreeSet<_>>()
            .into_iter()
            .collect();
        timings.passes += 1;
        let started = Stopwatch::start();
        let (_, failures) = ctx.torques.get(&ctx.model, &ctx.tasks, &union);
        let failed: BTreeSet<usize> = failures.iter().map(|f| f.0).collect();

        let counter =
            StageCounter::start(progress, "critical-task pass", timings.passes, active.len());
        type Outcome = (usize, Result<Candidate, Failure>, Option<SearchState>);
        let mut outcomes: Vec<Outcome> = heaviest_first(runs, &active)
            .into_iter()
            .par_bridge()
            .map(|k| {
                let mut search = runs[k].search.clone();
                let outcome = step(ctx, &runs[k], &failed, options, &mut search);
                counter.tick();
                (k, outcome, search)
            })
            .collect();
        outcomes.sort_by_key(|o| o.0);
        timings.solve += started.elapsed();
        let started = Stopwatch::start();
        let mut evaluated: Vec<usize> = Vec::new();
        for (k, outcome, search) in outcomes {
            runs[k].search = search;
            match outcome {
                Ok(c) => {
                    runs[k].candidate = Some(c);
                    evaluated.push(k);
                }
                Err(failure) => runs[k].state = failure.into_state(),
            }
        }
        if evaluated.is_empty() {
            continue;
        }
        if options.siblings {
            for (k, shared) in siblings::sibling_designs(ctx, runs, &evaluated, options) {
                let cand = runs[k]
                    .candidate
                    .as_mut()
                    .expect("evaluated runs have a candidate");
                cand.x = shared.design.x;
                cand.cws = shared.design.cws;
                cand.springs = shared.design.springs;
                cand.working_value = shared.design.value;
                cand.spring_starts = Some(shared.starts);
                cand.design_from = Some(shared.from);
            }
        }
        timings.solve += started.elapsed();
        let started = Stopwatch::start();
        let share = ShareCounter::start(
            progress,
            "all-task evaluation",
            timings.passes,
            evaluated.len(),
        );
        let dyn_variants = candidate_variants(&ctx.model, runs, &evaluated);
        let indicators = grid_indicators(
            ctx,
            &dyn_variants,
            false,
            options.loop_torques.combination(),
            &share,
        );
        timings.loop_grid += started.elapsed();
        let indicators = match indicators {
            Ok(i) => i,
            Err(e) => {
                for &k in &evaluated {
                    runs[k].state = State::Undecided(format!("dynamics evaluation failed: {e}"));
                }
                continue;
            }
        };
        for (&k, ind) in evaluated.iter().zip(&indicators) {
            let run = &mut runs[k];
            let problem = run.problem.as_ref().expect("problem");
            let cand = run.candidate.as_ref().expect("candidate");
            let critical = critical_tasks(ctx, problem, ind, options.objective);
            let added: Vec<usize> = critical
                .into_iter()
                .filter(|w| !run.working.contains(w))
                .collect::<BTreeSet<_>>()
                .into_iter()
                .collect();
            run.iterations.push(Iteration {
                tasks: run.working.len(),
                lower_bound: cand.lower_bound,
                objective_working: cand.working_value,
                objective_all: objective_of(ind, options.objective),
                added: added.iter().map(|&w| ctx.pair(w)).collect(),
                relaxation_status: cand.relaxation_status,
                relaxation_iterations: cand.relaxation_iterations,
                gap_before_refinement: cand.gap_before,
                boxes: cand.boxes,
                design_from: cand.design_from.as_ref().map(|e| e.join(" + ")),
            });
            if added.is_empty() {
                run.state = State::Converged;
            } else {
                run.working.extend(added);
            }
        }
    }
    for run in runs.iter_mut() {
        if run.state == State::Running {
            run.state = State::Stopped;
        }
    }
}

fn new_run(ctx: &Context, v: &VariantResult, options: &OptimiseOptions) -> Run {
    let set: Vec<usize> = v.elements.iter().map(|e| e.entry).collect();
    let solution = solve(&ctx.basis, &set);
    let problem = VariantProblem::new(
        &ctx.model,
        &ctx.catalogue,
        &ctx.bounds,
        &set,
        solution,
        |b| ctx.torques.slot_of(b),
    );
    let mut working = BTreeSet::new();
    for a in &ctx.unbalanced.actuators {
        if let Some(w) = ctx.task_index(a.crt) {
            working.insert(w);
        }
    }
    let limits = ctx
        .model
        .balancing
        .as_ref()
        .map(|b| b.peak_limits.clone())
        .unwrap_or_default();
    for (n, a) in ctx.unbalanced.actuators.iter().enumerate() {
        if limits.get(n).copied().flatten().is_some()
            && let Some(w) = ctx.task_index(a.cpt)
        {
            working.insert(w);
        }
    }
    if options.objective == Objective::Minimax
        && let Some(w) = ctx.task_index(ctx.unbalanced.qtr_task)
    {
        working.insert(w);
    }
    let (problem, state) = match problem {
        Ok(p) => (Some(p), State::Running),
        Err(e) => (None, State::Discarded(e)),
    };
    Run {
        elements: v.elements.iter().map(|e| e.label.clone()).collect(),
        class: v.class,
        problem,
        working: working.into_iter().collect(),
        iterations: Vec::new(),
        state,
        candidate: None,
        search: None,
    }
}

/// One pass for one variant: relaxation, recovery, refinement, springs.
///
/// A relaxation proved infeasible discards the variant (the certificate), with the binding
/// constraint named. Any other status short of `Solved` is not a verdict: the local search
/// starts from the relaxation's last iterate, the bounds-only relaxation's point and the
/// particular solution in turn, and the pass continues without a certified lower bound (the
/// trivial bound 0 is recorded). If no start leads to a point within every bound, the variant
/// is undecided, with the smallest violation found.
fn step(
    ctx: &Context,
    run: &Run,
    failed: &BTreeSet<usize>,
    options: &OptimiseOptions,
    search: &mut Option<SearchState>,
) -> Result<Candidate, Failure> {
    let problem = run
        .problem
        .as_ref()
        .expect("running variants have a problem");
    if let Some(w) = run.working.iter().find(|w| failed.contains(w)) {
        return Err(Failure::Undecided(format!(
            "the kinematics of critical task {:?} failed",
            ctx.pair(*w)
        )));
    }
    let (tasks, _) = ctx.torques.get(&ctx.model, &ctx.tasks, &run.working);
    // Every design a pass keeps has the offsets no torque or relation sees centred (`centre`).
    let centre = |d: Design| crate::centre::centred(problem, &tasks, options.objective, d);
    let relaxed = solve_relaxation(
        problem,
        &tasks,
        options.objective,
        options.solver_iterations,
    );
    let status = relaxed.solution.status;
    let discard = || {
        Failure::Discard(crate::diagnose::infeasibility_reason(
            problem,
            &tasks,
            options.objective,
            options.solver_iterations,
            &ctx.unbalanced
                .actuators
                .iter()
                .map(|a| a.name.clone())
                .collect::<Vec<_>>(),
            |w| ctx.pair(w),
        ))
    };
    if status.is_infeasible() {
        return Err(discard());
    }
    let solved = status == crate::clarabel_map::ConicStatus::Solved;
    let mut starts = vec![relaxed.z.clone()];
    if !solved {
        let bounds_only = solve_bounds_only(problem, options.solver_iterations);
        if bounds_only.solution.status.is_infeasible() {
            return Err(discard());
        }
        starts.push(bounds_only.z);
        starts.push(DVector::zeros(problem.dim()));
        starts.retain(|z| z.iter().all(|v| v.is_finite()));
    }
    let lower = if solved { relaxed.bound } else { 0.0 };
    let dirs = counterweight_directions(problem);
    let scale = if solved {
        lower.abs().max(1e-9)
    } else {
        tasks
            .iter()
            .flat_map(|t| t.base.iter())
            .fold(0.0f64, |a, &b| a.max(b.abs()))
            .max(1e-9)
    };
    let mut smallest_violation = f64::INFINITY;
    let mut chosen: Option<(DVector<f64>, f64)> = None;
    for z0 in &starts {
        let z_fixed = project_fixed(problem, z0);
        let z_start = project_radius(problem, &z_fixed, &dirs).unwrap_or(z_fixed);
        let (_, v0, viol0) = merit(problem, &tasks, options.objective, &z_start, scale);
        let gap_before = if solved && viol0 <= FEASIBILITY_TOL && v0.is_finite() {
            ((v0 - lower) / v0.max(1e-300)).max(0.0)
        } else {
            f64::INFINITY
        };
        if gap_before <= options.gap_tolerance {
            chosen = Some((z_start, gap_before));
            break;
        }
        let refined = refine(problem, &tasks, options.objective, &z_start, &dirs, scale);
        if refined.feasible {
            chosen = Some((refined.z, gap_before));
            break;
        }
        smallest_violation = smallest_violation.min(refined.violation);
    }
    let fast = chosen
        .as_ref()
        .and_then(|(z, _)| fast_design(ctx, problem, &tasks, options, z));
    let gap_before = chosen.as_ref().map_or(f64::INFINITY, |c| c.1);
    if !solved {
        // Without a certified bound the search cannot prove anything: keep what was found.
        let Some((design, record)) = fast else {
            let limits = if problem.peak_limits.iter().any(Option::is_some) {
                " and peak limit"
            } else {
                ""
            };
            return Err(Failure::Undecided(format!(
                "no parameters meeting every bound{limits} were found from {} starting points \
                 (smallest relative violation {smallest_violation:.2e}), but none are proved \
                 impossible; the convex relaxation could not be solved either (clarabel: {})",
                starts.len(),
                status.name()
            )));
        };
        return Ok(candidate(
            centre(design),
            0.0,
            false,
            status,
            &relaxed,
            gap_before,
            record,
            0,
        ));
    }
    let b = &ctx.basis.unbalanced;
    // The last pass's design, carried to this pass's tasks (see `certify::carried`).
    let carried = run.candidate.as_ref().and_then(|c| {
        crate::certify::carried(problem, b, &tasks, options.objective, &c.x, &c.springs)
    });
    let (incumbent, record) = first_design(fast, carried);
    let record = record.flatten();
    // The first design is accepted when it is within the gap tolerance of the bound;
    // otherwise the branch-and-bound certifies the optimum or proves that none exists.
    if let Some(design) = &incumbent
        && design.value - lower <= options.gap_tolerance * design.value.abs()
    {
        return Ok(candidate(
            centre(design.clone()),
            lower,
            true,
            status,
            &relaxed,
            gap_before,
            record,
            0,
        ));
    }
    let branch = options.branch_options();
    let (verdict, state) = branch_and_bound(
        problem,
        b,
        &tasks,
        options.objective,
        &branch,
        incumbent,
        search.take(),
    )
    .map_err(Failure::Undecided)?;
    *search = Some(state);
    match verdict {
        Verdict::Optimal {
            design,
            lower_bound,
            nodes,
        }
        | Verdict::Stopped {
            design: Some(design),
            lower_bound,
            nodes,
        } => Ok(candidate(
            centre(design),
            lower_bound.max(lower),
            true,
            status,
            &relaxed,
            gap_before,
            record,
            nodes,
        )),
        Verdict::Stopped {
            design: None,
            lower_bound,
            nodes,
        } => Err(Failure::Undecided(format!(
            "the search stopped at its limit of {} boxes ({} × --max-nodes while no design is \
             known; {nodes} solved in this pass) before finding a design within the bounds or \
             proving that none exists (lower bound {:.4} N·m)",
            branch.box_limit(false),
            crate::certify::NO_DESIGN_BUDGET_FACTOR,
            lower_bound.max(lower)
        ))),
        Verdict::Impossible { nodes } => Err(Failure::Discard(impossibility_certificate(
            ctx,
            problem,
            &tasks,
            &branch,
            nodes,
            search.as_ref().map(SearchState::restart),
        ))),
    }
}

/// The first design of a pass and the record that goes with it: of the fast path's design
/// (with its record `R`) and the last pass's design carried to this pass's tasks, the lower,
/// ties to the carried one, which does not depend on the seed; the fast path's record of spring
/// starts goes with its own design only (the spring choice reuses it for the same
/// counterweights).
fn first_design<R>(
    fast: Option<(Design, R)>,
    carried: Option<Design>,
) -> (Option<Design>, Option<R>) {
    match (fast, carried) {
        (Some((f, _)), Some(c)) if c.value <= f.value => (Some(c), None),
        (Some((f, r)), _) => (Some(f), Some(r)),
        (None, c) => (c, None),
    }
}

/// The candidate of a pass from a design.
fn candidate(
    design: Design,
    lower_bound: f64,
    bound_certified: bool,
    status: crate::clarabel_map::ConicStatus,
    relaxed: &crate::relaxation::Relaxed,
    gap_before: f64,
    spring_starts: Option<StartRecord>,
    boxes: usize,
) -> Candidate {
    Candidate {
        boxes,
        x: design.x,
        cws: design.cws,
        springs: design.springs,
        lower_bound,
        bound_certified,
        working_value: design.value,
        relaxation_status: status,
        relaxation_iterations: relaxed.solution.iterations,
        gap_before,
        spring_starts,
        design_from: None,
    }
}

/// The fast path: springs realized by local search for the refined counterweights at `z`
/// (then with more starts, then moving the counterweights too); a design only when every
/// bound and peak limit holds on the working set.
fn fast_design(
    ctx: &Context,
    problem: &VariantProblem,
    tasks: &[std::sync::Arc<crate::torque::TaskTorques>],
    options: &OptimiseOptions,
    z: &DVector<f64>,
) -> Option<(Design, Option<StartRecord>)> {
    let x = problem.lifted(z);
    let b = &ctx.basis.unbalanced;
    let seed = options.start_seed;
    let (mut springs, _, mut starts_record) =
        realize_springs_seeded(problem, b, &x, options.spring_starts, false, None, seed);
    // Nothing found means the variant has springs (without any, the realization returns the
    // point itself): retry with more starts.
    if springs.is_empty() {
        (springs, _, starts_record) = realize_springs_seeded(
            problem,
            b,
            &x,
            options.spring_starts * 4,
            false,
            Some(&starts_record),
            seed,
        );
    }
    let judge = |(s, xj): crate::springs::Realized| {
        let cws = problem.cw_physical(&xj);
        let e = problem.evaluate(&cws, tasks);
        let excess = problem
            .bound_violations(&xj)
            .into_iter()
            .fold(problem.peak_excess(&e), f64::max);
        let value = e.objective(options.objective, problem.actuators);
        (excess, value, s, xj, cws)
    };
    let design = |(excess, value, springs, x, cws): (f64, f64, _, _, _)| {
        (excess <= FEASIBILITY_TOL).then_some(Design {
            x,
            cws,
            springs,
            value,
        })
    };
    if let Some(found) = springs.into_iter().next() {
        return design(judge(found)).map(|d| (d, Some(starts_record)));
    }
    if problem.counterweights.is_empty() {
        return None;
    }
    // The motors' best counterweights leave no admissible springs: move both, and keep the
    // best admissible set that meets the peak limits on the working set.
    let (joint, _, _) =
        realize_springs_seeded(problem, b, &x, options.spring_starts * 4, true, None, seed);
    joint
        .into_iter()
        .map(judge)
        .filter(|j| j.0 <= FEASIBILITY_TOL)
        .min_by(|p, q| p.1.total_cmp(&q.1))
        .and_then(design)
        .map(|d| (d, Some(starts_record)))
}

/// Boxes the bounds-only search may use to word a certificate.
const CERTIFICATE_NODES: usize = 30;

/// The certificate of a variant the search proved impossible: the bounds alone when the
/// bounds-only search also finds no box (else the peak limits on the working set), with the
/// number of boxes.
fn impossibility_certificate(
    ctx: &Context,
    problem: &VariantProblem,
    tasks: &[std::sync::Arc<crate::torque::TaskTorques>],
    branch: &BranchOptions,
    nodes: usize,
    first_box: Option<SearchState>,
) -> String {
    let b = &ctx.basis.unbalanced;
    let proof = format!(
        "proved by splitting the anchor and counterweight box into {nodes} boxes, none of \
         which holds a solution"
    );
    let limited: Vec<String> = problem
        .peak_limits
        .iter()
        .zip(&ctx.unbalanced.actuators)
        .filter_map(|(l, a)| l.map(|l| format!("{} ≤ {l} N·m", a.name)))
        .collect();
    if limited.is_empty() || tasks.is_empty() {
        return format!(
            "no parameters within the bounds balance this variant ({}); {proof}",
            crate::certify::bounds_in_words(problem)
        );
    }
    // Which constraint excludes the variant: the bounds alone, when the bounds-only search
    // proves it too (a smaller budget: this only chooses the words).
    let wording = BranchOptions {
        max_nodes: branch.max_nodes.min(CERTIFICATE_NODES),
        ..*branch
    };
    match branch_and_bound(
        problem,
        b,
        &[],
        Objective::Minimax,
        &wording,
        None,
        first_box,
    )
    .map(|(verdict, _)| verdict)
    {
        Ok(Verdict::Impossible { nodes: n }) => format!(
            "no parameters within the bounds balance this variant ({}); proved by splitting \
             the anchor and counterweight box into {n} boxes, none of which holds a solution",
            crate::certify::bounds_in_words(problem)
        ),
        Ok(Verdict::Optimal { .. }) => format!(
            "parameters within the bounds exist, but none meets the peak limits ({}) on the \
             critical tasks; {proof}",
            limited.join(", ")
        ),
        _ => format!(
            "no parameters within the bounds ({}) meet the peak limits ({}) on the critical \
             tasks; {proof}",
            crate::certify::bounds_in_words(problem),
            limited.join(", ")
        ),
    }
}

#[cfg(test)]
mod tests;
