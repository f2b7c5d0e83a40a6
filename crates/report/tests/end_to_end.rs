//! End to end: a hand-built palletizer-like run → finalize → all outputs in a temp dir → parse
//! them back and check their structure.

use std::f64::consts::PI;

use counterpoise_report::*;
use quick_xml::events::Event;
use serde_json::json;

fn task(a: usize, b: usize) -> TaskRef {
    [a, b]
}

fn joints(f: [f64; 4], m: [f64; 4]) -> Vec<JointPeak> {
    (0..4)
        .map(|j| JointPeak {
            name: format!("J{}", j + 1),
            force: f[j],
            force_task: Some(task(0, j + 1)),
            moment: m[j],
            moment_task: None,
        })
        .collect()
}

fn evaluation(qtr: f64, qit: f64, f: [f64; 4], m: [f64; 4]) -> Evaluation {
    Evaluation {
        qtr,
        qtr_task: task(3, 40),
        qit,
        qit_task: task(5, 12),
        actuators: (1..=3)
            .map(|n| ActuatorSummary {
                name: format!("M{n}"),
                crt: task(n, 30 + n),
                crt_rms: qtr / 3.0,
                cpt: task(n + 1, 20),
                cpt_peak: qit / 2.5,
            })
            .collect(),
        joints: joints(f, m),
        tasks: 1176,
        excluded_tasks: 2,
        reactions_minimum_norm: false,
    }
}

fn element(label: &str) -> ElementInfo {
    let spring = label.starts_with('K');
    ElementInfo {
        label: label.into(),
        kind: if spring {
            ElementKind::Spring
        } else {
            ElementKind::Counterweight
        },
        bodies: if spring {
            vec![
                format!("body{}", &label[1..2]),
                format!("body{}", &label[2..3]),
            ]
        } else {
            vec![format!("body{}", &label[1..])]
        },
    }
}

fn params(labels: &[&str]) -> PhysicalParameters {
    let mut p = PhysicalParameters::default();
    for l in labels {
        if l.starts_with('K') {
            p.springs.push(Spring {
                label: l.to_string(),
                body: format!("body{}", &l[1..2]),
                other: format!("body{}", &l[2..3]),
                stiffness: 5669.0,
                anchor_a: [0.9989, 0.0, 0.0],
                anchor_b: [0.0, 0.4999, 0.0],
                plane: Some(Plane::Xy),
            });
        } else {
            p.counterweights.push(Counterweight {
                label: l.to_string(),
                body: format!("body{}", &l[1..]),
                mass: 228.6,
                offset: [-0.0813, 0.0, 0.0],
                plane: Some(Plane::Xy),
            });
        }
    }
    p
}

fn feasible(id: usize, labels: &[&str], class: Class, e: Evaluation) -> VariantRecord {
    let mut v = VariantRecord::new(
        id,
        labels.iter().map(|l| element(l)).collect(),
        class,
        Status::Feasible,
    );
    v.parameters = Some(params(labels));
    // Every spring stretched to at most 0.8 m: 5669 N/m · 0.8 m = 4535.2 N.
    let peaks = params(labels)
        .springs
        .iter()
        .map(|s| SpringPeak::from_lengths(&s.label, s.stiffness, [0.5, 0.8]))
        .collect();
    v.practical = Some(PracticalFigures::new(
        &params(labels),
        Some(1188.625),
        peaks,
    ));
    v.evaluation = Some(e);
    v.relations = vec![format!("m4·r4x = −18.59 kg·m <{id}>")];
    v.free_directions = vec![FreeDirection {
        components: vec![("K43".into(), 1.0), ("K53".into(), -0.5)],
        positive_interval: Some((Some(-2.0), None)),
    }];
    v.verification_residual = Some(3.2e-13);
    v.optimiser = Some(OptimiserInfo {
        objective: Some(12.5),
        lower_bound: Some(12.4),
        gap: Some(0.008),
        iterations: Some(2),
        boxes: Some(0),
        message: None,
    });
    v
}

