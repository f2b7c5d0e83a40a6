//! `counterpoise run CASE`: the whole case study — Phase 1 (unbalanced robot), Phase 2 (balance
//! search, optimisation with re-evaluation over all tasks), Phase 3 (ranking, reports).
//!
//! With `--shard I/N` only the balanced variants of shard I are optimised and the result is a
//! partial file (see [`super::shard_file`]); `merge` then runs Phase 3 on every shard's records
//! through [`finish`], the same function a single run ends with.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::{Instant, SystemTime, UNIX_EPOCH};

use anyhow::{Context as _, Result, bail};
use counterpoise::shard::{self, ShardSpec};
use counterpoise_balance::{
    Catalogue, SearchOptions, SearchReport, Status, VariantResult, catalogue_options,
    mechanism_energy, realization_hints, search,
};
use counterpoise_dynamics::params::ParameterSet;
use counterpoise_dynamics::{
    Counterweight, EvaluateOptions, Indicators, Spring, Variant, evaluate_grid, task_series_with,
};
use counterpoise_model::Model;
use counterpoise_optimise::{Context, Objective, OptimiseOptions, optimise_all_reporting};
use counterpoise_report as report;
use report::{
    ActuatorSummary, ElementInfo, ElementKind, Evaluation, FreeDirection, JointPeak, OptimiserInfo,
    PhaseTiming, PhysicalParameters, RankingOptions, RunMetadata, RunResults, VariantRecord,
    VariantStatus,
};

use super::progress::Count;
use super::shard_file::{self, OptimisedRecord, Outcome, ShardFile, StudyKey};

/// Options of the command.
pub struct Options {
    pub dmax: Option<usize>,
    pub out: Option<PathBuf>,
    pub jobs: usize,
    pub minimax: bool,
    pub resolution: f64,
    /// Tolerance of the decision section's equivalence, percentage points.
    pub tolerance: f64,
    /// How progress is shown on stderr.
    pub progress: super::progress::Progress,
    /// Optimise only this shard's variants and write a partial result.
    pub shard: Option<ShardSpec>,
    /// The certified search's settings.
    pub search: SearchSettings,
}

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

/// Times the phases and shows their progress.
pub struct Timer {
    pub timings: Vec<PhaseTiming>,
    progress: super::progress::Progress,
}

impl Timer {
    pub fn new(progress: super::progress::Progress) -> Timer {
        Timer {
            timings: Vec::new(),
            progress,
        }
    }

    fn time<T>(&mut self, name: &str, work: impl FnOnce() -> Result<T>) -> Result<T> {
        self.time_reporting(name, |_| work())
    }

    /// [`Timer::time`] for a phase outside the count ([`super::progress::Progress::extra_phase`]).
    fn time_extra<T>(&mut self, name: &str, work: impl FnOnce() -> Result<T>) -> Result<T> {
        let phase = self.progress.extra_phase(name);
        self.finish_timed(name, phase, |_| work())
    }

    /// [`Timer::time`] for work that reports its own progress to the phase.
    fn time_reporting<T>(
        &mut self,
        name: &str,
        work: impl FnOnce(&super::progress::Phase) -> Result<T>,
    ) -> Result<T> {
        let phase = self.progress.phase(name);
        self.finish_timed(name, phase, work)
    }

