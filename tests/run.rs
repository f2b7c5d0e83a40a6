//! End-to-end: `counterpoise run` on the palletizer with a reduced task grid, then `report`.

use std::path::PathBuf;
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn run_writes_every_output_and_report_regenerates_them() {
    let dir = std::env::temp_dir().join(format!("counterpoise-run-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // the palletizer on a 3 × 3 × 3 grid (351 tasks) with 11 samples per task
    let text = std::fs::read_to_string(root().join("cases/palletizer.json")).unwrap();
    let mut case: serde_json::Value = serde_json::from_str(&text).unwrap();
    // the same corners as the case's 7 × 7 × 7 grid, fewer points
    let mut grid = case["tasks"]["grid"].clone();
    for axis in grid.as_object_mut().unwrap().values_mut() {
        axis[2] = serde_json::json!(3);
    }
    case["tasks"]["grid"] = grid;
    case["tasks"]["samples"] = serde_json::json!(11);
    let case_path = dir.join("palletizer-small.json");
    std::fs::write(&case_path, serde_json::to_string(&case).unwrap()).unwrap();
    let out = dir.join("out");

    let run = Command::new(env!("CARGO_BIN_EXE_counterpoise"))
        .args([
            "run",
            case_path.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    for file in ["results.json", "report.html", "report.md", "ranking.csv"] {
        assert!(out.join(file).is_file(), "{file} missing");
    }
    let results: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("results.json")).unwrap()).unwrap();
    assert_eq!(results["schema_version"], 1);
    let variants = results["variants"].as_array().unwrap();
    assert_eq!(variants.len(), 406, "paper Eq. A8");
    let feasible: Vec<_> = variants
        .iter()
        .filter(|v| v["status"] == "feasible")
        .collect();
    assert!(!feasible.is_empty());
    for v in &feasible {
        for field in ["dqtr", "dqit", "dr", "rank", "class_rank"] {
            assert!(!v[field].is_null(), "{field} missing in {v}");
        }
        assert!(v["verification_residual"].as_f64().unwrap() <= 1e-9);
        // balanced: motor torque is inertial only, so the balanced QTR is below the unbalanced
        assert!(v["dqtr"].as_f64().unwrap() < 0.0);
    }
    // spring-only variants are dynamically identical: same ΔQTR and ΔQIT
    let springs: Vec<_> = feasible
        .iter()
        .filter(|v| v["class"] == "springs")
        .collect();
    for pair in springs.windows(2) {
        let d = |v: &serde_json::Value, k: &str| v[k].as_f64().unwrap();
        assert!((d(pair[0], "dqtr") - d(pair[1], "dqtr")).abs() < 1e-6);
        assert!((d(pair[0], "dqit") - d(pair[1], "dqit")).abs() < 1e-6);
    }
    let ranks: Vec<u64> = feasible
        .iter()
        .map(|v| v["rank"].as_u64().unwrap())
        .collect();
    let mut sorted = ranks.clone();
    sorted.sort_unstable();
    assert_eq!(sorted, (1..=feasible.len() as u64).collect::<Vec<_>>());
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(html.contains("<svg"));
    assert!(
        results["path"]["dynamic_run"].is_object(),
        "the case's path Λ is simulated"
    );

    std::fs::remove_file(out.join("report.html")).unwrap();
    let report = Command::new(env!("CARGO_BIN_EXE_counterpoise"))
        .args(["report", out.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(
        report.status.success(),
        "{}",
        String::from_utf8_lossy(&report.stderr)
    );
    assert_eq!(
        std::fs::read_to_string(out.join("report.html")).unwrap(),
        html
    );
    std::fs::remove_dir_all(&dir).ok();
}