/// A run with every status, all three classes, torque charts and a path simulation.
fn sample() -> RunResults {
    let ub_f = [9000.0, 4000.0, 2500.0, 1500.0];
    let ub_m = [3000.0, 1200.0, 600.0, 200.0];
    let meta = RunMetadata {
        tool: "counterpoise".into(),
        tool_version: "0.1.0".into(),
        case_name: "palletizer <test> & \"quotes\"".into(),
        case_path: "cases/palletizer.json".into(),
        dmax: 2,
        jobs: 2,
        shards: None,
        shard_timings: Vec::new(),
        date: "2026-11-22T00:00:00Z".into(),
        timings: vec![
            PhaseTiming {
                phase: "unbalanced".into(),
                seconds: 0.41,
            },
            PhaseTiming {
                phase: "balance search".into(),
                seconds: 0.12,
            },
            PhaseTiming {
                phase: "optimisation".into(),
                seconds: 7.9,
            },
        ],
        notes: vec!["Payload excluded from balancing.".into()],
    };
    let mut r = RunResults::new(
        meta,
        json!({"name": "palletizer", "bodies": [{"name": "column"}]}),
        evaluation(40.0, 90.0, ub_f, ub_m),
    );
    // Springs: dynamically identical (same QTR/QIT), different reactions.
    r.variants.push(feasible(
        10,
        &["K42", "K43"],
        Class::Springs,
        evaluation(14.0, 50.0, [9100.0, 4100.0, 2500.0, 1500.0], ub_m),
    ));
    r.variants.push(feasible(
        11,
        &["K43", "K53"],
        Class::Springs,
        evaluation(14.0 + 1e-12, 50.0, [9000.0, 4400.0, 2500.0, 1500.0], ub_m),
    ));
    r.variants.push(feasible(
        3,
        &["m4", "m5"],
        Class::Counterweights,
        evaluation(
            22.0,
            60.0,
            [11000.0, 4000.0, 2500.0, 1500.0],
            [3600.0, 1200.0, 600.0, 200.0],
        ),
    ));
    r.variants.push(feasible(
        4,
        &["m4", "m6"],
        Class::Counterweights,
        evaluation(24.0, 62.0, ub_f, ub_m),
    ));
    r.variants.push(feasible(
        20,
        &["m6", "K43"],
        Class::Hybrid,
        evaluation(15.0, 51.0, [9500.0, 4000.0, 2500.0, 1500.0], ub_m),
    ));
    let mut d = VariantRecord::new(
        21,
        vec![element("m4"), element("K42")],
        Class::Hybrid,
        Status::Discarded,
    );
    d.reason = Some("mass 620 kg > bound 500 kg".into());
    r.variants.push(d);
    let mut u = VariantRecord::new(
        22,
        vec![element("K52")],
        Class::Springs,
        Status::Unrealizable,
    );
    u.reason = Some("K·W ≠ α·βᵀ <unrealizable>".into());
    r.variants.push(u);
    r.variants.push(VariantRecord::new(
        0,
        vec![element("m1")],
        Class::Counterweights,
        Status::Infeasible,
    ));
    r.variants.push(VariantRecord::new(
        1,
        vec![element("m2")],
        Class::Counterweights,
        Status::Infeasible,
    ));
    let mut g = VariantRecord::new(
        2,
        vec![element("m3"), element("m4")],
        Class::Counterweights,
        Status::Degenerate,
    );
    g.reason = Some("m3 = 0".into());
    r.variants.push(g);
    r.variants.push(VariantRecord::new(
        30,
        vec![element("K21")],
        Class::Springs,
        Status::Undecided,
    ));
    r
}

