//! Phase 3 of counterpoise (DESIGN §2, §7; Martini et al. 2019, Sec. 2.3 and 3.2–3.3): the
//! ranking indicators, the rankings, the versioned results document and the reports.
//!
//! Data flow: the `run` command fills a [`RunResults`] (plain serde types, independent of the
//! search, dynamics and optimiser crates so the document's schema is owned here), calls
//! [`RunResults::finalize`] (ΔQTR, ΔQIT, ΔR, ranks, counts, tables), then [`write_outputs`]
//! (results.json, report.html, report.md, ranking.csv, each written atomically).
//! `counterpoise report DIR` calls [`regenerate`].
//!
//! Modules, one job each: [`indicators`] (Eqs. 15–21), [`ranking`] (lexicographic order at a
//! resolution), [`results`] (the schema and `finalize`), [`tables`] (the tables both reports
//! share), [`svg`] (hand-written charts), [`charts`] (which charts), [`html`], [`markdown`],
//! [`csv`], [`text`] (terminal summary), [`output`] (atomic files), [`format`] (numbers and
//! escaping).

pub mod charts;
pub mod csv;
pub mod format;
pub mod html;
pub mod indicators;
pub mod markdown;
pub mod output;
pub mod ranking;
pub mod results;
pub mod svg;
pub mod tables;
pub mod text;

pub use indicators::{
    DeltaR, IndicatorError, JointReaction, JointVariation, delta_r, percent_variation,
};
pub use output::{OutputError, read_results, regenerate, write_atomic, write_outputs};
pub use ranking::{Class, RankItem, Ranking, RankingError, RankingOptions, rank};
pub use results::{
    ActuatorSummary, CounterweightParams, CriticalTask, Curve, ElementInfo, ElementKind,
    Evaluation, FreeDirection, JointPeak, OptimiserInfo, PathMechanism, PathRun, PathSimulation,
    PathStat, PhaseTiming, PhysicalParameters, Plane, RankingInfo, ResultsError, RunMetadata,
    RunResults, SCHEMA_VERSION, SpringParams, StatusCount, TaskRef, TorqueChart, VariantRecord,
    VariantStatus,
};
