//! The report's tables as plain data, built once and rendered by both the HTML and the Markdown
//! writers, so the two reports can never disagree on a number.

use crate::format::{angle, compact, fixed, percent, polar, seconds, task, value};
use crate::honest::on_bound;
use crate::results::{PathSimulation, RunResults, Status, VariantRecord};
use crate::springspec::SpringSpec;

/// One cell: text, whether it is a number (right-aligned) and whether it is prose that may wrap
/// (everything else stays on one line, so labels like `K42 + K43` never break).
#[derive(Clone, Debug, PartialEq)]
pub struct Cell {
    pub text: String,
    pub numeric: bool,
    pub prose: bool,
}

impl Cell {
    pub fn text(s: impl Into<String>) -> Cell {
        Cell {
            text: s.into(),
            numeric: false,
            prose: false,
        }
    }
    pub fn num(s: impl Into<String>) -> Cell {
        Cell {
            text: s.into(),
            numeric: true,
            prose: false,
        }
    }
    pub fn prose(s: impl Into<String>) -> Cell {
        Cell {
            text: s.into(),
            numeric: false,
            prose: true,
        }
    }
    pub fn empty() -> Cell {
        Cell::text("")
    }
}

/// A table: header, rows, which rows start a visual group (e.g. a new variant) and which rows
/// are highlighted (those of a recommended variant, so the design to build stands out in
/// every list of variants).
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    pub header: Vec<String>,
    pub rows: Vec<Vec<Cell>>,
    pub group_starts: Vec<bool>,
    pub highlighted: Vec<bool>,
}

impl Table {
    fn new(header: &[&str]) -> Table {
        Table {
            header: header.iter().map(|s| s.to_string()).collect(),
            rows: Vec::new(),
            group_starts: Vec::new(),
            highlighted: Vec::new(),
        }
    }
    fn push(&mut self, row: Vec<Cell>, group_start: bool) {
        self.push_marked(row, group_start, false);
    }
    fn push_marked(&mut self, row: Vec<Cell>, group_start: bool, highlighted: bool) {
        debug_assert_eq!(row.len(), self.header.len());
        self.rows.push(row);
        self.group_starts.push(group_start);
        self.highlighted.push(highlighted);
    }

    /// Removes columns that are empty in every row (e.g. the optimiser's columns when it
    /// reported nothing, or the spring columns of a counterweight-only Table 1).
    fn without_empty_columns(mut self) -> Table {
        if self.rows.is_empty() {
            return self;
        }
        let keep: Vec<bool> = (0..self.header.len())
            .map(|c| self.rows.iter().any(|r| !r[c].text.is_empty()))
            .collect();
        let filter = |v: Vec<Cell>| -> Vec<Cell> {
            v.into_iter()
                .zip(&keep)
                .filter(|(_, k)| **k)
                .map(|(c, _)| c)
                .collect()
        };
        self.header = std::mem::take(&mut self.header)
            .into_iter()
            .zip(&keep)
            .filter(|(_, k)| **k)
            .map(|(h, _)| h)
            .collect();
        self.rows = std::mem::take(&mut self.rows)
            .into_iter()
            .map(filter)
            .collect();
        self
    }
}

/// Run metadata as key/value rows.
pub fn metadata(r: &RunResults) -> Table {
    let m = &r.metadata;
    let mut t = Table::new(&["", ""]);
    let examined = r.variants.len().to_string();
    let total: f64 = m.timings.iter().map(|p| p.seconds).sum();
    let mut rows = vec![
        ("Case", m.case_name.clone()),
        ("Case file", m.case_path.clone()),
        ("Date", m.date.clone()),
        ("Tool", format!("{} {}", m.tool, m.tool_version)),
        ("Dmax", m.dmax.to_string()),
        ("Worker threads", m.jobs.to_string()),
    ];
    if let Some(n) = m.shards {
        rows.push(("Merged from", format!("{n} shards")));
    }
    rows.extend([
        ("Variants examined", examined),
        ("Wall time", format!("{} s", seconds(total))),
        ("Schema version", r.schema_version.to_string()),
    ]);
    for (k, v) in rows {
        t.push(vec![Cell::text(k), Cell::text(v)], false);
    }
    t
}

