//! The box of one branch-and-bound node: an interval for every coordinate the branching
//! splits — each spring's anchor coordinates (body-frame axes of `a` and `b`) and each
//! counterweight's mass and first-moment components.
//!
//! Only these coordinates carry non-convexity. Given the anchors, everything else is linear:
//! the spring's lifted vector `(K, K a, K b, K a⊗b)` is `K` times a constant, so the stiffness
//! is never split (see [`crate::relaxation`], where a node's box becomes homogenised McCormick
//! rows). The counterweights' second moments `μμᵀ/m` and `m^{5/3}` are convex functions of
//! `(μ, m)`, so their upper bounds over a box are the planes through the box's corners.

use crate::problem::VariantProblem;

/// Relative width below which an interval counts as a point: the corner planes switch to
/// chords, and the search no longer splits it (relative to the coordinate's natural size, see
/// [`NodeBox::split_floor`]).
pub const NARROW: f64 = 1e-6;

/// What a branching coordinate is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Coordinate {
    /// Component `i` (index into `axes_a`) of spring `spring`'s anchor `a`, m.
    AnchorA { spring: usize, i: usize },
    /// Component `l` (index into `axes_b`) of spring `spring`'s anchor `b`, m.
    AnchorB { spring: usize, l: usize },
    /// Mass of counterweight `cw`, kg.
    Mass { cw: usize },
    /// Component `k` (index into `axes`) of counterweight `cw`'s first moment `m·r`, kg·m.
    Moment { cw: usize, k: usize },
}

/// Intervals of every branching coordinate, in the order of [`coordinates`].
#[derive(Clone, Debug, PartialEq)]
pub struct NodeBox {
    pub ranges: Vec<[f64; 2]>,
}

/// The branching coordinates of a variant: per spring its anchor `a` then `b` components, then
/// per counterweight its mass and first-moment components.
pub fn coordinates(problem: &VariantProblem) -> Vec<Coordinate> {
    let mut out = Vec::new();
    for (spring, s) in problem.springs.iter().enumerate() {
        out.extend((0..s.axes_a.len()).map(|i| Coordinate::AnchorA { spring, i }));
        out.extend((0..s.axes_b.len()).map(|l| Coordinate::AnchorB { spring, l }));
    }
    for (cw, c) in problem.counterweights.iter().enumerate() {
        out.push(Coordinate::Mass { cw });
        out.extend((0..c.axes.len()).map(|k| Coordinate::Moment { cw, k }));
    }
    out
}

impl NodeBox {
    /// The box the case's bounds give: each anchor component within its anchor box and within
    /// `±|a|_max`; each mass within its bounds; each first-moment component within
    /// `±r_max·m_max`. An error names the first coordinate without a finite bound (the search
    /// needs a bounded box to be complete).
    pub fn root(problem: &VariantProblem) -> Result<NodeBox, String> {
        let mut ranges = Vec::new();
        for c in coordinates(problem) {
            let range = match c {
                Coordinate::AnchorA { spring, i } => {
                    let s = &problem.springs[spring];
                    let reach = s.bounds.anchor_a[1];
                    let [lo, hi] = s.bounds.box_a[s.axes_a[i]];
                    [lo.max(-reach), hi.min(reach)]
                }
                Coordinate::AnchorB { spring, l } => {
                    let s = &problem.springs[spring];
                    let reach = s.bounds.anchor_b[1];
                    let [lo, hi] = s.bounds.box_b[s.axes_b[l]];
                    [lo.max(-reach), hi.min(reach)]
                }
                Coordinate::Mass { cw } => {
                    let c = &problem.counterweights[cw];
                    [c.min_mass(), c.bounds.mass[1]]
                }
                Coordinate::Moment { cw, .. } => {
                    let c = &problem.counterweights[cw];
                    let reach = c.bounds.radius[1] * c.bounds.mass[1];
                    [-reach, reach]
                }
            };
            if !(range[0].is_finite() && range[1].is_finite()) {
                return Err(format!(
                    "{} has no finite bound, so the search over its values cannot be complete",
                    describe(problem, c)
                ));
            }
            ranges.push(range);
        }
        Ok(NodeBox { ranges })
    }

    /// Width below which coordinate `c` is not split: [`NARROW`] times its natural size (the
    /// anchor's reach, the mass bound, the first moment's reach).
    pub fn split_floor(problem: &VariantProblem, c: Coordinate) -> f64 {
        NARROW
            * match c {
                Coordinate::AnchorA { spring, .. } => problem.springs[spring].bounds.anchor_a[1],
                Coordinate::AnchorB { spring, .. } => problem.springs[spring].bounds.anchor_b[1],
                Coordinate::Mass { cw } => problem.counterweights[cw].bounds.mass[1],
                Coordinate::Moment { cw, .. } => {
                    let b = &problem.counterweights[cw].bounds;
                    b.radius[1] * b.mass[1]
                }
            }
    }

