//! The best design of a set with springs: alternating convex programs from several starts,
//! with a certified lower bound from a convex relaxation.
//!
//! A zero-free-length spring's energy is linear in `K`, `K·a`, `K·b` and `W = K·a·bᵀ`, but a
//! physical spring needs `W` of rank one, so the set's optimum is not a convex program. With
//! every spring's anchor b fixed it is one — each spring a block `(K, K·a)` of a counterweight's
//! shape ([`Shape::FixedB`]) — and likewise with anchor a fixed. Alternating the fixed anchor
//! (b, then a, …) never increases the residual (the current design is feasible for the next
//! program, which is solved to optimality) and every iterate is a realisable design within the
//! bounds. It stops at a point where neither anchor can improve alone, which need not be the
//! optimum: `b = 0` is such a point for a spring that does nothing there. So the alternation
//! runs from several deterministic starts — anchor b from the relaxation's `W` (its leading
//! right singular vector), then along each plane axis of b in both directions at full radius,
//! then (for a spring in a plane) along the four diagonals —
//! and keeps the best, stopping early once the design meets the lower bound.
//!
//! The lower bound is the relaxation: `K·a`, `K·b`, `W` free under `‖K·a‖ ≤ a_hi·K`,
//! `‖K·b‖ ≤ b_hi·K`, `‖W‖_F ≤ a_hi·b_hi·K` and the nuclear norm of every 2 × 2 block of `W`
//! below `a_hi·b_hi·K` (exact where only `W` reaches the torque, as for a plane spring from the
//! base to a link about its pivot), its dual objective a certified bound on every
//! design of the set. Where the relaxation is tight the design is certified optimal; otherwise
//! the gap is reported.

use super::counterweights::{Block, Quadratic, Shape, Solution, solve_shaped};

/// At most this many alternations (one program with b fixed, one with a fixed) per start.
pub const MAX_ROUNDS: usize = 30;

/// An alternation stops when a round lowers the mean square by less than this fraction of it
/// (or of the unbalanced mean square, when the residual is smaller).
const STALL: f64 = 1e-6;

/// The best design found for a set with springs.
#[derive(Clone, Debug)]
pub struct SpringSolution {
    /// Lifted parameters of the best design (realisable: `W = K·a·bᵀ` for every spring).
    pub x: Vec<f64>,
    /// `f(x)`.
    pub value: f64,
    /// The relaxation's lower bound on `min f` (`NaN` when it failed).
    pub lower_bound: f64,
    pub status: String,
    /// Starts run and programs solved.
    pub starts: usize,
    pub programs: usize,
}

/// Anchor b of every spring block at the start.
type Anchors = Vec<Option<Vec<f64>>>;

/// `v` scaled to length `radius`, each coordinate then clamped into its box.
fn at_radius(v: &[f64], radius: f64, boxes: &[[f64; 2]]) -> Vec<f64> {
    let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    v.iter()
        .enumerate()
        .map(|(i, x)| {
            let x = if norm > 0.0 { x / norm * radius } else { 0.0 };
            boxes.get(i).map_or(x, |[lo, hi]| x.clamp(*lo, *hi))
        })
        .collect()
}

/// The leading right singular vector of the `na × nb` matrix `w` (row-major), with its
/// singular value.
fn leading_right(w: &[f64], na: usize, nb: usize) -> (f64, Vec<f64>) {
    let m = nalgebra::DMatrix::from_row_slice(na, nb, w);
    let Some(svd) = nalgebra::linalg::SVD::try_new(m, false, true, f64::EPSILON, 1000) else {
        return (0.0, vec![0.0; nb]);
    };
    let Some(vt) = svd.v_t else {
        return (0.0, vec![0.0; nb]);
    };
    let (k, s) = svd
        .singular_values
        .iter()
        .enumerate()
        .fold(
            (0, -1.0),
            |(bk, bs), (k, &s)| {
                if s > bs { (k, s) } else { (bk, bs) }
            },
        );
    (s.max(0.0), vt.row(k).iter().copied().collect())
}