/// Adds torque curves for UB and the best of each class, and a path simulation.
fn add_curves(r: &mut RunResults) {
    let best: Vec<(usize, String)> = r
        .best_per_class()
        .iter()
        .map(|v| (v.id, v.display_name()))
        .collect();
    let t: Vec<f64> = (0..51).map(|k| k as f64 * 0.05).collect();
    for (a, actuator) in ["M1", "M2", "M3"].iter().enumerate() {
        let mut curves = vec![Curve {
            label: "UB".into(),
            variant: None,
            values: t
                .iter()
                .map(|t| 20.0 + 10.0 * (2.0 * PI * t / 2.5).sin() * (a + 1) as f64)
                .collect(),
        }];
        for (k, (id, name)) in best.iter().enumerate() {
            curves.push(Curve {
                label: name.clone(),
                variant: Some(*id),
                values: t
                    .iter()
                    .map(|t| (8.0 - k as f64) * (2.0 * PI * t / 2.5).sin())
                    .collect(),
            });
        }
        r.torque_charts.push(TorqueChart {
            actuator: actuator.to_string(),
            task: [a, 40],
            critical_for: vec!["CRT of UB".into(), "CPT of UB".into()],
            t: t.clone(),
            curves,
        });
    }
    let x: Vec<f64> = (0..200).map(|k| k as f64 * 0.025).collect();
    let mech = |label: &str, variant: Option<usize>, scale: f64| PathMechanism {
        label: label.into(),
        variant,
        torques: (0..3)
            .map(|a| {
                x.iter()
                    .map(|x| scale * (10.0 + 5.0 * a as f64) * (x + a as f64).sin())
                    .collect()
            })
            .collect(),
    };
    let mut mechanisms = vec![mech("UB", None, 1.0)];
    for (k, (id, name)) in best.iter().enumerate() {
        mechanisms.push(mech(name, Some(*id), 0.4 + 0.1 * k as f64));
    }
    let run = PathRun {
        x_label: "time".into(),
        x_unit: "s".into(),
        x: x.clone(),
        mechanisms: mechanisms.clone(),
    };
    let mut static_run = run.clone();
    static_run.x_label = "path point".into();
    static_run.x_unit = String::new();
    r.path = Some(PathSimulation {
        name: "Λ (A-C-B-E-F-D-A)".into(),
        description: Some("5 s cycle, 150 kg payload picked at C, dropped at F".into()),
        actuators: vec!["M1".into(), "M2".into(), "M3".into()],
        static_run: Some(static_run),
        dynamic_run: Some(run),
        table: Vec::new(),
    });
}

fn full() -> RunResults {
    let mut r = sample();
    r.finalize(&RankingOptions::default()).unwrap();
    add_curves(&mut r);
    r.finalize(&RankingOptions::default()).unwrap();
    r
}

