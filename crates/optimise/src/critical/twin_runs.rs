//! The critical-task loop over one variant per class of mirror twins (see [`crate::twins`]).
//!
//! Each balanced variant's *leader* is the variant with every spring replaced by the twin of
//! lowest catalogue index: the same balanced family up to sign changes of anchor coordinates,
//! the same objective at every counterweight choice. The loop runs on the leaders alone; each
//! variant then takes its leader's run with the lifted point and the springs mirrored, and
//! keeps its own spring choice, final evaluation and verification (where twins differ: the
//! joints their springs load). A leader is chosen from the variant's elements only, never
//! from the other variants of the study, so a shard solves the leaders its own variants need
//! and gets the single run's bits; a leader that is not itself among the variants is solved
//! and left out of the results.

use std::collections::BTreeMap;

use counterpoise_balance::VariantResult;
use counterpoise_balance::search::ElementRef;
use nalgebra::DVector;

use super::state::{Candidate, Run, State};
use crate::context::Context;
use crate::problem::VariantProblem;
use crate::twins::SpringTwin;

/// The leaders to run and, per balanced variant in input order, its leader's index among them.
pub(super) struct Leaders {
    pub(super) variants: Vec<VariantResult>,
    pub(super) of: Vec<usize>,
}

/// The leader of each of `balanced` (by `twins`, per catalogue entry): a variant is its own
/// leader when none of its springs has a twin, or when two of them share one.
pub(super) fn leaders(
    balanced: &[&VariantResult],
    twins: &[Option<SpringTwin>],
    ctx: &Context,
) -> Leaders {
    let mut index: BTreeMap<Vec<usize>, usize> = BTreeMap::new();
    let mut variants = Vec::new();
    let mut of = Vec::with_capacity(balanced.len());
    for v in balanced {
        let leader = leader_variant(v, twins, ctx);
        let mut key: Vec<usize> = leader.elements.iter().map(|e| e.entry).collect();
        key.sort_unstable();
        let k = *index.entry(key).or_insert_with(|| {
            variants.push(leader);
            variants.len() - 1
        });
        of.push(k);
    }
    Leaders { variants, of }
}

/// `v` with each spring that follows a twin replaced by that twin, elements in catalogue
/// order; `v` itself when no spring follows one or the replacement would repeat an element.
fn leader_variant(v: &VariantResult, twins: &[Option<SpringTwin>], ctx: &Context) -> VariantResult {
    let mut elements: Vec<ElementRef> = v
        .elements
        .iter()
        .map(|e| match twins.get(e.entry).and_then(Option::as_ref) {
            Some(t) => {
                let entry = &ctx.catalogue.entries[t.leader];
                ElementRef {
                    entry: t.leader,
                    label: entry.label.clone(),
                    kind: e.kind,
                    bodies: entry.bodies.clone(),
                }
            }
            None => e.clone(),
        })
        .collect();
    elements.sort_by_key(|e| e.entry);
    let repeated = elements.windows(2).any(|w| w[0].entry == w[1].entry);
    let mut own: Vec<usize> = v.elements.iter().map(|e| e.entry).collect();
    own.sort_unstable();
    if repeated || elements.iter().map(|e| e.entry).eq(own) {
        // No spring follows a twin (whatever the order `v` lists its elements in).
        return v.clone();
    }
    VariantResult {
        elements,
        ..v.clone()
    }
}

/// The run of `member` (built by `new_run`, not searched) from its leader's finished run:
/// its state, working set and record of passes, and its candidate with every lifted block
/// and spring mirrored into `member`'s own slots. `None` when some slot has no counterpart
/// (then the member is searched itself).
pub(super) fn follow(
    ctx: &Context,
    twins: &[Option<SpringTwin>],
    leader: &Run,
    mut member: Run,
) -> Option<Run> {
    let mirrored = |reason: &str| {
        format!(
            "as for {}, whose springs store the same energy with mirrored anchors: {reason}",
            leader.elements.join(" + ")
        )
    };
    member.working = leader.working.clone();
    member.iterations = leader.iterations.clone();
    member.search = None;
    member.state = match &leader.state {
        State::Discarded(r) => State::Discarded(mirrored(r)),
        State::Undecided(r) => State::Undecided(mirrored(r)),
        other => other.clone(),
    };
    member.candidate = match (&leader.candidate, &leader.problem, &member.problem) {
        (Some(c), Some(lp), Some(mp)) => Some(mirror_candidate(ctx, twins, c, lp, mp)?),
        (None, _, _) => None,
        _ => return None,
    };
    Some(member)
}

/// `cand` of the leader's problem `lp` as a candidate of the member's problem `mp`.
fn mirror_candidate(
    ctx: &Context,
    twins: &[Option<SpringTwin>],
    cand: &Candidate,
    lp: &VariantProblem,
    mp: &VariantProblem,
) -> Option<Candidate> {
    let mut x = DVector::<f64>::from_element(mp.particular.len(), f64::NAN);
    let mut cws = Vec::with_capacity(mp.counterweights.len());
    for slot in &mp.counterweights {
        let (k, from) = lp
            .counterweights
            .iter()
            .enumerate()
            .find(|(_, l)| l.entry == slot.entry)?;
        let len = 1 + slot.axes.len();
        x.rows_mut(slot.column, len)
            .copy_from(&cand.x.rows(from.column, len));
        cws.push(*cand.cws.get(k)?);
    }
    let mut springs = Vec::with_capacity(mp.springs.len());
    for slot in &mp.springs {
        let mirror = twins
            .get(slot.entry)
            .and_then(Option::clone)
            .unwrap_or_else(|| {
                SpringTwin::identity(slot.entry, slot.axes_a.len(), slot.axes_b.len())
            });
        let from = lp.springs.iter().find(|l| l.entry == mirror.leader)?;
        if from.axes_a != slot.axes_a || from.axes_b != slot.axes_b {
            return None;
        }
        let signs = mirror.lifted_signs();
        for (k, s) in signs.iter().enumerate() {
            x[slot.column + k] = s * cand.x[from.column + k];
        }
        let spring = cand.springs.iter().find(|s| s.label == from.label)?;
        let mut anchor_a = spring.anchor_a;
        let mut anchor_b = spring.anchor_b;
        for (i, &axis) in slot.axes_a.iter().enumerate() {
            anchor_a[axis] = mirror.sign_a[i] * spring.anchor_a[axis];
        }
        for (l, &axis) in slot.axes_b.iter().enumerate() {
            anchor_b[axis] = mirror.sign_b[l] * spring.anchor_b[axis];
        }
        let entry = &ctx.catalogue.entries[slot.entry];
        springs.push(crate::springs::Spring {
            label: entry.label.clone(),
            body: slot.bodies[0].clone(),
            other: slot.bodies[1].clone(),
            anchor_a,
            anchor_b,
            ..spring.clone()
        });
    }
    if x.iter().any(|v| v.is_nan()) {
        return None;
    }
    Some(Candidate {
        x,
        cws,
        springs,
        spring_starts: None,
        ..cand.clone()
    })
}
