//! The mechanism in exact rational arithmetic, for the balance decision.
//!
//! Every number of a case file is read as the decimal the designer wrote (the shortest decimal
//! that rounds to the double serde produced; see [`counterpoise_symbolic::decimal_to_rational`]).
//! Rotations stay exact when their constant part is a multiple of π/2 or a rational rotation
//! `atan2(y, x)` with a rational hypotenuse. The poses are lowered by the same generic code as
//! the numeric model ([`crate::pose::Parser`]), so the two cannot disagree on a formula; where a
//! constant is irrational (`rot_z: 0.3`, `d1*pi`), [`exact_mechanism`] says why and the caller
//! decides numerically.

use std::collections::BTreeMap;

use counterpoise_symbolic::{Context, Field, Mat3, Poly, Rational, Surd, VarKind, Vec3};

use crate::case::Expr;
use crate::model::{BodyId, Model};
use crate::pose::{Parser, SymbolicPose};

/// One body's exact world pose: `x_world = origin + rotation · x_body`.
#[derive(Clone, Debug, PartialEq)]
pub struct ExactFrame<F = Rational> {
    pub rotation: Mat3<F>,
    pub origin: Vec3<F>,
}

/// What the exact balance decision needs: gravity, every body's pose and the unbalanced energy,
/// all with coefficients in the exact field `F` (ℚ, or ℚ(√2, √3) for rotations by multiples of
/// π/12).
#[derive(Clone, Debug, PartialEq)]
pub struct ExactMechanism<F = Rational> {
    pub gravity: [F; 3],
    /// In the model's body order.
    pub bodies: Vec<ExactFrame<F>>,
    /// Gravitational potential of the bodies and the payloads marked `in_balance` (J).
    pub unbalanced: Poly<F>,
}

/// The mechanism over ℚ(√2, √3): for cases whose rotations are multiples of π/12 (π/6, π/4
/// and their sums), which ℚ refuses.
pub type SurdMechanism = ExactMechanism<Surd>;

/// Why a case cannot be taken exactly: the field and the reason.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{path}: {reason}")]
pub struct NotExact {
    pub path: String,
    pub reason: String,
}

fn not_exact(path: impl Into<String>, reason: impl Into<String>) -> NotExact {
    NotExact {
        path: path.into(),
        reason: reason.into(),
    }
}

fn literal<F: Field>(x: f64, path: &str) -> Result<F, NotExact> {
    let constant = F::literal(x).map_err(|r| not_exact(path, r))?;
    F::to_scalar(&constant).map_err(|r| not_exact(path, r))
}

/// Builds the exact mechanism of a validated model over ℚ, or says which field prevents it.
pub fn exact_mechanism(model: &Model) -> Result<ExactMechanism, NotExact> {
    exact_mechanism_in::<Rational>(model)
}

