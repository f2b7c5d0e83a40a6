//! Reading the URDF XML into plain structures (no tree logic yet).
//!
//! Only what the static and dynamic model needs is read: links with their `<inertial>`, joints
//! with `type`, `<parent>`, `<child>`, `<origin>`, `<axis>`, `<limit>` and `<mimic>`. Visual and
//! collision geometry, transmissions and Gazebo tags are ignored.

use crate::error::UrdfError;

/// A rigid placement `<origin xyz="…" rpy="…">`; both default to zero.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Origin {
    pub xyz: [f64; 3],
    /// Roll, pitch, yaw: the rotation `Rz(yaw)·Ry(pitch)·Rx(roll)`.
    pub rpy: [f64; 3],
}

/// `<inertial>`: mass and inertia about the centre of mass in the inertial frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inertial {
    pub origin: Origin,
    pub mass: f64,
    /// `[ixx, iyy, izz, ixy, ixz, iyz]`.
    pub inertia: [f64; 6],
}

#[derive(Clone, Debug, PartialEq)]
pub struct Link {
    pub name: String,
    /// `None`: the URDF gives no `<inertial>` (a massless link).
    pub inertial: Option<Inertial>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JointType {
    Revolute,
    Continuous,
    Prismatic,
    Fixed,
}

impl JointType {
    pub fn name(self) -> &'static str {
        match self {
            JointType::Revolute => "revolute",
            JointType::Continuous => "continuous",
            JointType::Prismatic => "prismatic",
            JointType::Fixed => "fixed",
        }
    }

    /// Whether the joint value is an angle.
    pub fn is_angular(self) -> bool {
        matches!(self, JointType::Revolute | JointType::Continuous)
    }
}

/// `<limit lower upper effort>`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limit {
    pub lower: f64,
    pub upper: f64,
    pub effort: Option<f64>,
}

