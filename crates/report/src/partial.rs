//! The partial-balancing section of the reports: what `run` found when no variant is feasible —
//! the smallest Dmax at which a variant balances, and the best counterweights within the study's
//! Dmax that leave the least RMS gravity torque (the `partial.json` written beside
//! `results.json`). Plain data, filled by the caller: this crate knows nothing of the search or
//! the mechanics, it renders numbers. The section is in report.html and report.md only when
//! [`RunResults::partial`](crate::RunResults) is set, which `run` does only when nothing is
//! feasible.

use serde::{Deserialize, Serialize};

use crate::format::fixed;
use crate::svg::{BarChart, PALETTE, bar_chart_in};
use crate::tables::{Cell, Table};

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

/// One counterweight of a design.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PartialElement {
    pub label: String,
    /// The body it is fixed to.
    pub body: String,
    /// kg.
    pub mass: f64,
    /// Centre of mass in the body frame, m.
    pub offset: [f64; 3],
    /// Left at 0 kg by the best design (the smaller set does as well).
    pub unused: bool,
}

impl PartialDesign {
    /// `m2 + m3`.
    pub fn set(&self) -> String {
        self.elements
            .iter()
            .map(|e| e.label.as_str())
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
fn change_text(value: f64, reference: f64) -> Option<String> {
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
        return format!("{} on {}: unused (0 kg)", e.label, e.body);
    }
    let r = e.offset.iter().map(|v| v * v).sum::<f64>().sqrt();
    format!(
        "{} on {}: {} kg at ({}, {}, {}) mm (|r| = {} mm)",
        e.label,
        e.body,
        fixed(e.mass, 3),
        millimetres(e.offset[0]),
        millimetres(e.offset[1]),
        millimetres(e.offset[2]),
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

/// The designs table: the unbalanced robot first (its RMS per actuator), then the
/// [`TABLE_ROWS`] best sets (the change of each actuator's RMS).
pub fn table(p: &PartialBalancing) -> Table {
    let columns = loaded(p);
    let mut header = vec![
        "Rank".to_string(),
        "Set".to_string(),
        "Counterweights (mass at the centre of mass, body frame)".to_string(),
        "Total RMS [N·m]".to_string(),
        "Δ total".to_string(),
    ];
    header.extend(columns.iter().map(|&j| format!("Δ {}", p.actuators[j])));
    header.push("Exact".to_string());
    let mut t = Table {
        header,
        rows: Vec::new(),
        group_starts: Vec::new(),
        highlighted: Vec::new(),
    };
    let mut unbalanced = vec![
        Cell::text("—"),
        Cell::text("none (unbalanced)"),
        Cell::empty(),
        Cell::num(rms(p.unbalanced_total)),
        Cell::empty(),
    ];
    unbalanced.extend(
        columns
            .iter()
            .map(|&j| Cell::num(format!("{} N·m", rms(p.unbalanced_rms[j])))),
    );
    unbalanced.push(Cell::empty());
    t.rows.push(unbalanced);
    t.group_starts.push(false);
    t.highlighted.push(false);
    let best = best_of_each_size(p);
    for (i, d) in p.designs.iter().enumerate().take(TABLE_ROWS) {
        let mut row = vec![
            Cell::num(d.rank.to_string()),
            Cell::text(d.set()),
            Cell::prose(
                d.elements
                    .iter()
                    .map(element_text)
                    .collect::<Vec<_>>()
                    .join("; "),
            ),
            Cell::num(rms(d.total_rms)),
            Cell::num(change_text(d.total_rms, p.unbalanced_total).unwrap_or_default()),
        ];
        for &j in &columns {
            let v = d.rms[j];
            // An actuator the unbalanced robot does not load has no change: its RMS instead.
            row.push(Cell::num(
                change_text(v, p.unbalanced_rms[j]).unwrap_or_else(|| format!("{} N·m", rms(v))),
            ));
        }
        row.push(Cell::text(d.exact.clone().unwrap_or_default()));
        t.rows.push(row);
        t.group_starts.push(i == 0);
        // The best design of each size stands out, as the recommended variants do elsewhere.
        t.highlighted.push(best.contains(&i));
    }
    t
}

/// The bar chart: per actuator, the RMS gravity torque of the unbalanced robot and of the best
/// design of each size (`None` without designs).
pub fn chart(p: &PartialBalancing) -> Option<String> {
    let best = best_of_each_size(p);
    if best.is_empty() {
        return None;
    }
    let mut series = vec![("unbalanced".to_string(), PALETTE[0].to_string())];
    let mut values: Vec<Vec<f64>> = p.unbalanced_rms.iter().map(|v| vec![*v]).collect();
    for (k, &i) in best.iter().enumerate() {
        let d = &p.designs[i];
        let n = d.elements.len();
        series.push((
            format!(
                "{} (best of {n} counterweight{}, rank {})",
                d.set(),
                if n == 1 { "" } else { "s" },
                d.rank
            ),
            PALETTE[1 + k % (PALETTE.len() - 1)].to_string(),
        ));
        for (a, v) in values.iter_mut().zip(&d.rms) {
            a.push(*v);
        }
    }
    let chart = BarChart {
        title: "RMS gravity torque per actuator: unbalanced and the best design of each size"
            .into(),
        y_label: "RMS gravity torque [N·m]".into(),
        categories: p
            .actuators
            .iter()
            .zip(&p.unbalanced_rms)
            .map(|(a, u)| (a.clone(), format!("unbalanced {}", rms(*u))))
            .collect(),
        series,
        values,
        clip: None,
        min_width: 720.0,
        height: 340.0,
    };
    Some(bar_chart_in(&chart, "N·m", rms))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn element(label: &str, mass: f64, unused: bool) -> PartialElement {
        PartialElement {
            label: label.into(),
            body: "link".into(),
            mass,
            offset: [0.0, 0.0, -0.4255],
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

    fn sample() -> PartialBalancing {
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

    /// The table: the unbalanced row (RMS per loaded actuator), then the designs in rank order
    /// with their numbers; the unloaded actuator `pan` has no column.
    #[test]
    fn table_rows_carry_the_designs_numbers() {
        let t = table(&sample());
        assert_eq!(t.header[5], "Δ lift");
        assert_eq!(t.header.len(), 7);
        assert_eq!(t.rows.len(), 4);
        assert_eq!(t.rows[0][3].text, "8.000");
        assert_eq!(t.rows[0][5].text, "8.000 N·m");
        assert_eq!(t.rows[2][1].text, "m2");
        assert_eq!(t.rows[2][3].text, "2.000");
        assert_eq!(t.rows[2][4].text, "-75.0 %");
        assert_eq!(t.rows[2][5].text, "-75.0 %");
        assert_eq!(
            t.rows[2][2].text,
            "m2 on link: 2.000 kg at (0.0, 0.0, -425.5) mm (|r| = 425.5 mm)"
        );
        assert!(t.rows[1][2].text.starts_with("m1 on link: unused (0 kg)"));
        assert_eq!(t.highlighted, vec![false, false, true, false]);
    }

    /// The chart: one group per actuator, the unbalanced bar and one per best design, values in
    /// N·m in the tooltips.
    #[test]
    fn chart_has_a_bar_per_actuator_and_series() {
        let svg = chart(&sample()).unwrap();
        assert!(svg.contains("lift unbalanced: 8.000 N·m"), "{svg}");
        assert!(svg.contains("lift m2 (best of 1 counterweight, rank 2): 2.000 N·m"));
        let mut without = sample();
        without.designs.clear();
        assert!(chart(&without).is_none());
    }
}