/// Builds the exact mechanism over the field `F`, or says which field of the case prevents it.
pub fn exact_mechanism_in<F: Field>(model: &Model) -> Result<ExactMechanism<F>, NotExact> {
    let case = &model.case;
    let mut parameters = BTreeMap::new();
    for (name, value) in case.parameters.iter() {
        let constant =
            F::literal(*value).map_err(|r| not_exact(format!("parameters.{name}"), r))?;
        parameters.insert(name.to_string(), constant);
    }
    let coordinates: Vec<(String, VarKind)> = model
        .coordinates
        .iter()
        .map(|c| (c.name.clone(), c.kind))
        .collect();
    let context = Context::<F>::new(parameters, coordinates);
    let parser = Parser { context: &context };

    let first_error = |errors: Vec<crate::ModelError>, path: String| -> NotExact {
        errors.into_iter().next().map_or_else(
            || not_exact(path, "not exact"),
            |e| {
                let path = e.path().to_string();
                let text = e.to_string();
                let reason = text.strip_prefix(&format!("{path}: ")).unwrap_or(&text);
                not_exact(path.clone(), reason.to_string())
            },
        )
    };
    let mut relative = Vec::with_capacity(case.bodies.len());
    for (i, body) in case.bodies.iter().enumerate() {
        let path = format!("bodies[{i}].pose");
        let mut errors = Vec::new();
        let pose = parser.pose(&body.pose, &path, &mut errors);
        relative.push(pose.ok_or_else(|| first_error(errors, path))?);
    }
    let mut world: Vec<Option<SymbolicPose<F>>> = vec![None; case.bodies.len()];
    for i in 0..model.bodies.len() {
        world_pose(model, &relative, &mut world, i);
    }
    let bodies: Vec<ExactFrame<F>> = world
        .into_iter()
        .map(|p| {
            let p = p.expect("every body's world pose was composed");
            ExactFrame {
                rotation: p.rotation,
                origin: p.origin,
            }
        })
        .collect();

    let gravity = [
        literal::<F>(case.gravity[0], "gravity[0]")?,
        literal::<F>(case.gravity[1], "gravity[1]")?,
        literal::<F>(case.gravity[2], "gravity[2]")?,
    ];
    let point = |exprs: &[Expr; 3], path: &str| -> Result<[F; 3], NotExact> {
        let mut errors = Vec::new();
        let constants = parser
            .constant_vec(exprs, path, &mut errors)
            .ok_or_else(|| first_error(errors, path.to_string()))?;
        let mut out: [F; 3] = Default::default();
        for (k, c) in constants.iter().enumerate() {
            out[k] = F::to_scalar(c).map_err(|r| not_exact(format!("{path}[{k}]"), r))?;
        }
        Ok(out)
    };
    let mut unbalanced = Poly::<F>::zero();
    for (i, body) in case.bodies.iter().enumerate() {
        if body.mass == 0.0 {
            continue;
        }
        let path = format!("bodies[{i}]");
        let mass = literal::<F>(body.mass, &format!("{path}.mass"))?;
        let com = match &body.com {
            Some(com) => point(com, &format!("{path}.com"))?,
            None => Default::default(),
        };
        unbalanced += &gravity_potential(&bodies[i], &gravity, &mass, com);
    }
    for (j, payload) in case.payloads.iter().enumerate() {
        if !payload.in_balance || payload.mass == 0.0 {
            continue;
        }
        let path = format!("payloads[{j}]");
        let body = model.payloads[j].body;
        let mass = literal::<F>(payload.mass, &format!("{path}.mass"))?;
        let com = point(&payload.com, &format!("{path}.com"))?;
        unbalanced += &gravity_potential(&bodies[body], &gravity, &mass, com);
    }
    Ok(ExactMechanism {
        gravity,
        bodies,
        unbalanced,
    })
}

/// `−m g·(p + R c)`: the potential of mass `m` at `c` in the frame's body axes.
fn gravity_potential<F: Field>(
    frame: &ExactFrame<F>,
    gravity: &[F; 3],
    mass: &F,
    com: [F; 3],
) -> Poly<F> {
    let world = frame.origin.add(&frame.rotation.mul_const_vec(com));
    world.dot_const(gravity.clone()).scale(mass.neg_ref())
}

/// Composes body `i`'s world pose from its parent's (memoised; the parent relation is acyclic
/// in a validated model).
fn world_pose<F: Field>(
    model: &Model,
    relative: &[SymbolicPose<F>],
    world: &mut Vec<Option<SymbolicPose<F>>>,
    i: usize,
) -> SymbolicPose<F> {
    if let Some(pose) = &world[i] {
        return pose.clone();
    }
    let pose = match model.bodies[i].parent {
        BodyId::Base => relative[i].clone(),
        BodyId::Body(p) => world_pose(model, relative, world, p).compose(&relative[i]),
    };
    world[i] = Some(pose.clone());
    pose
}

impl<F: Field> ExactMechanism<F> {
    /// The exact energy with coefficients rounded to doubles (for comparison with the model).
    pub fn unbalanced_f64(&self) -> counterpoise_symbolic::TrigPoly {
        Poly::to_f64(&self.unbalanced)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use counterpoise_symbolic::{ExactPoly, Monomial};
    use num_bigint::BigInt;

    fn q(n: i64, d: i64) -> Rational {
        Rational::new(BigInt::from(n), BigInt::from(d))
    }

    const PENDULUM: &str = r#"{
        "name": "p", "gravity": [0, -9.81, 0],
        "parameters": { "l": 0.3 },
        "coordinates": [ { "name": "th", "kind": "angle", "range": [-3, 3] } ],
        "bodies": [ { "name": "rod", "parent": "base", "pose": [ { "rot_z": "th - pi/2" } ],
                      "mass": 2, "com": ["4*l/3", 0, 0], "inertia": [0, 0, 0.1, 0, 0, 0] } ],
        "joints": [ { "name": "J1", "kind": "revolute", "bodies": ["base", "rod"],
                      "point": [0, 0, 0], "axis": [0, 0, 1] } ],
        "actuators": [ { "name": "M1", "joint": "J1", "coordinate": "th", "ratio": 1 } ]
    }"#;