#[test]
fn finalize_computes_indicators_and_ranks() {
    let r = full();
    let by_id = |id| r.variant(id).unwrap();
    // Springs tie on ΔQTR/ΔQIT (−65 %, −44.44 %) and are separated by ΔR.
    let (a, b) = (by_id(10), by_id(11));
    assert!((a.dqtr.unwrap() + 65.0).abs() < 1e-9);
    assert!((a.dqit.unwrap() - (50.0 - 90.0) / 90.0 * 100.0).abs() < 1e-9);
    // ΔR by hand: ΣF = 17000; K42+K43 raises J1 by 100 N and J2 by 100 N → 200/17000·100.
    assert!((a.dr.unwrap() - 200.0 / 17000.0 * 100.0).abs() < 1e-9);
    // K43+K53 raises J2 by 400 N → 400/17000·100 (worse).
    assert!((b.dr.unwrap() - 400.0 / 17000.0 * 100.0).abs() < 1e-9);
    assert_eq!((a.rank, b.rank), (Some(1), Some(2)));
    assert_eq!((a.class_rank, b.class_rank), (Some(1), Some(2)));
    assert_eq!(by_id(20).rank, Some(3));
    assert_eq!(by_id(20).class_rank, Some(1));
    assert_eq!(by_id(3).rank, Some(4));
    assert_eq!(by_id(4).class_rank, Some(2));
    assert_eq!(a.name.as_deref(), Some("SB1"));
    // Counter-weight variant m4+m5: ΔR = 2000/17000·100 + 600/5000·100.
    let dr = 2000.0 / 17000.0 * 100.0 + 600.0 / 5000.0 * 100.0;
    assert!((by_id(3).dr.unwrap() - dr).abs() < 1e-9);
    // Non-feasible variants carry no Phase 3 fields.
    assert!(by_id(21).rank.is_none() && by_id(21).dqtr.is_none());
    // Counts.
    let count = |s| r.counts.iter().find(|c| c.status == s).unwrap().total;
    assert_eq!(count(Status::Feasible), 5);
    assert_eq!(count(Status::Infeasible), 2);
    assert_eq!(count(Status::Discarded), 1);
    assert_eq!(
        r.counts.iter().map(|c| c.total).sum::<usize>(),
        r.variants.len()
    );
    // Path table: UB row has no variation, the others do.
    let p = r.path.as_ref().unwrap();
    assert_eq!(p.table.len(), 3 * 4);
    assert!(p.table[0].rms_variation.is_none());
    assert!((p.table[1].rms_variation.unwrap() + 60.0).abs() < 1e-9);
    assert_eq!(r.best_per_class().len(), 3);
}

#[test]
fn results_round_trip_through_json() {
    let r = full();
    let text = serde_json::to_string_pretty(&r).unwrap();
    let back: RunResults = serde_json::from_str(&text).unwrap();
    assert_eq!(back, r);
    // The required per-variant fields are at the top level of a feasible record.
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let rec = v["variants"]
        .as_array()
        .unwrap()
        .iter()
        .find(|x| x["status"] == "feasible")
        .unwrap();
    for key in ["dqtr", "dqit", "dr", "rank", "class_rank"] {
        assert!(rec.get(key).is_some(), "missing {key}");
    }
    assert_eq!(v["schema_version"], SCHEMA_VERSION);
}

#[test]
fn feasible_without_evaluation_is_an_error() {
    let mut r = sample();
    r.variants[0].evaluation = None;
    assert!(matches!(
        r.finalize(&RankingOptions::default()),
        Err(ResultsError::MissingEvaluation { id: 10, .. })
    ));
}

/// Parses the HTML as XML (fails on any unbalanced tag) and returns the number of `<svg>`
/// elements and of `<table>` elements.
fn check_xhtml(html: &str) -> (usize, usize) {
    let mut reader = quick_xml::Reader::from_str(html);
    let mut stack: Vec<String> = Vec::new();
    let (mut svgs, mut tables) = (0, 0);
    loop {
        match reader.read_event() {
            Ok(Event::Start(e)) => {
                let name = e.name().into_inner().to_string();
                match name.as_str() {
                    "svg" => svgs += 1,
                    "table" => tables += 1,
                    // One inline script (the ranking table's sorting and filtering) is
                    // allowed; nothing that loads from elsewhere.
                    "script" => assert!(
                        e.attributes().all(|a| a.unwrap().key.into_inner() != "src"),
                        "external script"
                    ),
                    "link" | "img" | "iframe" => {
                        panic!("external element <{name}>")
                    }
                    _ => {}
                }
                stack.push(name);
            }
            Ok(Event::End(e)) => {
                let name = e.name().into_inner().to_string();
                assert_eq!(stack.pop().as_deref(), Some(name.as_str()));
            }
            Ok(Event::Empty(e)) => {
                let name = e.name().into_inner().to_string();
                assert!(!["script", "link", "img"].contains(&name.as_str()));
            }
            Ok(Event::Eof) => break,
            Ok(_) => {}
            Err(e) => panic!(
                "report.html is not well-formed at {}: {e}",
                reader.buffer_position()
            ),
        }
    }
    assert!(stack.is_empty(), "unclosed: {stack:?}");
    (svgs, tables)
}

