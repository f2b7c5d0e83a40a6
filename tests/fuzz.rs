//! Fuzz harness (issue 13): mutations of the shipped cases must load or be refused with errors,
//! and a loadable one must go through everything `check` runs (validation, then the preflight:
//! variant count, catalogue, paths, the task grid as `evaluate` sees it) and the balance search
//! at Dmax 1 — never a panic, within a time and memory budget.
//!
//! Each case applies up to two mutations, either to the JSON tree (a value replaced by an odd one,
//! a number rescaled, a member removed, an array element duplicated, a key renamed) or to the text (truncated, a
//! byte overwritten). CI runs 300 cases (a few seconds; `FUZZ_STATS=1` prints which loaded); `PROPTEST_CASES=10000 cargo test
//! --release --test fuzz` runs more.
//!
//! The extreme-value fuzz (issue 28) sets numbers of the shipped cases to ±1e308, ±1e-308,
//! subnormals, ±0 and values just inside and outside each field's limit, and runs the binary on
//! each (`check`, which runs every command's preflight, then `variants --dmax 1`) with a
//! wall-time budget per case: a hang is killed and reported with the case instead of stalling
//! the run, and an abort or a panic is reported too. CI runs 300 cases (about half a minute);
//! `FUZZ_EXTREME_CASES=10000 cargo test --release --test fuzz extreme -- --nocapture` runs more
//! and prints the counts (`FUZZ_EXTREME_SEED` picks another sequence).

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;
use std::sync::mpsc;
use std::time::{Duration, Instant};

mod common;

use common::process::{Ran, run_binary};
use counterpoise::balance::{
    Catalogue, SearchOptions, catalogue_options, mechanism_energy, realization_hints, search,
};
use counterpoise::model::Case;
use counterpoise::model::limits::Limits;
use counterpoise::model::sampling::SplitMix64;
use counterpoise::model::validate::{
    DURATION_RANGE, MAX_ANGLE, MAX_DENSITY, MAX_GRAVITY, MAX_INERTIA, MAX_LENGTH, MAX_MASS,
    MAX_PARAMETER, MAX_RATIO, MAX_STIFFNESS, MAX_TORQUE, MIN_AXIS_NORM,
};
use counterpoise::preflight;
use proptest::prelude::*;
use serde_json::{Value, json};

/// Longest a single case may take (load + search), generous for a loaded CI machine.
const BUDGET: Duration = Duration::from_secs(10);
/// Largest resident memory the whole run may reach.
const MEMORY_BUDGET_KB: u64 = 1 << 20;

/// The shipped cases, the palletizer's grid coarsened to 3 × 3 × 3 points and 11 samples so
/// that the task-grid check of a case costs milliseconds (robustness, not accuracy, is tested).
fn shipped() -> Vec<Value> {
    ["palletizer", "pendulum", "two_link"]
        .iter()
        .map(|name| {
            let path = format!("{}/cases/{name}.json", env!("CARGO_MANIFEST_DIR"));
            let mut case: Value =
                serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
            if let Some(grid) = case
                .pointer_mut("/tasks/grid")
                .and_then(Value::as_object_mut)
            {
                for axis in grid.values_mut() {
                    axis[2] = json!(3);
                }
                case["tasks"]["samples"] = json!(11);
            }
            case
        })
        .collect()
}

fn odd_values() -> Vec<Value> {
    vec![
        json!(-1),
        json!(0),
        json!(1),
        json!(1e308),
        json!(-1e-300),
        json!(1e15),
        json!(18446744073709551615u64),
        json!(""),
        json!("base"),
        json!("q1"),
        json!("th1"),
        json!("((((((((((1))))))))))"),
        json!("cos(th1)^64*sin(q1)^64"),
        json!("1/0"),
        json!("-".repeat(500) + "1"),
        json!([]),
        json!([0, 0, 0]),
        json!([1, 0]),
        json!([0, 1, 1]),
        json!({}),
        json!(null),
        json!(true),
    ]
}

