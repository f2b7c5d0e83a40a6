//! Designs shared between the variants of a pass that have the same counterweights.
//!
//! The objective depends on the counterweights alone (massless springs never change a
//! balanced variant's motor torques); a variant's springs only decide which counterweight
//! choices are admissible. Variants with the same counterweights and other springs often admit
//! the same best counterweights — on the palletizer, a counterweight with each of the
//! parallelogram's springs K54, K64, K65, K74, K75, K76, whose anchors differ by a translation
//! — yet each search ends at whichever design within the gap tolerance its own path met: at
//! Dmax 3, m4 + K54 + K73 ended at 11.5950 N·m (ΔQTR −54.25 %) and m4 + K73 + K74 at
//! 11.6012 N·m (−54.13 %), both certified within 1e-3 of their bounds, and another start seed
//! swapped the two, moving each by some fifty ranks.
//!
//! So after each pass's searches, each such variant tries the designs of its *siblings* (the
//! study's other variants with the same counterweight entries and springs that have a design:
//! this pass's, or one that converged in an earlier pass): the counterweights that give a lower
//! objective than its own design on its own working set, and not less than its certified bound
//! (lower ones cannot be admissible for it). Siblings that share more of its springs come
//! first (their admissible counterweights are more alike: at the m6 optimum, dozens of designs
//! that need other springs would otherwise use up the tries), then the lower objective; designs
//! within [`SAME_DESIGN`] of one already listed are tried once; at most [`SIBLING_ATTEMPTS`].
//! For each, its springs are realized for those counterweights (the pass's starts and seed; only
//! solutions that balance are returned) and the first design that meets every bound and peak
//! limit replaces its own. A design is only ever replaced by a better verified one on the same
//! tasks, so the bound and the verdict keep their meaning and the gap only shrinks; the
//! all-task evaluation that follows checks the new design's critical tasks as it would the
//! search's. Variants without counterweights take no part (their objective is the same at
//! every design), nor do those without springs (there would be no realization to check the
//! balance of another variant's counterweights).
//!
//! Every variant reads its siblings' designs as the searches left them, in a fixed order, so
//! the outcome does not depend on the thread count or on the order of work. It does depend on
//! which siblings are in the study: a shard holds every variant of a counterweight set
//! together (see the study crate's partition), so a sharded study merges into the single run.

use std::collections::BTreeMap;

use nalgebra::DVector;
use rayon::prelude::*;

use super::state::{OptimiseOptions, Run, State};
use crate::certify::{Design, verified_design};
use crate::context::Context;
use crate::problem::VariantProblem;
use crate::slots::CwPhysical;
use crate::springs::{StartRecord, realize_springs_seeded};

/// At most this many siblings' designs are tried per variant and pass (in the order of the
/// module doc): each costs a spring realization from the pass's starts.
pub(super) const SIBLING_ATTEMPTS: usize = 16;

/// A better design for one variant, from a sibling's counterweights.
pub(super) struct SharedDesign {
    pub(super) design: Design,
    pub(super) starts: StartRecord,
    /// The sibling whose counterweights the design takes (its element labels).
    pub(super) from: Vec<String>,
}

