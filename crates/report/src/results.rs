//! The results document (`results.json`): a versioned, self-describing record of a run that the
//! reports are rendered from, so `counterpoise report DIR` can rebuild them without the case.
//!
//! The caller (the `run` command) fills a [`RunResults`] with what the earlier phases produced —
//! metadata, the case echo, the unbalanced indicators, every variant examined with its status and,
//! for feasible ones, physical parameters and re-evaluated indicators, then torque curves and an
//! optional path simulation — and calls [`RunResults::finalize`], which computes the Phase 3
//! fields (ΔQTR, ΔQIT, ΔR, ranks, counts, tables). `finalize` is idempotent: call it, add the
//! practical figures, call it again (the recommendation reads them), ask
//! [`RunResults::shown_variants`] which variants need torque curves, add them, call it again.
//!
//! Units are SI throughout the document (kg, m, N/m, N, N·m, s, rad); the reports convert to
//! the paper's display units (mm, N/mm). Changes that rename or remove fields bump
//! [`SCHEMA_VERSION`]; see `docs/results-schema.md`.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::decision::{Decision, decide};
use crate::honest::{ElementBounds, idle_elements};
use crate::indicators::{IndicatorError, delta_r, percent_variation};
use crate::ranking::{Class, RankItem, RankingError, RankingOptions, rank};
use crate::schematic::Schematic;

pub use crate::parameters::{
    Counterweight, ElementInfo, ElementKind, FreeDirection, PhysicalParameters, Plane, Spring,
};
pub use crate::variant::{
    ActuatorSummary, Evaluation, JointPeak, OptimiserInfo, Status, TaskRef, VariantRecord,
};

/// Version of the results.json layout.
/// Version 2 added the practical figures (`practical`), the moving mass and the decision.
pub const SCHEMA_VERSION: u32 = 2;

/// Why results cannot be finalised.
#[derive(Debug, Error)]
pub enum ResultsError {
    #[error("variant {id} ({label}) is feasible but has no evaluation")]
    MissingEvaluation { id: usize, label: String },
    #[error("variant {id} ({label}): {source}")]
    Indicator {
        id: usize,
        label: String,
        #[source]
        source: IndicatorError,
    },
    #[error(transparent)]
    Ranking(#[from] RankingError),
    #[error("path simulation {name}: {what}")]
    Path { name: String, what: String },
}

/// A task on which an actuator's torque curve is worth showing (see
/// [`RunResults::critical_tasks`]).
#[derive(Clone, Debug, PartialEq)]
pub struct CriticalTask {
    /// Actuator index (order of `unbalanced.actuators`, i.e. the case's).
    pub actuator: usize,
    pub actuator_name: String,
    pub task: TaskRef,
    /// e.g. `["CRT of UB", "CPT of UB", "CRT of SB1"]`; goes into [`TorqueChart::critical_for`].
    pub critical_for: Vec<String>,
}

/// Wall time of one phase.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PhaseTiming {
    pub phase: String,
    pub seconds: f64,
}

/// Who ran what, when, and how long it took.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunMetadata {
    /// `counterpoise` and its version.
    pub tool: String,
    pub tool_version: String,
    pub case_name: String,
    pub case_path: String,
    pub dmax: usize,
    /// Worker threads (results do not depend on it).
    pub jobs: usize,
    /// N when the results were merged from N shards (`counterpoise merge`); absent for a
    /// single run. The results do not depend on it either.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shards: Option<usize>,
    /// Timestamp supplied by the caller (e.g. RFC 3339, UTC); kept verbatim.
    pub date: String,
    pub timings: Vec<PhaseTiming>,
    /// For merged results, the phases of each shard (named `shard I/N: …`): they ran
    /// elsewhere and in parallel, so they are not part of this run's wall time.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub shard_timings: Vec<PhaseTiming>,
    /// Anything else the designer should know (e.g. "reactions are minimum-norm").
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
}

/// Number of variants with one status, per class.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StatusCount {
    pub status: Status,
    pub counterweights: usize,
    pub springs: usize,
    pub hybrid: usize,
    pub total: usize,
}

/// How the ranking was made (stated in the reports).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RankingInfo {
    pub resolution: f64,
    pub criteria: Vec<String>,
    pub tie_break: String,
    /// Variant ids tied on all three criteria, in rank order.
    pub tie_groups: Vec<Vec<usize>>,
}

/// One curve of a chart: a mechanism's values on a shared abscissa.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Curve {
    /// `UB` or the variant's display name.
    pub label: String,
    /// Variant id, `None` for the unbalanced robot.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub variant: Option<usize>,
    pub values: Vec<f64>,
}

