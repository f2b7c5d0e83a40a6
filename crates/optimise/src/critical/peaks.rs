//! Joint-reaction peaks over the reaction tasks and ΔR, the criterion that chooses among a
//! variant's spring options.

use std::collections::BTreeMap;

use counterpoise_dynamics::params::{ParameterSet, Variant};
use counterpoise_dynamics::runner::Workspace;
use counterpoise_dynamics::{Evaluator, Indicators};
use rayon::prelude::*;

use crate::context::Context;

/// Peak joint reaction forces and moments, one entry per joint each.
pub(super) type JointPeaks = (Vec<f64>, Vec<f64>);

/// Peak joint reactions `(F_j, M_j)` of each variant over the given tasks.
pub(super) fn reaction_peaks(
    ctx: &Context,
    variants: &[Variant],
    tasks: &[usize],
) -> Option<Vec<JointPeaks>> {
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
pub(super) fn batched_reaction_peaks(
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
pub(super) fn zero_peaks(ctx: &Context, columns: usize) -> Vec<JointPeaks> {
    let nj = ctx.model.joints.len();
    vec![(vec![0.0; nj], vec![0.0; nj]); columns]
}

/// `total = max(total, peaks)`, entry by entry.
pub(super) fn raise_peaks(total: &mut [JointPeaks], peaks: Vec<JointPeaks>) {
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
pub(super) fn move_peaks(
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
/// There is one definition of ΔR in the workspace: [`counterpoise_vocabulary::delta_r`], which the
/// ranking uses. Calling it here means the springs are chosen by the very quantity they are
/// ranked by. In particular a joint that carries no load in the unbalanced robot counts with
/// its weighted term `γ·ΔF = (F − F_UB)/Σ F_UB · 100` (the continuous extension of Eq. 19 at
/// `F_UB = 0`), so a spring that loads a previously idle joint is penalised.
///
/// `None` when the unbalanced robot has no joint reactions or a value is not finite.
pub fn delta_r(unbalanced: &Indicators, force: &[f64], moment: &[f64]) -> Option<f64> {
    use counterpoise_vocabulary::JointReaction;
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
    counterpoise_vocabulary::delta_r(&reference, &variant)
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
