//! The command line on hostile inputs (issue 13): every one ends with a clear non-zero exit
//! naming the field — never a panic (exit 101) or an abort (134) — and `check` refuses what
//! `variants`, `evaluate` and `run` would refuse later. The inputs are in tests/data/hostile/.

use std::io::{BufRead, BufReader};
use std::path::PathBuf;
use std::process::{Command, Output, Stdio};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn counterpoise(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_counterpoise"))
        .args(args)
        .current_dir(root())
        .output()
        .expect("the binary runs")
}

fn hostile(name: &str) -> String {
    format!("tests/data/hostile/{name}.json")
}

/// Runs `args`, expects exit code 1 and every needle in stderr; returns stderr.
fn refused(args: &[&str], needles: &[&str]) -> String {
    let out = counterpoise(args);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{args:?}: {err}");
    for needle in needles {
        assert!(err.contains(needle), "{args:?}: `{needle}` not in\n{err}");
    }
    err
}

#[test]
fn malformed_files_name_the_field_and_position() {
    refused(
        &["check", &hostile("top_level_array")],
        &[".: a case file is one JSON object", "found an array"],
    );
    refused(
        &["check", &hostile("truncated")],
        &["is it truncated?", "(line "],
    );
    refused(
        &["check", &hostile("invalid_utf8")],
        &["not valid UTF-8", "byte 500 (0xff)", "(line "],
    );
    let err = refused(
        &["check", &hostile("many_errors")],
        &[
            "5 error(s)",
            "actuators[0].joint: unknown joint `nope`",
            "bodies[0].masss: unknown field `masss`",
            "bodies[1].mass: must be a finite number ≥ 0",
            "joints[1].axiss: unknown field",
            "tasks.extra: unknown field",
        ],
    );
    // sorted by path
    let actuators = err.find("actuators[0]").unwrap();
    let tasks = err.find("tasks.extra").unwrap();
    assert!(actuators < tasks);
}