/// Wall time per phase.
pub fn timings(r: &RunResults) -> Table {
    let mut t = Table::new(&["Phase", "Time [s]"]);
    for p in &r.metadata.timings {
        t.push(
            vec![Cell::text(&p.phase), Cell::num(seconds(p.seconds))],
            false,
        );
    }
    t
}

/// Phase 1 summary.
pub fn unbalanced_summary(r: &RunResults) -> Table {
    let u = &r.unbalanced;
    let mut t = Table::new(&["Indicator", "Value", "Task"]);
    t.push(
        vec![
            Cell::text("QTR (Eq. 1) [N·m]"),
            Cell::num(value(u.qtr)),
            Cell::text(task(u.qtr_task)),
        ],
        false,
    );
    t.push(
        vec![
            Cell::text("QIT (Eq. 2) [N·m]"),
            Cell::num(value(u.qit)),
            Cell::text(task(u.qit_task)),
        ],
        false,
    );
    t.push(
        vec![
            Cell::text("Tasks evaluated"),
            Cell::num(u.tasks.to_string()),
            Cell::empty(),
        ],
        false,
    );
    t.push(
        vec![
            Cell::text("Tasks excluded"),
            Cell::num(u.excluded_tasks.to_string()),
            Cell::empty(),
        ],
        false,
    );
    t
}

/// Per-actuator RMS and peak on the critical tasks of the unbalanced robot.
pub fn unbalanced_actuators(r: &RunResults) -> Table {
    let mut t = Table::new(&["Actuator", "CRT", "RMS [N·m]", "CPT", "|peak| [N·m]"]);
    for a in &r.unbalanced.actuators {
        t.push(
            vec![
                Cell::text(&a.name),
                Cell::text(task(a.crt)),
                Cell::num(value(a.crt_rms)),
                Cell::text(task(a.cpt)),
                Cell::num(value(a.cpt_peak)),
            ],
            false,
        );
    }
    t
}

/// Per-joint peak reactions of the unbalanced robot.
pub fn unbalanced_joints(r: &RunResults) -> Table {
    let mut t = Table::new(&["Joint", "F_j [N]", "task", "M_j [N·m]", "task"]);
    let opt_task = |x: Option<[usize; 2]>| x.map(task).unwrap_or_default();
    for j in &r.unbalanced.joints {
        t.push(
            vec![
                Cell::text(&j.name),
                Cell::num(value(j.force)),
                Cell::text(opt_task(j.force_task)),
                Cell::num(value(j.moment)),
                Cell::text(opt_task(j.moment_task)),
            ],
            false,
        );
    }
    t
}

/// Variants per status and class.
pub fn counts(r: &RunResults) -> Table {
    let mut t = Table::new(&[
        "Status",
        "Meaning",
        "Counterweights",
        "Springs",
        "Hybrid",
        "Total",
    ]);
    let mut sums = [0usize; 4];
    for c in &r.counts {
        let n = [c.counterweights, c.springs, c.hybrid, c.total];
        for (s, x) in sums.iter_mut().zip(n) {
            *s += x;
        }
        let mut row = vec![Cell::text(c.status.name()), Cell::prose(c.status.meaning())];
        row.extend(n.iter().map(|x| Cell::num(x.to_string())));
        t.push(row, false);
    }
    let mut row = vec![Cell::text("all"), Cell::empty()];
    row.extend(sums.iter().map(|x| Cell::num(x.to_string())));
    t.push(row, true);
    t
}

fn opt(x: Option<f64>, f: fn(f64) -> String) -> String {
    x.map(f).unwrap_or_default()
}

