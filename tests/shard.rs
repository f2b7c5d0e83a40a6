//! Sharded studies: `run --shard I/N` on each shard, then `merge`, gives the results.json of a
//! single `run` (timings, date, jobs and the shard count aside); merge refuses incomplete or
//! mixed sets of shards, naming the file and the reason.

mod common;

use std::path::{Path, PathBuf};

use common::{assert_success, counterpoise, reduced_palletizer, results, stderr, write_case};

/// results.json without the metadata that says how the run was made rather than what it found
/// (the fields `merge` is allowed to change).
fn comparable(mut doc: serde_json::Value) -> serde_json::Value {
    let metadata = doc["metadata"].as_object_mut().expect("metadata");
    for key in ["timings", "shard_timings", "date", "jobs", "shards"] {
        metadata.remove(key);
    }
    doc
}

fn run_single(case: &str, out: &Path, extra: &[&str]) -> serde_json::Value {
    let mut args = vec!["run", case, "--out", out.to_str().unwrap(), "--quiet"];
    args.extend(extra);
    assert_success(&counterpoise(&args));
    results(out)
}

fn run_shard(case: &str, spec: &str, dir: &Path, extra: &[&str]) {
    let mut args = vec![
        "run",
        case,
        "--shard",
        spec,
        "--out",
        dir.to_str().unwrap(),
        "--quiet",
    ];
    args.extend(extra);
    assert_success(&counterpoise(&args));
}

fn merge(inputs: &[&Path], out: &Path) -> std::process::Output {
    let mut args = vec!["merge".to_string()];
    args.extend(inputs.iter().map(|p| p.to_str().unwrap().to_string()));
    args.extend([
        "--out".into(),
        out.to_str().unwrap().into(),
        "--quiet".into(),
    ]);
    counterpoise(&args.iter().map(String::as_str).collect::<Vec<_>>())
}

/// Runs the study in `n` shards, merges them and compares with the single run `single`.
fn assert_merge_equals_single(case: &str, n: usize, single: &serde_json::Value, extra: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let shards = dir.path().join("shards");
    for i in 1..=n {
        run_shard(case, &format!("{i}/{n}"), &shards, extra);
    }
    let out = dir.path().join("merged");
    let o = merge(&[&shards], &out);
    assert_success(&o);
    let merged = results(&out);
    assert_eq!(merged["metadata"]["shards"], serde_json::json!(n));
    // each shard's three phases (Phase 1, search, its optimisation)
    assert_eq!(
        merged["metadata"]["shard_timings"].as_array().map(Vec::len),
        Some(3 * n)
    );
    assert!(
        comparable(merged.clone()) == comparable(single.clone()),
        "{n} shards: the merged results.json differs from the single run's"
    );
    for report in ["report.html", "report.md", "ranking.csv"] {
        assert!(out.join(report).is_file(), "{report} not written");
    }
}

#[test]
fn merged_two_link_study_equals_the_single_run_for_one_two_and_three_shards() {
    // the second method: the single-machine `run` of the same case and options
    let dir = tempfile::tempdir().unwrap();
    let case = "cases/two_link.json";
    let single = run_single(case, &dir.path().join("single"), &[]);
    // two_link: 4 balanced variants (README's variants table for the case): N = 3 puts one or
    // two in each shard
    let feasible = single["variants"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|v| v["status"] == "feasible")
        .count();
    assert!(feasible >= 2, "the comparison needs ranked variants");
    assert!(single["metadata"].get("shards").is_none());
    assert!(single["metadata"].get("shard_timings").is_none());
    for n in 1..=3 {
        assert_merge_equals_single(case, n, &single, &[]);
    }
    // the options travel with the shards: minimax and another tolerance
    let options = ["--minimax", "--tolerance", "2"];
    let single = run_single(case, &dir.path().join("minimax"), &options);
    assert_merge_equals_single(case, 2, &single, &options);
}

/// Exact merging of the palletizer needs every variant's optimisation to be independent of the
/// other variants in its batch (tests/batch_independence.rs): counterweights, springs sharing
/// the robot's inertia, springs to the base and the rotation about gravity are all there.
#[test]
fn merged_palletizer_study_equals_the_single_run_for_one_two_and_three_shards() {
    let dir = tempfile::tempdir().unwrap();
    let case = write_case(dir.path(), "palletizer.json", &reduced_palletizer(3, 11));
    let single = run_single(&case, &dir.path().join("single"), &[]);
    for n in 1..=3 {
        assert_merge_equals_single(&case, n, &single, &[]);
    }
}