    /// Whether some coordinate's interval is empty.
    pub fn is_empty(&self) -> bool {
        self.ranges.iter().any(|r| r[0] > r[1])
    }

    /// The two halves of the box at the midpoint of coordinate `k`.
    pub fn split(&self, k: usize) -> [NodeBox; 2] {
        let [lo, hi] = self.ranges[k];
        let mid = 0.5 * (lo + hi);
        let mut left = self.clone();
        let mut right = self.clone();
        left.ranges[k][1] = mid;
        right.ranges[k][0] = mid;
        [left, right]
    }

    /// Interval of spring `spring`'s anchor-a component `i` (`b == false`) or anchor-b
    /// component `i` (`b == true`).
    pub fn anchor(&self, problem: &VariantProblem, spring: usize, b: bool, i: usize) -> [f64; 2] {
        let mut k = 0;
        for s in &problem.springs[..spring] {
            k += s.axes_a.len() + s.axes_b.len();
        }
        if b {
            k += problem.springs[spring].axes_a.len();
        }
        self.ranges[k + i]
    }

    /// First index of counterweight `cw`'s coordinates (its mass; the moments follow).
    fn cw_start(problem: &VariantProblem, cw: usize) -> usize {
        let springs: usize = problem
            .springs
            .iter()
            .map(|s| s.axes_a.len() + s.axes_b.len())
            .sum();
        springs
            + problem.counterweights[..cw]
                .iter()
                .map(|c| 1 + c.axes.len())
                .sum::<usize>()
    }

    /// Interval of counterweight `cw`'s mass.
    pub fn mass(&self, problem: &VariantProblem, cw: usize) -> [f64; 2] {
        self.ranges[Self::cw_start(problem, cw)]
    }

    /// Interval of counterweight `cw`'s first-moment component `k`.
    pub fn moment(&self, problem: &VariantProblem, cw: usize, k: usize) -> [f64; 2] {
        self.ranges[Self::cw_start(problem, cw) + 1 + k]
    }

    /// Whether an anchor's norm bound from below cannot be met anywhere in the box: the
    /// farthest corner of its anchor-a (or b) box is nearer than `|a|_min`. The relaxation
    /// drops that non-convex bound, so boxes inside the excluded ball are pruned here.
    pub fn inside_anchor_floor(&self, problem: &VariantProblem) -> Option<String> {
        for (k, s) in problem.springs.iter().enumerate() {
            for (b, n, floor) in [
                (false, s.axes_a.len(), s.bounds.anchor_a[0]),
                (true, s.axes_b.len(), s.bounds.anchor_b[0]),
            ] {
                if floor <= 0.0 {
                    continue;
                }
                let farthest: f64 = (0..n)
                    .map(|i| {
                        let [lo, hi] = self.anchor(problem, k, b, i);
                        lo.abs().max(hi.abs()).powi(2)
                    })
                    .sum::<f64>()
                    .sqrt();
                if farthest < floor {
                    return Some(format!(
                        "{}'s anchor {} is nearer than {} m to its body's origin",
                        s.label,
                        if b { "b" } else { "a" },
                        floor
                    ));
                }
            }
        }
        None
    }
}

/// A coordinate in words, for messages: "K42 anchor a_x", "m4 mass".
pub fn describe(problem: &VariantProblem, c: Coordinate) -> String {
    const AXIS: [&str; 3] = ["x", "y", "z"];
    match c {
        Coordinate::AnchorA { spring, i } => {
            let s = &problem.springs[spring];
            format!("{} anchor a_{}", s.label, AXIS[s.axes_a[i]])
        }
        Coordinate::AnchorB { spring, l } => {
            let s = &problem.springs[spring];
            format!("{} anchor b_{}", s.label, AXIS[s.axes_b[l]])
        }
        Coordinate::Mass { cw } => format!("{} mass", problem.counterweights[cw].label),
        Coordinate::Moment { cw, k } => {
            let c = &problem.counterweights[cw];
            format!("{} first moment m·r_{}", c.label, AXIS[c.axes[k]])
        }
    }
}