/// Motor torque of one actuator along one task for several mechanisms (Fig. 10-style).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TorqueChart {
    pub actuator: String,
    pub task: TaskRef,
    /// Why this task is shown, e.g. `["CRT of UB", "CPT of UB"]`.
    pub critical_for: Vec<String>,
    /// Time, s.
    pub t: Vec<f64>,
    /// Motor torque, N·m, one curve per mechanism (UB first).
    pub curves: Vec<Curve>,
}

/// Torques of several mechanisms along a path, per actuator.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PathRun {
    /// Abscissa label and unit, e.g. ("time", "s") or ("path point", "").
    pub x_label: String,
    pub x_unit: String,
    pub x: Vec<f64>,
    /// For each mechanism (UB first), motor torque per actuator: `torques[actuator][sample]`.
    pub mechanisms: Vec<PathMechanism>,
}

/// One mechanism's motor torques along a path.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PathMechanism {
    pub label: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub variant: Option<usize>,
    /// N·m, `[actuator][sample]`.
    pub torques: Vec<Vec<f64>>,
}

/// One row of the Table 2-style statistics: RMS and |peak| of one actuator for one mechanism.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PathStat {
    pub actuator: String,
    pub mechanism: String,
    /// N·m.
    pub rms: f64,
    pub peak: f64,
    /// Percent variation vs the unbalanced robot (`None` for UB itself or a zero reference).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rms_variation: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub peak_variation: Option<f64>,
}

/// The paper's Sec. 3.3 simulation: static and dynamic motor torques along a named path.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PathSimulation {
    pub name: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub description: Option<String>,
    pub actuators: Vec<String>,
    /// Static torques (velocities and accelerations zero) along the path.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub static_run: Option<PathRun>,
    /// The timed cycle (Fig. 10).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dynamic_run: Option<PathRun>,
    /// Table 2 of the dynamic run, filled by `finalize`.
    #[serde(default)]
    pub table: Vec<PathStat>,
}

/// The whole results document.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunResults {
    pub schema_version: u32,
    pub metadata: RunMetadata,
    /// The case file as read (JSON).
    pub case: serde_json::Value,
    /// Phase 1: the unbalanced robot.
    pub unbalanced: Evaluation,
    /// Every variant examined, in enumeration order.
    pub variants: Vec<VariantRecord>,
    /// Filled by `finalize`.
    #[serde(default)]
    pub counts: Vec<StatusCount>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ranking: Option<RankingInfo>,
    #[serde(default)]
    pub torque_charts: Vec<TorqueChart>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub path: Option<PathSimulation>,
    /// Sum of the bodies' masses (every body moves; payloads excluded), kg: the reference of
    /// the added-mass shares.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub moving_mass: Option<f64>,
    /// Where the peak spring forces and stretches were taken, in words.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spring_peaks_basis: Option<String>,
    /// Equivalence groups and recommendations (filled by `finalize`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub decision: Option<Decision>,
    /// The bounds each element was optimised within, to mark parameters on a bound (filled
    /// by the caller; see [`crate::honest`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub element_bounds: Vec<ElementBounds>,
    /// Drawings of the recommended variants and of any the user named (`report --draw`),
    /// geometry from the model's kinematics (filled by the caller; see [`crate::schematic`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub schematics: Vec<Schematic>,
    /// Potential energy of the unbalanced mechanism and of the recommended variants along a
    /// path (filled by the caller): flat for a balanced variant.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub energy: Option<EnergyChart>,
    /// What `run` found when no variant is feasible: the smallest Dmax that balances and the
    /// best partial balancing (filled by the caller; see [`crate::partial`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub partial: Option<crate::partial::PartialBalancing>,
}

/// Potential energy (gravity and springs) along one motion, relative to its first sample, per
/// mechanism: the unbalanced mechanism first, then variants. A balanced variant's curve is
/// flat (its energy is constant), which is the whole point of static balancing.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EnergyChart {
    /// What the motion is, in words (`path Lambda`, `task 0→8`).
    pub along: String,
    /// What the energy counts, in words (e.g. which payloads).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
    /// Time, s.
    pub t: Vec<f64>,
    /// J, `V(t) − V(0)`.
    pub curves: Vec<Curve>,
}

impl RunResults {
    /// A document with the current schema version and no variants, charts or path yet.
    pub fn new(metadata: RunMetadata, case: serde_json::Value, unbalanced: Evaluation) -> Self {
        RunResults {
            schema_version: SCHEMA_VERSION,
            metadata,
            case,
            unbalanced,
            variants: Vec::new(),
            counts: Vec::new(),
            ranking: None,
            torque_charts: Vec::new(),
            path: None,
            moving_mass: None,
            spring_peaks_basis: None,
            decision: None,
            element_bounds: Vec::new(),
            schematics: Vec::new(),
            energy: None,
            partial: None,
        }
    }

