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

use counterpoise_dynamics::linalg::checked_svd;
use std::collections::{BTreeMap, BTreeSet};

use counterpoise_balance::linear::solve;
use counterpoise_balance::{Attachment, Status, VariantResult};
use counterpoise_dynamics::params::{Counterweight, ParameterSet, Spring, Variant};
use counterpoise_dynamics::runner::Workspace;
use counterpoise_dynamics::{
    Combination, EvaluateOptions, Evaluator, GridProgress, Indicators,
    evaluate_grid_indicators_reporting,
};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::certify::{BranchOptions, Design, SearchState, Verdict, branch_and_bound};
use crate::context::Context;
use crate::problem::{CwPhysical, Objective, VariantProblem};
use crate::progress::{ProgressSink, ShareCounter, StageCounter};
use crate::refine::{
    FEASIBILITY_TOL, counterweight_directions, merit, project_fixed, project_radius, refine,
};
use crate::relaxation::{solve_bounds_only, solve_relaxation};
use crate::result::{
    FreeParameter, Iteration, OptimisedCounterweight, OptimisedSpring, OptimisedStatus,
    OptimisedVariant,
};
use crate::springs::{SpringValues, StartRecord, realize_springs_reusing, realize_springs_seeded};
use crate::timing::{StageTime, Stopwatch};
use crate::verify::verify;

/// Settings of the optimisation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct OptimiseOptions {
    pub objective: Objective,
    /// Most passes of the critical-task loop.
    pub max_iterations: usize,
    /// Relative gap below which the relaxation's recovered point is accepted without local
    /// refinement.
    pub gap_tolerance: f64,
    /// Starts of the spring realization per pass (the final choice uses four times as many).
    pub spring_starts: usize,
    /// Compute joint reactions in the final all-task evaluation (F_j, M_j, ΔR).
    pub final_reactions: bool,
    /// clarabel iteration limit.
    pub solver_iterations: u32,
    /// Boxes the certified search ([`crate::certify`]) solves at most per variant and pass: the
    /// only limit that can leave a variant undecided.
    #[serde(default = "default_max_nodes")]
    pub max_nodes: usize,
    /// Seed of the local search's starting points after the first. Verdicts, optima (within
    /// the gap tolerance) and ranks do not depend on it.
    #[serde(default = "default_start_seed")]
    pub start_seed: u64,
}

fn default_start_seed() -> u64 {
    crate::springs::DEFAULT_SEED
}

fn default_max_nodes() -> usize {
    OptimiseOptions::default().max_nodes
}

impl Default for OptimiseOptions {
    fn default() -> Self {
        OptimiseOptions {
            objective: Objective::RmsStar,
            max_iterations: 8,
            gap_tolerance: 1e-3,
            spring_starts: 8,
            final_reactions: true,
            solver_iterations: 200,
            max_nodes: crate::certify::DEFAULT_MAX_NODES,
            start_seed: crate::springs::DEFAULT_SEED,
        }
    }
}

/// A variant in the loop.
#[derive(Clone)]
struct Run {
    elements: Vec<String>,
    class: counterpoise_balance::Class,
    problem: Option<VariantProblem>,
    working: Vec<usize>,
    iterations: Vec<Iteration>,
    state: State,
    candidate: Option<Candidate>,
    /// What the last branch-and-bound left (its next pass starts from these boxes).
    search: Option<SearchState>,
}

#[derive(Clone, Debug, PartialEq)]
enum State {
    Running,
    Converged,
    Stopped,
    /// Proved impossible (the reason names the binding constraint).
    Discarded(String),
    /// Not built, not proved impossible.
    Undecided(String),
}

/// Why a pass produced no candidate.
#[derive(Clone, Debug, PartialEq)]
enum Failure {
    Discard(String),
    Undecided(String),
}

impl Failure {
    fn into_state(self) -> State {
        match self {
            Failure::Discard(r) => State::Discarded(r),
            Failure::Undecided(r) => State::Undecided(r),
        }
    }
}

#[derive(Clone, Debug)]
struct Candidate {
    x: DVector<f64>,
    cws: Vec<CwPhysical>,
    springs: Vec<SpringValues>,
    /// 0 (the trivial bound) when the relaxation was not solved.
    lower_bound: f64,
    /// Whether `lower_bound` is the relaxation's certified bound.
    bound_certified: bool,
    working_value: f64,
    relaxation_status: crate::clarabel_map::ConicStatus,
    relaxation_iterations: u32,
    gap_before: f64,
    /// The spring realization's local solves for these counterweights (the spring choice
    /// reuses them).
    spring_starts: Option<StartRecord>,
    /// Boxes the certified search solved (0 when the fast path was within the tolerance).
    boxes: usize,
}

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

