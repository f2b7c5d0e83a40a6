//! Realization: from a lifted solution set to physical parameters (m, r, K, a, b).
//!
//! The only nonlinear step of the balance search. Counterweights are easy — `(m, μ) ↦ (m, μ/m)` is
//! a bijection for `m > 0` — but a spring's lifted variables must satisfy `W = α βᵀ / K` with
//! `K > 0`. So the search is a small nonlinear least-squares problem in physical variables,
//! `A_S x(y) = −b` with `y = (ln m, μ; ln K, a, b)`, solved by Levenberg–Marquardt from a few
//! deterministic starting points. The logarithms keep every mass and stiffness positive.
//!
//! The solver either finds a witness (which the caller then verifies by sampling the energy) or
//! gives up; giving up is reported as `undecided`, never as a proof of impossibility. Proofs come
//! from the linear stage: a mass or stiffness that is the same in every lifted solution and is
//! not positive.

use counterpoise_model::sampling::SplitMix64;

use nalgebra::{DMatrix, DVector};

use crate::element::{CatalogueEntry, Element};
use crate::linear::LinearSolution;

/// Scales that make starting points and witnesses plausible to a designer.
#[derive(Clone, Copy, Debug)]
pub struct RealizationHints {
    /// Typical counterweight mass (kg).
    pub mass: f64,
    /// Typical spring stiffness (N/m).
    pub stiffness: f64,
    /// Typical anchor or offset length (m).
    pub length: f64,
}

/// A witness's masses and stiffnesses must be at least this fraction of the typical scale
/// ([`RealizationHints::mass`], [`RealizationHints::stiffness`]): a "balance" carried by a
/// 3·10⁻⁹ N/m spring is a numerical artefact, not a part anyone can build.
pub const FLOOR_FRACTION: f64 = 1e-6;

impl RealizationHints {
    /// Smallest counterweight mass a witness may have (kg).
    pub fn mass_floor(&self) -> f64 {
        FLOOR_FRACTION * self.mass
    }

    /// Smallest spring stiffness a witness may have (N/m).
    pub fn stiffness_floor(&self) -> f64 {
        FLOOR_FRACTION * self.stiffness
    }
}

impl Default for RealizationHints {
    fn default() -> Self {
        RealizationHints {
            mass: 50.0,
            stiffness: 3000.0,
            length: 0.5,
        }
    }
}

/// The physical parameters of one counterweight and one spring: the shared types, named by
/// catalogue label and body names.
pub use counterpoise_vocabulary::{Counterweight, Spring};

/// A physical parameter set for a variant: the shared physical parameters, which the search
/// verifies by sampling the energy before it reports them.
pub use counterpoise_vocabulary::PhysicalParameters as Witness;

/// Outcome of realization.
#[derive(Clone, Debug)]
pub enum Realization {
    Found(Witness),
    /// Proven impossible, with the reason.
    Impossible(String),
    /// The local search gave up; the reason says how far it got.
    GaveUp(String),
}

/// Layout of physical unknowns for one element of the variant.
struct Slot<'a> {
    entry: &'a CatalogueEntry,
    /// First lifted variable (column of `A_S`).
    column: usize,
    /// First physical unknown in `y`.
    unknown: usize,
}

/// Tries to find physical parameters in the solution set of `solution` (the numeric path: its
/// proofs are decided in floating point).
pub fn realize(
    solution: &LinearSolution,
    b: &DVector<f64>,
    entries: &[(usize, &CatalogueEntry)],
    hints: RealizationHints,
) -> Realization {
    if let Some(proof) = numeric_proofs(solution, b, entries) {
        return proof;
    }
    match find_witness(solution, b, entries, hints) {
        Ok(witness) => Realization::Found(witness),
        Err(reason) => Realization::GaveUp(reason),
    }
}

