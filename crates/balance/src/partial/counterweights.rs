//! The best counterweights of one set within their bounds: a convex quadratic program.
//!
//! With lifted parameters `x = (m, μ = m·r)` per counterweight, the residual gravity torque is
//! affine in `x` ([`super::torque`]), so its mean square over the workspace is a convex
//! quadratic `f(x) = xᵀHx + 2gᵀx + c`. The bounds are convex in the same variables:
//! `m ∈ [m_lo, m_hi]` is linear and `|r| ≤ r_hi` is the second-order cone `‖μ‖ ≤ r_hi·m`. The
//! program is solved by clarabel, so its optimum is the optimum over every counterweight design
//! within the bounds — not a local one.
//!
//! Many designs can leave the same residual (a mass on a point that does not move vertically,
//! a mass and a larger radius traded for each other). A second program then picks the
//! lightest of them: minimise `Σ m_i/m_hi,i` over the bounds with the torque held at the
//! optimum's, `A(x − x*) = 0`, written `vᵀ(x − x*) = 0` for the eigenvectors `v` of `H` with a
//! non-negligible eigenvalue (`ker A = ker H`). That program is linear in the objective, so its
//! answer is on the bounds to the solver's precision, and the residual does not change.
//!
//! The one non-convex bound is a lower radius `|r| ≥ r_lo > 0`. When the convex optimum
//! violates it, each offending counterweight's offset is restricted to the direction of its
//! convex optimum (the first axis of its plane when that is zero), `μ = s·d` with
//! `r_lo·m ≤ s ≤ r_hi·m` (linear), and the program solved again: that design is within the
//! bounds, and the first solve's dual objective stays a lower bound, so the gap is reported.

use super::conic::{Qp, Row};

/// Bounds of one counterweight (the case's `balancing.bounds` with its overrides); for a spring
/// block, `mass` is the stiffness `K` (N/m) and `radius` the free anchor's `|a|` (or `|b|`).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct CounterweightLimits {
    /// kg.
    pub mass: [f64; 2],
    /// |r|, m.
    pub radius: [f64; 2],
}

/// A counterweight or spring of the set: its lifted columns (indices into the Gram matrix)
/// and bounds.
#[derive(Clone, Debug)]
pub struct Block {
    /// Column of `m` (of `K` for a spring).
    pub mass: usize,
    /// Columns of `μ` along the plane axes (of `K·a` for a spring).
    pub moment: Vec<usize>,
    pub limits: CounterweightLimits,
    /// Per moment axis, `[lo, hi]` of the offset (m; infinite when free): `lo·m ≤ μ_k ≤ hi·m`,
    /// linear. Empty: no box.
    pub boxes: Vec<[f64; 2]>,
    /// The spring's other anchor, when the block is a spring.
    pub spring: Option<SpringColumns>,
}

/// The columns and bounds of a spring's anchor b and of `W = K·a·bᵀ`.
#[derive(Clone, Debug)]
pub struct SpringColumns {
    /// Columns of `K·b`.
    pub beta: Vec<usize>,
    /// Columns of `W`, row-major: `w[k·beta.len() + l]` is `K·a_k·b_l`.
    pub w: Vec<usize>,
    /// `|b|`, m.
    pub anchor_b: [f64; 2],
    /// Per axis of `b`, as [`Block::boxes`].
    pub box_b: Vec<[f64; 2]>,
}

/// How a block enters the program.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// A counterweight's `(m, μ)`; for a spring, the relaxation (every lifted parameter free).
    Free,
    /// A spring with anchor b fixed (m, in the other body's frame, per plane axis): variables
    /// `(K, K·a)`.
    FixedB(Vec<f64>),
    /// A spring with anchor a fixed: variables `(K, K·b)`.
    FixedA(Vec<f64>),
}

/// The quadratic `f(x) = xᵀHx + 2gᵀx + c` over the columns of every block.
#[derive(Clone, Debug)]
pub struct Quadratic {
    /// Row-major `p × p`.
    pub h: Vec<f64>,
    pub g: Vec<f64>,
    pub c: f64,
}

