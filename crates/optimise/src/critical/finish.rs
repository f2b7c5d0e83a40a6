//! After the loop: the spring choice by ΔR, the final all-task evaluation, the free
//! parameters' intervals, verification, and each variant's record.

use counterpoise_dynamics::linalg::checked_svd;
use std::collections::BTreeSet;

use counterpoise_dynamics::Indicators;
use counterpoise_dynamics::params::Variant;
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

use super::grid::*;
use super::peaks::*;
use super::state::*;
use crate::context::Context;
use crate::problem::VariantProblem;
use crate::progress::{ProgressSink, ShareCounter, StageCounter};
use crate::result::{FreeParameter, OptimisedVariant, Status};
use crate::springs::{Spring, realize_springs_reusing};
use crate::timing::{StageTime, Stopwatch};
use crate::verify::verify;

/// Interval of coordinate `k` (others held) over which the convex lifted bounds hold.
pub(super) fn interval(
    problem: &VariantProblem,
    x: &DVector<f64>,
    direction: &DVector<f64>,
) -> [f64; 2] {
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
pub(super) fn free_parameters(
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
pub(super) type SpringChoice = (Vec<Spring>, DVector<f64>, Option<f64>);

/// Spring choice by ΔR, final all-task evaluation, verification and the output records.
pub(super) fn finish(
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
    let variants = candidate_variants(&ctx.model, &runs, &finals);
    let final_indicators = if variants.is_empty() {
        Ok(Vec::new())
    } else {
        grid_indicators(
            ctx,
            &variants,
            options.final_reactions,
            options.final_reaction_solve.combination(),
            &share,
        )
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
pub(super) fn spring_choice(
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
pub(super) enum SpringOptions {
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
/// starts; when none is found, for a variant of springs alone the first design of a search
/// without an incumbent, [`springs_only_design`], else the candidate's own springs), scored on the reaction tasks plus
/// the run's working set. The first start takes its springs from the bounds
/// ([`crate::springs::springs_from_bounds`]), not from the candidate: the candidate's springs
/// are where its search happened to realize them, so two searches that end at the same
/// counterweights (another `--seed`, another path) would otherwise offer different options and
/// report different ΔR for the same design (on the palletizer at Dmax 3, m1 + K52 + K53, the
/// same objective to the bit under two seeds, had ΔR 3.316 or 3.356 %).
pub(super) fn spring_options(
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
        &crate::springs::springs_from_bounds(problem, &cand.x),
        options.spring_starts * 4,
        false,
        cand.spring_starts.as_ref(),
    );
    if found.is_empty() {
        found.push(
            springs_only_design(ctx, run, problem, options)
                .unwrap_or_else(|| (cand.springs.clone(), cand.x.clone())),
        );
    }
    let variants: Vec<Variant> = found
        .iter()
        .map(|(s, _)| dynamics_variant(&ctx.model, problem, &cand.cws, s))
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

/// For a variant of springs alone, the springs of the first design a search from the first box
/// finds on the run's working tasks, when it finds one (`None` for a variant with
/// counterweights).
///
/// The spring choice falls back on the candidate's own springs when none of its starts
/// realizes the springs within the bounds; for a variant of springs alone those come from the
/// fast path's seeded starts, or from wherever the search's path met a design (every design of
/// such a variant has the same objective, so the first one closes the gap). Two seeds then
/// reported different springs, hence ΔR, for the same variant (on the palletizer at Dmax 3,
/// K31 + K61 + K63: 14.22 or 15.44 %). A search from the first box without an incumbent
/// draws nothing from the seed, so its first design is the same in every run.
fn springs_only_design(
    ctx: &Context,
    run: &Run,
    problem: &VariantProblem,
    options: &OptimiseOptions,
) -> Option<crate::springs::Realized> {
    if !problem.counterweights.is_empty() {
        return None;
    }
    let (tasks, _) = ctx.torques.get(&ctx.model, &ctx.tasks, &run.working);
    let (verdict, _) = crate::certify::branch_and_bound(
        problem,
        &ctx.basis.unbalanced,
        &tasks,
        options.objective,
        &options.branch_options(),
        None,
        None,
    )
    .ok()?;
    match verdict {
        crate::certify::Verdict::Optimal { design, .. }
        | crate::certify::Verdict::Stopped {
            design: Some(design),
            ..
        } => Some((design.springs, design.x)),
        _ => None,
    }
}

/// The spring choice of every run, in run order: per run the option with the lowest ΔR on its
/// reaction tasks (see [`lowest_delta_r`]). The options are realized run by run in parallel;
/// their reactions are then evaluated in batches over all the runs' tasks, leaving out the
/// options that cannot be the lowest ([`lowest_delta_r_choices`]: the same choice and bits as
/// every option run by run). `tick` is called once per run as its choice is known; the time of
/// the reactions is added to `reactions_time`.
pub(super) fn spring_choices(
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
    let mut choices = lowest_delta_r_choices(ctx, &groups).into_iter();
    *reactions_time += started.elapsed();
    prepared
        .into_iter()
        .map(|o| match o {
            SpringOptions::Nothing => None,
            SpringOptions::NoSprings(x) => Some((Vec::new(), x, None)),
            SpringOptions::Options { mut found, .. } => {
                let (best, score) = choices.next().expect("one choice per group");
                let (s, x) = found.swap_remove(best);
                tick();
                Some((s, x, score))
            }
        })
        .collect()
}

pub(super) fn record(
    ctx: &Context,
    run: Run,
    delta_r_estimate: Option<f64>,
    indicators: Option<Result<Indicators, String>>,
    options: &OptimiseOptions,
) -> OptimisedVariant {
    let mut out = OptimisedVariant {
        elements: run.elements.clone(),
        class: run.class,
        status: Status::Discarded,
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
            out.status = Status::Undecided;
            out.reason = Some(reason.clone());
            return out;
        }
        _ => {}
    }
    let (Some(problem), Some(cand)) = (run.problem.as_ref(), run.candidate.as_ref()) else {
        out.status = Status::Undecided;
        out.reason = Some("no candidate parameters were produced".into());
        return out;
    };
    // The elements as the results record them and the balance check samples them.
    let elements = dynamics_variant(&ctx.model, problem, &cand.cws, &cand.springs);
    out.counterweights = elements.counterweights.clone();
    out.springs = elements.springs.clone();
    out.free_parameters = free_parameters(problem, &lifted_names(ctx, problem), &cand.x);
    out.lower_bound = cand.bound_certified.then_some(cand.lower_bound);
    let ind = match indicators {
        Some(Ok(i)) => i,
        Some(Err(e)) => {
            out.status = Status::Undecided;
            out.reason = Some(format!("final dynamics evaluation failed: {e}"));
            return out;
        }
        None => {
            out.status = Status::Undecided;
            out.reason = Some("no final evaluation".into());
            return out;
        }
    };
    let objective = objective_of(&ind, options.objective);
    out.objective = Some(objective);
    out.gap = out
        .lower_bound
        .map(|lb| ((objective - lb) / objective.abs().max(1e-300)).max(0.0));
    let report = verify(
        problem,
        &ctx.checks,
        &elements,
        &cand.cws,
        &cand.springs,
        &ind,
    );
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
            out.status = Status::Undecided;
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
        out.status = Status::Feasible;
    }
    out.verification = Some(report);
    out.indicators = Some(ind);
    out
}