/// JSON pointers of every value in `v`.
fn pointers(v: &Value, prefix: String, out: &mut Vec<String>) {
    match v {
        Value::Object(map) => {
            for (k, child) in map {
                pointers(
                    child,
                    format!("{prefix}/{}", k.replace('~', "~0").replace('/', "~1")),
                    out,
                );
            }
        }
        Value::Array(items) => {
            for (i, child) in items.iter().enumerate() {
                pointers(child, format!("{prefix}/{i}"), out);
            }
        }
        _ => {}
    }
    out.push(prefix);
}

/// One tree mutation chosen by `op` at the node chosen by `which`.
fn mutate(v: &mut Value, op: u8, which: usize, pick: usize) {
    let mut all = Vec::new();
    pointers(v, String::new(), &mut all);
    let pointer = all[which % all.len()].clone();
    if pointer.is_empty() {
        return;
    }
    let (parent, key) = pointer.rsplit_once('/').unwrap();
    let key = key.replace("~1", "/").replace("~0", "~");
    let odd = odd_values();
    match (op % 5, v.pointer_mut(parent)) {
        (0, _) => *v.pointer_mut(&pointer).unwrap() = odd[pick % odd.len()].clone(),
        // Rescale a number by 10^-20 … 10^19: stresses the numerics, keeps the shape.
        (4, _) => {
            let target = v.pointer_mut(&pointer).unwrap();
            if let Some(x) = target.as_f64() {
                *target = json!(x * 10f64.powi(pick as i32 % 40 - 20));
            }
        }
        (1, Some(Value::Object(map))) => {
            map.remove(&key);
        }
        (1, Some(Value::Array(items))) => {
            items.remove(key.parse::<usize>().unwrap());
        }
        (2, Some(Value::Array(items))) => {
            let i = key.parse::<usize>().unwrap();
            let copy = items[i].clone();
            items.insert(i, copy);
        }
        (3, Some(Value::Object(map))) => {
            if let Some(value) = map.remove(&key) {
                map.insert(format!("{key}_"), value);
            }
        }
        _ => {}
    }
}

/// Loads the text; a loaded case goes through the preflight of `check` and, with balancing,
/// the search at Dmax 1.
fn load_and_search(text: &str) {
    let loaded = Case::from_json_str(text);
    let problems = loaded
        .as_ref()
        .ok()
        .map(|model| preflight::problems(model).0.len());
    if std::env::var_os("FUZZ_STATS").is_some() {
        eprintln!("FUZZ loaded={} problems={problems:?}", loaded.is_ok());
    }
    if let Ok(model) = loaded
        && model.balancing.is_some()
    {
        let energy = mechanism_energy(&model);
        let catalogue = Catalogue::build(&energy, &catalogue_options(&model));
        if !catalogue.is_empty() {
            search(
                &energy,
                catalogue,
                SearchOptions {
                    dmax: 1,
                    hints: realization_hints(&model),
                },
            );
        }
    }
}

fn peak_memory_kb() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]
    #[test]
    fn mutated_cases_load_or_fail_cleanly(
        case in 0usize..3,
        ops in proptest::collection::vec((0u8..5, 0usize..100_000, 0usize..1_000), 0..3),
        text_op in 0u8..8,
        cut in 0usize..100_000,
        byte in 0u8..=255,
    ) {
        let mut v = shipped().swap_remove(case);
        for (op, which, pick) in ops {
            mutate(&mut v, op, which, pick);
        }
        let mut bytes = serde_json::to_string_pretty(&v).unwrap().into_bytes();
        match text_op {
            0 => bytes.truncate(cut % (bytes.len() + 1)),
            1 => { let i = cut % bytes.len(); bytes[i] = byte; }
            _ => {}
        }
        let text = String::from_utf8_lossy(&bytes).into_owned();
        let started = Instant::now();
        let outcome = catch_unwind(AssertUnwindSafe(|| load_and_search(&text)));
        let elapsed = started.elapsed();
        prop_assert!(outcome.is_ok(), "panicked on:\n{}", &text[..text.len().min(4000)]);
        prop_assert!(elapsed < BUDGET, "took {elapsed:?}");
        if let Some(kb) = peak_memory_kb() {
            prop_assert!(kb < MEMORY_BUDGET_KB, "peak memory {kb} kB");
        }
    }
}

