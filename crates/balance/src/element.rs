//! The catalogue of balancing elements and their lifted energy basis.
//!
//! Each element's potential energy is linear in its *lifted* parameters (docs/design.md §3):
//!
//! - counterweight on body i, mass m at r: `V = −m g·p_i − g·R_i μ` with `μ = m r`;
//! - zero-free-length spring of stiffness K from anchor a on body i to anchor b on body s (or the
//!   base): `V = (K/2)|d|² + αᵀR_iᵀd − βᵀR_sᵀd − ⟨W, R_iᵀR_s⟩ + const`, with `d = p_i − p_s`,
//!   `α = K a`, `β = K b`, `W = K a bᵀ`.
//!
//! So the catalogue computes, once per element, one trigonometric polynomial per lifted variable
//! (the energy per unit of that variable). A variant's energy is then a linear combination of
//! these polynomials, whatever the variant.

pub use counterpoise_model::Plane;
use counterpoise_symbolic::{Mat3, Poly, Scalar, TrigPoly, Vec3};
use serde::Serialize;

use crate::energy::MechanismEnergy;

/// Body-frame axes spanning a plane (all three when unrestricted).
pub fn plane_axes(plane: Option<Plane>) -> Vec<usize> {
    plane.map_or_else(|| vec![0, 1, 2], |p| p.axes().to_vec())
}

/// Where a spring's second anchor sits.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase", tag = "kind", content = "index")]
pub enum Attachment {
    Base,
    Body(usize),
}

/// One balancing element that a variant may install.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "type", rename_all = "lowercase")]
pub enum Element {
    /// A counterweight rigidly attached to a body, offset `r` restricted to `axes`.
    Counterweight { body: usize, axes: Vec<usize> },
    /// A zero-free-length spring from `body` (anchor a on `axes_a`) to `other` (anchor b on
    /// `axes_b`).
    Spring {
        body: usize,
        other: Attachment,
        axes_a: Vec<usize>,
        axes_b: Vec<usize>,
    },
}

/// Options that decide which elements exist (paper Eqs. 27–29, A6–A7).
#[derive(Clone, Debug, Default)]
pub struct CatalogueOptions {
    /// Bodies that may carry a counterweight, in order.
    pub counterweight_bodies: Vec<usize>,
    pub counterweight_plane: Option<Plane>,
    /// Spring pairs `(i, s)` in catalogue order: anchor a on body `i`, anchor b on `s`.
    pub spring_pairs: Vec<(usize, Attachment)>,
    pub spring_plane: Option<Plane>,
}

/// An element with its lifted variables and their energy polynomials.
#[derive(Clone, Debug)]
pub struct CatalogueEntry {
    pub element: Element,
    /// Short label used in tables: `m4` (counterweight on the 4th listed body), `K43`, `K40`.
    pub label: String,
    /// Human name: `counterweight on upper_arm`, `spring upper_arm–slider_v`.
    pub description: String,
    /// Body names: the counterweight's body, or the spring's two (`base` for the ground), as
    /// the element's physical parameters name them.
    pub bodies: Vec<String>,
    /// Names of the lifted variables, e.g. `m4`, `m4·r4x`, `K43`, `K43·a43x`, `K43·a43x·b43y`.
    pub variables: Vec<String>,
    /// Energy per unit of each lifted variable (J per unit).
    pub energy: Vec<TrigPoly>,
}

/// Every element the case allows, with its lifted energy basis.
#[derive(Clone, Debug)]
pub struct Catalogue {
    pub entries: Vec<CatalogueEntry>,
}

const AXIS: [&str; 3] = ["x", "y", "z"];

impl Catalogue {
    /// Builds the catalogue: counterweights in body order, then springs in pair order.
    ///
    /// Labels use 1-based positions in the body list of `energy` (the case's member numbering):
    /// `m4`, `K43` (spring between members 4 and 3), `K40` (member 4 to the base).
    pub fn build(energy: &MechanismEnergy, options: &CatalogueOptions) -> Catalogue {
        let mut entries = Vec::new();
        let cw_axes = plane_axes(options.counterweight_plane);
        for &body in &options.counterweight_bodies {
            entries.push(counterweight(energy, body, &cw_axes));
        }
        let spring_axes = plane_axes(options.spring_plane);
        for &(i, other) in &options.spring_pairs {
            entries.push(spring(energy, i, other, &spring_axes));
        }
        Catalogue { entries }
    }

    pub fn len(&self) -> usize {
        self.entries.len()
    }

    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// Number of counterweights and of springs (paper Eqs. A6, A7).
    pub fn counts(&self) -> (usize, usize) {
        let cw = self
            .entries
            .iter()
            .filter(|e| matches!(e.element, Element::Counterweight { .. }))
            .count();
        (cw, self.entries.len() - cw)
    }
}