/// Per variant of `evaluated` (the runs with a candidate this pass, in increasing order), in
/// that order, the better design its siblings' counterweights give, if any (see the module
/// doc).
pub(super) fn sibling_designs(
    ctx: &Context,
    runs: &[Run],
    evaluated: &[usize],
    options: &OptimiseOptions,
) -> Vec<(usize, SharedDesign)> {
    // Sources: every run with a design that still stands (this pass's, or a converged run's
    // from an earlier pass); targets: this pass's.
    let stands = |run: &Run| {
        run.candidate.is_some() && matches!(run.state, State::Running | State::Converged)
    };
    let mut groups: BTreeMap<Vec<usize>, Vec<usize>> = BTreeMap::new();
    for (k, run) in runs.iter().enumerate() {
        let Some(problem) = run.problem.as_ref() else {
            continue;
        };
        let entries = problem.counterweights.iter().map(|c| c.entry);
        let Some(key) = sibling_group(entries, !problem.springs.is_empty()) else {
            continue;
        };
        if stands(run) {
            groups.entry(key).or_default().push(k);
        }
    }
    let targets: Vec<(usize, &[usize])> = groups
        .values()
        .filter(|g| g.len() > 1)
        .flat_map(|g| {
            g.iter()
                .filter(|k| evaluated.binary_search(k).is_ok())
                .map(move |&k| (k, g.as_slice()))
        })
        .collect();
    let mut shared: Vec<(usize, SharedDesign)> = targets
        .par_iter()
        .with_max_len(1)
        .filter_map(|&(k, group)| better_design(ctx, runs, k, group, options).map(|s| (k, s)))
        .collect();
    shared.sort_by_key(|s| s.0);
    shared
}

/// The group of siblings a variant belongs to: its counterweights' catalogue entries, sorted,
/// when it has counterweights and at least one spring; `None` for a variant that takes no part
/// (see the module doc). The study's shard partition keeps each group whole with this same key.
pub fn sibling_group(
    counterweight_entries: impl IntoIterator<Item = usize>,
    has_spring: bool,
) -> Option<Vec<usize>> {
    let mut key: Vec<usize> = counterweight_entries.into_iter().collect();
    key.sort_unstable();
    (!key.is_empty() && has_spring).then_some(key)
}

/// `x` with the counterweights' lifted columns (mass, first moment) of another variant's point
/// `their_x` (the same counterweight entries, so the same axes), `None` when one of them is
/// missing from `their_problem`.
pub(super) fn with_their_counterweights(
    problem: &VariantProblem,
    x: &DVector<f64>,
    their_problem: &VariantProblem,
    their_x: &DVector<f64>,
) -> Option<DVector<f64>> {
    let mut x = x.clone();
    for mine in &problem.counterweights {
        let their = their_problem
            .counterweights
            .iter()
            .find(|c| c.entry == mine.entry)?;
        for r in 0..=mine.axes.len() {
            x[mine.column + r] = their_x[their.column + r];
        }
    }
    Some(x)
}

/// Relative distance below which two designs' counterweights count as one design to try.
const SAME_DESIGN: f64 = 1e-4;

/// Whether two designs' counterweights (the same entries, in order) are within
/// [`SAME_DESIGN`] of each other: each mass relative to the larger of the two, each first
/// moment's difference relative to the larger first moment.
fn near_counterweights(a: &[CwPhysical], b: &[CwPhysical]) -> bool {
    let norm = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    a.iter().zip(b).all(|(p, q)| {
        let dmu = [p.mu[0] - q.mu[0], p.mu[1] - q.mu[1], p.mu[2] - q.mu[2]];
        (p.mass - q.mass).abs() <= SAME_DESIGN * p.mass.abs().max(q.mass.abs())
            && norm(dmu) <= SAME_DESIGN * norm(p.mu).max(norm(q.mu))
    })
}

/// A sibling's design offered to a variant.
struct Offer<'a> {
    /// How many of the variant's springs the sibling has too.
    shared_springs: usize,
    /// The design's objective on the variant's working set.
    value: f64,
    /// The sibling's run.
    run: usize,
    /// The design's counterweights.
    cws: &'a [CwPhysical],
}

