//! Why a balanced variant cannot be built, in the designer's words.
//!
//! The convex relaxation ([`crate::relaxation`]) contains every physical point of the variant,
//! so when it is infeasible no parameters meet the bounds (and peak limits): that is the
//! certificate of a discard. This module finds the constraint to blame by re-solving the
//! relaxation with one bound widened at a time: a bound whose widening alone makes it feasible
//! is binding, and a bisection on its value gives the least value the variant would need — a
//! certified "at least", since the relaxation is still infeasible at that value. Peak limits
//! are examined (and mentioned) only when the case sets them.

use std::sync::Arc;

use crate::problem::{Objective, VariantProblem};
use crate::relaxation::{solve_bounds_only, solve_relaxation};
use crate::torque::TaskTorques;

/// How far a bound is widened to test whether it alone is to blame.
const WIDEN: f64 = 100.0;
/// Bisection steps on the logarithm of a bound (factor 100 in 8 steps: 1.8 % resolution; the
/// value reported is the infeasible end, so "at least" holds whatever the resolution).
const BISECTION_STEPS: usize = 8;

/// One bound of one element that can be moved.
#[derive(Clone, Copy, Debug)]
enum Knob {
    CwMass(usize),
    CwRadius(usize),
    SpringStiffnessHi(usize),
    SpringStiffnessLo(usize),
    AnchorA(usize),
    AnchorB(usize),
    PeakLimit(usize),
}

impl Knob {
    /// The bound's current value.
    fn value(self, p: &VariantProblem) -> Option<f64> {
        match self {
            Knob::CwMass(k) => Some(p.counterweights[k].bounds.mass[1]),
            Knob::CwRadius(k) => Some(p.counterweights[k].bounds.radius[1]),
            Knob::SpringStiffnessHi(k) => Some(p.springs[k].bounds.stiffness[1]),
            Knob::SpringStiffnessLo(k) => Some(p.springs[k].bounds.stiffness[0]),
            Knob::AnchorA(k) => Some(p.springs[k].bounds.anchor_a[1]),
            Knob::AnchorB(k) => Some(p.springs[k].bounds.anchor_b[1]),
            Knob::PeakLimit(a) => p.peak_limits.get(a).copied().flatten(),
        }
    }

    /// Whether relaxing means lowering the value (a lower bound).
    fn is_lower(self) -> bool {
        matches!(self, Knob::SpringStiffnessLo(_))
    }

    fn set(self, p: &mut VariantProblem, v: f64) {
        match self {
            Knob::CwMass(k) => p.counterweights[k].bounds.mass[1] = v,
            Knob::CwRadius(k) => {
                let b = &mut p.counterweights[k].bounds.radius;
                b[1] = v;
                b[0] = b[0].min(v);
            }
            Knob::SpringStiffnessHi(k) => p.springs[k].bounds.stiffness[1] = v,
            Knob::SpringStiffnessLo(k) => p.springs[k].bounds.stiffness[0] = v,
            Knob::AnchorA(k) => {
                let b = &mut p.springs[k].bounds.anchor_a;
                b[1] = v;
                b[0] = b[0].min(v);
            }
            Knob::AnchorB(k) => {
                let b = &mut p.springs[k].bounds.anchor_b;
                b[1] = v;
                b[0] = b[0].min(v);
            }
            Knob::PeakLimit(a) => p.peak_limits[a] = Some(v),
        }
    }

    /// The designer's sentence: what the element would need, and the bound.
    fn sentence(
        self,
        p: &VariantProblem,
        names: &[String],
        needed: f64,
        bound: f64,
        task: Option<[usize; 2]>,
    ) -> String {
        let g = |v: f64| format!("{}", Sig(v));
        match self {
            Knob::CwMass(k) => format!(
                "{} would need a mass of at least {} kg; the bound is {} kg",
                p.counterweights[k].label,
                g(needed),
                g(bound)
            ),
            Knob::CwRadius(k) => format!(
                "{} would need an offset of at least {} m; the bound is {} m",
                p.counterweights[k].label,
                g(needed),
                g(bound)
            ),
            Knob::SpringStiffnessHi(k) => format!(
                "{} would need a stiffness of at least {} N/m; the bound is {} N/m",
                p.springs[k].label,
                g(needed),
                g(bound)
            ),
            Knob::SpringStiffnessLo(k) => format!(
                "{} would need a stiffness of at most {} N/m; the lower bound is {} N/m",
                p.springs[k].label,
                g(needed),
                g(bound)
            ),
            Knob::AnchorA(k) => format!(
                "{} would need its anchor a at least {} m from the origin of its body; the bound \
                 is {} m",
                p.springs[k].label,
                g(needed),
                g(bound)
            ),
            Knob::AnchorB(k) => format!(
                "{} would need its anchor b at least {} m from the origin of its body; the bound \
                 is {} m",
                p.springs[k].label,
                g(needed),
                g(bound)
            ),
            Knob::PeakLimit(a) => {
                let on = task
                    .map(|t| format!(" on task {}→{}", t[0], t[1]))
                    .unwrap_or_default();
                let motor = names
                    .get(a)
                    .cloned()
                    .unwrap_or_else(|| format!("motor {}", a + 1));
                format!(
                    "{motor} would peak at {} N·m at least{on} (limit {} N·m)",
                    g(needed),
                    g(bound)
                )
            }
        }
    }
}

/// Four significant digits, without trailing zeros.
struct Sig(f64);

impl std::fmt::Display for Sig {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let v = self.0;
        if v == 0.0 || !v.is_finite() {
            return write!(f, "{v}");
        }
        let digits = (3 - v.abs().log10().floor() as i32).max(0) as usize;
        let s = format!("{v:.digits$}");
        let s = if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        };
        write!(f, "{s}")
    }
}