// ---- extreme values (issue 28) ----------------------------------------------------------

/// The shipped cases (every `.json` file of `cases/`), coarsened like [`shipped`].
fn all_shipped() -> Vec<(String, Value)> {
    let dir = format!("{}/cases", env!("CARGO_MANIFEST_DIR"));
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.ends_with(".json"))
        .collect();
    names.sort();
    names
        .into_iter()
        .map(|name| {
            let mut case: Value =
                serde_json::from_str(&std::fs::read_to_string(format!("{dir}/{name}")).unwrap())
                    .unwrap();
            coarsen(&mut case);
            (name, case)
        })
        .collect()
}

/// The task grid cut to at most 3 values per actuator and 11 samples per move (as [`shipped`]).
/// An axis of fewer values keeps them: raised to 3, the two fixed wrist axes of `arm6.json`
/// would make its 81 points 729 and its `check` take tens of seconds.
fn coarsen(case: &mut Value) {
    if let Some(grid) = case
        .pointer_mut("/tasks/grid")
        .and_then(Value::as_object_mut)
    {
        for axis in grid.values_mut() {
            let n = axis[2].as_u64().unwrap_or(3).min(3);
            axis[2] = json!(n);
        }
        case["tasks"]["samples"] = json!(11);
    }
}

/// Huge, tiny, subnormal and signed-zero values, and each field limit of the validator with its
/// neighbours just inside and just outside (`next_down`/`next_up`), both signs.
fn extreme_numbers() -> Vec<f64> {
    let mut out = vec![
        1e308,
        -1e308,
        f64::MAX,
        -f64::MAX,
        1e-308,
        -1e-308,
        f64::MIN_POSITIVE,
        5e-324,
        -5e-324,
        2.5e-320,
        0.0,
        -0.0,
        // the square of a component overflows from √MAX ≈ 1.34e154 up
        -1.3e154,
        1.4e154,
        1e-154,
        1e-162,
        1e300,
        1e-300,
    ];
    let limits = [
        MAX_LENGTH,
        MAX_ANGLE,
        MAX_MASS,
        MAX_INERTIA,
        MAX_GRAVITY,
        MAX_PARAMETER,
        MAX_RATIO,
        MAX_TORQUE,
        MAX_STIFFNESS,
        MAX_DENSITY,
        DURATION_RANGE[0],
        DURATION_RANGE[1],
        MIN_AXIS_NORM,
    ];
    // the default limits on counts (grid points, samples per task, Dmax)
    let counts = Limits::default();
    let limits = limits
        .into_iter()
        .chain([counts.grid_points, counts.samples, counts.dmax].map(|n| n as f64));
    for limit in limits {
        for x in [limit, limit.next_down(), limit.next_up()] {
            out.push(x);
            out.push(-x);
        }
    }
    out
}

/// JSON pointers of the number leaves of `v`, and of its string leaves but `name` and
/// `description` (most are expressions; the others, a parent or a kind, only test that a
/// number written where a name belongs is refused).
fn number_pointers(v: &Value, prefix: String, numbers: &mut Vec<String>, texts: &mut Vec<String>) {
    match v {
        Value::Object(map) => {
            for (k, child) in map {
                if matches!(k.as_str(), "name" | "description") {
                    continue;
                }
                number_pointers(
                    child,
                    format!("{prefix}/{}", k.replace('~', "~0").replace('/', "~1")),
                    numbers,
                    texts,
                );
            }
        }
        Value::Array(items) => {
            for (i, child) in items.iter().enumerate() {
                number_pointers(child, format!("{prefix}/{i}"), numbers, texts);
            }
        }
        Value::Number(_) => numbers.push(prefix),
        Value::String(_) => texts.push(prefix),
        _ => {}
    }
}