/// Wall and CPU time of the stages of [`optimise_all`].
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct StageTimings {
    /// Relaxations, refinements and spring realizations of every pass.
    pub solve: StageTime,
    /// The all-task torque evaluations of the critical-task loop.
    pub loop_grid: StageTime,
    /// Spring choice by ΔR on the reaction tasks.
    pub spring_choice: StageTime,
    /// Of the spring choice, the joint reactions of the options on the reaction tasks (the
    /// rest is the realization of the options).
    pub spring_reactions: StageTime,
    /// Final all-task evaluation (torques and joint reactions).
    pub final_grid: StageTime,
    /// Verification and records.
    pub records: StageTime,
    /// Passes of the critical-task loop.
    pub passes: usize,
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
    let mut runs: Vec<Run> = variants
        .iter()
        .filter(|v| v.status == Status::Balanced)
        .map(|v| new_run(ctx, v, options))
        .collect();
    critical_task_loop(ctx, &mut runs, options, &mut timings, progress);
    let out = finish(ctx, runs, options, &mut timings, progress);
    (out, timings)
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
        let outcomes: Vec<Outcome> = active
            .par_iter()
            .map(|&k| {
                let mut search = runs[k].search.clone();
                let outcome = step(ctx, &runs[k], &failed, options, &mut search);
                counter.tick();
                (k, outcome, search)
            })
            .collect();
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
        let share = ShareCounter::start(
            progress,
            "all-task evaluation",
            timings.passes,
            evaluated.len(),
        );
        let dyn_variants = candidate_variants(runs, &evaluated);
        let indicators = grid_indicators(ctx, &dyn_variants, false, &share);
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
            design, 0.0, false, status, &relaxed, gap_before, record, 0,
        ));
    }
    // The fast path's design is accepted when it is within the gap tolerance of the bound;
    // otherwise the branch-and-bound certifies the optimum or proves that none exists.
    if let Some((design, record)) = &fast
        && design.value - lower <= options.gap_tolerance * design.value.abs()
    {
        return Ok(candidate(
            design.clone(),
            lower,
            true,
            status,
            &relaxed,
            gap_before,
            record.clone(),
            0,
        ));
    }
    let (incumbent, record) = match fast {
        Some((d, r)) => (Some(d), r),
        None => (None, None),
    };
    let branch = BranchOptions {
        gap_tolerance: options.gap_tolerance,
        max_nodes: options.max_nodes,
        solver_iterations: options.solver_iterations,
    };
    let b = &ctx.basis.unbalanced;
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
            design,
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
            ctx, problem, &tasks, &branch, nodes,
        ))),
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
    match branch_and_bound(problem, b, &[], Objective::Minimax, &wording, None, None)
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

/// The dynamics variants of the current candidates of runs `ks` (each has a problem and a
/// candidate).
fn candidate_variants(runs: &[Run], ks: &[usize]) -> Vec<Variant> {
    ks.iter()
        .map(|&k| {
            let cand = runs[k].candidate.as_ref().expect("candidate");
            dynamics_variant(
                runs[k].problem.as_ref().expect("problem"),
                &cand.cws,
                &cand.springs,
            )
        })
        .collect()
}

/// The dynamics crate's variant of physical counterweights `cws` (in the problem's slot order)
/// and realized springs.
fn dynamics_variant(
    problem: &VariantProblem,
    cws: &[CwPhysical],
    springs: &[SpringValues],
) -> Variant {
    Variant {
        counterweights: problem
            .counterweights
            .iter()
            .zip(cws)
            .map(|(slot, p)| Counterweight {
                body: slot.body,
                mass: p.mass,
                position: p.offset(),
            })
            .collect(),
        springs: springs
            .iter()
            .map(|s| Spring {
                body: s.body,
                other: match s.other {
                    Attachment::Base => None,
                    Attachment::Body(b) => Some(b),
                },
                stiffness: s.stiffness,
                anchor: s.anchor_a,
                other_anchor: s.anchor_b,
            })
            .collect(),
    }
}

/// The names of the set's lifted variables, in the order of the problem's columns.
fn lifted_names(ctx: &Context, problem: &VariantProblem) -> Vec<String> {
    problem
        .set
        .iter()
        .flat_map(|&e| ctx.catalogue.entries[e].variables.clone())
        .collect()
}