/// What the relaxation is solved with: the bounds alone, or the working-set tasks with the
/// peak limits.
struct Probe<'a> {
    tasks: &'a [Arc<TaskTorques>],
    objective: Objective,
    max_iter: u32,
}

impl Probe<'_> {
    /// Whether the relaxation of `p` is proved infeasible.
    fn infeasible(&self, p: &VariantProblem) -> bool {
        if self.tasks.is_empty() {
            solve_bounds_only(p, self.max_iter)
                .solution
                .status
                .is_infeasible()
        } else {
            solve_relaxation(p, self.tasks, self.objective, self.max_iter)
                .solution
                .status
                .is_infeasible()
        }
    }

    /// The least value of `knob` (the largest, for a lower bound) at which the relaxation is
    /// no longer proved infeasible, if widening the bound by [`WIDEN`] is enough; the value
    /// returned is one at which the relaxation is still infeasible ("at least").
    fn needed(&self, p: &VariantProblem, knob: Knob) -> Option<f64> {
        let bound = knob.value(p)?;
        let mut q = p.clone();
        let far = if knob.is_lower() {
            0.0
        } else {
            bound.max(1e-6) * WIDEN
        };
        knob.set(&mut q, far);
        if self.infeasible(&q) {
            return None;
        }
        if knob.is_lower() {
            // Bisect linearly between the widened (feasible) 0 and the bound (infeasible).
            let (mut ok, mut bad) = (0.0, bound);
            for _ in 0..BISECTION_STEPS {
                let mid = 0.5 * (ok + bad);
                knob.set(&mut q, mid);
                if self.infeasible(&q) {
                    bad = mid;
                } else {
                    ok = mid;
                }
            }
            return Some(bad);
        }
        let (mut bad, mut ok) = (bound.max(1e-6).ln(), far.ln());
        for _ in 0..BISECTION_STEPS {
            let mid = 0.5 * (bad + ok);
            knob.set(&mut q, mid.exp());
            if self.infeasible(&q) {
                bad = mid;
            } else {
                ok = mid;
            }
        }
        Some(bad.exp().max(bound))
    }
}

fn bound_knobs(p: &VariantProblem) -> Vec<Knob> {
    let mut knobs = Vec::new();
    for (k, c) in p.counterweights.iter().enumerate() {
        knobs.push(Knob::CwMass(k));
        if !c.axes.is_empty() {
            knobs.push(Knob::CwRadius(k));
        }
    }
    for (k, s) in p.springs.iter().enumerate() {
        knobs.push(Knob::SpringStiffnessHi(k));
        if s.bounds.stiffness[0] > 0.0 {
            knobs.push(Knob::SpringStiffnessLo(k));
        }
        if !s.axes_a.is_empty() {
            knobs.push(Knob::AnchorA(k));
        }
        if !s.axes_b.is_empty() {
            knobs.push(Knob::AnchorB(k));
        }
    }
    knobs
}

/// The reason a variant whose relaxation was proved infeasible is discarded: the binding
/// bound(s) with the value needed, or the motor whose peak limit cannot be met (only when the
/// case sets peak limits). `pair` names a working-set task.
pub fn infeasibility_reason(
    problem: &VariantProblem,
    tasks: &[Arc<TaskTorques>],
    objective: Objective,
    max_iter: u32,
    actuator_names: &[String],
    pair: impl Fn(usize) -> [usize; 2],
) -> String {
    let bounds_only = Probe {
        tasks: &[],
        objective,
        max_iter,
    };
    let has_limits = problem.peak_limits.iter().any(Option::is_some);
    if bounds_only.infeasible(problem) {
        let found: Vec<String> = bound_knobs(problem)
            .into_iter()
            .filter_map(|knob| {
                let needed = bounds_only.needed(problem, knob)?;
                Some(knob.sentence(problem, actuator_names, needed, knob.value(problem)?, None))
            })
            .collect();
        if found.is_empty() {
            let labels = problem.labels.join(", ");
            return format!(
                "the bounds of {labels} cannot all be met together (no single bound widened \
                 {WIDEN}× makes it possible)"
            );
        }
        return found.join("; or ");
    }
    if has_limits && !tasks.is_empty() {
        let with_tasks = Probe {
            tasks,
            objective,
            max_iter,
        };
        let mut found = Vec::new();
        for a in 0..problem.peak_limits.len() {
            let knob = Knob::PeakLimit(a);
            let Some(limit) = knob.value(problem) else {
                continue;
            };
            let Some(needed) = with_tasks.needed(problem, knob) else {
                continue;
            };
            // The task on which this limit alone cannot be met, if one is.
            let mut only_a = problem.clone();
            for (b, l) in only_a.peak_limits.iter_mut().enumerate() {
                if b != a {
                    *l = None;
                }
            }
            let task = tasks.iter().find_map(|t| {
                let single = Probe {
                    tasks: std::slice::from_ref(t),
                    objective,
                    max_iter,
                };
                single.infeasible(&only_a).then(|| pair(t.task))
            });
            found.push(knob.sentence(problem, actuator_names, needed, limit, task));
        }
        if !found.is_empty() {
            return found.join("; or ");
        }
        return "the bounds and the peak limits cannot all be met together".into();
    }
    "the bounds cannot all be met together".into()
}

#[cfg(test)]
mod tests {
    use super::Sig;

    #[test]
    fn four_significant_digits() {
        assert_eq!(Sig(0.52349).to_string(), "0.5235");
        assert_eq!(Sig(30.13).to_string(), "30.13");
        assert_eq!(Sig(12345.6).to_string(), "12346");
        assert_eq!(Sig(0.5).to_string(), "0.5");
    }
}
