use super::*;

/// A problem in the builder's row form: each row `(terms, b)`, cones as blocks.
struct Owned {
    n: usize,
    row_start: Vec<usize>,
    terms: Vec<(usize, f64)>,
    b: Vec<f64>,
    c: Vec<f64>,
    blocks: Vec<Block>,
}

impl Owned {
    fn new(n: usize, c: Vec<f64>) -> Owned {
        Owned {
            n,
            row_start: vec![0],
            terms: Vec::new(),
            b: Vec::new(),
            c,
            blocks: Vec::new(),
        }
    }

    /// `e(x) = constant + Σ coef·x ≥ 0` as the row `A x + s = b` with `A = −coef`.
    fn push(&mut self, coef: &[(usize, f64)], constant: f64) {
        self.terms.extend(coef.iter().map(|&(j, v)| (j, -v)));
        self.row_start.push(self.terms.len());
        self.b.push(constant);
    }

    fn nonneg(&mut self, coef: &[(usize, f64)], constant: f64) {
        let start = self.b.len();
        self.push(coef, constant);
        self.blocks.push(Block::Nonneg { start, len: 1 });
    }

    fn soc(&mut self, rows: &[(&[(usize, f64)], f64)]) {
        let start = self.b.len();
        for (coef, constant) in rows {
            self.push(coef, *constant);
        }
        self.blocks.push(Block::Soc {
            start,
            len: rows.len(),
        });
    }

    fn solve(&self) -> DenseOutcome {
        let data = DenseData {
            n: self.n,
            row_start: &self.row_start,
            terms: &self.terms,
            b: &self.b,
            c: &self.c,
            blocks: &self.blocks,
        };
        solve(&data, Tolerances::with(1e-8), 100)
    }
}

fn solved(outcome: DenseOutcome) -> (Vec<f64>, Vec<f64>, f64, f64) {
    match outcome {
        DenseOutcome::Solved {
            x,
            z,
            primal_objective,
            dual_objective,
            ..
        } => (x, z, primal_objective, dual_objective),
        other => panic!("not solved: {other:?}"),
    }
}

/// Deterministic pseudo-random numbers in (−1, 1).
fn numbers(seed: u64, count: usize) -> Vec<f64> {
    let mut state = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (0..count)
        .map(|_| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        })
        .collect()
}

/// An interior point of a second-order cone of `len` rows.
fn interior(seed: u64, len: usize) -> Vec<f64> {
    let mut v = numbers(seed, len);
    v[0] = norm(&v[1..]) + 0.1 + v[0].abs();
    v
}

/// The Nesterov–Todd point: `W z = W⁻¹ s` (both `λ`), and `W⁻¹` undoes `W`, for cones of two
/// to eight rows and for nonnegative rows.
#[test]
fn the_scaling_maps_z_and_s_to_one_point_and_inverts() {
    for len in 2..=8 {
        for seed in 0..5u64 {
            let s = interior(seed * 31 + len as u64, len);
            let z = interior(seed * 17 + 1000 + len as u64, len);
            let blk = [Block::Soc { start: 0, len }];
            let mut sc = Scaling::default();
            assert!(sc.update(&blk, &s, &z), "interior");
            let (mut wz, mut winv_s) = (vec![0.0; len], vec![0.0; len]);
            sc.apply(&blk, &z, &mut wz, false);
            sc.apply(&blk, &s, &mut winv_s, true);
            for k in 0..len {
                assert!(
                    (wz[k] - winv_s[k]).abs() < 1e-12 * (1.0 + wz[k].abs()),
                    "{wz:?} {winv_s:?}"
                );
            }
            let v = numbers(seed + 99, len);
            let (mut wv, mut back) = (vec![0.0; len], vec![0.0; len]);
            sc.apply(&blk, &v, &mut wv, false);
            sc.apply(&blk, &wv, &mut back, true);
            for k in 0..len {
                assert!((back[k] - v[k]).abs() < 1e-12, "{back:?} {v:?}");
            }
        }
    }
    let (s, z) = ([4.0, 0.25], [1.0, 4.0]);
    let blk = [Block::Nonneg { start: 0, len: 2 }];
    let mut sc = Scaling::default();
    assert!(sc.update(&blk, &s, &z));
    let mut wz = [0.0; 2];
    sc.apply(&blk, &z, &mut wz, false);
    assert_eq!(wz, [2.0, 1.0]); // √(s z)
}