#[test]
fn writes_all_outputs_and_regenerates() {
    let r = full();
    // Set COUNTERPOISE_REPORT_SAMPLE=DIR to keep a copy of the sample report for viewing.
    if let Some(keep) = std::env::var_os("COUNTERPOISE_REPORT_SAMPLE") {
        write_outputs(std::path::Path::new(&keep), &r).unwrap();
    }
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let written = write_outputs(&out, &r).unwrap();
    assert_eq!(written.len(), 4);
    for name in ["results.json", "report.html", "report.md", "ranking.csv"] {
        assert!(out.join(name).is_file(), "{name}");
    }
    // No temporary files left behind.
    assert_eq!(std::fs::read_dir(&out).unwrap().count(), 4);

    let back = read_results(&out).unwrap();
    assert_eq!(back, r);

    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    let (svgs, tables) = check_xhtml(&html);
    // The Pareto chart + one bar chart (the three classes have 2, 2 and 1 ranked variants:
    // fewer than 3 each, so they share it) + 3 torque charts + 3 static + 3 dynamic path charts.
    let charts = counterpoise_report::charts::all(&r);
    assert_eq!(charts.len(), 11);
    assert_eq!(
        charts[1].title,
        "Counterweights only and Springs only and Hybrid — ranking indicators"
    );
    assert_eq!(
        charts[1].svg.matches("<title>SB").count(),
        5 * 3,
        "5 groups of 3 bars"
    );
    // The decision comes first, in both reports.
    let decision = html.find("Which variant to build").unwrap();
    assert!(decision < html.find("<h2>Summary</h2>").unwrap());
    assert!(html.contains(
        "<summary>Balance relations and free directions of the 5 ranked variants</summary>"
    ));
    assert_eq!(svgs, charts.len());
    assert!(tables >= 8);
    assert!(!html.contains("http://") || !html.contains("href="));
    assert!(!html.contains("src="));
    // Case-provided strings are escaped.
    assert!(html.contains("palletizer &lt;test&gt; &amp; &quot;quotes&quot;"));
    assert!(!html.contains("<test>"));
    assert!(html.contains("&lt;unrealizable&gt;"));

    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    let ranking_rows: Vec<&str> = md
        .lines()
        .skip_while(|l| *l != "## Ranking")
        .skip(4)
        .take_while(|l| l.starts_with('|'))
        .collect();
    assert_eq!(ranking_rows.len(), 5, "{md}");
    // SB1 is the springs' and the overall recommendation: its name in bold.
    assert!(
        ranking_rows[0].starts_with("| 1 | **SB1** | K42 + K43 |"),
        "{md}"
    );
    assert!(md.contains("## Optimised parameters (Table 1)"));
    assert!(md.find("## Which variant to build").unwrap() < md.find("## Summary").unwrap());
    // 2 springs of 4535.2 N peak; 228.6 kg per counterweight, 2 of them = 457.2 kg = 38.5 %
    // of 1188.625 kg.
    assert!(md.contains("| 457.2 | 38.5 | 2 |"), "{md}");
    assert!(md.contains("| 4535 |"), "{md}");
    assert!(
        md.contains("| 998.9 | 0 (0.0°) |"),
        "Table 1 anchor in mm and angle"
    );

    let csv = std::fs::read_to_string(out.join("ranking.csv")).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), 6);
    assert_eq!(lines[0], counterpoise_report::csv::HEADER.join(","));
    assert!(lines[1].starts_with("1,1,SB1,10,K42 + K43,springs,"));
    assert!(lines[3].starts_with("3,1,SB3,20,m6 + K43,hybrid,"));

    // regenerate rewrites the reports from results.json alone.
    std::fs::remove_file(out.join("report.html")).unwrap();
    std::fs::write(out.join("report.md"), "stale").unwrap();
    let rewritten = regenerate(&out).unwrap();
    assert_eq!(rewritten.len(), 3);
    assert_eq!(
        std::fs::read_to_string(out.join("report.html")).unwrap(),
        html
    );
    assert_eq!(std::fs::read_to_string(out.join("report.md")).unwrap(), md);
}

