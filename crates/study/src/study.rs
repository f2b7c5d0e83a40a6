//! The case study as a typed pipeline: Phase 1 (the unbalanced robot over every task), Phase 2
//! (the exact balance search, then the optimisation of every balanced variant re-evaluated over
//! all tasks), Phase 3 (ranking, practical figures, torque curves, path simulation, schematics).
//!
//! A single run is [`Study::run`]. A sharded study optimises each shard's variants with
//! [`Study::run_shard`]; [`crate::merge::merge`] then runs Phase 3 on every shard's records
//! through [`Study::finish`], the same function a single run ends with.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use counterpoise_balance::{
    Catalogue, SearchOptions, SearchReport, Status, VariantResult, catalogue_options,
    mechanism_energy, realization_hints, search,
};
use counterpoise_dynamics::{EvaluateOptions, Indicators, evaluate_unbalanced_grid};
use counterpoise_model::{Model, ModelError};
use counterpoise_optimise::{
    Context, FinalReactionSolve, LoopTorques, Objective, OptimiseOptions, optimise_all_reporting,
};
use counterpoise_report as report;
use report::{PhaseTiming, RankingOptions, RunMetadata, RunResults};

use crate::error::{Result, StudyError, invalid};
use crate::figures::{
    add_practical_figures, add_torque_charts, path_configurations, path_simulation,
    shown_mechanisms,
};
use crate::guards::{derived_bounds_note, located};
use crate::partial::fallback::{self, Fallback};
use crate::progress::{Count, Phase, Progress};
use crate::record::{capitalised, evaluation, record, utc_now};
use crate::shard::{self, ShardSpec};
use crate::shard_file::{self, OptimisedRecord, ShardFile, StudyKey};
use crate::{design, preflight};

/// Settings of the certified spring stage (`--gap`, `--max-nodes`, `--seed`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SearchSettings {
    /// Relative optimality gap at which the search stops.
    pub gap: f64,
    /// Boxes per variant and pass.
    pub max_nodes: usize,
    /// Seed of the local search's starts (`None`: the built-in one).
    pub seed: Option<u64>,
}

impl Default for SearchSettings {
    fn default() -> Self {
        let d = OptimiseOptions::default();
        SearchSettings {
            gap: d.gap_tolerance,
            max_nodes: d.max_nodes,
            seed: None,
        }
    }
}

/// What a study is asked to do (the options of `counterpoise run`).
#[derive(Clone, Debug, PartialEq)]
pub struct StudyOptions {
    /// Most elements per variant (`None`: the case's `balancing.dmax`).
    pub dmax: Option<usize>,
    /// Minimise QTR over all tasks instead of the paper's RMS*.
    pub minimax: bool,
    /// Ranking resolution and the decision's equivalence tolerance, percentage points.
    pub ranking: RankingOptions,
    /// The certified search's settings.
    pub search: SearchSettings,
    /// Worker threads, recorded in the results' metadata (the caller sizes the thread pool).
    pub jobs: usize,
    /// The case file, for the results' metadata and to locate refused fields in its text
    /// (`None` for a case built in memory).
    pub case_path: Option<PathBuf>,
}

impl Default for StudyOptions {
    fn default() -> Self {
        StudyOptions {
            dmax: None,
            minimax: false,
            ranking: RankingOptions::default(),
            search: SearchSettings::default(),
            jobs: rayon::current_num_threads(),
            case_path: None,
        }
    }
}

/// Times the phases and shows their progress.
pub struct Timer<'p> {
    pub timings: Vec<PhaseTiming>,
    progress: &'p mut dyn Progress,
    cancel: &'p AtomicBool,
}