/// The all-task indicators of each variant.
///
/// The dynamics crate evaluates a batch through the cyclic shortcut only when no variant of it
/// has a spring to the base (such a spring breaks the symmetry). Variants with one are
/// evaluated in a batch of their own, so that every variant takes the same path, and gets the
/// same bits, whatever else is optimised with it — a sharded study merges exactly.
fn grid_indicators(
    ctx: &Context,
    variants: &[Variant],
    reactions: bool,
    share: &ShareCounter,
) -> Result<Vec<Indicators>, String> {
    let to_base: Vec<bool> = variants
        .iter()
        .map(|v| v.springs.iter().any(|s| s.other.is_none()))
        .collect();
    if to_base.iter().all(|&b| b) || to_base.iter().all(|&b| !b) {
        let n = variants.len();
        return batch_indicators(ctx, variants, reactions, &|d, t| share.batch(0, n, d, t));
    }
    let with_base_count = to_base.iter().filter(|&&b| b).count();
    let part = |base: bool| -> Result<Vec<Indicators>, String> {
        let members: Vec<Variant> = variants
            .iter()
            .zip(&to_base)
            .filter(|(_, b)| **b == base)
            .map(|(v, _)| v.clone())
            .collect();
        // The batch with springs to the base runs first.
        let before = if base { 0 } else { with_base_count };
        let n = members.len();
        batch_indicators(ctx, &members, reactions, &|d, t| {
            share.batch(before, n, d, t)
        })
    };
    let (mut with_base, mut without) = (part(true)?.into_iter(), part(false)?.into_iter());
    Ok(to_base
        .iter()
        .map(|&b| {
            if b { with_base.next() } else { without.next() }.expect("one result per variant")
        })
        .collect())
}

// Built from the default and then set: fields the dynamics crate adds keep their defaults.
#[allow(clippy::field_reassign_with_default)]
fn batch_indicators(
    ctx: &Context,
    variants: &[Variant],
    reactions: bool,
    progress: GridProgress,
) -> Result<Vec<Indicators>, String> {
    let params = ParameterSet::from_variants(&ctx.model, variants).map_err(|e| e.to_string())?;
    let mut evaluate_options = EvaluateOptions::default();
    evaluate_options.reactions = reactions;
    // Only the indicators are needed: the streaming evaluation keeps running maxima per
    // variant instead of a table of every task and variant (tasks × variants × 33 values).
    let grid = evaluate_grid_indicators_reporting(
        &ctx.model,
        &params,
        &evaluate_options,
        Combination::Direct,
        progress,
    )
    .map_err(|e| e.to_string())?;
    Ok(grid.indicators)
}

/// The objective over all tasks from a variant's indicators.
pub fn objective_of(ind: &Indicators, objective: Objective) -> f64 {
    match objective {
        Objective::RmsStar => {
            let n = ind.actuators.len().max(1) as f64;
            (ind.actuators
                .iter()
                .map(|a| a.crt_rms * a.crt_rms)
                .sum::<f64>()
                / n)
                .sqrt()
        }
        Objective::Minimax => ind.qtr,
    }
}

fn critical_tasks(
    ctx: &Context,
    problem: &VariantProblem,
    ind: &Indicators,
    objective: Objective,
) -> Vec<usize> {
    let mut out = Vec::new();
    for (n, a) in ind.actuators.iter().enumerate() {
        if objective == Objective::RmsStar {
            out.extend(ctx.task_index(a.crt));
        }
        if problem.peak_limits.get(n).copied().flatten().is_some() {
            out.extend(ctx.task_index(a.cpt));
        }
    }
    if objective == Objective::Minimax {
        out.extend(ctx.task_index(ind.qtr_task));
    }
    out
}

/// Peak joint reaction forces and moments, one entry per joint each.
type JointPeaks = (Vec<f64>, Vec<f64>);

/// Peak joint reactions `(F_j, M_j)` of each variant over the given tasks.
fn reaction_peaks(ctx: &Context, variants: &[Variant], tasks: &[usize]) -> Option<Vec<JointPeaks>> {
    let ev = Evaluator::new(&ctx.model).ok()?;
    let params = ParameterSet::from_variants(&ctx.model, variants).ok()?;
    let columns: Vec<usize> = (0..params.len()).collect();
    let per_task: Vec<Option<Vec<JointPeaks>>> = tasks
        .par_iter()
        .map_init(Workspace::default, |ws, &w| {
            move_peaks(ctx, &ev, &params, w, &columns, ws)
        })
        .collect();
    let mut total = zero_peaks(ctx, columns.len());
    for t in per_task.into_iter().flatten() {
        raise_peaks(&mut total, t);
    }
    Some(total)
}