/// `<mimic joint multiplier offset>`: `value = multiplier · value(joint) + offset`.
#[derive(Clone, Debug, PartialEq)]
pub struct Mimic {
    pub joint: String,
    pub multiplier: f64,
    pub offset: f64,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Joint {
    pub name: String,
    pub kind: JointType,
    pub parent: String,
    pub child: String,
    pub origin: Origin,
    /// As written (not normalised), default `[1, 0, 0]`; non-zero.
    pub axis: [f64; 3],
    pub limit: Option<Limit>,
    pub mimic: Option<Mimic>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Robot {
    pub name: String,
    pub links: Vec<Link>,
    pub joints: Vec<Joint>,
}

/// Parses URDF text.
pub fn parse(text: &str) -> Result<Robot, UrdfError> {
    let doc = roxmltree::Document::parse(text).map_err(|e| UrdfError::Xml(e.to_string()))?;
    let root = doc.root_element();
    if root.tag_name().name() != "robot" {
        return Err(UrdfError::invalid(
            format!("<{}>", root.tag_name().name()),
            "the root element must be <robot>",
        ));
    }
    let name = root.attribute("name").unwrap_or("robot").to_string();
    let mut links = Vec::new();
    let mut joints = Vec::new();
    for node in root.children().filter(|n| n.is_element()) {
        match node.tag_name().name() {
            "link" => links.push(parse_link(node)?),
            "joint" => joints.push(parse_joint(node)?),
            _ => {}
        }
    }
    if links.is_empty() {
        return Err(UrdfError::invalid("<robot>", "no <link> element"));
    }
    Ok(Robot {
        name,
        links,
        joints,
    })
}

fn required_name(node: roxmltree::Node, what: &str) -> Result<String, UrdfError> {
    match node.attribute("name") {
        Some(n) if !n.is_empty() => Ok(n.to_string()),
        _ => Err(UrdfError::invalid(
            format!("<{what}> at byte {}", node.range().start),
            "missing `name` attribute",
        )),
    }
}

fn child<'a, 'i>(node: roxmltree::Node<'a, 'i>, tag: &str) -> Option<roxmltree::Node<'a, 'i>> {
    node.children()
        .find(|n| n.is_element() && n.tag_name().name() == tag)
}

/// A number attribute; `element` names where it is, for the error.
fn number(node: roxmltree::Node, attr: &str, element: &str) -> Result<Option<f64>, UrdfError> {
    let Some(text) = node.attribute(attr) else {
        return Ok(None);
    };
    let value: f64 = text.trim().parse().map_err(|_| {
        UrdfError::invalid(
            format!("{element}.{attr}"),
            format!("`{text}` is not a number"),
        )
    })?;
    if !value.is_finite() {
        return Err(UrdfError::invalid(
            format!("{element}.{attr}"),
            format!("`{text}` is not finite"),
        ));
    }
    Ok(Some(value))
}

fn triple(node: roxmltree::Node, attr: &str, element: &str) -> Result<Option<[f64; 3]>, UrdfError> {
    let Some(text) = node.attribute(attr) else {
        return Ok(None);
    };
    let parts: Vec<&str> = text.split_whitespace().collect();
    let bad = || {
        UrdfError::invalid(
            format!("{element}.{attr}"),
            format!("`{text}` is not three finite numbers"),
        )
    };
    if parts.len() != 3 {
        return Err(bad());
    }
    let mut out = [0.0; 3];
    for (o, p) in out.iter_mut().zip(&parts) {
        *o = p.parse::<f64>().map_err(|_| bad())?;
        if !o.is_finite() {
            return Err(bad());
        }
    }
    Ok(Some(out))
}

fn parse_origin(node: roxmltree::Node, element: &str) -> Result<Origin, UrdfError> {
    let Some(o) = child(node, "origin") else {
        return Ok(Origin::default());
    };
    let element = format!("{element}.origin");
    Ok(Origin {
        xyz: triple(o, "xyz", &element)?.unwrap_or_default(),
        rpy: triple(o, "rpy", &element)?.unwrap_or_default(),
    })
}

fn parse_link(node: roxmltree::Node) -> Result<Link, UrdfError> {
    let name = required_name(node, "link")?;
    let element = format!("link `{name}`");
    let Some(inertial) = child(node, "inertial") else {
        return Ok(Link {
            name,
            inertial: None,
        });
    };
    let element = format!("{element}.inertial");
    let origin = parse_origin(inertial, &element)?;
    let mass_element = format!("{element}.mass");
    let mass = child(inertial, "mass")
        .map(|m| number(m, "value", &mass_element))
        .transpose()?
        .flatten()
        .ok_or_else(|| UrdfError::invalid(&mass_element, "missing <mass value=…>"))?;
    if mass < 0.0 {
        return Err(UrdfError::invalid(
            format!("{mass_element}.value"),
            format!("negative mass {mass} kg"),
        ));
    }
    let inertia_element = format!("{element}.inertia");
    let node = child(inertial, "inertia");
    let mut inertia = [0.0; 6];
    for (slot, attr) in inertia
        .iter_mut()
        .zip(["ixx", "iyy", "izz", "ixy", "ixz", "iyz"])
    {
        let value = match node {
            Some(n) => number(n, attr, &inertia_element)?,
            None => None,
        };
        *slot = match value {
            Some(v) => v,
            // A point mass may omit <inertia>; a partial <inertia> is a mistake.
            None if node.is_none() => 0.0,
            None => {
                return Err(UrdfError::invalid(
                    format!("{inertia_element}.{attr}"),
                    "missing",
                ));
            }
        };
    }
    Ok(Link {
        name,
        inertial: Some(Inertial {
            origin,
            mass,
            inertia,
        }),
    })
}

fn parse_joint(node: roxmltree::Node) -> Result<Joint, UrdfError> {
    let name = required_name(node, "joint")?;
    let element = format!("joint `{name}`");
    let kind_text = node.attribute("type").unwrap_or("");
    let kind = match kind_text {
        "revolute" => JointType::Revolute,
        "continuous" => JointType::Continuous,
        "prismatic" => JointType::Prismatic,
        "fixed" => JointType::Fixed,
        "floating" | "planar" => {
            return Err(UrdfError::invalid(
                format!("{element}.type"),
                format!(
                    "`{kind_text}` joints are not supported (only revolute, continuous, prismatic and fixed)"
                ),
            ));
        }
        other => {
            return Err(UrdfError::invalid(
                format!("{element}.type"),
                format!("unknown joint type `{other}`"),
            ));
        }
    };
    let link_of = |tag: &str| -> Result<String, UrdfError> {
        child(node, tag)
            .and_then(|n| n.attribute("link"))
            .map(str::to_string)
            .ok_or_else(|| UrdfError::invalid(format!("{element}.{tag}"), "missing <{tag} link=…>"))
    };
    let parent = link_of("parent")?;
    let child_link = link_of("child")?;
    let origin = parse_origin(node, &element)?;
    let axis_element = format!("{element}.axis");
    let axis = child(node, "axis")
        .map(|a| triple(a, "xyz", &axis_element))
        .transpose()?
        .flatten()
        .unwrap_or([1.0, 0.0, 0.0]);
    // Checked by its norm, not only its components: a norm that overflows or underflows
    // would normalise to zeros or NaN.
    if kind != JointType::Fixed
        && let Err(reason) =
            counterpoise_model::validate::unit_direction(&nalgebra::Vector3::from(axis))
    {
        return Err(UrdfError::invalid(format!("{axis_element}.xyz"), reason));
    }
    let limit_element = format!("{element}.limit");
    let limit = match child(node, "limit") {
        None => None,
        Some(l) => {
            let lower = number(l, "lower", &limit_element)?.unwrap_or(0.0);
            let upper = number(l, "upper", &limit_element)?.unwrap_or(0.0);
            let effort = number(l, "effort", &limit_element)?;
            Some(Limit {
                lower,
                upper,
                effort,
            })
        }
    };
    let mimic_element = format!("{element}.mimic");
    let mimic = match child(node, "mimic") {
        None => None,
        Some(m) => Some(Mimic {
            joint: m
                .attribute("joint")
                .map(str::to_string)
                .ok_or_else(|| UrdfError::invalid(&mimic_element, "missing `joint` attribute"))?,
            multiplier: number(m, "multiplier", &mimic_element)?.unwrap_or(1.0),
            offset: number(m, "offset", &mimic_element)?.unwrap_or(0.0),
        }),
    };
    Ok(Joint {
        name,
        kind,
        parent,
        child: child_link,
        origin,
        axis,
        limit,
        mimic,
    })
}