impl<'p> Timer<'p> {
    pub fn new(progress: &'p mut dyn Progress, cancel: &'p AtomicBool) -> Timer<'p> {
        Timer {
            timings: Vec::new(),
            progress,
            cancel,
        }
    }

    fn time<T>(&mut self, name: &str, work: impl FnOnce() -> Result<T>) -> Result<T> {
        self.time_reporting(name, |_| work())
    }

    /// [`Timer::time`] for a phase outside the count (see [`Progress::phase`]).
    fn time_extra<T>(&mut self, name: &str, work: impl FnOnce() -> Result<T>) -> Result<T> {
        self.run_phase(name, true, |_| work())
    }

    /// [`Timer::time`] for work that reports its own progress to the phase.
    fn time_reporting<T>(
        &mut self,
        name: &str,
        work: impl FnOnce(&dyn Phase) -> Result<T>,
    ) -> Result<T> {
        self.run_phase(name, false, work)
    }

    /// Runs `work` as a phase, ends the phase and records its time; refuses to start once
    /// the caller has cancelled.
    fn run_phase<T>(
        &mut self,
        name: &str,
        extra: bool,
        work: impl FnOnce(&dyn Phase) -> Result<T>,
    ) -> Result<T> {
        if self.cancel.load(Ordering::Relaxed) {
            return Err(StudyError::Cancelled);
        }
        let phase = self.progress.phase(name, extra);
        let started = Instant::now();
        let out = work(phase.as_ref());
        let seconds = started.elapsed().as_secs_f64();
        phase.finish();
        self.timings.push(PhaseTiming {
            phase: name.to_string(),
            seconds,
        });
        out
    }
}

/// What a study computes before the optimisation: Phase 1 and the balance search. Every shard
/// and the merge compute it again (a few seconds even at Dmax 3) rather than share a file.
pub struct Front {
    pub unbalanced: Indicators,
    /// Tasks, excluded tasks, whether the reactions are minimum-norm.
    pub grid_info: (usize, usize, bool),
    pub found: SearchReport,
}

/// A finished study: the results document and, when no variant is feasible, the partial
/// balancing that stands in for a recommendation.
pub struct StudyOutcome {
    pub results: RunResults,
    pub fallback: Option<Fallback>,
}

impl StudyOutcome {
    /// Writes results.json and the reports (and partial.json, partial.csv with a fallback)
    /// into `dir`, each atomically; returns the files written.
    pub fn write(&self, dir: &Path) -> Result<Vec<PathBuf>> {
        let mut written = report::write_outputs(dir, &self.results)?;
        if let Some(f) = &self.fallback {
            let json = serde_json::to_string_pretty(&f.json)?;
            written.push(report::write_atomic(
                dir,
                fallback::PARTIAL_JSON,
                json.as_bytes(),
            )?);
            if !f.csv.is_empty() {
                written.push(report::write_atomic(
                    dir,
                    fallback::PARTIAL_CSV,
                    f.csv.as_bytes(),
                )?);
            }
        }
        Ok(written)
    }

    /// The summary a run prints: the ranking's head, and the partial balancing if any.
    pub fn summary(&self) -> String {
        let mut s = report::text::summary(&self.results);
        if let Some(f) = &self.fallback {
            s.push_str(&f.text);
        }
        s
    }
}

/// One study of one case: its model, the effective Dmax after the guards, and the options.
pub struct Study<'m> {
    model: &'m Model,
    dmax: usize,
    options: StudyOptions,
    notes: Vec<String>,
    /// N when the study is merged from shards.
    shards: Option<usize>,
    /// The shards' own phases, for merged results.
    shard_timings: Vec<PhaseTiming>,
}