/// The global ranking (Fig. 7's order) with indicators.
pub fn ranking(r: &RunResults) -> Table {
    let mut t = Table::new(&[
        "Rank",
        "Variant",
        "Elements",
        "Class",
        "Class rank",
        "QTR [N·m]",
        "QIT [N·m]",
        "ΔQTR [%]",
        "ΔQIT [%]",
        "ΔR [%]",
        "Added mass [kg]",
        "Peak spring force [N]",
        "Objective [N·m]",
        "Gap",
        "Note",
    ]);
    let recommended = r.recommended_ids();
    for v in r.ranked() {
        let eval = v.evaluation.as_ref();
        let optim = v.optimiser.as_ref();
        let practical = v.practical.as_ref();
        t.push_marked(
            vec![
                Cell::num(v.rank.map(|x| x.to_string()).unwrap_or_default()),
                Cell::text(v.name.clone().unwrap_or_default()),
                Cell::text(v.label()),
                Cell::text(v.class.name()),
                Cell::num(v.class_rank.map(|x| x.to_string()).unwrap_or_default()),
                Cell::num(opt(eval.map(|e| e.qtr), value)),
                Cell::num(opt(eval.map(|e| e.qit), value)),
                Cell::num(opt(v.dqtr, percent)),
                Cell::num(opt(v.dqit, percent)),
                Cell::num(opt(v.dr, percent)),
                Cell::num(opt(practical.map(|p| p.added_mass), value)),
                Cell::num(opt(practical.and_then(|p| p.peak_spring_force), value)),
                Cell::num(opt(optim.and_then(|o| o.objective), value)),
                Cell::num(opt(optim.and_then(|o| o.gap), |g| format!("{:.1e}", g))),
                Cell::text(note(v)),
            ],
            false,
            recommended.contains(&v.id),
        );
    }
    t.without_empty_columns()
}

/// The Note column of the ranking: an idle element and the variant it really is, then a
/// rank decided by the labels.
fn note(v: &VariantRecord) -> String {
    let mut parts: Vec<String> = v.idle_note().into_iter().collect();
    if v.tie_broken_by_label {
        parts.push("label tie-break".into());
    }
    parts.join("; ")
}

/// The paper's Table 1: optimised parameters of the feasible variants, one row per element,
/// in the paper's units (N/mm, mm, kg) with angles in radians and degrees. A value on a bound
/// of the optimisation carries `(min)` or `(max)`; an idle element ([`crate::honest`]) says so
/// in the Element column.
pub fn parameters(r: &RunResults) -> Table {
    parameters_of(r, &r.ranked())
}