impl Quadratic {
    /// `f(x)`.
    pub fn value(&self, x: &[f64]) -> f64 {
        let p = self.g.len();
        let mut f = self.c;
        for i in 0..p {
            if x[i] == 0.0 {
                continue;
            }
            let row = &self.h[i * p..(i + 1) * p];
            f += x[i] * (2.0 * self.g[i] + row.iter().zip(x).map(|(h, v)| h * v).sum::<f64>());
        }
        f
    }
}

/// The program's answer for one set.
#[derive(Clone, Debug)]
pub struct Solution {
    /// Lifted parameters, in the quadratic's column order.
    pub x: Vec<f64>,
    /// A lower bound on `min f` over the bounds (clarabel's dual objective of the convex
    /// program; `NaN` when it failed).
    pub lower_bound: f64,
    pub status: String,
    pub solved: bool,
    /// Why the design is not the convex optimum (radius lower bound active), when it is not.
    pub note: Option<String>,
}

/// One block as the program sees it under its shape: the reduced variables as combinations of
/// the lifted columns, and the bounds on them.
struct View<'a> {
    /// `m` or `K` (or `K + Σ b_l K·b_l`, …).
    scale: Vec<(usize, f64)>,
    /// One combination per free moment axis (or one along a fixed direction).
    moments: Vec<Vec<(usize, f64)>>,
    /// The direction the moment is fixed along, if it is.
    along: Option<Vec<f64>>,
    radius: [f64; 2],
    boxes: &'a [[f64; 2]],
    /// Columns of `x` holding the scale and the free moment (for the radius lower bound).
    x_scale: usize,
    x_moment: &'a [usize],
    /// The relaxation's extra variables: `K·b` and `W`.
    relaxed: Option<&'a SpringColumns>,
}

impl Block {
    fn view<'a>(&'a self, shape: &Shape, along: Option<&[f64]>) -> View<'a> {
        let plain = |cols: &[usize]| -> Vec<Vec<(usize, f64)>> {
            cols.iter().map(|&j| vec![(j, 1.0)]).collect()
        };
        let (scale, moments, radius, boxes, x_moment, relaxed): (
            _,
            _,
            _,
            &[[f64; 2]],
            &[usize],
            _,
        ) = match (shape, &self.spring) {
            (Shape::FixedB(b), Some(s)) => {
                let nb = s.beta.len();
                let mut scale = vec![(self.mass, 1.0)];
                scale.extend(s.beta.iter().zip(b).map(|(&j, &v)| (j, v)));
                let moments = (0..self.moment.len())
                    .map(|k| {
                        let mut row = vec![(self.moment[k], 1.0)];
                        row.extend((0..nb).map(|l| (s.w[k * nb + l], b[l])));
                        row
                    })
                    .collect();
                (
                    scale,
                    moments,
                    self.limits.radius,
                    &self.boxes[..],
                    &self.moment[..],
                    None,
                )
            }
            (Shape::FixedA(a), Some(s)) => {
                let nb = s.beta.len();
                let mut scale = vec![(self.mass, 1.0)];
                scale.extend(self.moment.iter().zip(a).map(|(&j, &v)| (j, v)));
                let moments = (0..nb)
                    .map(|l| {
                        let mut row = vec![(s.beta[l], 1.0)];
                        row.extend((0..self.moment.len()).map(|k| (s.w[k * nb + l], a[k])));
                        row
                    })
                    .collect();
                (scale, moments, s.anchor_b, &s.box_b[..], &s.beta[..], None)
            }
            (_, spring) => (
                vec![(self.mass, 1.0)],
                plain(&self.moment),
                self.limits.radius,
                &self.boxes[..],
                &self.moment[..],
                spring.as_ref(),
            ),
        };
        let (moments, along) = match along {
            Some(d) => {
                let mut row: Vec<(usize, f64)> = Vec::new();
                for (m, &dk) in moments.iter().zip(d) {
                    row.extend(m.iter().map(|&(j, v)| (j, v * dk)));
                }
                (vec![row], Some(d.to_vec()))
            }
            None => (moments, None),
        };
        View {
            scale,
            moments,
            along,
            radius,
            boxes,
            x_scale: self.mass,
            x_moment,
            relaxed,
        }
    }
}

