//! Phase 3 of counterpoise (docs/design.md §2, §7; Martini et al. 2019, Sec. 2.3 and 3.2–3.3): the
//! ranking indicators, the rankings, the versioned results document and the reports.
//!
//! Data flow: the `run` command fills a [`RunResults`] (plain serde types, independent of the
//! search, dynamics and optimiser crates so the document's schema is owned here), calls
//! [`RunResults::finalize`] (ΔQTR, ΔQIT, ΔR, ranks, counts, tables), then [`write_outputs`]
//! (results.json, report.html, report.md, ranking.csv, each written atomically).
//! `counterpoise report DIR` calls [`regenerate`].
//!
//! ```
//! use counterpoise_report::*;
//!
//! let metadata = RunMetadata {
//!     tool: "counterpoise".into(), tool_version: "0.1.0".into(),
//!     case_name: "pendulum".into(), case_path: "cases/pendulum.json".into(),
//!     dmax: 1, jobs: 2, shards: None, shard_timings: Vec::new(), date: "2026-11-22T00:00:00Z".into(),
//!     timings: vec![PhaseTiming { phase: "search".into(), seconds: 0.01 }], notes: vec![],
//! };
//! let eval = |qtr: f64| Evaluation {
//!     qtr, qtr_task: [0, 1], qit: 2.0 * qtr, qit_task: [0, 1], actuators: vec![],
//!     joints: vec![JointPeak { name: "J1".into(), force: 100.0, force_task: None,
//!                              moment: 10.0 * qtr, moment_task: None }],
//!     tasks: 1, excluded_tasks: 0, reactions_minimum_norm: false,
//! };
//! let mut results = RunResults::new(metadata, serde_json::json!({}), eval(10.0));
//! let element = ElementInfo { label: "m1".into(), kind: ElementKind::Counterweight,
//!                             bodies: vec!["arm".into()] };
//! let mut v = VariantRecord::new(0, vec![element], Class::Counterweights, Status::Feasible);
//! v.evaluation = Some(eval(4.0));
//! results.variants.push(v);
//! results.finalize(&RankingOptions::default())?;        // ΔQTR = −60 %, rank 1
//! assert_eq!(results.variants[0].dqtr, Some(-60.0));
//! // Torque curves: for each `results.critical_tasks()`, compute the series of UB and of
//! // `results.shown_variants()` (best-ranked and recommended), push a `TorqueChart`, then
//! // `finalize` again (idempotent).
//! let dir = std::env::temp_dir().join(format!("cp-report-doc-{}", std::process::id()));
//! write_outputs(&dir, &results)?;                        // results.json, report.html, …
//! print!("{}", text::summary(&results));                  // the run command's stdout table
//! regenerate(&dir)?;                                      // `counterpoise report DIR`
//! # std::fs::remove_dir_all(&dir).ok();
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! Modules, one job each: [`indicators`] (Eqs. 15–21), [`ranking`] (lexicographic order at a
//! resolution), [`practical`] (added mass, element count, spring and offset peaks),
//! [`decision`] (equivalence groups and recommendations), [`partial`] (the partial balancing
//! when nothing is feasible), [`honest`] (idle elements,
//! parameters on a bound), [`schematic`] (drawings of variants), [`springspec`] (what to order
//! for each spring), [`results`] (the schema and
//! `finalize`), [`tables`] (the tables both reports
//! share), [`svg`] (hand-written charts), [`charts`] (which charts), [`html`], [`markdown`],
//! [`csv`], [`text`] (terminal summary), [`output`] (atomic files), [`format`] (numbers and
//! escaping).

pub mod charts;
pub mod csv;
pub mod decision;
pub mod format;
pub mod honest;
pub mod html;
/// The paper's indicators (Eqs. 15–21) are shared vocabulary: the optimiser chooses springs by ΔR.
pub use counterpoise_vocabulary::indicators;
pub mod labels;
pub mod markdown;
pub mod output;
pub mod parameters;
pub mod partial;
pub mod partial_view;
pub mod practical;
pub mod ranking;
pub mod results;
pub mod schematic;
pub mod schematic_svg;
pub mod springspec;
pub mod svg;
pub mod tables;
pub mod text;
pub mod variant;

pub use decision::{Decision, Recommendation, decide};
pub use honest::ElementBounds;
pub use indicators::{
    DeltaR, IndicatorError, JointReaction, JointVariation, delta_r, percent_variation,
};
pub use output::{
    OutputError, read_results, regenerate, regenerate_with, write_atomic, write_outputs,
    write_reports,
};
pub use partial::{PartialBalancing, PartialDesign, PartialElement};
pub use practical::{PracticalFigures, SpringPeak};
pub use ranking::{Class, RankItem, Ranking, RankingError, RankingOptions, rank};
pub use results::{
    ActuatorSummary, Counterweight, CriticalTask, Curve, ElementInfo, ElementKind, EnergyChart,
    Evaluation, FreeDirection, JointPeak, OptimiserInfo, PathMechanism, PathRun, PathSimulation,
    PathStat, PhaseTiming, PhysicalParameters, Plane, RankingInfo, ResultsError, RunMetadata,
    RunResults, SCHEMA_VERSION, Spring, Status, StatusCount, TaskRef, TorqueChart, VariantRecord,
};
pub use schematic::{DrawnBody, DrawnCounterweight, DrawnJoint, DrawnSpring, Schematic};