/// [`parameters`] for the given variants only.
pub fn parameters_of(r: &RunResults, variants: &[&VariantRecord]) -> Table {
    let mut t = Table::new(&[
        "Variant",
        "Element",
        "Bodies",
        "K [N/mm]",
        "a [mm]",
        "α [rad (°)]",
        "b [mm]",
        "β [rad (°)]",
        "m [kg]",
        "r [mm]",
        "φ [rad (°)]",
    ]);
    let recommended = r.recommended_ids();
    for v in variants {
        let Some(p) = &v.parameters else { continue };
        let mark = recommended.contains(&v.id);
        let mut first = true;
        let name = v.name.clone().unwrap_or_default();
        let element = |label: &str| {
            if v.idle.iter().any(|l| l == label) {
                format!("{label} (idle)")
            } else {
                label.to_string()
            }
        };
        for s in &p.springs {
            let b = r.bounds_of(&s.label);
            let (a, alpha) = vector_cells(s.anchor_a, s.plane, b.and_then(|b| b.anchor_a));
            let (bb, beta) = vector_cells(s.anchor_b, s.plane, b.and_then(|b| b.anchor_b));
            t.push_marked(
                vec![
                    Cell::text(if first { name.clone() } else { String::new() }),
                    Cell::text(element(&s.label)),
                    Cell::text(format!("{}–{}", s.body, s.other)),
                    Cell::num(marked(
                        value(s.stiffness / 1000.0),
                        s.stiffness,
                        b.and_then(|b| b.stiffness),
                    )),
                    Cell::num(a),
                    Cell::num(alpha),
                    Cell::num(bb),
                    Cell::num(beta),
                    Cell::empty(),
                    Cell::empty(),
                    Cell::empty(),
                ],
                first,
                mark,
            );
            first = false;
        }
        for c in &p.counterweights {
            let b = r.bounds_of(&c.label);
            let (rr, phi) = vector_cells(c.offset, c.plane, b.and_then(|b| b.radius));
            t.push_marked(
                vec![
                    Cell::text(if first { name.clone() } else { String::new() }),
                    Cell::text(element(&c.label)),
                    Cell::text(&c.body),
                    Cell::empty(),
                    Cell::empty(),
                    Cell::empty(),
                    Cell::empty(),
                    Cell::empty(),
                    Cell::num(marked(value(c.mass), c.mass, b.and_then(|b| b.mass))),
                    Cell::num(rr),
                    Cell::num(phi),
                ],
                first,
                mark,
            );
            first = false;
        }
    }
    t.without_empty_columns()
}

/// `text` with ` (min)` / ` (max)` when `x` is on an end of `range`.
fn marked(text: String, x: f64, range: Option<[f64; 2]>) -> String {
    match on_bound(x, range) {
        Some(b) => format!("{text} ({})", b.word()),
        None => text,
    }
}

/// An angle in radians (Table 1 style) with its degrees: `π/2 (90°)`, `1.000 (57.3°)`.
pub fn angle_with_degrees(rad: f64) -> String {
    if !rad.is_finite() {
        return angle(rad);
    }
    let deg = rad.rem_euclid(2.0 * std::f64::consts::PI).to_degrees();
    let deg = if (deg - 360.0).abs() < 1e-4 { 0.0 } else { deg };
    format!("{} ({}°)", angle(rad), fixed(deg, 1))
}

/// (length, angle) of a body-frame vector: polar in its plane when known (Table 1 style),
/// else the Cartesian components in mm and no angle. The length is marked when it is on an
/// end of `range` (m).
fn vector_cells(
    v: [f64; 3],
    plane: Option<crate::results::Plane>,
    range: Option<[f64; 2]>,
) -> (String, String) {
    let length = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    match plane {
        Some(p) => {
            let [a0, a1] = p.axes();
            let (r, phi) = polar(v, (a0, a1));
            let off = v[3 - a0 - a1];
            let len = if off.abs() > 1e-9 {
                format!(
                    "{} (out of plane {})",
                    fixed(r * 1000.0, 1),
                    fixed(off * 1000.0, 1)
                )
            } else {
                fixed(r * 1000.0, 1)
            };
            (
                marked(len, length, range),
                if r > 1e-12 {
                    angle_with_degrees(phi)
                } else {
                    "–".into()
                },
            )
        }
        None => (
            marked(
                format!(
                    "({}, {}, {})",
                    fixed(v[0] * 1000.0, 1),
                    fixed(v[1] * 1000.0, 1),
                    fixed(v[2] * 1000.0, 1)
                ),
                length,
                range,
            ),
            String::new(),
        ),
    }
}

/// The variants the design views show: the recommended ones, then those drawn on request, in
/// that order, each once.
pub fn design_variants(r: &RunResults) -> Vec<&VariantRecord> {
    let mut ids = r.recommended_ids();
    for id in r.schematics.iter().filter_map(|s| s.variant) {
        if !ids.contains(&id) {
            ids.push(id);
        }
    }
    ids.iter().filter_map(|&id| r.variant(id)).collect()
}

