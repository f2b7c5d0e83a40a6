//! A plain-text summary for the terminal (the `run` command's final table on stdout): counts per
//! status, the best variant of each class and the head of the ranking, as aligned columns built
//! from the same tables as the reports.

use std::fmt::Write;

use crate::results::RunResults;
use crate::tables::{self, Cell, Table};

/// Rows of the ranking shown in the summary.
pub const SUMMARY_RANKS: usize = 10;

/// The summary: a few aligned tables, ending with a newline.
pub fn summary(r: &RunResults) -> String {
    let mut s = String::new();
    let m = &r.metadata;
    let total: f64 = m.timings.iter().map(|p| p.seconds).sum();
    let _ = writeln!(
        s,
        "{}: {} variants examined (Dmax = {}) in {} s\n",
        m.case_name,
        r.variants.len(),
        m.dmax,
        crate::format::seconds(total)
    );
    let counts: Vec<String> = r
        .counts
        .iter()
        .filter(|c| c.total > 0)
        .map(|c| format!("{} {}", c.total, c.status.name()))
        .collect();
    let _ = writeln!(s, "{}\n", counts.join(", "));
    let best = tables::best_per_class(r);
    if best.rows.is_empty() {
        s.push_str("No feasible balanced variant.\n");
        return s;
    }
    s.push_str("Best variant of each class (ΔQTR, ΔQIT in % vs unbalanced, negative = reduction; ΔR ≥ 0):\n");
    s.push_str(&aligned(&best));
    if let Some(rec) = r.decision.as_ref().and_then(|d| d.overall.as_ref()) {
        let _ = writeln!(
            s,
            "\nRecommended: {}\n(one per class, and the rule, in report.html)",
            rec.reason
        );
    }
    let mut ranking = tables::ranking(r);
    let shown = ranking.rows.len().min(SUMMARY_RANKS);
    let hidden = ranking.rows.len() - shown;
    ranking.rows.truncate(shown);
    let _ = writeln!(s, "\nRanking (top {shown}):");
    s.push_str(&aligned(&ranking));
    if hidden > 0 {
        let _ = writeln!(s, "… and {hidden} more in ranking.csv / report.html");
    }
    if r.ranked().iter().any(|v| v.optimiser.is_some()) {
        s.push_str(
            "Objective: what the optimiser minimised (RMS*, Eq. 11, or QTR with --minimax), N·m; \
             Gap: (objective − certified lower bound)/objective.\n",
        );
    }
    s
}

/// A table as aligned text columns (numbers right-aligned).
pub fn aligned(t: &Table) -> String {
    let width = |c: &str| c.chars().count();
    let cols = t.header.len();
    let mut w: Vec<usize> = t.header.iter().map(|h| width(h)).collect();
    for row in &t.rows {
        for (c, cell) in row.iter().enumerate() {
            w[c] = w[c].max(width(&cell.text));
        }
    }
    let numeric: Vec<bool> = (0..cols)
        .map(|c| t.rows.iter().any(|r| r[c].numeric))
        .collect();
    let line = |cells: Vec<(&str, bool)>| {
        let parts: Vec<String> = cells
            .iter()
            .enumerate()
            .map(|(c, (text, num))| {
                let pad = " ".repeat(w[c] - width(text));
                if *num {
                    format!("{pad}{text}")
                } else {
                    format!("{text}{pad}")
                }
            })
            .collect();
        format!("  {}\n", parts.join("  ").trim_end())
    };
    let mut s = line(
        t.header
            .iter()
            .enumerate()
            .map(|(c, h)| (h.as_str(), numeric[c]))
            .collect(),
    );
    for row in &t.rows {
        s.push_str(&line(
            row.iter()
                .map(|cell: &Cell| (cell.text.as_str(), cell.numeric))
                .collect(),
        ));
    }
    s
}
