//! Partial balancing: when no small set balances a mechanism exactly, the sets of at most a
//! budget of elements, with parameters within the bounds, that leave the least gravity torque.
//!
//! The measure is the RMS over the workspace sample points of the static actuator torques
//! (`Q_u = G⁻ᵀ ∂V/∂q`, before the motor ratio) of the joints the user names, summed in
//! squares: `total = √(Σ_j RMS_j²)` — the plain sum, so the joints that carry the most gravity
//! torque (the shoulder and elbow of an arm) weigh the most, as they do for the motors. Every
//! joint's RMS is reported, named or not.
//!
//! The energy, hence the torque, is linear in the lifted parameters ([`torque`]); for
//! counterweights the bounds are convex in them too, so each set's optimum is a convex
//! quadratic program ([`counterweights`]): its answer is the global optimum within the bounds,
//! with clarabel's dual objective as a certified lower bound. A spring's lifted parameters must
//! also satisfy `W = K·a·bᵀ`, which is not convex; a set with springs is solved by alternating
//! convex programs with one anchor of every spring fixed, from several starts, and bounded
//! below by a convex relaxation ([`springs`]): its design is realisable and within the bounds,
//! and is called certified optimal only when it meets the bound within [`CERTIFY`] of the
//! unbalanced torque.

pub mod conic;
pub mod counterweights;
pub mod springs;
pub mod torque;

use rayon::prelude::*;
use serde::Serialize;

pub use counterweights::CounterweightLimits;
pub use torque::{TorqueBasis, Workspace};

use crate::element::{Catalogue, Element};
use crate::enumerate::variants;
use crate::realize::{Counterweight, Spring};

/// What went wrong before any set was solved.
#[derive(Debug, thiserror::Error)]
pub enum PartialError {
    #[error("no joint selected")]
    NoJoints,
    #[error("joint index {0} is out of range ({1} actuators)")]
    JointOutOfRange(usize, usize),
    #[error("no workspace point where the actuator Jacobian is regular")]
    NoPoints,
    #[error("the catalogue has no counterweight or spring with bounds to search")]
    NoCounterweights,
    #[error("budget must be at least 1")]
    ZeroBudget,
    #[error("{0} bounds given for {1} catalogue entries")]
    BoundsLength(usize, usize),
}

/// What to search.
#[derive(Clone, Debug)]
pub struct PartialOptions {
    /// Most elements per set.
    pub budget: usize,
    /// Actuator indices whose torque is minimised.
    pub joints: Vec<usize>,
    /// Of the designs with the least residual, take the lightest (otherwise whichever the
    /// solver ends at).
    pub lightest: bool,
    /// Sets drawn from the springs of the catalogue too (otherwise counterweights only).
    pub springs: bool,
}

impl PartialOptions {
    /// The lightest design with the least residual on `joints`, from counterweights and
    /// springs.
    pub fn new(budget: usize, joints: Vec<usize>) -> PartialOptions {
        PartialOptions {
            budget,
            joints,
            lightest: true,
            springs: true,
        }
    }
}

/// Bounds of one spring (the case's `balancing.bounds` with its overrides).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SpringLimits {
    /// N/m.
    pub stiffness: [f64; 2],
    /// |a|, m.
    pub anchor_a: [f64; 2],
    /// |b|, m.
    pub anchor_b: [f64; 2],
    /// Per body-frame axis (x, y, z) of anchor a, `[lo, hi]` in m (infinite when free).
    pub box_a: [[f64; 2]; 3],
    /// The same for anchor b, in the frame of the other body (or the base).
    pub box_b: [[f64; 2]; 3],
}

/// Bounds of one catalogue entry.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ElementLimits {
    Counterweight(CounterweightLimits),
    Spring(SpringLimits),
}

/// A spring of a design: its physical parameters and the share of the balancing it does.
#[derive(Clone, Debug, Serialize)]
pub struct PartialSpring {
    #[serde(flatten)]
    pub spring: Spring,
    /// RMS over the workspace of the torque this spring alone exerts, `√(Σ RMS_j²)` over the
    /// selected joints (N·m or N): how much of the balancing it does.
    pub torque_rms: f64,
}

