//! The README's case-study figures are what `run cases/palletizer.json` produces: the best
//! variant of each class (its elements, rank, ΔQTR, ΔQIT and ΔR to the two decimals printed)
//! is read from the README's sample output and compared with a fresh run's `results.json`.
//! The README was written from an earlier measured run, so this pins the case study's result
//! against a record kept outside the code, and keeps the README honest when results change.
//!
//! The same run checks the rest of what the README states and a run can show: its sample
//! standard output line for line (the time and the output paths aside), the progress lines'
//! stages and counts, the counts of the balance-search table and of `run`'s undecided verdict.
//! Without a run: every command of `--help` has a row in the command table, the palletizer is
//! described with the case file's coordinates and actuators, and the run time is one figure
//! (the introduction, the sample output and the Performance table agree).

mod common;

use common::{assert_success, counterpoise, num, results, root, stderr, stdout};

/// One row of the README's "Best variant of each class" table.
#[derive(Debug)]
struct ReadmeRow {
    class: String,
    elements: Vec<String>,
    rank: u64,
    dqtr: f64,
    dqit: f64,
    dr: f64,
}

/// The README's class names, as `results.json` writes them.
fn class_key(readme_class: &str) -> &'static str {
    match readme_class {
        "Counterweights only" => "counterweights",
        "Springs only" => "springs",
        "Hybrid" => "hybrid",
        other => panic!("unknown class {other:?} in the README"),
    }
}

/// Element labels of a variant written `m4 + K43` or `{m4, K43}`, sorted.
fn labels(text: &str) -> Vec<String> {
    let mut v: Vec<String> = text
        .split(['+', ',', '{', '}', ' '])
        .filter(|s| !s.is_empty())
        .map(str::to_string)
        .collect();
    v.sort();
    v
}

/// Parses the README's best-per-class table: after the line starting "Best variant of each
/// class", a header row, then one row per class until a blank line. Columns are separated by
/// two or more spaces.
fn readme_rows() -> Vec<ReadmeRow> {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let mut lines = readme
        .lines()
        .skip_while(|l| !l.starts_with("Best variant of each class"))
        .skip(2);
    let mut rows = Vec::new();
    for line in lines.by_ref() {
        if line.trim().is_empty() {
            break;
        }
        let cols: Vec<&str> = line
            .trim()
            .split("  ")
            .map(str::trim)
            .filter(|c| !c.is_empty())
            .collect();
        assert_eq!(cols.len(), 7, "a README class row has 7 columns: {line:?}");
        let number = |s: &str| -> f64 { s.trim_start_matches('+').parse().unwrap() };
        rows.push(ReadmeRow {
            class: class_key(cols[0]).to_string(),
            elements: labels(cols[2]),
            rank: cols[3].parse().unwrap(),
            dqtr: number(cols[4]),
            dqit: number(cols[5]),
            dr: number(cols[6]),
        });
    }
    rows
}

