//! The study's typed API on the two-link arm: the phases it reports, cancellation, the guards
//! of `Study::new`, and a sharded study merged back into the single run's results.

use std::path::PathBuf;
use std::sync::Mutex;
use std::sync::atomic::AtomicBool;

use counterpoise_balance::{
    Catalogue, SearchOptions, Status, catalogue_options, mechanism_energy, realization_hints,
    search,
};
use counterpoise_model::Model;
use counterpoise_study::shard::ShardSpec;
use counterpoise_study::{
    Count, Phase, Progress, Silent, Study, StudyError, StudyOptions, load_case, merge,
};

fn two_link_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../cases/two_link.json")
}

fn two_link() -> Model {
    load_case(&two_link_path()).expect("the two-link case is valid")
}

/// Balanced variants of the exact search run directly (not through the study).
fn balanced_count(model: &Model, dmax: usize) -> usize {
    let energy = mechanism_energy(model);
    let catalogue = Catalogue::build(&energy, &catalogue_options(model));
    let options = SearchOptions {
        dmax,
        hints: realization_hints(model),
    };
    search(&energy, catalogue, options)
        .variants
        .iter()
        .filter(|v| v.status == Status::Balanced)
        .count()
}

/// Records the phases it is told of, in order, and whether each was ended.
#[derive(Default)]
struct Recorder {
    phases: Vec<(String, bool)>,
    ended: std::sync::Arc<Mutex<usize>>,
}

struct RecordedPhase {
    ended: std::sync::Arc<Mutex<usize>>,
}

impl Progress for Recorder {
    fn phase(&mut self, name: &str, extra: bool) -> Box<dyn Phase> {
        self.phases.push((name.to_string(), extra));
        Box::new(RecordedPhase {
            ended: self.ended.clone(),
        })
    }
}

impl Phase for RecordedPhase {
    fn report(&self, _stage: &str, _count: Count) {}
    fn finish(self: Box<Self>) {
        *self.ended.lock().unwrap() += 1;
    }
}

#[test]
fn a_run_reports_its_four_phases_in_order_and_ends_each() {
    let model = two_link();
    let study = Study::new(&model, StudyOptions::default()).unwrap();
    let mut recorder = Recorder::default();
    let outcome = study.run(&mut recorder, &AtomicBool::new(false)).unwrap();
    let balanced = balanced_count(&model, 2);
    assert!(balanced > 0);
    let names: Vec<&str> = recorder.phases.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(
        names,
        [
            "Phase 1: unbalanced robot over all tasks",
            "Phase 2: balance search",
            &format!("Phase 2: optimisation of the {balanced} balanced variants"),
            "Phase 3: ranking, torque curves, path",
        ]
    );
    assert!(recorder.phases.iter().all(|(_, extra)| !extra));
    assert_eq!(*recorder.ended.lock().unwrap(), 4);
    // The results account for every variant the search examined, and time every phase.
    let examined: usize = outcome.results.counts.iter().map(|c| c.total).sum();
    assert_eq!(examined, outcome.results.variants.len());
    assert_eq!(outcome.results.metadata.timings.len(), 4);
}

#[test]
fn a_cancelled_study_stops_before_its_first_phase() {
    let model = two_link();
    let study = Study::new(&model, StudyOptions::default()).unwrap();
    let mut recorder = Recorder::default();
    let result = study.run(&mut recorder, &AtomicBool::new(true));
    assert!(matches!(result, Err(StudyError::Cancelled)));
    assert!(recorder.phases.is_empty());
}

#[test]
fn the_guards_refuse_before_any_work_and_name_the_reason() {
    let model = two_link();
    let zero = StudyOptions {
        dmax: Some(0),
        ..StudyOptions::default()
    };
    match Study::new(&model, zero) {
        Err(StudyError::Invalid(m)) => assert_eq!(m, "--dmax must be at least 1"),
        other => panic!("{:?}", other.err()),
    }
    // Far beyond the variants limit: refused with the option named, located as a case error.
    let huge = StudyOptions {
        dmax: Some(60),
        case_path: Some(two_link_path()),
        ..StudyOptions::default()
    };
    match Study::new(&model, huge) {
        Err(e @ StudyError::Case { .. }) => assert!(e.to_string().contains("--dmax"), "{e}"),
        other => panic!("{:?}", other.err()),
    }
    let mut without_tasks = model.clone();
    without_tasks.tasks = None;
    match Study::new(&without_tasks, StudyOptions::default()) {
        Err(StudyError::Invalid(m)) => assert!(m.ends_with("the case has no `tasks` section")),
        other => panic!("{:?}", other.err()),
    }
}

#[test]
fn two_shards_merge_into_the_single_runs_results() {
    let model = two_link();
    let options = StudyOptions {
        case_path: Some(two_link_path()),
        ..StudyOptions::default()
    };
    let cancel = AtomicBool::new(false);
    let single = Study::new(&model, options.clone())
        .unwrap()
        .run(&mut Silent, &cancel)
        .unwrap();
    let text = std::fs::read_to_string(two_link_path()).unwrap();
    let shards: Vec<(PathBuf, _)> = (1..=2)
        .map(|index| {
            let spec = ShardSpec { index, count: 2 };
            let study = Study::new(&model, options.clone()).unwrap();
            let file = study
                .run_shard(spec, text.clone(), &mut Silent, &cancel)
                .unwrap();
            (PathBuf::from(format!("shard-{index}")), file)
        })
        .collect();
    assert_eq!(
        shards.iter().map(|(_, s)| s.variants.len()).sum::<usize>(),
        balanced_count(&model, 2)
    );
    let merged = merge::merge(&shards, options.jobs, &mut Silent, &cancel).unwrap();
    let json = |r: &counterpoise_report::RunResults| {
        let mut v = serde_json::to_value(r).unwrap();
        let m = v["metadata"].as_object_mut().unwrap();
        for key in ["timings", "shard_timings", "date", "shards"] {
            m.remove(key);
        }
        v
    };
    assert_eq!(json(&merged.results), json(&single.results));
    assert_eq!(merged.results.metadata.shards, Some(2));
}
