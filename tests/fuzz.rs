//! Fuzz harness (issue 13): mutations of the shipped cases must load or be refused with errors,
//! and a loadable one must go through everything `check` runs (validation, then the preflight:
//! variant count, catalogue, paths, the task grid as `evaluate` sees it) and the balance search
//! at Dmax 1 — never a panic, within a time and memory budget.
//!
//! Each case applies up to two mutations, either to the JSON tree (a value replaced by an odd one,
//! a number rescaled, a member removed, an array element duplicated, a key renamed) or to the text (truncated, a
//! byte overwritten). CI runs 300 cases (a few seconds; `FUZZ_STATS=1` prints which loaded); `PROPTEST_CASES=10000 cargo test
//! --release --test fuzz` runs more.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::time::{Duration, Instant};

use counterpoise::balance::{
    Catalogue, SearchOptions, catalogue_options, mechanism_energy, realization_hints, search,
};
use counterpoise::model::Case;
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