/// What to order for each spring of the recommended (and drawn) variants
/// ([`crate::springspec`]): lengths in mm, forces in N.
pub fn spring_specs(r: &RunResults) -> Table {
    let mut t = Table::new(&[
        "Variant",
        "Spring",
        "K [N/mm]",
        "Length [mm]",
        "Stroke [mm]",
        "Force [N]",
        "Energy [J]",
        "Wire ≥ [kg]",
        "Cable: pulley load [N]",
        "Pre-tensioned: body [mm]",
        "initial tension [N]",
        "extension [mm]",
    ]);
    let recommended = r.recommended_ids();
    for v in design_variants(r) {
        for (k, s) in SpringSpec::of_variant(v).iter().enumerate() {
            let mm = |x: f64| fixed(x * 1000.0, 0);
            let (body, tension, ext) = match &s.pre_tensioned {
                Some(p) => (
                    mm(p.body_length),
                    fixed(p.initial_tension, 0),
                    format!("{}–{}", mm(p.extension[0]), mm(p.extension[1])),
                ),
                None => ("no room".into(), String::new(), String::new()),
            };
            t.push_marked(
                vec![
                    Cell::text(if k == 0 {
                        v.display_name()
                    } else {
                        String::new()
                    }),
                    Cell::text(&s.label),
                    Cell::num(value(s.stiffness / 1000.0)),
                    Cell::num(format!("{}–{}", mm(s.length[0]), mm(s.length[1]))),
                    Cell::num(mm(s.stroke)),
                    Cell::num(format!("{}–{}", fixed(s.force[0], 0), fixed(s.force[1], 0))),
                    Cell::num(fixed(s.energy, 0)),
                    Cell::num(fixed(s.wire_mass, 1)),
                    Cell::num(fixed(s.pulley_load, 0)),
                    Cell::num(body),
                    Cell::num(tension),
                    Cell::num(ext),
                ],
                k == 0,
                recommended.contains(&v.id),
            );
        }
    }
    t
}

/// Best variant of each class.
pub fn best_per_class(r: &RunResults) -> Table {
    let mut t = Table::new(&[
        "Class",
        "Best variant",
        "Elements",
        "Rank",
        "ΔQTR [%]",
        "ΔQIT [%]",
        "ΔR [%]",
    ]);
    for v in r.best_per_class() {
        t.push(
            vec![
                Cell::text(v.class.title()),
                Cell::text(v.name.clone().unwrap_or_default()),
                Cell::text(v.label()),
                Cell::num(v.rank.map(|x| x.to_string()).unwrap_or_default()),
                Cell::num(opt(v.dqtr, percent)),
                Cell::num(opt(v.dqit, percent)),
                Cell::num(opt(v.dr, percent)),
            ],
            false,
        );
    }
    t
}

/// Per-joint reactions and ΔR terms of every ranked variant.
pub fn joint_reactions(r: &RunResults) -> Table {
    joint_reactions_of(r, &r.ranked())
}

/// [`joint_reactions`] for the given variants only.
pub fn joint_reactions_of(_r: &RunResults, variants: &[&VariantRecord]) -> Table {
    let mut t = Table::new(&[
        "Variant",
        "Joint",
        "F_j [N]",
        "ΔF_j [%]",
        "γ_F",
        "M_j [N·m]",
        "ΔM_j [%]",
        "γ_M",
        "ΔR term [%]",
    ]);
    for v in variants {
        let (Some(e), Some(d)) = (&v.evaluation, &v.dr_terms) else {
            continue;
        };
        for (k, (j, jv)) in e.joints.iter().zip(&d.joints).enumerate() {
            t.push(
                vec![
                    Cell::text(if k == 0 {
                        v.name.clone().unwrap_or_default()
                    } else {
                        String::new()
                    }),
                    Cell::text(&j.name),
                    Cell::num(value(j.force)),
                    Cell::num(opt(jv.dforce, percent)),
                    Cell::num(fixed(jv.gamma_force, 3)),
                    Cell::num(value(j.moment)),
                    Cell::num(opt(jv.dmoment, percent)),
                    Cell::num(fixed(jv.gamma_moment, 3)),
                    Cell::num(fixed(jv.term_force + jv.term_moment, 2)),
                ],
                k == 0,
            );
        }
    }
    t.without_empty_columns()
}