/// [`reaction_peaks`] of several groups of variants (each with its own tasks) in one pass
/// over the union of their tasks: a task's kinematics and reaction factorisation, per sample,
/// are computed once for every group that needs the task (the spring options of all runs
/// share the unbalanced joints' critical tasks), not once per group.
///
/// The result is the same bits as [`reaction_peaks`] group by group: a column's reactions are
/// the same arithmetic whatever other columns share the sample (one Cholesky factor, the
/// substitutions lane by lane; spring slots a column does not use are skipped; its own slots
/// keep their order), and each group takes the maximum over its own tasks only. A task that
/// fails for the batch is run again group by group, so that a non-finite value of one group
/// leaves the task out for that group alone, as on its own.
fn batched_reaction_peaks(
    ctx: &Context,
    groups: &[(&[Variant], &[usize])],
) -> Vec<Option<Vec<JointPeaks>>> {
    let all: Vec<Variant> = groups.iter().flat_map(|g| g.0.iter().cloned()).collect();
    let (Ok(ev), Ok(params)) = (
        Evaluator::new(&ctx.model),
        ParameterSet::from_variants(&ctx.model, &all),
    ) else {
        return groups
            .iter()
            .map(|(variants, tasks)| reaction_peaks(ctx, variants, tasks))
            .collect();
    };
    let mut first = Vec::with_capacity(groups.len());
    let mut next = 0;
    for (variants, _) in groups {
        first.push(next);
        next += variants.len();
    }
    let columns_of = |gs: &[usize]| -> Vec<usize> {
        gs.iter()
            .flat_map(|&g| first[g]..first[g] + groups[g].0.len())
            .collect()
    };
    let mut needed: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
    for (g, (_, tasks)) in groups.iter().enumerate() {
        for &w in *tasks {
            needed.entry(w).or_default().push(g);
        }
    }
    let needed: Vec<(usize, Vec<usize>)> = needed.into_iter().collect();
    // Per task, per group needing it: the group's peaks on that task (`None`: left out).
    let per_task: Vec<Vec<Option<Vec<JointPeaks>>>> = needed
        .par_iter()
        .map_init(Workspace::default, |ws, (w, gs)| {
            match move_peaks(ctx, &ev, &params, *w, &columns_of(gs), ws) {
                Some(mut peaks) => gs
                    .iter()
                    .rev()
                    .map(|&g| Some(peaks.split_off(peaks.len() - groups[g].0.len())))
                    .collect::<Vec<_>>()
                    .into_iter()
                    .rev()
                    .collect(),
                None if gs.len() == 1 => vec![None],
                None => gs
                    .iter()
                    .map(|&g| move_peaks(ctx, &ev, &params, *w, &columns_of(&[g]), ws))
                    .collect(),
            }
        })
        .collect();
    let mut total: Vec<Vec<JointPeaks>> = groups
        .iter()
        .map(|(variants, _)| zero_peaks(ctx, variants.len()))
        .collect();
    for ((_, gs), peaks) in needed.iter().zip(per_task) {
        for (&g, p) in gs.iter().zip(peaks) {
            if let Some(p) = p {
                raise_peaks(&mut total[g], p);
            }
        }
    }
    total.into_iter().map(Some).collect()
}

/// Zero peaks for `columns` columns.
fn zero_peaks(ctx: &Context, columns: usize) -> Vec<JointPeaks> {
    let nj = ctx.model.joints.len();
    vec![(vec![0.0; nj], vec![0.0; nj]); columns]
}

/// `total = max(total, peaks)`, entry by entry.
fn raise_peaks(total: &mut [JointPeaks], peaks: Vec<JointPeaks>) {
    for (tot, a) in total.iter_mut().zip(peaks) {
        for (x, y) in tot.0.iter_mut().zip(a.0) {
            *x = f64::max(*x, y);
        }
        for (x, y) in tot.1.iter_mut().zip(a.1) {
            *x = f64::max(*x, y);
        }
    }
}