#[test]
fn more_shards_than_balanced_variants_leave_empty_shards_that_still_merge() {
    // two_link has 4 balanced variants (README's variants table): in 6 shards, two are empty
    // and must still be written and merged; the second method is the single run
    let dir = tempfile::tempdir().unwrap();
    let case = "cases/two_link.json";
    let single = run_single(case, &dir.path().join("single"), &[]);
    assert_merge_equals_single(case, 6, &single, &[]);
    let shards = dir.path().join("shards");
    run_shard(case, "6/6", &shards, &[]);
    let file: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(shards.join("shard-6-of-6.json")).unwrap())
            .unwrap();
    assert_eq!(file["variants"], serde_json::json!([]));
    assert_eq!(file["balanced"], serde_json::json!(4));
}

#[test]
fn malformed_shard_specs_are_usage_errors_naming_the_spec() {
    for (spec, reason) in [
        ("3/2", "numbered 1 to 2"),
        ("0/2", "numbered 1 to 2"),
        ("a/b", "`a` is not a whole number"),
        ("2", "expected I/N"),
        ("1/0", "at least 1"),
    ] {
        let o = counterpoise(&["run", "cases/two_link.json", "--shard", spec]);
        assert_eq!(o.status.code(), Some(2), "--shard {spec}: {}", stderr(&o));
        let err = stderr(&o);
        assert!(
            err.contains("--shard") && err.contains(reason),
            "{spec}: {err}"
        );
        assert!(!err.contains("panicked"), "{err}");
    }
    // merge needs at least one input and an output directory
    for args in [&["merge", "--out", "x"][..], &["merge", "shards"]] {
        let o = counterpoise(args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
    }
}

/// The shard files of a 3-shard two_link study in `dir/shards`.
fn three_shards(dir: &Path) -> PathBuf {
    let shards = dir.join("shards");
    for i in 1..=3 {
        run_shard("cases/two_link.json", &format!("{i}/3"), &shards, &[]);
    }
    shards
}

#[test]
fn a_shard_that_died_is_missing_until_it_is_rerun() {
    let dir = tempfile::tempdir().unwrap();
    let shards = three_shards(dir.path());
    // shard 2 "dies midway": its file never appears, only the temporary file the atomic write
    // leaves behind (a dot file, truncated JSON)
    let two = shards.join("shard-2-of-3.json");
    std::fs::remove_file(&two).unwrap();
    std::fs::write(
        shards.join(".shard-2-of-3.json.tmp-4242"),
        "{\"format\": \"counterp",
    )
    .unwrap();
    let out = dir.path().join("merged");
    let o = merge(&[&shards], &out);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains("missing: 2/3") && err.contains("shard-2-of-3.json"),
        "{err}"
    );
    assert!(!out.join("results.json").exists());
    // rerunning that shard alone completes the study
    run_shard("cases/two_link.json", "2/3", &shards, &[]);
    assert_success(&merge(&[&shards], &out));
    let single = run_single("cases/two_link.json", &dir.path().join("single"), &[]);
    assert!(comparable(results(&out)) == comparable(single));
}

#[test]
fn merge_refuses_duplicated_foreign_and_alien_files_naming_them() {
    let dir = tempfile::tempdir().unwrap();
    let shards = three_shards(dir.path());
    let out = dir.path().join("merged");

    // duplicated: shard 1 in a second directory too
    let copy = dir.path().join("copy");
    std::fs::create_dir_all(&copy).unwrap();
    std::fs::copy(
        shards.join("shard-1-of-3.json"),
        copy.join("shard-1-of-3.json"),
    )
    .unwrap();
    let o = merge(&[&shards, &copy], &out);
    assert_eq!(o.status.code(), Some(1));
    let err = stderr(&o);
    assert!(err.contains("shard 1/3 appears twice"), "{err}");
    assert!(
        err.contains(copy.join("shard-1-of-3.json").to_str().unwrap()),
        "{err}"
    );

    // foreign: shard 3 of a study of another case (one mass changed)
    let mut case = common::case_json("two_link.json");
    case["bodies"][1]["mass"] = serde_json::json!(3.0); // 2.5 kg in the case
    let other_case = write_case(dir.path(), "other.json", &case);
    let other = dir.path().join("other");
    run_shard(&other_case, "3/3", &other, &[]);
    std::fs::remove_file(shards.join("shard-3-of-3.json")).unwrap();
    let o = merge(&[&shards, &other], &out);
    assert_eq!(o.status.code(), Some(1));
    let err = stderr(&o);
    let foreign = other.join("shard-3-of-3.json");
    assert!(
        err.contains(foreign.to_str().unwrap())
            && err.contains("another study")
            && err.contains("case hash"),
        "{err}"
    );

    // foreign: the same case at another Dmax
    let dmax1 = dir.path().join("dmax1");
    run_shard("cases/two_link.json", "3/3", &dmax1, &["--dmax", "1"]);
    let o = merge(&[&shards, &dmax1], &out);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("Dmax 2 ≠ 1"), "{}", stderr(&o));

    // foreign: another split of the same study
    let halves = dir.path().join("halves");
    run_shard("cases/two_link.json", "2/2", &halves, &[]);
    let o = merge(&[&shards, &halves], &out);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("number of shards N 3 ≠ 2"),
        "{}",
        stderr(&o)
    );

    // a shard numbered outside 1…N (a hand-edited file)
    let outside = dir.path().join("outside");
    std::fs::create_dir_all(&outside).unwrap();
    let mut doc: serde_json::Value =
        serde_json::from_slice(&std::fs::read(shards.join("shard-2-of-3.json")).unwrap()).unwrap();
    doc["shard"] = serde_json::json!(4);
    std::fs::write(outside.join("shard-4-of-3.json"), doc.to_string()).unwrap();
    let o = merge(&[&shards, &outside], &out);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("shard index 4 is outside 1…3"),
        "{}",
        stderr(&o)
    );

    // not a shard file at all
    let alien = dir.path().join("alien");
    std::fs::create_dir_all(&alien).unwrap();
    std::fs::write(alien.join("shard-3-of-3.json"), "{\"schema_version\": 2}").unwrap();
    let o = merge(&[&shards, &alien], &out);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("not a shard file"), "{}", stderr(&o));

    // nothing to merge
    let empty = dir.path().join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let o = merge(&[&empty], &out);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("no shard files"), "{}", stderr(&o));
    assert!(!stderr(&o).contains("panicked"));
    assert!(!out.join("results.json").exists());
}

