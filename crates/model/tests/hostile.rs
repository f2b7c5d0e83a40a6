//! Hostile case files (issue 13): each is refused with an error naming the field, or accepted,
//! never a panic; limits can be lifted explicitly.

use counterpoise_model::{Case, CaseErrors, Limits, ModelError};
use serde_json::{Value, json};

fn two_link() -> Value {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../cases/two_link.json");
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn errors_of(v: &Value) -> CaseErrors {
    Case::from_json_str(&serde_json::to_string_pretty(v).unwrap()).expect_err("must be refused")
}

/// The first error at `path`, as printed (with its position).
fn line_at(errors: &CaseErrors, path: &str) -> String {
    let lines = errors.lines();
    errors
        .iter()
        .zip(&lines)
        .find(|(e, _)| e.path() == path)
        .map(|(_, l)| l.clone())
        .unwrap_or_else(|| panic!("no error at {path}:\n{}", lines.join("\n")))
}

#[test]
fn unknown_fields_do_not_hide_other_errors() {
    let mut v = two_link();
    v["bodies"][0]["masss"] = json!(1);
    v["joints"][1]["axiss"] = json!([0, 0, 1]);
    v["tasks"]["extra"] = json!(true);
    v["bodies"][1]["mass"] = json!(-3);
    v["actuators"][0]["joint"] = json!("nope");
    v["colour"] = json!("red");
    let errors = errors_of(&v);
    let paths: Vec<&str> = errors.iter().map(ModelError::path).collect();
    // sorted by path, indices numerically
    assert_eq!(
        paths,
        vec![
            "actuators[0].joint",
            "bodies[0].masss",
            "bodies[1].mass",
            "colour",
            "joints[1].axiss",
            "tasks.extra"
        ]
    );
    assert!(line_at(&errors, "bodies[0].masss").contains("unknown field `masss`"));
    // every error carries a line and column
    for line in errors.lines() {
        assert!(line.contains("(line "), "{line}");
    }
}

#[test]
fn several_shape_errors_are_reported_together() {
    let mut v = two_link();
    v["bodies"][0]["mass"] = json!("heavy");
    v["bodies"][1]["com"] = json!([0, 0]);
    v["joints"][0]["kind"] = json!("hinge");
    let errors = errors_of(&v);
    let paths: Vec<&str> = errors.iter().map(ModelError::path).collect();
    assert_eq!(
        paths,
        vec!["bodies[0].mass", "bodies[1].com", "joints[0].kind"]
    );
}

#[test]
fn line_and_column_point_at_the_field() {
    let text = "{\n  \"name\": \"x\",\n  \"gravity\": [0, 0, 0],\n  \"coordinates\": [],\n  \"bodies\": [],\n  \"actuators\": [],\n  \"bogus\": 1\n}";
    let errors = Case::from_json_str(text).unwrap_err();
    let line = line_at(&errors, "bogus");
    assert!(line.ends_with("(line 7, column 3)"), "{line}");
}

#[test]
fn a_top_level_array_truncated_json_and_bad_utf8_get_sensible_messages() {
    let case = serde_json::to_string_pretty(&two_link()).unwrap();
    let array = format!("[{case}]");
    let e = Case::from_json_str(&array).unwrap_err();
    assert!(
        e.to_string().contains("a case file is one JSON object"),
        "{e}"
    );
    assert!(e.to_string().contains("found an array"), "{e}");

    let truncated = &case[..case.find("\"link2\"").unwrap() + 3];
    let e = Case::from_json_str(truncated).unwrap_err();
    let text = e.to_string();
    assert!(text.contains("truncated"), "{text}");
    assert!(text.contains("bodies[1].name"), "{text}");

    let dir = std::env::temp_dir().join(format!("counterpoise-utf8-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("bad.json");
    let mut bytes = case.as_bytes().to_vec();
    let at = case.find("\"link1\"").unwrap() + 2;
    bytes[at] = 0xff;
    std::fs::write(&file, &bytes).unwrap();
    let e = Case::from_path(&file).unwrap_err();
    let text = e.to_string();
    // the position of the bad byte, computed independently from the text before it
    let line = case[..at].matches('\n').count() + 1;
    assert!(text.contains(&format!("byte {at} (0xff)")), "{text}");
    assert!(text.contains(&format!("line {line},")), "{text}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn repeated_keys_are_reported_even_though_json_objects_keep_one() {
    let case = serde_json::to_string_pretty(&two_link()).unwrap();
    let text = case.replacen("\"mass\": 4.0,", "\"mass\": 4.0, \"mass\": 5.0,", 1);
    let e = Case::from_json_str(&text).unwrap_err();
    assert!(line_at(&e, "bodies[0].mass").contains("duplicate key `mass`"));
}

#[test]
fn a_huge_description_is_accepted_and_errors_never_print_it_whole() {
    let mut v = two_link();
    v["description"] = json!("x".repeat(10 << 20));
    let text = serde_json::to_string(&v).unwrap();
    assert!(Case::from_json_str(&text).is_ok());
    // as an unknown variant it appears in an error: clipped
    let mut v = two_link();
    v["joints"][0]["kind"] = json!("y".repeat(1 << 20));
    let e = errors_of(&v);
    assert!(e.to_string().len() < 1_000, "{} bytes", e.to_string().len());
}

#[test]
fn too_many_parameters_are_refused_in_linear_time() {
    let mut v = two_link();
    let params = v["parameters"].as_object_mut().unwrap();
    for i in 0..400_000 {
        params.insert(format!("p{i}"), json!(i));
    }
    let e = errors_of(&v);
    assert!(line_at(&e, "parameters").contains("400,002 parameters; the limit is 10,000"));
    let mut lifted = Limits::default();
    lifted.apply("parameters=500000").unwrap();
    let text = serde_json::to_string(&v).unwrap();
    assert!(Case::from_json_str_with(&text, &lifted).is_ok());
}

#[test]
fn grids_are_sized_before_they_are_built() {
    for n in [1e30, 2f64.powi(63), 1e308, 2_000.0] {
        let mut v = two_link();
        v["tasks"]["grid"]["M1"] = json!([-1, 1, n]);
        let e = errors_of(&v);
        assert!(
            line_at(&e, "tasks.grid.M1[2]").contains("values on one axis; the limit is 1,000"),
            "{e}"
        );
    }
    // 40 × 40 = 1,600 points: each axis is fine, the product is not
    let mut v = two_link();
    v["tasks"]["grid"] = json!({ "M1": [-1, 1, 40], "M2": [-1, 1, 40] });
    let e = errors_of(&v);
    assert!(line_at(&e, "tasks.grid").contains("1,600 grid points; the limit is 1,000"));
    let mut lifted = Limits::default();
    lifted.apply("grid-points=2000").unwrap();
    let text = serde_json::to_string(&v).unwrap();
    // 1,600 points → 1,279,200 tasks × 51 samples: within the evaluation limit? no (6.5e7)
    let e = Case::from_json_str_with(&text, &lifted).unwrap_err();
    assert!(line_at(&e, "tasks").contains("evaluations (1,279,200 tasks × 51 samples)"));
}

#[test]
fn a_grid_of_one_point_is_an_error() {
    let mut v = two_link();
    v["tasks"]["grid"] = json!({ "M1": [-1, 1, 1], "M2": [0, 1, 1] });
    let e = errors_of(&v);
    assert!(line_at(&e, "tasks.grid").contains("single point"));
}

#[test]
fn magnitudes_are_checked_with_the_field_path() {
    let mut v = two_link();
    v["parameters"]["L1"] = json!(1e308);
    v["bodies"][1]["mass"] = json!(1e308);
    v["bodies"][0]["inertia"][1] = json!(1e12);
    v["gravity"] = json!([0, -1e308, 0]);
    v["tasks"]["duration"] = json!(1e-300);
    v["actuators"][1]["ratio"] = json!(1e300);
    let e = errors_of(&v);
    assert!(line_at(&e, "parameters.L1").contains("1e308 is beyond the supported magnitude"));
    assert!(line_at(&e, "bodies[1].mass").contains("1e308 kg is beyond"));
    assert!(line_at(&e, "bodies[0].inertia[1]").contains("1e12 kg·m²"));
    assert!(line_at(&e, "gravity[1]").contains("±1000 m/s²"));
    assert!(line_at(&e, "tasks.duration").contains("found 1e-300"));
    assert!(line_at(&e, "actuators[1].ratio").contains("1e300"));
}

#[test]
fn a_link_of_1e9_metres_is_refused_at_its_pose() {
    let mut v = two_link();
    v["parameters"]["L1"] = json!(1e9);
    let e = errors_of(&v);
    assert!(line_at(&e, "bodies[1].pose").contains("translations reach 1e9 m"));
}

#[test]
fn pose_degrees_cannot_overflow() {
    let mut v = two_link();
    v["bodies"][1]["pose"] = json!(vec![json!({"rot_z": "q1"}); 300]);
    let e = errors_of(&v);
    assert_eq!(e.len(), 1, "{e}");
    assert!(line_at(&e, "bodies[1].pose[64]").contains("degree 65"));
    // a chain of bodies, each rotating by 20·q1, passes the limit at the fourth
    let mut v = two_link();
    let mut bodies = Vec::new();
    for k in 0..4 {
        let parent = if k == 0 {
            "base".to_string()
        } else {
            format!("b{}", k - 1)
        };
        bodies.push(json!({ "name": format!("b{k}"), "parent": parent,
                            "pose": [ { "rot_z": "20*q1" } ], "mass": 0 }));
    }
    v["bodies"] = json!(bodies);
    v["joints"] = json!([]);
    let e = errors_of(&v);
    assert!(line_at(&e, "bodies[3].pose").contains("degree 80"), "{e}");
}

#[test]
fn deep_expressions_are_errors_on_a_small_stack() {
    let worker = std::thread::Builder::new()
        .stack_size(2 << 20)
        .spawn(|| {
            let mut v = two_link();
            v["bodies"][0]["com"][0] = json!(format!("{}L1{}", "(".repeat(3000), ")".repeat(3000)));
            v["bodies"][1]["com"][0] = json!(format!("{}L2", "-".repeat(5000)));
            errors_of(&v)
        })
        .unwrap();
    let e = worker.join().expect("no stack overflow");
    assert!(line_at(&e, "bodies[0].com[0]").contains("deeper than 256 levels"));
    assert!(line_at(&e, "bodies[1].com[0]").contains("deeper than 256 levels"));
}

#[test]
fn a_long_parent_chain_does_not_recurse() {
    let worker = std::thread::Builder::new()
        .stack_size(256 << 10)
        .spawn(|| {
            let mut v = two_link();
            let mut bodies = vec![json!({ "name": "b0", "parent": "base", "mass": 0 })];
            for k in 1..5_000 {
                bodies.push(
                    json!({ "name": format!("b{k}"), "parent": format!("b{}", k - 1),
                                    "mass": 0 }),
                );
            }
            v["bodies"] = json!(bodies);
            v["joints"] = json!([]);
            v["payloads"] = json!([]);
            v["balancing"] = json!(null);
            Case::from_json_str(&serde_json::to_string(&v).unwrap()).map(|m| m.bodies.len())
        })
        .unwrap();
    // the actuators name joints that are gone: refused, but without a stack overflow
    assert!(worker.join().expect("no stack overflow").is_err());
}
