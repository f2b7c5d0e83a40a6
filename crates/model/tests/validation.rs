//! One test per kind of case-file error: each must name the JSON path of the offending field.

use counterpoise_model::{Case, CaseErrors, ModelError};
use serde_json::{Value, json};

/// A small valid case (a two-link arm with every optional section) to break one field at a time.
fn base() -> Value {
    json!({
        "name": "arm",
        "gravity": [0, -9.81, 0],
        "parameters": { "L1": 0.8, "L2": 0.6 },
        "coordinates": [
            { "name": "q1", "kind": "angle", "range": [-3.0, 3.0] },
            { "name": "q2", "kind": "angle", "range": [-2.8, 2.8] }
        ],
        "bodies": [
            { "name": "link1", "parent": "base", "pose": [ { "rot_z": "q1" } ],
              "mass": 4.0, "com": ["L1/2", 0, 0], "inertia": [0.004, 0.2, 0.2, 0, 0, 0] },
            { "name": "link2", "parent": "link1",
              "pose": [ { "translate": ["L1", 0, 0] }, { "rot_z": "q2" } ],
              "mass": 2.5, "com": ["L2/2", 0, 0], "inertia": [0.002, 0.07, 0.07, 0, 0, 0] }
        ],
        "payloads": [ { "body": "link2", "mass": 1.0, "com": ["L2", 0, 0] } ],
        "joints": [
            { "name": "J1", "kind": "revolute", "bodies": ["base", "link1"], "point": [0, 0, 0], "axis": [0, 0, 1] },
            { "name": "J2", "kind": "revolute", "bodies": ["link1", "link2"], "point": ["L1", 0, 0], "axis": [0, 0, 1] }
        ],
        "actuators": [
            { "name": "M1", "joint": "J1", "coordinate": "q1", "ratio": 0.01 },
            { "name": "M2", "joint": "J2", "coordinate": "q2", "ratio": 0.01 }
        ],
        "balancing": {
            "dmax": 2,
            "counterweights": { "bodies": "all", "plane": "xy" },
            "springs": { "bodies": ["link1", "link2"], "include_base": true },
            "peak_limits": { "M1": 10 }
        },
        "tasks": { "grid": { "M1": [-1, 1, 3], "M2": [-1, 1, 3] }, "duration": 1.0 },
        "paths": [ {
            "name": "p", "waypoints": { "a": [0, 0], "b": [1, 1] }, "sequence": ["a", "b", "a"],
            "durations": [1, 1],
            "payload": { "body": "link2", "mass": 1, "com": [0, 0, 0], "pick_at": "b", "drop_at": "a" }
        } ]
    })
}

fn load(v: &Value) -> Result<counterpoise_model::Model, CaseErrors> {
    Case::from_json_str(&serde_json::to_string_pretty(v).unwrap())
}

/// Applies `edit` to the base case and expects an error at `path` whose message contains
/// `needle`; returns that error.
fn expect_error(edit: impl FnOnce(&mut Value), path: &str, needle: &str) -> ModelError {
    let mut v = base();
    edit(&mut v);
    let errors = load(&v).expect_err("the edited case must be refused");
    let found = errors.iter().find(|e| e.path() == path).unwrap_or_else(|| {
        panic!("no error at `{path}`; got:\n{errors}");
    });
    let text = found.to_string();
    assert!(
        text.starts_with(path),
        "message must start with the path: {text}"
    );
    assert!(text.contains(needle), "`{text}` should mention `{needle}`");
    found.clone()
}