impl<'m> Study<'m> {
    /// A study of `model`, after the guards that must pass before the first stage: the case
    /// has `balancing` and `tasks`, Dmax is at least 1, the variant count is within the limit
    /// and every path can be followed (a problem found only at the end would waste the run).
    pub fn new(model: &'m Model, options: StudyOptions) -> Result<Study<'m>> {
        let path = options.case_path.clone().unwrap_or_default();
        let Some(balancing) = &model.balancing else {
            invalid!("{}: the case has no `balancing` section", path.display());
        };
        if model.tasks.is_none() {
            invalid!("{}: the case has no `tasks` section", path.display());
        }
        let dmax = options.dmax.unwrap_or(balancing.dmax);
        if dmax == 0 {
            invalid!("--dmax must be at least 1");
        }
        let source = if options.dmax.is_some() {
            "--dmax"
        } else {
            "balancing.dmax"
        };
        let mut problems: Vec<ModelError> = preflight::variant_guard(model, dmax, source)
            .err()
            .into_iter()
            .collect();
        problems.extend(preflight::path_problems(model));
        if !problems.is_empty() {
            let errors = located(options.case_path.as_deref(), problems);
            return Err(StudyError::Case { path, errors });
        }
        Ok(Study {
            model,
            dmax,
            notes: derived_bounds_note(model).into_iter().collect(),
            options,
            shards: None,
            shard_timings: Vec::new(),
        })
    }

    /// The same study, merged from `count` shards whose own phases took `timings`.
    pub fn merged(mut self, count: usize, timings: Vec<PhaseTiming>) -> Study<'m> {
        self.shards = Some(count);
        self.shard_timings = timings;
        self
    }

    pub fn model(&self) -> &Model {
        self.model
    }

    /// The effective Dmax.
    pub fn dmax(&self) -> usize {
        self.dmax
    }

    pub fn options(&self) -> &StudyOptions {
        &self.options
    }

    /// Notes for the user before the run (the bounds the case left out, derived from the
    /// mechanism).
    pub fn notes(&self) -> &[String] {
        &self.notes
    }

    /// The whole study: Phase 1, the balance search, the optimisation, Phase 3.
    pub fn run(&self, progress: &mut dyn Progress, cancel: &AtomicBool) -> Result<StudyOutcome> {
        let mut timer = Timer::new(progress, cancel);
        let front = self.front(&mut timer)?;
        let balanced = balanced_ids(&front.found.variants);
        let phase = format!(
            "Phase 2: optimisation of the {} balanced variants",
            balanced.len()
        );
        let optimised = self.optimise(&front, &balanced, &mut timer, &phase)?;
        self.finish(&front, &optimised, timer)
    }

    /// Phase 1 (the unbalanced robot over every task, with joint reactions) and the exact
    /// balance search.
    pub fn front(&self, timer: &mut Timer) -> Result<Front> {
        let model = self.model;
        let (unbalanced, grid_info) =
            timer.time("Phase 1: unbalanced robot over all tasks", || {
                let grid = evaluate_unbalanced_grid(model, &EvaluateOptions::default())?;
                let info = (
                    grid.tasks.len(),
                    grid.excluded.count,
                    grid.reactions_minimum_norm,
                );
                Ok((grid.indicators[0].clone(), info))
            })?;
        let dmax = self.dmax;
        let found = timer.time("Phase 2: balance search", || {
            let energy = mechanism_energy(model);
            let catalogue = Catalogue::build(&energy, &catalogue_options(model));
            if catalogue.is_empty() {
                invalid!("`balancing` allows no counterweight and no spring");
            }
            Ok(search(
                &energy,
                catalogue,
                SearchOptions {
                    dmax,
                    hints: realization_hints(model),
                },
            ))
        })?;
        Ok(Front {
            unbalanced,
            grid_info,
            found,
        })
    }

    /// The optimiser's objective.
    pub fn objective(&self) -> Objective {
        if self.options.minimax {
            Objective::Minimax
        } else {
            Objective::RmsStar
        }
    }