    /// Computes counts, ΔQTR/ΔQIT/ΔR, ranks, names and the path table. Idempotent.
    pub fn finalize(&mut self, options: &RankingOptions) -> Result<(), ResultsError> {
        self.counts = count_statuses(&self.variants);
        let ub_joints = self.unbalanced.reactions();
        let mut items = Vec::new();
        let mut ranked = Vec::new();
        for (index, v) in self.variants.iter_mut().enumerate() {
            v.name = None;
            v.dqtr = None;
            v.dqit = None;
            v.dr = None;
            v.dr_terms = None;
            v.rank = None;
            v.class_rank = None;
            v.tie_broken_by_label = false;
            if v.status != Status::Feasible {
                continue;
            }
            let label = v.label();
            let wrap = |source| ResultsError::Indicator {
                id: v.id,
                label: label.clone(),
                source,
            };
            let Some(eval) = &v.evaluation else {
                return Err(ResultsError::MissingEvaluation { id: v.id, label });
            };
            let dqtr = percent_variation(eval.qtr, self.unbalanced.qtr, "QTR").map_err(wrap)?;
            let dqit = percent_variation(eval.qit, self.unbalanced.qit, "QIT").map_err(wrap)?;
            let dr = delta_r(&ub_joints, &eval.reactions()).map_err(wrap)?;
            items.push(RankItem {
                key: label,
                class: v.class,
                dqtr,
                dqit,
                dr: dr.value,
            });
            v.dqtr = Some(dqtr);
            v.dqit = Some(dqit);
            v.dr = Some(dr.value);
            v.dr_terms = Some(dr);
            ranked.push(index);
        }
        let ranking = rank(&items, options)?;
        for (k, &index) in ranked.iter().enumerate() {
            let v = &mut self.variants[index];
            v.rank = Some(ranking.rank[k]);
            v.class_rank = Some(ranking.class_rank[k]);
            v.name = Some(format!("SB{}", ranking.rank[k]));
        }
        for group in &ranking.tie_groups {
            for &k in group {
                self.variants[ranked[k]].tie_broken_by_label = true;
            }
        }
        self.ranking = Some(RankingInfo {
            resolution: options.resolution,
            criteria: vec!["dqtr".into(), "dqit".into(), "dr".into()],
            tie_break: "variants in the same cell on all three criteria are ordered by their \
                        element labels (ascending)"
                .into(),
            tie_groups: ranking
                .tie_groups
                .iter()
                .map(|g| g.iter().map(|&k| self.variants[ranked[k]].id).collect())
                .collect(),
        });
        self.mark_idle();
        self.decision = Some(decide(&self.ranked(), options.tolerance, self.moving_mass));
        if let Some(path) = &mut self.path {
            path.table = match &path.dynamic_run {
                Some(run) => path_table(&path.name, &path.actuators, run)?,
                None => Vec::new(),
            };
        }
        Ok(())
    }

    /// Recomputes the path simulation's Table 2 from its dynamic run (after the caller
    /// replaced the run).
    pub fn finalize_path(&mut self) -> Result<(), ResultsError> {
        if let Some(path) = &mut self.path {
            path.table = match &path.dynamic_run {
                Some(run) => path_table(&path.name, &path.actuators, run)?,
                None => Vec::new(),
            };
        }
        Ok(())
    }

    /// Recomputes only the decision, at another tolerance (`counterpoise report --tolerance`).
    pub fn redecide(&mut self, tolerance: f64) {
        self.mark_idle();
        self.decision = Some(decide(&self.ranked(), tolerance, self.moving_mass));
    }

    /// Marks the idle elements of every feasible variant ([`crate::honest`]).
    pub fn mark_idle(&mut self) {
        let g = self.gravity();
        let moving_mass = self.moving_mass;
        for v in &mut self.variants {
            v.idle = match (&v.parameters, v.status) {
                (Some(p), Status::Feasible) => {
                    idle_elements(p, v.practical.as_ref(), moving_mass, g)
                }
                _ => Vec::new(),
            };
        }
    }

    /// |g| of the case echo, m/s² (9.81 when the echo has none).
    pub fn gravity(&self) -> f64 {
        let g: Option<f64> = self
            .case
            .get("gravity")
            .and_then(|g| g.as_array())
            .map(|a| {
                a.iter()
                    .filter_map(|x| x.as_f64())
                    .map(|x| x * x)
                    .sum::<f64>()
                    .sqrt()
            });
        g.filter(|g| *g > 0.0 && g.is_finite()).unwrap_or(9.81)
    }