#[test]
fn regenerate_rejects_other_schema_versions() {
    let dir = tempfile::tempdir().unwrap();
    let mut v = serde_json::to_value(full()).unwrap();
    v["schema_version"] = json!(99);
    std::fs::write(dir.path().join("results.json"), v.to_string()).unwrap();
    let err = regenerate(dir.path()).unwrap_err();
    assert!(
        matches!(err, OutputError::Schema { found: 99, .. }),
        "{err}"
    );
    assert!(matches!(
        regenerate(&dir.path().join("missing")),
        Err(OutputError::Io { .. })
    ));
}

#[test]
fn empty_run_renders() {
    // No feasible variant, no joints, no curves: still a valid report.
    let mut r = sample();
    r.variants.retain(|v| v.status != Status::Feasible);
    r.unbalanced.joints.clear();
    r.finalize(&RankingOptions::default()).unwrap();
    let html = counterpoise_report::html::render(&r);
    let (svgs, _) = check_xhtml(&html);
    assert_eq!(svgs, 0);
    assert!(html.contains("No feasible balanced variant"));
    let csv = counterpoise_report::csv::render(&r);
    assert_eq!(csv.lines().count(), 1);
}

#[test]
fn output_is_deterministic() {
    let a = full();
    let mut shuffled = sample();
    shuffled.variants.reverse();
    shuffled.finalize(&RankingOptions::default()).unwrap();
    add_curves(&mut shuffled);
    shuffled.finalize(&RankingOptions::default()).unwrap();
    let ranks = |r: &RunResults| {
        let mut v: Vec<(usize, Option<usize>, Option<usize>)> = r
            .variants
            .iter()
            .map(|v| (v.id, v.rank, v.class_rank))
            .collect();
        v.sort();
        v
    };
    assert_eq!(ranks(&a), ranks(&shuffled));
    assert_eq!(
        counterpoise_report::csv::render(&a),
        counterpoise_report::csv::render(&shuffled)
    );
}

#[test]
fn full_ties_are_flagged_and_listed() {
    // Two counterweight variants with identical indicators: the labels decide, and both the
    // records and the ranking info say so.
    let mut r = sample();
    let e = r.variant(4).unwrap().evaluation.clone().unwrap();
    let mut twin = feasible(5, &["m4", "m3"], Class::Counterweights, e);
    twin.relations.clear();
    r.variants.push(twin);
    r.finalize(&RankingOptions::default()).unwrap();
    let (a, b) = (r.variant(4).unwrap(), r.variant(5).unwrap());
    assert!(a.tie_broken_by_label && b.tie_broken_by_label);
    // "m4 + m3" < "m4 + m6".
    assert_eq!(b.rank.unwrap() + 1, a.rank.unwrap());
    assert_eq!(r.ranking.as_ref().unwrap().tie_groups, vec![vec![5, 4]]);
    assert!(!r.variant(3).unwrap().tie_broken_by_label);
    let html = counterpoise_report::html::render(&r);
    assert!(
        html.contains("Tied on all three criteria: SB5 = SB6."),
        "{html}"
    );
}

