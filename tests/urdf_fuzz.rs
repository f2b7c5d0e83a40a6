//! Fuzz harness for imported robots (issue 27): mutated URDF files go through the whole command
//! line — `import-urdf` (sometimes with `--tip` or `--base`), then, on a case it writes, `check`
//! (every command's preflight), `variants --dmax 1` and `partial --budget 1` — and every step
//! either succeeds or fails with a message, within a time budget per case: never a panic, an
//! abort or another signal, a hang, or a failure without a message.
//!
//! Each case applies one to three mutations to one of the project's URDF robots
//! (`crates/urdf/tests/data/*.urdf`, `cases/arm6.urdf`): a number replaced by an odd value (NaN,
//! ±inf, ±1e308, 1e-308, 5e-324, 0, a negative, text), an element deleted or duplicated, a joint
//! type changed (including `floating`, `planar` and nonsense), a parent or child pointed at
//! another link or a missing one, parent and child swapped (a cycle), an attribute removed, a
//! `<mimic>` added with an odd multiplier, an axis zeroed, the text truncated or a byte
//! overwritten. CI runs 40 cases (a few seconds);
//! `URDF_FUZZ_CASES=1000 cargo test --release --test urdf_fuzz -- --nocapture` runs more and
//! prints the counts (`URDF_FUZZ_SEED` picks another sequence).

use std::path::Path;
use std::time::{Duration, Instant};

mod common;
use common::process::{Ran, run_binary};

use counterpoise::model::sampling::SplitMix64;

/// Longest one case may take (import and the three commands), generous for a loaded machine.
const BUDGET: Duration = Duration::from_secs(20);

/// Exit 0, or 1/2 with a message on stderr; anything else is a failure, described.
fn answer(ran: Ran) -> Result<i32, String> {
    match ran {
        Ran::Hung(used) => Err(format!(
            "no answer within {BUDGET:?} (processor time used: {used:?})"
        )),
        Ran::Signalled(what) => Err(format!("ended by a signal ({what})")),
        Ran::Exited(_, e) if e.contains("panicked") => Err(format!("panic: {e}")),
        Ran::Exited(code, e) if !(0..=2).contains(&code) => Err(format!("exit {code}: {e}")),
        Ran::Exited(code, e) if code != 0 && e.trim().is_empty() => {
            Err(format!("exit {code} without a message"))
        }
        Ran::Exited(code, _) => Ok(code),
    }
}

/// The project's URDF robots, as (file name, text).
fn robots() -> Vec<(String, String)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut out = Vec::new();
    for dir in ["crates/urdf/tests/data", "cases"] {
        let mut names: Vec<_> = std::fs::read_dir(root.join(dir))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|x| x == "urdf"))
            .collect();
        names.sort();
        for p in names {
            let text = std::fs::read_to_string(&p).unwrap();
            out.push((p.file_name().unwrap().to_string_lossy().into_owned(), text));
        }
    }
    assert!(out.len() >= 5, "the URDF robots are there");
    out
}

fn pick<'a, T>(rng: &mut SplitMix64, items: &'a [T]) -> &'a T {
    &items[(rng.next_u64() % items.len() as u64) as usize]
}

/// Byte ranges of `<tag …>…</tag>` and `<tag …/>` elements named `tag`.
fn elements(text: &str, tag: &str) -> Vec<(usize, usize)> {
    let open = format!("<{tag}");
    let close = format!("</{tag}>");
    let mut out = Vec::new();
    let mut from = 0;
    while let Some(i) = text[from..].find(&open) {
        let start = from + i;
        let after = start + open.len();
        // `<link` must not match `<linkage`: the tag name ends at a space, `>` or `/`.
        if !text[after..].starts_with([' ', '>', '/', '\n', '\t']) {
            from = after;
            continue;
        }
        let Some(gt) = text[start..].find('>') else {
            break;
        };
        let end = if text[start..start + gt].ends_with('/') {
            start + gt + 1
        } else {
            match text[start..].find(&close) {
                Some(c) => start + c + close.len(),
                None => break,
            }
        };
        out.push((start, end));
        from = end;
    }
    out
}

