//! Per-element bounds: the case's `balancing.bounds` with `balancing.overrides` applied.
//!
//! Format (documented in `docs/case-format.md`): each override is an object naming one element
//! and replacing some of its bounds,
//!
//! ```json
//! { "element": "m4", "radius": [0.2, 0.2] }
//! { "element": "K43", "anchor_a": [0.25, 0.8], "stiffness": [2000, 8000] }
//! { "element": "upper_arm", "mass": [0, 150] }
//! { "element": ["upper_arm", "slider_v"], "anchor_b": [0, 0.3] }
//! ```
//!
//! `element` is a catalogue label (`m4`, `K43`), a body name (its counterweight) or a pair of
//! body names `[i, s]` (the spring with anchor a on `i`, anchor b on `s`; `"base"` allowed).
//! Counterweights accept `mass` and `radius`; springs accept `stiffness`, `anchor_a`,
//! `anchor_b`. Every range is `[lo, hi]` with `0 ≤ lo ≤ hi`, finite. Later overrides of the
//! same element win field by field. Errors name `balancing.overrides[i].field`.

use std::collections::BTreeMap;

use counterpoise_balance::{Attachment, Catalogue, Element};
use counterpoise_model::{Bounds, Model};
use serde::Serialize;

use crate::error::OptimiseError;

/// Bounds of one counterweight.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct CounterweightBounds {
    /// kg.
    pub mass: [f64; 2],
    /// |r|, m.
    pub radius: [f64; 2],
}

/// Bounds of one spring.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SpringBounds {
    /// N/m.
    pub stiffness: [f64; 2],
    /// |a|, m.
    pub anchor_a: [f64; 2],
    /// |b|, m.
    pub anchor_b: [f64; 2],
    /// Per body-frame axis (x, y, z) of anchor a, `[lo, hi]` in m (infinite when free): a box,
    /// a half-space per coordinate, or a fixed anchor (`lo = hi` on every axis).
    pub box_a: [[f64; 2]; 3],
    /// The same for anchor b, in the frame of the other body (or the base).
    pub box_b: [[f64; 2]; 3],
}

/// No constraint on an anchor coordinate.
pub const FREE_AXIS: [f64; 2] = [f64::NEG_INFINITY, f64::INFINITY];

impl SpringBounds {
    /// Whether any anchor coordinate is bounded.
    pub fn has_box(&self) -> bool {
        self.box_a
            .iter()
            .chain(&self.box_b)
            .any(|r| r[0].is_finite() || r[1].is_finite())
    }
}

/// Bounds of one catalogue element.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(untagged)]
pub enum ElementBounds {
    Counterweight(CounterweightBounds),
    Spring(SpringBounds),
}

/// Bounds of every catalogue entry, in catalogue order.
#[derive(Clone, Debug, PartialEq)]
pub struct BoundsTable {
    pub entries: Vec<ElementBounds>,
}

impl BoundsTable {
    /// The defaults of `bounds` for every entry, then the overrides.
    pub fn new(model: &Model, catalogue: &Catalogue) -> Result<BoundsTable, OptimiseError> {
        let balancing = model.balancing.as_ref().ok_or(OptimiseError::NoBalancing)?;
        let defaults: Bounds = balancing.bounds;
        let mut entries: Vec<ElementBounds> = catalogue
            .entries
            .iter()
            .map(|e| match e.element {
                Element::Counterweight { .. } => {
                    ElementBounds::Counterweight(CounterweightBounds {
                        mass: defaults.mass,
                        radius: defaults.radius,
                    })
                }
                Element::Spring { .. } => ElementBounds::Spring(SpringBounds {
                    stiffness: defaults.stiffness,
                    anchor_a: defaults.anchor_a,
                    anchor_b: defaults.anchor_b,
                    box_a: [FREE_AXIS; 3],
                    box_b: [FREE_AXIS; 3],
                }),
            })
            .collect();
        let mut errors = Vec::new();
        // The last override of each entry, to name it when the entry's constraints conflict.
        let mut last: Vec<Option<usize>> = vec![None; entries.len()];
        for (i, value) in balancing.overrides.iter().enumerate() {
            if let Some(k) = apply(model, catalogue, &mut entries, i, value, &mut errors) {
                last[k] = Some(i);
            }
        }
        for (k, e) in entries.iter().enumerate() {
            if let (ElementBounds::Spring(b), Some(i)) = (e, last[k]) {
                consistent_anchors(catalogue, k, i, b, &mut errors);
            }
        }
        if errors.is_empty() {
            Ok(BoundsTable { entries })
        } else {
            Err(OptimiseError::Overrides(errors))
        }
    }

    pub fn counterweight(&self, entry: usize) -> CounterweightBounds {
        match self.entries[entry] {
            ElementBounds::Counterweight(b) => b,
            ElementBounds::Spring(_) => panic!("entry {entry} is a spring"),
        }
    }

