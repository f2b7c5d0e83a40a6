//! The `counterpoise` command line.

mod commands;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// Exact static balancing of mechanisms with counterweights and springs.
#[derive(Parser, Debug)]
#[command(name = "counterpoise", version, about, long_about = None)]
struct Cli {
    /// Lift (or lower) a resource limit, e.g. `--limit variants=100000`; repeatable. Names:
    /// file-bytes, parameters, list-items, expression-length, expression-depth, grid-points,
    /// samples, task-samples, dmax, variants (defaults in docs/case-format.md, Limits).
    #[arg(long = "limit", global = true, value_name = "NAME=VALUE")]
    limits: Vec<String>,
    #[command(subcommand)]
    command: Command,
}

/// The option of the commands with parallel stages (not `report`, not `import-urdf`).
#[derive(clap::Args, Debug, Clone, Copy)]
struct Jobs {
    /// Worker threads for the parallel stages (default: all cores). Results do not depend on
    /// it.
    #[arg(long, value_name = "N")]
    jobs: Option<usize>,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Validate a case file and print a summary of the mechanism.
    Check {
        /// Case file (JSON).
        case: PathBuf,
        #[command(flatten)]
        jobs: Jobs,
    },
    /// Find every set of at most Dmax balancing elements that balances the mechanism exactly.
    Variants {
        /// Case file (JSON).
        case: PathBuf,
        /// Most elements per variant (default: the case's `balancing.dmax`; at least 1).
        #[arg(long, value_parser = parse_dmax)]
        dmax: Option<usize>,
        /// Print the full results as JSON instead of tables.
        #[arg(long)]
        json: bool,
        /// Only the minimal balancing sets (no proper subset balances), each decided in full,
        /// and the smallest Dmax at which a variant balances: a pruned walk, for high Dmax.
        #[arg(long)]
        minimal: bool,
        #[command(flatten)]
        jobs: Jobs,
    },
    /// Partial balancing: the sets of at most a budget of counterweights, with parameters
    /// within the case's bounds, that leave the least RMS gravity torque over the workspace on
    /// the joints that matter, ranked beside the exact search's verdict on each set.
    Partial {
        /// Case file (JSON).
        case: PathBuf,
        /// Most elements per set (default: the case's `balancing.dmax`).
        #[arg(long, alias = "dmax", value_name = "N")]
        budget: Option<usize>,
        /// Actuators (or the joints they drive) whose gravity torque is minimised, e.g.
        /// `--joints J2,J3` (default: all).
        #[arg(long, value_delimiter = ',', value_name = "A,B")]
        joints: Option<Vec<String>>,
        /// Workspace values per varying actuator over the task grid's range (default 7, fewer
        /// when the product would pass the grid-points limit).
        #[arg(long, value_name = "N")]
        points: Option<usize>,
        /// Best designs shown per number of elements.
        #[arg(long, default_value_t = 5, value_name = "N")]
        top: usize,
        /// Print every set's design as JSON instead of tables.
        #[arg(long)]
        json: bool,
        /// Sets of counterweights only (default: counterweights and springs; the spring sets
        /// take most of the time).
        #[arg(long)]
        counterweights_only: bool,
        #[command(flatten)]
        jobs: Jobs,
    },
    /// Phase 1: motor torques, joint reactions and the paper's indicators of the unbalanced
    /// mechanism over its task grid.
    Evaluate {
        /// Case file (JSON).
        case: PathBuf,
        /// Print the report as JSON.
        #[arg(long)]
        json: bool,
        /// Samples per task (default: the case's `tasks.samples`).
        #[arg(long)]
        samples: Option<usize>,
        /// Skip the joint reactions (motor torques only: much faster).
        #[arg(long)]
        no_reactions: bool,
        /// One task `I,J` (grid indices, also written `I→J`) to write as a time series with
        /// --series.
        #[arg(long, value_parser = parse_task, requires = "series")]
        task: Option<(usize, usize)>,
        /// File for the time series of --task (JSON).
        #[arg(long, requires = "task")]
        series: Option<PathBuf>,
        /// Inverse dynamics at the states of FILE (a JSON array of {"q", "qd", "qdd"}):
        /// actuator forces, motor torques and potential energy, as JSON.
        #[arg(long, value_name = "FILE", conflicts_with_all = ["task", "series", "samples", "no_reactions"])]
        states: Option<PathBuf>,
        #[command(flatten)]
        jobs: Jobs,
    },
    /// The whole case study: unbalanced indicators, balance search, optimisation, ranking,
    /// reports (results.json, report.html, report.md, ranking.csv).
    Run {
        /// Case file (JSON).
        case: PathBuf,
        /// Most elements per variant (default: the case's `balancing.dmax`; at least 1).
        #[arg(long, value_parser = parse_dmax)]
        dmax: Option<usize>,
        /// Output directory (default: out/<case name>).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Minimise QTR over all tasks (constraint generation) instead of the paper's RMS*.
        #[arg(long)]
        minimax: bool,
        /// Ranking resolution in percentage points: each indicator is rounded to the nearest
        /// multiple of it (its cell); variants in the same cell tie on that indicator and the
        /// next one decides.
        #[arg(long, default_value_t = 0.01, value_parser = parse_points)]
        resolution: f64,
        /// Equivalence tolerance of the report's decision section, percentage points: variants
        /// whose ΔQTR and ΔQIT are within it of the best-ranked one are compared by added
        /// mass, ΔR, element count and spring force.
        #[arg(long, default_value_t = counterpoise_report::decision::DEFAULT_TOLERANCE, value_name = "PP", value_parser = parse_points)]
        tolerance: f64,
        /// No progress on stderr (the summary still goes to stdout).
        #[arg(long, short)]
        quiet: bool,
        /// Optimise only shard I of N (1-based, as SLURM_ARRAY_TASK_ID) and write
        /// DIR/shard-I-of-N.json for `merge` instead of the reports.
        #[arg(long, value_name = "I/N", value_parser = parse_shard)]
        shard: Option<counterpoise::shard::ShardSpec>,
        /// Relative optimality gap at which the certified search stops: every feasible
        /// variant's objective is within it of the certified lower bound.
        #[arg(long, default_value_t = 1e-3, value_name = "REL", value_parser = parse_gap)]
        gap: f64,
        /// Boxes the certified search may solve per variant and pass once a design is known
        /// (four times as many while none is); a variant that reaches the limit before a
        /// verdict ends undecided, and says so.
        #[arg(long, default_value_t = counterpoise_optimise::certify::DEFAULT_MAX_NODES as u64, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
        max_nodes: u64,
        /// Seed of the local search's starting points. Verdicts do not depend on it, nor an
        /// objective beyond its certified gap; a rank can move where a gap stays open or the
        /// spring choice by ΔR (a local search, not certified) finds another option.
        #[arg(long, value_name = "N")]
        seed: Option<u64>,
        #[command(flatten)]
        jobs: Jobs,
    },
    /// Merge the shards of a study (`run --shard I/N`) into results.json and the reports, as a
    /// single run writes them.
    Merge {
        /// Shard files, or directories holding them (shard-I-of-N.json).
        #[arg(required = true, value_name = "DIR")]
        inputs: Vec<PathBuf>,
        /// Output directory.
        #[arg(long)]
        out: PathBuf,
        /// No progress on stderr (the summary still goes to stdout).
        #[arg(long, short)]
        quiet: bool,
        #[command(flatten)]
        jobs: Jobs,
    },
    /// Write a case file from a URDF robot description (bodies, joints, actuators, a default
    /// balancing section and task grid).
    ImportUrdf {
        /// The robot description (URDF).
        urdf: PathBuf,
        /// Case file to write (default: standard output).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Link fixed to the ground (default: the URDF's root link).
        #[arg(long)]
        base: Option<String>,
        /// Last link of the chain: joints off the base-tip path are frozen at 0.
        #[arg(long)]
        tip: Option<String>,
    },
    /// Regenerate report.html, report.md and ranking.csv from DIR/results.json.
    Report {
        /// A directory written by `run`.
        dir: PathBuf,
        /// Recompute the decision section at this equivalence tolerance (percentage points;
        /// default: the one of the run).
        #[arg(long, value_name = "PP", value_parser = parse_points)]
        tolerance: Option<f64>,
        /// Also draw this variant's schematic (its name, `SB12`, or its elements, `m4 + K43`;
        /// repeatable). The recommended variants are always drawn.
        #[arg(long, value_name = "VARIANT")]
        draw: Vec<String>,
    },
}

