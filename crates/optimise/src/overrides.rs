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
                }),
            })
            .collect();
        let mut errors = Vec::new();
        for (i, value) in balancing.overrides.iter().enumerate() {
            apply(model, catalogue, &mut entries, i, value, &mut errors);
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
) {
    let path = format!("balancing.overrides[{i}]");
    let Some(object) = value.as_object() else {
        errors.push(format!(
            "{path}: expected an object like {{\"element\": \"m4\", \"radius\": [0.2, 0.2]}}"
        ));
        return;
    };
    let Some(element) = object.get("element") else {
        errors.push(format!(
            "{path}.element: missing (which element the override applies to)"
        ));
        return;
    };
    let entry = match resolve(model, catalogue, element) {
        Ok(k) => k,
        Err(e) => {
            errors.push(format!("{path}.element: {e}"));
            return;
        }
    };
    for (key, v) in object {
        if key == "element" {
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
            (ElementBounds::Counterweight(_), _) => errors.push(format!(
                "{path}.{key}: unknown field for a counterweight (expected mass, radius)"
            )),
            (ElementBounds::Spring(_), _) => errors.push(format!(
                "{path}.{key}: unknown field for a spring (expected stiffness, anchor_a, anchor_b)"
            )),
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
