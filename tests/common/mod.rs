//! Helpers shared by the command-line tests (a module, not a test binary of its own).
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

pub mod process;
pub mod variants;

/// The workspace root, where `cases/` lives.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Runs the binary with `args` from the workspace root.
pub fn counterpoise(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_counterpoise"))
        .args(args)
        .current_dir(root())
        .output()
        .expect("the binary runs")
}

pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Asserts a zero exit status, showing stderr otherwise.
pub fn assert_success(o: &Output) {
    assert!(o.status.success(), "{:?}: {}", o.status, stderr(o));
}

/// A case file of `cases/` as JSON, for editing.
pub fn case_json(name: &str) -> serde_json::Value {
    let text = std::fs::read_to_string(root().join("cases").join(name)).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// Writes `case` into `dir` as `name` and returns its path as a string.
pub fn write_case(dir: &Path, name: &str, case: &serde_json::Value) -> String {
    let path = dir.join(name);
    std::fs::write(&path, serde_json::to_string_pretty(case).unwrap()).unwrap();
    path.to_str().unwrap().to_string()
}

/// The palletizer with `points` grid values per actuator over the case's ranges and
/// `samples` samples per move.
pub fn reduced_palletizer(points: usize, samples: usize) -> serde_json::Value {
    let mut case = case_json("palletizer.json");
    for axis in case["tasks"]["grid"].as_object_mut().unwrap().values_mut() {
        axis[2] = serde_json::json!(points);
    }
    case["tasks"]["samples"] = serde_json::json!(samples);
    case
}

/// `results.json` of a run directory.
pub fn results(out: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(out.join("results.json")).unwrap()).unwrap()
}

/// A number of a JSON object.
pub fn num(v: &serde_json::Value, key: &str) -> f64 {
    v[key]
        .as_f64()
        .unwrap_or_else(|| panic!("{key} is not a number in {v}"))
}

/// `run` of the palletizer on a 2 × 2 × 2 grid with 11 samples per move (a few seconds: every
/// report section is there) into `dir/out`; returns that directory.
pub fn run_reduced_palletizer(dir: &Path) -> PathBuf {
    let case = write_case(dir, "tiny.json", &reduced_palletizer(2, 11));
    let out = dir.join("out");
    assert_success(&counterpoise(&[
        "run",
        &case,
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]));
    out
}