fn main() -> ExitCode {
    quiet_broken_pipe();
    let cli = Cli::parse();
    let mut limits = counterpoise_model::Limits::default();
    for setting in &cli.limits {
        if let Err(e) = limits.apply(setting) {
            eprintln!("error: --limit {setting}: {e}");
            return ExitCode::from(2);
        }
    }
    counterpoise::preflight::set_limits(limits);
    // Expressions are parsed recursively up to the depth limit: give the command a stack sized
    // for it, so that lifting the limit cannot overflow the main thread's stack.
    let worker = std::thread::Builder::new()
        .name("counterpoise".into())
        .stack_size(limits.stack_bytes())
        .spawn(move || run(cli));
    match worker.map(|handle| handle.join()) {
        Ok(Ok(code)) => code,
        Ok(Err(_)) => ExitCode::from(101),
        Err(e) => {
            eprintln!("error: cannot start the worker thread: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Writing to a closed pipe (`counterpoise variants … | head -1`) ends the process quietly, as
/// for any Unix filter, instead of panicking in `println!`: the default action of SIGPIPE is
/// restored (Rust ignores it, turning the signal into an error every print would panic on).
fn quiet_broken_pipe() {
    #[cfg(unix)]
    // SAFETY: called first thing in `main`, before any thread exists; `signal` with SIG_DFL
    // only resets the disposition of SIGPIPE.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

/// The `--jobs` of the command, if it has one.
fn jobs_of(command: &Command) -> Option<usize> {
    match command {
        Command::Check { jobs, .. }
        | Command::Variants { jobs, .. }
        | Command::Partial { jobs, .. }
        | Command::Evaluate { jobs, .. }
        | Command::Run { jobs, .. }
        | Command::Merge { jobs, .. } => jobs.jobs,
        Command::ImportUrdf { .. } | Command::Report { .. } => None,
    }
}

fn run(cli: Cli) -> ExitCode {
    if let Some(jobs) = jobs_of(&cli.command) {
        if jobs == 0 {
            eprintln!("error: --jobs must be at least 1");
            return ExitCode::from(2);
        }
        if let Err(e) = rayon::ThreadPoolBuilder::new()
            .num_threads(jobs)
            .build_global()
        {
            eprintln!("error: cannot start {jobs} worker threads: {e}");
            return ExitCode::from(2);
        }
    }
    let result = match cli.command {
        Command::Check { case, .. } => Ok(commands::text::check(&case)),
        Command::Variants {
            case,
            dmax,
            json,
            minimal,
            ..
        } => Ok(commands::text::variants(&case, dmax, json, minimal)),
        Command::Partial {
            case,
            budget,
            joints,
            points,
            top,
            json,
            counterweights_only,
            ..
        } => Ok(commands::text::partial(
            &case,
            counterpoise_study::partial::Options {
                budget,
                joints,
                points,
                top,
                json,
                springs: !counterweights_only,
            },
        )),
        Command::Evaluate {
            case,
            states: Some(states),
            ..
        } => Ok(commands::text::states(&case, &states)),
        Command::Evaluate {
            case,
            json,
            samples,
            no_reactions,
            task,
            series,
            states: None,
            ..
        } => Ok(commands::text::evaluate(
            &case,
            counterpoise_study::evaluate::Options {
                json,
                samples,
                no_reactions,
            },
            task.zip(series.as_deref()),
        )),
        Command::Run {
            case,
            dmax,
            out,
            minimax,
            resolution,
            tolerance,
            quiet,
            shard,
            gap,
            max_nodes,
            seed,
            ..
        } => commands::run::run(
            &case,
            commands::run::Options {
                dmax,
                out,
                jobs: rayon::current_num_threads(),
                minimax,
                ranking: counterpoise_report::RankingOptions {
                    resolution,
                    tolerance,
                },
                // a shard stops after the optimisation: three phases
                progress: commands::progress::Progress::detect(
                    quiet,
                    if shard.is_some() { 3 } else { 4 },
                ),
                shard,
                search: counterpoise_study::SearchSettings {
                    gap,
                    max_nodes: max_nodes as usize,
                    seed,
                },
            },
        ),
        Command::Merge {
            inputs, out, quiet, ..
        } => commands::run::merge(
            &inputs,
            commands::run::MergeOptions {
                out,
                jobs: rayon::current_num_threads(),
                // Phase 1 and the search again, then Phase 3
                progress: commands::progress::Progress::detect(quiet, 3),
            },
        ),
        Command::Report {
            dir,
            tolerance,
            draw,
        } => Ok(commands::text::report(&dir, tolerance, &draw)),
        Command::ImportUrdf {
            urdf,
            out,
            base,
            tip,
        } => commands::import_urdf::run(
            &urdf,
            out.as_deref(),
            counterpoise_urdf::ImportOptions { base, tip },
        ),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

/// `I,J` (or `I→J`, as the reports write tasks, or `I->J`) → grid indices of a task.
fn parse_task(text: &str) -> Result<(usize, usize), String> {
    let (i, j) = ["→", "->", ","]
        .iter()
        .find_map(|sep| text.split_once(sep))
        .ok_or_else(|| format!("expected I,J (two grid indices), found `{text}`"))?;
    let parse = |s: &str| {
        s.trim()
            .parse::<usize>()
            .map_err(|_| format!("`{s}` is not a grid index"))
    };
    Ok((parse(i)?, parse(j)?))
}

/// `I/N`: shard I of N, 1 ≤ I ≤ N.
fn parse_shard(text: &str) -> Result<counterpoise::shard::ShardSpec, String> {
    text.parse()
        .map_err(|e: counterpoise::shard::ShardSpecError| e.to_string())
}

/// Percentage points: a finite number ≥ 0.
fn parse_gap(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(x) if x.is_finite() && x > 0.0 && x < 1.0 => Ok(x),
        _ => Err(format!(
            "`{text}` is not a relative gap (a number greater than 0 and less than 1, e.g. 1e-3)"
        )),
    }
}

/// `--dmax`: a positive count (0 is a usage error, exit 2, as every other bad option).
fn parse_dmax(text: &str) -> Result<usize, String> {
    match text.trim().parse::<usize>() {
        Ok(n) if n >= 1 => Ok(n),
        _ => Err(format!(
            "`{text}` is not a positive number of elements (at least 1)"
        )),
    }
}

fn parse_points(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(x) if x.is_finite() && x >= 0.0 => Ok(x),
        _ => Err(format!(
            "`{text}` is not a number of percentage points (finite, ≥ 0)"
        )),
    }
}