#[test]
fn reports_state_the_rule_the_stored_order_follows() {
    // After `finalize` the order is in cell order and the reports state the grid rule.
    let mut r = full();
    let grid = "rounded to the nearest multiple of 0.01 percentage points";
    assert!(r.ranking_rule().unwrap().contains(grid));
    assert!(counterpoise_report::html::render(&r).contains(grid));
    assert!(counterpoise_report::markdown::render(&r).contains(grid));
    // A results.json of an earlier version can hold an order the grid does not give: here
    // SB1 (ΔQTR −65 %) and SB3 (m6 + K43, ΔQTR (15 − 40)/40 = −62.5 %) swapped, so −62.5 is
    // ranked above −65. `report DIR` re-renders such a file without re-ranking it, so the
    // reports must not claim the grid rule for it.
    let (first, third) = (r.variant(10).unwrap().rank, r.variant(20).unwrap().rank);
    assert_eq!((first, third), (Some(1), Some(3)));
    for v in &mut r.variants {
        v.rank = match v.rank {
            Some(1) => Some(3),
            Some(3) => Some(1),
            other => other,
        };
    }
    let rule = r.ranking_rule().unwrap();
    assert!(!rule.contains(grid), "{rule}");
    assert!(rule.contains("chained into one tie group"), "{rule}");
    assert!(counterpoise_report::html::render(&r).contains("chained into one tie group"));
}

#[test]
fn critical_tasks_cover_ub_and_best_variants_once() {
    let r = full();
    let tasks = r.critical_tasks();
    // UB: per actuator n, CRT [n, 30+n] and CPT [n+1, 20]; the best variants share them.
    assert_eq!(tasks.len(), 6);
    assert_eq!(tasks[0].actuator_name, "M1");
    assert_eq!(tasks[0].task, [1, 31]);
    assert_eq!(
        tasks[0].critical_for,
        ["CRT of UB", "CRT of SB4", "CRT of SB1", "CRT of SB3"]
    );
    let mut pairs: Vec<_> = tasks.iter().map(|t| (t.actuator, t.task)).collect();
    pairs.dedup();
    assert_eq!(pairs.len(), 6);
}