/// Peak joint reactions of `columns` of `params` over task `w` (`None` when the move fails).
fn move_peaks(
    ctx: &Context,
    ev: &Evaluator,
    params: &ParameterSet,
    w: usize,
    columns: &[usize],
    ws: &mut Workspace,
) -> Option<Vec<JointPeaks>> {
    let (i, j) = ctx.tasks.pair(w);
    let mut q = ev.solve_point(&ctx.tasks.points[i]).ok()?;
    let mut acc = zero_peaks(ctx, columns.len());
    ev.run_move(
        &ctx.tasks.points[i],
        &ctx.tasks.points[j],
        ctx.tasks.duration,
        ctx.tasks.samples,
        &mut q,
        params,
        columns,
        true,
        ws,
        |_, view| {
            for (c, a) in acc.iter_mut().enumerate() {
                let r = &view.reactions[c];
                for (p, f) in a.0.iter_mut().zip(r.force_magnitudes()) {
                    *p = f64::max(*p, f);
                }
                for (p, m) in a.1.iter_mut().zip(r.moment_magnitudes()) {
                    *p = f64::max(*p, m);
                }
            }
        },
    )
    .ok()?;
    Some(acc)
}

/// ΔR (paper Eqs. 17–21, percent) of a variant whose peak joint reactions are `force`, `moment`
/// (one per joint, in the unbalanced indicators' joint order), against the unbalanced robot.
///
/// There is one definition of ΔR in the workspace: [`counterpoise_report::delta_r`], which the
/// ranking uses. Calling it here means the springs are chosen by the very quantity they are
/// ranked by. In particular a joint that carries no load in the unbalanced robot counts with
/// its weighted term `γ·ΔF = (F − F_UB)/Σ F_UB · 100` (the continuous extension of Eq. 19 at
/// `F_UB = 0`), so a spring that loads a previously idle joint is penalised.
///
/// `None` when the unbalanced robot has no joint reactions or a value is not finite.
pub fn delta_r(unbalanced: &Indicators, force: &[f64], moment: &[f64]) -> Option<f64> {
    use counterpoise_report::JointReaction;
    if unbalanced.joints.is_empty()
        || force.len() != unbalanced.joints.len()
        || moment.len() != unbalanced.joints.len()
    {
        return None;
    }
    let reference: Vec<JointReaction> = unbalanced
        .joints
        .iter()
        .map(|j| JointReaction {
            name: j.name.clone(),
            force: j.force,
            moment: j.moment,
        })
        .collect();
    let variant: Vec<JointReaction> = unbalanced
        .joints
        .iter()
        .zip(force.iter().zip(moment))
        .map(|(j, (&force, &moment))| JointReaction {
            name: j.name.clone(),
            force,
            moment,
        })
        .collect();
    counterpoise_report::delta_r(&reference, &variant)
        .ok()
        .map(|d| d.value)
}

/// The spring option to keep: the one with the lowest ΔR (paper Proc-9 ranks spring-only
/// variants by ΔR, so the optimiser keeps the realization that ranks best); options without a
/// score come last, ties go to the earliest option (the realization from the lifted optimum is
/// first). `None` for no options.
pub fn lowest_delta_r(scores: &[Option<f64>]) -> Option<usize> {
    (0..scores.len()).min_by(|&a, &b| {
        let sa = scores[a].unwrap_or(f64::INFINITY);
        let sb = scores[b].unwrap_or(f64::INFINITY);
        sa.total_cmp(&sb).then(a.cmp(&b))
    })
}

/// Interval of coordinate `k` (others held) over which the convex lifted bounds hold.
fn interval(problem: &VariantProblem, x: &DVector<f64>, direction: &DVector<f64>) -> [f64; 2] {
    let ok = |t: f64| {
        let xt = x + direction * t;
        problem.bound_violations(&xt).iter().all(|&v| v <= 1e-12)
    };
    let mut ends = [0.0; 2];
    for (side, sign) in [(0usize, -1.0f64), (1, 1.0)] {
        let mut inside = 0.0;
        let mut step = 1e-6;
        let mut outside = None;
        // Doublings from 1e-6 up to about 1.2e12: beyond that the side is unbounded.
        for _ in 0..60 {
            if ok(sign * step) {
                inside = step;
                step *= 2.0;
            } else {
                outside = Some(step);
                break;
            }
        }
        ends[side] = match outside {
            None => sign * f64::INFINITY,
            Some(mut out) => {
                for _ in 0..80 {
                    let mid = 0.5 * (inside + out);
                    if ok(sign * mid) {
                        inside = mid;
                    } else {
                        out = mid;
                    }
                }
                sign * inside
            }
        };
    }
    ends
}