/// Solves `min f` over the blocks' bounds, every block a counterweight (see the module
/// documentation); with `lightest`, then the lightest design with the same torques.
pub fn solve(quad: &Quadratic, blocks: &[Block], lightest: bool) -> Solution {
    let shapes = vec![Shape::Free; blocks.len()];
    solve_shaped(quad, blocks, &shapes, lightest)
}

/// [`solve`] with each block in its shape. A lower radius bound is met, as for a
/// counterweight, by fixing the offending moment's direction; the relaxation (a spring in
/// [`Shape::Free`]) ignores lower radius bounds, which only makes it a looser relaxation.
pub fn solve_shaped(
    quad: &Quadratic,
    blocks: &[Block],
    shapes: &[Shape],
    lightest: bool,
) -> Solution {
    let none: Vec<Option<Vec<f64>>> = vec![None; blocks.len()];
    let first = solve_forms(quad, blocks, shapes, &none, lightest);
    if !first.solved {
        return first;
    }
    // Radius lower bounds: the only non-convex constraint.
    let mut violated = 0;
    let along: Vec<Option<Vec<f64>>> = blocks
        .iter()
        .zip(shapes)
        .map(|(b, shape)| {
            let view = b.view(shape, None);
            if view.relaxed.is_some() {
                return None;
            }
            let m = first.x[view.x_scale];
            let mu: Vec<f64> = view.x_moment.iter().map(|&j| first.x[j]).collect();
            let norm = mu.iter().map(|v| v * v).sum::<f64>().sqrt();
            let lo = view.radius[0];
            if lo > 0.0 && m > 0.0 && norm < lo * m * (1.0 - 1e-9) {
                violated += 1;
                Some(if norm > 0.0 {
                    mu.iter().map(|v| v / norm).collect()
                } else {
                    let mut d = vec![0.0; mu.len()];
                    if let Some(first) = d.first_mut() {
                        *first = 1.0;
                    }
                    d
                })
            } else {
                None
            }
        })
        .collect();
    if violated == 0 {
        return first;
    }
    let mut second = solve_forms(quad, blocks, shapes, &along, lightest);
    second.lower_bound = first.lower_bound;
    second.note = Some(format!(
        "the convex optimum puts {violated} counterweight(s) inside the radius lower bound; their \
         offsets were fixed along its direction (lower bound from the convex program)"
    ));
    second
}

/// `‖W‖_* ≤ c·K` for a 2 × 2 block of `W` (rows `k0, k1` of a, columns `l0, l1` of b), as two
/// cones: with `W = C + A`, its conformal part `C` (rotation-like) and anticonformal part `A`,
/// the singular values are `|C| ± |A|`, so the nuclear norm is `2·max(|C|, |A|)`, i.e.
/// `‖(W00 + W11, W10 − W01)‖ ≤ c·K` and `‖(W00 − W11, W01 + W10)‖ ≤ c·K`. For a rank-one
/// `W = K·a·bᵀ` both hold with `c = |a|·|b|`, and every 2 × 2 block of a matrix has a nuclear
/// norm at most the matrix's: a valid cut, and for a plane spring the whole nuclear norm.
fn nuclear_2x2(w: [usize; 4]) -> [[(usize, f64); 2]; 4] {
    let [w00, w01, w10, w11] = w;
    [
        [(w00, 1.0), (w11, 1.0)],
        [(w10, 1.0), (w01, -1.0)],
        [(w00, 1.0), (w11, -1.0)],
        [(w01, 1.0), (w10, 1.0)],
    ]
}