/// The best design of one set of elements.
#[derive(Clone, Debug, Serialize)]
pub struct PartialDesign {
    /// Catalogue entries, ascending.
    pub entries: Vec<usize>,
    pub labels: Vec<String>,
    /// The design; a counterweight of (numerically) zero mass is listed with offset 0.
    pub counterweights: Vec<Counterweight>,
    /// The design's springs; one of (numerically) zero stiffness is listed with anchors 0.
    pub springs: Vec<PartialSpring>,
    /// Labels of elements the optimum leaves at zero mass (or stiffness): the set is really a
    /// smaller one.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub unused: Vec<String>,
    /// RMS gravity torque of every actuator over the workspace with this design (N·m or N).
    pub rms: Vec<f64>,
    /// `√(Σ RMS_j²)` over the selected joints.
    pub total_rms: f64,
    /// A certified lower bound on `total_rms` over every design of this set within the bounds
    /// (with springs: the relaxation's).
    pub lower_bound: f64,
    /// `total_rms − lower_bound` (at least 0; `NaN` when the bound failed).
    pub gap: f64,
    /// `gap ≤` [`CERTIFY`] `× unbalanced_total`: no design of the set within the bounds is
    /// better by more than that.
    pub certified: bool,
    /// The solver's status (`Solved`, …).
    pub status: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

/// Every set's best design, best first.
#[derive(Clone, Debug, Serialize)]
pub struct PartialReport {
    pub budget: usize,
    pub joints: Vec<usize>,
    /// Workspace points.
    pub points: usize,
    /// RMS gravity torque of every actuator of the unbalanced mechanism.
    pub unbalanced_rms: Vec<f64>,
    /// `√(Σ RMS_j²)` of the unbalanced mechanism over the selected joints.
    pub unbalanced_total: f64,
    /// Sets solved.
    pub sets: usize,
    /// Ranked: by `total_rms`, then fewer elements, then enumeration order.
    pub designs: Vec<PartialDesign>,
}

/// A mass below this fraction of the mass bound counts as no counterweight (a stiffness below
/// it of the stiffness bound, as no spring).
const UNUSED_MASS: f64 = 1e-6;

/// A design is certified optimal when its total RMS is within this fraction of the unbalanced
/// total of the lower bound: 0.1 % of the torque there was to remove.
pub const CERTIFY: f64 = 1e-3;

/// Spring entries of the catalogue, in catalogue order.
pub fn spring_entries(catalogue: &Catalogue) -> Vec<usize> {
    catalogue
        .entries
        .iter()
        .enumerate()
        .filter(|(_, e)| matches!(e.element, Element::Spring { .. }))
        .map(|(i, _)| i)
        .collect()
}

/// The entries a search draws its sets from: the counterweights, then (with `springs`) the
/// springs, in catalogue order.
pub fn candidate_entries(catalogue: &Catalogue, springs: bool) -> Vec<usize> {
    let mut out = counterweight_entries(catalogue);
    if springs {
        out.extend(spring_entries(catalogue));
    }
    out.sort_unstable();
    out
}

/// Counterweight entries of the catalogue, in catalogue order.
pub fn counterweight_entries(catalogue: &Catalogue) -> Vec<usize> {
    catalogue
        .entries
        .iter()
        .enumerate()
        .filter(|(_, e)| matches!(e.element, Element::Counterweight { .. }))
        .map(|(i, _)| i)
        .collect()
}

/// The number of sets [`partial_search`] solves: `Σ_{d ≤ budget} C(n, d)` over the
/// [`candidate_entries`].
pub fn set_count(catalogue: &Catalogue, budget: usize, springs: bool) -> u128 {
    let n = candidate_entries(catalogue, springs).len() as u64;
    (1..=(budget as u64).min(n))
        .map(|d| crate::enumerate::binomial(n, d))
        .sum()
}

/// `√(Σ_{j ∈ joints} v_j²)`.
fn total(values: &[f64], joints: &[usize]) -> f64 {
    joints
        .iter()
        .map(|&j| values[j] * values[j])
        .sum::<f64>()
        .sqrt()
}

/// Solves every set of at most `budget` elements (counterweights, and springs with
/// `options.springs`) for the least RMS gravity torque on the selected joints within `limits`
/// (per catalogue entry; an entry without limits, or without torque columns in `basis`, is
/// left out).
pub fn partial_search(
    catalogue: &Catalogue,
    basis: &TorqueBasis,
    limits: &[Option<ElementLimits>],
    options: &PartialOptions,
) -> Result<PartialReport, PartialError> {
    if options.budget == 0 {
        return Err(PartialError::ZeroBudget);
    }
    if options.joints.is_empty() {
        return Err(PartialError::NoJoints);
    }
    if let Some(&j) = options.joints.iter().find(|&&j| j >= basis.actuators) {
        return Err(PartialError::JointOutOfRange(j, basis.actuators));
    }
    if basis.points == 0 {
        return Err(PartialError::NoPoints);
    }
    if limits.len() != catalogue.len() {
        return Err(PartialError::BoundsLength(limits.len(), catalogue.len()));
    }
    let candidates: Vec<usize> = candidate_entries(catalogue, options.springs)
        .into_iter()
        .filter(|&e| limits[e].is_some() && !basis.entries[e].is_empty())
        .collect();
    if candidates.is_empty() {
        return Err(PartialError::NoCounterweights);
    }
    // Column layout of the global quadratic: every candidate's variables in turn.
    let mut offset = Vec::with_capacity(candidates.len());
    let mut columns: Vec<&[f64]> = Vec::new();
    for &e in &candidates {
        offset.push(columns.len());
        columns.extend(basis.entries[e].iter().map(Vec::as_slice));
    }
    let quad = gram(basis, &columns, &options.joints);
    let unbalanced_rms = basis.rms(&[], &[]);
    let unbalanced_total = total(&unbalanced_rms, &options.joints);
    let sets: Vec<Vec<usize>> = variants(candidates.len(), options.budget).collect();
    let mut designs: Vec<(usize, PartialDesign)> = sets
        .par_iter()
        .enumerate()
        .map(|(order, set)| {
            let design = solve_set(
                &Context {
                    catalogue,
                    basis,
                    limits,
                    options,
                    quad: &quad,
                    columns: &columns,
                    unbalanced_total,
                },
                set.iter().map(|&i| (candidates[i], offset[i])),
            );
            (order, design)
        })
        .collect();
    designs.sort_by(|(oa, a), (ob, b)| {
        a.total_rms
            .total_cmp(&b.total_rms)
            .then(a.entries.len().cmp(&b.entries.len()))
            .then(oa.cmp(ob))
    });
    Ok(PartialReport {
        budget: options.budget,
        joints: options.joints.clone(),
        points: basis.points,
        unbalanced_total,
        unbalanced_rms,
        sets: sets.len(),
        designs: designs.into_iter().map(|(_, d)| d).collect(),
    })
}

/// `f(x) = Σ_{j ∈ joints} mean_k (τ_UB + Σ columns·x)²` as `xᵀHx + 2gᵀx + c`.
fn gram(basis: &TorqueBasis, columns: &[&[f64]], joints: &[usize]) -> counterweights::Quadratic {
    let p = columns.len();
    let a = basis.actuators;
    let rows: Vec<usize> = (0..basis.points)
        .flat_map(|k| joints.iter().map(move |&j| k * a + j))
        .collect();
    let scale = 1.0 / basis.points as f64;
    let dot = |u: &[f64], v: &[f64]| rows.iter().map(|&r| u[r] * v[r]).sum::<f64>() * scale;
    let mut h = vec![0.0; p * p];
    for i in 0..p {
        for j in i..p {
            let v = dot(columns[i], columns[j]);
            h[i * p + j] = v;
            h[j * p + i] = v;
        }
    }
    let g = columns.iter().map(|c| dot(c, &basis.unbalanced)).collect();
    let c = dot(&basis.unbalanced, &basis.unbalanced);
    counterweights::Quadratic { h, g, c }
}

/// What every set's solve shares.
struct Context<'a> {
    catalogue: &'a Catalogue,
    basis: &'a TorqueBasis,
    limits: &'a [Option<ElementLimits>],
    options: &'a PartialOptions,
    quad: &'a counterweights::Quadratic,
    columns: &'a [&'a [f64]],
    unbalanced_total: f64,
}