/// Proofs of unrealizability read off a floating-point solution set: a fixed mass or stiffness
/// that is not positive, or the rank-one contradiction.
pub fn numeric_proofs(
    solution: &LinearSolution,
    b: &DVector<f64>,
    entries: &[(usize, &CatalogueEntry)],
) -> Option<Realization> {
    let b_norm = b.norm();
    // Proofs from the linear stage first.
    for (k, (_, entry)) in entries.iter().enumerate() {
        let range = solution.element_range(k);
        let head = range.start; // m or K
        if solution.is_fixed(head) {
            let value = solution.particular[head];
            let scaled = value * solution.column_scale[head];
            let zero = scaled.abs() <= 1e-7 * b_norm.max(1.0);
            match entry.element {
                Element::Counterweight { .. } if zero => {
                    return Some(Realization::Impossible(format!(
                        "{}: balance forces its mass to zero",
                        entry.label
                    )));
                }
                Element::Counterweight { .. } if value < 0.0 => {
                    return Some(Realization::Impossible(format!(
                        "{}: mass must be negative ({value:.4} kg)",
                        entry.label
                    )));
                }
                Element::Spring { .. } if zero => {
                    return Some(Realization::Impossible(format!(
                        "{}: balance forces its stiffness to zero",
                        entry.label
                    )));
                }
                Element::Spring { .. } if value < 0.0 => {
                    return Some(Realization::Impossible(format!(
                        "{}: stiffness must be negative ({value:.4} N/m)",
                        entry.label
                    )));
                }
                _ => {}
            }
        }
    }

    rank_one_contradiction(solution, entries).map(Realization::Impossible)
}

/// Looks for physical parameters (every mass and stiffness at least its floor) in the solution
/// set by Levenberg–Marquardt from deterministic starts; the reason when none is found.
pub fn find_witness(
    solution: &LinearSolution,
    b: &DVector<f64>,
    entries: &[(usize, &CatalogueEntry)],
    hints: RealizationHints,
) -> Result<Witness, String> {
    find_witness_on(solution, b, entries, hints, &[])
}

/// [`find_witness`] with anchor components held at zero: `zero_columns` lists lifted columns of
/// the variant, and each that is a spring's `α_i` (or `β_j`) holds its anchor's `a_i` (`b_j`) at
/// exactly zero; other columns (`W`, masses) are ignored. A branch of the rank-one case split
/// ([`crate::exact::split`]) is such a family: its extra equations `α_I = 0`, `W_I· = 0` only
/// restrict the lifted solution set, which the search in physical variables never sees, and a
/// search left free to place `a_I` has to creep onto the cancellation of the cross terms
/// `K·a_I·b_Jᵀ` (the three-chain leg's five undecided sets stalled at residuals 4e-7–3e-4).
/// Held at zero, those terms vanish identically and the rest is the easy part.
pub fn find_witness_on(
    solution: &LinearSolution,
    b: &DVector<f64>,
    entries: &[(usize, &CatalogueEntry)],
    hints: RealizationHints,
    zero_columns: &[usize],
) -> Result<Witness, String> {
    let mut slots = Vec::new();
    let mut unknowns = 0;
    for (k, (_, entry)) in entries.iter().enumerate() {
        slots.push(Slot {
            entry,
            column: solution.offsets[k],
            unknown: unknowns,
        });
        unknowns += physical_len(&entry.element);
    }
    let held = held_unknowns(&slots, unknowns, zero_columns);
    let scale = 1.0 / b.norm().max(f64::MIN_POSITIVE);
    let problem = Problem {
        hints,
        scaled: &solution.matrix * scale,
        scaled_b: b * scale,
        slots: &slots,
        unknowns,
        held: &held,
    };

    // Fixed seed: starting points must not depend on thread count or on run.
    let mut rng = SplitMix64::new(0x5eed_ba1a_2ce0_0001);
    let mut best = f64::INFINITY;
    let mut small: Option<String> = None;
    for start in 0..STARTS {
        let y0 = problem.start(solution, hints, start, &mut rng);
        // First towards a plausible balanced point, then onto the exact balance from there.
        let (plausible, _) = problem.levenberg_marquardt(y0, PULL, PULL_ITERATIONS);
        let (y, residual) = problem.levenberg_marquardt(plausible, 0.0, MAX_ITERATIONS);
        best = best.min(residual);
        if residual <= SOLVED_TOL {
            let witness = problem.witness(&y);
            match below_floor(&witness, hints) {
                None => return Ok(witness),
                Some(what) => small = Some(what),
            }
        }
    }
    Err(match small {
        Some(what) => format!(
            "the only physical parameters found have {what}, below the floor of {FLOOR_FRACTION:e} \
             of the typical scale"
        ),
        None => format!(
            "no physical parameters found from {STARTS} starts (best relative residual {best:.2e})"
        ),
    })
}

