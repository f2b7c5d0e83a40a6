//! The balancing section: which bodies take counterweights and springs, their planes and
//! bounds.

use std::collections::HashMap;

use super::magnitudes::*;
use super::validator::*;
use crate::case::{BalancingSpec, Case, PlaneSpec, Selection, ShapeSpec};
use crate::limits::Limit;
use crate::model::{
    Balancing, Bounds, CounterweightOptions, CounterweightShape, Plane, SpringOptions,
};
use crate::reader::too_large;

/// Resolves a body selection to ascending body indices.
pub(super) fn selection(
    v: &mut Validator,
    case: &Case,
    selection: &Selection,
    path: &str,
    base_hint: &str,
) -> Option<Vec<usize>> {
    match selection {
        Selection::All => Some((0..case.bodies.len()).collect()),
        Selection::Names(names) => {
            let mut out = Vec::new();
            let mut ok = true;
            let mut seen = HashMap::new();
            for (k, name) in names.iter().enumerate() {
                let item = format!("{path}[{k}]");
                if name == "base" {
                    v.invalid(&item, base_hint);
                    ok = false;
                } else if let Some(i) = case.bodies.iter().position(|b| b.name == *name) {
                    if v.unique(&mut seen, name, item, "body") {
                        out.push(i);
                    }
                } else {
                    v.unknown(item, "body", name);
                    ok = false;
                }
            }
            out.sort_unstable();
            ok.then_some(out)
        }
    }
}

pub(super) fn plane(p: Option<PlaneSpec>) -> Option<Plane> {
    p.map(|p| match p {
        PlaneSpec::Xy => Plane::Xy,
        PlaneSpec::Yz => Plane::Yz,
        PlaneSpec::Xz => Plane::Xz,
    })
}

pub(super) fn balancing(
    v: &mut Validator,
    b: &BalancingSpec,
    case: &Case,
    actuator_index: &dyn Fn(&str) -> Option<usize>,
) -> Option<Balancing> {
    let start = v.errors.len();
    if b.dmax < 1 {
        v.invalid("balancing.dmax", "must be an integer ≥ 1");
    } else if u64::from(b.dmax) > v.limits.dmax {
        v.push(too_large(
            "balancing.dmax",
            "elements per variant",
            f64::from(b.dmax),
            Limit::Dmax,
            v.limits.dmax,
        ));
    }
    let counterweights = b.counterweights.as_ref().and_then(|c| {
        let bodies = selection(
            v,
            case,
            &c.bodies,
            "balancing.counterweights.bodies",
            "the base cannot carry a counterweight",
        );
        let shape = c.shape.as_ref().map(|ShapeSpec::Cylinder(cyl)| {
            v.positive_at_most(
                cyl.radius_to_thickness,
                1e3,
                "balancing.counterweights.shape.cylinder.radius_to_thickness",
                "",
            );
            v.positive_at_most(
                cyl.density,
                MAX_DENSITY,
                "balancing.counterweights.shape.cylinder.density",
                "kg/m³",
            );
            CounterweightShape::Cylinder {
                radius_to_thickness: cyl.radius_to_thickness,
                density: cyl.density,
            }
        });
        Some(CounterweightOptions {
            bodies: bodies?,
            plane: plane(c.plane),
            shape,
        })
    });
    let springs = b.springs.as_ref().and_then(|s| {
        let bodies = selection(
            v,
            case,
            &s.bodies,
            "balancing.springs.bodies",
            "list moving bodies only; set include_base for springs to the base",
        );
        Some(SpringOptions {
            bodies: bodies?,
            include_base: s.include_base,
            plane: plane(s.plane),
        })
    });
    let defaults = Bounds::default();
    let spec = b.bounds.clone().unwrap_or_default();
    let mut bound = |value: Option<[f64; 2]>, default: [f64; 2], name: &str, max, unit| match value
    {
        Some(x) => v
            .interval(x, max, unit, &format!("balancing.bounds.{name}"))
            .unwrap_or(default),
        None => default,
    };
    let bounds = Bounds {
        mass: bound(spec.mass, defaults.mass, "mass", MAX_MASS, "kg"),
        radius: bound(spec.radius, defaults.radius, "radius", MAX_LENGTH, "m"),
        stiffness: bound(
            spec.stiffness,
            defaults.stiffness,
            "stiffness",
            MAX_STIFFNESS,
            "N/m",
        ),
        anchor_a: bound(
            spec.anchor_a,
            defaults.anchor_a,
            "anchor_a",
            MAX_LENGTH,
            "m",
        ),
        anchor_b: bound(
            spec.anchor_b,
            defaults.anchor_b,
            "anchor_b",
            MAX_LENGTH,
            "m",
        ),
    };
    let mut peak_limits = vec![None; case.actuators.len()];
    for (name, &limit) in b.peak_limits.iter() {
        let path = format!("balancing.peak_limits.{name}");
        match actuator_index(name) {
            None => v.unknown(&path, "actuator", name),
            Some(k) => {
                if v.positive_at_most(limit, MAX_TORQUE, &path, "N·m") {
                    peak_limits[k] = Some(limit);
                }
            }
        }
    }
    (v.errors.len() == start).then(|| Balancing {
        dmax: b.dmax as usize,
        counterweights,
        springs,
        bounds,
        derived_bounds: [
            ("mass", spec.mass),
            ("radius", spec.radius),
            ("stiffness", spec.stiffness),
            ("anchor_a", spec.anchor_a),
            ("anchor_b", spec.anchor_b),
        ]
        .iter()
        .filter(|(_, given)| given.is_none())
        .map(|(name, _)| *name)
        .collect(),
        peak_limits,
        overrides: b.overrides.clone(),
    })
}