#[test]
fn expressions_too_deep_or_too_long_are_errors_not_aborts() {
    for (name, needle) in [
        ("expr_nested_parens", "the limit is 10000"),
        ("expr_unary_minus", "the limit is 10000"),
        ("expr_long_sum", "the limit is 10000"),
        ("expr_deep_short", "deeper than 256 levels"),
    ] {
        refused(&["check", &hostile(name)], &["bodies[0].com[0]", needle]);
    }
    // lifting the limits: the nesting is parsed on a stack sized for it
    let out = counterpoise(&[
        "--limit",
        "expression-depth=5000",
        "check",
        &hostile("expr_deep_short"),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn grids_samples_and_variants_are_guarded() {
    refused(
        &["check", &hostile("empty_grid")],
        &["tasks.grid", "single point"],
    );
    refused(
        &["evaluate", &hostile("empty_grid")],
        &["tasks.grid", "single point"],
    );
    for name in [
        "grid_n_1e30",
        "grid_n_2e63",
        "grid_n_1e308",
        "grid_3e6_points",
        "grid_1e15_points",
    ] {
        refused(
            &["check", &hostile(name)],
            &["tasks.grid.M1[2]", "--limit grid-points=N"],
        );
    }
    refused(
        &["variants", "cases/palletizer.json", "--dmax", "50"],
        &["--dmax: 50 elements per variant; the limit is 8"],
    );
    refused(
        &["variants", "cases/palletizer.json", "--dmax", "5"],
        &[
            "122,437 variants (7 counterweights and 21 springs",
            "lower --dmax or restrict the elements",
            "--limit variants=N",
        ],
    );
    refused(
        &["evaluate", "cases/palletizer.json", "--samples", "100000"],
        &["--samples: 100,000 samples per task; the limit is 1,000"],
    );
}

#[test]
fn values_out_of_range_are_refused_at_load() {
    refused(
        &["check", &hostile("huge_mass_inertia_gravity")],
        &[
            "bodies[0].mass: 1e308 kg",
            "bodies[1].inertia[0]",
            "gravity[1]",
        ],
    );
    refused(
        &["variants", &hostile("link_1e308")],
        &["parameters.L1: 1e308", "bodies[1].pose"],
    );
    refused(
        &["check", &hostile("tiny_duration")],
        &["tasks.duration", "found 1e-300"],
    );
    refused(
        &["check", &hostile("pose_degree_300")],
        &["bodies[1].pose[64]", "degree 65"],
    );
}

#[test]
fn check_refuses_what_run_would_meet_later() {
    refused(
        &["check", &hostile("unreachable_waypoint")],
        &[
            "paths[0].waypoints.B",
            "waypoint `B`",
            "path `far` is not reachable",
        ],
    );
    refused(
        &[
            "run",
            &hostile("unreachable_waypoint"),
            "--out",
            "target/hostile-run",
        ],
        &["paths[0].waypoints.B"],
    );
    refused(
        &["check", &hostile("grid_unreachable")],
        &["tasks.grid: none of the 15 tasks can be evaluated"],
    );
}

/// `check` counts the tasks `evaluate` evaluates: the same numbers on a grid whose cyclic
/// actuator runs past its coordinate range.
#[test]
fn check_and_evaluate_agree_on_the_tasks() {
    let file = hostile("grid_partly_unreachable");
    let check = counterpoise(&["check", &file]);
    assert!(check.status.success());
    let text = String::from_utf8_lossy(&check.stdout);
    let line = text.lines().find(|l| l.starts_with("task grid:")).unwrap();
    let evaluate = counterpoise(&["evaluate", &file, "--json", "--no-reactions"]);
    let report: serde_json::Value = serde_json::from_slice(&evaluate.stdout).unwrap();
    let (tasks, evaluated) = (
        report["tasks"].as_u64().unwrap(),
        report["evaluated"].as_u64().unwrap(),
    );
    assert!(evaluated < tasks, "the grid is partly out of reach");
    assert!(
        line.contains(&format!("{tasks} tasks, {evaluated} evaluable")),
        "{line}"
    );
}

#[test]
fn a_case_without_balancing_is_accepted_with_a_note() {
    let out = counterpoise(&["check", &hostile("no_balancing")]);
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).contains("no `balancing` section"));
    refused(
        &["variants", &hostile("no_balancing")],
        &["no `balancing` section"],
    );
}

#[test]
fn a_huge_description_is_not_printed_whole() {
    let dir = root().join("target").join("hostile-description");
    std::fs::create_dir_all(&dir).unwrap();
    let mut case: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(root().join("cases/two_link.json")).unwrap())
            .unwrap();
    case["description"] = serde_json::json!("d".repeat(10 << 20));
    let file = dir.join("case.json");
    std::fs::write(&file, serde_json::to_string(&case).unwrap()).unwrap();
    let out = counterpoise(&["check", file.to_str().unwrap()]);
    assert!(out.status.success());
    assert!(
        out.stdout.len() < 10_000,
        "{} bytes printed",
        out.stdout.len()
    );
    // over the file-size limit: refused before reading
    let out = counterpoise(&[
        "--limit",
        "file-bytes=1000000",
        "check",
        file.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        err.contains("bytes in the file; the limit is 1,000,000"),
        "{err}"
    );
}

#[test]
fn a_closed_pipe_ends_the_output_quietly() {
    let mut child = Command::new(env!("CARGO_BIN_EXE_counterpoise"))
        .args(["variants", "cases/palletizer.json", "--json"])
        .current_dir(root())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut first = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut first)
        .unwrap();
    // the reader is dropped: the rest of the output (well over a pipe buffer) has nowhere to go
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("panicked"), "{err}");
    use std::os::unix::process::ExitStatusExt;
    assert!(
        out.status.code() == Some(0) || out.status.signal() == Some(13),
        "{:?}",
        out.status
    );
    assert_eq!(first.trim(), "{");
}