/// Which physical unknowns are held at zero: the anchor components whose lifted `α_i`, `β_j`
/// columns are in `zero_columns` (a spring's lifted `K, α, β` and physical `K, a, b` share one
/// layout).
fn held_unknowns(slots: &[Slot], unknowns: usize, zero_columns: &[usize]) -> Vec<bool> {
    let mut held = vec![false; unknowns];
    for slot in slots {
        let Element::Spring { axes_a, axes_b, .. } = &slot.entry.element else {
            continue;
        };
        for t in 0..axes_a.len() + axes_b.len() {
            if zero_columns.contains(&(slot.column + 1 + t)) {
                held[slot.unknown + 1 + t] = true;
            }
        }
    }
    held
}

/// The first mass or stiffness of the witness below its floor, described.
fn below_floor(witness: &Witness, hints: RealizationHints) -> Option<String> {
    for cw in &witness.counterweights {
        // NaN fails too.
        if cw.mass.is_nan() || cw.mass < hints.mass_floor() {
            return Some(format!("a mass of {:.3e} kg", cw.mass));
        }
    }
    for spring in &witness.springs {
        if spring.stiffness.is_nan() || spring.stiffness < hints.stiffness_floor() {
            return Some(format!("a stiffness of {:.3e} N/m", spring.stiffness));
        }
    }
    None
}

/// Starting points per variant. On the palletizer at Dmax = 3, 1156 of 1167 balanced variants
/// are realized from the first start and none needed more than four.
/// Random points of the solution set used to recognise a spring residual as an identity.
const IDENTITY_SAMPLES: usize = 8;

/// Proves a variant unrealizable when some spring cannot have a rank-one `W = αβᵀ/K`.
///
/// For a spring, realizability means `A_W (K·W − α βᵀ) = 0` (only the combinations of `W` that
/// change the energy matter). Along the solution set `x = x_p + N z` each component of that
/// residual is a quadratic polynomial in `z`. If it equals `c0 + c1·K(z)` identically — checked at
/// random points of the solution set, which for a polynomial identity is conclusive with
/// probability one — and that affine function of `K` has no root with `K > 0`, no spring exists.
/// This is the palletizer's lone `K42`: balance fixes `a = (1/4, 0)` and `K·b`, so
/// `K·(a×b)` is a fixed multiple of `K` that differs from the required value for every `K > 0`.
pub fn rank_one_contradiction(
    solution: &LinearSolution,
    entries: &[(usize, &CatalogueEntry)],
) -> Option<String> {
    let mut rng = SplitMix64::new(0x0a4e_0f0e_5a11_0001);
    let scale = solution
        .particular
        .component_mul(&solution.column_scale)
        .norm()
        .max(1.0);
    let points: Vec<DVector<f64>> = (0..IDENTITY_SAMPLES)
        .map(|_| {
            let z = DVector::from_fn(solution.nullspace.ncols(), |_, _| {
                scale * rng.uniform(-1.0, 1.0)
            });
            &solution.particular + &solution.nullspace * z
        })
        .collect();
    for (k, (_, entry)) in entries.iter().enumerate() {
        let Element::Spring { axes_a, axes_b, .. } = &entry.element else {
            continue;
        };
        let (na, nb) = (axes_a.len(), axes_b.len());
        let start = solution.offsets[k];
        let w_start = start + 1 + na + nb;
        let a_w = solution.matrix.columns(w_start, na * nb);
        let mut stiffness = Vec::with_capacity(points.len());
        let mut residuals = Vec::with_capacity(points.len());
        let mut magnitude = 0.0f64;
        for x in &points {
            let kk = x[start];
            let mut mismatch = DVector::zeros(na * nb);
            let mut outer = DVector::zeros(na * nb);
            for i in 0..na {
                for j in 0..nb {
                    let ab = x[start + 1 + i] * x[start + 1 + na + j];
                    outer[i * nb + j] = ab;
                    mismatch[i * nb + j] = kk * x[w_start + i * nb + j] - ab;
                }
            }
            let kw = DVector::from_fn(na * nb, |r, _| kk * x[w_start + r]);
            magnitude = magnitude.max((a_w * kw).amax()).max((a_w * outer).amax());
            stiffness.push(kk);
            residuals.push(a_w * mismatch);
        }
        if magnitude == 0.0 {
            continue;
        }
        let tol = 1e-8 * magnitude;
        for row in 0..a_w.nrows() {
            let values: Vec<f64> = residuals.iter().map(|r| r[row]).collect();
            if let Some(reason) =
                affine_in_stiffness_without_positive_root(&stiffness, &values, tol)
            {
                return Some(format!(
                    "{}: no spring has the anchors balance requires ({reason})",
                    entry.label
                ));
            }
        }
    }
    None
}

