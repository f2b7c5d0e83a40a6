//! Schematics (issue 31, item 1): the drawn positions of joint centres, counterweight centres
//! and spring anchors are the model's kinematics at the drawn pose. The SVG is parsed back:
//! its configuration (`data-q`) and its projection (`data-right`, `data-up`, `data-scale`,
//! `data-ox`, `data-oy`); each point is recomputed here from the case file (the model's
//! kinematics and the variant's parameters in results.json) and projected by the stated
//! formula. The pose itself is checked against what the report says it is (the first path
//! waypoint, or the middle grid point) through the actuator map.

mod common;

use std::path::Path;

use common::{assert_success, counterpoise, reduced_palletizer, results, root, write_case};
use counterpoise_model::{Case, JointKind, Kinematics, Model};
use nalgebra::{DVector, Vector3};

/// The value of attribute `name` in the tag text `tag`.
fn attr<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let key = format!(" {name}=\"");
    let start = tag.find(&key)? + key.len();
    let end = start + tag[start..].find('"')?;
    Some(&tag[start..end])
}

fn floats(s: &str) -> Vec<f64> {
    s.split_whitespace().map(|x| x.parse().unwrap()).collect()
}

/// Every `<svg … schematic …>…</svg>` of a page: (root tag, body).
fn schematics(html: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    let mut rest = html;
    while let Some(k) = rest.find("<svg ") {
        let tail = &rest[k..];
        let open_end = tail.find('>').unwrap();
        let end = tail.find("</svg>").unwrap();
        if tail[..open_end].contains("schematic") {
            out.push((
                tail[..open_end].to_string(),
                tail[open_end..end].to_string(),
            ));
        }
        rest = &tail[end..];
    }
    out
}

/// Every tag of `body` opening with `<circle` and carrying attribute `key`.
fn circles<'a>(body: &'a str, key: &str) -> Vec<&'a str> {
    body.split('<')
        .filter(|t| t.starts_with("circle ") && t.contains(&format!(" {key}=\"")))
        .collect()
}

/// The labels of a drawing do not overprint each other, and each is beside the point it names
/// or joined to it by a leader line (issue 31: the palletizer's labels crowded at its sliders).
/// Boxes are estimated here from the text's position, size and length at 0.55 em a character
/// (0.6 em bold), about DejaVu Sans's average, from 0.75 em above the baseline to 0.2 em below.
fn assert_labels_clear(body: &str, what: &str) -> usize {
    struct Text {
        text: String,
        point: (f64, f64),
        x0: f64,
        x1: f64,
        y0: f64,
        y1: f64,
        /// The right end at a generous 0.7 em a character (where a leader may end).
        wide: f64,
    }
    let num = |tag: &str, key: &str| attr(tag, key).unwrap().parse::<f64>().unwrap();
    let texts: Vec<Text> = body
        .split('<')
        .filter(|t| t.starts_with("text ") && t.contains(" data-label-x=\""))
        .map(|t| {
            let (tag, text) = t.split_once('>').unwrap();
            let size = num(tag, "font-size");
            let em = if tag.contains("font-weight") {
                0.6
            } else {
                0.55
            };
            let (x, y) = (num(tag, "x"), num(tag, "y"));
            Text {
                text: text.to_string(),
                point: (num(tag, "data-label-x"), num(tag, "data-label-y")),
                x0: x,
                x1: x + em * size * text.chars().count() as f64,
                y0: y - 0.75 * size,
                y1: y + 0.2 * size,
                wide: x + 0.7 * size * text.chars().count() as f64,
            }
        })
        .collect();
    let leaders: Vec<(String, [f64; 4])> = body
        .split('<')
        .filter(|t| t.starts_with("line ") && t.contains(" data-leader=\""))
        .map(|t| {
            let c = ["x1", "y1", "x2", "y2"].map(|k| num(t, k));
            (attr(t, "data-leader").unwrap().to_string(), c)
        })
        .collect();
    for (i, a) in texts.iter().enumerate() {
        for b in &texts[i + 1..] {
            let w = a.x1.min(b.x1) - a.x0.max(b.x0);
            let h = a.y1.min(b.y1) - a.y0.max(b.y0);
            assert!(
                w <= 0.0 || h <= 0.0,
                "{what}: labels {} and {} overprint",
                a.text,
                b.text
            );
        }
        let (px, py) = a.point;
        let gap = (px.clamp(a.x0, a.x1) - px).hypot(py.clamp(a.y0, a.y1) - py);
        let led = leaders.iter().any(|(t, [x1, y1, x2, y2])| {
            // From the marker's edge (a disc is at most 30 px) to the label's box.
            *t == a.text
                && (x1 - px).hypot(y1 - py) <= 32.0
                && *y2 >= a.y0 - 1.0
                && *y2 <= a.y1 + 1.0
                && *x2 >= a.x0 - 1.0
                && *x2 <= a.wide + 1.0
        });
        assert!(
            gap <= 40.0 || led,
            "{what}: label {} is {gap:.0} px from its point without a leader",
            a.text
        );
    }
    texts.len()
}