    pub fn spring(&self, entry: usize) -> SpringBounds {
        match self.entries[entry] {
            ElementBounds::Spring(b) => b,
            ElementBounds::Counterweight(_) => panic!("entry {entry} is a counterweight"),
        }
    }
}

/// Resolves `element` to a catalogue entry.
fn resolve(
    model: &Model,
    catalogue: &Catalogue,
    element: &serde_json::Value,
) -> Result<usize, String> {
    match element {
        serde_json::Value::String(name) => {
            if let Some(k) = catalogue.entries.iter().position(|e| &e.label == name) {
                return Ok(k);
            }
            let Some(body) = model.body_index(name) else {
                return Err(format!(
                    "`{name}` is neither an element label (like m4, K43) nor a body name"
                ));
            };
            catalogue
                .entries
                .iter()
                .position(
                    |e| matches!(e.element, Element::Counterweight { body: b, .. } if b == body),
                )
                .ok_or_else(|| format!("body `{name}` may not carry a counterweight in this case"))
        }
        serde_json::Value::Array(pair) if pair.len() == 2 => {
            let names: Vec<&str> = pair.iter().filter_map(|v| v.as_str()).collect();
            if names.len() != 2 {
                return Err("a spring is named by two body names".into());
            }
            let body = model
                .body_index(names[0])
                .ok_or_else(|| format!("no body named `{}`", names[0]))?;
            let other = if names[1] == "base" {
                Attachment::Base
            } else {
                Attachment::Body(
                    model
                        .body_index(names[1])
                        .ok_or_else(|| format!("no body named `{}`", names[1]))?,
                )
            };
            catalogue
                .entries
                .iter()
                .position(|e| {
                    matches!(e.element, Element::Spring { body: b, other: o, .. } if b == body && o == other)
                })
                .ok_or_else(|| {
                    format!(
                        "no candidate spring with anchor a on `{}` and anchor b on `{}` (pairs are \
                         written [later body, earlier body])",
                        names[0], names[1]
                    )
                })
        }
        _ => Err("expected an element label, a body name or a pair of body names".into()),
    }
}

fn range(value: &serde_json::Value) -> Result<[f64; 2], String> {
    let arr = value
        .as_array()
        .filter(|a| a.len() == 2)
        .ok_or("expected [lo, hi]")?;
    let lo = arr[0].as_f64().ok_or("expected numbers [lo, hi]")?;
    let hi = arr[1].as_f64().ok_or("expected numbers [lo, hi]")?;
    if !(lo.is_finite() && hi.is_finite()) || lo < 0.0 || lo > hi {
        return Err(format!("expected 0 ≤ lo ≤ hi, finite; got [{lo}, {hi}]"));
    }
    Ok([lo, hi])
}

fn apply(
    model: &Model,
    catalogue: &Catalogue,
    entries: &mut [ElementBounds],
    i: usize,
    value: &serde_json::Value,
    errors: &mut Vec<String>,
) -> Option<usize> {
    let path = format!("balancing.overrides[{i}]");
    let Some(object) = value.as_object() else {
        errors.push(format!(
            "{path}: expected an object like {{\"element\": \"m4\", \"radius\": [0.2, 0.2]}}"
        ));
        return None;
    };
    let Some(element) = object.get("element") else {
        errors.push(format!(
            "{path}.element: missing (which element the override applies to)"
        ));
        return None;
    };
    let entry = match resolve(model, catalogue, element) {
        Ok(k) => k,
        Err(e) => {
            errors.push(format!("{path}.element: {e}"));
            return None;
        }
    };
    for (key, v) in object {
        if key == "element" {
            continue;
        }
        if let (
            ElementBounds::Spring(b),
            "anchor_a_box" | "anchor_b_box" | "anchor_a_fixed" | "anchor_b_fixed",
        ) = (&mut entries[entry], key.as_str())
        {
            let parsed = if key.ends_with("_box") {
                anchor_box(v)
            } else {
                fixed_anchor(v)
            };
            match parsed {
                Ok(r) if key.starts_with("anchor_a") => b.box_a = r,
                Ok(r) => b.box_b = r,
                Err(e) => errors.push(format!("{path}.{key}: {e}")),
            }
            continue;
        }
        let known = match &entries[entry] {
            ElementBounds::Counterweight(_) => ["mass", "radius"].contains(&key.as_str()),
            ElementBounds::Spring(_) => {
                ["stiffness", "anchor_a", "anchor_b"].contains(&key.as_str())
            }
        };
        if !known {
            errors.push(match &entries[entry] {
                ElementBounds::Counterweight(_) => format!(
                    "{path}.{key}: unknown field for a counterweight (expected mass, radius)"
                ),
                ElementBounds::Spring(_) => format!(
                    "{path}.{key}: unknown field for a spring (expected stiffness, anchor_a, \
                     anchor_b, anchor_a_box, anchor_b_box, anchor_a_fixed, anchor_b_fixed)"
                ),
            });
            continue;
        }
        let r = match range(v) {
            Ok(r) => r,
            Err(e) => {
                errors.push(format!("{path}.{key}: {e}"));
                continue;
            }
        };
        match (&mut entries[entry], key.as_str()) {
            (ElementBounds::Counterweight(b), "mass") => b.mass = r,
            (ElementBounds::Counterweight(b), "radius") => b.radius = r,
            (ElementBounds::Spring(b), "stiffness") => b.stiffness = r,
            (ElementBounds::Spring(b), "anchor_a") => b.anchor_a = r,
            (ElementBounds::Spring(b), "anchor_b") => b.anchor_b = r,
            _ => unreachable!("unknown fields are reported above"),
        }
    }
    Some(entry)
}