    /// Runs `work` as `phase`, ends the phase and records its time.
    fn finish_timed<T>(
        &mut self,
        name: &str,
        phase: super::progress::Phase,
        work: impl FnOnce(&super::progress::Phase) -> Result<T>,
    ) -> Result<T> {
        let started = Instant::now();
        let out = work(&phase);
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

/// Everything Phase 3 needs besides the computed results.
pub struct Study<'a> {
    pub model: &'a Model,
    pub case_path: String,
    pub dmax: usize,
    pub jobs: usize,
    pub ranking: RankingOptions,
    /// N when the study was merged from shards.
    pub shards: Option<usize>,
    /// The shards' own phases, for merged results.
    pub shard_timings: Vec<PhaseTiming>,
}

pub fn run(path: &Path, options: Options) -> Result<ExitCode> {
    let Some(model) = super::load(path)? else {
        return Ok(ExitCode::FAILURE);
    };
    let Some(dmax) = checked_dmax(path, &model, options.dmax, options.progress.mode)? else {
        return Ok(ExitCode::FAILURE);
    };
    let out_dir = options
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("out").join(&model.name));
    std::fs::create_dir_all(&out_dir)
        .with_context(|| format!("cannot create the output directory {}", out_dir.display()))?;
    let mut timer = Timer::new(options.progress);
    let front = front(&model, dmax, &mut timer)?;
    let balanced = balanced_ids(&front.found.variants);
    if let Some(spec) = options.shard {
        return run_shard(path, &model, dmax, &front, spec, &options, timer, &out_dir);
    }
    let phase = format!(
        "Phase 2: optimisation of the {} balanced variants",
        balanced.len()
    );
    let optimised = optimise(&model, &front, &balanced, &options, &mut timer, &phase)?;
    let study = Study {
        model: &model,
        case_path: path.display().to_string(),
        dmax,
        jobs: options.jobs,
        ranking: RankingOptions {
            resolution: options.resolution,
            tolerance: options.tolerance,
        },
        shards: None,
        shard_timings: Vec::new(),
    };
    finish(&study, &front, &optimised, timer, &out_dir)
}

/// The effective Dmax after the guards of `run` (printed when they fail: `None`).
pub fn checked_dmax(
    path: &Path,
    model: &Model,
    dmax: Option<usize>,
    mode: super::progress::Mode,
) -> Result<Option<usize>> {
    let Some(balancing) = &model.balancing else {
        bail!("{}: the case has no `balancing` section", path.display());
    };
    if model.tasks.is_none() {
        bail!("{}: the case has no `tasks` section", path.display());
    }
    let effective = dmax.unwrap_or(balancing.dmax);
    if effective == 0 {
        bail!("--dmax must be at least 1");
    }
    if !super::before_run(path, model, dmax.is_some(), effective) {
        return Ok(None);
    }
    if let (Some(note), false) = (
        super::derived_bounds_note(model),
        mode == super::progress::Mode::Quiet,
    ) {
        eprintln!("note: {note}");
    }
    Ok(Some(effective))
}