/// `λ ∘ (λ ⋄ r) = r`, and the Jordan product by hand: `(1, 2, 3) ∘ (4, 5, 6) = (32, 13, 18)`.
#[test]
fn the_jordan_division_undoes_the_product() {
    let blk = Block::Soc { start: 0, len: 3 };
    let mut out = [0.0; 3];
    jordan(blk, &[1.0, 2.0, 3.0], &[4.0, 5.0, 6.0], &mut out);
    assert_eq!(out, [32.0, 13.0, 18.0]);
    for len in 2..=6 {
        let lambda = interior(len as u64, len);
        let r = numbers(7 + len as u64, len);
        let (mut q, mut back) = (vec![0.0; len], vec![0.0; len]);
        jordan_solve(Block::Soc { start: 0, len }, &lambda, &r, &mut q);
        jordan(Block::Soc { start: 0, len }, &lambda, &q, &mut back);
        for k in 0..len {
            assert!((back[k] - r[k]).abs() < 1e-12, "{back:?} {r:?}");
        }
    }
}

/// Steps to the boundary by hand: from (2, 0) along (−1, 1), `(2 − α)² = α²` at α = 1; along
/// (1, 0) never; from (1, 0, 0) along (0, 3, 4) at α = 1/5; nonnegative rows at the first zero.
#[test]
fn the_step_to_the_boundary_matches_hand_values() {
    let soc2 = Block::Soc { start: 0, len: 2 };
    assert!((max_step(soc2, &[2.0, 0.0], &[-1.0, 1.0]) - 1.0).abs() < 1e-15);
    assert_eq!(max_step(soc2, &[2.0, 0.0], &[1.0, 0.0]), f64::INFINITY);
    let soc3 = Block::Soc { start: 0, len: 3 };
    assert!((max_step(soc3, &[1.0, 0.0, 0.0], &[0.0, 3.0, 4.0]) - 0.2).abs() < 1e-15);
    // Straight through the apex: (1, 0) along (−1, 0) reaches it at α = 1.
    assert!((max_step(soc2, &[1.0, 0.0], &[-1.0, 0.0]) - 1.0).abs() < 1e-15);
    let nn = Block::Nonneg { start: 0, len: 3 };
    assert_eq!(max_step(nn, &[1.0, 2.0, 3.0], &[-2.0, -1.0, 5.0]), 0.5);
}

/// `min −x − y` over `0 ≤ x ≤ 1`, `0 ≤ y ≤ 2`, `x + y ≤ 2.5`: optimum −2.5; the duals of the
/// active row `x + y ≤ 2.5` is 1, of the others 0 (hand: `c = −(1, 1)` lies on that row's normal).
#[test]
fn a_small_lp_reaches_its_hand_optimum_and_duals() {
    let mut p = Owned::new(2, vec![-1.0, -1.0]);
    p.nonneg(&[(0, 1.0)], 0.0);
    p.nonneg(&[(1, 1.0)], 0.0);
    p.nonneg(&[(0, -1.0)], 1.0);
    p.nonneg(&[(1, -1.0)], 2.0);
    p.nonneg(&[(0, -1.0), (1, -1.0)], 2.5);
    let (x, z, primal, dual) = solved(p.solve());
    assert!(
        (primal + 2.5).abs() < 1e-7 && (dual + 2.5).abs() < 1e-7,
        "{primal} {dual}"
    );
    assert!((x[0] + x[1] - 2.5).abs() < 1e-7);
    assert!((z[4] - 1.0).abs() < 1e-6, "{z:?}");
    for (k, zk) in z.iter().enumerate().take(4) {
        assert!(zk.abs() < 1e-6, "z[{k}] = {zk}");
    }
}

