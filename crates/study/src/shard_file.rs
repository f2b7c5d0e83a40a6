//! The partial result of one shard (`DIR/shard-I-of-N.json`) and the optimiser's record of one
//! variant as the post-optimisation stages read it.
//!
//! A shard file is self-contained: it carries the case file's text, so `merge` needs nothing
//! but the shard files, and the identity of its study (the case's hash, Dmax and every option
//! that changes results), so `merge` can refuse a shard of another study.

use std::path::{Path, PathBuf};

use crate::error::{Result, StudyError, invalid};
use counterpoise_dynamics::Indicators;
use counterpoise_model::Model;
use counterpoise_optimise::{Objective, OptimisedVariant};
use counterpoise_report::PhaseTiming;
use counterpoise_vocabulary::{Counterweight, PhysicalParameters, Spring, Status};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

/// The `format` field of every shard file.
pub const FORMAT: &str = "counterpoise-shard";
/// Version of the shard file layout; `merge` reads this version only.
pub const FORMAT_VERSION: u32 = 1;

/// What makes two shards parts of one study: `merge` requires these to be equal in every file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StudyKey {
    /// SHA-256 (hex) of the case as counterpoise read it: [`case_sha256`].
    pub case_sha256: String,
    pub dmax: usize,
    pub objective: Objective,
    /// Ranking resolution, percentage points (`--resolution`).
    pub resolution: f64,
    /// Equivalence tolerance of the decision, percentage points (`--tolerance`).
    pub tolerance: f64,
    /// N, the number of shards.
    pub shards: usize,
    /// The counterpoise version that wrote the shard: results are only comparable within one.
    pub tool_version: String,
}

impl StudyKey {
    /// The first field in which `self` and `other` differ, with both values, or `None`.
    pub fn difference(&self, other: &StudyKey) -> Option<String> {
        let fields = [
            (
                "case hash",
                self.case_sha256.clone(),
                other.case_sha256.clone(),
            ),
            ("Dmax", self.dmax.to_string(), other.dmax.to_string()),
            (
                "objective",
                format!("{:?}", self.objective),
                format!("{:?}", other.objective),
            ),
            (
                "--resolution",
                self.resolution.to_string(),
                other.resolution.to_string(),
            ),
            (
                "--tolerance",
                self.tolerance.to_string(),
                other.tolerance.to_string(),
            ),
            (
                "number of shards N",
                self.shards.to_string(),
                other.shards.to_string(),
            ),
            (
                "counterpoise version",
                self.tool_version.clone(),
                other.tool_version.clone(),
            ),
        ];
        fields
            .into_iter()
            .find(|(_, a, b)| a != b)
            .map(|(name, a, b)| format!("{name} {a} ≠ {b}"))
    }
}

/// The partial result of one shard.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ShardFile {
    /// [`FORMAT`].
    pub format: String,
    /// [`FORMAT_VERSION`].
    pub format_version: u32,
    pub study: StudyKey,
    /// I, 1-based.
    pub shard: usize,
    /// The case path as given to `run` (echoed in the merged results.json).
    pub case_path: String,
    /// The case file's text.
    pub case_text: String,
    /// Balanced variants of the whole study.
    pub balanced: usize,
    /// Enumeration indices of this shard's variants (the partition's shard I).
    pub variants: Vec<usize>,
    /// The partition's expected cost of this shard and of the whole study (see
    /// `counterpoise::shard::expected_cost`).
    pub expected_cost: u64,
    pub study_expected_cost: u64,
    /// Phase 1 as this shard computed it: `merge` checks that it computes the same.
    pub unbalanced: Indicators,
    /// This shard's phases, seconds.
    pub timings: Vec<PhaseTiming>,
    /// The optimiser's records of this shard's variants, in enumeration order.
    pub optimised: Vec<OptimisedRecord>,
}

/// `shard-I-of-N.json`.
pub fn file_name(index: usize, count: usize) -> String {
    format!("shard-{index}-of-{count}.json")
}

/// Whether `name` looks like a shard file (`shard-*-of-*.json`; temporary files start with a
/// dot and are never matched).
pub fn is_shard_file_name(name: &str) -> bool {
    name.starts_with("shard-") && name.ends_with(".json") && name.contains("-of-")
}