/// Whether `values = c0 + c1·K` exactly over the samples with no root at `K > 0`; the reason.
fn affine_in_stiffness_without_positive_root(
    k: &[f64],
    values: &[f64],
    tol: f64,
) -> Option<String> {
    let n = k.len() as f64;
    let k_mean = k.iter().sum::<f64>() / n;
    let v_mean = values.iter().sum::<f64>() / n;
    let k_var: f64 = k.iter().map(|x| (x - k_mean).powi(2)).sum();
    let k_span = k.iter().map(|x| (x - k_mean).abs()).fold(0.0, f64::max);
    let (c0, c1) = if k_span <= 1e-12 * k_mean.abs().max(1.0) {
        (v_mean, 0.0) // stiffness fixed: the residual must be constant
    } else {
        let cov: f64 = k
            .iter()
            .zip(values)
            .map(|(x, v)| (x - k_mean) * (v - v_mean))
            .sum();
        let c1 = cov / k_var;
        (v_mean - c1 * k_mean, c1)
    };
    let exact = k
        .iter()
        .zip(values)
        .all(|(x, v)| (c0 + c1 * x - v).abs() <= tol);
    if !exact {
        return None;
    }
    if c1.abs() * k.iter().fold(0.0f64, |a, x| a.max(x.abs())) <= tol {
        // constant residual
        return (c0.abs() > tol).then(|| {
            format!("a rank-one K·a·bᵀ misses the required value by {c0:.4e} for every K")
        });
    }
    // A root at K = 0 (within rounding) is no spring either: K must be strictly positive.
    if c0.abs() <= tol {
        return Some(format!("K·W − α·βᵀ = {c1:.4e}·K vanishes only at K = 0"));
    }
    let root = -c0 / c1;
    (root <= 0.0)
        .then(|| format!("K·W − α·βᵀ = {c0:.4e} + {c1:.4e}·K vanishes only at K = {root:.4e} ≤ 0"))
}

const STARTS: usize = 6;
const MAX_ITERATIONS: usize = 300;
/// Iterations in a row that each gain less than 0.1 % before a start is abandoned: such a start
/// is creeping towards a solution at infinity (a stiffness or mass going to zero or infinity).
const STALL_ITERATIONS: usize = 15;
/// Iterations of the plausibility phase: enough to settle near a plausible point, which the
/// second phase then makes exact.
const PULL_ITERATIONS: usize = 40;
/// Weight of the plausibility rows in the first phase, relative to the balance residual.
const PULL: f64 = 1e-3;
/// Relative residual ‖A x(y) + b‖/‖b‖ at which the local search stops; the energy sampling of
/// the caller is the real check.
const SOLVED_TOL: f64 = 1e-13;
const LOG_RANGE: (f64, f64) = (-25.0, 30.0);

fn physical_len(element: &Element) -> usize {
    match element {
        Element::Counterweight { axes, .. } => 1 + axes.len(),
        Element::Spring { axes_a, axes_b, .. } => 1 + axes_a.len() + axes_b.len(),
    }
}