#[test]
fn the_partition_of_the_palletizer_covers_every_balanced_variant_once_with_balanced_costs() {
    use counterpoise::shard::{
        CostFeatures, ShardSpec, expected_cost, shard_units, shard_variants,
    };
    use counterpoise_balance::{
        Catalogue, SearchOptions, Status, catalogue_options, mechanism_energy, realization_hints,
        search,
    };
    let model =
        counterpoise_model::Case::from_path(&common::root().join("cases/palletizer.json")).unwrap();
    let energy = mechanism_energy(&model);
    let catalogue = Catalogue::build(&energy, &catalogue_options(&model));
    let found = search(
        &energy,
        catalogue,
        SearchOptions {
            dmax: 2,
            hints: realization_hints(&model),
        },
    );
    let balanced: Vec<usize> = (0..found.variants.len())
        .filter(|&k| found.variants[k].status == Status::Balanced)
        .collect();
    // README: 97 balanced variants at Dmax 2
    assert_eq!(balanced.len(), 97);
    let cost = |ids: &[usize]| -> u64 {
        ids.iter()
            .map(|&k| expected_cost(CostFeatures::of(&found.variants[k])))
            .sum()
    };
    // The units kept whole: a counterweight set with springs is one (the optimiser's siblings),
    // every other variant its own. Counted here from the labels: per counterweight label set
    // (`m…`) of a variant with a spring (`K…`), its variants.
    let units = shard_units(&found.variants);
    let mut by_labels: std::collections::BTreeMap<Vec<String>, Vec<usize>> = Default::default();
    let mut alone = Vec::new();
    for &k in &balanced {
        let labels: Vec<String> = found.variants[k]
            .elements
            .iter()
            .map(|e| e.label.clone())
            .collect();
        let masses: Vec<String> = labels
            .iter()
            .filter(|l| l.starts_with('m'))
            .cloned()
            .collect();
        if masses.is_empty() || masses.len() == labels.len() {
            alone.push(vec![k]);
        } else {
            by_labels.entry(masses).or_default().push(k);
        }
    }
    let mut expected: Vec<Vec<usize>> = by_labels.into_values().chain(alone).collect();
    expected.sort();
    let mut got = units.clone();
    got.sort();
    assert_eq!(got, expected);
    assert!(units.iter().any(|u| u.len() > 1));
    let largest = units.iter().map(|u| cost(u)).max().unwrap();
    for n in 1..=5 {
        let parts: Vec<Vec<usize>> = (1..=n)
            .map(|index| shard_variants(&found.variants, ShardSpec { index, count: n }))
            .collect();
        let mut all: Vec<usize> = parts.iter().flatten().copied().collect();
        all.sort_unstable();
        assert_eq!(
            all, balanced,
            "{n} shards: not every balanced variant exactly once"
        );
        for unit in &units {
            let holders = parts.iter().filter(|p| p.contains(&unit[0])).count();
            assert_eq!(holders, 1);
            let holder = parts.iter().find(|p| p.contains(&unit[0])).unwrap();
            assert!(
                unit.iter().all(|k| holder.contains(k)),
                "{n} shards split {unit:?}"
            );
        }
        let costs: Vec<u64> = parts.iter().map(|p| cost(p)).collect();
        let (lo, hi) = (costs.iter().min().unwrap(), costs.iter().max().unwrap());
        assert!(hi - lo <= largest, "{n} shards: costs {costs:?}");
        // the same partition when computed again
        let again: Vec<Vec<usize>> = (1..=n)
            .map(|index| shard_variants(&found.variants, ShardSpec { index, count: n }))
            .collect();
        assert_eq!(again, parts);
    }
}