#[test]
fn best_variant_of_each_class_matches_the_readme() {
    let expected = readme_rows();
    assert_eq!(
        expected.len(),
        3,
        "three classes in the README: {expected:?}"
    );

    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("palletizer");
    let run = counterpoise(&[
        "run",
        "cases/palletizer.json",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_success(&run);
    // The README's recommendation line is the one the run prints.
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let printed = |text: &str| {
        text.lines()
            .find(|l| l.starts_with("Recommended: "))
            .map(str::to_string)
    };
    let stdout = String::from_utf8_lossy(&run.stdout).into_owned();
    assert!(printed(&stdout).is_some(), "{stdout}");
    assert_eq!(printed(&readme), printed(&stdout));
    assert_sample_output(&stdout, &out);
    assert_progress_lines(&stderr(&run));
    let doc = results(&out);
    assert_counts(&doc);
    for row in &expected {
        let best = doc["variants"]
            .as_array()
            .unwrap()
            .iter()
            .find(|v| v["class"] == row.class.as_str() && v["class_rank"] == 1)
            .unwrap_or_else(|| panic!("no best {} variant", row.class));
        let elements: Vec<String> = best["elements"]
            .as_array()
            .unwrap()
            .iter()
            .map(|e| e["label"].as_str().unwrap().to_string())
            .collect();
        let elements = labels(&elements.join(" "));
        assert_eq!(elements, row.elements, "best {} variant", row.class);
        assert_eq!(best["rank"].as_u64().unwrap(), row.rank, "{row:?}");
        // the README prints two decimals: the run must round to the same figure
        for (key, printed) in [("dqtr", row.dqtr), ("dqit", row.dqit), ("dr", row.dr)] {
            let value = num(best, key);
            assert!(
                (value - printed).abs() <= 0.005 + 1e-9,
                "{key} of the best {} variant: run {value:.4}, README {printed}",
                row.class
            );
        }
    }
}

fn readme() -> String {
    std::fs::read_to_string(root().join("README.md")).unwrap()
}

/// The fenced block of the README that starts with a line starting `first`.
fn block(readme: &str, first: &str) -> Vec<String> {
    let start = readme.find(&format!("\n{first}")).expect(first) + 1;
    let end = start + readme[start..].find("```").unwrap();
    readme[start..end].lines().map(str::to_string).collect()
}

/// The README's sample standard output is the run's, line for line, but for the time on the
/// first line and the output directory (`out/palletizer` in the README).
fn assert_sample_output(printed: &str, out: &std::path::Path) {
    let sample = block(&readme(), "palletizer: 406 variants examined");
    let printed: Vec<String> = printed
        .replace(out.to_str().unwrap(), "out/palletizer")
        .lines()
        .map(str::to_string)
        .collect();
    let head = |l: &str| l.split(" in ").next().unwrap().to_string();
    assert_eq!(head(&sample[0]), head(&printed[0]));
    assert_eq!(
        sample[1..],
        printed[1..],
        "README sample output against the run's"
    );
}

/// The README's progress lines are the run's (off a terminal: one per phase and stage), with
/// the same stages and counts; only the times differ.
fn assert_progress_lines(printed: &str) {
    let without_time = |l: &str| l.split(" (").next().unwrap().to_string();
    let sample: Vec<String> = block(&readme(), "[1/4] Phase 1")
        .iter()
        .map(|l| without_time(l))
        .collect();
    let printed: Vec<String> = printed.lines().map(without_time).collect();
    assert_eq!(sample, printed);
}

/// The Dmax 2 row of the balance-search table (balanced = feasible + discarded + undecided,
/// the run's verdicts on them), and `run`'s undecided count as the README states it.
fn assert_counts(doc: &serde_json::Value) {
    let count = |status: &str| -> u64 {
        doc["counts"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["status"] == status)
            .map_or(0, |c| c["total"].as_u64().unwrap())
    };
    let readme = readme();
    let row = readme
        .lines()
        .skip_while(|l| !l.starts_with("| Dmax | balanced | degenerate |"))
        .find(|l| l.starts_with("| 2 |"))
        .unwrap();
    let cells: Vec<u64> = row
        .split('|')
        .map(str::trim)
        .filter(|c| !c.is_empty())
        .map(|c| c.parse().unwrap())
        .collect();
    let balanced = count("feasible") + count("discarded") + count("undecided");
    assert_eq!(
        cells[1..5],
        [
            balanced,
            count("degenerate"),
            count("unrealizable"),
            count("infeasible")
        ],
        "{row}"
    );
    let stated = readme
        .split("`run`'s *undecided* is another verdict")
        .nth(1)
        .and_then(|t| t.split("): ").nth(1))
        .and_then(|t| t.split(" at Dmax 2").next())
        .unwrap();
    assert_eq!(stated.parse::<u64>().unwrap(), count("undecided"));
    assert!(
        readme.contains(&format!(
            "On the palletizer at Dmax 2: {} undecided",
            count("undecided")
        )),
        "the certified stage's Dmax 2 figure"
    );
}

#[test]
fn every_command_is_in_the_command_table() {
    let help = stdout(&counterpoise(&["--help"]));
    let commands: Vec<&str> = help
        .lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|c| *c != "help")
        .collect();
    assert!(commands.len() >= 8, "{help}");
    let readme = readme();
    let table: Vec<&str> = readme
        .lines()
        .skip_while(|l| !l.starts_with("## Command line"))
        .take_while(|l| !l.starts_with("## Case files"))
        .filter(|l| l.starts_with("| `counterpoise "))
        .collect();
    for c in commands {
        assert!(
            table
                .iter()
                .any(|l| l.starts_with(&format!("| `counterpoise {c} "))),
            "{c} has no row in the README's command table"
        );
    }
}

#[test]
fn the_palletizer_is_described_as_the_case_file_models_it() {
    let case: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(root().join("cases/palletizer.json")).unwrap(),
    )
    .unwrap();
    let n = |key: &str| case[key].as_array().unwrap().len();
    let readme = readme();
    let start = readme.find("- `cases/palletizer.json` —").unwrap();
    let entry = &readme[start..start + readme[start..].find("\n\n").unwrap()];
    let entry = entry.split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(
        entry.contains(&format!("{} coordinates", n("coordinates"))),
        "{entry}"
    );
    assert!(
        entry.contains(&format!("{} actuators", n("actuators"))),
        "{entry}"
    );
    // No other DOF count of the modelled robot elsewhere in the README.
    assert!(!readme.contains("the 4-DOF pantograph palletizer"));
}

#[test]
fn the_run_time_is_one_figure() {
    let readme = readme();
    let row = readme
        .lines()
        .find(|l| l.starts_with("| `counterpoise run cases/palletizer.json` (Dmax = 2"))
        .unwrap();
    let after = |text: &str, key: &str| -> f64 {
        let at = text
            .find(key)
            .unwrap_or_else(|| panic!("{key:?} in {text}"))
            + key.len();
        let number: String = text[at..]
            .chars()
            .take_while(|c| c.is_ascii_digit() || *c == '.')
            .collect();
        number.parse().unwrap()
    };
    let wall = after(row, "**wall ");
    // The CPU median: the number before " s CPU [".
    let cpu = {
        let at = row.find(" s CPU [").unwrap();
        let number: String = row[..at]
            .chars()
            .rev()
            .take_while(|c| c.is_ascii_digit() || *c == '.')
            .collect::<Vec<_>>()
            .into_iter()
            .rev()
            .collect();
        number.parse::<f64>().unwrap()
    };
    // The introduction quotes the CPU time, rounded.
    let intro = after(&readme, "in about ");
    assert_eq!(
        intro,
        cpu.round(),
        "introduction {intro} s, Performance {cpu} s CPU"
    );
    // The sample output is the median run: its own clock (from the start of the work to the
    // reports) is within half a second of the process's wall time.
    let sample = after(&readme, "palletizer: 406 variants examined (Dmax = 2) in ");
    assert!(
        (sample - wall).abs() <= 0.5,
        "sample {sample} s, median {wall} s"
    );
}