/// The program with each block in the given shape and, where given, its moment along a fixed
/// direction: variables are the views' combinations, scaled so that each has unit effect on the
/// normalised objective.
fn solve_forms(
    quad: &Quadratic,
    blocks: &[Block],
    shapes: &[Shape],
    along: &[Option<Vec<f64>>],
    lightest: bool,
) -> Solution {
    let p = quad.g.len();
    let views: Vec<View> = blocks
        .iter()
        .zip(shapes)
        .zip(along)
        .map(|((b, s), d)| b.view(s, d.as_deref()))
        .collect();
    // x = M y: one column of M per reduced variable.
    let mut map: Vec<Vec<(usize, f64)>> = Vec::new();
    // Natural size of each reduced variable (its bound), for the scaling.
    let mut natural: Vec<f64> = Vec::new();
    // Per block: index of m, of the moment variables, of K·b and of W in y.
    struct Layout {
        m: usize,
        moment: Vec<usize>,
        beta: Vec<usize>,
        w: Vec<usize>,
    }
    let finite = |v: f64| if v.is_finite() { v.max(1e-9) } else { 1.0 };
    let mut layout: Vec<Layout> = Vec::new();
    for (b, v) in blocks.iter().zip(&views) {
        let m_hi = finite(b.limits.mass[1]);
        let m = map.len();
        map.push(v.scale.clone());
        natural.push(m_hi);
        let moment = v
            .moments
            .iter()
            .map(|row| {
                map.push(row.clone());
                natural.push(finite(v.radius[1] * m_hi));
                map.len() - 1
            })
            .collect();
        let (mut beta, mut w) = (Vec::new(), Vec::new());
        if let Some(s) = v.relaxed {
            for &j in &s.beta {
                map.push(vec![(j, 1.0)]);
                natural.push(finite(s.anchor_b[1] * m_hi));
                beta.push(map.len() - 1);
            }
            for &j in &s.w {
                map.push(vec![(j, 1.0)]);
                natural.push(finite(v.radius[1] * s.anchor_b[1] * m_hi));
                w.push(map.len() - 1);
            }
        }
        layout.push(Layout { m, moment, beta, w });
    }
    let n = map.len();
    // Reduced quadratic: H_r = Mᵀ H M, g_r = Mᵀ g.
    let hm = |col: &[(usize, f64)], row: usize| -> f64 {
        col.iter().map(|&(j, v)| quad.h[row * p + j] * v).sum()
    };
    let mut h = vec![0.0; n * n];
    let mut g = vec![0.0; n];
    for a in 0..n {
        g[a] = map[a].iter().map(|&(j, v)| quad.g[j] * v).sum();
        for b in a..n {
            let v = map[a].iter().map(|&(i, u)| u * hm(&map[b], i)).sum::<f64>();
            h[a * n + b] = v;
            h[b * n + a] = v;
        }
    }
    // Scaling x = t·z: unit diagonal for the normalised objective f/c, or the bound's size for
    // a variable the objective does not see.
    let c = if quad.c > 0.0 { quad.c } else { 1.0 };
    let biggest = (0..n).map(|a| h[a * n + a]).fold(0.0f64, f64::max);
    let t: Vec<f64> = (0..n)
        .map(|a| {
            let d = h[a * n + a];
            if d > 1e-18 * biggest && d > 0.0 {
                (c / d).sqrt()
            } else {
                natural[a]
            }
        })
        .collect();
    let mut pz = vec![0.0; n * n];
    let mut qz = vec![0.0; n];
    for a in 0..n {
        qz[a] = 2.0 * t[a] * g[a] / c;
        for b in 0..n {
            pz[a * n + b] = 2.0 * t[a] * t[b] * h[a * n + b] / c;
        }
    }
    // lo·m ≤ e ≤ hi·m for the finite sides of a box.
    let boxed = |qp: &mut Qp, e: Row, m: usize, [lo, hi]: [f64; 2]| {
        if hi.is_finite() {
            let mut row = e.clone();
            row.push((m, -hi * t[m]));
            qp.at_most(row, 0.0);
        }
        if lo.is_finite() {
            let mut row: Row = e.iter().map(|&(j, v)| (j, -v)).collect();
            row.push((m, lo * t[m]));
            qp.at_most(row, 0.0);
        }
    };
    let bounds = |qp: &mut Qp| {
        for ((bl, v), lay) in blocks.iter().zip(&views).zip(&layout) {
            let m = lay.m;
            let [m_lo, m_hi] = bl.limits.mass;
            let [r_lo, r_hi] = v.radius;
            qp.at_most(vec![(m, t[m])], m_hi);
            qp.at_most(vec![(m, -t[m])], -m_lo);
            match &v.along {
                None => {
                    let tail: Vec<Row> = lay.moment.iter().map(|&a| vec![(a, t[a])]).collect();
                    qp.norm_at_most(vec![(m, r_hi * t[m])], tail);
                    for (&a, &range) in lay.moment.iter().zip(v.boxes) {
                        boxed(qp, vec![(a, t[a])], m, range);
                    }
                }
                Some(d) => {
                    let s = lay.moment[0];
                    // r_lo·m ≤ s ≤ r_hi·m
                    qp.at_most(vec![(s, t[s]), (m, -r_hi * t[m])], 0.0);
                    qp.at_most(vec![(s, -t[s]), (m, r_lo * t[m])], 0.0);
                    for (&dk, &range) in d.iter().zip(v.boxes) {
                        boxed(qp, vec![(s, dk * t[s])], m, range);
                    }
                }
            }
            if let Some(spring) = v.relaxed {
                let b_hi = spring.anchor_b[1];
                let tail: Vec<Row> = lay.beta.iter().map(|&a| vec![(a, t[a])]).collect();
                qp.norm_at_most(vec![(m, b_hi * t[m])], tail);
                for (&a, &range) in lay.beta.iter().zip(&spring.box_b) {
                    boxed(qp, vec![(a, t[a])], m, range);
                }
                // ‖W‖_F ≤ a_hi·b_hi·K, and the nuclear norm of every 2 × 2 block.
                let ab = r_hi * b_hi;
                let tail: Vec<Row> = lay.w.iter().map(|&a| vec![(a, t[a])]).collect();
                qp.norm_at_most(vec![(m, ab * t[m])], tail);
                let (na, nb) = (lay.moment.len(), lay.beta.len());
                for k0 in 0..na {
                    for k1 in k0 + 1..na {
                        for l0 in 0..nb {
                            for l1 in l0 + 1..nb {
                                let at = |k: usize, l: usize| lay.w[k * nb + l];
                                let rows =
                                    nuclear_2x2([at(k0, l0), at(k0, l1), at(k1, l0), at(k1, l1)]);
                                let scaled: Vec<Row> = rows
                                    .iter()
                                    .map(|r| r.iter().map(|&(a, v)| (a, v * t[a])).collect())
                                    .collect();
                                qp.norm_at_most(vec![(m, ab * t[m])], scaled[..2].to_vec());
                                qp.norm_at_most(vec![(m, ab * t[m])], scaled[2..].to_vec());
                            }
                        }
                    }
                }
            }
        }
    };
    let mut qp = Qp::new(pz.clone(), qz);
    bounds(&mut qp);
    let mut solution = qp.solve();
    let lower_bound = if solution.solved {
        (c * solution.dual_objective + quad.c).max(0.0)
    } else {
        f64::NAN
    };
    if lightest && solution.solved {
        // Hold the torque: vᵀ(z − z*) = 0 for the eigenvectors of P with λ > 1e-10·λ_max.
        let eigen = nalgebra::SymmetricEigen::try_new(
            nalgebra::DMatrix::from_row_slice(n, n, &pz),
            f64::EPSILON,
            1000,
        );
        if let Some(eigen) = eigen.filter(|e| e.eigenvalues.iter().all(|l| l.is_finite())) {
            let top = eigen.eigenvalues.iter().fold(0.0f64, |a, &l| a.max(l));
            let mut objective = vec![0.0; n];
            for (b, lay) in blocks.iter().zip(&layout) {
                objective[lay.m] = t[lay.m] / b.limits.mass[1].max(f64::MIN_POSITIVE);
            }
            let mut light = Qp::new(vec![0.0; n * n], objective);
            bounds(&mut light);
            for (k, &l) in eigen.eigenvalues.iter().enumerate() {
                if l > 1e-10 * top {
                    let v = eigen.eigenvectors.column(k);
                    let rhs = v.iter().zip(&solution.z).map(|(a, b)| a * b).sum();
                    light.equal(v.iter().copied().enumerate().collect(), rhs);
                }
            }
            let second = light.solve();
            if second.solved {
                solution.z = second.z;
            }
        }
    }
    let y: Vec<f64> = solution.z.iter().zip(&t).map(|(z, t)| z * t).collect();
    let mut x = vec![0.0; p];
    for (col, &yv) in map.iter().zip(&y) {
        for &(j, v) in col {
            x[j] += v * yv;
        }
    }
    Solution {
        x,
        lower_bound,
        status: solution.status,
        solved: solution.solved,
        note: None,
    }
}
