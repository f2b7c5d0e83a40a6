//! `counterpoise import-urdf` end to end: import, then `check` and `variants` on the result.

mod common;

use common::{assert_success, counterpoise, root, stderr, stdout};

#[test]
fn imported_two_link_arm_is_the_example_case_and_checks_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let out_path = dir.path().join("arm.json");
    let out = counterpoise(&[
        "import-urdf",
        "crates/urdf/tests/data/two_link.urdf",
        "--out",
        out_path.to_str().unwrap(),
    ]);
    assert_success(&out);
    let written = std::fs::read_to_string(&out_path).unwrap();
    let example = std::fs::read_to_string(root().join("cases/two_link_urdf.json")).unwrap();
    assert_eq!(
        written, example,
        "cases/two_link_urdf.json is the importer's output"
    );
    // Without --out the case goes to standard output.
    let out = counterpoise(&["import-urdf", "crates/urdf/tests/data/two_link.urdf"]);
    assert_success(&out);
    assert_eq!(stdout(&out), example);

    let out = counterpoise(&["check", out_path.to_str().unwrap()]);
    assert_success(&out);
    let text = stdout(&out);
    // g·(m1·c1 + m2·l1) = 9.81·(4·0.4 + 2.5·0.8) = 35.316; g·m2·c2 = 9.81·2.5·0.3 = 7.3575.
    assert!(
        text.contains("V = const + 35.32·sin(shoulder) + 7.36·sin(shoulder)·cos(elbow) + 7.36·cos(shoulder)·sin(elbow) J"),
        "{text}"
    );
    assert!(text.contains("balance decision: exact"), "{text}");
    assert!(text.contains("9 points, 9 reachable"), "{text}");

    let out = counterpoise(&["variants", out_path.to_str().unwrap(), "--json"]);
    assert_success(&out);
    let doc: serde_json::Value = serde_json::from_str(&stdout(&out)).unwrap();
    let variants = doc["variants"].as_array().unwrap();
    let pair = variants
        .iter()
        .find(|v| {
            v["elements"]
                .as_array()
                .unwrap()
                .iter()
                .map(|e| e["label"].as_str().unwrap())
                .collect::<Vec<_>>()
                == ["m1", "m2"]
        })
        .unwrap();
    assert_eq!(pair["status"], "balanced", "{pair}");
}

#[test]
fn malformed_urdf_fails_naming_the_element() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.urdf");
    let text =
        std::fs::read_to_string(root().join("crates/urdf/tests/data/two_link.urdf")).unwrap();
    std::fs::write(
        &bad,
        text.replace("<child link=\"link2\"/>", "<child link=\"link7\"/>"),
    )
    .unwrap();
    let out = counterpoise(&["import-urdf", bad.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(
        err.contains("joint `elbow`.child: child link `link7` does not exist"),
        "{err}"
    );
    assert!(stdout(&out).is_empty());
}
