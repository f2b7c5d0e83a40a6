//! `counterpoise run CASE` (the whole study, or with `--shard I/N` one shard's optimisation)
//! and `counterpoise merge SHARDS… --out DIR`: the study library's [`Study`] with progress on
//! stderr, the summary on stdout and the files written into the output directory.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::AtomicBool;

use anyhow::{Context as _, Result};
use counterpoise_report::RankingOptions;
use counterpoise_study::shard::ShardSpec;
use counterpoise_study::{SearchSettings, Study, StudyOptions, StudyOutcome, merge, shard_file};

use super::progress::Progress;

/// Options of `run`.
pub struct Options {
    pub dmax: Option<usize>,
    pub out: Option<PathBuf>,
    pub jobs: usize,
    pub minimax: bool,
    pub ranking: RankingOptions,
    pub progress: Progress,
    pub shard: Option<ShardSpec>,
    pub search: SearchSettings,
}

pub fn run(path: &Path, options: Options) -> Result<ExitCode> {
    let Some(model) = super::load(path) else {
        return Ok(ExitCode::FAILURE);
    };
    let study_options = StudyOptions {
        dmax: options.dmax,
        minimax: options.minimax,
        ranking: options.ranking,
        search: options.search,
        jobs: options.jobs,
        case_path: Some(path.to_path_buf()),
    };
    let study = match Study::new(&model, study_options) {
        Ok(study) => study,
        Err(e) => return Ok(super::failed(e)),
    };
    let mut progress = options.progress;
    for note in study.notes() {
        counterpoise_study::Progress::note(&mut progress, note);
    }
    let out_dir = options
        .out
        .unwrap_or_else(|| PathBuf::from("out").join(&model.name));
    create_dir(&out_dir)?;
    let cancel = AtomicBool::new(false);
    let Some(spec) = options.shard else {
        return finished(study.run(&mut progress, &cancel), &out_dir);
    };
    let case_text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    let file = match study.run_shard(spec, case_text, &mut progress, &cancel) {
        Ok(file) => file,
        Err(e) => return Ok(super::failed(e)),
    };
    let written = shard_file::write(&out_dir, &file)?;
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

/// Options of `merge`.
pub struct MergeOptions {
    pub out: PathBuf,
    pub jobs: usize,
    pub progress: Progress,
}

pub fn merge(inputs: &[PathBuf], options: MergeOptions) -> Result<ExitCode> {
    let shards = match merge::read_shards(inputs) {
        Ok(shards) => shards,
        Err(e) => return Ok(super::failed(e)),
    };
    create_dir(&options.out)?;
    let mut progress = options.progress;
    let cancel = AtomicBool::new(false);
    let outcome = merge::merge(&shards, options.jobs, &mut progress, &cancel);
    finished(outcome, &options.out)
}

fn create_dir(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create the output directory {}", dir.display()))
}

/// Writes a finished study's files and prints its summary and the files written.
fn finished(outcome: counterpoise_study::Result<StudyOutcome>, out_dir: &Path) -> Result<ExitCode> {
    let outcome = match outcome {
        Ok(outcome) => outcome,
        Err(e) => return Ok(super::failed(e)),
    };
    let written = match outcome.write(out_dir) {
        Ok(written) => written,
        Err(e) => return Ok(super::failed(e)),
    };
    print!("{}", outcome.summary());
    for f in written {
        println!("wrote {}", f.display());
    }
    Ok(ExitCode::SUCCESS)
}
