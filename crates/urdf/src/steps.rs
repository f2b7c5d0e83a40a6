//! URDF placements and joint motions as case pose steps, and the same transforms numerically.
//!
//! **Exactness rule.** A constant angle within [`SNAP`] of a multiple of π/2 is written as that
//! multiple (`"pi/2"`, `"-pi"`, `"3*pi/2"`), and its cosine and sine are taken as exactly 0 or ±1
//! in the numeric transforms, so that a URDF whose rotations are quarter turns yields an exact
//! case. Any other angle is written as the decimal read from the file (or as `atan2(y, x)` of
//! the axis components for the rotation that carries z onto a joint axis), and the balance
//! search then decides the case numerically.

use nalgebra::{Matrix3, Rotation3, Vector3};
use serde_json::{Value, json};

use crate::parse::Origin;

/// Distance to a multiple of π/2 below which an angle is taken as that multiple.
pub const SNAP: f64 = 1e-9;

/// The multiple `k` of π/2 that `angle` is within [`SNAP`] of.
pub fn quarter_turns(angle: f64) -> Option<i64> {
    let k = (angle / std::f64::consts::FRAC_PI_2).round();
    ((angle - k * std::f64::consts::FRAC_PI_2).abs() <= SNAP).then_some(k as i64)
}

/// `k·π/2` in the expression language.
fn quarter_text(k: i64) -> String {
    match k {
        0 => "0".into(),
        1 => "pi/2".into(),
        -1 => "-pi/2".into(),
        2 => "pi".into(),
        -2 => "-pi".into(),
        k if k % 2 == 0 => format!("{}*pi", k / 2),
        k => format!("{k}*pi/2"),
    }
}

/// A number as the shortest decimal that reads back as the same double.
pub fn decimal(x: f64) -> String {
    if x == 0.0 { "0".into() } else { format!("{x}") }
}

/// A constant angle: a decimal, or the angle of the vector `(x, y)` (`atan2(y, x)`), times a sign.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ConstAngle {
    Decimal(f64),
    Atan2 { y: f64, x: f64, sign: f64 },
}

impl ConstAngle {
    pub fn value(self) -> f64 {
        match self {
            ConstAngle::Decimal(a) => a,
            ConstAngle::Atan2 { y, x, sign } => sign * y.atan2(x),
        }
    }

    pub fn negated(self) -> ConstAngle {
        match self {
            ConstAngle::Decimal(a) => ConstAngle::Decimal(-a),
            ConstAngle::Atan2 { y, x, sign } => ConstAngle::Atan2 { y, x, sign: -sign },
        }
    }

    /// Whether the angle is (snapped to) zero.
    pub fn is_zero(self) -> bool {
        quarter_turns(self.value()) == Some(0)
    }

    /// Cosine and sine, exact for snapped multiples of π/2.
    pub fn cos_sin(self) -> (f64, f64) {
        match quarter_turns(self.value()) {
            Some(k) => match k.rem_euclid(4) {
                0 => (1.0, 0.0),
                1 => (0.0, 1.0),
                2 => (-1.0, 0.0),
                _ => (0.0, -1.0),
            },
            None => (self.value().cos(), self.value().sin()),
        }
    }

    /// The angle as a term of an expression (without a leading `+`).
    fn text(self) -> String {
        if let Some(k) = quarter_turns(self.value()) {
            return quarter_text(k);
        }
        match self {
            ConstAngle::Decimal(a) => decimal(a),
            ConstAngle::Atan2 { y, x, sign } => {
                let call = format!("atan2({}, {})", decimal(y), decimal(x));
                if sign < 0.0 { format!("-{call}") } else { call }
            }
        }
    }

    pub fn to_json(self) -> Value {
        match (quarter_turns(self.value()), self) {
            (None, ConstAngle::Decimal(a)) => json!(a),
            (Some(0), _) => json!(0),
            _ => json!(self.text()),
        }
    }
}

/// An angle `k·q + c` of one chart coordinate `q` (integer `k`) plus a constant.
#[derive(Clone, Debug, PartialEq)]
pub struct AngleExpr {
    pub coordinate: String,
    pub factor: i64,
    pub offset: ConstAngle,
}

impl AngleExpr {
    pub fn negated(&self) -> AngleExpr {
        AngleExpr {
            coordinate: self.coordinate.clone(),
            factor: -self.factor,
            offset: self.offset.negated(),
        }
    }

    pub fn to_json(&self) -> Value {
        let mut text = match self.factor {
            1 => self.coordinate.clone(),
            -1 => format!("-{}", self.coordinate),
            k => format!("{k}*{}", self.coordinate),
        };
        if !self.offset.is_zero() {
            let c = self.offset.text();
            match c.strip_prefix('-') {
                Some(rest) => text.push_str(&format!(" - {rest}")),
                None => text.push_str(&format!(" + {c}")),
            }
        }
        json!(text)
    }
}

/// A length `f·q + c` of one length coordinate.
#[derive(Clone, Debug, PartialEq)]
pub struct LengthExpr {
    pub coordinate: String,
    pub factor: f64,
    pub offset: f64,
}

impl LengthExpr {
    /// `scale · (f·q + c)` as an expression.
    fn scaled(&self, scale: f64) -> Value {
        let (f, c) = (self.factor * scale, self.offset * scale);
        if f == 0.0 {
            return json!(c);
        }
        let mut text = if f == 1.0 {
            self.coordinate.clone()
        } else if f == -1.0 {
            format!("-{}", self.coordinate)
        } else {
            format!("{}*{}", decimal(f), self.coordinate)
        };
        if c > 0.0 {
            text.push_str(&format!(" + {}", decimal(c)));
        } else if c < 0.0 {
            text.push_str(&format!(" - {}", decimal(-c)));
        }
        json!(text)
    }
}

