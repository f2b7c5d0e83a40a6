//! ranking.csv: one row per feasible variant in rank order, for spreadsheets and scripts.
//! Full precision (shortest round-trip formatting, `1.5e-13` style for tiny values), SI units, empty fields for values the
//! optimiser did not report.

use crate::format::csv_field;
use crate::results::RunResults;

/// Column names, in order.
pub const HEADER: [&str; 23] = [
    "rank",
    "class_rank",
    "name",
    "id",
    "elements",
    "class",
    "qtr_nm",
    "qit_nm",
    "dqtr_percent",
    "dqit_percent",
    "dr_percent",
    "added_mass_kg",
    "added_mass_percent",
    "elements_count",
    "peak_spring_force_n",
    "peak_spring_elongation_m",
    "peak_counterweight_offset_m",
    "objective_nm",
    "gap",
    "iterations",
    "verification_residual",
    "tie_broken_by_label",
    "idle_elements",
];

/// Renders the CSV (header line included).
pub fn render(r: &RunResults) -> String {
    let mut s = HEADER.join(",");
    s.push('\n');
    // Debug formatting is Rust's shortest round-trip form, with an exponent for tiny values.
    let num = |x: Option<f64>| x.map(|v| format!("{v:?}")).unwrap_or_default();
    for v in r.ranked() {
        let o = v.optimiser.clone().unwrap_or_default();
        let e = v.evaluation.as_ref();
        let p = v.practical.as_ref();
        let fields = [
            v.rank.map(|x| x.to_string()).unwrap_or_default(),
            v.class_rank.map(|x| x.to_string()).unwrap_or_default(),
            v.name.clone().unwrap_or_default(),
            v.id.to_string(),
            v.label(),
            v.class.name().to_string(),
            num(e.map(|e| e.qtr)),
            num(e.map(|e| e.qit)),
            num(v.dqtr),
            num(v.dqit),
            num(v.dr),
            num(p.map(|p| p.added_mass)),
            num(p.and_then(|p| p.added_mass_percent)),
            v.elements.len().to_string(),
            num(p.and_then(|p| p.peak_spring_force)),
            num(p.and_then(|p| p.peak_spring_elongation)),
            num(p.and_then(|p| p.peak_counterweight_offset)),
            num(o.objective),
            num(o.gap),
            o.iterations.map(|x| x.to_string()).unwrap_or_default(),
            num(v.verification_residual),
            v.tie_broken_by_label.to_string(),
            // Space-separated labels of the elements that only idle (crate::honest).
            v.idle.join(" "),
        ];
        let line: Vec<String> = fields.iter().map(|f| csv_field(f)).collect();
        s.push_str(&line.join(","));
        s.push('\n');
    }
    s
}