    /// Optimises the balanced variants `ids` (enumeration indices, increasing), re-evaluated
    /// over all tasks, as phase `phase`.
    pub fn optimise(
        &self,
        front: &Front,
        ids: &[usize],
        timer: &mut Timer,
        phase: &str,
    ) -> Result<Vec<OptimisedRecord>> {
        let variants: Vec<VariantResult> = ids
            .iter()
            .map(|&k| front.found.variants[k].clone())
            .collect();
        let search = self.options.search;
        let objective = self.objective();
        let model = self.model;
        timer.time_reporting(phase, |phase| {
            let context = Context::new(model, Some(front.unbalanced.clone()))?;
            let defaults = OptimiseOptions::default();
            // From the whole search, not this phase's share: every shard chooses alike.
            let balanced = balanced_ids(&front.found.variants).len();
            let settings = OptimiseOptions {
                objective,
                gap_tolerance: search.gap,
                max_nodes: search.max_nodes,
                start_seed: search.seed.unwrap_or(defaults.start_seed),
                final_reaction_solve: FinalReactionSolve::for_study(model, balanced),
                loop_torques: LoopTorques::for_study(model, balanced),
                ..defaults
            };
            let report = |p: counterpoise_optimise::StageProgress| {
                let (done, total) = (p.done, p.total);
                // An evaluation runs its variants together: its share done, as a percentage
                // (the live line stays within 120 columns without the variant count).
                let count = match p.unit {
                    counterpoise_optimise::Unit::Variants => Count::Items { done, total },
                    counterpoise_optimise::Unit::Share { .. } => Count::Share { done, total },
                };
                let stage = if p.stage == "critical-task pass" {
                    format!("{} {}", p.stage, p.pass)
                } else if p.pass > 0 {
                    format!("{} (pass {})", p.stage, p.pass)
                } else {
                    p.stage.to_string()
                };
                phase.report(&stage, count);
            };
            let optimised = optimise_all_reporting(&context, &variants, &settings, &report).0;
            if optimised.len() != ids.len() {
                invalid!(
                    "the optimiser returned {} results for {} balanced variants",
                    optimised.len(),
                    ids.len()
                );
            }
            Ok(ids
                .iter()
                .zip(&optimised)
                .map(|(&id, o)| OptimisedRecord::new(id, o))
                .collect())
        })
    }

    /// `run --shard I/N`: Phase 1, the search, and the optimisation of shard I's variants, as
    /// the shard file `merge` reads (`case_text`: the case file's text, carried along so the
    /// merge can check and recompute the study).
    pub fn run_shard(
        &self,
        spec: ShardSpec,
        case_text: String,
        progress: &mut dyn Progress,
        cancel: &AtomicBool,
    ) -> Result<ShardFile> {
        let mut timer = Timer::new(progress, cancel);
        let front = self.front(&mut timer)?;
        let balanced = balanced_ids(&front.found.variants);
        let ids = shard::shard_variants(&front.found.variants, spec);
        let cost = |ids: &[usize]| -> u64 {
            ids.iter()
                .map(|&k| shard::expected_cost(shard::CostFeatures::of(&front.found.variants[k])))
                .sum()
        };
        let phase = format!(
            "Phase 2: optimisation of shard {spec}: {} of the {} balanced variants",
            ids.len(),
            balanced.len()
        );
        let optimised = self.optimise(&front, &ids, &mut timer, &phase)?;
        Ok(ShardFile {
            format: shard_file::FORMAT.into(),
            format_version: shard_file::FORMAT_VERSION,
            study: StudyKey {
                case_sha256: shard_file::case_sha256(self.model)?,
                dmax: self.dmax,
                objective: self.objective(),
                resolution: self.options.ranking.resolution,
                tolerance: self.options.ranking.tolerance,
                shards: spec.count,
                tool_version: env!("CARGO_PKG_VERSION").into(),
            },
            shard: spec.index,
            case_path: self.case_path(),
            case_text,
            balanced: balanced.len(),
            expected_cost: cost(&ids),
            study_expected_cost: cost(&balanced),
            variants: ids,
            unbalanced: front.unbalanced.clone(),
            timings: timer.timings,
            optimised,
        })
    }

    fn case_path(&self) -> String {
        self.options
            .case_path
            .as_deref()
            .map(|p| p.display().to_string())
            .unwrap_or_default()
    }

