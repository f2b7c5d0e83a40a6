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
        s.push('\n');
        s.push_str(&wrap(&format!("Recommended: {}", rec.reason), WIDTH));
        s.push_str("(one per class, and the rule, in report.html)\n");
    }
    let mut ranking = compact_ranking(r);
    let shown = ranking.rows.len().min(SUMMARY_RANKS);
    let hidden = ranking.rows.len() - shown;
    ranking.rows.truncate(shown);
    let _ = writeln!(s, "\nRanking (top {shown}):");
    s.push_str(&aligned(&ranking));
    if hidden > 0 {
        let _ = writeln!(s, "… and {hidden} more in ranking.csv / report.html");
    }
    if r.ranked().iter().any(|v| v.optimiser.is_some()) {
        s.push_str(&wrap(
            "Mass: added mass; Spring: peak spring force; Gap: (objective − certified lower \
             bound)/objective of the optimiser (RMS*, Eq. 11, or QTR with --minimax); QTR, QIT \
             and the objective in N·m are in ranking.csv and report.html.",
            WIDTH,
        ));
    }
    s
}

/// Columns of the terminal: the summary stays within them.
pub const WIDTH: usize = 120;

/// `text` broken into lines of at most `width` characters at spaces.
pub fn wrap(text: &str, width: usize) -> String {
    let mut out = String::new();
    let mut line = String::new();
    for word in text.split(' ') {
        if !line.is_empty() && line.chars().count() + 1 + word.chars().count() > width {
            out.push_str(&line);
            out.push('\n');
            line.clear();
        }
        if !line.is_empty() {
            line.push(' ');
        }
        line.push_str(word);
    }
    if !line.is_empty() {
        out.push_str(&line);
        out.push('\n');
    }
    out
}

/// The ranking's columns that fit a terminal: rank, name, elements, class, the three
/// indicators, added mass, peak spring force, gap and a short note.
fn compact_ranking(r: &RunResults) -> Table {
    let full = tables::ranking(r);
    let keep = [
        "Rank",
        "Variant",
        "Elements",
        "Class",
        "ΔQTR [%]",
        "ΔQIT [%]",
        "ΔR [%]",
        "Added mass [kg]",
        "Peak spring force [N]",
        "Gap",
        "Note",
    ];
    let short = |h: &str| match h {
        "Added mass [kg]" => "Mass [kg]".to_string(),
        "Peak spring force [N]" => "Spring [N]".to_string(),
        other => other.to_string(),
    };
    let cols: Vec<usize> = keep
        .iter()
        .filter_map(|k| full.header.iter().position(|h| h == k))
        .collect();
    let note = full.header.iter().position(|h| h == "Note");
    Table {
        header: cols.iter().map(|&c| short(&full.header[c])).collect(),
        rows: full
            .rows
            .iter()
            .map(|row| {
                cols.iter()
                    .map(|&c| {
                        let mut cell = row[c].clone();
                        if Some(c) == note {
                            // `m6 idle: really …; label tie-break` → `m6 idle; tie by label`
                            cell.text = cell
                                .text
                                .split("; ")
                                .map(|p| match p.split_once(": really") {
                                    Some((idle, _)) => idle.to_string(),
                                    None if p == "label tie-break" => "tie by label".into(),
                                    None => p.to_string(),
                                })
                                .collect::<Vec<_>>()
                                .join("; ");
                        }
                        cell
                    })
                    .collect()
            })
            .collect(),
        group_starts: full.group_starts.clone(),
        highlighted: full.highlighted.clone(),
    }
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
