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

/// Bounds of one counterweight (the case's `balancing.bounds` with its overrides).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct CounterweightLimits {
    /// kg.
    pub mass: [f64; 2],
    /// |r|, m.
    pub radius: [f64; 2],
}

/// A counterweight of the set: its lifted columns (indices into the Gram matrix) and bounds.
#[derive(Clone, Debug)]
pub struct Block {
    /// Column of `m`.
    pub mass: usize,
    /// Columns of `μ` along the plane axes.
    pub moment: Vec<usize>,
    pub limits: CounterweightLimits,
}

/// The quadratic `f(x) = xᵀHx + 2gᵀx + c` over the columns of every block.
#[derive(Clone, Debug)]
pub struct Quadratic {
    /// Row-major `p × p`.
    pub h: Vec<f64>,
    pub g: Vec<f64>,
    pub c: f64,
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

/// How a block enters the program: `(m, μ)` free under the cone, or `μ = s·d` along a fixed
/// direction.
enum Form {
    Cone,
    Along(Vec<f64>),
}

/// Solves `min f` over the blocks' bounds (see the module documentation); with `lightest`,
/// then the lightest design with the same torques.
pub fn solve(quad: &Quadratic, blocks: &[Block], lightest: bool) -> Solution {
    let forms: Vec<Form> = blocks.iter().map(|_| Form::Cone).collect();
    let first = solve_forms(quad, blocks, &forms, lightest);
    if !first.solved {
        return first;
    }
    // Radius lower bounds: the only non-convex constraint.
    let mut violated = Vec::new();
    let forms: Vec<Form> = blocks
        .iter()
        .enumerate()
        .map(|(i, b)| {
            let m = first.x[b.mass];
            let mu: Vec<f64> = b.moment.iter().map(|&j| first.x[j]).collect();
            let norm = mu.iter().map(|v| v * v).sum::<f64>().sqrt();
            let lo = b.limits.radius[0];
            if lo > 0.0 && m > 0.0 && norm < lo * m * (1.0 - 1e-9) {
                violated.push(i);
                let d = if norm > 0.0 {
                    mu.iter().map(|v| v / norm).collect()
                } else {
                    let mut d = vec![0.0; mu.len()];
                    if let Some(first) = d.first_mut() {
                        *first = 1.0;
                    }
                    d
                };
                Form::Along(d)
            } else {
                Form::Cone
            }
        })
        .collect();
    if violated.is_empty() {
        return first;
    }
    let mut second = solve_forms(quad, blocks, &forms, lightest);
    second.lower_bound = first.lower_bound;
    second.note = Some(format!(
        "the convex optimum puts {} counterweight(s) inside the radius lower bound; their \
         offsets were fixed along its direction (lower bound from the convex program)",
        violated.len()
    ));
    second
}

/// The program with each block in the given form: variables are the blocks' `m` and either
/// `μ` or `s`, scaled so that each has unit effect on the normalised objective.
fn solve_forms(quad: &Quadratic, blocks: &[Block], forms: &[Form], lightest: bool) -> Solution {
    let p = quad.g.len();
    // x = M y: one column of M per reduced variable.
    let mut map: Vec<Vec<(usize, f64)>> = Vec::new();
    // Per block: index of m and of the moment variables in y.
    let mut layout: Vec<(usize, Vec<usize>)> = Vec::new();
    for (b, form) in blocks.iter().zip(forms) {
        let m = map.len();
        map.push(vec![(b.mass, 1.0)]);
        let moment = match form {
            Form::Cone => b
                .moment
                .iter()
                .map(|&j| {
                    map.push(vec![(j, 1.0)]);
                    map.len() - 1
                })
                .collect(),
            Form::Along(d) => {
                map.push(b.moment.iter().copied().zip(d.iter().copied()).collect());
                vec![map.len() - 1]
            }
        };
        layout.push((m, moment));
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
        for b in 0..n {
            h[a * n + b] = map[a].iter().map(|&(i, u)| u * hm(&map[b], i)).sum::<f64>();
        }
    }
    // Scaling x = t·z: unit diagonal for the normalised objective f/c, or the bound's size for
    // a variable the objective does not see.
    let c = if quad.c > 0.0 { quad.c } else { 1.0 };
    let biggest = (0..n).map(|a| h[a * n + a]).fold(0.0f64, f64::max);
    let mut t = vec![1.0; n];
    for (b, (m, moment)) in blocks.iter().zip(&layout) {
        let natural_m = b.limits.mass[1].max(1e-9);
        let natural_mu = (b.limits.radius[1] * b.limits.mass[1]).max(1e-9);
        for (&a, natural) in
            std::iter::once((m, natural_m)).chain(moment.iter().map(|a| (a, natural_mu)))
        {
            let d = h[a * n + a];
            t[a] = if d > 1e-18 * biggest && d > 0.0 {
                (c / d).sqrt()
            } else {
                natural
            };
        }
    }
    let mut pz = vec![0.0; n * n];
    let mut qz = vec![0.0; n];
    for a in 0..n {
        qz[a] = 2.0 * t[a] * g[a] / c;
        for b in 0..n {
            pz[a * n + b] = 2.0 * t[a] * t[b] * h[a * n + b] / c;
        }
    }
    let bounds = |qp: &mut Qp| {
        for ((bl, form), (m, moment)) in blocks.iter().zip(forms).zip(&layout) {
            let [m_lo, m_hi] = bl.limits.mass;
            let [r_lo, r_hi] = bl.limits.radius;
            qp.at_most(vec![(*m, t[*m])], m_hi);
            qp.at_most(vec![(*m, -t[*m])], -m_lo);
            match form {
                Form::Cone => {
                    let tail: Vec<Row> = moment.iter().map(|&a| vec![(a, t[a])]).collect();
                    qp.norm_at_most(vec![(*m, r_hi * t[*m])], tail);
                }
                Form::Along(_) => {
                    let s = moment[0];
                    // r_lo·m ≤ s ≤ r_hi·m
                    qp.at_most(vec![(s, t[s]), (*m, -r_hi * t[*m])], 0.0);
                    qp.at_most(vec![(s, -t[s]), (*m, r_lo * t[*m])], 0.0);
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
            for (b, (m, _)) in blocks.iter().zip(&layout) {
                objective[*m] = t[*m] / b.limits.mass[1].max(f64::MIN_POSITIVE);
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