/// The coordinates of `x` along the free directions of the variant's balanced family, each
/// with the interval over which the bounds hold (the others held). `names` are the lifted
/// variables of the set. The directions are the balance crate's, normalised as it reports them
/// (largest column-scaled component ±1), one per column of the optimiser's own nullspace (the
/// balance search's report may list its directions in another basis).
fn free_parameters(
    problem: &VariantProblem,
    names: &[String],
    x: &DVector<f64>,
) -> Vec<FreeParameter> {
    let directions =
        counterpoise_balance::relations::free_directions(&problem.solution, names, &[]);
    if directions.is_empty() {
        return Vec::new();
    }
    // Coordinates of x in the family: least squares on the directions (exact: x is in it).
    let basis = DMatrix::from_columns(
        &directions
            .iter()
            .map(|f| f.direction.clone())
            .collect::<Vec<_>>(),
    );
    let delta = x - &problem.solution.particular;
    let values = checked_svd(basis, true)
        .and_then(|svd| svd.solve(&delta, 1e-12).ok())
        .unwrap_or_else(|| DVector::zeros(directions.len()));
    let cw_rows = problem.cw_rows();
    directions
        .into_iter()
        .zip(values.iter())
        .map(|(f, &value)| {
            let [lo, hi] = interval(problem, x, &f.direction);
            FreeParameter {
                // A component too small for the report to list does not count as a move.
                moves_counterweights: f.variables.iter().any(|j| cw_rows.contains(j)),
                components: f.components,
                value,
                interval: [value + lo, value + hi],
            }
        })
        .collect()
}

/// The chosen springs, the lifted point with them, and their ΔR on the reaction tasks.
type SpringChoice = (Vec<SpringValues>, DVector<f64>, Option<f64>);

/// Spring choice by ΔR, final all-task evaluation, verification and the output records.
fn finish(
    ctx: &Context,
    mut runs: Vec<Run>,
    options: &OptimiseOptions,
    timings: &mut StageTimings,
    progress: ProgressSink<'_>,
) -> Vec<OptimisedVariant> {
    let started = Stopwatch::start();
    // Reaction tasks: the critical tasks plus the unbalanced joints' critical tasks.
    let mut joint_tasks = BTreeSet::new();
    for j in &ctx.unbalanced.joints {
        joint_tasks.extend(ctx.task_index(j.force_task));
        joint_tasks.extend(ctx.task_index(j.moment_task));
    }
    let counter = StageCounter::start(progress, "spring choice", 0, runs.len());
    let choices = spring_choices(
        ctx,
        &runs,
        &joint_tasks,
        options,
        &|| counter.tick(),
        &mut timings.spring_reactions,
    );
    for (run, choice) in runs.iter_mut().zip(&choices) {
        if let (Some(c), Some((s, x, _))) = (run.candidate.as_mut(), choice) {
            c.springs = s.clone();
            c.x = x.clone();
        }
    }
    timings.spring_choice = started.elapsed();
    let started = Stopwatch::start();
    // Final evaluation over all tasks, batched.
    let finals: Vec<usize> = (0..runs.len())
        .filter(|&k| {
            runs[k].candidate.is_some()
                && matches!(runs[k].state, State::Converged | State::Stopped)
        })
        .collect();
    let share = ShareCounter::start(progress, "final evaluation", 0, finals.len());
    let variants = candidate_variants(&runs, &finals);
    let final_indicators = if variants.is_empty() {
        Ok(Vec::new())
    } else {
        grid_indicators(ctx, &variants, options.final_reactions, &share)
    };
    let mut indicators_of: Vec<Option<Result<Indicators, String>>> = vec![None; runs.len()];
    for (n, &k) in finals.iter().enumerate() {
        indicators_of[k] = Some(match &final_indicators {
            Ok(v) => Ok(v[n].clone()),
            Err(e) => Err(e.clone()),
        });
    }

    timings.final_grid = started.elapsed();
    let started = Stopwatch::start();
    let out = runs
        .into_iter()
        .zip(choices)
        .zip(indicators_of)
        .map(|((run, choice), ind)| record(ctx, run, choice.and_then(|c| c.2), ind, options))
        .collect();
    timings.records = started.elapsed();
    out
}

/// The spring option of one run with the lowest ΔR on the reaction tasks (`None` for a run
/// without a candidate).
#[cfg(test)]
fn spring_choice(
    ctx: &Context,
    run: &Run,
    joint_tasks: &BTreeSet<usize>,
    options: &OptimiseOptions,
) -> Option<SpringChoice> {
    let mut reactions = StageTime::default();
    let tick = || ();
    spring_choices(
        ctx,
        std::slice::from_ref(run),
        joint_tasks,
        options,
        &tick,
        &mut reactions,
    )
    .pop()
    .flatten()
}