    /// Phase 3, from the optimiser's records of every balanced variant (in any order): the end
    /// of a single run and all of a merge's work after its checks.
    pub fn finish(
        &self,
        front: &Front,
        optimised: &[OptimisedRecord],
        mut timer: Timer,
    ) -> Result<StudyOutcome> {
        let model = self.model;
        let ub_grid_info = front.grid_info;
        let mut results = RunResults::new(
            RunMetadata {
                tool: "counterpoise".into(),
                tool_version: env!("CARGO_PKG_VERSION").into(),
                case_name: model.name.clone(),
                case_path: self.case_path(),
                dmax: self.dmax,
                jobs: self.options.jobs,
                shards: self.shards,
                date: utc_now(),
                timings: Vec::new(),
                shard_timings: self.shard_timings.clone(),
                notes: Vec::new(),
            },
            serde_json::to_value(&model.case)?,
            evaluation(&front.unbalanced, ub_grid_info),
        );
        if let Some(note) = derived_bounds_note(model) {
            results
                .metadata
                .notes
                .push(format!("{}.", capitalised(&note)));
        }
        if ub_grid_info.2 {
            results.metadata.notes.push(
                "The mechanism is overconstrained (planar loops in space): joint reactions are \
                 the minimum-norm solution."
                    .into(),
            );
        }
        let by_id: BTreeMap<usize, &OptimisedRecord> =
            optimised.iter().map(|o| (o.variant, o)).collect();
        for (id, v) in front.found.variants.iter().enumerate() {
            let opt = if v.status == Status::Balanced {
                let Some(o) = by_id.get(&id) else {
                    invalid!("no optimisation result for the balanced variant {id}");
                };
                Some(*o)
            } else {
                None
            };
            results
                .variants
                .push(record(model, id, v, opt, ub_grid_info));
        }
        results.moving_mass = Some(model.bodies.iter().map(|b| b.mass).sum());
        results.element_bounds = design::element_bounds(model)?;
        let ranking = self.options.ranking;
        timer.time("Phase 3: ranking, torque curves, path", || {
            results.finalize(&ranking)?;
            // The recommendation reads the practical figures, and the charts show it: figures
            // first, then the decision, then the curves of the variants it names.
            let path_configurations = if model.paths.is_empty() {
                Vec::new()
            } else {
                path_configurations(model, 0)?
            };
            add_practical_figures(model, &mut results, path_configurations)?;
            results.finalize(&ranking)?;
            let mechanisms = shown_mechanisms(model, &results, optimised)?;
            add_torque_charts(model, &mut results, &mechanisms)?;
            if !model.paths.is_empty() {
                results.path = Some(path_simulation(model, &mechanisms, 0)?.0);
            }
            results.finalize(&ranking)?;
            results.schematics = design::schematics(model, &results, &[])?;
            results.energy = design::energy_chart(model, &results)?;
            Ok(())
        })?;
        // Nothing to recommend: how many elements the mechanism needs, and the best partial
        // balancing within Dmax (partial.json, partial.csv, a note the reports print).
        let fallback = if results
            .variants
            .iter()
            .any(|v| v.status == Status::Feasible)
        {
            None
        } else {
            let dmax = self.dmax;
            let fallback = timer.time_extra("Partial balancing (no feasible variant)", || {
                fallback::fallback(model, dmax, &front.found)
            })?;
            results.metadata.notes.push(fallback.note.clone());
            results.partial = Some(fallback.section.clone());
            Some(fallback)
        };
        results.metadata.timings = timer.timings;
        Ok(StudyOutcome { results, fallback })
    }
}

/// Enumeration indices of the balanced variants.
pub fn balanced_ids(variants: &[VariantResult]) -> Vec<usize> {
    (0..variants.len())
        .filter(|&k| variants[k].status == Status::Balanced)
        .collect()
}