/// A JSON number for `x` (serde_json writes `-0.0` and `5e-324` as such).
fn number(x: f64) -> Value {
    Value::from(x)
}

/// One extreme mutation: a number leaf set to an extreme value, or (one time in four) an
/// expression scaled or replaced by one (`1e308*(d2)`). Returns what it did.
fn mutate_extreme(v: &mut Value, rng: &mut SplitMix64, values: &[f64]) -> String {
    let (mut numbers, mut texts) = (Vec::new(), Vec::new());
    number_pointers(v, String::new(), &mut numbers, &mut texts);
    let x = values[rng.next_u64() as usize % values.len()];
    if !texts.is_empty() && (numbers.is_empty() || rng.next_u64().is_multiple_of(4)) {
        let pointer = &texts[rng.next_u64() as usize % texts.len()];
        let target = v.pointer_mut(pointer).unwrap();
        let old = target.as_str().unwrap_or_default().to_string();
        *target = match rng.next_u64() % 3 {
            0 => json!(format!("{x:e}*({old})")),
            1 => json!(format!("({old})+{x:e}")),
            _ => number(x),
        };
        format!("{pointer} = {target}")
    } else {
        let pointer = &numbers[rng.next_u64() as usize % numbers.len()];
        *v.pointer_mut(pointer).unwrap() = number(x);
        format!("{pointer} = {x:e}")
    }
}

/// The field paths of the errors the binary printed: its error lines are
/// `  joints[9].axis: reason (line 442, column 7)`.
fn error_paths(stderr: &str) -> Vec<String> {
    stderr
        .lines()
        .filter_map(|l| l.strip_prefix("  "))
        .filter_map(|l| l.split_once(": ").map(|(path, _)| path.trim().to_string()))
        .collect()
}

/// What the binary answered on one case: `check` (validation and every command's preflight)
/// and `variants --dmax 1`, within [`BUDGET`] for the two together.
struct CaseAnswer {
    /// `check`'s exit status and the paths of its errors.
    check: Result<(i32, Vec<String>), String>,
    variants: Result<i32, String>,
    time: Duration,
}

/// Why a run is not an answer: a hang, a signal, a panic, an unexpected exit status, or a
/// failure without a message.
fn not_an_answer(ran: Ran) -> Result<(i32, String), String> {
    match ran {
        Ran::Hung(used) => Err(format!(
            "no answer within {BUDGET:?}{}",
            used.map(|t| format!(" (it had used {:.1} s of processor time)", t.as_secs_f64()))
                .unwrap_or_default()
        )),
        Ran::Signalled(what) => Err(format!("ended by a signal ({what})")),
        Ran::Exited(_, stderr) if stderr.contains("panicked") => Err(format!("panic: {stderr}")),
        Ran::Exited(code, stderr) if !(0..=2).contains(&code) => {
            Err(format!("exit status {code}: {stderr}"))
        }
        Ran::Exited(code, stderr) if code != 0 && stderr.trim().is_empty() => {
            Err(format!("exit status {code} without a message"))
        }
        Ran::Exited(code, stderr) => Ok((code, stderr)),
    }
}

/// Writes `case` to `dir` and runs `check` and `variants --dmax 1` on it.
fn answer_case(case: &Value, dir: &Path) -> CaseAnswer {
    let file = dir.join("case.json");
    std::fs::write(&file, serde_json::to_string_pretty(case).unwrap()).unwrap();
    let file = file.to_str().unwrap();
    let started = Instant::now();
    let deadline = started + BUDGET;
    let check =
        not_an_answer(run_binary(&["check", file], dir, deadline)).and_then(|(code, stderr)| {
            let paths = error_paths(&stderr);
            if code == 1 && paths.is_empty() {
                Err(format!("check failed without naming a field: {stderr}"))
            } else {
                Ok((code, paths))
            }
        });
    let variants = not_an_answer(run_binary(
        &["variants", file, "--dmax", "1"],
        dir,
        deadline,
    ))
    .map(|(code, _)| code);
    CaseAnswer {
        check,
        variants,
        time: started.elapsed(),
    }
}