/// Byte ranges of attribute values (between the quotes) of attributes named `name`.
fn attributes(text: &str, name: &str) -> Vec<(usize, usize)> {
    let key = format!(" {name}=\"");
    let mut out = Vec::new();
    let mut from = 0;
    while let Some(i) = text[from..].find(&key) {
        let start = from + i + key.len();
        let Some(len) = text[start..].find('"') else {
            break;
        };
        out.push((start, start + len));
        from = start + len;
    }
    out
}

/// Byte ranges of the numbers inside attribute values.
fn numbers(text: &str) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut from = 0;
    while let Some(i) = text[from..].find("=\"") {
        let start = from + i + 2;
        let Some(len) = text[start..].find('"') else {
            break;
        };
        let value = &text[start..start + len];
        let mut offset = 0;
        for word in value.split(' ') {
            if !word.is_empty() && word.parse::<f64>().is_ok() {
                out.push((start + offset, start + offset + word.len()));
            }
            offset += word.len() + 1;
        }
        from = start + len;
    }
    out
}

/// Link names of the robot, and a name that is none.
fn link_names(text: &str) -> Vec<String> {
    let mut names: Vec<String> = elements(text, "link")
        .into_iter()
        .filter_map(|(s, e)| {
            let (a, b) = attributes(&text[s..e], "name").into_iter().next()?;
            Some(text[s + a..s + b].to_string())
        })
        .collect();
    names.push("no_such_link".into());
    names
}

const ODD_NUMBERS: [&str; 16] = [
    "nan", "NaN", "inf", "-inf", "1e308", "-1e308", "1e-308", "5e-324", "0", "-0", "-1", "1e154",
    "abc", "", "1 2", "0x10",
];