/// What the spring choice of one run needs.
enum SpringOptions {
    /// No candidate, or a run that did not converge or stop: no choice.
    Nothing,
    /// A candidate without springs: nothing to choose.
    NoSprings(DVector<f64>),
    /// The realizations found, their dynamics variants and the tasks they are scored on.
    Options {
        found: Vec<crate::springs::Realized>,
        variants: Vec<Variant>,
        tasks: Vec<usize>,
    },
}

/// The spring options of one run (the admissible spring sets from four times the pass's
/// starts; the candidate's own springs when none is found), scored on the reaction tasks plus
/// the run's working set.
fn spring_options(
    ctx: &Context,
    run: &Run,
    joint_tasks: &BTreeSet<usize>,
    options: &OptimiseOptions,
) -> SpringOptions {
    let Some(cand) = run.candidate.as_ref() else {
        return SpringOptions::Nothing;
    };
    if !matches!(run.state, State::Converged | State::Stopped) {
        return SpringOptions::Nothing;
    }
    let Some(problem) = run.problem.as_ref() else {
        return SpringOptions::Nothing;
    };
    if problem.springs.is_empty() {
        return SpringOptions::NoSprings(cand.x.clone());
    }
    let (mut found, _, _) = realize_springs_reusing(
        problem,
        &ctx.basis.unbalanced,
        &cand.x,
        options.spring_starts * 4,
        false,
        cand.spring_starts.as_ref(),
    );
    if found.is_empty() {
        found.push((cand.springs.clone(), cand.x.clone()));
    }
    let variants: Vec<Variant> = found
        .iter()
        .map(|(s, _)| dynamics_variant(problem, &cand.cws, s))
        .collect();
    let tasks: Vec<usize> = joint_tasks
        .iter()
        .copied()
        .chain(run.working.iter().copied())
        .collect::<BTreeSet<_>>()
        .into_iter()
        .collect();
    SpringOptions::Options {
        found,
        variants,
        tasks,
    }
}

/// The spring choice of every run, in run order: per run the option with the lowest ΔR on its
/// reaction tasks (see [`lowest_delta_r`]). The options are realized run by run in parallel;
/// their reactions are then evaluated in one batch over all the runs' tasks
/// ([`batched_reaction_peaks`], the same bits as run by run). `tick` is called once per run as
/// its choice is known; the time of the reactions is added to `reactions_time`.
fn spring_choices(
    ctx: &Context,
    runs: &[Run],
    joint_tasks: &BTreeSet<usize>,
    options: &OptimiseOptions,
    tick: &(dyn Fn() + Sync),
    reactions_time: &mut StageTime,
) -> Vec<Option<SpringChoice>> {
    let prepared: Vec<SpringOptions> = runs
        .par_iter()
        .map(|run| {
            let o = spring_options(ctx, run, joint_tasks, options);
            if !matches!(o, SpringOptions::Options { .. }) {
                tick();
            }
            o
        })
        .collect();
    let groups: Vec<(&[Variant], &[usize])> = prepared
        .iter()
        .filter_map(|o| match o {
            SpringOptions::Options {
                variants, tasks, ..
            } => Some((&variants[..], &tasks[..])),
            _ => None,
        })
        .collect();
    let started = Stopwatch::start();
    let mut peaks = batched_reaction_peaks(ctx, &groups).into_iter();
    *reactions_time += started.elapsed();
    prepared
        .into_iter()
        .map(|o| match o {
            SpringOptions::Nothing => None,
            SpringOptions::NoSprings(x) => Some((Vec::new(), x, None)),
            SpringOptions::Options {
                mut found,
                variants,
                ..
            } => {
                let peaks = peaks.next().expect("one result per group");
                let scores: Vec<Option<f64>> = match &peaks {
                    Some(p) => p
                        .iter()
                        .map(|(f, m)| delta_r(&ctx.unbalanced, f, m))
                        .collect(),
                    None => vec![None; variants.len()],
                };
                let best = lowest_delta_r(&scores).unwrap_or(0);
                let (s, x) = found.swap_remove(best);
                tick();
                Some((s, x, scores[best]))
            }
        })
        .collect()
}