/// SHA-256 of the case's canonical JSON (the case as counterpoise parsed it, serialised with
/// serde_json: fields in a fixed order, numbers in shortest round-trip form), so that
/// re-indenting the file does not change it but any change of a value does.
pub fn case_sha256(model: &Model) -> Result<String> {
    let canonical = serde_json::to_vec(&serde_json::to_value(&model.case)?)?;
    Ok(Sha256::digest(&canonical)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect())
}

/// What the stages after the optimisation read of one variant's optimisation: the same for a
/// single run and a merge, so that both assemble results.json from the same data. (The
/// optimiser's full record also holds its iteration log and free parameters, which
/// results.json does not contain.)
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct OptimisedRecord {
    /// Index of the variant in the balance search's enumeration.
    pub variant: usize,
    pub elements: Vec<String>,
    /// `feasible`, `discarded` or `undecided`, as the optimiser decided.
    pub outcome: Status,
    pub reason: Option<String>,
    pub objective: Option<f64>,
    pub lower_bound: Option<f64>,
    pub gap: Option<f64>,
    /// Balance residual of the final parameters.
    pub residual: Option<f64>,
    /// Passes of the critical-task loop.
    pub iterations: usize,
    /// Boxes the certified branch-and-bound solved, over all passes.
    #[serde(default)]
    pub boxes: usize,
    pub counterweights: Vec<Counterweight>,
    pub springs: Vec<Spring>,
    /// Over all tasks, for the finalists.
    pub indicators: Option<Indicators>,
}

impl OptimisedRecord {
    pub fn new(variant: usize, o: &OptimisedVariant) -> OptimisedRecord {
        OptimisedRecord {
            variant,
            elements: o.elements.clone(),
            outcome: o.status,
            reason: o.reason.clone(),
            objective: o.objective,
            lower_bound: o.lower_bound,
            gap: o.gap,
            residual: o.residual,
            iterations: o.iterations.len(),
            boxes: o.iterations.iter().map(|i| i.boxes).sum(),
            counterweights: o.counterweights.clone(),
            springs: o.springs.clone(),
            indicators: o.indicators.clone(),
        }
    }

    /// The optimised elements: what the dynamics evaluates and the report records.
    pub fn physical_parameters(&self) -> PhysicalParameters {
        PhysicalParameters {
            counterweights: self.counterweights.clone(),
            springs: self.springs.clone(),
        }
    }

    pub fn label(&self) -> String {
        self.elements.join(" + ")
    }
}

/// Writes `file` into `dir` as `shard-I-of-N.json`, atomically (a temporary file renamed into
/// place): a shard killed while writing leaves no file `merge` could take for a complete one.
pub fn write(dir: &Path, file: &ShardFile) -> Result<PathBuf> {
    let json = serde_json::to_vec(file)?;
    let name = file_name(file.shard, file.study.shards);
    Ok(counterpoise_report::output::write_atomic(
        dir, &name, &json,
    )?)
}

/// Reads one shard file, checking its format.
pub fn read(path: &Path) -> Result<ShardFile> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        StudyError::io(format!("{}: cannot read the shard file", path.display()), e)
    })?;
    // The format first, so that another JSON file is named as such rather than by the first
    // field serde misses.
    let value: serde_json::Value = serde_json::from_str(&text).map_err(|e| {
        StudyError::Invalid(format!(
            "{}: not a shard file (invalid JSON): {e}",
            path.display()
        ))
    })?;
    if value.get("format").and_then(|f| f.as_str()) != Some(FORMAT) {
        invalid!(
            "{}: not a shard file (no \"format\": \"{FORMAT}\"; shard files are written by \
             `counterpoise run CASE --shard I/N`)",
            path.display()
        );
    }
    let version = value.get("format_version").and_then(|v| v.as_u64());
    if version != Some(u64::from(FORMAT_VERSION)) {
        invalid!(
            "{}: shard file format version {} is not supported (this build reads version \
             {FORMAT_VERSION})",
            path.display(),
            version.map_or("(missing)".to_string(), |v| v.to_string())
        );
    }
    serde_json::from_value(value).map_err(|e| {
        StudyError::Invalid(format!("{}: not a valid shard file: {e}", path.display()))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shard_file_names_are_recognised_and_temporary_files_are_not() {
        assert!(is_shard_file_name(&file_name(2, 3)));
        for other in [
            ".shard-2-of-3.json.tmp-4242",
            "shard-2-of-3.json.bak",
            "shard-notes.json",
            "results.json",
            "my-shard-1-of-2.json",
        ] {
            assert!(!is_shard_file_name(other), "{other} taken for a shard file");
        }
    }
}