/// Planes `u ≤ c₀ + c₁ x + c₂ m` bounding the convex `f(x, m) = x²/m` from above on the box
/// `[xl, xh] × [ml, mh]` (`ml > 0`).
///
/// Always the chord of `x²/ml` in `x` (valid since `f` decreases in `m`), which stays exact and
/// well conditioned when the mass interval is tiny (a mass fixed by balance); on a box of two
/// proper sides also each plane through three corners that lies above the fourth (since `f`
/// is convex, a plane above all four corners is above `f` on the whole box).
pub fn square_over_linear_planes(x: [f64; 2], m: [f64; 2]) -> Vec<[f64; 3]> {
    let f = |x: f64, m: f64| x * x / m;
    if m[0].is_nan() || m[0] <= 0.0 || x[0] > x[1] || m[0] > m[1] {
        return Vec::new();
    }
    let mut out = vec![[-x[0] * x[1] / m[0], (x[0] + x[1]) / m[0], 0.0]];
    let x_scale = x[0].abs().max(x[1].abs());
    if m[1] - m[0] <= NARROW * m[1] || x[1] - x[0] <= NARROW * x_scale {
        if m[1] > m[0] {
            // The chord in m of X²/m, X the largest |x|.
            let big = x_scale * x_scale;
            let slope = -big / (m[0] * m[1]);
            out.push([big / m[0] - slope * m[0], 0.0, slope]);
        }
        return out;
    }
    let corners = [(x[0], m[0]), (x[0], m[1]), (x[1], m[0]), (x[1], m[1])];
    for skip in 0..4 {
        let pts: Vec<(f64, f64)> = (0..4).filter(|&k| k != skip).map(|k| corners[k]).collect();
        let m3 = nalgebra::Matrix3::new(
            1.0, pts[0].0, pts[0].1, 1.0, pts[1].0, pts[1].1, 1.0, pts[2].0, pts[2].1,
        );
        let rhs = nalgebra::Vector3::new(
            f(pts[0].0, pts[0].1),
            f(pts[1].0, pts[1].1),
            f(pts[2].0, pts[2].1),
        );
        let Some(inv) = m3.try_inverse() else {
            continue;
        };
        let c = inv * rhs;
        let (sx, sm) = corners[skip];
        let plane = c[0] + c[1] * sx + c[2] * sm;
        let value = f(sx, sm);
        if plane >= value && c.iter().all(|v| v.is_finite()) {
            out.push([c[0], c[1], c[2]]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every plane lies above x²/m on a fine grid of the box and touches it at three corners.
    #[test]
    fn corner_planes_bound_the_square_over_linear_function_from_above() {
        for (x, m) in [
            ([-0.3, 0.7], [0.5, 2.0]),
            ([1.0, 4.0], [0.1, 0.2]),
            ([-2.0, -1.0], [3.0, 30.0]),
        ] {
            let planes = square_over_linear_planes(x, m);
            assert!(!planes.is_empty());
            for p in &planes {
                let mut touching = 0;
                for (cx, cm) in [(x[0], m[0]), (x[0], m[1]), (x[1], m[0]), (x[1], m[1])] {
                    let gap = p[0] + p[1] * cx + p[2] * cm - cx * cx / cm;
                    if gap.abs() < 1e-9 {
                        touching += 1;
                    }
                }
                assert!(touching >= 2, "plane {p:?} touches {touching} corners");
                for i in 0..=20 {
                    for j in 0..=20 {
                        let xv = x[0] + (x[1] - x[0]) * i as f64 / 20.0;
                        let mv = m[0] + (m[1] - m[0]) * j as f64 / 20.0;
                        let above = p[0] + p[1] * xv + p[2] * mv - xv * xv / mv;
                        assert!(above >= -1e-9, "plane {p:?} below at ({xv}, {mv}): {above}");
                    }
                }
            }
        }
    }

    /// At a point the box's planes meet x²/m exactly when the box shrinks to it: the upper
    /// bound converges (what makes the branch-and-bound converge on counterweights).
    #[test]
    fn corner_planes_tighten_as_the_box_shrinks() {
        let (x0, m0) = (0.4, 1.3);
        let mut previous = f64::INFINITY;
        for k in 1..8 {
            let h = 0.5f64.powi(k);
            let planes = square_over_linear_planes([x0 - h, x0 + h], [m0 - h, m0 + h]);
            let upper = planes
                .iter()
                .map(|p| p[0] + p[1] * x0 + p[2] * m0)
                .fold(f64::INFINITY, f64::min);
            let gap = upper - x0 * x0 / m0;
            assert!(gap >= -1e-12 && gap < previous, "gap {gap} at h = {h}");
            previous = gap;
        }
        assert!(previous < 1e-4);
    }

    /// A zero-width mass interval gives the chord along the moment.
    #[test]
    fn a_fixed_mass_gives_the_chord_in_the_moment() {
        let planes = square_over_linear_planes([1.0, 3.0], [2.0, 2.0]);
        assert_eq!(planes.len(), 1);
        let p = planes[0];
        // Chord of x²/2 between x = 1 (0.5) and x = 3 (4.5): 0.5 + 2 (x − 1).
        assert!((p[0] + p[1] * 2.0 - 2.5).abs() < 1e-12);
        assert!((p[1] - 2.0).abs() < 1e-12);
        assert_eq!(p[2], 0.0);
    }
}
