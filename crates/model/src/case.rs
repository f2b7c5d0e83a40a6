//! The case file as written: serde types that mirror the JSON one to one.
//!
//! These types only check the *shape* of the file (field names, types, array lengths); every
//! semantic rule (names resolve, masses are non-negative, joints agree, …) lives in
//! [`crate::validate`], which turns a [`Case`] into a [`crate::Model`]. Keeping the raw form
//! separate lets a results file echo the case exactly as the designer wrote it.
//!
//! Unknown fields are errors: a misspelt optional field would otherwise be silently ignored,
//! which is the worst kind of modelling error. [`Case::parse`] reports every one of them (the
//! nested types ignore them and [`serde_ignored`] lists them) together with every shape error
//! of every section and list element, each with its line and column (module `reader`).

use std::fmt;
use std::marker::PhantomData;

use serde::de::{self, Deserializer, MapAccess, SeqAccess, Visitor};
use serde::ser::{SerializeMap, Serializer};
use serde::{Deserialize, Serialize};

/// A case-language expression: a string such as `"d2 + d1*sin(th2)"`, or a plain number.
#[derive(Clone, Debug, PartialEq)]
pub enum Expr {
    Number(f64),
    Text(String),
}

impl Expr {
    /// The expression as source text (a number is printed in its shortest exact form).
    pub fn source(&self) -> String {
        match self {
            Expr::Number(x) => format!("{x}"),
            Expr::Text(s) => s.clone(),
        }
    }
}

impl From<f64> for Expr {
    fn from(x: f64) -> Self {
        Expr::Number(x)
    }
}

impl From<&str> for Expr {
    fn from(s: &str) -> Self {
        Expr::Text(s.to_string())
    }
}

impl Serialize for Expr {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        match self {
            Expr::Number(x) => serializer.serialize_f64(*x),
            Expr::Text(s) => serializer.serialize_str(s),
        }
    }
}

impl<'de> Deserialize<'de> for Expr {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct ExprVisitor;
        impl Visitor<'_> for ExprVisitor {
            type Value = Expr;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("an expression (a string such as \"d1*cos(th2)\" or a number)")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Expr, E> {
                Ok(Expr::Number(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Expr, E> {
                Ok(Expr::Number(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Expr, E> {
                Ok(Expr::Number(v as f64))
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Expr, E> {
                Ok(Expr::Text(v.to_string()))
            }
            fn visit_string<E: de::Error>(self, v: String) -> Result<Expr, E> {
                Ok(Expr::Text(v))
            }
        }
        deserializer.deserialize_any(ExprVisitor)
    }
}

/// A JSON object from names to values that keeps the file order and refuses duplicate keys
/// (a plain map would silently keep the last of two `"d1"` entries).
#[derive(Clone, Debug, PartialEq)]
pub struct NamedMap<V>(pub Vec<(String, V)>);

impl<V> Default for NamedMap<V> {
    fn default() -> Self {
        NamedMap(Vec::new())
    }
}

impl<V> NamedMap<V> {
    pub fn get(&self, name: &str) -> Option<&V> {
        self.0.iter().find(|(n, _)| n == name).map(|(_, v)| v)
    }

    pub fn iter(&self) -> impl Iterator<Item = (&str, &V)> {
        self.0.iter().map(|(n, v)| (n.as_str(), v))
    }

    pub fn len(&self) -> usize {
        self.0.len()
    }

    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

impl<V: Serialize> Serialize for NamedMap<V> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut map = serializer.serialize_map(Some(self.0.len()))?;
        for (k, v) in &self.0 {
            map.serialize_entry(k, v)?;
        }
        map.end()
    }
}

impl<'de, V: Deserialize<'de>> Deserialize<'de> for NamedMap<V> {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct MapVisitor<V>(PhantomData<V>);
        impl<'de, V: Deserialize<'de>> Visitor<'de> for MapVisitor<V> {
            type Value = NamedMap<V>;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("an object")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut access: A) -> Result<Self::Value, A::Error> {
                let mut entries: Vec<(String, V)> = Vec::new();
                let mut seen = std::collections::HashSet::new();
                while let Some(key) = access.next_key::<String>()? {
                    if !seen.insert(key.clone()) {
                        // Fail inside the value so that the error's path ends with the key.
                        access.next_value_seed(Duplicate(key))?;
                        unreachable!("a duplicate key always fails");
                    }
                    let value = access.next_value::<V>()?;
                    entries.push((key, value));
                }
                Ok(NamedMap(entries))
            }
        }
        deserializer.deserialize_map(MapVisitor(PhantomData))
    }
}

/// Consumes the value of a repeated key and fails with a "duplicate key" error.
struct Duplicate(String);

impl<'de> de::DeserializeSeed<'de> for Duplicate {
    type Value = ();

    fn deserialize<D: Deserializer<'de>>(self, deserializer: D) -> Result<Self::Value, D::Error> {
        de::IgnoredAny::deserialize(deserializer)?;
        Err(de::Error::custom(format!("duplicate key `{}`", self.0)))
    }
}

/// `"all"` or an explicit list of body names.
#[derive(Clone, Debug, PartialEq)]
pub enum Selection {
    All,
    Names(Vec<String>),
}