/// The rotation about the x, y or z axis by a constant angle.
pub fn rotation(axis: usize, angle: ConstAngle) -> Matrix3<f64> {
    let (c, s) = angle.cos_sin();
    match axis {
        0 => Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c),
        1 => Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c),
        _ => Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0),
    }
}

const ROT_KEYS: [&str; 3] = ["rot_x", "rot_y", "rot_z"];

fn rot_step(axis: usize, angle: Value) -> Value {
    json!({ ROT_KEYS[axis]: angle })
}

/// A rigid transform kept both as pose steps and numerically (rotation, translation).
#[derive(Clone, Debug, PartialEq)]
pub struct Placement {
    pub steps: Vec<Value>,
    pub rotation: Matrix3<f64>,
    pub translation: Vector3<f64>,
}

impl Placement {
    pub fn identity() -> Placement {
        Placement {
            steps: Vec::new(),
            rotation: Matrix3::identity(),
            translation: Vector3::zeros(),
        }
    }

    /// `self · other`.
    pub fn then(&self, other: &Placement) -> Placement {
        let mut steps = self.steps.clone();
        steps.extend(other.steps.iter().cloned());
        Placement {
            steps,
            rotation: self.rotation * other.rotation,
            translation: self.translation + self.rotation * other.translation,
        }
    }

    /// A point given in the placed frame, in the frame the placement is expressed in.
    pub fn apply(&self, p: &Vector3<f64>) -> Vector3<f64> {
        self.rotation * p + self.translation
    }

    fn translate(v: [f64; 3]) -> Placement {
        Placement {
            steps: if v == [0.0; 3] {
                Vec::new()
            } else {
                vec![json!({ "translate": v })]
            },
            rotation: Matrix3::identity(),
            translation: Vector3::from(v),
        }
    }

    fn rotate(axis: usize, angle: ConstAngle) -> Placement {
        Placement {
            steps: if angle.is_zero() {
                Vec::new()
            } else {
                vec![rot_step(axis, angle.to_json())]
            },
            rotation: rotation(axis, angle),
            translation: Vector3::zeros(),
        }
    }
}

/// `<origin xyz rpy>`: translate, then `Rz(yaw)·Ry(pitch)·Rx(roll)`.
pub fn origin(o: &Origin) -> Placement {
    let [roll, pitch, yaw] = o.rpy;
    Placement::translate(o.xyz)
        .then(&Placement::rotate(2, ConstAngle::Decimal(yaw)))
        .then(&Placement::rotate(1, ConstAngle::Decimal(pitch)))
        .then(&Placement::rotate(0, ConstAngle::Decimal(roll)))
}

/// The axis direction as a unit vector (the written vector when it already is one, so that its
/// decimals stay as written).
pub fn unit_axis(axis: [f64; 3]) -> Vector3<f64> {
    let v = Vector3::from(axis);
    let n = v.norm();
    if n == 1.0 { v } else { v / n }
}

/// The coordinate axis (`0..3`) and sign of an axis along x, y or z.
fn principal(axis: [f64; 3]) -> Option<(usize, f64)> {
    let nonzero: Vec<usize> = (0..3).filter(|&i| axis[i] != 0.0).collect();
    match nonzero.as_slice() {
        [i] => Some((*i, axis[*i].signum())),
        _ => None,
    }
}

/// The steps of a rotation by `angle` about `axis` (joint frame). Along x, y or z it is one
/// step; otherwise `Rz(φ)·Ry(θ)` carries z onto the axis, then `Rz(angle)`, then back.
pub fn revolute_steps(axis: [f64; 3], angle: &AngleExpr) -> Vec<Value> {
    if let Some((i, sign)) = principal(axis) {
        let a = if sign > 0.0 {
            angle.clone()
        } else {
            angle.negated()
        };
        return vec![rot_step(i, a.to_json())];
    }
    let [x, y, z] = axis;
    let phi = ConstAngle::Atan2 { y, x, sign: 1.0 };
    let theta = ConstAngle::Atan2 {
        y: (x * x + y * y).sqrt(),
        x: z,
        sign: 1.0,
    };
    let mut steps = Vec::new();
    steps.extend(Placement::rotate(2, phi).steps);
    steps.extend(Placement::rotate(1, theta).steps);
    steps.push(rot_step(2, angle.to_json()));
    steps.extend(Placement::rotate(1, theta.negated()).steps);
    steps.extend(Placement::rotate(2, phi.negated()).steps);
    steps
}

/// The step of a slide by `length` along `axis` (joint frame).
pub fn prismatic_steps(axis: [f64; 3], length: &LengthExpr) -> Vec<Value> {
    let u = unit_axis(axis);
    let parts: Vec<Value> = (0..3).map(|i| length.scaled(u[i])).collect();
    vec![json!({ "translate": parts })]
}

/// A joint frozen at a constant value, numerically only (the links beyond a frozen joint are
/// merged into a body, never posed by steps): rotation about or slide along the unit axis.
pub fn frozen_motion(axis: [f64; 3], angular: bool, value: f64) -> Placement {
    let u = unit_axis(axis);
    let (rotation, translation) = if angular {
        let r = Rotation3::from_axis_angle(&nalgebra::Unit::new_unchecked(u), value);
        (*r.matrix(), Vector3::zeros())
    } else {
        (Matrix3::identity(), u * value)
    };
    Placement {
        steps: Vec::new(),
        rotation,
        translation,
    }
}