/// `range` for the plane axes `axes` of a 3-axis box.
fn box_of(range: &[[f64; 2]; 3], axes: &[usize]) -> Vec<[f64; 2]> {
    axes.iter().map(|&a| range[a]).collect()
}

/// The program's block of one set element whose lifted columns start at `base` (in the set's
/// own column order).
fn block(
    catalogue: &Catalogue,
    entry: usize,
    limits: ElementLimits,
    base: usize,
) -> counterweights::Block {
    match (&catalogue.entries[entry].element, limits) {
        (Element::Spring { axes_a, axes_b, .. }, ElementLimits::Spring(l)) => {
            let (na, nb) = (axes_a.len(), axes_b.len());
            let alpha = base + 1;
            let beta = alpha + na;
            let w = beta + nb;
            counterweights::Block {
                mass: base,
                moment: (alpha..beta).collect(),
                limits: CounterweightLimits {
                    mass: l.stiffness,
                    radius: l.anchor_a,
                },
                boxes: box_of(&l.box_a, axes_a),
                spring: Some(counterweights::SpringColumns {
                    beta: (beta..w).collect(),
                    w: (w..w + na * nb).collect(),
                    anchor_b: l.anchor_b,
                    box_b: box_of(&l.box_b, axes_b),
                }),
            }
        }
        (Element::Counterweight { axes, .. }, ElementLimits::Counterweight(l)) => {
            counterweights::Block {
                mass: base,
                moment: (base + 1..base + 1 + axes.len()).collect(),
                limits: l,
                boxes: Vec::new(),
                spring: None,
            }
        }
        // A limit of the other kind: the entry's own bounds are unknown, so it may not move.
        (element, _) => {
            let vars = match element {
                Element::Counterweight { axes, .. } => axes.len(),
                Element::Spring { axes_a, .. } => axes_a.len(),
            };
            counterweights::Block {
                mass: base,
                moment: (base + 1..base + 1 + vars).collect(),
                limits: CounterweightLimits {
                    mass: [0.0, 0.0],
                    radius: [0.0, 0.0],
                },
                boxes: Vec::new(),
                spring: None,
            }
        }
    }
}