/// The runs whose designs a variant tries, in order (see the module doc): the offers whose
/// value lies in `[lower_bound, own_value)` — below its certified bound a design cannot be
/// admissible for it, at or above its own value it is no better — those sharing more springs
/// first, then the lower value, then the run order; of designs near one another
/// ([`near_counterweights`]: mirror twins, springs that load other joints, searches that
/// stopped within the gap of one optimum), the first only.
fn offers_to_try(mut offers: Vec<Offer>, lower_bound: f64, own_value: f64) -> Vec<usize> {
    offers.retain(|o| o.value >= lower_bound && o.value < own_value);
    offers.sort_by(|a, b| {
        b.shared_springs
            .cmp(&a.shared_springs)
            .then(a.value.total_cmp(&b.value))
            .then(a.run.cmp(&b.run))
    });
    let mut distinct: Vec<Offer> = Vec::new();
    for offer in offers {
        if !distinct
            .iter()
            .any(|d| near_counterweights(d.cws, offer.cws))
        {
            distinct.push(offer);
        }
    }
    distinct.into_iter().map(|o| o.run).collect()
}

/// The best of the siblings' counterweights that run `k`'s springs admit, when it is better
/// than `k`'s own design (see the module doc).
fn better_design(
    ctx: &Context,
    runs: &[Run],
    k: usize,
    group: &[usize],
    options: &OptimiseOptions,
) -> Option<SharedDesign> {
    let run = &runs[k];
    let problem = run.problem.as_ref()?;
    let own = run.candidate.as_ref()?;
    let (tasks, _) = ctx.torques.get(&ctx.model, &ctx.tasks, &run.working);
    let shared_springs = |j: usize| {
        runs[j].problem.as_ref().map_or(0, |theirs| {
            theirs
                .springs
                .iter()
                .filter(|s| problem.springs.iter().any(|t| t.entry == s.entry))
                .count()
        })
    };
    let offers: Vec<Offer> = group
        .iter()
        .filter(|&&j| j != k)
        .filter_map(|&j| {
            let theirs = runs[j].candidate.as_ref()?;
            let value = problem
                .evaluate(&theirs.cws, &tasks)
                .objective(options.objective, problem.actuators);
            Some(Offer {
                shared_springs: shared_springs(j),
                value,
                run: j,
                cws: &theirs.cws,
            })
        })
        .collect();
    let order = offers_to_try(offers, own.lower_bound, own.working_value);
    let b = &ctx.basis.unbalanced;
    for &j in order.iter().take(SIBLING_ATTEMPTS) {
        let theirs = runs[j].candidate.as_ref()?;
        let their_problem = runs[j].problem.as_ref()?;
        // Their counterweights in place of this run's; the springs are realized for them below.
        let x = with_their_counterweights(problem, &own.x, their_problem, &theirs.x)?;
        let (found, _, starts) = realize_springs_seeded(
            problem,
            b,
            &x,
            options.spring_starts,
            false,
            None,
            options.start_seed,
        );
        // Their offsets come through a least-squares fit of this family, so the ones no torque
        // or relation sees are centred again (`centre`).
        let design = found
            .into_iter()
            .find_map(|(springs, x_full)| {
                verified_design(problem, &tasks, options.objective, springs, x_full)
            })
            .map(|d| crate::centre::centred(problem, &tasks, options.objective, d));
        if let Some(design) = design.filter(|d| d.value < own.working_value) {
            return Some(SharedDesign {
                design,
                starts,
                from: runs[j].elements.clone(),
            });
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cw(mass: f64, mu: [f64; 3]) -> CwPhysical {
        CwPhysical { mass, mu }
    }

    /// By hand, a variant with certified bound 10 and its own design at 12 N·m: 9.9 lies below
    /// its bound and 12.0 is its own value, both out; 10.0 (the bound itself) and the rest are
    /// in. Sharing two springs first (runs 4, 5, 6: values 10.0, 10.5, 10.5, the equal values
    /// by run order), then one (runs 3, 7: 10.2, 11.0); run 8 (10.9, two springs, so before
    /// runs 3 and 7) has counterweights within 1e-4 of run 6's and is left out as the same
    /// design.
    #[test]
    fn offers_in_the_window_by_shared_springs_then_value_then_run_one_per_design() {
        let design = |m: f64| vec![cw(m, [1.0, 2.0, 0.0])];
        let designs: Vec<Vec<CwPhysical>> = (0..10).map(|r| design(10.0 + r as f64)).collect();
        let near_six = design(16.0001);
        let offer = |shared_springs: usize, value: f64, run: usize| Offer {
            shared_springs,
            value,
            run,
            cws: if run == 8 { &near_six } else { &designs[run] },
        };
        let offers = vec![
            offer(2, 9.9, 1),
            offer(2, 12.0, 2),
            offer(1, 10.2, 3),
            offer(2, 10.0, 4),
            offer(2, 10.5, 6),
            offer(2, 10.5, 5),
            offer(1, 11.0, 7),
            offer(2, 10.9, 8),
        ];
        assert_eq!(offers_to_try(offers, 10.0, 12.0), [4, 5, 6, 3, 7]);
    }

    /// By hand: counterweights 3 and 1 with a spring group as [1, 3] (the order of the
    /// elements does not matter); without a spring, or without a counterweight, no group.
    #[test]
    fn a_group_is_the_sorted_counterweights_of_a_variant_with_a_spring() {
        assert_eq!(sibling_group([3, 1], true), Some(vec![1, 3]));
        assert_eq!(sibling_group([1, 3], true), Some(vec![1, 3]));
        assert_eq!(sibling_group([3, 1], false), None);
        assert_eq!(sibling_group([], true), None);
    }

    #[test]
    fn designs_within_the_relative_distance_count_as_one() {
        let a = [cw(20.0, [3.0, -4.0, 0.0])];
        assert!(near_counterweights(&a, &a));
        // Mass: 1e-4 of the larger mass is 2e-3 kg; half of it is near, twice it is not.
        assert!(near_counterweights(&a, &[cw(20.001, [3.0, -4.0, 0.0])]));
        assert!(near_counterweights(&[cw(20.001, [3.0, -4.0, 0.0])], &a));
        assert!(!near_counterweights(&a, &[cw(20.004, [3.0, -4.0, 0.0])]));
        assert!(!near_counterweights(&a, &[cw(19.996, [3.0, -4.0, 0.0])]));
        // First moment: |μ| = 5 kg·m, so 5e-4 kg·m in any direction (a 3-4-5 step of
        // (1.2e-4, 1.6e-4, 0) is 2e-4: near; (3e-4, 4e-4, 0) is exactly 5e-4: near; twice
        // that along z is not).
        assert!(near_counterweights(
            &a,
            &[cw(20.0, [3.00012, -3.99984, 0.0])]
        ));
        assert!(near_counterweights(&a, &[cw(20.0, [3.0003, -4.0004, 0.0])]));
        assert!(!near_counterweights(&a, &[cw(20.0, [3.0, -4.0, 1e-3])]));
        assert!(!near_counterweights(&a, &[cw(20.0, [3.0, -4.0, -1e-3])]));
        assert!(!near_counterweights(&a, &[cw(20.0, [2.999, -4.0, 0.0])]));
        assert!(!near_counterweights(&a, &[cw(20.0, [3.0, -3.999, 0.0])]));
        // The mirror image is another design.
        assert!(!near_counterweights(&a, &[cw(20.0, [-3.0, 4.0, 0.0])]));
        // The larger first moment sets the scale: 1e-3 kg·m against |μ| = 10 is near.
        assert!(near_counterweights(
            &[cw(20.0, [0.0, 10.0, 0.0])],
            &[cw(20.0, [0.0, 10.0, 1e-3])]
        ));
        // Every counterweight must be near.
        let two = [cw(20.0, [3.0, -4.0, 0.0]), cw(5.0, [0.0, 0.0, 1.0])];
        assert!(near_counterweights(&two, &two));
        assert!(!near_counterweights(
            &two,
            &[cw(20.0, [3.0, -4.0, 0.0]), cw(5.1, [0.0, 0.0, 1.0])]
        ));
        assert!(!near_counterweights(
            &two,
            &[cw(20.1, [3.0, -4.0, 0.0]), cw(5.0, [0.0, 0.0, 1.0])]
        ));
    }
}
