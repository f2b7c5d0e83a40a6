//! Writing the outputs: atomically (a reader never sees a half-written file, and a crash leaves
//! the previous version), and regenerating the reports from results.json alone.

use std::fs::{self, File};
use std::io::Write;
use std::path::{Path, PathBuf};

use thiserror::Error;

use crate::results::{RunResults, SCHEMA_VERSION};
use crate::{csv, html, markdown};

/// File names inside the output directory.
pub const RESULTS_JSON: &str = "results.json";
pub const REPORT_HTML: &str = "report.html";
pub const REPORT_MD: &str = "report.md";
pub const RANKING_CSV: &str = "ranking.csv";

#[derive(Debug, Error)]
pub enum OutputError {
    // The OS reason is the source, printed once after the path by `{:#}` (anyhow's chain).
    #[error("{path}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{path}: not a valid results document")]
    Parse {
        path: PathBuf,
        #[source]
        source: serde_json::Error,
    },
    #[error(
        "{path}: schema version {found} is not supported (this build reads version {SCHEMA_VERSION})"
    )]
    Schema { path: PathBuf, found: u64 },
    #[error("serialising results: {0}")]
    Serialise(#[source] serde_json::Error),
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> OutputError + '_ {
    move |source| OutputError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// Writes `contents` to `dir/name` atomically: a temporary file in the same directory, flushed
/// and fsynced, then renamed over the target (rename is atomic within a file system), then the
/// directory fsynced so the rename itself survives a crash.
pub fn write_atomic(dir: &Path, name: &str, contents: &[u8]) -> Result<PathBuf, OutputError> {
    let target = dir.join(name);
    let tmp = dir.join(format!(".{name}.tmp-{}", std::process::id()));
    let result = (|| {
        let mut f = File::create(&tmp).map_err(io(&tmp))?;
        f.write_all(contents).map_err(io(&tmp))?;
        f.sync_all().map_err(io(&tmp))?;
        drop(f);
        fs::rename(&tmp, &target).map_err(io(&target))
    })();
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result?;
    // Directory fsync is not possible everywhere (e.g. on Windows); the data is already safe.
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
    Ok(target)
}

/// Writes results.json, report.html, report.md and ranking.csv into `dir` (created if needed).
/// Returns the paths written. Call [`RunResults::finalize`] first.
pub fn write_outputs(dir: &Path, results: &RunResults) -> Result<Vec<PathBuf>, OutputError> {
    fs::create_dir_all(dir).map_err(io(dir))?;
    // Compact: at Dmax 3 pretty-printing doubled the file (indentation of nested arrays).
    let json = serde_json::to_vec(results).map_err(OutputError::Serialise)?;
    let mut written = vec![write_atomic(dir, RESULTS_JSON, &json)?];
    written.extend(write_reports(dir, results)?);
    Ok(written)
}

/// Writes the three reports (not results.json): `counterpoise report DIR`, after it has added
/// what it computes from the case echo.
pub fn write_reports(dir: &Path, results: &RunResults) -> Result<Vec<PathBuf>, OutputError> {
    Ok(vec![
        write_atomic(dir, REPORT_HTML, html::render(results).as_bytes())?,
        write_atomic(dir, REPORT_MD, markdown::render(results).as_bytes())?,
        write_atomic(dir, RANKING_CSV, csv::render(results).as_bytes())?,
    ])
}

/// Reads `dir/results.json`, checking the schema version first so an old or future file gets a
/// clear message rather than a missing-field error.
pub fn read_results(dir: &Path) -> Result<RunResults, OutputError> {
    let path = dir.join(RESULTS_JSON);
    let text = fs::read_to_string(&path).map_err(io(&path))?;
    let value: serde_json::Value =
        serde_json::from_str(&text).map_err(|source| OutputError::Parse {
            path: path.clone(),
            source,
        })?;
    let found = value
        .get("schema_version")
        .and_then(|v| v.as_u64())
        .unwrap_or(0);
    if found != u64::from(SCHEMA_VERSION) {
        return Err(OutputError::Schema { path, found });
    }
    serde_json::from_value(value).map_err(|source| OutputError::Parse { path, source })
}

/// `counterpoise report DIR`: re-reads results.json and rewrites the three reports from it
/// (results.json itself is left untouched). Returns the paths written.
pub fn regenerate(dir: &Path) -> Result<Vec<PathBuf>, OutputError> {
    regenerate_with(dir, None)
}

/// [`regenerate`], with the decision section recomputed at `tolerance` (percentage points)
/// when one is given.
pub fn regenerate_with(dir: &Path, tolerance: Option<f64>) -> Result<Vec<PathBuf>, OutputError> {
    let mut results = read_results(dir)?;
    if let Some(t) = tolerance {
        results.redecide(t);
    }
    write_reports(dir, &results)
}
