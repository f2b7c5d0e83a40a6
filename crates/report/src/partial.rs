//! The partial-balancing section of the reports: what `run` found when no variant is feasible —
//! the smallest Dmax at which a variant balances, and the best counterweights within the study's
//! Dmax that leave the least RMS gravity torque (the `partial.json` written beside
//! `results.json`). Plain data, filled by the caller: this crate knows nothing of the search or
//! the mechanics, it renders numbers. The section is in report.html and report.md only when
//! [`RunResults::partial`](crate::RunResults) is set, which `run` does only when nothing is
//! feasible.

use serde::{Deserialize, Serialize};

use crate::format::fixed;
use crate::parameters::Counterweight;

/// Rows of the designs table in the reports; every set is in partial.json and partial.csv.
pub const TABLE_ROWS: usize = 30;

/// What `run`'s fallback found, in plain numbers (a copy of partial.json's essentials).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PartialBalancing {
    /// The statement of the smallest Dmax at which a variant balances, one sentence
    /// (`No feasible variant at Dmax 2: …; the smallest Dmax at which one does is 3, e.g. …`).
    pub smallest_dmax: String,
    /// Why no partial design was computed (then `designs` is empty).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub skipped: Option<String>,
    /// Most counterweights per set (the study's Dmax).
    pub budget: usize,
    /// Workspace points the RMS values are taken over.
    pub points: usize,
    /// Every actuator's name, in the case's order (the order of every `rms` vector).
    pub actuators: Vec<String>,
    /// The actuators whose torque was minimised.
    pub minimised: Vec<String>,
    /// Per actuator, the unbalanced robot's RMS gravity torque (N·m, N for a slide; the
    /// actuator force before the ratio).
    pub unbalanced_rms: Vec<f64>,
    /// `√(Σ RMS²)` over the minimised actuators, unbalanced.
    pub unbalanced_total: f64,
    /// Sets solved (every set of at most `budget` counterweights).
    pub sets: usize,
    /// Every set's best design, best first (partial.json's `designs`, in its order).
    pub designs: Vec<PartialDesign>,
}

/// One set's best design.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PartialDesign {
    /// 1 = least total RMS.
    pub rank: usize,
    pub elements: Vec<PartialElement>,
    /// `√(Σ RMS²)` over the minimised actuators.
    pub total_rms: f64,
    /// Per actuator, in [`PartialBalancing::actuators`]' order.
    pub rms: Vec<f64>,
    /// The exact balance search's verdict on the set, whatever the bounds, when it was decided
    /// (`balanced`, `infeasible`, …).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub exact: Option<String>,
}

/// One counterweight of a design: its physical parameters, and whether the design uses it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PartialElement {
    #[serde(flatten)]
    pub counterweight: Counterweight,
    /// Left at 0 kg by the best design (the smaller set does as well).
    pub unused: bool,
}

impl PartialDesign {
    /// `m2 + m3`.
    pub fn set(&self) -> String {
        self.elements
            .iter()
            .map(|e| e.counterweight.label.as_str())
            .collect::<Vec<_>>()
            .join(" + ")
    }
}

/// Change of `value` against `reference`, in % (negative = less torque); `None` when the
/// reference is zero (an actuator gravity does not load).
pub fn change(value: f64, reference: f64) -> Option<f64> {
    (reference > 0.0).then(|| 100.0 * (value / reference - 1.0))
}

/// A torque or an RMS in the reports: three decimals, as the terminal summary.
pub fn rms(x: f64) -> String {
    fixed(x, 3)
}

/// A change in %, one decimal with its sign (`-93.6 %`).
pub(crate) fn change_text(value: f64, reference: f64) -> Option<String> {
    change(value, reference).map(|c| {
        let s = fixed(c, 1);
        if c > 0.0 && s != "0.0" {
            format!("+{s} %")
        } else {
            format!("{s} %")
        }
    })
}

/// Millimetres to 0.1 mm without a negative zero.
fn millimetres(metres: f64) -> String {
    fixed(metres * 1e3, 1)
}

/// One counterweight in words: `m2 on upper_arm: 13.405 kg at (0.0, 0.0, -425.5) mm (|r| = 425.5 mm)`.
pub fn element_text(e: &PartialElement) -> String {
    if e.unused {
        return format!(
            "{} on {}: unused (0 kg)",
            e.counterweight.label, e.counterweight.body
        );
    }
    let r = e
        .counterweight
        .offset
        .iter()
        .map(|v| v * v)
        .sum::<f64>()
        .sqrt();
    format!(
        "{} on {}: {} kg at ({}, {}, {}) mm (|r| = {} mm)",
        e.counterweight.label,
        e.counterweight.body,
        fixed(e.counterweight.mass, 3),
        millimetres(e.counterweight.offset[0]),
        millimetres(e.counterweight.offset[1]),
        millimetres(e.counterweight.offset[2]),
        millimetres(r)
    )
}