struct Drawing {
    q: DVector<f64>,
    right: Vector3<f64>,
    up: Vector3<f64>,
    scale: f64,
    origin: (f64, f64),
}

impl Drawing {
    fn of(root: &str) -> Drawing {
        let v3 = |n: &str| Vector3::from_vec(floats(attr(root, n).unwrap()));
        Drawing {
            q: DVector::from_vec(floats(attr(root, "data-q").unwrap())),
            right: v3("data-right"),
            up: v3("data-up"),
            scale: attr(root, "data-scale").unwrap().parse().unwrap(),
            origin: (
                attr(root, "data-ox").unwrap().parse().unwrap(),
                attr(root, "data-oy").unwrap().parse().unwrap(),
            ),
        }
    }

    /// Where world point `p` must be drawn.
    fn pixel(&self, p: Vector3<f64>) -> (f64, f64) {
        (
            self.origin.0 + self.scale * p.dot(&self.right),
            self.origin.1 - self.scale * p.dot(&self.up),
        )
    }

    /// Asserts that the circle `tag` is drawn at world point `p` (the SVG prints two
    /// decimals: 0.005 px).
    fn assert_at(&self, tag: &str, p: Vector3<f64>, what: &str) {
        let (x, y) = self.pixel(p);
        let cx: f64 = attr(tag, "cx").unwrap().parse().unwrap();
        let cy: f64 = attr(tag, "cy").unwrap().parse().unwrap();
        assert!(
            (cx - x).abs() <= 0.006 && (cy - y).abs() <= 0.006,
            "{what}: drawn at ({cx}, {cy}), kinematics give ({x:.3}, {y:.3})"
        );
    }
}

/// World position of `p` in the frame of `body` (or the base) at `q`.
fn world(kin: &Kinematics, body: Option<usize>, p: Vector3<f64>, q: &DVector<f64>) -> Vector3<f64> {
    match body {
        Some(b) => {
            let pose = kin.body_pose(b, q);
            pose.position + pose.rotation * p
        }
        None => p,
    }
}

/// Runs `case`, then checks every schematic of its report; returns how many points were
/// checked.
fn check_case(case_path: &str, out: &Path, expected_pose: impl Fn(&Model) -> Vec<f64>) -> usize {
    let o = counterpoise(&["run", case_path, "--out", out.to_str().unwrap(), "--quiet"]);
    assert_success(&o);
    let model = Case::from_path(Path::new(case_path)).unwrap();
    let kin = Kinematics::new(&model);
    let doc = results(out);
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    let drawings = schematics(&html);
    assert!(!drawings.is_empty(), "{case_path}: no schematic");
    let mut checked = 0;
    for (root_tag, body) in &drawings {
        let d = Drawing::of(root_tag);
        // The pose is the one the report names: its actuator values are the expected ones.
        let u = kin.actuator_values(&d.q);
        for (a, b) in u.iter().zip(expected_pose(&model)) {
            assert!((a - b).abs() < 1e-9, "{case_path}: pose u {u:?}");
        }
        assert!((d.up.norm() - 1.0).abs() < 1e-9 && d.right.dot(&d.up).abs() < 1e-9);
        // Every body is named, and every element of a variant.
        let labelled = assert_labels_clear(body, case_path);
        assert!(
            labelled >= model.bodies.len(),
            "{case_path}: {labelled} labels"
        );
        for tag in circles(body, "data-joint") {
            let name = attr(tag, "data-joint").unwrap();
            let j = model.joints.iter().find(|j| j.name == name).unwrap();
            // The joint point on its first body; for joints that keep their point (revolute,
            // spherical, universal) the second body's gives the same pixel. A prismatic
            // joint's second point is where it sits at the reference configuration, an
            // orientation joint's only locates its moments.
            let keeps_point = matches!(
                j.kind,
                JointKind::Revolute | JointKind::Spherical | JointKind::Universal
            );
            for side in 0..if keeps_point { 2 } else { 1 } {
                let p = world(&kin, j.bodies[side].index(), j.points[side], &d.q);
                d.assert_at(tag, p, &format!("joint {name}, side {side}"));
            }
            checked += 1;
        }
        let variant = attr(root_tag, "data-variant").unwrap();
        if variant == "UB" {
            continue;
        }
        let id: u64 = variant.parse().unwrap();
        let v = doc["variants"]
            .as_array()
            .unwrap()
            .iter()
            .find(|v| v["id"].as_u64() == Some(id))
            .unwrap();
        let vec3 = |x: &serde_json::Value| {
            Vector3::new(
                x[0].as_f64().unwrap(),
                x[1].as_f64().unwrap(),
                x[2].as_f64().unwrap(),
            )
        };
        let body_of = |name: &str| {
            if name == "base" {
                None
            } else {
                Some(model.body_index(name).unwrap())
            }
        };
        let p = &v["parameters"];
        let cws = p["counterweights"].as_array().unwrap();
        let springs = p["springs"].as_array().unwrap();
        assert_eq!(circles(body, "data-cw").len(), cws.len());
        assert_eq!(circles(body, "data-spring").len(), 2 * springs.len());
        for tag in circles(body, "data-cw") {
            let label = attr(tag, "data-cw").unwrap();
            let c = cws.iter().find(|c| c["label"] == label).unwrap();
            let at = world(
                &kin,
                body_of(c["body"].as_str().unwrap()),
                vec3(&c["offset"]),
                &d.q,
            );
            d.assert_at(tag, at, &format!("counterweight {label}"));
            checked += 1;
        }
        for tag in circles(body, "data-spring") {
            let label = attr(tag, "data-spring").unwrap();
            let s = springs.iter().find(|s| s["label"] == label).unwrap();
            let (body_name, anchor) = match attr(tag, "data-end").unwrap() {
                "a" => (s["body"].as_str().unwrap(), &s["anchor_a"]),
                _ => (s["other"].as_str().unwrap(), &s["anchor_b"]),
            };
            let at = world(&kin, body_of(body_name), vec3(anchor), &d.q);
            d.assert_at(tag, at, &format!("spring {label}"));
            checked += 1;
        }
    }
    checked
}

