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
//! with clarabel's dual objective as a certified lower bound. This version covers
//! counterweights only; springs (whose lifted parameters must also satisfy `W = αβᵀ/K`) are
//! not part of the partial search.

pub mod conic;
pub mod counterweights;
pub mod torque;

use rayon::prelude::*;
use serde::Serialize;

pub use counterweights::CounterweightLimits;
pub use torque::{TorqueBasis, Workspace};

use crate::element::{Catalogue, Element};
use crate::enumerate::variants;
use crate::realize::CounterweightParams;

/// What went wrong before any set was solved.
#[derive(Debug, thiserror::Error)]
pub enum PartialError {
    #[error("no joint selected")]
    NoJoints,
    #[error("joint index {0} is out of range ({1} actuators)")]
    JointOutOfRange(usize, usize),
    #[error("no workspace point where the actuator Jacobian is regular")]
    NoPoints,
    #[error("the catalogue has no counterweight (partial balancing covers counterweights only)")]
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
}

impl PartialOptions {
    /// The lightest design with the least residual on `joints`.
    pub fn new(budget: usize, joints: Vec<usize>) -> PartialOptions {
        PartialOptions {
            budget,
            joints,
            lightest: true,
        }
    }
}

/// The best design of one set of elements.
#[derive(Clone, Debug, Serialize)]
pub struct PartialDesign {
    /// Catalogue entries, ascending.
    pub entries: Vec<usize>,
    pub labels: Vec<String>,
    /// The design; a counterweight of (numerically) zero mass is listed with offset 0.
    pub counterweights: Vec<CounterweightParams>,
    /// Labels of elements the optimum leaves at zero mass: the set is really a smaller one.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub unused: Vec<String>,
    /// RMS gravity torque of every actuator over the workspace with this design (N·m or N).
    pub rms: Vec<f64>,
    /// `√(Σ RMS_j²)` over the selected joints.
    pub total_rms: f64,
    /// A certified lower bound on `total_rms` over every design of this set within the bounds.
    pub lower_bound: f64,
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

/// A mass below this fraction of the mass bound counts as no counterweight.
const UNUSED_MASS: f64 = 1e-6;

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

/// The number of sets [`partial_search`] solves: `Σ_{d ≤ budget} C(counterweights, d)`.
pub fn set_count(catalogue: &Catalogue, budget: usize) -> u128 {
    let n = counterweight_entries(catalogue).len() as u64;
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

/// Solves every set of at most `budget` counterweights for the least RMS gravity torque on
/// the selected joints within `limits` (per catalogue entry; springs' are ignored).
pub fn partial_search(
    catalogue: &Catalogue,
    basis: &TorqueBasis,
    limits: &[Option<CounterweightLimits>],
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
    let candidates: Vec<usize> = counterweight_entries(catalogue)
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
    let sets: Vec<Vec<usize>> = variants(candidates.len(), options.budget).collect();
    let mut designs: Vec<(usize, PartialDesign)> = sets
        .par_iter()
        .enumerate()
        .map(|(order, set)| {
            let design = solve_set(
                catalogue,
                basis,
                limits,
                options,
                &quad,
                &columns,
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
        unbalanced_total: total(&unbalanced_rms, &options.joints),
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

/// The best design of one set: the sub-quadratic of its columns, solved; the residual
/// recomputed from the torque columns (not from the quadratic, which loses the digits of a
/// near-perfect balance to cancellation).
fn solve_set(
    catalogue: &Catalogue,
    basis: &TorqueBasis,
    limits: &[Option<CounterweightLimits>],
    options: &PartialOptions,
    quad: &counterweights::Quadratic,
    columns: &[&[f64]],
    set: impl Iterator<Item = (usize, usize)>,
) -> PartialDesign {
    let set: Vec<(usize, usize)> = set.collect();
    // The set's columns, in order, and its blocks over them.
    let mut picked = Vec::new();
    let mut blocks = Vec::new();
    for &(entry, first) in &set {
        let vars = basis.entries[entry].len();
        let base = picked.len();
        picked.extend(first..first + vars);
        blocks.push(counterweights::Block {
            mass: base,
            moment: (base + 1..base + vars).collect(),
            limits: limits[entry].expect("candidates have bounds"),
        });
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
    let mut solution = counterweights::solve(&sub, &blocks, options.lightest);
    // A counterweight left at (numerically) zero mass is not built: its lifted parameters are
    // zeroed, so the residual below is the one of the design as reported.
    let mut params = Vec::new();
    let mut unused = Vec::new();
    for (&(entry, _), block) in set.iter().zip(&blocks) {
        let Element::Counterweight { body, ref axes } = catalogue.entries[entry].element else {
            unreachable!("only counterweights are candidates");
        };
        let mass = solution.x[block.mass];
        let mut offset = [0.0; 3];
        if block.limits.mass[1] > 0.0 && mass > UNUSED_MASS * block.limits.mass[1] {
            for (&axis, &col) in axes.iter().zip(&block.moment) {
                offset[axis] = solution.x[col] / mass;
            }
            params.push(CounterweightParams {
                entry,
                body,
                mass,
                offset,
            });
        } else {
            unused.push(catalogue.entries[entry].label.clone());
            for &col in std::iter::once(&block.mass).chain(&block.moment) {
                solution.x[col] = 0.0;
            }
            params.push(CounterweightParams {
                entry,
                body,
                mass: 0.0,
                offset,
            });
        }
    }
    let cols: Vec<&[f64]> = picked.iter().map(|&i| columns[i]).collect();
    let rms = basis.rms(&cols, &solution.x);
    PartialDesign {
        entries: set.iter().map(|&(e, _)| e).collect(),
        labels: set
            .iter()
            .map(|&(e, _)| catalogue.entries[e].label.clone())
            .collect(),
        counterweights: params,
        unused,
        total_rms: total(&rms, &options.joints),
        rms,
        lower_bound: solution.lower_bound.sqrt(),
        status: solution.status,
        note: solution.note,
    }
}