fn record(
    ctx: &Context,
    run: Run,
    delta_r_estimate: Option<f64>,
    indicators: Option<Result<Indicators, String>>,
    options: &OptimiseOptions,
) -> OptimisedVariant {
    let mut out = OptimisedVariant {
        elements: run.elements.clone(),
        class: run.class,
        status: OptimisedStatus::Discarded,
        reason: None,
        objective_kind: options.objective,
        objective: None,
        lower_bound: None,
        gap: None,
        residual: None,
        converged: run.state == State::Converged,
        iterations: run.iterations.clone(),
        critical_tasks: run.working.iter().map(|&w| ctx.pair(w)).collect(),
        counterweights: Vec::new(),
        springs: Vec::new(),
        free_parameters: Vec::new(),
        delta_r_estimate,
        verification: None,
        indicators: None,
    };
    match &run.state {
        State::Discarded(reason) => {
            out.reason = Some(reason.clone());
            return out;
        }
        State::Undecided(reason) => {
            out.status = OptimisedStatus::Undecided;
            out.reason = Some(reason.clone());
            return out;
        }
        _ => {}
    }
    let (Some(problem), Some(cand)) = (run.problem.as_ref(), run.candidate.as_ref()) else {
        out.status = OptimisedStatus::Undecided;
        out.reason = Some("no candidate parameters were produced".into());
        return out;
    };
    let name = |b: usize| ctx.model.bodies[b].name.clone();
    out.counterweights = problem
        .counterweights
        .iter()
        .zip(&cand.cws)
        .map(|(slot, p)| OptimisedCounterweight {
            label: slot.label.clone(),
            body: name(slot.body),
            mass: p.mass,
            offset: p.offset(),
            radius: p.radius(),
        })
        .collect();
    out.springs = cand
        .springs
        .iter()
        .map(|s| OptimisedSpring {
            label: s.label.clone(),
            body: name(s.body),
            other: match s.other {
                Attachment::Base => "base".into(),
                Attachment::Body(b) => name(b),
            },
            other_attachment: Some(s.other),
            stiffness: s.stiffness,
            anchor_a: s.anchor_a,
            anchor_b: s.anchor_b,
        })
        .collect();
    out.free_parameters = free_parameters(problem, &lifted_names(ctx, problem), &cand.x);
    out.lower_bound = cand.bound_certified.then_some(cand.lower_bound);
    let ind = match indicators {
        Some(Ok(i)) => i,
        Some(Err(e)) => {
            out.status = OptimisedStatus::Undecided;
            out.reason = Some(format!("final dynamics evaluation failed: {e}"));
            return out;
        }
        None => {
            out.status = OptimisedStatus::Undecided;
            out.reason = Some("no final evaluation".into());
            return out;
        }
    };
    let objective = objective_of(&ind, options.objective);
    out.objective = Some(objective);
    out.gap = out
        .lower_bound
        .map(|lb| ((objective - lb) / objective.abs().max(1e-300)).max(0.0));
    let report = verify(problem, &ctx.checks, &cand.cws, &cand.springs, &ind);
    out.residual = Some(report.balance_residual);
    let passed = report.passed;
    if !passed {
        // A peak over a limit at the optimised point is a verified violation (discarded);
        // a balance or bound check that fails is a numerical shortfall (undecided).
        let mut why = Vec::new();
        if !report.peaks_passed {
            for (n, p) in report.peaks.iter().enumerate() {
                if let Some(l) = p.limit
                    && p.peak > l
                {
                    let task = ind.actuators.get(n).map_or(String::new(), |a| {
                        format!(" on task {}→{}", a.cpt[0], a.cpt[1])
                    });
                    why.push(format!(
                        "{} peaks at {:.2} N·m{task} (limit {l} N·m)",
                        p.actuator, p.peak
                    ));
                }
            }
        }
        if !report.balance_passed || !report.bounds_passed {
            out.status = OptimisedStatus::Undecided;
            if !report.balance_passed {
                why.push(format!(
                    "the optimised parameters balance only to a relative residual of {:.2e} \
                     (1e-9 required)",
                    report.balance_residual
                ));
            }
            if !report.bounds_passed {
                why.push(format!(
                    "the optimised parameters exceed a bound by {:.2e} (relative)",
                    report.bound_excess
                ));
            }
        }
        out.reason = Some(why.join("; "));
    } else {
        out.status = OptimisedStatus::Feasible;
    }
    out.verification = Some(report);
    out.indicators = Some(ind);
    out
}

#[cfg(test)]
mod tests;