/// `min t` with `t ≥ ‖(x − 1, y − 2)‖` and `x + y ≤ 0`: the distance from (1, 2) to the half
/// plane, 3/√2, at (−1/2, 1/2).
#[test]
fn a_second_order_cone_program_reaches_the_distance_to_a_half_plane() {
    let mut p = Owned::new(3, vec![0.0, 0.0, 1.0]);
    p.soc(&[(&[(2, 1.0)], 0.0), (&[(0, 1.0)], -1.0), (&[(1, 1.0)], -2.0)]);
    p.nonneg(&[(0, -1.0), (1, -1.0)], 0.0);
    let (x, _, primal, dual) = solved(p.solve());
    let expected = 3.0 / 2f64.sqrt();
    assert!((primal - expected).abs() < 1e-7 && (dual - expected).abs() < 1e-7);
    assert!(
        (x[0] + 0.5).abs() < 1e-6 && (x[1] - 0.5).abs() < 1e-6,
        "{x:?}"
    );
}

/// `x ≥ 1` and `x + ‖(y)‖ ≤ 0` (so `x ≤ −|y| ≤ 0`): no point; the certificate is checked.
#[test]
fn an_infeasible_program_gets_a_checked_certificate() {
    let mut p = Owned::new(2, vec![1.0, 0.0]);
    p.nonneg(&[(0, 1.0)], -1.0);
    p.soc(&[(&[(0, -1.0)], 0.0), (&[(1, 1.0)], 0.0)]);
    match p.solve() {
        DenseOutcome::PrimalInfeasible { z, .. } => {
            // bᵀz < 0 and Aᵀz ≈ 0, z in the cone.
            let bz: f64 = p.b.iter().zip(&z).map(|(a, b)| a * b).sum();
            assert!(bz < 0.0);
            assert!(z[0] > 0.0 && z[1] >= (z[2]).abs());
        }
        other => panic!("expected a certificate: {other:?}"),
    }
}

/// An unbounded program (`min x` with `x ≤ 1` only) gets no verdict: the caller falls back.
#[test]
fn an_unbounded_program_ends_without_a_verdict() {
    let mut p = Owned::new(1, vec![1.0]);
    p.nonneg(&[(0, -1.0)], 1.0);
    assert!(matches!(p.solve(), DenseOutcome::Failed));
}

/// The cone's degree, the `ν` of `μ = sᵀz / ν`: one per nonnegative row, one per second-order
/// cone whatever its size (the barrier `−log(s₀² − ‖s₁‖²)` counts for two halves of one).
#[test]
fn a_blocks_degree_counts_its_rows_or_its_cone() {
    assert_eq!(Block::Nonneg { start: 3, len: 5 }.degree(), 5);
    assert_eq!(Block::Soc { start: 3, len: 5 }.degree(), 1);
    assert_eq!(Block::Soc { start: 0, len: 2 }.degree(), 1);
}

/// The scaling exists only strictly inside the cone: each condition alone refuses a point
/// (a zero or negative row, a cone point on the boundary, one with `s₀² > ‖s₁‖²` but `s₀ < 0`).
#[test]
fn the_scaling_refuses_points_outside_the_cones_interior() {
    let refuses = |blk: Block, s: &[f64], z: &[f64]| !Scaling::default().update(&[blk], s, z);
    let nn = Block::Nonneg { start: 0, len: 2 };
    assert!(!refuses(nn, &[1.0, 2.0], &[3.0, 4.0]));
    assert!(refuses(nn, &[1.0, 0.0], &[3.0, 4.0]));
    assert!(refuses(nn, &[1.0, 2.0], &[0.0, 4.0]));
    assert!(refuses(nn, &[-1.0, 2.0], &[3.0, 4.0]));
    assert!(refuses(nn, &[1.0, 2.0], &[3.0, -4.0]));
    let soc = Block::Soc { start: 0, len: 2 };
    assert!(!refuses(soc, &[2.0, 1.0], &[3.0, -1.0]));
    // on the boundary: s₀ = |s₁|, then z₀ = |z₁|
    assert!(refuses(soc, &[1.0, 1.0], &[3.0, -1.0]));
    assert!(refuses(soc, &[2.0, 1.0], &[1.0, -1.0]));
    // in the opposite cone: s₀² − s₁² = 3 > 0 but s₀ < 0, then likewise z, then both (where
    // `s̄ᵀz̄ ≥ 1` and every number of the scaling would be finite: only the signs refuse it)
    assert!(refuses(soc, &[-2.0, 1.0], &[3.0, -1.0]));
    assert!(refuses(soc, &[2.0, 1.0], &[-3.0, 1.0]));
    assert!(refuses(soc, &[-2.0, 1.0], &[-3.0, 1.0]));
}