fn env_number(name: &str, default: u64) -> u64 {
    std::env::var(name)
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

/// Extreme values in the numeric fields (and expressions) of the shipped cases, up to three per
/// case: `check` and `variants --dmax 1` each answer (exit 0, or an error naming a field) within
/// [`BUDGET`] per case, with no panic and no signal. Prints the counts and the slowest case.
#[test]
fn extreme_values_are_answered_within_the_budget() {
    let cases = env_number("FUZZ_EXTREME_CASES", 300);
    let seed = env_number("FUZZ_EXTREME_SEED", 28);
    let shipped = all_shipped();
    let values = extreme_numbers();
    let dir = tempfile::tempdir().unwrap();
    let mut rng = SplitMix64::new(seed);
    let (mut refused, mut accepted, mut searched) = (0, 0, 0);
    let mut failures = Vec::new();
    let mut slowest = (Duration::ZERO, String::new());
    let started = Instant::now();
    for k in 0..cases {
        let (name, base) = &shipped[rng.next_u64() as usize % shipped.len()];
        let mut case = base.clone();
        // one mutation half the time (most extreme values are refused: one alone is likelier
        // to be legal and to reach the preflight and the search), else two or three
        let count = [1, 1, 1, 2, 2, 3][rng.next_u64() as usize % 6];
        let mutations: Vec<String> = (0..count)
            .map(|_| mutate_extreme(&mut case, &mut rng, &values))
            .collect();
        let what = format!("case {k}: {name} with {}", mutations.join(", "));
        let answer = answer_case(&case, dir.path());
        match answer.check {
            Ok((0, _)) => accepted += 1,
            Ok(_) => refused += 1,
            Err(why) => failures.push(format!("check: {why}: {what}")),
        }
        match answer.variants {
            Ok(0) => searched += 1,
            Ok(_) => {}
            Err(why) => failures.push(format!("variants --dmax 1: {why}: {what}")),
        }
        if answer.time > slowest.0 {
            slowest = (answer.time, what);
        }
    }
    eprintln!(
        "extreme values: {cases} cases in {:.1} s: check accepted {accepted}, refused {refused} naming a field; variants --dmax 1 ran {searched}; {} failures; slowest {:.3} s ({})",
        started.elapsed().as_secs_f64(),
        failures.len(),
        slowest.0.as_secs_f64(),
        slowest.1
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The case path of a JSON pointer, as errors write it: `/joints/9/axis/1` → `joints[9].axis[1]`.
fn case_path(pointer: &str) -> String {
    let mut out = String::new();
    for part in pointer.split('/').skip(1) {
        let part = part.replace("~1", "/").replace("~0", "~");
        if part.parse::<usize>().is_ok() {
            out.push_str(&format!("[{part}]"));
        } else {
            if !out.is_empty() {
                out.push('.');
            }
            out.push_str(&part);
        }
    }
    out
}

/// Whether case path `inner` is `outer` or lies inside it (`joints[1].axis[0]` in
/// `joints[1].axis`, not `joints[10]` in `joints[1]`).
fn within(inner: &str, outer: &str) -> bool {
    inner
        .strip_prefix(outer)
        .is_some_and(|rest| rest.is_empty() || rest.starts_with(['.', '[']))
}

fn palletizer() -> Value {
    let path = format!("{}/cases/palletizer.json", env!("CARGO_MANIFEST_DIR"));
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The hang of issue 28: the palletizer (its full grid) with `joints[9].axis[1] = -1e308` ran
/// `check` past 120 s. The axis's norm overflows, so `check` refuses it at load, naming the
/// field, well within a second (a few milliseconds; the limit allows for a loaded machine).
#[test]
fn a_huge_axis_component_is_refused_at_once() {
    let mut case = palletizer();
    case["joints"][9]["axis"][1] = json!(-1e308);
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("case.json");
    std::fs::write(&file, serde_json::to_string_pretty(&case).unwrap()).unwrap();
    let started = Instant::now();
    let ran = run_binary(
        &["check", file.to_str().unwrap()],
        dir.path(),
        started + BUDGET,
    );
    let time = started.elapsed();
    let Ran::Exited(1, stderr) = ran else {
        panic!("not refused")
    };
    assert!(time < Duration::from_secs(1), "{time:?}");
    assert_eq!(error_paths(&stderr), ["joints[9].axis"], "{stderr}");
    assert!(stderr.contains("overflows"), "{stderr}");
}

/// Every number of `cases/palletizer.json` (its grid coarsened as in [`shipped`]) set to 1e308
/// and to 1e-308, one at a time, through `check` and `variants --dmax 1`: each case is answered
/// within [`BUDGET`], without a panic. 1e308 is beyond every field's range: `check` refuses it
/// with an error naming the field (or the vector it is a component of: `joints[9].axis`).
/// 1e-308 is legal in most fields (a mass, a component of a centre of mass); where it is not (an
/// axis whose norm underflows, a duration, a count) the error names the field, and where it is,
/// `check` accepts the case or reports the problems the preflight finds (a parameter of 1e-308
/// collapses a link, so the path's waypoints are out of reach), each naming its field.
#[test]
fn every_palletizer_number_at_1e308_and_1e_minus_308_is_answered() {
    let mut base = palletizer();
    coarsen(&mut base);
    let (mut numbers, mut texts) = (Vec::new(), Vec::new());
    number_pointers(&base, String::new(), &mut numbers, &mut texts);
    assert!(numbers.len() > 200, "{} numbers", numbers.len());
    let dir = tempfile::tempdir().unwrap();
    let mut failures = Vec::new();
    let (mut accepted, mut refused) = (0, 0);
    let mut slowest = (Duration::ZERO, String::new());
    let started = Instant::now();
    for pointer in &numbers {
        for x in [1e308, 1e-308] {
            let mut case = base.clone();
            *case.pointer_mut(pointer).unwrap() = number(x);
            let field = case_path(pointer);
            let what = format!("{field} = {x:e}");
            let answer = answer_case(&case, dir.path());
            if answer.time > slowest.0 {
                slowest = (answer.time, what.clone());
            }
            match answer.check {
                Ok((0, _)) if x > 1.0 => failures.push(format!("{what}: accepted")),
                Ok((0, _)) => accepted += 1,
                Ok((_, paths)) => {
                    refused += 1;
                    if x > 1.0 && !paths.iter().any(|p| within(&field, p) || within(p, &field)) {
                        failures.push(format!("{what}: refused at {paths:?}"));
                    }
                }
                Err(why) => failures.push(format!("check: {why}: {what}")),
            }
            if let Err(why) = answer.variants {
                failures.push(format!("variants --dmax 1: {why}: {what}"));
            }
        }
    }
    eprintln!(
        "palletizer numbers at 1e308 and 1e-308: {} fields × 2 in {:.1} s, {accepted} accepted, {refused} refused; slowest {:.3} s ({})",
        numbers.len(),
        started.elapsed().as_secs_f64(),
        slowest.0.as_secs_f64(),
        slowest.1
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The byte ranges of the numbers in the attribute values of a URDF text (`xyz="0 0 1"` holds
/// three).
fn urdf_numbers(text: &str) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut rest = 0;
    while let Some(open) = text[rest..].find("=\"") {
        let start = rest + open + 2;
        let Some(len) = text[start..].find('"') else {
            break;
        };
        let value = &text[start..start + len];
        let mut offset = 0;
        for token in value.split_whitespace() {
            let at = value[offset..].find(token).unwrap() + offset;
            offset = at + token.len();
            if token.parse::<f64>().is_ok() {
                out.push((start + at, start + offset));
            }
        }
        rest = start + len + 1;
    }
    out
}

/// The URDF files of the test robots (`crates/urdf/tests/data`) and of `cases/`.
fn urdf_files() -> Vec<String> {
    let mut files = Vec::new();
    for dir in ["crates/urdf/tests/data", "cases"] {
        let dir = format!("{}/{dir}", env!("CARGO_MANIFEST_DIR"));
        let mut names: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .filter_map(|e| e.ok()?.file_name().into_string().ok())
            .filter(|n| n.ends_with(".urdf"))
            .map(|n| format!("{dir}/{n}"))
            .collect();
        names.sort();
        files.extend(names);
    }
    files
}

/// An imported case's grid cut to 2 values on its first three actuators and 1 (the middle of the
/// range) on the others, 11 samples per move: a 6-axis arm's default grid (3 values per axis)
/// has hundreds of points, and the preflight's grid evaluation would dominate the test.
fn coarsen_imported(case: &mut Value) {
    if let Some(grid) = case
        .pointer_mut("/tasks/grid")
        .and_then(Value::as_object_mut)
    {
        for (k, axis) in grid.values_mut().enumerate() {
            axis[2] = json!(if k < 3 { 2 } else { 1 });
        }
        case["tasks"]["samples"] = json!(11);
    }
}

/// Numbers of the URDF files of [`urdf_files`] set to ±1e308, 1e-308 and the smallest
/// subnormal, one at a time (CI takes every fourth pair of number and value, so each number
/// gets one of the four values; `FUZZ_URDF_STRIDE=1` runs them all, about 2,100 imports and
/// several minutes): the import refuses it with a message naming the URDF element, or
/// the imported case (its grid coarsened by [`coarsen_imported`]) goes through
/// [`load_and_search`];
/// each within [`BUDGET`], no panic.
#[test]
fn urdf_numbers_at_extreme_values_are_answered() {
    let mut failures = Vec::new();
    let (mut runs, mut imported) = (0, 0);
    // the pairs (number n, value k) with n + k a multiple of `stride`: with 4, each number gets
    // one value, the four rotating over the numbers
    let stride = env_number("FUZZ_URDF_STRIDE", 4).max(1);
    let mut number = 0u64;
    let started = Instant::now();
    for path in urdf_files() {
        let file = path.rsplit('/').next().unwrap().to_string();
        let text = std::fs::read_to_string(&path).unwrap();
        for (start, end) in urdf_numbers(&text) {
            number += 1;
            for (k, x) in [1e308, -1e308, 1e-308, 5e-324].into_iter().enumerate() {
                if !(number + k as u64).is_multiple_of(stride) {
                    continue;
                }
                runs += 1;
                let urdf = format!("{}{x:e}{}", &text[..start], &text[end..]);
                let what = format!(
                    "{file} with `{}` at byte {start} = {x:e}",
                    &text[start..end]
                );
                let (send, receive) = mpsc::channel();
                std::thread::Builder::new()
                    // expressions are parsed recursively: the stack the CLI gives its command
                    .stack_size(preflight::limits().stack_bytes())
                    .spawn(move || {
                        let outcome = catch_unwind(AssertUnwindSafe(|| {
                            match counterpoise_urdf::import(&urdf, &Default::default()) {
                                Ok(case) => {
                                    let mut case: Value = serde_json::from_str(&case.json).unwrap();
                                    coarsen_imported(&mut case);
                                    load_and_search(&case.to_string());
                                    Ok(())
                                }
                                Err(e) => Err(e.to_string()),
                            }
                        }));
                        let _ = send.send(outcome.ok());
                    })
                    .unwrap();
                match receive.recv_timeout(BUDGET) {
                    Err(_) => failures.push(format!("no answer within {BUDGET:?}: {what}")),
                    Ok(None) => failures.push(format!("panic: {what}")),
                    Ok(Some(Ok(()))) => imported += 1,
                    Ok(Some(Err(message))) => {
                        // `joint `j`.origin.xyz: …`
                        if !message.contains(": ") {
                            failures.push(format!("{what}: unclear error `{message}`"));
                        }
                    }
                }
            }
        }
    }
    eprintln!(
        "URDF numbers at extreme values: {runs} imports in {:.1} s, {imported} imported",
        started.elapsed().as_secs_f64()
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
