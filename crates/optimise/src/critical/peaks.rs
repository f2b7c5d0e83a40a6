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

/// Per group, the option with the lowest ΔR on the group's tasks and that ΔR: what
/// [`lowest_delta_r`] picks from every option's score over [`batched_reaction_peaks`] (the same
/// index and the same bits), without evaluating every option on every task.
///
/// A spring choice holds about thirty options per run. ΔR only grows with each joint's peak
/// (its terms are `γ·max(0, ΔF)` and alike), and a peak over some tasks is at most the peak
/// over all, so ΔR over a subset of the tasks is a lower bound of an option's ΔR. Four batched
/// rounds: the first option of each group on every task, one task at a time; the other options
/// on the [`PROBE_TASKS`] tasks where the first one's ΔR alone is largest (lower bounds); the
/// option with the lowest bound on the other tasks; and on those, every option whose bound
/// could still beat the best ΔR known (ties go to the earlier option, as in
/// [`lowest_delta_r`]). An option left out has a ΔR that cannot be the lowest, and every option
/// evaluated in full has the maximum over the same per-task peaks (a column's reactions do not
/// depend on its batch) as in one pass. A group whose first round fails (no evaluator, a task
/// whose kinematics fail for the first option) is evaluated in full.
pub(super) fn lowest_delta_r_choices(
    ctx: &Context,
    groups: &[(&[Variant], &[usize])],
) -> Vec<(usize, Option<f64>)> {
    let score = |peaks: &JointPeaks| delta_r(&ctx.unbalanced, &peaks.0, &peaks.1);
    // (ΔR, index) in the order of `lowest_delta_r`: no score last, ties to the earlier option.
    let key = |s: Option<f64>, i: usize| (delta_r_cell(s), i);
    let before = |a: (f64, usize), b: (f64, usize)| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).is_lt();
    let n = groups.len();
    // Round 1: the first option, task by task.
    let requests: Vec<(&[Variant], &[usize])> = groups
        .iter()
        .flat_map(|(variants, tasks)| {
            tasks
                .iter()
                .map(move |w| (&variants[..variants.len().min(1)], std::slice::from_ref(w)))
        })
        .collect();
    let mut per_task = batched_reaction_peaks(ctx, &requests).into_iter();
    let mut full = vec![false; n];
    let mut first: Vec<(JointPeaks, Option<f64>)> = Vec::with_capacity(n);
    let mut probes: Vec<Vec<usize>> = Vec::with_capacity(n);
    let mut rests: Vec<Vec<usize>> = Vec::with_capacity(n);
    for (g, (variants, tasks)) in groups.iter().enumerate() {
        let peaks: Vec<Option<JointPeaks>> = tasks
            .iter()
            .map(|_| {
                per_task
                    .next()
                    .expect("one result per request")
                    .and_then(|mut p| p.pop())
            })
            .collect();
        full[g] = variants.is_empty() || peaks.iter().any(Option::is_none);
        let peaks: Vec<JointPeaks> = peaks.into_iter().flatten().collect();
        let mut total = zero_peaks(ctx, 1);
        for p in &peaks {
            raise_peaks(&mut total, vec![p.clone()]);
        }
        let total = total.pop().expect("one column");
        // The tasks where the first option's ΔR alone is largest.
        let mut ranked: Vec<(f64, usize)> = peaks
            .iter()
            .zip(tasks.iter())
            .map(|(p, &w)| (score(p).unwrap_or(f64::INFINITY), w))
            .collect();
        ranked.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
        let probe: Vec<usize> = ranked.iter().take(PROBE_TASKS).map(|r| r.1).collect();
        rests.push(
            tasks
                .iter()
                .copied()
                .filter(|w| !probe.contains(w))
                .collect(),
        );
        probes.push(probe);
        let s = score(&total);
        first.push((total, s));
    }
    // Round 2: the other options on the probe tasks: lower bounds.
    let requests: Vec<(&[Variant], &[usize])> = (0..n)
        .map(|g| {
            let variants = groups[g].0;
            if full[g] {
                (&variants[..0], &probes[g][..0])
            } else {
                (&variants[1..], &probes[g][..])
            }
        })
        .collect();
    let partial: Vec<Option<Vec<JointPeaks>>> = batched_reaction_peaks(ctx, &requests);
    let lower: Vec<Vec<Option<f64>>> = (0..n)
        .map(|g| match &partial[g] {
            Some(p) if !full[g] => p.iter().map(score).collect(),
            _ => {
                full[g] = true;
                Vec::new()
            }
        })
        .collect();
    // Evaluates `chosen` options of each group on its other tasks: their ΔR.
    let finish = |chosen: &[Vec<usize>]| -> Vec<Vec<Option<f64>>> {
        let variants: Vec<Vec<Variant>> = (0..n)
            .map(|g| chosen[g].iter().map(|&i| groups[g].0[i].clone()).collect())
            .collect();
        let requests: Vec<(&[Variant], &[usize])> =
            (0..n).map(|g| (&variants[g][..], &rests[g][..])).collect();
        let rest = batched_reaction_peaks(ctx, &requests);
        (0..n)
            .map(|g| {
                chosen[g]
                    .iter()
                    .enumerate()
                    .map(|(c, &i)| {
                        let mut total = vec![partial[g].as_ref().expect("not full")[i - 1].clone()];
                        match rest[g].as_ref() {
                            Some(r) => raise_peaks(&mut total, vec![r[c].clone()]),
                            None => return None,
                        }
                        score(&total[0])
                    })
                    .collect()
            })
            .collect()
    };
    // Round 3: the option with the lowest bound, where it could beat the first.
    let leaders: Vec<Vec<usize>> = (0..n)
        .map(|g| {
            if full[g] {
                return Vec::new();
            }
            (0..lower[g].len())
                .map(|k| (key(lower[g][k], k + 1), k + 1))
                .filter(|(b, _)| before(*b, key(first[g].1, 0)))
                .reduce(|a, b| if before(b.0, a.0) { b } else { a })
                .map(|(_, i)| vec![i])
                .unwrap_or_default()
        })
        .collect();
    let leader_scores = finish(&leaders);
    // Round 4: every other option whose bound could still beat the best ΔR known.
    let best_known: Vec<(f64, usize)> = (0..n)
        .map(|g| {
            let mut best = key(first[g].1, 0);
            for (&i, &s) in leaders[g].iter().zip(&leader_scores[g]) {
                if before(key(s, i), best) {
                    best = key(s, i);
                }
            }
            best
        })
        .collect();
    let others: Vec<Vec<usize>> = (0..n)
        .map(|g| {
            if full[g] {
                return Vec::new();
            }
            (1..=lower[g].len())
                .filter(|i| !leaders[g].contains(i))
                .filter(|&i| {
                    lower[g][i - 1].is_none() || before(key(lower[g][i - 1], i), best_known[g])
                })
                .collect()
        })
        .collect();
    let other_scores = finish(&others);
    let fallback: Vec<(&[Variant], &[usize])> =
        (0..n).filter(|&g| full[g]).map(|g| groups[g]).collect();
    let mut fallback = batched_reaction_peaks(ctx, &fallback).into_iter();
    (0..n)
        .map(|g| {
            let scores: Vec<(usize, Option<f64>)> = if full[g] {
                match fallback.next().flatten() {
                    Some(peaks) => peaks.iter().map(score).enumerate().collect(),
                    None => (0..groups[g].0.len()).map(|i| (i, None)).collect(),
                }
            } else {
                std::iter::once((0, first[g].1))
                    .chain(
                        leaders[g]
                            .iter()
                            .copied()
                            .zip(leader_scores[g].iter().copied()),
                    )
                    .chain(
                        others[g]
                            .iter()
                            .copied()
                            .zip(other_scores[g].iter().copied()),
                    )
                    .collect()
            };
            // The choice itself by `lowest_delta_r`, over the options evaluated in full in
            // their own order (its ties go to the earlier position).
            let mut scores = scores;
            scores.sort_by_key(|s| s.0);
            let only: Vec<Option<f64>> = scores.iter().map(|s| s.1).collect();
            lowest_delta_r(&only).map_or((0, None), |best| scores[best])
        })
        .collect()
}