    #[test]
    fn pendulum_energy_is_the_hand_calculation() {
        // CoM at R(th − π/2)·(0.4, 0): y_c = −0.4 cos th, and with gravity (0, −9.81, 0)
        // V = m·9.81·y_c = 2 · 9.81 · (−0.4) cos th = −7.848 cos th = −981/125 cos th.
        let model = crate::Case::from_json_str(PENDULUM).unwrap();
        let exact = exact_mechanism(&model).unwrap();
        let mut expected = ExactPoly::zero();
        expected.add_term(Monomial::base(0), q(-981, 125));
        assert_eq!(exact.unbalanced, expected);
        // The numeric model agrees to rounding.
        let numeric = model.potential_energy(crate::PayloadMode::InBalance);
        assert!(numeric.approx_eq(&exact.unbalanced_f64(), 1e-15));
    }

    #[test]
    fn irrational_rotation_names_the_field() {
        let text = PENDULUM.replace("th - pi/2", "th - 0.3");
        let model = crate::Case::from_json_str(&text).unwrap();
        let err = exact_mechanism(&model).unwrap_err();
        assert_eq!(err.path, "bodies[0].pose[0].rot_z");
        assert!(err.reason.contains("irrational"), "{err}");
    }

    #[test]
    fn rational_rotation_by_atan2_is_exact() {
        // rot_z(th + atan2(4, 3)), CoM 5 along x: y = 5 sin(th + φ) with cos φ = 3/5,
        // sin φ = 4/5, so y = 5 (sin th · 3/5 + cos th · 4/5) = 3 sin th + 4 cos th.
        let text = PENDULUM
            .replace("th - pi/2", "th + atan2(4, 3)")
            .replace("\"4*l/3\", 0, 0", "5, 0, 0");
        let model = crate::Case::from_json_str(&text).unwrap();
        let exact = exact_mechanism(&model).unwrap();
        // V = m g y = 2 · 9.81 · (3 sin th + 4 cos th).
        let mut expected = ExactPoly::zero();
        expected.add_term(Monomial::sine(0), q(2 * 981 * 3, 100));
        expected.add_term(Monomial::base(0), q(2 * 981 * 4, 100));
        assert_eq!(exact.unbalanced, expected);
    }

    #[test]
    fn a_twelfth_turn_is_exact_over_the_surd_field_only() {
        // rot_z(th + 2π/3), CoM 2 along x: y = 2 sin(th + 120°) = 2(sin th·(−1/2) + cos th·√3/2)
        // = −sin th + √3 cos th, so V = m g y = 2·9.81·(−sin th + √3 cos th).
        let text = PENDULUM
            .replace("th - pi/2", "th + 2*pi/3")
            .replace("\"4*l/3\", 0, 0", "2, 0, 0");
        let model = crate::Case::from_json_str(&text).unwrap();
        let err = exact_mechanism(&model).unwrap_err();
        assert!(err.reason.contains("π/2"), "{err}");
        let exact = exact_mechanism_in::<Surd>(&model).unwrap();
        let g2 = q(2 * 981, 100);
        let mut expected = Poly::<Surd>::zero();
        expected.add_term(Monomial::sine(0), Surd::from_rational(-g2.clone()));
        expected.add_term(Monomial::base(0), &Surd::sqrt3() * &Surd::from_rational(g2));
        assert_eq!(exact.unbalanced, expected);
        // 0.3 rad is in neither field.
        let text = PENDULUM.replace("th - pi/2", "th + 0.3");
        let model = crate::Case::from_json_str(&text).unwrap();
        let err = exact_mechanism_in::<Surd>(&model).unwrap_err();
        assert_eq!(err.path, "bodies[0].pose[0].rot_z");
        assert!(err.reason.contains("pi/12"), "{err}");
    }
}
