//! report.html: one self-contained page (inline CSS, SVG and one inline script that sorts and
//! filters the ranking table; no fonts, links or network) that opens offline. It is written as XHTML-compatible markup (every element closed, attributes
//! quoted, only XML entities) so that it parses as XML, which the tests check.

use std::fmt::Write;

use crate::charts::{self, Chart, Section};
use crate::format::{escape_html as esc, value};
use crate::partial::{self, PartialBalancing};
use crate::results::{RunResults, Status};
use crate::tables::{self, Table};

const CSS: &str = r#"
:root { --ink: #1d2327; --muted: #5f6b73; --line: #d9dee2; --band: #f4f6f8; --accent: #0072B2; }
* { box-sizing: border-box; }
body { margin: 0; background: #ffffff; color: var(--ink);
  font: 14px/1.45 system-ui, -apple-system, "Segoe UI", Roboto, "Helvetica Neue", Arial, sans-serif; }
main { max-width: 1240px; margin: 0 auto; padding: 24px 28px 64px; }
header { border-bottom: 3px solid var(--accent); padding-bottom: 12px; margin-bottom: 8px; }
h1 { font-size: 26px; margin: 0 0 4px; }
h2 { font-size: 19px; margin: 34px 0 10px; padding-bottom: 4px; border-bottom: 1px solid var(--line); }
h3 { font-size: 15px; margin: 20px 0 6px; }
p.sub, p.note, .muted { color: var(--muted); }
p.note { font-size: 13px; max-width: 900px; }
table { border-collapse: collapse; margin: 6px 0 14px; font-variant-numeric: tabular-nums; }
th, td { padding: 4px 10px; border-bottom: 1px solid var(--line); text-align: left; vertical-align: top; }
td { white-space: nowrap; }
td.p { white-space: normal; min-width: 220px; }
table.partial td.p { min-width: 340px; }
th { background: var(--band); font-weight: 600; vertical-align: bottom; }
.scroll { overflow-x: auto; max-width: 100%; }
.scroll.tall { max-height: 70vh; overflow-y: auto; border: 1px solid var(--line); }
.scroll.tall thead th { position: sticky; top: 0; z-index: 1; }
table.sortable th[data-sort="asc"]::after { content: " ▲"; }
table.sortable th[data-sort="desc"]::after { content: " ▼"; }
.filter { margin: 8px 0 6px; font-size: 13px; }
.filter label { margin-right: 12px; }
.filter input, .filter select { font: inherit; padding: 1px 4px; }
td.n, th.n { text-align: right; }
td.n { white-space: nowrap; }
tr.g td { border-top: 2px solid #b9c2c9; }
tr.rec td { background: #fff4cc; }
tr.rec td:first-child { box-shadow: inset 4px 0 0 #d99a00; }
table.kv th { display: none; }
table.kv td:first-child { color: var(--muted); padding-right: 18px; }
.cols { display: flex; flex-wrap: wrap; gap: 8px 40px; align-items: flex-start; }
.charts { display: flex; flex-wrap: wrap; gap: 18px; }
.charts figure { margin: 0; border: 1px solid var(--line); border-radius: 4px; padding: 4px; }
svg.chart { display: block; max-width: 100%; height: auto; }
ul.why { margin: 4px 0 12px; padding-left: 20px; max-width: 980px; }
ul.why li { margin: 3px 0; }
ul.rel { margin: 4px 0 10px; padding-left: 20px; }
ul.rel code { font: 12.5px/1.5 ui-monospace, SFMono-Regular, Menlo, Consolas, monospace; }
details { margin: 8px 0; }
summary { cursor: pointer; font-weight: 600; }
.badge { display: inline-block; padding: 0 6px; border-radius: 3px; font-size: 12px; color: #ffffff; }
footer { margin-top: 40px; color: var(--muted); font-size: 12px; }
"#;

/// Renders the whole report.
pub fn render(r: &RunResults) -> String {
    let charts = charts::all(r);
    let m = &r.metadata;
    let mut h = String::new();
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html xmlns=\"http://www.w3.org/1999/xhtml\" lang=\"en\"><head><meta charset=\"utf-8\"/><meta name=\"viewport\" content=\"width=device-width, initial-scale=1\"/><title>{} — counterpoise balancing report</title><style>{CSS}</style></head><body><main>",
        esc(&m.case_name)
    );
    let _ = write!(
        h,
        "<header><h1>Static balancing report: {}</h1><p class=\"sub\">{} {} · {} · D<sub>max</sub> = {} · {} variants examined</p></header>",
        esc(&m.case_name),
        esc(&m.tool),
        esc(&m.tool_version),
        esc(&m.date),
        m.dmax,
        r.variants.len()
    );
    for note in &m.notes {
        let _ = write!(h, "<p class=\"note\">{}</p>", esc(note));
    }

    push_decision(&mut h, r, &charts);
    if tables::recommendations(r).rows.is_empty() && !r.schematics.is_empty() {
        h.push_str("<h2>The mechanism</h2><p class=\"note\">No variant to recommend; the mechanism as the case describes it.</p>");
        push_schematics(&mut h, r, "");
    }

    if let Some(p) = &r.partial {
        push_partial(&mut h, p);
    }

    h.push_str("<h2>Summary</h2>");
    let best = tables::best_per_class(r);
    if best.rows.is_empty() {
        h.push_str("<p>No feasible balanced variant was found.</p>");
    } else {
        h.push_str("<h3>Best-ranked variant of each class</h3>");
        h.push_str(&table(&best, ""));
        h.push_str(&sign_note(r));
    }
    h.push_str("<div class=\"cols\"><div><h3>Run</h3>");
    h.push_str(&table(&tables::metadata(r), "kv"));
    h.push_str("</div><div><h3>Timings</h3>");
    h.push_str(&table(&tables::timings(r), ""));
    h.push_str("</div></div><h3>Variants by status</h3>");
    h.push_str(&table(&tables::counts(r), ""));
    h.push_str("<p class=\"note\">Only <i>feasible</i> variants are ranked. Balanced ones are feasible, discarded or undecided; unrealizable and degenerate ones balance only on paper (no physical elements, or an element that can only idle); infeasible ones do not balance.</p>");

    h.push_str("<h2>Unbalanced robot (Phase 1)</h2><div class=\"cols\"><div>");
    h.push_str(&table(&tables::unbalanced_summary(r), ""));
    h.push_str("</div><div>");
    h.push_str(&table(&tables::unbalanced_actuators(r), ""));
    h.push_str("</div><div>");
    if r.unbalanced.joints.is_empty() {
        h.push_str(
            "<p class=\"muted\">Joint reactions were not computed; ΔR is 0 for every variant.</p>",
        );
    } else {
        h.push_str(&table(&tables::unbalanced_joints(r), ""));
    }
    h.push_str("</div></div>");
    if r.unbalanced.reactions_minimum_norm {
        h.push_str("<p class=\"note\">The mechanism is overconstrained: joint reactions are the minimum-norm solution.</p>");
    }
    h.push_str("<p class=\"note\">Tasks are moves between task-grid points, written from→to (grid indices). CRT/CPT: the task with the largest RMS / peak motor torque of each actuator.</p>");

    h.push_str("<h2>Ranking (Phase 3)</h2>");
    let ranking = tables::ranking(r);
    if ranking.rows.is_empty() {
        h.push_str("<p>No feasible variant to rank.</p>");
    } else {
        h.push_str(&sortable(&ranking, "ranking", r));
        h.push_str(&ranking_note(r));
        h.push_str(OBJECTIVE_NOTE);
        push_charts(&mut h, &charts, Section::Ranking);
        let (detail, all) = detail_variants(r);
        let of = if all {
            String::new()
        } else {
            format!(
                " of the recommended and best-ranked variants ({} of {}; every variant in report.md)",
                detail.len(),
                r.ranked().len()
            )
        };
        let _ = write!(h, "<h3>Practical figures{}</h3>", esc(&of));
        h.push_str(&table(&tables::practical_of(r, &detail), ""));
        h.push_str(&practical_note(r));
        let _ = write!(h, "<h3>Optimised parameters (Table 1){}</h3>", esc(&of));
        h.push_str(&table(&tables::parameters_of(r, &detail), ""));
        h.push_str("<p class=\"note\">Spring: stiffness K, anchor a on the first body and b on the second, as distance and angle in the element's plane (body frames). Counterweight: mass m, offset r and angle φ of its centre of mass in the body frame. Angles in radians, degrees in brackets. <b>(min)</b>, <b>(max)</b>: the value is on that bound of the optimisation (the bound, not the mechanics, decided it); <b>(idle)</b>: the element exerts less than 10⁻³ of the moving mass's weight and does nothing a model can tell (the variant is really the smaller one named in the ranking's Note).</p>");
        let joints = tables::joint_reactions_of(r, &detail);
        if !joints.rows.is_empty() {
            let _ = write!(
                h,
                "<details><summary>Joint reactions (ΔR breakdown){}</summary>",
                esc(&of)
            );
            h.push_str(&table(&joints, ""));
            h.push_str("<p class=\"note\">ΔF_j, ΔM_j: variation of the peak joint force and moment against the unbalanced robot; γ: the joint's share of the unbalanced reactions (Eqs. 20–21); the ΔR term adds the weighted increases only.</p></details>");
        }
    }

    if r.torque_charts.is_empty() {
        h.push_str("<h2>Torque curves</h2><p class=\"muted\">No torque curves were recorded.</p>");
    } else {
        h.push_str("<h2>Motor torques on the critical tasks</h2><p class=\"note\">Unbalanced robot (dashed grey), the best-ranked variant of each class and, where different, the recommended ones (named “recommended”): blue circles counterweights only, green squares springs only, orange triangles hybrid; curves of one class and coinciding curves differ by dash pattern.</p>");
        push_charts(&mut h, &charts, Section::Torque);
    }

    if let Some(p) = &r.path {
        let _ = write!(h, "<h2>Path simulation: {}</h2>", esc(&p.name));
        if let Some(d) = &p.description {
            let _ = write!(h, "<p class=\"note\">{}</p>", esc(d));
        }
        if !p.table.is_empty() {
            h.push_str("<h3>Motor torques along the path (Table 2)</h3>");
            h.push_str(&table(&tables::path_table(p), ""));
        }
        if p.static_run.is_some() {
            h.push_str("<h3>Static torques (Fig. 9)</h3>");
            push_charts(&mut h, &charts, Section::PathStatic);
        }
        if p.dynamic_run.is_some() {
            h.push_str("<h3>Dynamic torques (Fig. 10)</h3>");
            push_charts(&mut h, &charts, Section::PathDynamic);
        }
    }

    let mut others = tables::not_ranked(r);
    if !others.rows.is_empty() {
        let _ = write!(
            h,
            "<h2>Variants not ranked</h2><details><summary>{} (reasons)</summary>",
            esc(&not_ranked_summary(r))
        );
        let total = others.rows.len();
        if total > NOT_RANKED_ROWS {
            others.rows.truncate(NOT_RANKED_ROWS);
            others.group_starts.truncate(NOT_RANKED_ROWS);
            others.highlighted.truncate(NOT_RANKED_ROWS);
        }
        h.push_str(&table(&others, ""));
        if total > NOT_RANKED_ROWS {
            let _ = write!(
                h,
                "<p class=\"note\">The first {NOT_RANKED_ROWS} of {total}, in enumeration order; all of them, with their reasons, in report.md and results.json.</p>"
            );
        }
        h.push_str("</details>");
    }

    let (ranked, all) = detail_variants(r);
    if !ranked.is_empty() {
        let _ = write!(
            h,
            "<h2>Appendix</h2><details><summary>Balance relations and free directions of {}</summary>",
            if all {
                format!("the {} ranked variants", ranked.len())
            } else {
                format!(
                    "the recommended and best-ranked variants ({} of {}; every variant in report.md)",
                    ranked.len(),
                    r.ranked().len()
                )
            }
        );
        h.push_str("<p class=\"note\">What exact balance imposes on each ranked variant's lifted parameters (m, m·r, K, K·a, K·b, K·a·bᵀ), the freedom left inside the balanced family, and the verification of the optimised parameters (relative spread of the total potential energy at random configurations).</p>");
        for v in &ranked {
            let _ = write!(
                h,
                "<h3>{} <span class=\"badge\" style=\"background:{}\">{}</span></h3>",
                esc(&v.display_name()),
                charts::class_color(Some(v.class)),
                esc(v.class.name())
            );
            let lines = tables::relations(v);
            if lines.is_empty() {
                h.push_str("<p class=\"muted\">No relations recorded.</p>");
            } else {
                h.push_str("<ul class=\"rel\">");
                for l in lines {
                    let _ = write!(h, "<li><code>{}</code></li>", esc(&l));
                }
                h.push_str("</ul>");
            }
            if let Some(res) = v.verification_residual {
                let _ = write!(
                    h,
                    "<p class=\"muted\">Verification residual: {}</p>",
                    esc(&value(res))
                );
            }
        }
        h.push_str("</details>");
    }

    let _ = write!(
        h,
        "<footer>Generated by {} {} from results.json (schema {}). Method: Martini, Troncossi &amp; Rivola (2019), Eqs. 1–3 and 15–21.</footer></main></body></html>",
        esc(&m.tool),
        esc(&m.tool_version),
        r.schema_version
    );
    h.push('\n');
    h
}

/// Rows of the "not ranked" table the page shows (all of them are in report.md).
pub const NOT_RANKED_ROWS: usize = 50;
/// Rows of the equivalent group the page lists (its summary covers all).
pub const EQUIVALENT_ROWS: usize = 10;
/// Up to this many ranked variants, the per-variant tables (Table 1, the ΔR breakdown, the
/// balance relations) list every one; above it, the recommended and best-ranked ones (the
/// Dmax 3 palletizer page was 5.4 MB with all 788, 3.6 MB of it these tables).
pub const DETAIL_ALL: usize = 60;

/// The variants the per-variant tables list, in rank order, and whether that is all of them.
fn detail_variants(r: &RunResults) -> (Vec<&crate::results::VariantRecord>, bool) {
    let ranked = r.ranked();
    if ranked.len() <= DETAIL_ALL {
        return (ranked, true);
    }
    let mut ids: Vec<usize> = tables::design_variants(r).iter().map(|v| v.id).collect();
    ids.extend(r.shown_variants().iter().map(|v| v.id));
    (
        ranked.into_iter().filter(|v| ids.contains(&v.id)).collect(),
        false,
    )
}

/// The ranking as a table the reader can sort (click a header) and filter (class, elements,
/// ΔQTR) in the browser: plain JavaScript in the page, no network; without scripts it is the
/// same table in rank order. Numbers are right-aligned by column (one CSS rule per number
/// column rather than a class on each of thousands of cells).
fn sortable(t: &Table, id: &str, r: &RunResults) -> String {
    let mut s = String::new();
    let numeric: Vec<usize> = (0..t.header.len())
        .filter(|&c| t.rows.iter().any(|row| row[c].numeric))
        .collect();
    let rules: Vec<String> = numeric
        .iter()
        .map(|c| format!("#{id} td:nth-child({})", c + 1))
        .collect();
    let _ = write!(
        s,
        "<style>{} {{ text-align: right; }}</style>",
        rules.join(", ")
    );
    let classes: Vec<&str> = crate::ranking::Class::ALL
        .iter()
        .filter(|c| r.ranked().iter().any(|v| v.class == **c))
        .map(|c| c.name())
        .collect();
    let _ = write!(
        s,
        "<div class=\"filter\" id=\"{id}-filter\"><label>Class <select data-f=\"class\"><option value=\"\">all</option>{}</select></label> <label>Elements include <input data-f=\"elements\" size=\"14\" placeholder=\"e.g. K43 m4\"/></label> <label>ΔQTR ≤ <input data-f=\"dqtr\" size=\"7\" placeholder=\"e.g. -53.5\"/> %</label> <span class=\"muted\" data-f=\"count\"></span> <span class=\"muted\">· click a header to sort</span></div>",
        classes
            .iter()
            .map(|c| format!("<option>{c}</option>"))
            .collect::<String>()
    );
    let _ = write!(
        s,
        "<div class=\"scroll tall\"><table id=\"{id}\" class=\"sortable\"><thead><tr>"
    );
    for (c, head) in t.header.iter().enumerate() {
        if numeric.contains(&c) {
            let _ = write!(s, "<th class=\"n\">{}</th>", esc(head));
        } else {
            let _ = write!(s, "<th>{}</th>", esc(head));
        }
    }
    s.push_str("</tr></thead><tbody>");
    for (k, row) in t.rows.iter().enumerate() {
        s.push_str(if t.highlighted.get(k).copied().unwrap_or(false) {
            "<tr class=\"rec\">"
        } else {
            "<tr>"
        });
        for cell in row {
            let _ = write!(s, "<td>{}</td>", esc(&cell.text));
        }
        s.push_str("</tr>");
    }
    s.push_str("</tbody></table></div>");
    let _ = write!(
        s,
        "<script>//<![CDATA[\n{}\n//]]></script>",
        SORT_JS.replace("@ID@", id)
    );
    s
}

/// The sorting and filtering of [`sortable`] (ES5, no library).
const SORT_JS: &str = r#"(function () {
  var t = document.getElementById('@ID@'), box = document.getElementById('@ID@-filter');
  if (!t || !box) return;
  var body = t.tBodies[0], rows = Array.prototype.slice.call(body.rows), head = t.tHead.rows[0].cells;
  function col(name) { for (var i = 0; i < head.length; i++) if (head[i].textContent === name) return i; return -1; }
  var ci = col('Class'), ei = col('Elements'), qi = col('ΔQTR [%]');
  function num(s) { var v = parseFloat(s.replace('−', '-')); return isNaN(v) ? Infinity : v; }
  function field(f) { return box.querySelector('[data-f="' + f + '"]'); }
  Array.prototype.forEach.call(head, function (h, i) {
    h.style.cursor = 'pointer'; h.title = 'sort by this column';
    h.addEventListener('click', function () {
      var asc = h.getAttribute('data-sort') !== 'asc', numeric = h.className === 'n';
      Array.prototype.forEach.call(head, function (x) { x.removeAttribute('data-sort'); });
      h.setAttribute('data-sort', asc ? 'asc' : 'desc');
      rows.sort(function (x, y) {
        var a = x.cells[i].textContent, b = y.cells[i].textContent;
        var d = numeric ? num(a) - num(b) : a.localeCompare(b);
        if (d !== d) d = 0;
        return asc ? d : -d;
      });
      rows.forEach(function (r) { body.appendChild(r); });
    });
  });
  function filter() {
    var c = field('class').value, words = field('elements').value.trim().split(/[\s+]+/).filter(Boolean);
    var q = parseFloat(field('dqtr').value.replace('−', '-')), shown = 0;
    rows.forEach(function (r) {
      var el = ' ' + r.cells[ei].textContent.split(' + ').join(' ') + ' ';
      var ok = (!c || r.cells[ci].textContent === c) &&
        words.every(function (w) { return el.indexOf(' ' + w + ' ') >= 0; }) &&
        (isNaN(q) || num(r.cells[qi].textContent) <= q);
      r.style.display = ok ? '' : 'none';
      if (ok) shown++;
    });
    field('count').textContent = shown + ' of ' + rows.length + ' shown';
  }
  ['class', 'elements', 'dqtr'].forEach(function (f) { field(f).addEventListener('input', filter); });
  filter();
})();"#;

/// What the optimiser's two columns mean.
pub const OBJECTIVE_NOTE: &str = "<p class=\"note\"><b>Objective</b>: the value the optimiser minimised, at the returned parameters, N·m: RMS* (paper Eq. 11, the energy estimate of the motor torques over the critical tasks) or, with <code>--minimax</code>, QTR. <b>Gap</b>: (objective − lower bound) / objective, where the lower bound is certified by the convex relaxation: no parameters within the bounds can improve the objective by more than this fraction (1.0e-3 = 0.1 %).</p>";

/// The decision section: recommendations, the rule, the Pareto chart and the equivalent group.
fn push_decision(h: &mut String, r: &RunResults, charts: &[Chart]) {
    let Some(d) = &r.decision else { return };
    let recs = tables::recommendations(r);
    if recs.rows.is_empty() {
        return;
    }
    h.push_str("<h2>Which variant to build</h2>");
    h.push_str(&table(&recs, ""));
    h.push_str("<ul class=\"why\">");
    for (scope, reason) in tables::reasons(r) {
        let _ = write!(h, "<li><b>{}.</b> {}</li>", esc(&scope), esc(&reason));
    }
    h.push_str("</ul>");
    push_schematics(h, r, "What they look like");
    if let Some(e) = &r.energy {
        h.push_str("<h3>The proof: potential energy</h3>");
        push_charts(h, charts, Section::Energy);
        let _ = write!(
            h,
            "<p class=\"note\">{} A statically balanced variant keeps its potential energy constant in every pose, so its line is flat; the unbalanced mechanism's energy changes by what its motors must supply against gravity. The motor torques of the same variants follow below (critical tasks, and the path simulation).</p>",
            esc(e.note.as_deref().unwrap_or(""))
        );
    }
    let specs = tables::spring_specs(r);
    if !specs.rows.is_empty() {
        h.push_str("<h3>Spring specifications</h3>");
        h.push_str(&table(&specs, ""));
        let _ = write!(
            h,
            "<p class=\"note\">Each spring has zero free length in the model (force K·L at anchor distance L). Length: the shortest and longest anchor distance, {}. <b>Cable and pulley</b>: an extension spring of rate K beyond a pulley at anchor b, the cable from anchor a over the pulley, so the spring extends by the anchor distance; the pulley's axle carries up to twice the peak force. <b>Pre-tensioned</b>: an extension spring of body length L₀ coiled with initial tension K·L₀ pulls K·L for every L ≥ L₀; L₀ is the shortest length or a quarter of the longest, whichever is smaller (initial tension assumed achievable up to a quarter of the peak force), and “no room” means the anchors come within 5 % of the longest length of each other. Wire: the least mass of spring steel that stores ½·K·L_max² ({} J/kg at 700 MPa working shear stress, Wahl factor 1.2). A first sizing; the assumptions are in the README.</p>",
            esc(r
                .spring_peaks_basis
                .as_deref()
                .unwrap_or("over the configurations checked")),
            crate::format::fixed(crate::springspec::WIRE_ENERGY_PER_KG, 0)
        );
    }
    let _ = write!(h, "<p class=\"note\"><b>Rule.</b> {}</p>", esc(&d.rule));
    h.push_str(&practical_note(r));
    push_charts(h, charts, Section::Decision);
    let mut group = tables::equivalent_group(r);
    let size = group.rows.len();
    if size > 1 {
        let _ = write!(
            h,
            "<h3>The {size} variants equivalent to the best-ranked one</h3><p>{}</p>",
            esc(&tables::equivalent_summary(r))
        );
        if size > EQUIVALENT_ROWS {
            let keep: Vec<bool> = group
                .rows
                .iter()
                .enumerate()
                .map(|(k, row)| {
                    k < EQUIVALENT_ROWS || row.last().is_some_and(|c| c.text == "recommended")
                })
                .collect();
            fn pick<T>(v: Vec<T>, keep: &[bool]) -> Vec<T> {
                v.into_iter()
                    .zip(keep)
                    .filter(|(_, k)| **k)
                    .map(|(x, _)| x)
                    .collect()
            }
            group.rows = pick(std::mem::take(&mut group.rows), &keep);
            group.group_starts = pick(std::mem::take(&mut group.group_starts), &keep);
            group.highlighted = pick(std::mem::take(&mut group.highlighted), &keep);
            let _ = write!(
                h,
                "<p class=\"note\">The first {EQUIVALENT_ROWS} in rank order{}; the whole group is the filter “ΔQTR ≤” of the ranking table below, and is listed in report.md.</p>",
                if keep.iter().filter(|k| **k).count() > EQUIVALENT_ROWS {
                    ", and the recommended one"
                } else {
                    ""
                }
            );
        }
        h.push_str(&table(&group, ""));
    }
}

/// The drawings of the recommended variants (and of those `report --draw` named).
fn push_schematics(h: &mut String, r: &RunResults, heading: &str) {
    if r.schematics.is_empty() {
        return;
    }
    if !heading.is_empty() {
        let _ = write!(h, "<h3>{}</h3>", esc(heading));
    }
    h.push_str("<div class=\"charts\">");
    for s in &r.schematics {
        let v = s.variant.and_then(|id| r.variant(id));
        if s.variant.is_some() && v.is_none() {
            continue;
        }
        let _ = write!(h, "<figure>{}</figure>", crate::schematic_svg::svg(r, v, s));
    }
    h.push_str("</div><p class=\"note\">Bodies (grey bars from the joint each hangs from to its other joints and its centre of mass, a dot), joints (open circles, hatched where on the base), counterweights (blue discs at their centre of mass, area growing with the mass: the volume of a disc of the same material), springs (green zig-zags between their anchors, dashed to the joint of the body each anchor is on). Drawn from the model's kinematics, orthographic, in the vertical plane the mechanism spreads in most; up is against gravity.</p>");
}

/// Where the practical figures come from.
fn practical_note(r: &RunResults) -> String {
    let mass = r
        .moving_mass
        .map(|m| {
            format!(
                " Shares are of the moving mass, {} (every body).",
                crate::format::mass(m)
            )
        })
        .unwrap_or_default();
    let basis = r
        .spring_peaks_basis
        .as_ref()
        .map(|b| format!(" Peak spring force and stretch: {b}."))
        .unwrap_or_default();
    format!(
        "<p class=\"note\">Added mass: the counterweights' total (springs are massless). Parts: elements to mount. Stretch: the spring's anchor distance (zero free length), force = K·stretch. Offset: a counterweight's centre-of-mass distance from its body origin.{}{}</p>",
        esc(&mass),
        esc(&basis)
    )
}

/// `202 not ranked: 23 discarded (…), 146 unrealizable (…), …`.
pub fn not_ranked_summary(r: &RunResults) -> String {
    let parts: Vec<String> = r
        .counts
        .iter()
        .filter(|c| c.total > 0 && !matches!(c.status, Status::Feasible | Status::Infeasible))
        .map(|c| format!("{} {} ({})", c.total, c.status.name(), c.status.meaning()))
        .collect();
    let total: usize = r
        .counts
        .iter()
        .filter(|c| !matches!(c.status, Status::Feasible | Status::Infeasible))
        .map(|c| c.total)
        .sum();
    format!("{total} variants not ranked: {}", parts.join("; "))
}

fn sign_note(r: &RunResults) -> String {
    let _ = r;
    "<p class=\"note\">ΔQTR and ΔQIT are percentage variations with respect to the unbalanced robot (Eqs. 15–16): negative means a reduction, −100 % is the best possible. ΔR (Eqs. 17–21) weighs the increases of the joint reactions only, so it is never negative; 0 is best.</p>".to_string()
}

fn ranking_note(r: &RunResults) -> String {
    let Some(info) = &r.ranking else {
        return String::new();
    };
    let mut s = format!(
        "<p class=\"note\">{} {}. Class rank is the position within the class in this order. SB<i>n</i> names the variant ranked <i>n</i>-th.",
        esc(&r.ranking_rule().unwrap_or_default()),
        esc(&capitalise(&info.tie_break))
    );
    if info.tie_groups.is_empty() {
        s.push_str(" No ranks were decided by the tie-break.");
    } else {
        let groups: Vec<String> = info
            .tie_groups
            .iter()
            .map(|g| {
                g.iter()
                    .filter_map(|id| r.variant(*id))
                    .map(|v| v.name.clone().unwrap_or_default())
                    .collect::<Vec<_>>()
                    .join(" = ")
            })
            .collect();
        let _ = write!(
            s,
            " Tied on all three criteria: {}.",
            esc(&groups.join("; "))
        );
    }
    let names = recommended_names(r);
    if !names.is_empty() {
        let _ = write!(
            s,
            " Highlighted rows, here and in the tables below: the recommended variants ({}).",
            esc(&names)
        );
    }
    s.push_str("</p>");
    s
}

/// The recommended variants' names, `SB6, SB37, SB44`, best rank first.
pub(crate) fn recommended_names(r: &RunResults) -> String {
    let ids = r.recommended_ids();
    r.ranked()
        .iter()
        .filter(|v| ids.contains(&v.id))
        .filter_map(|v| v.name.clone())
        .collect::<Vec<_>>()
        .join(", ")
}

pub(crate) fn capitalise(s: &str) -> String {
    let mut c = s.chars();
    match c.next() {
        Some(f) => f.to_uppercase().chain(c).collect(),
        None => String::new(),
    }
}

/// The partial-balancing section (see [`crate::partial`]): the smallest-Dmax statement, the
/// chart and the designs table.
fn push_partial(h: &mut String, p: &PartialBalancing) {
    h.push_str("<h2 id=\"partial\">Partial balancing (no feasible variant)</h2>");
    for paragraph in partial::paragraphs(p) {
        let _ = write!(h, "<p class=\"note\">{}</p>", esc(&paragraph));
    }
    if let Some(svg) = crate::partial_view::chart(p) {
        let _ = write!(h, "<div class=\"charts\"><figure>{svg}</figure></div>");
    }
    if !p.designs.is_empty() {
        h.push_str(&table(&crate::partial_view::table(p), "partial"));
    }
}

fn push_charts(h: &mut String, charts: &[Chart], section: Section) {
    h.push_str("<div class=\"charts\">");
    for c in charts.iter().filter(|c| c.section == section) {
        let _ = write!(h, "<figure>{}</figure>", c.svg);
    }
    h.push_str("</div>");
}

/// A table as HTML; `class` is an optional CSS class.
fn table(t: &Table, class: &str) -> String {
    let mut s = String::from("<div class=\"scroll\">");
    if class.is_empty() {
        s.push_str("<table>");
    } else {
        let _ = write!(s, "<table class=\"{class}\">");
    }
    s.push_str("<thead><tr>");
    for (c, head) in t.header.iter().enumerate() {
        // Headers of number columns align with their numbers.
        if t.rows.iter().any(|r| r[c].numeric) {
            let _ = write!(s, "<th class=\"n\">{}</th>", esc(head));
        } else {
            let _ = write!(s, "<th>{}</th>", esc(head));
        }
    }
    s.push_str("</tr></thead><tbody>");
    for (k, (row, &group)) in t.rows.iter().zip(&t.group_starts).enumerate() {
        let rec = t.highlighted.get(k).copied().unwrap_or(false);
        s.push_str(match (group, rec) {
            (true, true) => "<tr class=\"g rec\">",
            (true, false) => "<tr class=\"g\">",
            (false, true) => "<tr class=\"rec\">",
            (false, false) => "<tr>",
        });
        for cell in row {
            if cell.numeric {
                let _ = write!(s, "<td class=\"n\">{}</td>", esc(&cell.text));
            } else if cell.prose {
                let _ = write!(s, "<td class=\"p\">{}</td>", esc(&cell.text));
            } else {
                let _ = write!(s, "<td>{}</td>", esc(&cell.text));
            }
        }
        s.push_str("</tr>");
    }
    s.push_str("</tbody></table></div>");
    s
}