/// Tasks on which every spring option is evaluated before the options that cannot be the
/// lowest ΔR are left out (see [`lowest_delta_r_choices`]).
const PROBE_TASKS: usize = 2;

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

/// The grid on which spring options' ΔR are compared, percentage points: scores in the same
/// cell ([`delta_r_cell`]) tie, and the earlier option wins.
///
/// The options are scored on the reaction tasks, where several can have the same ΔR up to
/// rounding (its terms are `γ·max(0, ΔF)` and alike, so a joint whose peak stays below the
/// unbalanced mechanism's adds nothing whatever the springs do to it). Compared exactly, such a tie went to whichever option the last
/// bits of the counterweights favoured: on the palletizer at Dmax 3, two runs whose
/// m5 + K53 + K54 designs differed by 1e-14 of the mass chose different options from the same
/// 32, whose ΔR over all tasks are 0.347 and 0.328 %. Scores closer than 1e-9 pp are below any
/// meaning a reaction peak has (the tables print two decimals) and far above rounding.
pub const DELTA_R_GRID: f64 = 1e-9;

/// The cell of an option's ΔR on the grid of [`DELTA_R_GRID`] (`round(ΔR / grid)`); an option
/// without a score is in the cell +∞, after every other. Rounding is monotone, so a lower bound
/// of a score has a cell at most the score's: pruning on cells stays valid.
pub fn delta_r_cell(score: Option<f64>) -> f64 {
    score.map_or(f64::INFINITY, |s| (s / DELTA_R_GRID).round())
}