/// `√(Σ_{j ∈ joints} RMS_j²)` of the torque `Σ columns·x` alone (no unbalanced part).
fn torque_alone(basis: &TorqueBasis, columns: &[&[f64]], x: &[f64], joints: &[usize]) -> f64 {
    let a = basis.actuators;
    let mut sum = 0.0;
    for k in 0..basis.points {
        for &j in joints {
            let row = k * a + j;
            let t: f64 = columns.iter().zip(x).map(|(c, xi)| c[row] * xi).sum();
            sum += t * t;
        }
    }
    (sum / basis.points.max(1) as f64).sqrt()
}

/// The best design of one set: the sub-quadratic of its columns, solved (as one convex program
/// for counterweights, by [`springs::solve`] with springs); the residual recomputed from the
/// torque columns (not from the quadratic, which loses the digits of a near-perfect balance to
/// cancellation).
fn solve_set(ctx: &Context, set: impl Iterator<Item = (usize, usize)>) -> PartialDesign {
    let Context {
        catalogue,
        basis,
        limits,
        options,
        quad,
        columns,
        unbalanced_total,
    } = *ctx;
    let set: Vec<(usize, usize)> = set.collect();
    // The set's columns, in order, and its blocks over them.
    let mut picked = Vec::new();
    let mut blocks = Vec::new();
    for &(entry, first) in &set {
        let vars = basis.entries[entry].len();
        let base = picked.len();
        picked.extend(first..first + vars);
        blocks.push(block(
            catalogue,
            entry,
            limits[entry].expect("candidates have bounds"),
            base,
        ));
    }
    let p = quad.g.len();
    let sub = counterweights::Quadratic {
        h: picked
            .iter()
            .flat_map(|&i| picked.iter().map(move |&j| quad.h[i * p + j]))
            .collect(),
        g: picked.iter().map(|&i| quad.g[i]).collect(),
        c: quad.c,
    };
    let (mut x, lower_bound, status, note) = if blocks.iter().any(|b| b.spring.is_some()) {
        let s = springs::solve(&sub, &blocks, options.lightest, CERTIFY * unbalanced_total);
        (s.x, s.lower_bound, s.status, None)
    } else {
        let s = counterweights::solve(&sub, &blocks, options.lightest);
        (s.x, s.lower_bound, s.status, s.note)
    };
    let cols: Vec<&[f64]> = picked.iter().map(|&i| columns[i]).collect();
    // An element left at (numerically) zero mass or stiffness is not built: its lifted
    // parameters are zeroed, so the residual below is the one of the design as reported.
    let mut params = Vec::new();
    let mut spring_params = Vec::new();
    let mut unused = Vec::new();
    for (&(entry, _), block) in set.iter().zip(&blocks) {
        let label = &catalogue.entries[entry].label;
        let scale = x[block.mass];
        let used = block.limits.mass[1] > 0.0 && scale > UNUSED_MASS * block.limits.mass[1];
        let vars = basis.entries[entry].len();
        if !used {
            unused.push(label.clone());
            for v in &mut x[block.mass..block.mass + vars] {
                *v = 0.0;
            }
        }
        match &catalogue.entries[entry].element {
            Element::Counterweight { axes, .. } => {
                let mut offset = [0.0; 3];
                if used {
                    for (&axis, &col) in axes.iter().zip(&block.moment) {
                        offset[axis] = x[col] / scale;
                    }
                }
                params.push(Counterweight {
                    label: label.clone(),
                    body: catalogue.entries[entry].bodies[0].clone(),
                    mass: if used { scale } else { 0.0 },
                    offset,
                    plane: None,
                });
            }
            Element::Spring { axes_a, axes_b, .. } => {
                let (mut anchor_a, mut anchor_b) = ([0.0; 3], [0.0; 3]);
                if used && let Some(s) = &block.spring {
                    for (&axis, &col) in axes_a.iter().zip(&block.moment) {
                        anchor_a[axis] = x[col] / scale;
                    }
                    for (&axis, &col) in axes_b.iter().zip(&s.beta) {
                        anchor_b[axis] = x[col] / scale;
                    }
                }
                let range = block.mass..block.mass + vars;
                let bodies = &catalogue.entries[entry].bodies;
                spring_params.push(PartialSpring {
                    spring: Spring {
                        label: label.clone(),
                        body: bodies[0].clone(),
                        other: bodies[1].clone(),
                        stiffness: if used { scale } else { 0.0 },
                        anchor_a,
                        anchor_b,
                        plane: None,
                    },
                    torque_rms: torque_alone(
                        basis,
                        &cols[range.clone()],
                        &x[range],
                        &options.joints,
                    ),
                });
            }
        }
    }
    let rms = basis.rms(&cols, &x);
    let total_rms = total(&rms, &options.joints);
    // NaN (a failed bound) stays NaN: `f64::max` would make it 0.
    let lower_bound = if lower_bound.is_nan() {
        f64::NAN
    } else {
        lower_bound.max(0.0).sqrt()
    };
    let gap = (total_rms - lower_bound).max(0.0);
    PartialDesign {
        entries: set.iter().map(|&(e, _)| e).collect(),
        labels: set
            .iter()
            .map(|&(e, _)| catalogue.entries[e].label.clone())
            .collect(),
        counterweights: params,
        springs: spring_params,
        unused,
        total_rms,
        rms,
        lower_bound,
        gap,
        certified: gap <= CERTIFY * unbalanced_total,
        status,
        note,
    }
}