    /// The bounds of element `label`, when recorded.
    pub fn bounds_of(&self, label: &str) -> Option<&ElementBounds> {
        self.element_bounds.iter().find(|b| b.label == label)
    }

    /// Feasible variants in global rank order (after `finalize`).
    pub fn ranked(&self) -> Vec<&VariantRecord> {
        let mut v: Vec<&VariantRecord> =
            self.variants.iter().filter(|v| v.rank.is_some()).collect();
        v.sort_by_key(|v| v.rank);
        v
    }

    /// The ranking rule in words, as the reports state it (`None` before `finalize`).
    ///
    /// `counterpoise report DIR` re-renders a results.json without ranking it again, and one
    /// written by an earlier version holds an order made by chaining values closer than the
    /// resolution ([`crate::ranking`] says why that was replaced). So the rule stated is the
    /// one the stored order follows: the grid rule when every rank is in cell order (always
    /// for results this version writes), else the chained rule, with what it can do.
    pub fn ranking_rule(&self) -> Option<String> {
        let info = self.ranking.as_ref()?;
        let res = info.resolution;
        let cells = |v: &VariantRecord| -> [f64; 3] {
            [v.dqtr, v.dqit, v.dr].map(|x| crate::ranking::cell(x.unwrap_or(0.0), res))
        };
        let ranked = self.ranked();
        let follows_grid = ranked.windows(2).all(|w| {
            let (a, b) = (cells(w[0]), cells(w[1]));
            a.iter()
                .zip(&b)
                .fold(std::cmp::Ordering::Equal, |o, (x, y)| {
                    o.then_with(|| x.total_cmp(y))
                })
                .is_le()
        });
        Some(if follows_grid {
            crate::ranking::rule_text(res)
        } else {
            format!(
                "Variants are ordered by ΔQTR, then ΔQIT, then ΔR, lower first, by the rule of \
                 the version that wrote these results: values whose gaps to their neighbours \
                 are below {res} percentage points were chained into one tie group, so a \
                 variant can be ranked above one that is better by more than {res} percentage \
                 points on the criterion that decides them. Run again to rank by the current \
                 rule (values rounded to a fixed grid)."
            )
        })
    }

    /// The best variant of each class that has one (after `finalize`), in class order.
    pub fn best_per_class(&self) -> Vec<&VariantRecord> {
        Class::ALL
            .iter()
            .filter_map(|&c| {
                self.variants
                    .iter()
                    .find(|v| v.class == c && v.class_rank == Some(1))
            })
            .collect()
    }

    /// Ids of the recommended variants (after `finalize`): the overall recommendation, then
    /// each class's, each once.
    pub fn recommended_ids(&self) -> Vec<usize> {
        let mut ids: Vec<usize> = Vec::new();
        if let Some(d) = &self.decision {
            for rec in d.overall.iter().chain(&d.classes) {
                if !ids.contains(&rec.chosen) {
                    ids.push(rec.chosen);
                }
            }
        }
        ids
    }

    /// The variants the torque curves and the path simulation show (after `finalize`): per
    /// class, the best-ranked one and, where different, the class's recommendation; then the
    /// overall recommendation if no class brought it. The report leads with the
    /// recommendation, so the design one would build must have its curves; the best-ranked
    /// stays beside it as the paper's reference. Call it after the practical figures are in
    /// (the decision reads them) and `finalize` again.
    pub fn shown_variants(&self) -> Vec<&VariantRecord> {
        let decision = self.decision.as_ref();
        let class_choice = |c: Class| {
            decision
                .and_then(|d| d.classes.iter().find(|r| r.class == Some(c)))
                .and_then(|r| self.variant(r.chosen))
        };
        let overall = decision
            .and_then(|d| d.overall.as_ref())
            .and_then(|r| self.variant(r.chosen));
        let candidates = self
            .best_per_class()
            .into_iter()
            .flat_map(|best| [Some(best), class_choice(best.class)])
            .chain([overall])
            .flatten();
        let mut out: Vec<&VariantRecord> = Vec::new();
        for v in candidates {
            if v.rank.is_some() && !out.iter().any(|o| o.id == v.id) {
                out.push(v);
            }
        }
        out
    }