/// Indices into `designs` of the best design of each size (1, 2, … counterweights), leaving
/// out designs with an unused counterweight (the smaller set is ranked on its own), smallest
/// size first.
pub fn best_of_each_size(p: &PartialBalancing) -> Vec<usize> {
    let mut best: Vec<Option<usize>> = vec![None; p.budget + 1];
    for (i, d) in p.designs.iter().enumerate() {
        let size = d.elements.len();
        if size <= p.budget && best[size].is_none() && d.elements.iter().all(|e| !e.unused) {
            best[size] = Some(i);
        }
    }
    best.into_iter().flatten().collect()
}

/// The paragraphs before the table: the smallest-Dmax statement and what the table holds.
pub fn paragraphs(p: &PartialBalancing) -> Vec<String> {
    let mut out = vec![p.smallest_dmax.clone()];
    if let Some(reason) = &p.skipped {
        out.push(format!("Partial balancing not computed: {reason}."));
        return out;
    }
    let counterweights = if p.budget == 1 {
        "1 counterweight".to_string()
    } else {
        format!("{} counterweights", p.budget)
    };
    out.push(format!(
        "Best partial balancing with at most {counterweights}: for each of the {} sets, the \
         masses and offsets within the case's bounds that leave the least total RMS gravity \
         torque √(Σ RMS²) of {} over {} workspace points (unbalanced: {}). RMS values are \
         actuator forces before the ratio (N·m; N for a slide); Δ is the change against the \
         unbalanced robot (negative = less torque); exact is the balance search's verdict on \
         the set whatever the bounds, for the best set of each size.{}",
        p.sets,
        p.minimised.join(", "),
        p.points,
        rms(p.unbalanced_total),
        if p.designs.len() > TABLE_ROWS {
            format!(
                " The {TABLE_ROWS} best of {} sets are shown; every set is in partial.json and \
                 partial.csv.",
                p.designs.len()
            )
        } else {
            " Every set is also in partial.json and partial.csv.".to_string()
        }
    ));
    out
}

/// The actuators the table has a column for: those with gravity torque, unbalanced or in a
/// design (a vertical pan axis or a last wrist joint never carries any).
pub fn loaded(p: &PartialBalancing) -> Vec<usize> {
    (0..p.actuators.len())
        .filter(|&j| {
            std::iter::once(p.unbalanced_rms.get(j))
                .chain(p.designs.iter().map(|d| d.rms.get(j)))
                .any(|v| v.is_some_and(|v| *v > 0.0))
        })
        .collect()
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    fn element(label: &str, mass: f64, unused: bool) -> PartialElement {
        PartialElement {
            counterweight: Counterweight {
                label: label.into(),
                body: "link".into(),
                mass,
                offset: [0.0, 0.0, -0.4255],
                plane: None,
            },
            unused,
        }
    }

    fn design(rank: usize, elements: Vec<PartialElement>, total: f64) -> PartialDesign {
        PartialDesign {
            rank,
            elements,
            total_rms: total,
            rms: vec![0.0, total],
            exact: None,
        }
    }

    pub(crate) fn sample() -> PartialBalancing {
        PartialBalancing {
            smallest_dmax: "No feasible variant at Dmax 2.".into(),
            skipped: None,
            budget: 2,
            points: 25,
            actuators: vec!["pan".into(), "lift".into()],
            minimised: vec!["pan".into(), "lift".into()],
            unbalanced_rms: vec![0.0, 8.0],
            unbalanced_total: 8.0,
            sets: 3,
            designs: vec![
                design(
                    1,
                    vec![element("m1", 1.0, true), element("m2", 2.0, false)],
                    2.0,
                ),
                design(2, vec![element("m2", 2.0, false)], 2.0),
                design(3, vec![element("m1", 1.0, false)], 6.0),
            ],
        }
    }

    /// The best of each size skips a design with an unused counterweight: rank 1 (m1 idle)
    /// is not the best pair; the best single is rank 2. No pair qualifies.
    #[test]
    fn best_of_each_size_skips_unused_counterweights() {
        assert_eq!(best_of_each_size(&sample()), vec![1]);
    }

    /// 2 against 8 is −75 %; an actuator gravity does not load has no change; a rise has a
    /// plus sign.
    #[test]
    fn changes_by_hand() {
        assert_eq!(change_text(2.0, 8.0).as_deref(), Some("-75.0 %"));
        assert_eq!(change_text(0.0, 0.0), None);
        assert_eq!(change_text(9.0, 8.0).as_deref(), Some("+12.5 %"));
    }
}