/// One mutation of `text`; returns a description.
fn mutate(text: &mut String, rng: &mut SplitMix64) -> String {
    let replace = |text: &mut String, (s, e): (usize, usize), with: &str| {
        text.replace_range(s..e, with);
    };
    match rng.next_u64() % 12 {
        0 | 1 => {
            let spots = numbers(text);
            if spots.is_empty() {
                return "no number".into();
            }
            let at = *pick(rng, &spots);
            let with = *pick(rng, &ODD_NUMBERS);
            let was = text[at.0..at.1].to_string();
            replace(text, at, with);
            format!("number {was} at byte {} → {with:?}", at.0)
        }
        2 => {
            let tag = *pick(
                rng,
                &[
                    "joint", "link", "inertial", "origin", "axis", "limit", "mass",
                ],
            );
            let spots = elements(text, tag);
            if spots.is_empty() {
                return format!("no <{tag}>");
            }
            let at = *pick(rng, &spots);
            replace(text, at, "");
            format!("<{tag}> at byte {} deleted", at.0)
        }
        3 => {
            let tag = *pick(rng, &["joint", "link", "inertial", "axis", "limit"]);
            let spots = elements(text, tag);
            if spots.is_empty() {
                return format!("no <{tag}>");
            }
            let (s, e) = *pick(rng, &spots);
            let copy = text[s..e].to_string();
            text.insert_str(e, &copy);
            format!("<{tag}> at byte {s} duplicated")
        }
        4 => {
            let spots = attributes(text, "type");
            if spots.is_empty() {
                return "no type".into();
            }
            let at = *pick(rng, &spots);
            let with = *pick(
                rng,
                &[
                    "revolute",
                    "continuous",
                    "prismatic",
                    "fixed",
                    "floating",
                    "planar",
                    "spherical",
                    "",
                ],
            );
            replace(text, at, with);
            format!("a joint type → {with:?}")
        }
        5 => {
            let which = *pick(rng, &["parent", "child"]);
            let key = format!("<{which} link=\"");
            let spots: Vec<(usize, usize)> = text
                .match_indices(&key)
                .filter_map(|(i, _)| {
                    let s = i + key.len();
                    text[s..].find('"').map(|l| (s, s + l))
                })
                .collect();
            if spots.is_empty() {
                return format!("no {which}");
            }
            let at = *pick(rng, &spots);
            let names = link_names(text);
            let with = pick(rng, &names).clone();
            replace(text, at, &with);
            format!("a {which} → {with}")
        }
        6 => {
            // Parent and child of one joint swapped: a cycle or two roots.
            let joints = elements(text, "joint");
            if joints.is_empty() {
                return "no joint".into();
            }
            let (s, e) = *pick(rng, &joints);
            let block = text[s..e]
                .replace("<parent link=", "<PARENT link=")
                .replace("<child link=", "<parent link=")
                .replace("<PARENT link=", "<child link=");
            text.replace_range(s..e, &block);
            format!("parent and child of the joint at byte {s} swapped")
        }
        7 => {
            let name = *pick(
                rng,
                &[
                    "xyz", "rpy", "lower", "upper", "effort", "value", "ixx", "name", "link",
                ],
            );
            let key = format!(" {name}=\"");
            let spots: Vec<(usize, usize)> = attributes(text, name)
                .into_iter()
                .map(|(s, e)| (s - key.len(), e + 1))
                .collect();
            if spots.is_empty() {
                return format!("no {name}");
            }
            let at = *pick(rng, &spots);
            replace(text, at, "");
            format!("attribute {name} removed at byte {}", at.0)
        }
        8 => {
            let joints = elements(text, "joint");
            let names = link_names(text);
            if joints.is_empty() {
                return "no joint".into();
            }
            let (s, e) = *pick(rng, &joints);
            let Some(close) = text[s..e].rfind("</joint>") else {
                return "a self-closed joint".into();
            };
            let target = pick(rng, &names).replace("link", "joint");
            let multiplier = *pick(rng, &["2", "0.5", "-1", "nan", "1e308", "0"]);
            let mimic =
                format!("<mimic joint=\"{target}\" multiplier=\"{multiplier}\" offset=\"0.1\"/>");
            text.insert_str(s + close, &mimic);
            format!("mimic of {target} ×{multiplier} added at byte {s}")
        }
        9 => {
            let spots = attributes(text, "xyz");
            if spots.is_empty() {
                return "no xyz".into();
            }
            let at = *pick(rng, &spots);
            replace(text, at, "0 0 0");
            format!("xyz at byte {} → 0 0 0", at.0)
        }
        10 => {
            let at = (rng.next_u64() % text.len().max(1) as u64) as usize;
            let at = (0..=at)
                .rev()
                .find(|&i| text.is_char_boundary(i))
                .unwrap_or(0);
            text.truncate(at);
            format!("truncated at byte {at}")
        }
        _ => {
            let at = (rng.next_u64() % text.len().max(1) as u64) as usize;
            if !text.is_char_boundary(at) || !text.is_char_boundary((at + 1).min(text.len())) {
                return "no byte".into();
            }
            let with = *pick(rng, &["<", ">", "\"", "&", "\u{0}", "é", "/"]);
            let end = (at + 1).min(text.len());
            text.replace_range(at..end, with);
            format!("byte {at} → {with:?}")
        }
    }
}

/// What happened to the cases, for the summary line.
#[derive(Default)]
struct Counts {
    imported: usize,
    refused: usize,
    checked: usize,
    balanced_searches: usize,
    partial: usize,
    failures: Vec<String>,
    slowest: (Duration, String),
}

