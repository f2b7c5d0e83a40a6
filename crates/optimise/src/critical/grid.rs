//! The all-task evaluations of the loop: candidates as the dynamics crate's variants, their
//! indicators over the task grid in batches, and each variant's new critical tasks.

use counterpoise_dynamics::params::{Counterweight, ParameterSet, Spring, Variant};
use counterpoise_dynamics::{
    Combination, EvaluateOptions, GridProgress, Indicators, evaluate_grid_indicators_reporting,
};
use counterpoise_model::Model;

use super::state::*;
use crate::context::Context;
use crate::problem::{CwPhysical, Objective, VariantProblem};
use crate::progress::ShareCounter;

/// The dynamics variants of the current candidates of runs `ks` (each has a problem and a
/// candidate).
pub(super) fn candidate_variants(model: &Model, runs: &[Run], ks: &[usize]) -> Vec<Variant> {
    ks.iter()
        .map(|&k| {
            let cand = runs[k].candidate.as_ref().expect("candidate");
            dynamics_variant(
                model,
                runs[k].problem.as_ref().expect("problem"),
                &cand.cws,
                &cand.springs,
            )
        })
        .collect()
}

/// The physical parameters of counterweights `cws` (in the problem's slot order) and realized
/// springs, named as the results record them (the case's plane for each kind): the variant the
/// dynamics crate evaluates and the optimiser reports.
pub(super) fn dynamics_variant(
    model: &Model,
    problem: &VariantProblem,
    cws: &[CwPhysical],
    springs: &[Spring],
) -> Variant {
    let name = |b: usize| model.bodies[b].name.clone();
    let (cw_plane, spring_plane) = (model.counterweight_plane(), model.spring_plane());
    Variant {
        counterweights: problem
            .counterweights
            .iter()
            .zip(cws)
            .map(|(slot, p)| Counterweight {
                label: slot.label.clone(),
                body: name(slot.body),
                mass: p.mass,
                offset: p.offset(),
                plane: cw_plane,
            })
            .collect(),
        springs: springs
            .iter()
            .map(|s| Spring {
                plane: spring_plane,
                ..s.clone()
            })
            .collect(),
    }
}

/// The names of the set's lifted variables, in the order of the problem's columns.
pub(super) fn lifted_names(ctx: &Context, problem: &VariantProblem) -> Vec<String> {
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
pub(super) fn grid_indicators(
    ctx: &Context,
    variants: &[Variant],
    reactions: bool,
    combination: Combination,
    share: &ShareCounter,
) -> Result<Vec<Indicators>, String> {
    let to_base: Vec<bool> = variants
        .iter()
        .map(|v| v.springs.iter().any(|s| s.to_base()))
        .collect();
    if to_base.iter().all(|&b| b) || to_base.iter().all(|&b| !b) {
        let n = variants.len();
        return batch_indicators(ctx, variants, reactions, combination, &|d, t| {
            share.batch(0, n, d, t)
        });
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
        batch_indicators(ctx, &members, reactions, combination, &|d, t| {
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
pub(super) fn batch_indicators(
    ctx: &Context,
    variants: &[Variant],
    reactions: bool,
    combination: Combination,
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
        combination,
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

pub(super) fn critical_tasks(
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