/// Phase 1 (the unbalanced robot over every task, with joint reactions) and the exact balance
/// search.
pub fn front(model: &Model, dmax: usize, timer: &mut Timer) -> Result<Front> {
    let (unbalanced, grid_info) = timer.time("Phase 1: unbalanced robot over all tasks", || {
        let grid = evaluate_grid(
            model,
            &ParameterSet::unbalanced(model),
            &EvaluateOptions::default(),
        )?;
        let info = (
            grid.tasks.len(),
            grid.excluded.count,
            grid.reactions_minimum_norm,
        );
        Ok((grid.indicators[0].clone(), info))
    })?;
    let found = timer.time("Phase 2: balance search", || {
        let energy = mechanism_energy(model);
        let catalogue = Catalogue::build(&energy, &catalogue_options(model));
        if catalogue.is_empty() {
            bail!("`balancing` allows no counterweight and no spring");
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

/// Enumeration indices of the balanced variants.
fn balanced_ids(variants: &[VariantResult]) -> Vec<usize> {
    (0..variants.len())
        .filter(|&k| variants[k].status == Status::Balanced)
        .collect()
}

/// The optimiser's objective for `--minimax`.
pub fn objective(minimax: bool) -> Objective {
    if minimax {
        Objective::Minimax
    } else {
        Objective::RmsStar
    }
}

/// Optimises the balanced variants `ids` (enumeration indices, increasing), re-evaluated over
/// all tasks, as phase `phase`.
fn optimise(
    model: &Model,
    front: &Front,
    ids: &[usize],
    options: &Options,
    timer: &mut Timer,
    phase: &str,
) -> Result<Vec<OptimisedRecord>> {
    let variants: Vec<VariantResult> = ids
        .iter()
        .map(|&k| front.found.variants[k].clone())
        .collect();
    timer.time_reporting(phase, |phase| {
        let context = Context::new(model, Some(front.unbalanced.clone()))?;
        let defaults = OptimiseOptions::default();
        let settings = OptimiseOptions {
            objective: objective(options.minimax),
            gap_tolerance: options.search.gap,
            max_nodes: options.search.max_nodes,
            start_seed: options.search.seed.unwrap_or(defaults.start_seed),
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
            bail!(
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

/// `run --shard I/N`: optimises shard I's variants and writes `DIR/shard-I-of-N.json`.
#[allow(clippy::too_many_arguments)]
fn run_shard(
    path: &Path,
    model: &Model,
    dmax: usize,
    front: &Front,
    spec: ShardSpec,
    options: &Options,
    mut timer: Timer,
    out_dir: &Path,
) -> Result<ExitCode> {
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
    let optimised = optimise(model, front, &ids, options, &mut timer, &phase)?;
    let case_text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    let file = ShardFile {
        format: shard_file::FORMAT.into(),
        format_version: shard_file::FORMAT_VERSION,
        study: StudyKey {
            case_sha256: shard_file::case_sha256(model)?,
            dmax,
            objective: objective(options.minimax),
            resolution: options.resolution,
            tolerance: options.tolerance,
            shards: spec.count,
            tool_version: env!("CARGO_PKG_VERSION").into(),
        },
        shard: spec.index,
        case_path: path.display().to_string(),
        case_text,
        balanced: balanced.len(),
        expected_cost: cost(&ids),
        study_expected_cost: cost(&balanced),
        variants: ids,
        unbalanced: front.unbalanced.clone(),
        timings: timer.timings,
        optimised,
    };
    let written = shard_file::write(out_dir, &file)?;
    let seconds: f64 = file.timings.iter().map(|t| t.seconds).sum();
    println!(
        "{}: shard {spec}: {} of {} balanced variants (expected cost {:.1} % of the study) \
         optimised in {seconds:.1} s",
        model.name,
        file.variants.len(),
        file.balanced,
        100.0 * file.expected_cost as f64 / file.study_expected_cost.max(1) as f64,
    );
    println!("wrote {}", written.display());
    Ok(ExitCode::SUCCESS)
}

/// Phase 3 and the outputs, from the optimiser's records of every balanced variant (in any
/// order): the end of a single run and all of a merge's work after its checks.
pub fn finish(
    study: &Study,
    front: &Front,
    optimised: &[OptimisedRecord],
    mut timer: Timer,
    out_dir: &Path,
) -> Result<ExitCode> {
    let model = study.model;
    let ub_grid_info = front.grid_info;
    let mut results = RunResults::new(
        RunMetadata {
            tool: "counterpoise".into(),
            tool_version: env!("CARGO_PKG_VERSION").into(),
            case_name: model.name.clone(),
            case_path: study.case_path.clone(),
            dmax: study.dmax,
            jobs: study.jobs,
            shards: study.shards,
            date: utc_now(),
            timings: Vec::new(),
            shard_timings: study.shard_timings.clone(),
            notes: Vec::new(),
        },
        serde_json::to_value(&model.case)?,
        evaluation(&front.unbalanced, ub_grid_info),
    );
    if let Some(note) = super::derived_bounds_note(model) {
        results
            .metadata
            .notes
            .push(format!("{}.", capitalised(&note)));
    }
    if ub_grid_info.2 {
        results.metadata.notes.push(
            "The mechanism is overconstrained (planar loops in space): joint reactions are the \
             minimum-norm solution."
                .into(),
        );
    }
    let by_id: BTreeMap<usize, &OptimisedRecord> =
        optimised.iter().map(|o| (o.variant, o)).collect();
    for (id, v) in front.found.variants.iter().enumerate() {
        let opt = if v.status == Status::Balanced {
            let Some(o) = by_id.get(&id) else {
                bail!("no optimisation result for the balanced variant {id}");
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
    results.element_bounds = super::design::element_bounds(model)?;
    timer.time("Phase 3: ranking, torque curves, path", || {
        results.finalize(&study.ranking)?;
        // The recommendation reads the practical figures, and the charts show it: figures
        // first, then the decision, then the curves of the variants it names.
        let path_configurations = if model.paths.is_empty() {
            Vec::new()
        } else {
            path_configurations(model, 0)?
        };
        add_practical_figures(model, &mut results, path_configurations)?;
        results.finalize(&study.ranking)?;
        let mechanisms = shown_mechanisms(model, &results, optimised)?;
        add_torque_charts(model, &mut results, &mechanisms)?;
        if !model.paths.is_empty() {
            results.path = Some(path_simulation(model, &mechanisms, 0)?.0);
        }
        results.finalize(&study.ranking)?;
        results.schematics = super::design::schematics(model, &results, &[])?;
        results.energy = super::design::energy_chart(model, &results)?;
        Ok(())
    })?;
    // Nothing to recommend: how many elements the mechanism needs, and the best partial
    // balancing within Dmax (partial.json, partial.csv, a note the reports print).
    let fallback = if results
        .variants
        .iter()
        .any(|v| v.status == VariantStatus::Feasible)
    {
        None
    } else {
        let fallback = timer.time_extra("Partial balancing (no feasible variant)", || {
            super::partial::fallback::fallback(model, study.dmax, &front.found)
        })?;
        results.metadata.notes.push(fallback.note.clone());
        results.partial = Some(fallback.section.clone());
        Some(fallback)
    };
    results.metadata.timings = timer.timings;
    let mut written = report::write_outputs(out_dir, &results)?;
    if let Some(f) = &fallback {
        let json = out_dir.join(super::partial::fallback::PARTIAL_JSON);
        super::write_atomic(&json, serde_json::to_string_pretty(&f.json)?.as_bytes())?;
        written.push(json);
        if !f.csv.is_empty() {
            let csv = out_dir.join(super::partial::fallback::PARTIAL_CSV);
            super::write_atomic(&csv, f.csv.as_bytes())?;
            written.push(csv);
        }
    }
    print!("{}", report::text::summary(&results));
    if let Some(f) = &fallback {
        print!("{}", f.text);
    }
    for f in written {
        println!("wrote {}", f.display());
    }
    Ok(ExitCode::SUCCESS)
}

fn capitalised(s: &str) -> String {
    let mut c = s.chars();
    c.next()
        .map(|f| f.to_uppercase().chain(c).collect())
        .unwrap_or_default()
}

fn utc_now() -> String {
    let secs = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    // civil-from-days (Howard Hinnant's algorithm): no date crate for one timestamp
    let days = (secs / 86_400) as i64;
    let rem = secs % 86_400;
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}-{month:02}-{day:02}T{:02}:{:02}:{:02}Z",
        rem / 3600,
        (rem % 3600) / 60,
        rem % 60
    )
}

/// Indicators in the report's schema.
fn evaluation(
    ind: &Indicators,
    (tasks, excluded, minimum_norm): (usize, usize, bool),
) -> Evaluation {
    Evaluation {
        qtr: ind.qtr,
        qtr_task: ind.qtr_task,
        qit: ind.qit,
        qit_task: ind.qit_task,
        actuators: ind
            .actuators
            .iter()
            .map(|a| ActuatorSummary {
                name: a.name.clone(),
                crt: a.crt,
                crt_rms: a.crt_rms,
                cpt: a.cpt,
                cpt_peak: a.cpt_peak,
            })
            .collect(),
        joints: ind
            .joints
            .iter()
            .map(|j| JointPeak {
                name: j.name.clone(),
                force: j.force,
                force_task: Some(j.force_task),
                moment: j.moment,
                moment_task: Some(j.moment_task),
            })
            .collect(),
        tasks: tasks - excluded,
        excluded_tasks: excluded,
        reactions_minimum_norm: minimum_norm,
    }
}

fn class(c: counterpoise_balance::Class) -> report::Class {
    match c {
        counterpoise_balance::Class::Counterweights => report::Class::Counterweights,
        counterpoise_balance::Class::Springs => report::Class::Springs,
        counterpoise_balance::Class::Hybrid => report::Class::Hybrid,
    }
}

fn plane(p: Option<counterpoise_model::Plane>) -> Option<report::Plane> {
    p.map(|p| match p {
        counterpoise_model::Plane::Xy => report::Plane::Xy,
        counterpoise_model::Plane::Yz => report::Plane::Yz,
        counterpoise_model::Plane::Xz => report::Plane::Xz,
    })
}

/// One variant's record: the search's verdict, and the optimiser's for balanced ones.
fn record(
    model: &Model,
    id: usize,
    v: &VariantResult,
    opt: Option<&OptimisedRecord>,
    grid_info: (usize, usize, bool),
) -> VariantRecord {
    let elements = v
        .elements
        .iter()
        .map(|e| ElementInfo {
            label: e.label.clone(),
            kind: if e.kind == "spring" {
                ElementKind::Spring
            } else {
                ElementKind::Counterweight
            },
            bodies: e.bodies.clone(),
        })
        .collect();
    let status = match v.status {
        Status::Balanced => VariantStatus::Feasible,
        Status::Degenerate => VariantStatus::Degenerate,
        Status::Unrealizable => VariantStatus::Unrealizable,
        Status::Infeasible => VariantStatus::Infeasible,
        Status::Undecided => VariantStatus::Undecided,
    };
    let mut r = VariantRecord::new(id, elements, class(v.class), status);
    r.reason = v.reason.clone();
    r.relations = v.relations.clone();
    r.free_directions = v
        .free_directions
        .iter()
        .map(|f| FreeDirection {
            // Nine significant digits: the reports show four, and at Dmax 3 the directions
            // of the ranked variants are half of results.json.
            components: f
                .components
                .iter()
                .map(|(name, c)| (name.clone(), significant(*c, 9)))
                .collect(),
            positive_interval: f.positive_interval,
        })
        .collect();
    r.verification_residual = v.verification.map(|x| x.residual);
    let Some(opt) = opt else {
        r.relations.clear();
        r.free_directions.clear();
        return r;
    };
    r.optimiser = Some(OptimiserInfo {
        objective: opt.objective,
        lower_bound: opt.lower_bound,
        gap: opt.gap,
        iterations: Some(opt.iterations),
        boxes: Some(opt.boxes),
        message: opt.reason.clone(),
    });
    let balancing = model.balancing.as_ref();
    let cw_plane = plane(
        balancing
            .and_then(|b| b.counterweights.as_ref())
            .and_then(|c| c.plane),
    );
    let spring_plane = plane(
        balancing
            .and_then(|b| b.springs.as_ref())
            .and_then(|s| s.plane),
    );
    r.parameters = Some(PhysicalParameters {
        counterweights: opt
            .counterweights
            .iter()
            .map(|c| report::CounterweightParams {
                label: c.label.clone(),
                body: c.body.clone(),
                mass: c.mass,
                offset: c.offset,
                plane: cw_plane,
            })
            .collect(),
        springs: opt
            .springs
            .iter()
            .map(|s| report::SpringParams {
                label: s.label.clone(),
                body: s.body.clone(),
                other: s.other.clone(),
                stiffness: s.stiffness,
                anchor_a: s.anchor_a,
                anchor_b: s.anchor_b,
                plane: spring_plane,
            })
            .collect(),
    });
    match (opt.outcome == Outcome::Feasible, &opt.indicators) {
        (true, Some(ind)) => {
            r.status = VariantStatus::Feasible;
            r.evaluation = Some(evaluation(ind, grid_info));
            if let Some(res) = opt.residual {
                r.verification_residual = Some(res);
            }
        }
        (true, None) => {
            r.status = VariantStatus::Discarded;
            r.reason = Some("optimised, but not re-evaluated over all tasks".into());
        }
        (false, _) => {
            r.status = if opt.outcome == Outcome::Undecided {
                VariantStatus::Undecided
            } else {
                VariantStatus::Discarded
            };
            r.reason = opt.reason.clone();
        }
    }
    if r.status != VariantStatus::Feasible {
        // The reports show the balance relations of ranked variants only; the free directions
        // of thousands of unranked variants at Dmax 3 were most of results.json.
        r.relations.clear();
        r.free_directions.clear();
    }
    r
}

/// `x` rounded to `digits` significant digits (through the decimal representation, so the JSON
/// holds the short form).
fn significant(x: f64, digits: usize) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    format!("{x:.*e}", digits.saturating_sub(1))
        .parse()
        .unwrap_or(x)
}

/// The dynamics crate's description of a variant's elements.
fn dynamics_variant(model: &Model, opt: &OptimisedRecord) -> Result<Variant> {
    let body = |name: &str| {
        model
            .body_index(name)
            .with_context(|| format!("optimiser named an unknown body `{name}`"))
    };
    let mut v = Variant::default();
    for c in &opt.counterweights {
        v.counterweights.push(Counterweight {
            body: body(&c.body)?,
            mass: c.mass,
            position: c.offset,
        });
    }
    for s in &opt.springs {
        v.springs.push(Spring {
            body: body(&s.body)?,
            other: if s.other == "base" {
                None
            } else {
                Some(body(&s.other)?)
            },
            stiffness: s.stiffness,
            anchor: s.anchor_a,
            other_anchor: s.anchor_b,
        });
    }
    Ok(v)
}

/// The unbalanced robot and the variants the report shows (the best-ranked and the
/// recommended of each class, [`RunResults::shown_variants`]) as parameter columns, with their
/// labels (`UB`, then `SB6 (K42 + K43), recommended`-style names) and variant ids.
pub(super) struct Mechanisms {
    params: ParameterSet,
    labels: Vec<(String, Option<usize>)>,
}

fn shown_mechanisms(
    model: &Model,
    results: &RunResults,
    optimised: &[OptimisedRecord],
) -> Result<Mechanisms> {
    let mut variants = vec![Variant::default()];
    let mut labels = vec![("UB".to_string(), None)];
    for v in results.shown_variants() {
        let label = v.label();
        let Some(opt) = optimised.iter().find(|o| o.label() == label) else {
            continue;
        };
        variants.push(dynamics_variant(model, opt)?);
        labels.push((results.shown_label(v), Some(v.id)));
    }
    Ok(Mechanisms {
        params: ParameterSet::from_variants(model, &variants)?,
        labels,
    })
}

/// [`shown_mechanisms`] from the parameters stored in the results (`report DIR`, which has no
/// optimiser records).
pub(super) fn shown_mechanisms_of_results(
    model: &Model,
    results: &RunResults,
) -> Result<Mechanisms> {
    let body = |name: &str| {
        model
            .body_index(name)
            .with_context(|| format!("results.json names an unknown body `{name}`"))
    };
    let mut variants = vec![Variant::default()];
    let mut labels = vec![("UB".to_string(), None)];
    for v in results.shown_variants() {
        let Some(p) = &v.parameters else { continue };
        let mut d = Variant::default();
        for c in &p.counterweights {
            d.counterweights.push(Counterweight {
                body: body(&c.body)?,
                mass: c.mass,
                position: c.offset,
            });
        }
        for s in &p.springs {
            d.springs.push(Spring {
                body: body(&s.body)?,
                other: if s.other == "base" {
                    None
                } else {
                    Some(body(&s.other)?)
                },
                stiffness: s.stiffness,
                anchor: s.anchor_a,
                other_anchor: s.anchor_b,
            });
        }
        variants.push(d);
        labels.push((results.shown_label(v), Some(v.id)));
    }
    Ok(Mechanisms {
        params: ParameterSet::from_variants(model, &variants)?,
        labels,
    })
}

/// Samples per path segment in the path simulation.
const PATH_SAMPLES_PER_SEGMENT: usize = 60;
/// How much the quasi-static run stretches the path's durations: velocities scale by 1e-6 and
/// the inertial torques by 1e-12, far below anything a report shows.
const STATIC_STRETCH: f64 = 1e6;

/// The configurations along path `index`, sampled as [`path_simulation`] samples them (they
/// are kinematics, the same for every mechanism): where the practical figures take the springs'
/// peaks, needed before the simulation because the recommendation reads those figures.
pub(super) fn path_configurations(model: &Model, index: usize) -> Result<Vec<Vec<f64>>> {
    let params = ParameterSet::from_variants(model, &[Variant::default()])?;
    let series =
        counterpoise_dynamics::path_series(model, &params, 0, index, PATH_SAMPLES_PER_SEGMENT)?;
    Ok(series.q)
}

/// The paper's Sec. 3.3 simulation along path `index`: the timed cycle, and the same path
/// traversed quasi-statically (static torques).
pub(super) fn path_simulation(
    model: &Model,
    m: &Mechanisms,
    index: usize,
) -> Result<(report::PathSimulation, Vec<Vec<f64>>)> {
    let spec = &model.paths[index];
    let actuators: Vec<String> = model.actuators.iter().map(|a| a.name.clone()).collect();
    let mut configurations: Vec<Vec<f64>> = Vec::new();
    let mut run_of = |model: &Model, time_scale: f64| -> Result<report::PathRun> {
        let mut x = Vec::new();
        let mut mechanisms = Vec::new();
        for (column, (label, variant)) in m.labels.iter().enumerate() {
            let series = counterpoise_dynamics::path_series(
                model,
                &m.params,
                column,
                index,
                PATH_SAMPLES_PER_SEGMENT,
            )?;
            if x.is_empty() {
                x = series.t.iter().map(|t| t / time_scale).collect();
                if configurations.is_empty() {
                    configurations = series.q.clone();
                }
            }
            let torques = (0..actuators.len())
                .map(|k| series.motor_torque.iter().map(|row| row[k]).collect())
                .collect();
            mechanisms.push(report::PathMechanism {
                label: label.clone(),
                variant: *variant,
                torques,
            });
        }
        Ok(report::PathRun {
            x_label: "time".into(),
            x_unit: "s".into(),
            x,
            mechanisms,
        })
    };
    let dynamic_run = run_of(model, 1.0)?;
    let mut slow = model.clone();
    for d in &mut slow.paths[index].durations {
        *d *= STATIC_STRETCH;
    }
    let static_run = run_of(&slow, STATIC_STRETCH)?;
    let name = |k: usize| spec.waypoints[spec.sequence[k]].name.clone();
    let waypoints = (0..spec.sequence.len())
        .map(name)
        .collect::<Vec<_>>()
        .join("-");
    let payload = spec
        .payload
        .as_ref()
        .map(|p| {
            format!(
                ", {} kg payload picked at {} and dropped at {}",
                p.mass,
                name(p.pick_at),
                name(p.drop_at)
            )
        })
        .unwrap_or_default();
    let simulation = report::PathSimulation {
        name: spec.name.clone(),
        description: Some(format!(
            "{waypoints} in {:.2} s{payload}; static torques from the same path traversed \
             {STATIC_STRETCH:e} times slower",
            spec.durations.iter().sum::<f64>()
        )),
        actuators,
        static_run: Some(static_run),
        dynamic_run: Some(dynamic_run),
        table: Vec::new(),
    };
    Ok((simulation, configurations))
}

/// Configurations at every task-grid point (where each task starts and ends), solved as the
/// dynamics solves them; points whose kinematics fail are left out (they are excluded tasks).
fn grid_configurations(model: &Model) -> Result<Vec<Vec<f64>>> {
    let Some(spec) = &model.tasks else {
        return Ok(Vec::new());
    };
    let ev = counterpoise_dynamics::Evaluator::new(model)?;
    Ok(spec
        .grid_points()
        .iter()
        .filter_map(|u| ev.solve_point(u).ok())
        .collect())
}

/// Length of a spring (the distance of its anchors, world frame) at configuration `q`.
fn spring_length(
    model: &Model,
    kinematics: &counterpoise_model::Kinematics,
    s: &report::SpringParams,
    q: &nalgebra::DVector<f64>,
) -> Option<f64> {
    let point = |body: &str, anchor: [f64; 3]| -> Option<nalgebra::Vector3<f64>> {
        let a = nalgebra::Vector3::from(anchor);
        if body == "base" {
            return Some(a);
        }
        let pose = kinematics.body_pose(model.body_index(body)?, q);
        Some(pose.position + pose.rotation * a)
    };
    Some((point(&s.body, s.anchor_a)? - point(&s.other, s.anchor_b)?).norm())
}

/// The practical figures of every feasible variant (added mass, elements, peak offset, peak
/// spring force and stretch). The spring peaks are the largest anchor distances over the
/// task-grid points and the samples of the path simulation: the configurations the mechanism
/// rests in and the one cycle simulated in full. A move between two grid points can pass
/// through a longer stretch; that is the documented limit of the figure.
pub(super) fn add_practical_figures(
    model: &Model,
    results: &mut RunResults,
    path_configurations: Vec<Vec<f64>>,
) -> Result<()> {
    let grid = grid_configurations(model)?;
    let (grid_n, path_n) = (grid.len(), path_configurations.len());
    let configurations: Vec<nalgebra::DVector<f64>> = grid
        .into_iter()
        .chain(path_configurations)
        .map(nalgebra::DVector::from_vec)
        .collect();
    let kinematics = counterpoise_model::Kinematics::new(model);
    let moving_mass = results.moving_mass;
    for v in results.variants.iter_mut() {
        if v.status != VariantStatus::Feasible {
            continue;
        }
        let Some(p) = &v.parameters else { continue };
        let peaks = p
            .springs
            .iter()
            .map(|s| {
                report::SpringPeak::from_lengths(
                    &s.label,
                    s.stiffness,
                    configurations
                        .iter()
                        .filter_map(|q| spring_length(model, &kinematics, s, q)),
                )
            })
            .collect();
        v.practical = Some(report::PracticalFigures::new(p, moving_mass, peaks));
    }
    results.spring_peaks_basis = Some(if path_n > 0 {
        format!(
            "the largest over the {grid_n} task-grid points (where every task starts and ends) \
             and the {path_n} samples of the path simulation"
        )
    } else {
        format!("the largest over the {grid_n} task-grid points (where every task starts and ends)")
    });
    Ok(())
}

/// Torque curves (paper Fig. 10-style) of the unbalanced robot and the shown variants (the
/// best-ranked and the recommended of each class), on the critical RMS and peak tasks of each
/// of them.
pub(super) fn add_torque_charts(
    model: &Model,
    results: &mut RunResults,
    m: &Mechanisms,
) -> Result<()> {
    let (params, labels) = (&m.params, &m.labels);
    let columns = labels.len();
    let critical = results.critical_tasks();
    let mut cache: Vec<([usize; 2], Vec<counterpoise_dynamics::Series>)> = Vec::new();
    let mut charts = Vec::new();
    for c in critical {
        if !cache.iter().any(|(t, _)| *t == c.task) {
            let series = (0..columns)
                .map(|col| task_series_with(model, params, col, c.task[0], c.task[1], None))
                .collect::<Result<Vec<_>, _>>()?;
            cache.push((c.task, series));
        }
        let series = &cache.iter().find(|(t, _)| *t == c.task).expect("cached").1;
        charts.push(report::TorqueChart {
            actuator: c.actuator_name.clone(),
            task: c.task,
            critical_for: c.critical_for.clone(),
            t: series[0].t.clone(),
            curves: series
                .iter()
                .zip(labels)
                .map(|(s, (label, variant))| report::Curve {
                    label: label.clone(),
                    variant: *variant,
                    values: s.motor_torque.iter().map(|row| row[c.actuator]).collect(),
                })
                .collect(),
        });
    }
    results.torque_charts = charts;
    Ok(())
}