impl Serialize for Selection {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        match self {
            Selection::All => serializer.serialize_str("all"),
            Selection::Names(names) => names.serialize(serializer),
        }
    }
}

impl<'de> Deserialize<'de> for Selection {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct SelectionVisitor;
        impl<'de> Visitor<'de> for SelectionVisitor {
            type Value = Selection;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("\"all\" or an array of body names")
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Selection, E> {
                if v == "all" {
                    Ok(Selection::All)
                } else {
                    Err(E::invalid_value(de::Unexpected::Str(v), &self))
                }
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Selection, A::Error> {
                let mut names = Vec::new();
                while let Some(name) = seq.next_element::<String>()? {
                    names.push(name);
                }
                Ok(Selection::Names(names))
            }
        }
        deserializer.deserialize_any(SelectionVisitor)
    }
}

/// The whole case file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Case {
    pub name: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub description: Option<String>,
    /// Gravitational acceleration in the base frame, m/s².
    pub gravity: [f64; 3],
    #[serde(default)]
    pub parameters: NamedMap<f64>,
    pub coordinates: Vec<CoordinateSpec>,
    pub bodies: Vec<BodySpec>,
    #[serde(default)]
    pub payloads: Vec<PayloadSpec>,
    #[serde(default)]
    pub joints: Vec<JointSpec>,
    pub actuators: Vec<ActuatorSpec>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub balancing: Option<BalancingSpec>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tasks: Option<TasksSpec>,
    #[serde(default)]
    pub paths: Vec<PathSpec>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum CoordinateKindSpec {
    Angle,
    Length,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CoordinateSpec {
    pub name: String,
    pub kind: CoordinateKindSpec,
    pub range: [f64; 2],
}

/// One step of a body pose; the steps of a body are composed left to right.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PoseStep {
    Translate([Expr; 3]),
    RotX(Expr),
    RotY(Expr),
    RotZ(Expr),
    Dh(DhStep),
}

/// Standard Denavit–Hartenberg parameters: `Rz(theta)·Tz(d)·Tx(a)·Rx(alpha)`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DhStep {
    pub d: Expr,
    pub theta: Expr,
    pub a: Expr,
    pub alpha: Expr,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BodySpec {
    pub name: String,
    /// Reference frame of the pose: `"base"` or another body.
    pub parent: String,
    #[serde(default)]
    pub pose: Vec<PoseStep>,
    pub mass: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub com: Option<[Expr; 3]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inertia: Option<[f64; 6]>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PayloadSpec {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    pub body: String,
    pub mass: f64,
    pub com: [Expr; 3],
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inertia: Option<[f64; 6]>,
    #[serde(default)]
    pub in_balance: bool,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum JointKindSpec {
    Revolute,
    Prismatic,
    Spherical,
    Universal,
    Fixed,
    Orientation,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct JointSpec {
    pub name: String,
    pub kind: JointKindSpec,
    pub bodies: [String; 2],
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub point: Option<[Expr; 3]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis: Option<[Expr; 3]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis2: Option<[Expr; 3]>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ActuatorSpec {
    pub name: String,
    pub joint: String,
    pub coordinate: Expr,
    pub ratio: f64,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PlaneSpec {
    Xy,
    Yz,
    Xz,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BalancingSpec {
    pub dmax: u32,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub counterweights: Option<CounterweightSpec>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub springs: Option<SpringSpec>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bounds: Option<BoundsSpec>,
    #[serde(default)]
    pub peak_limits: NamedMap<f64>,
    /// Reserved for per-element overrides; kept verbatim until its format is defined.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub overrides: Vec<serde_json::Value>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CounterweightSpec {
    pub bodies: Selection,
    #[serde(default)]
    pub plane: Option<PlaneSpec>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape: Option<ShapeSpec>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ShapeSpec {
    Cylinder(CylinderSpec),
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CylinderSpec {
    pub radius_to_thickness: f64,
    pub density: f64,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SpringSpec {
    pub bodies: Selection,
    #[serde(default)]
    pub include_base: bool,
    #[serde(default)]
    pub plane: Option<PlaneSpec>,
}

#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
pub struct BoundsSpec {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mass: Option<[f64; 2]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius: Option<[f64; 2]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stiffness: Option<[f64; 2]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub anchor_a: Option<[f64; 2]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub anchor_b: Option<[f64; 2]>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PairsSpec {
    #[default]
    All,
    Ordered,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LawSpec {
    #[default]
    Quintic,
}

fn default_samples() -> u32 {
    51
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TasksSpec {
    /// Actuator name → `[from, to, n]`.
    pub grid: NamedMap<[f64; 3]>,
    #[serde(default)]
    pub pairs: PairsSpec,
    #[serde(default)]
    pub law: LawSpec,
    pub duration: f64,
    #[serde(default = "default_samples")]
    pub samples: u32,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PathSpec {
    pub name: String,
    /// Waypoint name → actuator values in actuator order.
    pub waypoints: NamedMap<Vec<f64>>,
    pub sequence: Vec<String>,
    pub durations: Vec<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub payload: Option<PathPayloadSpec>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PathPayloadSpec {
    pub body: String,
    pub mass: f64,
    pub com: [Expr; 3],
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inertia: Option<[f64; 6]>,
    pub pick_at: String,
    pub drop_at: String,
}