/// The middle point of the task grid (the pose of a case without paths).
fn middle_grid_point(model: &Model) -> Vec<f64> {
    let points = model.tasks.as_ref().unwrap().grid_points();
    points[points.len() / 2].clone()
}

#[test]
fn two_link_schematics_are_its_kinematics() {
    let dir = tempfile::tempdir().unwrap();
    let case = root().join("cases/two_link.json");
    let n = check_case(
        case.to_str().unwrap(),
        &dir.path().join("out"),
        middle_grid_point,
    );
    assert!(n >= 4, "{n} points checked");
}

#[test]
fn imported_urdf_arm_schematics_are_its_kinematics() {
    // cases/two_link_urdf.json: imported by `import-urdf`; its recommendations hold
    // counterweights (SB4) and springs (SB1), so every kind of point is checked.
    let dir = tempfile::tempdir().unwrap();
    let case = root().join("cases/two_link_urdf.json");
    let n = check_case(
        case.to_str().unwrap(),
        &dir.path().join("out"),
        middle_grid_point,
    );
    assert!(n >= 8, "{n} points checked");
}

#[test]
fn palletizer_schematics_are_its_kinematics_at_the_first_waypoint() {
    // Spatial, with closed loops; drawn at the first waypoint of its path.
    let dir = tempfile::tempdir().unwrap();
    let case = write_case(dir.path(), "tiny.json", &reduced_palletizer(2, 11));
    let first_waypoint = |m: &Model| {
        let path = &m.paths[0];
        path.waypoints[path.sequence[0]].u.clone()
    };
    let n = check_case(&case, &dir.path().join("out"), first_waypoint);
    assert!(n >= 12, "{n} points checked");
}

#[test]
fn a_mechanism_without_a_recommendation_is_drawn_alone() {
    // cases/arm6.json (a 6-axis arm of our own, as from URDF) has no feasible variant at
    // Dmax 1: the report draws the unbalanced arm.
    let dir = tempfile::tempdir().unwrap();
    let case = root().join("cases/arm6.json");
    let out = dir.path().join("out");
    let o = counterpoise(&[
        "run",
        case.to_str().unwrap(),
        "--dmax",
        "1",
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert_success(&o);
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    let drawings = schematics(&html);
    assert_eq!(drawings.len(), 1);
    assert_eq!(attr(&drawings[0].0, "data-variant"), Some("UB"));
    let model = Case::from_path(&case).unwrap();
    assert_eq!(
        circles(&drawings[0].1, "data-joint").len(),
        model.joints.len()
    );
}

#[test]
fn report_draw_names_a_variant() {
    let dir = tempfile::tempdir().unwrap();
    let case = root().join("cases/two_link.json");
    let out = dir.path().join("out");
    assert_success(&counterpoise(&[
        "run",
        case.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]));
    let before = schematics(&std::fs::read_to_string(out.join("report.html")).unwrap()).len();
    assert_success(&counterpoise(&[
        "report",
        out.to_str().unwrap(),
        "--draw",
        "SB3",
    ]));
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert_eq!(schematics(&html).len(), before + 1);
    assert!(html.contains("SB3 (m2 + K20) at one pose"));
    let o = counterpoise(&["report", out.to_str().unwrap(), "--draw", "SB99"]);
    assert!(!o.status.success());
    assert!(common::stderr(&o).contains("--draw SB99"));
}
