//! `counterpoise merge DIR… --out DIR`: the shards of one study (`run --shard I/N`) assembled
//! into the results a single run writes.
//!
//! The checks come first and each names the file and the reason: every file is a shard file
//! of this build's format, all belong to one study (same case hash, Dmax, options, N), every
//! shard 1…N is there exactly once. The merge then recomputes Phase 1 and the balance search
//! from the case text the shards carry, checks that each shard optimised exactly the variants
//! the partition gives it and saw the same unbalanced robot, and runs Phase 3 through
//! [`Study::finish`], as a single run does.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use counterpoise_model::Case;
use counterpoise_optimise::Objective;
use counterpoise_report::{PhaseTiming, RankingOptions};

use crate::error::{Result, StudyError, invalid};
use crate::preflight;
use crate::progress::Progress;
use crate::shard::{ShardSpec, shard_variants};
use crate::shard_file::{self, OptimisedRecord, ShardFile};
use crate::study::{Study, StudyOptions, StudyOutcome, Timer};

/// Merges the shards of one study (as [`read_shards`] returns them) into the results a single
/// run gives: the case is rebuilt from the text the shards carry and checked against its
/// hash, Phase 1 and the search are run again, every shard is checked against them, and Phase
/// 3 runs on all the records.
pub fn merge(
    shards: &[(PathBuf, ShardFile)],
    jobs: usize,
    progress: &mut dyn Progress,
    cancel: &AtomicBool,
) -> Result<StudyOutcome> {
    let (first_path, first) = &shards[0];
    let text = &first.case_text;
    let model = match Case::from_json_str_with(text, preflight::limits()) {
        Ok(model) => model,
        Err(errors) => {
            let mut lines = vec![format!(
                "{}: the case text in the shard file is not a valid case:",
                first_path.display()
            )];
            lines.extend(errors.lines().iter().map(|l| format!("  {l}")));
            return Err(StudyError::Problems(lines.join("\n")));
        }
    };
    let hash = shard_file::case_sha256(&model)?;
    if hash != first.study.case_sha256 {
        invalid!(
            "{}: the case text does not match the case hash recorded with it ({} ≠ {}): the \
             file was edited or damaged",
            first_path.display(),
            hash,
            first.study.case_sha256
        );
    }
    let study = Study::new(
        &model,
        StudyOptions {
            dmax: Some(first.study.dmax),
            minimax: first.study.objective == Objective::Minimax,
            ranking: RankingOptions {
                resolution: first.study.resolution,
                tolerance: first.study.tolerance,
            },
            jobs,
            case_path: Some(PathBuf::from(&first.case_path)),
            ..StudyOptions::default()
        },
    )?;
    for note in study.notes() {
        progress.note(note);
    }
    let mut timer = Timer::new(progress, cancel);
    let front = study.front(&mut timer)?;

    let count = first.study.shards;
    let unbalanced = serde_json::to_value(&front.unbalanced)?;
    let mut optimised: Vec<OptimisedRecord> = Vec::new();
    let mut shard_timings: Vec<PhaseTiming> = Vec::new();
    for (path, shard) in shards {
        let spec = ShardSpec {
            index: shard.shard,
            count,
        };
        let expected = shard_variants(&front.found.variants, spec);
        if shard.variants != expected {
            invalid!(
                "{}: shard {spec} optimised other variants than the partition of this study \
                 gives it ({} listed, {} expected): it was written by another build",
                path.display(),
                shard.variants.len(),
                expected.len()
            );
        }
        let ids: Vec<usize> = shard.optimised.iter().map(|o| o.variant).collect();
        if ids != expected {
            invalid!(
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
                invalid!(
                    "{}: variant {} is {} in the shard but {} in this study",
                    path.display(),
                    o.variant,
                    o.label(),
                    elements.join(" + ")
                );
            }
        }
        if serde_json::to_value(&shard.unbalanced)? != unbalanced {
            invalid!(
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
    study
        .merged(count, shard_timings)
        .finish(&front, &optimised, timer)
}

/// The shard files of `inputs` (directories are searched for `shard-*-of-*.json`), checked to
/// be the shards 1…N of one study, each once; sorted by shard index.
pub fn read_shards(inputs: &[PathBuf]) -> Result<Vec<(PathBuf, ShardFile)>> {
    let mut paths = Vec::new();
    for input in inputs {
        if input.is_dir() {
            let mut found: Vec<PathBuf> = std::fs::read_dir(input)
                .map_err(|e| {
                    StudyError::io(format!("cannot read the directory {}", input.display()), e)
                })?
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
            invalid!("{}: no such file or directory", input.display());
        }
    }
    if paths.is_empty() {
        invalid!(
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
            invalid!(
                "{}: belongs to another study than {} ({difference})",
                path.display(),
                first_path.display()
            );
        }
        if shard.shard == 0 || shard.shard > count {
            invalid!(
                "{}: shard index {} is outside 1…{count}",
                path.display(),
                shard.shard
            );
        }
        if let Some(other) = seen.insert(shard.shard, path) {
            invalid!(
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
        invalid!(
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
