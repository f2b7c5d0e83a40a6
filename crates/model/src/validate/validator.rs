//! The collector of problems that every section of the validation writes to.
//!
//! The validator keeps going after a problem so that all of them are reported at once; this is
//! the state it carries (the errors so far and the limits) and its elementary checks (finite,
//! bounded, positive, named), shared by the sections in the sibling modules.

use std::collections::HashMap;

use nalgebra::{Matrix3, Vector3};

use super::magnitudes::*;
use crate::case::Expr;
use crate::error::ModelError;
use crate::inertia::{EIGEN_MAX_ITERATIONS, principal_moments};
use crate::limits::{Limit, Limits};
use crate::pose::Parser;
use crate::reader::too_large;

/// Names the expression language reserves.
pub(super) const RESERVED: [&str; 3] = ["pi", "cos", "sin"];

pub(super) fn is_identifier(name: &str) -> bool {
    let mut chars = name.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

pub(super) struct Validator {
    pub(super) errors: Vec<ModelError>,
    pub(super) limits: Limits,
}

impl Validator {
    /// Checks `|value| ≤ max` (the value is already known finite or reported).
    pub(super) fn magnitude(&mut self, value: f64, max: f64, path: &str, unit: &str) -> bool {
        let unit = if unit.is_empty() {
            String::new()
        } else {
            format!(" {unit}")
        };
        if value.abs() > max {
            self.invalid(
                path,
                format!(
                    "{}{unit} is beyond the supported magnitude ±{}{unit}",
                    num(value),
                    num(max)
                ),
            );
            return false;
        }
        true
    }

    /// Every entry finite and within `±max`.
    pub(super) fn bounded(&mut self, values: &[f64], max: f64, path: &str, unit: &str) -> bool {
        let mut ok = true;
        for (k, &v) in values.iter().enumerate() {
            let item = format!("{path}[{k}]");
            if !v.is_finite() {
                self.invalid(item, format!("{v} is not a finite number"));
                ok = false;
            } else {
                ok &= self.magnitude(v, max, &item, unit);
            }
        }
        ok
    }

    /// A duration within [`DURATION_RANGE`].
    pub(super) fn duration(&mut self, value: f64, path: &str) -> bool {
        let [lo, hi] = DURATION_RANGE;
        if !(value.is_finite() && (lo..=hi).contains(&value)) {
            self.invalid(
                path,
                format!(
                    "must be a duration between {lo} and {hi} s (found {})",
                    num(value)
                ),
            );
            return false;
        }
        true
    }

    /// A list no longer than the list limit.
    pub(super) fn list_size(&mut self, len: usize, path: &str) -> bool {
        if len as u64 > self.limits.list_items {
            self.push(too_large(
                path,
                "entries",
                len as f64,
                Limit::ListItems,
                self.limits.list_items,
            ));
            return false;
        }
        true
    }

    pub(super) fn push(&mut self, error: ModelError) {
        self.errors.push(error);
    }

    pub(super) fn invalid(&mut self, path: impl Into<String>, reason: impl Into<String>) {
        self.errors.push(ModelError::invalid(path, reason));
    }

    pub(super) fn unknown(&mut self, path: impl Into<String>, what: &'static str, name: &str) {
        self.errors.push(ModelError::UnknownName {
            path: path.into(),
            what,
            name: name.to_string(),
        });
    }

    /// Records a name in `seen`, reporting a duplicate; returns whether it was new.
    pub(super) fn unique(
        &mut self,
        seen: &mut HashMap<String, String>,
        name: &str,
        path: String,
        what: &'static str,
    ) -> bool {
        if let Some(first) = seen.get(name) {
            self.push(ModelError::Duplicate {
                path,
                what,
                name: name.to_string(),
                first: first.clone(),
            });
            false
        } else {
            seen.insert(name.to_string(), path);
            true
        }
    }

    pub(super) fn name(&mut self, name: &str, path: &str) {
        if name.trim().is_empty() {
            self.invalid(path, "must not be empty");
        }
    }

    pub(super) fn finite(&mut self, values: &[f64], path: &str) -> bool {
        let mut ok = true;
        for (k, v) in values.iter().enumerate() {
            if !v.is_finite() {
                self.invalid(
                    format!("{path}[{k}]"),
                    format!("{v} is not a finite number"),
                );
                ok = false;
            }
        }
        ok
    }

    pub(super) fn positive(&mut self, value: f64, path: &str) -> bool {
        if !(value.is_finite() && value > 0.0) {
            self.invalid(
                path,
                format!("must be a finite number > 0 (found {})", num(value)),
            );
            return false;
        }
        true
    }

    /// `0 < value ≤ max`.
    pub(super) fn positive_at_most(
        &mut self,
        value: f64,
        max: f64,
        path: &str,
        unit: &str,
    ) -> bool {
        self.positive(value, path) && self.magnitude(value, max, path, unit)
    }

    pub(super) fn non_negative(&mut self, value: f64, path: &str) -> bool {
        if !(value.is_finite() && value >= 0.0) {
            self.invalid(
                path,
                format!("must be a finite number ≥ 0 (found {})", num(value)),
            );
            return false;
        }
        true
    }

    /// `0 ≤ value ≤ max`.
    pub(super) fn non_negative_at_most(
        &mut self,
        value: f64,
        max: f64,
        path: &str,
        unit: &str,
    ) -> bool {
        self.non_negative(value, path) && self.magnitude(value, max, path, unit)
    }

    /// A constant vector of lengths within [`MAX_LENGTH`].
    pub(super) fn length_vec(&mut self, value: Option<[f64; 3]>, path: &str) -> Option<[f64; 3]> {
        let value = value?;
        self.bounded(&value, MAX_LENGTH, path, "m").then_some(value)
    }

    /// The inertia tensor from `[Ixx, Iyy, Izz, Ixy, Ixz, Iyz]`, checked positive semi-definite.
    pub(super) fn inertia(&mut self, v: &[f64; 6], path: &str) -> Option<Matrix3<f64>> {
        if !self.bounded(v, MAX_INERTIA, path, "kg·m²") {
            return None;
        }
        let [ixx, iyy, izz, ixy, ixz, iyz] = *v;
        let m = Matrix3::new(ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz);
        let Some(eigenvalues) = principal_moments(&m) else {
            self.invalid(
                path,
                format!(
                    "the principal moments of this inertia could not be computed in {EIGEN_MAX_ITERATIONS} iterations"
                ),
            );
            return None;
        };
        let trace = m.trace();
        if eigenvalues.iter().any(|&e| e < -1e-9 * trace.abs()) {
            let mut e: Vec<f64> = eigenvalues.iter().copied().collect();
            e.sort_by(f64::total_cmp);
            self.invalid(
                path,
                format!(
                    "inertia is not positive semi-definite (principal moments {:.6}, {:.6}, {:.6} kg·m²)",
                    e[0], e[1], e[2]
                ),
            );
            return None;
        }
        Some(m)
    }

    /// A unit axis from a constant 3-vector, checked by its norm (its components are only
    /// known finite): a zero vector, a norm below [`MIN_AXIS_NORM`] (it underflows, or is too
    /// short to give a direction) or one that overflows is an error naming the field.
    pub(super) fn axis(
        &mut self,
        parser: &Parser,
        exprs: &[Expr; 3],
        path: &str,
    ) -> Option<Vector3<f64>> {
        let v = Vector3::from(parser.constant_vec(exprs, path, &mut self.errors)?);
        match unit_direction(&v) {
            Ok(unit) => Some(unit),
            Err(reason) => {
                self.invalid(path, reason);
                None
            }
        }
    }

    pub(super) fn interval(
        &mut self,
        v: [f64; 2],
        max: f64,
        unit: &str,
        path: &str,
    ) -> Option<[f64; 2]> {
        if !self.bounded(&v, max, path, unit) {
            return None;
        }
        if v[0] < 0.0 || v[0] > v[1] {
            self.invalid(
                path,
                format!(
                    "must be [lo, hi] with 0 ≤ lo ≤ hi (found [{}, {}])",
                    v[0], v[1]
                ),
            );
            return None;
        }
        Some(v)
    }
}