/// `{"x": [lo, hi], "y": [lo, null], …}`: per-axis bounds of an anchor in its body frame, m;
/// `null` leaves that side free (a half-space), a missing axis is free.
fn anchor_box(value: &serde_json::Value) -> Result<[[f64; 2]; 3], String> {
    let object = value
        .as_object()
        .ok_or("expected an object like {\"x\": [0, 0.5], \"y\": [-0.1, null]}")?;
    let mut out = [FREE_AXIS; 3];
    for (key, v) in object {
        let axis = match key.as_str() {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            _ => return Err(format!("unknown axis `{key}` (expected x, y, z)")),
        };
        let arr = v
            .as_array()
            .filter(|a| a.len() == 2)
            .ok_or_else(|| format!("{key}: expected [lo, hi] (null for no bound)"))?;
        let side = |x: &serde_json::Value, free: f64| -> Result<f64, String> {
            if x.is_null() {
                return Ok(free);
            }
            let v = x
                .as_f64()
                .ok_or_else(|| format!("{key}: expected numbers or null"))?;
            if v.is_finite() {
                Ok(v)
            } else {
                Err(format!("{key}: bounds must be finite (null for none)"))
            }
        };
        let lo = side(&arr[0], f64::NEG_INFINITY)?;
        let hi = side(&arr[1], f64::INFINITY)?;
        if lo > hi {
            return Err(format!("{key}: lo > hi ([{lo}, {hi}])"));
        }
        out[axis] = [lo, hi];
    }
    Ok(out)
}

/// `[x, y, z]`: a fixed anchor in its body frame, m.
fn fixed_anchor(value: &serde_json::Value) -> Result<[[f64; 2]; 3], String> {
    let arr = value
        .as_array()
        .filter(|a| a.len() == 3)
        .ok_or("expected [x, y, z] (m, body frame)")?;
    let mut out = [FREE_AXIS; 3];
    for (k, v) in arr.iter().enumerate() {
        let x = v
            .as_f64()
            .filter(|x| x.is_finite())
            .ok_or("expected three finite numbers")?;
        out[k] = [x, x];
    }
    Ok(out)
}

/// Contradictions between a spring's anchor constraints: a box that excludes 0 on an axis
/// outside the springs' plane (the coordinate is 0 there), or a box entirely outside the
/// distance range `|a| ≤ hi` (a fixed anchor outside its bounds, for one). Errors name the
/// element.
fn consistent_anchors(
    catalogue: &Catalogue,
    entry: usize,
    index: usize,
    b: &SpringBounds,
    errors: &mut Vec<String>,
) {
    let Element::Spring { axes_a, axes_b, .. } = &catalogue.entries[entry].element else {
        return;
    };
    let label = &catalogue.entries[entry].label;
    let path = format!("balancing.overrides[{index}]");
    for (name, bx, axes, dist) in [
        ("anchor_a", &b.box_a, axes_a, b.anchor_a),
        ("anchor_b", &b.box_b, axes_b, b.anchor_b),
    ] {
        for (k, r) in bx.iter().enumerate() {
            if !axes.contains(&k) && (r[0] > 0.0 || r[1] < 0.0) {
                errors.push(format!(
                    "{path}.{name}: {label}'s anchors lie in a plane where the {} \
                     coordinate is 0, outside its box [{}, {}]",
                    ["x", "y", "z"][k],
                    r[0],
                    r[1]
                ));
            }
        }
        // Nearest point of the box to the origin must be within the distance bound.
        let nearest: f64 = bx
            .iter()
            .map(|r| {
                if r[0] > 0.0 {
                    r[0]
                } else if r[1] < 0.0 {
                    -r[1]
                } else {
                    0.0
                }
            })
            .map(|d| d * d)
            .sum::<f64>()
            .sqrt();
        if nearest > dist[1] * (1.0 + 1e-12) {
            errors.push(format!(
                "{path}.{name}: every point of {label}'s {name} box is at least \
                 {nearest} m from the body origin, beyond the bound |{}| ≤ {} m",
                &name[7..],
                dist[1]
            ));
        }
    }
}

/// Labels → entries, for callers that name elements.
pub fn labels(catalogue: &Catalogue) -> BTreeMap<String, usize> {
    catalogue
        .entries
        .iter()
        .enumerate()
        .map(|(k, e)| (e.label.clone(), k))
        .collect()
}