/// Balanced variants that were not ranked, and why (infeasible ones are only counted).
pub fn not_ranked(r: &RunResults) -> Table {
    let mut t = Table::new(&["Id", "Elements", "Class", "Status", "Reason"]);
    for v in r
        .variants
        .iter()
        .filter(|v| !matches!(v.status, Status::Feasible | Status::Infeasible))
    {
        t.push(
            vec![
                Cell::num(v.id.to_string()),
                Cell::text(v.label()),
                Cell::text(v.class.name()),
                Cell::text(v.status.name()),
                Cell::prose(v.reason.clone().unwrap_or_default()),
            ],
            false,
        );
    }
    t
}

/// The paper's Table 2: RMS and |peak| motor torque along the path, with variations vs UB.
pub fn path_table(p: &PathSimulation) -> Table {
    let mechanisms: Vec<&str> = {
        let mut m: Vec<&str> = Vec::new();
        for s in &p.table {
            if !m.contains(&s.mechanism.as_str()) {
                m.push(&s.mechanism);
            }
        }
        m
    };
    let mut header = vec!["Motor".to_string(), "".to_string()];
    for (k, m) in mechanisms.iter().enumerate() {
        header.push(format!("{m}: T [N·m]"));
        if k > 0 {
            header.push("Δ [%]".to_string());
        }
    }
    let mut t = Table {
        header,
        rows: Vec::new(),
        group_starts: Vec::new(),
        highlighted: Vec::new(),
    };
    for a in &p.actuators {
        for (stat, first) in [("RMS", true), ("|peak|", false)] {
            let mut row = vec![
                Cell::text(if first { a.clone() } else { String::new() }),
                Cell::text(stat),
            ];
            for (k, m) in mechanisms.iter().enumerate() {
                let s = p
                    .table
                    .iter()
                    .find(|s| &s.actuator == a && s.mechanism == *m);
                let (v, var) = match s {
                    Some(s) if first => (s.rms, s.rms_variation),
                    Some(s) => (s.peak, s.peak_variation),
                    None => (f64::NAN, None),
                };
                row.push(Cell::num(if v.is_finite() {
                    fixed(v, 2)
                } else {
                    String::new()
                }));
                if k > 0 {
                    row.push(Cell::num(
                        var.map(|x| fixed_signed(x, 1)).unwrap_or_default(),
                    ));
                }
            }
            t.push(row, first);
        }
    }
    t
}

fn fixed_signed(x: f64, d: usize) -> String {
    let s = fixed(x, d);
    if x > 0.0 && s.chars().any(|c| ('1'..='9').contains(&c)) {
        format!("+{s}")
    } else {
        s
    }
}

/// The balance relations and free directions of a variant, as lines of text.
pub fn relations(v: &VariantRecord) -> Vec<String> {
    let mut lines = v.relations.clone();
    for (k, d) in v.free_directions.iter().enumerate() {
        let mut comps = String::new();
        for (i, (name, c)) in d.components.iter().enumerate() {
            let mag = compact(c.abs());
            match (i, *c < 0.0) {
                (0, false) => comps.push_str(&format!("{mag}·{name}")),
                (0, true) => comps.push_str(&format!("−{mag}·{name}")),
                (_, false) => comps.push_str(&format!(" + {mag}·{name}")),
                (_, true) => comps.push_str(&format!(" − {mag}·{name}")),
            }
        }
        let mut line = format!("free direction {}: {comps}", k + 1);
        if let Some((lo, hi)) = d.positive_interval {
            let lo = lo.map(compact).unwrap_or_else(|| "−∞".into());
            let hi = hi.map(compact).unwrap_or_else(|| "+∞".into());
            line.push_str(&format!(
                " (all masses and stiffnesses positive for step t in [{lo}, {hi}])"
            ));
        }
        lines.push(line);
    }
    lines
}