#[test]
fn the_base_case_and_the_shipped_cases_are_valid() {
    load(&base()).unwrap_or_else(|e| panic!("{e}"));
    for name in ["palletizer", "pendulum", "two_link"] {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../cases")
            .join(format!("{name}.json"));
        Case::from_path(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
    }
}

#[test]
fn malformed_json_reports_line_and_column() {
    let errors =
        Case::from_json_str("{\n  \"name\": \"x\",\n  \"gravity\": [0, 0, \n}").unwrap_err();
    match &errors.errors[0] {
        ModelError::Syntax { line, column, .. } => assert_eq!((*line, *column), (4, 1)),
        other => panic!("{other:?}"),
    }
    // Trailing garbage after the object.
    let text = serde_json::to_string(&base()).unwrap() + " x";
    assert!(matches!(
        Case::from_json_str(&text).unwrap_err().errors[0],
        ModelError::Syntax { .. }
    ));
}

#[test]
fn wrong_types_and_unknown_fields_name_their_path() {
    let e = expect_error(
        |v| v["bodies"][1]["mass"] = json!("heavy"),
        "bodies[1].mass",
        "invalid type",
    );
    assert!(matches!(e, ModelError::Syntax { .. }));
    expect_error(
        |v| v["bodies"][0]["masss"] = json!(1),
        "bodies[0].masss",
        "unknown field",
    );
    expect_error(
        |v| v["joints"][0]["kind"] = json!("hinge"),
        "joints[0].kind",
        "unknown variant",
    );
    expect_error(
        |v| v["bodies"][0]["pose"][0] = json!({"rot_q": 1}),
        "bodies[0].pose[0]",
        "unknown variant",
    );
    expect_error(
        |v| v["gravity"] = json!([0, 1]),
        "gravity",
        "invalid length",
    );
    expect_error(
        |v| v["balancing"]["counterweights"]["bodies"] = json!("some"),
        "balancing.counterweights.bodies",
        "\"all\"",
    );
    expect_error(
        |v| v["balancing"]["dmax"] = json!(1.5),
        "balancing.dmax",
        "invalid type",
    );
}

#[test]
fn numbers_out_of_range_are_refused() {
    // serde_json refuses 1e999 (infinite) while reading; the path is still named.
    let text = serde_json::to_string(&base())
        .unwrap()
        .replace("\"mass\":4.0", "\"mass\":1e999");
    let errors = Case::from_json_str(&text).unwrap_err();
    assert_eq!(errors.errors[0].path(), "bodies[0].mass", "{errors}");
    // A non-finite value computed by an expression.
    expect_error(
        |v| v["bodies"][0]["com"][0] = json!("1e300*1e300"),
        "bodies[0].com[0]",
        "not finite",
    );
}

#[test]
fn unknown_names() {
    expect_error(
        |v| v["bodies"][1]["parent"] = json!("link9"),
        "bodies[1].parent",
        "unknown body `link9`",
    );
    expect_error(
        |v| v["joints"][1]["bodies"][1] = json!("link3"),
        "joints[1].bodies[1]",
        "unknown body `link3`",
    );
    expect_error(
        |v| v["actuators"][0]["joint"] = json!("J7"),
        "actuators[0].joint",
        "unknown joint `J7`",
    );
    expect_error(
        |v| v["payloads"][0]["body"] = json!("hand"),
        "payloads[0].body",
        "unknown body `hand`",
    );
    expect_error(
        |v| v["balancing"]["springs"]["bodies"] = json!(["link1", "link7"]),
        "balancing.springs.bodies[1]",
        "unknown body `link7`",
    );
    expect_error(
        |v| v["balancing"]["peak_limits"] = json!({"M9": 3}),
        "balancing.peak_limits.M9",
        "unknown actuator `M9`",
    );
    expect_error(
        |v| v["tasks"]["grid"] = json!({"M1": [0, 1, 2], "M2": [0, 1, 2], "M3": [0, 1, 2]}),
        "tasks.grid.M3",
        "unknown actuator `M3`",
    );
    expect_error(
        |v| v["paths"][0]["sequence"][2] = json!("z"),
        "paths[0].sequence[2]",
        "unknown waypoint `z`",
    );
    expect_error(
        |v| v["bodies"][0]["pose"][0]["rot_z"] = json!("q3"),
        "bodies[0].pose[0].rot_z",
        "unknown name",
    );
}

#[test]
fn duplicate_names() {
    expect_error(
        |v| v["bodies"][1]["name"] = json!("link1"),
        "bodies[1].name",
        "duplicate body `link1`",
    );
    expect_error(
        |v| v["coordinates"][1]["name"] = json!("q1"),
        "coordinates[1].name",
        "duplicate name `q1`",
    );
    expect_error(
        |v| v["joints"][1]["name"] = json!("J1"),
        "joints[1].name",
        "duplicate joint `J1`",
    );
    expect_error(
        |v| v["actuators"][1]["name"] = json!("M1"),
        "actuators[1].name",
        "duplicate actuator `M1`",
    );
    // A parameter and a coordinate share a name.
    expect_error(
        |v| v["parameters"]["q2"] = json!(1.0),
        "coordinates[1].name",
        "already defined at parameters.q2",
    );
    expect_error(
        |v| v["parameters"]["pi"] = json!(3.0),
        "parameters.pi",
        "not a valid parameter name",
    );
    // The same key twice in one JSON object.
    let text = serde_json::to_string(&base())
        .unwrap()
        .replace("\"L2\":0.6", "\"L2\":0.6,\"L1\":0.7");
    let errors = Case::from_json_str(&text).unwrap_err();
    assert!(
        errors.errors[0].to_string().contains("duplicate key `L1`"),
        "{errors}"
    );
    assert_eq!(errors.errors[0].path(), "parameters.L1");
}

#[test]
fn parent_cycles() {
    let e = expect_error(
        |v| v["bodies"][0]["parent"] = json!("link2"),
        "bodies[0].parent",
        "link1 → link2 → link1",
    );
    assert!(matches!(e, ModelError::Cycle { .. }));
    expect_error(
        |v| v["bodies"][1]["parent"] = json!("link2"),
        "bodies[1].parent",
        "link2 → link2",
    );
}

#[test]
fn masses_and_inertias() {
    expect_error(
        |v| v["bodies"][1]["mass"] = json!(-2.5),
        "bodies[1].mass",
        "≥ 0",
    );
    expect_error(
        |v| v["bodies"][0]["inertia"] = json!([1.0, 1.0, 1.0, 2.0, 0, 0]),
        "bodies[0].inertia",
        "not positive semi-definite",
    );
    expect_error(
        |v| v["payloads"][0]["mass"] = json!(-1),
        "payloads[0].mass",
        "≥ 0",
    );
    expect_error(
        |v| v["payloads"][0]["inertia"] = json!([-1, 0, 0, 0, 0, 0]),
        "payloads[0].inertia",
        "not positive semi-definite",
    );
    expect_error(
        |v| {
            v["bodies"][0]
                .as_object_mut()
                .unwrap()
                .remove("com")
                .map(drop)
                .unwrap()
        },
        "bodies[0].com",
        "required when mass > 0",
    );
    // A massless link needs neither com nor inertia; the triangle inequality is not required.
    let mut v = base();
    v["bodies"][0] =
        json!({ "name": "link1", "parent": "base", "pose": [ { "rot_z": "q1" } ], "mass": 0 });
    v["bodies"][1]["inertia"] = json!([10.0, 1.0, 1.0, 0, 0, 0]);
    load(&v).unwrap_or_else(|e| panic!("{e}"));
}

#[test]
fn zero_and_misplaced_axes() {
    expect_error(
        |v| v["joints"][0]["axis"] = json!([0, 0, 0]),
        "joints[0].axis",
        "must not be zero",
    );
    expect_error(
        |v| {
            v["joints"][0].as_object_mut().unwrap().remove("axis");
        },
        "joints[0].axis",
        "required for a revolute joint",
    );
    expect_error(
        |v| v["joints"][1]["axis2"] = json!([1, 0, 0]),
        "joints[1].axis2",
        "only a universal joint",
    );
}

#[test]
fn coordinate_ranges() {
    expect_error(
        |v| v["coordinates"][0]["range"] = json!([1.0, 1.0]),
        "coordinates[0].range",
        "min must be < max",
    );
    expect_error(
        |v| v["coordinates"][1]["range"] = json!([2.0, -2.0]),
        "coordinates[1].range",
        "min must be < max",
    );
}

#[test]
fn expression_errors_wrap_the_field_path() {
    let e = expect_error(
        |v| v["bodies"][1]["pose"][0]["translate"][0] = json!("sqrt(L1)"),
        "bodies[1].pose[0].translate[0]",
        "sqrt",
    );
    assert!(matches!(e, ModelError::Expression { .. }));
    expect_error(
        |v| v["bodies"][0]["pose"][0]["rot_z"] = json!("q1/2"),
        "bodies[0].pose[0].rot_z",
        "q1/2",
    );
    expect_error(
        |v| v["joints"][1]["point"][0] = json!("L1*cos(q1)"),
        "joints[1].point[0]",
        "constant",
    );
    expect_error(
        |v| v["actuators"][1]["coordinate"] = json!("atan2(q1, q2)"),
        "actuators[1].coordinate",
        "atan2",
    );
}

#[test]
fn inconsistent_joints_name_the_joint_the_deviation_and_the_configuration() {
    // J2's point put 3 cm off the end of link1: link2 swings about another point.
    let e = expect_error(
        |v| v["joints"][1]["point"] = json!([0.77, 0, 0]),
        "joints[1]",
        "joint `J2` is inconsistent: points differ by",
    );
    let text = e.to_string();
    assert!(text.contains("q1 = ") && text.contains("q2 = "), "{text}");
    // A tilted revolute axis.
    expect_error(
        |v| v["joints"][1]["axis"] = json!([0, 0.1, 1]),
        "joints[1]",
        "axes differ by",
    );
    // A prismatic joint on bodies that rotate relative to each other.
    expect_error(
        |v| {
            v["joints"][1]["kind"] = json!("prismatic");
            v["actuators"][1]["joint"] = json!("J1");
        },
        "joints[1]",
        "relative rotation changes by",
    );
    // A fixed joint between moving bodies.
    expect_error(
        |v| v["joints"][1]["kind"] = json!("fixed"),
        "joints[1]",
        "relative rotation changes by",
    );
    // Universal joint whose axes are not perpendicular.
    expect_error(
        |v| {
            v["joints"][1]["kind"] = json!("universal");
            v["joints"][1]["axis2"] = json!([0, 0, 1]);
            v["actuators"][1]["joint"] = json!("J1");
        },
        "joints[1]",
        "off perpendicular",
    );
}

#[test]
fn actuators_must_be_square_and_follow_their_joints() {
    expect_error(
        |v| {
            v["actuators"].as_array_mut().unwrap().pop();
            v["tasks"]["grid"].as_object_mut().unwrap().remove("M2");
            v["paths"] = json!([]);
        },
        "actuators",
        "1 actuators for 2 coordinates",
    );
    // u = 2·q2 is not the rotation of J2.
    expect_error(
        |v| v["actuators"][1]["coordinate"] = json!("2*q2"),
        "actuators[1].coordinate",
        "does not follow its joint",
    );
    // u = q1 + q2 is the absolute angle of link2, not J2's relative rotation.
    expect_error(
        |v| v["actuators"][1]["coordinate"] = json!("q1 + q2"),
        "actuators[1].coordinate",
        "does not follow its joint",
    );
    expect_error(
        |v| v["actuators"][0]["ratio"] = json!(0),
        "actuators[0].ratio",
        "> 0",
    );
}

#[test]
fn balancing_tasks_and_paths() {
    expect_error(
        |v| v["balancing"]["dmax"] = json!(0),
        "balancing.dmax",
        "≥ 1",
    );
    expect_error(
        |v| v["balancing"]["bounds"] = json!({"mass": [5, 1]}),
        "balancing.bounds.mass",
        "0 ≤ lo ≤ hi",
    );
    expect_error(
        |v| v["balancing"]["counterweights"]["bodies"] = json!(["base"]),
        "balancing.counterweights.bodies[0]",
        "base cannot carry",
    );
    expect_error(
        |v| v["tasks"]["grid"]["M2"] = json!([0, 1, 2.5]),
        "tasks.grid.M2[2]",
        "integer ≥ 1",
    );
    expect_error(
        |v| {
            v["tasks"]["grid"].as_object_mut().unwrap().remove("M2");
        },
        "tasks.grid",
        "missing: M2",
    );
    expect_error(
        |v| v["tasks"]["duration"] = json!(0),
        "tasks.duration",
        "between 0.001 and 1000000 s",
    );
    expect_error(|v| v["tasks"]["samples"] = json!(1), "tasks.samples", "≥ 2");
    expect_error(
        |v| v["paths"][0]["durations"] = json!([1]),
        "paths[0].durations",
        "one duration per segment",
    );
    expect_error(
        |v| v["paths"][0]["waypoints"]["a"] = json!([0]),
        "paths[0].waypoints.a",
        "one value per actuator",
    );
    expect_error(
        |v| v["paths"][0]["payload"]["drop_at"] = json!("b"),
        "paths[0].payload.drop_at",
        "after pick_at",
    );
}

#[test]
fn all_errors_are_collected() {
    let mut v = base();
    v["bodies"][1]["mass"] = json!(-1);
    v["coordinates"][0]["range"] = json!([1, 0]);
    v["joints"][0]["axis"] = json!([0, 0, 0]);
    v["actuators"][1]["joint"] = json!("nope");
    let errors = load(&v).unwrap_err();
    let paths: Vec<&str> = errors.iter().map(ModelError::path).collect();
    for expected in [
        "bodies[1].mass",
        "coordinates[0].range",
        "joints[0].axis",
        "actuators[1].joint",
    ] {
        assert!(
            paths.contains(&expected),
            "{expected} missing from {paths:?}"
        );
    }
    assert!(
        errors
            .to_string()
            .starts_with(&format!("{} errors in the case file", errors.len()))
    );
}

/// JSON pointers of every value in `v` (objects and arrays included).
fn pointers(v: &Value, prefix: String, out: &mut Vec<String>) {
    match v {
        Value::Object(map) => {
            for (k, child) in map {
                pointers(child, format!("{prefix}/{k}"), out);
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

fn odd_values() -> Vec<Value> {
    vec![
        json!(-1),
        json!(0),
        json!(1e308),
        json!(-1e-300),
        json!(""),
        json!("q1"),
        json!("base"),
        json!("link1"),
        json!("sqrt(2)"),
        json!("cos(q1)^70"),
        json!("1/0"),
        json!([]),
        json!([0, 0, 0]),
        json!([1, 0]),
        json!({}),
        json!(null),
        json!(true),
    ]
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(400))]
    /// Whatever single field is replaced or removed, loading returns a model or errors: it never
    /// panics.
    #[test]
    fn mutated_cases_never_panic(which in 0usize..10_000, value in 0usize..17, remove in proptest::bool::weighted(0.2)) {
        let mut v = base();
        let mut all = Vec::new();
        pointers(&v, String::new(), &mut all);
        let pointer = all[which % all.len()].clone();
        if pointer.is_empty() {
            return Ok(());
        }
        if remove {
            let (parent, key) = pointer.rsplit_once('/').unwrap();
            match v.pointer_mut(parent) {
                Some(Value::Object(map)) => { map.remove(key); }
                Some(Value::Array(items)) => { items.remove(key.parse::<usize>().unwrap()); }
                _ => {}
            }
        } else {
            *v.pointer_mut(&pointer).unwrap() = odd_values()[value].clone();
        }
        let text = serde_json::to_string(&v).unwrap();
        if let Err(errors) = Case::from_json_str(&text) {
            proptest::prop_assert!(!errors.is_empty());
            for e in &errors {
                proptest::prop_assert!(!e.path().is_empty());
            }
        }
    }
}
