//! The README's case-study figures are what `run cases/palletizer.json` produces: the best
//! variant of each class (its elements, rank, ΔQTR, ΔQIT and ΔR to the two decimals printed)
//! is read from the README's sample output and compared with a fresh run's `results.json`.
//! The README was written from an earlier measured run, so this pins the case study's result
//! against a record kept outside the code, and keeps the README honest when results change.

mod common;

use common::{assert_success, counterpoise, num, results, root};

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
    let doc = results(&out);
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