/// The spring option to keep: the one with the lowest ΔR (paper Proc-9 ranks spring-only
/// variants by ΔR, so the optimiser keeps the realization that ranks best), compared on the
/// grid of [`DELTA_R_GRID`]; options without a score come last, ties go to the earliest
/// option (the realization from the first start is first). `None` for no options.
pub fn lowest_delta_r(scores: &[Option<f64>]) -> Option<usize> {
    (0..scores.len()).min_by(|&a, &b| {
        delta_r_cell(scores[a])
            .total_cmp(&delta_r_cell(scores[b]))
            .then(a.cmp(&b))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Scores closer than the grid tie and the earlier option wins; one grid step apart (or
    /// more), the lower one wins whatever its position; no score comes last.
    #[test]
    fn spring_options_closer_than_the_grid_tie_to_the_earlier_one() {
        let s = 0.346_661_466_570_231_6;
        // The two orders of a pair 1e-14 apart (the rounding seen between two runs): the
        // first option in either order.
        assert_eq!(lowest_delta_r(&[Some(s), Some(s - 1e-14)]), Some(0));
        assert_eq!(lowest_delta_r(&[Some(s - 1e-14), Some(s)]), Some(0));
        // A grid step apart: the lower score, in either position.
        let step = 1.5 * DELTA_R_GRID;
        assert_eq!(lowest_delta_r(&[Some(s), Some(s - step)]), Some(1));
        assert_eq!(lowest_delta_r(&[Some(s - step), Some(s)]), Some(0));
        assert_eq!(lowest_delta_r(&[None, Some(5.0), Some(0.33)]), Some(2));
        assert_eq!(lowest_delta_r(&[None, None]), Some(0));
        assert_eq!(lowest_delta_r(&[]), None);
        // The cell by hand: 0.33 pp on a 1e-9 grid is 330,000,000.
        assert_eq!(delta_r_cell(Some(0.33)), 330_000_000.0);
        assert_eq!(delta_r_cell(None), f64::INFINITY);
    }
}