/// Energy per unit of each lifted variable of a counterweight on a body with world pose
/// `(rotation, origin)`: `V = −m g·p − g·R μ`, so `[−g·p, −g·R e_k for k in axes]`.
///
/// Generic over the field so that the exact decision and the numeric stages use one formula.
pub fn counterweight_energy<C: Scalar>(
    gravity: &[C; 3],
    rotation: &Mat3<C>,
    origin: &Vec3<C>,
    axes: &[usize],
) -> Vec<Poly<C>> {
    let minus_g = gravity.clone().map(|g| g.neg_ref());
    let mut polys = vec![origin.dot_const(minus_g.clone())];
    for &axis in axes {
        polys.push(rotation.column(axis).dot_const(minus_g.clone()));
    }
    polys
}

/// Energy per unit of each lifted variable of a zero-free-length spring from body `i` (pose
/// `frame`) to `other` (the base when `None`): with `d = p_i − p_s`,
/// `[½|d|², R_i e_k·d, −R_s e_l·d, −R_i e_k·R_s e_l]` for `K`, `K a_k`, `K b_l`, `K a_k b_l`.
pub fn spring_energy<C: Scalar>(
    frame: (&Mat3<C>, &Vec3<C>),
    other: Option<(&Mat3<C>, &Vec3<C>)>,
    axes: &[usize],
) -> Vec<Poly<C>> {
    let (rotation, origin) = frame;
    let identity = Mat3::identity();
    let zero = Vec3::zero();
    let (other_rotation, other_origin) = other.unwrap_or((&identity, &zero));
    let d = origin.sub(other_origin);
    let mut polys = vec![d.dot(&d).scale(C::from_ratio(1, 2))];
    for &k in axes {
        polys.push(rotation.column(k).dot(&d));
    }
    for &l in axes {
        polys.push(-other_rotation.column(l).dot(&d));
    }
    for &k in axes {
        for &l in axes {
            polys.push(-rotation.column(k).dot(&other_rotation.column(l)));
        }
    }
    polys
}

fn counterweight(energy: &MechanismEnergy, body: usize, axes: &[usize]) -> CatalogueEntry {
    let frame = &energy.bodies[body];
    let n = body + 1;
    let mut variables = vec![format!("m{n}")];
    for &axis in axes {
        variables.push(format!("m{n}·r{n}{}", AXIS[axis]));
    }
    let polys = counterweight_energy(&energy.gravity, &frame.rotation, &frame.origin, axes);
    CatalogueEntry {
        element: Element::Counterweight {
            body,
            axes: axes.to_vec(),
        },
        label: format!("m{n}"),
        description: format!("counterweight on {}", frame.name),
        bodies: vec![frame.name.clone()],
        variables,
        energy: polys.into_iter().map(clean).collect(),
    }
}

fn spring(
    energy: &MechanismEnergy,
    body: usize,
    other: Attachment,
    axes: &[usize],
) -> CatalogueEntry {
    let frame = &energy.bodies[body];
    let (other_frame, other_number, other_name) = match other {
        Attachment::Base => (None, 0, counterpoise_vocabulary::BASE.to_string()),
        Attachment::Body(s) => {
            let f = &energy.bodies[s];
            (Some((&f.rotation, &f.origin)), s + 1, f.name.clone())
        }
    };
    // `K43`; with ten or more members the numbers need a separator: `K10,3`.
    let label = if body + 1 >= 10 || other_number >= 10 {
        format!("K{},{}", body + 1, other_number)
    } else {
        format!("K{}{}", body + 1, other_number)
    };
    let mut variables = vec![label.clone()];
    for &k in axes {
        variables.push(format!("{label}·a{}", AXIS[k]));
    }
    for &l in axes {
        variables.push(format!("{label}·b{}", AXIS[l]));
    }
    for &k in axes {
        for &l in axes {
            variables.push(format!("{label}·a{}·b{}", AXIS[k], AXIS[l]));
        }
    }
    let polys = spring_energy((&frame.rotation, &frame.origin), other_frame, axes);
    CatalogueEntry {
        element: Element::Spring {
            body,
            other,
            axes_a: axes.to_vec(),
            axes_b: axes.to_vec(),
        },
        label,
        description: format!("spring {}–{}", frame.name, other_name),
        bodies: vec![frame.name.clone(), other_name],
        variables,
        energy: polys.into_iter().map(clean).collect(),
    }
}

/// Drops the rounding residue of symbolic cancellations (coefficients below 1e-12 J are far
/// below anything a case can mean) so that the coefficient pattern is exact.
fn clean(mut p: TrigPoly) -> TrigPoly {
    p.prune(1e-12);
    p
}
