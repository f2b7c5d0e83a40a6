//! `counterpoise merge DIR… --out DIR`: the shards of one study (`run --shard I/N`) assembled
//! into the results a single run writes.
//!
//! The checks come first and each names the file and the reason: every file is a shard file
//! of this build's format, all belong to one study (same case hash, Dmax, options, N), every
//! shard 1…N is there exactly once. The merge then recomputes Phase 1 and the balance search
//! from the case text the shards carry, checks that each shard optimised exactly the variants
//! the partition gives it and saw the same unbalanced robot, and runs Phase 3 through
//! [`super::run::finish`], as a single run does.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context as _, Result, bail};
use counterpoise::shard::{ShardSpec, shard_variants};
use counterpoise_model::Case;
use counterpoise_report::{PhaseTiming, RankingOptions};

use super::run::{Study, Timer, checked_dmax, finish, front};
use super::shard_file::{self, OptimisedRecord, ShardFile};

/// Options of the command.
pub struct Options {
    pub out: PathBuf,
    pub jobs: usize,
    pub progress: super::progress::Progress,
}

pub fn run(inputs: &[PathBuf], options: Options) -> Result<ExitCode> {
    let shards = read_shards(inputs)?;
    let (first_path, first) = &shards[0];
    let text = &first.case_text;
    let model = match Case::from_json_str_with(text, counterpoise::preflight::limits()) {
        Ok(model) => model,
        Err(errors) => {
            eprintln!(
                "{}: the case text in the shard file is not a valid case:",
                first_path.display()
            );
            for line in errors.lines() {
                eprintln!("  {line}");
            }
            return Ok(ExitCode::FAILURE);
        }
    };
    let hash = shard_file::case_sha256(&model)?;
    if hash != first.study.case_sha256 {
        bail!(
            "{}: the case text does not match the case hash recorded with it ({} ≠ {}): the \
             file was edited or damaged",
            first_path.display(),
            hash,
            first.study.case_sha256
        );
    }
    let case_path = Path::new(&first.case_path);
    let dmax = first.study.dmax;
    let Some(dmax) = checked_dmax(case_path, &model, Some(dmax), options.progress.mode)? else {
        return Ok(ExitCode::FAILURE);
    };
    std::fs::create_dir_all(&options.out).with_context(|| {
        format!(
            "cannot create the output directory {}",
            options.out.display()
        )
    })?;
    let mut timer = Timer::new(options.progress);
    let front = front(&model, dmax, &mut timer)?;

    let count = first.study.shards;
    let unbalanced = serde_json::to_value(&front.unbalanced)?;
    let mut optimised: Vec<OptimisedRecord> = Vec::new();
    let mut shard_timings: Vec<PhaseTiming> = Vec::new();
    for (path, shard) in &shards {
        let spec = ShardSpec {
            index: shard.shard,
            count,
        };
        let expected = shard_variants(&front.found.variants, spec);
        if shard.variants != expected {
            bail!(
                "{}: shard {spec} optimised other variants than the partition of this study \
                 gives it ({} listed, {} expected): it was written by another build",
                path.display(),
                shard.variants.len(),
                expected.len()
            );
        }
        let ids: Vec<usize> = shard.optimised.iter().map(|o| o.variant).collect();
        if ids != expected {
            bail!(
                "{}: shard {spec} holds {} optimisation results for its {} variants: the file \
                 is damaged",
                path.display(),
                shard.optimised.len(),
                expected.len()
            );
        }
        for o in &shard.optimised {
            let elements: Vec<&str> = front.found.variants[o.variant]
                .elements
                .iter()
                .map(|e| e.label.as_str())
                .collect();
            if o.elements != elements {
                bail!(
                    "{}: variant {} is {} in the shard but {} in this study",
                    path.display(),
                    o.variant,
                    o.label(),
                    elements.join(" + ")
                );
            }
        }
        if serde_json::to_value(&shard.unbalanced)? != unbalanced {
            bail!(
                "{}: shard {spec} computed other Phase 1 indicators of the unbalanced robot than \
                 this merge: run every shard and the merge with the same counterpoise build",
                path.display()
            );
        }
        optimised.extend(shard.optimised.iter().cloned());
        shard_timings.extend(shard.timings.iter().map(|t| PhaseTiming {
            phase: format!("shard {spec}: {}", t.phase),
            seconds: t.seconds,
        }));
    }
    let study = Study {
        model: &model,
        case_path: first.case_path.clone(),
        dmax,
        jobs: options.jobs,
        ranking: RankingOptions {
            resolution: first.study.resolution,
            tolerance: first.study.tolerance,
        },
        shards: Some(count),
        shard_timings,
    };
    finish(&study, &front, &optimised, timer, &options.out)
}

/// The shard files of `inputs` (directories are searched for `shard-*-of-*.json`), checked to
/// be the shards 1…N of one study, each once; sorted by shard index.
fn read_shards(inputs: &[PathBuf]) -> Result<Vec<(PathBuf, ShardFile)>> {
    let mut paths = Vec::new();
    for input in inputs {
        if input.is_dir() {
            let mut found: Vec<PathBuf> = std::fs::read_dir(input)
                .with_context(|| format!("cannot read the directory {}", input.display()))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| {
                    p.file_name()
                        .and_then(|n| n.to_str())
                        .is_some_and(shard_file::is_shard_file_name)
                })
                .collect();
            found.sort();
            paths.extend(found);
        } else if input.exists() {
            paths.push(input.clone());
        } else {
            bail!("{}: no such file or directory", input.display());
        }
    }
    if paths.is_empty() {
        bail!(
            "no shard files (shard-I-of-N.json) in {}",
            inputs
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    let mut shards: Vec<(PathBuf, ShardFile)> = Vec::new();
    for path in paths {
        let file = shard_file::read(&path)?;
        shards.push((path, file));
    }
    let (first_path, first) = &shards[0];
    let count = first.study.shards;
    let mut seen: BTreeMap<usize, &Path> = BTreeMap::new();
    for (path, shard) in &shards {
        if let Some(difference) = first.study.difference(&shard.study) {
            bail!(
                "{}: belongs to another study than {} ({difference})",
                path.display(),
                first_path.display()
            );
        }
        if shard.shard == 0 || shard.shard > count {
            bail!(
                "{}: shard index {} is outside 1…{count}",
                path.display(),
                shard.shard
            );
        }
        if let Some(other) = seen.insert(shard.shard, path) {
            bail!(
                "shard {}/{count} appears twice: {} and {}",
                shard.shard,
                other.display(),
                path.display()
            );
        }
    }
    let missing: Vec<usize> = (1..=count).filter(|i| !seen.contains_key(i)).collect();
    if !missing.is_empty() {
        let list = |f: &dyn Fn(usize) -> String| {
            missing.iter().map(|&i| f(i)).collect::<Vec<_>>().join(", ")
        };
        bail!(
            "the study of {} has {count} shards; missing: {} (no {}; rerun a missing shard \
             with `counterpoise run CASE --shard I/{count} --out DIR`)",
            first_path.display(),
            list(&|i| format!("{i}/{count}")),
            list(&|i| shard_file::file_name(i, count)),
        );
    }
    shards.sort_by_key(|(_, s)| s.shard);
    Ok(shards)
}