/// `12.00 (1.0 %)`-style cells of the practical figures, shared by the decision tables.
fn practical_cells(v: &VariantRecord) -> Vec<Cell> {
    let p = v.practical.as_ref();
    vec![
        Cell::num(opt(p.map(|p| p.added_mass), value)),
        Cell::num(opt(p.and_then(|p| p.added_mass_percent), |x| fixed(x, 1))),
        Cell::num(
            p.map(|p| p.elements)
                .unwrap_or(v.elements.len())
                .to_string(),
        ),
        Cell::num(opt(p.and_then(|p| p.peak_spring_force), value)),
        Cell::num(opt(p.and_then(|p| p.peak_spring_elongation), |x| {
            fixed(x * 1000.0, 0)
        })),
        Cell::num(opt(p.and_then(|p| p.peak_counterweight_offset), |x| {
            fixed(x * 1000.0, 0)
        })),
    ]
}

const PRACTICAL_HEADER: [&str; 6] = [
    "Added mass [kg]",
    "of moving mass [%]",
    "Parts",
    "Peak spring force [N]",
    "Peak stretch [mm]",
    "Peak offset [mm]",
];

/// The recommendations: overall first, then one per class, with the figures behind them and
/// the reason.
pub fn recommendations(r: &RunResults) -> Table {
    let mut header = vec![
        "Recommendation",
        "Variant",
        "Elements",
        "Rank",
        "Equivalent",
        "ΔQTR [%]",
        "ΔQIT [%]",
        "ΔR [%]",
    ];
    header.extend(PRACTICAL_HEADER);
    let mut t = Table::new(&header);
    let Some(d) = &r.decision else {
        return t;
    };
    for (k, rec) in d.overall.iter().chain(&d.classes).enumerate() {
        let Some(v) = r.variant(rec.chosen) else {
            continue;
        };
        let scope = match rec.class {
            None => "Overall".to_string(),
            Some(c) => c.title().to_string(),
        };
        let mut row = vec![
            Cell::text(scope),
            Cell::text(v.name.clone().unwrap_or_default()),
            Cell::text(v.label()),
            Cell::num(v.rank.map(|x| x.to_string()).unwrap_or_default()),
            Cell::num(rec.equivalent.len().to_string()),
            Cell::num(opt(v.dqtr, percent)),
            Cell::num(opt(v.dqit, percent)),
            Cell::num(opt(v.dr, percent)),
        ];
        row.extend(practical_cells(v));
        t.push(row, k == 1);
    }
    t.without_empty_columns()
}