fn env_number(name: &str, default: u64) -> u64 {
    std::env::var(name)
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

/// Runs one mutated robot through the command line, recording what happened.
fn one_case(urdf: &str, tip: Option<&str>, dir: &Path, what: &str, counts: &mut Counts) {
    let file = dir.join("robot.urdf");
    std::fs::write(&file, urdf).unwrap();
    let case = dir.join("case.json");
    let _ = std::fs::remove_file(&case);
    let started = Instant::now();
    let deadline = started + BUDGET;
    let (file, case_s) = (file.to_str().unwrap(), case.to_str().unwrap());
    let mut import = vec!["import-urdf", file, "--out", case_s];
    if let Some(tip) = tip {
        import.extend(["--tip", tip]);
    }
    let fail = |counts: &mut Counts, step: &str, why: String| {
        counts.failures.push(format!("{what}: {step}: {why}"));
    };
    match answer(run_binary(&import, dir, deadline)) {
        Err(why) => fail(counts, "import-urdf", why),
        Ok(0) => {
            counts.imported += 1;
            let steps: [(&str, Vec<&str>); 3] = [
                ("check", vec!["check", case_s]),
                ("variants", vec!["variants", case_s, "--dmax", "1"]),
                (
                    "partial",
                    vec!["partial", case_s, "--budget", "1", "--points", "3"],
                ),
            ];
            for (step, args) in steps {
                match answer(run_binary(&args, dir, deadline)) {
                    Err(why) => fail(counts, step, why),
                    Ok(code) => {
                        if code == 0 {
                            match step {
                                "check" => counts.checked += 1,
                                "variants" => counts.balanced_searches += 1,
                                _ => counts.partial += 1,
                            }
                        }
                    }
                }
            }
        }
        Ok(_) => counts.refused += 1,
    }
    let took = started.elapsed();
    if took > counts.slowest.0 {
        counts.slowest = (took, what.to_string());
    }
}

/// Mutated URDF robots through import, `check`, `variants --dmax 1` and `partial --budget 1`:
/// no panic, signal, hang or silent failure. An unmutated robot must import (the harness's own
/// check that it reaches past the parser).
#[test]
fn mutated_urdf_robots_are_imported_or_refused_cleanly() {
    let cases = env_number("URDF_FUZZ_CASES", 40) as usize;
    let seed = env_number("URDF_FUZZ_SEED", 27);
    let robots = robots();
    let dir = tempfile::tempdir().unwrap();
    let mut rng = SplitMix64::new(seed);
    let mut counts = Counts::default();
    let started = Instant::now();
    // Every robot once unmutated: imported and answered.
    for (name, text) in &robots {
        one_case(
            text,
            None,
            dir.path(),
            &format!("{name} (unmutated)"),
            &mut counts,
        );
    }
    assert_eq!(counts.imported, robots.len(), "{:?}", counts.failures);
    for k in 0..cases {
        let (name, text) = pick(&mut rng, &robots);
        let mut urdf = text.clone();
        let mutations = 1 + rng.next_u64() % 3;
        let done: Vec<String> = (0..mutations)
            .map(|_| mutate(&mut urdf, &mut rng))
            .collect();
        // Now and then the import keeps the chain to one link (`--tip`).
        let tip = if rng.next_u64().is_multiple_of(5) {
            let names = link_names(&urdf);
            Some(pick(&mut rng, &names).clone())
        } else {
            None
        };
        let what = format!(
            "case {k}: {name}: {}{}",
            done.join("; "),
            tip.as_ref()
                .map_or(String::new(), |t| format!("; --tip {t}"))
        );
        one_case(&urdf, tip.as_deref(), dir.path(), &what, &mut counts);
    }
    println!(
        "URDF fuzz: {cases} mutated cases (seed {seed}) in {:.1} s: {} imported, {} refused with \
         a message; of the imported, {} checked, {} searched at Dmax 1, {} partial; slowest {:.2} \
         s ({}); {} failures",
        started.elapsed().as_secs_f64(),
        counts.imported.saturating_sub(robots.len()),
        counts.refused,
        counts.checked.saturating_sub(robots.len()),
        counts.balanced_searches.saturating_sub(robots.len()),
        counts.partial.saturating_sub(robots.len()),
        counts.slowest.0.as_secs_f64(),
        counts.slowest.1,
        counts.failures.len()
    );
    assert!(
        counts.failures.is_empty(),
        "{} failures:\n{}",
        counts.failures.len(),
        counts.failures.join("\n")
    );
}
