//! report.md: the report's tables in Markdown (GitHub-flavoured pipe tables), for reading in a
//! terminal, a pull request or a wiki. Charts are in report.html only.

use std::fmt::Write;

use crate::format::escape_md as esc;
use crate::results::RunResults;
use crate::tables::{self, Table};

/// Renders the Markdown report.
pub fn render(r: &RunResults) -> String {
    let m = &r.metadata;
    let mut s = String::new();
    let _ = writeln!(s, "# Static balancing report: {}\n", esc(&m.case_name));
    let _ = writeln!(
        s,
        "{} {} · {} · Dmax = {} · {} variants examined\n",
        esc(&m.tool),
        esc(&m.tool_version),
        esc(&m.date),
        m.dmax,
        r.variants.len()
    );
    for note in &m.notes {
        let _ = writeln!(s, "> {}\n", esc(note));
    }
    let recs = tables::recommendations(r);
    if let (Some(d), false) = (&r.decision, recs.rows.is_empty()) {
        section(&mut s, "Which variant to build", &recs);
        for (scope, reason) in tables::reasons(r) {
            let _ = writeln!(s, "- **{}.** {}", esc(&scope), esc(&reason));
        }
        s.push('\n');
        let _ = writeln!(s, "**Rule.** {}\n", esc(&d.rule));
        let group = tables::equivalent_group(r);
        if group.rows.len() > 1 {
            let _ = writeln!(
                s,
                "### The {} variants equivalent to the best-ranked one\n",
                group.rows.len()
            );
            table(&mut s, &group);
        }
        s.push_str(
            "The Pareto chart (ΔQTR against added mass, ΔR as marker size) is in report.html.\n\n",
        );
    }
    if let Some(p) = &r.partial {
        let _ = writeln!(s, "## Partial balancing (no feasible variant)\n");
        for paragraph in crate::partial::paragraphs(p) {
            let _ = writeln!(s, "{}\n", esc(&paragraph));
        }
        if !p.designs.is_empty() {
            table(&mut s, &crate::partial_view::table(p));
            s.push_str("The chart of the RMS per actuator is in report.html.\n\n");
        }
    }
    section(&mut s, "Summary", &tables::best_per_class(r));
    s.push_str(
        "ΔQTR and ΔQIT are percentage variations with respect to the unbalanced robot \
         (negative = reduction, −100 % best); ΔR weighs joint-reaction increases only (≥ 0, 0 best).\n\n",
    );
    section(&mut s, "Run", &tables::metadata(r));
    section(&mut s, "Timings", &tables::timings(r));
    section(&mut s, "Variants by status", &tables::counts(r));
    s.push_str(
        "Only feasible variants are ranked. Unrealizable and degenerate ones balance only on \
         paper; infeasible ones do not balance.\n\n",
    );
    section(&mut s, "Unbalanced robot", &tables::unbalanced_summary(r));
    table(&mut s, &tables::unbalanced_actuators(r));
    if !r.unbalanced.joints.is_empty() {
        table(&mut s, &tables::unbalanced_joints(r));
    }
    section(&mut s, "Ranking", &tables::ranking(r));
    if let Some(info) = &r.ranking {
        let _ = writeln!(
            s,
            "{} {}.\n",
            esc(&r.ranking_rule().unwrap_or_default()),
            esc(&crate::html::capitalise(&info.tie_break))
        );
        let names = crate::html::recommended_names(r);
        if !names.is_empty() {
            let _ = writeln!(
                s,
                "Names in bold, here and in the tables below: the recommended variants ({}).\n",
                esc(&names)
            );
        }
    }
    s.push_str(
        "Objective: the value the optimiser minimised at the returned parameters (RMS*, Eq. 11, \
         or QTR with --minimax), N·m. Gap: (objective − lower bound)/objective, the lower bound \
         certified by the convex relaxation.\n\n",
    );
    section(&mut s, "Practical figures", &tables::practical(r));
    if let Some(b) = &r.spring_peaks_basis {
        let _ = writeln!(s, "Peak spring force and stretch: {}.\n", esc(b));
    }
    section(
        &mut s,
        "Optimised parameters (Table 1)",
        &tables::parameters(r),
    );
    if let Some(p) = r.path.as_ref().filter(|p| !p.table.is_empty()) {
        section(
            &mut s,
            &format!("Path simulation: {}", esc(&p.name)),
            &tables::path_table(p),
        );
    }
    let ranked = r.ranked();
    if !ranked.is_empty() {
        section(
            &mut s,
            "Joint reactions of the ranked variants",
            &tables::joint_reactions(r),
        );
    }
    let others = tables::not_ranked(r);
    if !others.rows.is_empty() {
        let _ = writeln!(
            s,
            "## Variants not ranked\n\n{}.\n",
            esc(&crate::html::not_ranked_summary(r))
        );
        table(&mut s, &others);
    }
    if !ranked.is_empty() {
        s.push_str("## Appendix: balance relations\n\n<details><summary>Balance relations and free directions of the ranked variants</summary>\n\n");
        for v in ranked {
            let _ = writeln!(s, "### {} — {}\n", esc(&v.display_name()), v.class.name());
            for line in tables::relations(v) {
                let _ = writeln!(s, "- `{}`", line.replace('`', "'"));
            }
            if let Some(res) = v.verification_residual {
                let _ = writeln!(s, "- verification residual: {res:.2e}");
            }
            s.push('\n');
        }
        s.push_str("</details>\n");
    }
    s
}

fn section(s: &mut String, title: &str, t: &Table) {
    let _ = writeln!(s, "## {title}\n");
    if t.rows.is_empty() {
        s.push_str("(none)\n\n");
    } else {
        table(s, t);
    }
}

/// A pipe table; numeric columns right-aligned.
fn table(s: &mut String, t: &Table) {
    let numeric: Vec<bool> = (0..t.header.len())
        .map(|c| t.rows.iter().any(|r| r[c].numeric))
        .collect();
    s.push('|');
    for h in &t.header {
        let _ = write!(s, " {} |", esc(h));
    }
    s.push_str("\n|");
    for &n in &numeric {
        s.push_str(if n { " ---: |" } else { " --- |" });
    }
    s.push('\n');
    // Markdown has no row colour: a recommended variant's name is in bold (its "Variant"
    // cell, or the row's first), which keeps the numbers plain for anyone reading them back.
    let name_column = t.header.iter().position(|h| h == "Variant").unwrap_or(0);
    for (k, row) in t.rows.iter().enumerate() {
        let rec = t.highlighted.get(k).copied().unwrap_or(false);
        s.push('|');
        for (column, c) in row.iter().enumerate() {
            if rec && column == name_column && !c.text.is_empty() {
                let _ = write!(s, " **{}** |", esc(&c.text));
            } else {
                let _ = write!(s, " {} |", esc(&c.text));
            }
        }
        s.push('\n');
    }
    s.push('\n');
}