    /// The name of a shown variant in chart legends and the path table: its display name
    /// (`SB6 (K42 + K43)`), with `, recommended` when it is one of the recommendations.
    pub fn shown_label(&self, v: &VariantRecord) -> String {
        if self.recommended_ids().contains(&v.id) {
            format!("{}, recommended", v.display_name())
        } else {
            v.display_name()
        }
    }

    /// The (actuator, task) pairs whose torque curves the report should show: the critical RMS
    /// and peak tasks of every actuator of the unbalanced robot and of every shown variant
    /// ([`RunResults::shown_variants`]: the best-ranked and the recommended of each class)
    /// (after `finalize`), each pair once, with every reason it is critical. In actuator order,
    /// then in order of first mention.
    pub fn critical_tasks(&self) -> Vec<CriticalTask> {
        let mut out: Vec<CriticalTask> = Vec::new();
        let mut mechanisms = vec![("UB".to_string(), &self.unbalanced)];
        for v in self.shown_variants() {
            if let (Some(name), Some(e)) = (&v.name, &v.evaluation) {
                mechanisms.push((name.clone(), e));
            }
        }
        for (a, actuator) in self.unbalanced.actuators.iter().enumerate() {
            for (who, eval) in &mechanisms {
                let Some(act) = eval.actuators.get(a) else {
                    continue;
                };
                for (task, kind) in [(act.crt, "CRT"), (act.cpt, "CPT")] {
                    let why = format!("{kind} of {who}");
                    match out.iter_mut().find(|c| c.actuator == a && c.task == task) {
                        Some(c) => c.critical_for.push(why),
                        None => out.push(CriticalTask {
                            actuator: a,
                            actuator_name: actuator.name.clone(),
                            task,
                            critical_for: vec![why],
                        }),
                    }
                }
            }
        }
        out
    }

    /// Look a variant up by id.
    pub fn variant(&self, id: usize) -> Option<&VariantRecord> {
        self.variants.iter().find(|v| v.id == id)
    }
}

fn count_statuses(variants: &[VariantRecord]) -> Vec<StatusCount> {
    let mut map: BTreeMap<Status, [usize; 3]> = BTreeMap::new();
    for v in variants {
        let c = Class::ALL.iter().position(|&c| c == v.class).unwrap_or(0);
        map.entry(v.status).or_default()[c] += 1;
    }
    Status::STUDY_VERDICTS
        .iter()
        .map(|&status| {
            let n = map.get(&status).copied().unwrap_or_default();
            StatusCount {
                status,
                counterweights: n[0],
                springs: n[1],
                hybrid: n[2],
                total: n.iter().sum(),
            }
        })
        .collect()
}

/// RMS (`sqrt(mean τ²)`, all samples equally weighted, as in the dynamics crate) and |peak|.
pub fn rms_peak(values: &[f64]) -> (f64, f64) {
    if values.is_empty() {
        return (0.0, 0.0);
    }
    let sum_sq: f64 = values.iter().map(|v| v * v).sum();
    let peak = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    ((sum_sq / values.len() as f64).sqrt(), peak)
}

/// Table 2: per actuator, per mechanism, RMS and |peak| with variations vs the first mechanism
/// (the unbalanced robot).
pub fn path_table(
    name: &str,
    actuators: &[String],
    run: &PathRun,
) -> Result<Vec<PathStat>, ResultsError> {
    let bad = |what: String| ResultsError::Path {
        name: name.to_string(),
        what,
    };
    for m in &run.mechanisms {
        if m.torques.len() != actuators.len() {
            return Err(bad(format!(
                "{} has {} torque series for {} actuators",
                m.label,
                m.torques.len(),
                actuators.len()
            )));
        }
        if let Some(s) = m.torques.iter().find(|s| s.len() != run.x.len()) {
            return Err(bad(format!(
                "{} has a series of {} samples, the abscissa has {}",
                m.label,
                s.len(),
                run.x.len()
            )));
        }
    }
    let mut rows = Vec::new();
    for (a, actuator) in actuators.iter().enumerate() {
        let reference = run.mechanisms.first().map(|m| rms_peak(&m.torques[a]));
        for (k, m) in run.mechanisms.iter().enumerate() {
            let (rms, peak) = rms_peak(&m.torques[a]);
            let variation = |value: f64, reference: f64| {
                (k > 0 && reference > 0.0).then(|| (value - reference) / reference * 100.0)
            };
            let (ref_rms, ref_peak) = reference.unwrap_or((0.0, 0.0));
            rows.push(PathStat {
                actuator: actuator.clone(),
                mechanism: m.label.clone(),
                rms,
                peak,
                rms_variation: variation(rms, ref_rms),
                peak_variation: variation(peak, ref_peak),
            });
        }
    }
    Ok(rows)
}