/// The starts: the relaxation's anchors first, then every axis of b in both directions, then in
/// the plane the diagonals, the same for every spring of the set; duplicates dropped, order
/// kept.
fn starts(blocks: &[Block], relaxed: &Solution) -> Vec<Anchors> {
    let mut out: Vec<Anchors> = Vec::new();
    let from_relaxation: Anchors = blocks
        .iter()
        .map(|b| {
            let s = b.spring.as_ref()?;
            let nb = s.beta.len();
            let na = b.moment.len();
            let w: Vec<f64> = s.w.iter().map(|&j| relaxed.x[j]).collect();
            let (sigma, v) = leading_right(&w, na, nb);
            let scale = w.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            let dir = if sigma > 1e-9 * scale && sigma > 0.0 {
                v
            } else {
                // No W: K·b's direction, else the first axis.
                let beta: Vec<f64> = s.beta.iter().map(|&j| relaxed.x[j]).collect();
                if beta.iter().any(|v| *v != 0.0) {
                    beta
                } else {
                    (0..nb).map(|l| if l == 0 { 1.0 } else { 0.0 }).collect()
                }
            };
            Some(at_radius(&dir, s.anchor_b[1], &s.box_b))
        })
        .collect();
    if relaxed.solved {
        out.push(from_relaxation);
    }
    let axes = blocks
        .iter()
        .filter_map(|b| b.spring.as_ref().map(|s| s.beta.len()))
        .max()
        .unwrap_or(0);
    for l in 0..axes {
        for sign in [1.0, -1.0] {
            let start: Anchors = blocks
                .iter()
                .map(|b| {
                    let s = b.spring.as_ref()?;
                    let dir: Vec<f64> = (0..s.beta.len())
                        .map(|i| if i == l { sign } else { 0.0 })
                        .collect();
                    Some(at_radius(&dir, s.anchor_b[1], &s.box_b))
                })
                .collect();
            out.push(start);
        }
    }
    // In the plane, the four diagonals too: on the palletizer they improve 41 of the 406 sets
    // of budget 2 (up to 10 %, none worse) at twice the time; in space (twelve more starts) they
    // improved 3 of the 6-axis arm's 378 sets by under 0.1 % at three times the time.
    if axes == 2 {
        for (s0, s1) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
            let start: Anchors = blocks
                .iter()
                .map(|b| {
                    let s = b.spring.as_ref()?;
                    let dir: Vec<f64> = (0..s.beta.len())
                        .map(|i| [s0, s1].get(i).copied().unwrap_or(0.0))
                        .collect();
                    Some(at_radius(&dir, s.anchor_b[1], &s.box_b))
                })
                .collect();
            out.push(start);
        }
    }
    let mut unique: Vec<Anchors> = Vec::new();
    for s in out {
        if !unique.contains(&s) {
            unique.push(s);
        }
    }
    unique
}

/// Every spring's anchor (`a` when `which_a`, else `b`) from a realisable `x`: `K·a / K`. A
/// spring at `K = 0` keeps `previous` (its anchors mean nothing there).
fn anchors(blocks: &[Block], x: &[f64], which_a: bool, previous: &Anchors) -> Anchors {
    blocks
        .iter()
        .zip(previous)
        .map(|(b, prev)| {
            let s = b.spring.as_ref()?;
            let k = x[b.mass];
            let cols = if which_a { &b.moment } else { &s.beta };
            if k > 0.0 && k.is_finite() {
                Some(cols.iter().map(|&j| x[j] / k).collect())
            } else {
                prev.clone().or_else(|| Some(vec![0.0; cols.len()]))
            }
        })
        .collect()
}

fn shapes(blocks: &[Block], anchors: &Anchors, fixed_b: bool) -> Vec<Shape> {
    blocks
        .iter()
        .zip(anchors)
        .map(|(b, v)| match (&b.spring, v) {
            (Some(_), Some(v)) if fixed_b => Shape::FixedB(v.clone()),
            (Some(_), Some(v)) => Shape::FixedA(v.clone()),
            _ => Shape::Free,
        })
        .collect()
}

