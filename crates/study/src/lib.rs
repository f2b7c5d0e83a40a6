//! counterpoise's case study as a library: from a validated case to ranked, verified results.
//!
//! A [`Study`] runs Phase 1 (the unbalanced robot over every task), the exact balance search,
//! the certified optimisation of every balanced variant and Phase 3 (ranking, practical
//! figures, torque curves, schematics), and returns the results document that `counterpoise
//! run` writes as results.json. Shards of a study ([`Study::run_shard`]) merge into exactly the
//! single run's results ([`merge::merge`]). The command line and the Python module are thin
//! layers over this crate.
//!
//! The two-link arm of the repository's `cases/`, start to finish:
//!
//! ```
//! use std::sync::atomic::AtomicBool;
//! use counterpoise_study::{Silent, Study, StudyOptions, load_case};
//! use counterpoise_report::Status;
//!
//! let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../cases/two_link.json");
//! let model = load_case(path.as_ref()).expect("a valid case");
//! let study = Study::new(&model, StudyOptions::default()).expect("within the limits");
//! let outcome = study.run(&mut Silent, &AtomicBool::new(false)).expect("a finished study");
//! let best = outcome.results.variants.iter().find(|v| v.rank == Some(1)).expect("a ranked variant");
//! assert_eq!(best.status, Status::Feasible);
//! assert!(best.verification_residual.expect("verified") < 1e-9);
//! println!("best: {} (ΔQTR {:+.1} %)", best.label(), best.dqtr.unwrap_or_default());
//! ```

pub mod check;
pub mod design;
pub mod error;
pub mod evaluate;
pub mod figures;
pub mod guards;
pub mod merge;
pub mod partial;
pub mod preflight;
pub mod progress;
mod record;
pub mod reports;
pub mod shard;
pub mod shard_file;
pub mod states;
pub mod study;
pub mod variants;

use std::path::Path;

use counterpoise_model::{Case, Model};

pub use error::{Result, StudyError};
pub use progress::{Count, Phase, Progress, Silent};
pub use study::{Front, SearchSettings, Study, StudyOptions, StudyOutcome, Timer};

/// Loads and validates a case file within the limits in force ([`preflight::limits`]): every
/// problem, each naming its field, line and column, in [`StudyError::Case`].
pub fn load_case(path: &Path) -> Result<Model> {
    Case::from_path_with(path, preflight::limits()).map_err(|errors| StudyError::Case {
        path: path.to_path_buf(),
        errors,
    })
}

/// Writes `contents` to the file `path` atomically (a temporary file in the same directory,
/// renamed over the target), so a reader never sees a half-written file.
pub fn write_file(path: &Path, contents: &[u8]) -> Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let Some(name) = path.file_name().and_then(|n| n.to_str()) else {
        return Err(StudyError::Invalid(format!(
            "{}: not a file path",
            path.display()
        )));
    };
    counterpoise_report::write_atomic(dir, name, contents)?;
    Ok(())
}