struct Problem<'a> {
    hints: RealizationHints,
    /// The lifted matrix times `1/‖b‖`, scaled once here: `evaluate` runs at every
    /// Levenberg–Marquardt step and used to allocate each scaled column afresh (a quarter of
    /// the balance search's time). Each entry is the same product `a_ij · (1/‖b‖)`, so the bits
    /// are those of the per-step scaling.
    scaled: DMatrix<f64>,
    /// `b / ‖b‖`, entry by entry the same product as the matrix.
    scaled_b: DVector<f64>,
    slots: &'a [Slot<'a>],
    unknowns: usize,
    /// Unknowns held at zero (their Jacobian columns are zero, so no step moves them).
    held: &'a [bool],
}

impl Problem<'_> {
    /// Residual `(A x(y) + b)/‖b‖` and its Jacobian; with `pull > 0`, extra rows pull every
    /// mass and stiffness towards its hint and every offset and anchor towards the body origin
    /// (scaled by the hint length), so that among many solutions a plausible one is found.
    // Index loops mirror the formulas (a_k, b_l, W_kl) more clearly than zipped iterators.
    #[allow(clippy::needless_range_loop)]
    fn evaluate(&self, y: &DVector<f64>, pull: f64) -> (DVector<f64>, DMatrix<f64>) {
        let rows = self.scaled.nrows();
        let extra = if pull > 0.0 { self.unknowns } else { 0 };
        let height = rows + extra;
        let mut r = DVector::zeros(height);
        r.as_mut_slice()[..rows].copy_from_slice(self.scaled_b.as_slice());
        let mut jac = DMatrix::zeros(height, self.unknowns);
        // Plain slice loops, one scratch column per spring: the same products and sums, in the
        // same order, as the former column-vector expressions, without an allocation per term.
        let matrix = self.scaled.as_slice();
        let mut unit = vec![0.0; rows];
        let mut d = vec![0.0; rows];
        for slot in self.slots {
            let col = |j: usize| {
                let start = (slot.column + j) * rows;
                &matrix[start..start + rows]
            };
            match &slot.entry.element {
                Element::Counterweight { axes, .. } => {
                    let m = y[slot.unknown].exp();
                    {
                        let (r, jac) = (r.as_mut_slice(), jac.as_mut_slice());
                        let jcol = &mut jac[slot.unknown * height..slot.unknown * height + rows];
                        for ((ri, ji), &c) in r.iter_mut().zip(jcol.iter_mut()).zip(col(0)) {
                            let dm = c * m;
                            *ri += dm;
                            *ji = dm;
                        }
                    }
                    for k in 0..axes.len() {
                        let u = slot.unknown + 1 + k;
                        let mu = y[u];
                        let (r, jac) = (r.as_mut_slice(), jac.as_mut_slice());
                        for ((ri, ji), &c) in r
                            .iter_mut()
                            .zip(jac[u * height..u * height + rows].iter_mut())
                            .zip(col(1 + k))
                        {
                            *ri += c * mu;
                            *ji = c;
                        }
                    }
                    if pull > 0.0 {
                        let row = rows + slot.unknown;
                        r[row] = pull * (y[slot.unknown] - self.hints.mass.ln());
                        jac[(row, slot.unknown)] = pull;
                        for k in 0..axes.len() {
                            let mu = y[slot.unknown + 1 + k];
                            let row = rows + slot.unknown + 1 + k;
                            r[row] = pull * mu / (m * self.hints.length);
                            jac[(row, slot.unknown)] = -r[row];
                            jac[(row, slot.unknown + 1 + k)] = pull / (m * self.hints.length);
                        }
                    }
                }
                Element::Spring { axes_a, axes_b, .. } => {
                    let (na, nb) = (axes_a.len(), axes_b.len());
                    let stiffness = y[slot.unknown].exp();
                    let a: Vec<f64> = (0..na).map(|k| y[slot.unknown + 1 + k]).collect();
                    let bb: Vec<f64> = (0..nb).map(|l| y[slot.unknown + 1 + na + l]).collect();
                    let w = |k: usize, l: usize| 1 + na + nb + k * nb + l;
                    // contribution per unit K: φ_K + Σ a_k φ_αk + Σ b_l φ_βl + Σ a_k b_l φ_Wkl
                    unit.copy_from_slice(col(0));
                    for k in 0..na {
                        add_scaled(&mut unit, col(1 + k), a[k]);
                    }
                    for l in 0..nb {
                        add_scaled(&mut unit, col(1 + na + l), bb[l]);
                    }
                    for k in 0..na {
                        for l in 0..nb {
                            add_scaled(&mut unit, col(w(k, l)), a[k] * bb[l]);
                        }
                    }
                    {
                        let u = slot.unknown;
                        let (r, jac) = (r.as_mut_slice(), jac.as_mut_slice());
                        for ((ri, ji), &x) in r
                            .iter_mut()
                            .zip(jac[u * height..u * height + rows].iter_mut())
                            .zip(unit.iter())
                        {
                            let v = x * stiffness;
                            *ri += v;
                            *ji = v;
                        }
                    }
                    for k in 0..na {
                        d.copy_from_slice(col(1 + k));
                        for l in 0..nb {
                            add_scaled(&mut d, col(w(k, l)), bb[l]);
                        }
                        let u = slot.unknown + 1 + k;
                        scale_into(
                            &mut jac.as_mut_slice()[u * height..u * height + rows],
                            &d,
                            stiffness,
                        );
                    }
                    for l in 0..nb {
                        d.copy_from_slice(col(1 + na + l));
                        for k in 0..na {
                            add_scaled(&mut d, col(w(k, l)), a[k]);
                        }
                        let u = slot.unknown + 1 + na + l;
                        scale_into(
                            &mut jac.as_mut_slice()[u * height..u * height + rows],
                            &d,
                            stiffness,
                        );
                    }
                    if pull > 0.0 {
                        let row = rows + slot.unknown;
                        r[row] = pull * (y[slot.unknown] - self.hints.stiffness.ln());
                        jac[(row, slot.unknown)] = pull;
                        for j in 0..na + nb {
                            let row = rows + slot.unknown + 1 + j;
                            r[row] = pull * y[slot.unknown + 1 + j] / self.hints.length;
                            jac[(row, slot.unknown + 1 + j)] = pull / self.hints.length;
                        }
                    }
                }
            }
        }
        for (j, _) in self.held.iter().enumerate().filter(|(_, h)| **h) {
            jac.column_mut(j).fill(0.0);
        }
        (r, jac)
    }

    /// Starting point `start`: the first follows the lifted particular solution where it is
    /// physical, the others are spread deterministically around the hints.
    fn start(
        &self,
        solution: &LinearSolution,
        hints: RealizationHints,
        start: usize,
        rng: &mut SplitMix64,
    ) -> DVector<f64> {
        let mut y = DVector::zeros(self.unknowns);
        for slot in self.slots {
            let x = |j: usize| solution.particular[slot.column + j];
            match &slot.entry.element {
                Element::Counterweight { axes, .. } => {
                    let m = if start == 0 && x(0) > 0.0 {
                        x(0)
                    } else {
                        hints.mass * (rng.uniform(-2.3, 2.3)).exp()
                    };
                    y[slot.unknown] = m.ln();
                    for k in 0..axes.len() {
                        y[slot.unknown + 1 + k] = if start == 0 {
                            x(1 + k)
                        } else {
                            m * hints.length * rng.uniform(-1.0, 1.0)
                        };
                    }
                }
                Element::Spring { axes_a, axes_b, .. } => {
                    let k0 = if start == 0 && x(0) > 0.0 {
                        x(0)
                    } else {
                        hints.stiffness * (rng.uniform(-1.6, 1.6)).exp()
                    };
                    y[slot.unknown] = k0.ln();
                    for j in 0..axes_a.len() + axes_b.len() {
                        y[slot.unknown + 1 + j] = hints.length * rng.uniform(-1.0, 1.0);
                    }
                }
            }
        }
        for (j, _) in self.held.iter().enumerate().filter(|(_, h)| **h) {
            y[j] = 0.0;
        }
        y
    }

    /// Damped Gauss–Newton with Marquardt's adaptive damping; returns the point and the
    /// relative balance residual (without the pull rows).
    fn levenberg_marquardt(
        &self,
        mut y: DVector<f64>,
        pull: f64,
        max_iterations: usize,
    ) -> (DVector<f64>, f64) {
        let (mut r, mut jac) = self.evaluate(&y, pull);
        let mut cost = r.norm();
        let mut lambda = 1e-3;
        let mut slow = 0;
        for _ in 0..max_iterations {
            if cost <= SOLVED_TOL || slow >= STALL_ITERATIONS {
                break;
            }
            let jtj = jac.transpose() * &jac;
            let gradient = jac.transpose() * &r;
            let mut improved = false;
            for _ in 0..12 {
                let mut damped = jtj.clone();
                for i in 0..self.unknowns {
                    damped[(i, i)] += lambda * (jtj[(i, i)] + 1e-9);
                }
                let Some(chol) = damped.cholesky() else {
                    lambda *= 10.0;
                    continue;
                };
                let step = chol.solve(&(-&gradient));
                let mut candidate = &y + &step;
                self.clamp_logs(&mut candidate);
                let (r_new, jac_new) = self.evaluate(&candidate, pull);
                let cost_new = r_new.norm();
                if cost_new.is_finite() && cost_new < cost {
                    y = candidate;
                    r = r_new;
                    jac = jac_new;
                    let relative_gain = (cost - cost_new) / cost;
                    cost = cost_new;
                    lambda = (lambda / 3.0).max(1e-15);
                    improved = relative_gain > 1e-15;
                    slow = if relative_gain < 1e-3 { slow + 1 } else { 0 };
                    break;
                }
                lambda *= 4.0;
            }
            if !improved {
                break;
            }
        }
        let balance = r.rows(0, self.scaled.nrows()).norm();
        (y, balance)
    }

    fn clamp_logs(&self, y: &mut DVector<f64>) {
        for slot in self.slots {
            let v = &mut y[slot.unknown];
            *v = v.clamp(LOG_RANGE.0, LOG_RANGE.1);
        }
    }

    fn witness(&self, y: &DVector<f64>) -> Witness {
        let mut witness = Witness::default();
        for slot in self.slots {
            match &slot.entry.element {
                Element::Counterweight { axes, .. } => {
                    let mass = y[slot.unknown].exp();
                    let mut offset = [0.0; 3];
                    for (k, &axis) in axes.iter().enumerate() {
                        offset[axis] = y[slot.unknown + 1 + k] / mass;
                    }
                    witness.counterweights.push(Counterweight {
                        label: slot.entry.label.clone(),
                        body: slot.entry.bodies[0].clone(),
                        mass,
                        offset,
                        plane: None,
                    });
                }
                Element::Spring { axes_a, axes_b, .. } => {
                    let mut anchor_a = [0.0; 3];
                    let mut anchor_b = [0.0; 3];
                    for (k, &axis) in axes_a.iter().enumerate() {
                        anchor_a[axis] = y[slot.unknown + 1 + k];
                    }
                    for (l, &axis) in axes_b.iter().enumerate() {
                        anchor_b[axis] = y[slot.unknown + 1 + axes_a.len() + l];
                    }
                    witness.springs.push(Spring {
                        label: slot.entry.label.clone(),
                        body: slot.entry.bodies[0].clone(),
                        other: slot.entry.bodies[1].clone(),
                        stiffness: y[slot.unknown].exp(),
                        anchor_a,
                        anchor_b,
                        plane: None,
                    });
                }
            }
        }
        witness
    }
}

/// `acc += x · c`, entry by entry (the product first, then the sum: the order of `acc += &x * c`).
fn add_scaled(acc: &mut [f64], x: &[f64], c: f64) {
    for (a, &v) in acc.iter_mut().zip(x) {
        *a += v * c;
    }
}

/// `out = x · c`, entry by entry.
fn scale_into(out: &mut [f64], x: &[f64], c: f64) {
    for (o, &v) in out.iter_mut().zip(x) {
        *o = v * c;
    }
}