/// The best design of a set with at least one spring (see the module documentation): the
/// relaxation, then the alternation from each start until a design's RMS is within `certify`
/// of the lower bound's (`√f − √bound`) or every start has run; then, with `lightest`, the
/// lightest design with the best one's torques (anchor b fixed at the best one's).
pub fn solve(quad: &Quadratic, blocks: &[Block], lightest: bool, certify: f64) -> SpringSolution {
    let free = vec![Shape::Free; blocks.len()];
    let relaxed = solve_shaped(quad, blocks, &free, false);
    let mut programs = 1;
    let lower_bound = relaxed.lower_bound;
    let floor = STALL * quad.c.max(f64::MIN_POSITIVE);
    let mut best: Option<(f64, Vec<f64>, String)> = None;
    let mut tried = 0;
    let certified = |value: f64| {
        lower_bound.is_finite() && value.max(0.0).sqrt() - lower_bound.sqrt() <= certify
    };
    for start in starts(blocks, &relaxed) {
        tried += 1;
        let mut b = start;
        let mut a: Anchors = vec![None; blocks.len()];
        let mut current = f64::INFINITY;
        'rounds: for _ in 0..MAX_ROUNDS {
            let mut improved = false;
            for fixed_b in [true, false] {
                let fixed = if fixed_b { &b } else { &a };
                let step = solve_shaped(quad, blocks, &shapes(blocks, fixed, fixed_b), false);
                programs += 1;
                if !step.solved {
                    // The other anchor would be unknown: this start ends here.
                    break 'rounds;
                }
                let value = quad.value(&step.x);
                if value < current {
                    improved |= current - value > STALL * value.max(0.0).max(floor);
                    current = value;
                    if best.as_ref().is_none_or(|(v, _, _)| value < *v) {
                        best = Some((value, step.x.clone(), step.status.clone()));
                    }
                }
                if fixed_b {
                    a = anchors(blocks, &step.x, true, &a);
                } else {
                    b = anchors(blocks, &step.x, false, &b);
                }
            }
            // Not stopped at `certified`: the alternation goes on while it improves, so a
            // set that balances reaches a residual far below the certification tolerance.
            if !improved {
                break;
            }
        }
        if best.as_ref().is_some_and(|(v, _, _)| certified(*v)) {
            break;
        }
    }
    let Some((mut value, mut x, mut status)) = best else {
        return SpringSolution {
            x: vec![0.0; quad.g.len()],
            value: quad.c,
            lower_bound,
            status: relaxed.status,
            starts: tried,
            programs,
        };
    };
    if lightest {
        let b = anchors(blocks, &x, false, &vec![None; blocks.len()]);
        let light = solve_shaped(quad, blocks, &shapes(blocks, &b, true), true);
        programs += 1;
        if light.solved {
            let v = quad.value(&light.x);
            // The torque is held to the solver's precision: accept what does not lose more.
            if v <= value + 1e-9 * quad.c.max(f64::MIN_POSITIVE) {
                value = v;
                x = light.x;
                status = light.status;
            }
        }
    }
    SpringSolution {
        x,
        value,
        lower_bound,
        status,
        starts: tried,
        programs,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `[[3, 0], [0, 1]]`: the leading right singular vector is ±e0 with σ = 3; the rank-one
    /// `u vᵀ` with `v = (0.6, 0.8)` has it ±v with σ = |u|.
    #[test]
    fn leading_singular_vector_by_hand() {
        let (s, v) = leading_right(&[3.0, 0.0, 0.0, 1.0], 2, 2);
        assert!((s - 3.0).abs() < 1e-12);
        assert!((v[0].abs() - 1.0).abs() < 1e-12 && v[1].abs() < 1e-12);
        let (s, v) = leading_right(&[1.2, 1.6, 0.0, 0.0], 2, 2);
        assert!((s - 2.0).abs() < 1e-12);
        assert!((v[0].abs() - 0.6).abs() < 1e-12 && (v[1].abs() - 0.8).abs() < 1e-12);
    }

    /// `(3, 4)` at radius 0.5 is `(0.3, 0.4)`; a box `x ≤ 0.1` clamps the first coordinate.
    #[test]
    fn start_anchor_at_full_radius_within_the_box() {
        assert_eq!(at_radius(&[3.0, 4.0], 0.5, &[]), vec![0.3, 0.4]);
        let v = at_radius(
            &[3.0, 4.0],
            0.5,
            &[[-1.0, 0.1], [f64::NEG_INFINITY, f64::INFINITY]],
        );
        assert!((v[0] - 0.1).abs() < 1e-15 && (v[1] - 0.4).abs() < 1e-15);
    }
}
