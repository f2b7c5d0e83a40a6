//! One joint of the case and one actuator's map, read into the model's terms.

use counterpoise_symbolic::{ExprContext, TrigPoly};
use nalgebra::Vector3;

use super::validator::*;
use crate::case::{Expr, JointKindSpec};
use crate::error::ModelError;
use crate::joints::JointInput;
use crate::model::{ActuatorMap, BodyId, JointKind};
use crate::pose::Parser;

/// Checks a joint's fields and returns its geometry in the first body's frame.
pub(super) fn joint(
    v: &mut Validator,
    parser: &Parser,
    body_id: &dyn Fn(&str) -> Option<BodyId>,
    j: &crate::case::JointSpec,
    path: &str,
) -> Option<JointInput> {
    let kind = match j.kind {
        JointKindSpec::Revolute => JointKind::Revolute,
        JointKindSpec::Prismatic => JointKind::Prismatic,
        JointKindSpec::Spherical => JointKind::Spherical,
        JointKindSpec::Universal => JointKind::Universal,
        JointKindSpec::Fixed => JointKind::Fixed,
        JointKindSpec::Orientation => JointKind::Orientation,
    };
    let mut ok = true;
    let mut bodies = [BodyId::Base; 2];
    for (k, name) in j.bodies.iter().enumerate() {
        match body_id(name) {
            Some(id) => bodies[k] = id,
            None => {
                v.unknown(format!("{path}.bodies[{k}]"), "body", name);
                ok = false;
            }
        }
    }
    if ok && bodies[0] == bodies[1] {
        v.invalid(
            format!("{path}.bodies"),
            "a joint must connect two different bodies",
        );
        ok = false;
    }
    let point = match &j.point {
        Some(e) => {
            let point_path = format!("{path}.point");
            let point = parser.constant_vec(e, &point_path, &mut v.errors);
            v.length_vec(point, &point_path)
        }
        None if kind == JointKind::Orientation => Some([0.0; 3]),
        None => {
            v.invalid(
                format!("{path}.point"),
                format!("required for a {} joint", kind.name()),
            );
            None
        }
    };
    let axis = match (&j.axis, kind.has_axis()) {
        (Some(e), true) => v.axis(parser, e, &format!("{path}.axis")),
        (None, true) => {
            v.invalid(
                format!("{path}.axis"),
                format!("required for a {} joint", kind.name()),
            );
            None
        }
        (Some(_), false) => {
            v.invalid(
                format!("{path}.axis"),
                format!("a {} joint has no axis", kind.name()),
            );
            None
        }
        (None, false) => None,
    };
    let axis2 = match (&j.axis2, kind == JointKind::Universal) {
        (Some(e), true) => v.axis(parser, e, &format!("{path}.axis2")),
        (None, true) => {
            v.invalid(format!("{path}.axis2"), "required for a universal joint");
            None
        }
        (Some(_), false) => {
            v.invalid(format!("{path}.axis2"), "only a universal joint has axis2");
            None
        }
        (None, false) => None,
    };
    let axis_ok = !kind.has_axis() || axis.is_some();
    let axis2_ok = kind != JointKind::Universal || axis2.is_some();
    (ok && axis_ok && axis2_ok).then_some(())?;
    Some(JointInput {
        name: j.name.clone(),
        path: path.to_string(),
        kind,
        bodies,
        point: Vector3::from(point?),
        axis,
        axis2,
    })
}

/// An actuated coordinate: a trigonometric polynomial, or else an angle expression (an integer
/// combination of angle coordinates plus a constant, e.g. `th1`).
pub(super) fn actuator_map(
    context: &ExprContext,
    expr: &Expr,
    path: &str,
) -> Result<ActuatorMap, ModelError> {
    let src = match expr {
        Expr::Number(_) => {
            return Err(ModelError::invalid(
                path,
                "an actuated coordinate must depend on the coordinates",
            ));
        }
        Expr::Text(s) => s,
    };
    let map = match context.parse_poly(src) {
        Ok(poly) => ActuatorMap {
            linear: Vec::new(),
            poly,
        },
        Err(poly_error) => match context.parse_angle(src) {
            Ok(angle) => ActuatorMap {
                linear: angle
                    .terms
                    .iter()
                    .map(|&(k, n)| (k, f64::from(n)))
                    .collect(),
                poly: TrigPoly::constant(angle.offset),
            },
            Err(_) => {
                return Err(ModelError::Expression {
                    path: path.to_string(),
                    source: poly_error,
                });
            }
        },
    };
    if map.poly.terms().any(|(_, c)| !c.is_finite()) {
        return Err(ModelError::invalid(path, "expression is not finite"));
    }
    if map.linear.is_empty() && map.poly.is_constant() {
        return Err(ModelError::invalid(
            path,
            "an actuated coordinate must depend on the coordinates",
        ));
    }
    Ok(map)
}