#[test]
fn terminal_summary() {
    let r = full();
    let s = counterpoise_report::text::summary(&r);
    assert!(s.contains("11 variants examined (Dmax = 2)"), "{s}");
    assert!(s.contains("5 feasible, 1 discarded"), "{s}");
    assert!(
        s.lines()
            .any(|l| l.trim_start().starts_with("Springs only") && l.contains("SB1")),
        "{s}"
    );
    // The ranking section lists the five feasible variants, once each, in rank order.
    let ranking: Vec<&str> = s
        .lines()
        .skip_while(|l| !l.starts_with("Ranking (top 5):"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .collect();
    assert_eq!(ranking.len(), 1 + 5, "header and five rows: {s}");
    // The optimiser's columns are explained under the table.
    assert!(
        s.contains("\nMass: added mass; Spring: peak spring force; Gap:"),
        "{s}"
    );
    // Within a 120-column terminal (issue 31: it was 174 wide).
    assert!(s.lines().all(|l| l.chars().count() <= 120), "{s}");
    // The overall recommendation is stated.
    assert!(s.contains("\nRecommended: "), "{s}");
    let mut ranked: Vec<(usize, String)> = r
        .variants
        .iter()
        .filter_map(|v| v.rank.map(|k| (k, v.label())))
        .collect();
    ranked.sort();
    assert_eq!(ranked.len(), 5);
    for (line, (rank, label)) in ranking[1..].iter().zip(&ranked) {
        assert!(
            line.contains(&format!("SB{rank}")) && line.contains(label.as_str()),
            "SB{rank} {label} in `{line}`"
        );
    }
    // Columns line up: the Gap column (numeric, right-aligned) ends at the same place on
    // every line of the section.
    let gap_end = ranking[0].find("Gap").unwrap() + 3;
    for line in &ranking[1..] {
        let head: String = line
            .chars()
            .take(ranking[0][..gap_end].chars().count())
            .collect();
        assert!(
            head.ends_with(|c: char| c.is_ascii_digit()),
            "`{line}`\n{s}"
        );
    }
}

#[test]
fn aligned_columns_match_a_hand_layout() {
    use counterpoise_report::tables::{Cell, Table};
    // Widths by hand: "Variant" 7 ≥ "K42 + K43" 9 → 9; "ΔQTR" 4 ≤ "−63.20" 6 → 6.
    // Text is left-aligned, numbers right-aligned, columns joined by two spaces, lines indented
    // by two and trimmed at the end.
    let t = Table {
        header: vec!["Variant".into(), "ΔQTR".into(), "Note".into()],
        rows: vec![
            vec![Cell::text("m4"), Cell::num("−5.00"), Cell::text("")],
            vec![
                Cell::text("K42 + K43"),
                Cell::num("−63.20"),
                Cell::text("tie"),
            ],
        ],
        group_starts: vec![false, false],
        highlighted: vec![false, false],
    };
    assert_eq!(
        counterpoise_report::text::aligned(&t),
        "  Variant      ΔQTR  Note\n  m4          −5.00\n  K42 + K43  −63.20  tie\n"
    );
}

#[test]
fn charts_and_tables_follow_the_recommendation() {
    // At a 5 pp tolerance the counterweights' recommendation is no longer their best-ranked
    // variant. By hand: SB5 (m4 + m6: ΔQTR −40, ΔQIT −31.11) is within 5 pp of SB4 (m4 + m5:
    // −45, −33.33); both add 457.2 kg; ΔR 0.00 against 23.76, so SB5. Springs: SB1 and SB2
    // tie on mass, ΔR 1.18 and 2.35 are within 5, same parts and force, so the rank: SB1.
    // Hybrid: SB3 alone. Overall: SB1 and SB2 add no mass, then as the springs: SB1.
    let mut r = full();
    r.redecide(5.0);
    let name = |id: usize| r.variant(id).unwrap().name.clone().unwrap();
    let mut recommended: Vec<String> = r.recommended_ids().into_iter().map(name).collect();
    recommended.sort();
    assert_eq!(recommended, ["SB1", "SB3", "SB5"]);
    // Shown: per class (counterweights, springs, hybrid) the best-ranked, then the
    // recommendation where different.
    let shown: Vec<String> = r
        .shown_variants()
        .iter()
        .map(|v| v.name.clone().unwrap())
        .collect();
    assert_eq!(shown, ["SB4", "SB5", "SB1", "SB3"]);
    let labels: Vec<String> = r
        .shown_variants()
        .iter()
        .map(|v| r.shown_label(v))
        .collect();
    assert_eq!(
        labels,
        [
            "SB4 (m4 + m5)",
            "SB5 (m4 + m6), recommended",
            "SB1 (K42 + K43), recommended",
            "SB3 (m6 + K43), recommended"
        ]
    );
    // The recommended SB5 has its critical tasks among those to chart.
    assert!(
        r.critical_tasks()
            .iter()
            .any(|c| c.critical_for.iter().any(|w| w.ends_with("of SB5")))
    );
    // Highlighted rows: the ranking and practical tables one row per recommended variant,
    // Table 1 one row per element of them (SB1: 2, SB3: 2, SB5: 2).
    let html = counterpoise_report::html::render(&r);
    let rows = |t: &counterpoise_report::tables::Table| -> Vec<String> {
        t.rows
            .iter()
            .zip(&t.highlighted)
            .filter(|(_, h)| **h)
            .map(|(row, _)| row[1].text.clone())
            .collect()
    };
    let ranking = counterpoise_report::tables::ranking(&r);
    assert_eq!(rows(&ranking), ["SB1", "SB3", "SB5"]);
    assert_eq!(
        counterpoise_report::tables::parameters(&r)
            .highlighted
            .iter()
            .filter(|h| **h)
            .count(),
        6
    );
    assert!(html.contains("the recommended variants (SB1, SB3, SB5)"));
    assert_eq!(
        html.matches("<tr class=\"rec\">").count() + html.matches("<tr class=\"g rec\">").count(),
        3 + 3 + 6 + counterpoise_report::tables::spring_specs(&r).rows.len(),
        "ranking, practical figures, Table 1, the spring specifications (all recommended)"
    );
}