/// The equivalent group in one sentence: its size, its classes, the spread of its indicators
/// and practical figures, and how many hold an idle element.
pub fn equivalent_summary(r: &RunResults) -> String {
    let Some(rec) = r.decision.as_ref().and_then(|d| d.overall.as_ref()) else {
        return String::new();
    };
    let group: Vec<&VariantRecord> = rec
        .equivalent
        .iter()
        .filter_map(|id| r.variant(*id))
        .collect();
    let range = |f: &dyn Fn(&VariantRecord) -> Option<f64>| -> (f64, f64) {
        group
            .iter()
            .filter_map(|v| f(v))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                (lo.min(x), hi.max(x))
            })
    };
    let (q0, q1) = range(&|v| v.dqtr);
    let (i0, i1) = range(&|v| v.dqit);
    let (r0, r1) = range(&|v| v.dr);
    let (m0, m1) = range(&|v| v.practical.as_ref().map(|p| p.added_mass));
    let classes: Vec<String> = crate::ranking::Class::ALL
        .iter()
        .filter_map(|c| {
            let n = group.iter().filter(|v| v.class == *c).count();
            (n > 0).then(|| format!("{n} {}", c.name()))
        })
        .collect();
    let idle = group.iter().filter(|v| !v.idle.is_empty()).count();
    let leader = r
        .variant(rec.leader)
        .and_then(|v| v.name.clone())
        .unwrap_or_default();
    let mut s = format!(
        "{} variants ({}) are within {} percentage points of {leader} on ΔQTR and ΔQIT: ΔQTR \
         {} to {} %, ΔQIT {} to {} %, ΔR {} to {} %, added mass {} to {}",
        group.len(),
        classes.join(", "),
        compact(r.decision.as_ref().map_or(0.0, |d| d.tolerance)),
        percent(q0),
        percent(q1),
        percent(i0),
        percent(i1),
        percent(r0),
        percent(r1),
        crate::format::mass(m0.max(0.0)),
        crate::format::mass(m1.max(0.0)),
    );
    if idle > 0 {
        s.push_str(&format!(
            "; {idle} of them hold an idle element (never recommended)"
        ));
    }
    s.push('.');
    s
}

/// The variants equivalent to the overall leader (the material of the overall pick), in rank
/// order; the pick is marked.
pub fn equivalent_group(r: &RunResults) -> Table {
    let mut header = vec![
        "Rank",
        "Variant",
        "Elements",
        "Class",
        "ΔQTR [%]",
        "ΔQIT [%]",
        "ΔR [%]",
    ];
    header.extend(PRACTICAL_HEADER);
    header.push("");
    let mut t = Table::new(&header);
    let Some(rec) = r.decision.as_ref().and_then(|d| d.overall.as_ref()) else {
        return t;
    };
    for id in &rec.equivalent {
        let Some(v) = r.variant(*id) else { continue };
        let mut row = vec![
            Cell::num(v.rank.map(|x| x.to_string()).unwrap_or_default()),
            Cell::text(v.name.clone().unwrap_or_default()),
            Cell::text(v.label()),
            Cell::text(v.class.name()),
            Cell::num(opt(v.dqtr, percent)),
            Cell::num(opt(v.dqit, percent)),
            Cell::num(opt(v.dr, percent)),
        ];
        row.extend(practical_cells(v));
        row.push(Cell::text(if *id == rec.chosen {
            "recommended".to_string()
        } else {
            v.idle_note().unwrap_or_default()
        }));
        t.push(row, false);
    }
    t.without_empty_columns()
}

/// Practical figures of every ranked variant.
pub fn practical(r: &RunResults) -> Table {
    practical_of(r, &r.ranked())
}

/// [`practical`] for the given variants only.
pub fn practical_of(r: &RunResults, variants: &[&VariantRecord]) -> Table {
    let mut header = vec!["Rank", "Variant", "Elements", "Class"];
    header.extend(PRACTICAL_HEADER);
    let mut t = Table::new(&header);
    let recommended = r.recommended_ids();
    for v in variants {
        let mut row = vec![
            Cell::num(v.rank.map(|x| x.to_string()).unwrap_or_default()),
            Cell::text(v.name.clone().unwrap_or_default()),
            Cell::text(v.label()),
            Cell::text(v.class.name()),
        ];
        row.extend(practical_cells(v));
        t.push_marked(row, false, recommended.contains(&v.id));
    }
    t.without_empty_columns()
}

/// The recommendations' reasons, one sentence each, headed by their scope.
pub fn reasons(r: &RunResults) -> Vec<(String, String)> {
    let Some(d) = &r.decision else {
        return Vec::new();
    };
    d.overall
        .iter()
        .chain(&d.classes)
        .map(|rec| {
            let scope = match rec.class {
                None => "Overall".to_string(),
                Some(c) => c.title().to_string(),
            };
            (scope, rec.reason.clone())
        })
        .collect()
}
