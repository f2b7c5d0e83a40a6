//! The balanced family restricted by the springs' anchors that balance fixes.
//!
//! A spring's lifted variables `(K, α = K·a, β = K·b, W = K·a·bᵀ)` are realizable only when
//! `K·W = α·βᵀ`, which the lifted family ignores. Where balance itself fixes an anchor
//! coordinate — `α_i = c·K` at every point of the family (the palletizer's `K42` has
//! `K42 − 4·K42·ax = 0`: `a_x = 1/4`) — the rank-one condition becomes linear:
//! `W_il = c·β_l` for every `l`, and likewise `W_il = d·α_i` when `β_l = d·K`. Every physical
//! point satisfies these, so intersecting the family with them loses no realizable parameters
//! and removes only lifted points no spring can take. Without it the relaxation and the local
//! refinement wander along those directions (they change the counterweights' optimum through
//! the shared relations) and end where no spring fits.

use counterpoise_dynamics::linalg::checked_svd;
use nalgebra::{DMatrix, DVector};

use crate::slots::SpringSlot;

/// Relative tolerance of "row `α_i` is `c` times row `K`" on the family `x_p + N z` (the family
/// comes from exact arithmetic rounded to doubles, so proportional rows agree to ~1e-15).
const PROPORTIONAL_TOL: f64 = 1e-9;

/// `Some(c)` when row `a` of the family is `c` times row `k` (and row `k` is not zero).
fn proportional(p: &DVector<f64>, n: &DMatrix<f64>, a: usize, k: usize) -> Option<f64> {
    let row = |r: usize| {
        std::iter::once(p[r])
            .chain(n.row(r).iter().copied())
            .collect::<Vec<f64>>()
    };
    let (ra, rk) = (row(a), row(k));
    let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    let nk = norm(&rk);
    if nk == 0.0 {
        return None;
    }
    let c = ra.iter().zip(&rk).map(|(x, y)| x * y).sum::<f64>() / (nk * nk);
    let miss: Vec<f64> = ra.iter().zip(&rk).map(|(x, y)| x - c * y).collect();
    // Relative to the row's size at an anchor of at least a metre, so that a coordinate fixed
    // at zero (a row that is zero up to rounding) is recognised too.
    (norm(&miss) <= PROPORTIONAL_TOL * (norm(&ra) + c.abs().max(1.0) * nk)).then_some(c)
}

/// The linear rows `W_il − c·β_l` and `W_il − d·α_i` implied by anchors fixed on the family.
pub fn implied_rows(
    springs: &[SpringSlot],
    particular: &DVector<f64>,
    nullspace: &DMatrix<f64>,
) -> Vec<Vec<(usize, f64)>> {
    let mut rows = Vec::new();
    for s in springs {
        let (na, nb) = (s.axes_a.len(), s.axes_b.len());
        let k = s.column;
        let alpha = |i: usize| s.column + 1 + i;
        let beta = |l: usize| s.column + 1 + na + l;
        let w = |i: usize, l: usize| s.column + 1 + na + nb + i * nb + l;
        for i in 0..na {
            if let Some(c) = proportional(particular, nullspace, alpha(i), k) {
                for l in 0..nb {
                    rows.push(vec![(w(i, l), 1.0), (beta(l), -c)]);
                }
            }
        }
        for l in 0..nb {
            if let Some(d) = proportional(particular, nullspace, beta(l), k) {
                for i in 0..na {
                    rows.push(vec![(w(i, l), 1.0), (alpha(i), -d)]);
                }
            }
        }
    }
    rows
}

/// The family `x_p + N z` intersected with `rows·x = 0`: `(x_p', N')`. `None` when there is
/// nothing to restrict, when the rows already hold on the whole family, or when they are
/// inconsistent with it (then no spring is realizable and the realization says so).
pub fn restrict(
    springs: &[SpringSlot],
    particular: &DVector<f64>,
    nullspace: &DMatrix<f64>,
) -> Option<(DVector<f64>, DMatrix<f64>)> {
    let rows = implied_rows(springs, particular, nullspace);
    if rows.is_empty() || nullspace.ncols() == 0 {
        return None;
    }
    let d = nullspace.ncols();
    let mut m = DMatrix::<f64>::zeros(rows.len(), d);
    let mut rhs = DVector::<f64>::zeros(rows.len());
    for (r, row) in rows.iter().enumerate() {
        for &(j, c) in row {
            for k in 0..d {
                m[(r, k)] += c * nullspace[(j, k)];
            }
            rhs[r] -= c * particular[j];
        }
    }
    // Pad to at least d rows so that the decomposition has all d right singular vectors.
    let r = rows.len().max(d);
    let mut padded = DMatrix::<f64>::zeros(r, d);
    padded.rows_mut(0, rows.len()).copy_from(&m);
    let mut padded_rhs = DVector::<f64>::zeros(r);
    padded_rhs.rows_mut(0, rows.len()).copy_from(&rhs);
    let svd = checked_svd(padded, true)?;
    let sigma_max = svd.singular_values.max();
    if sigma_max <= 1e-12 * nullspace.norm().max(1.0) {
        // The rows do not involve the free directions: they hold (or fail) on the whole family.
        return None;
    }
    let z0 = svd.solve(&padded_rhs, 1e-10 * sigma_max).ok()?;
    let scale = rows
        .iter()
        .flat_map(|row| row.iter().map(|&(j, c)| (c * particular[j]).abs()))
        .fold(rhs.norm(), f64::max)
        .max(f64::MIN_POSITIVE);
    if (&m * &z0 - &rhs).norm() > 1e-9 * scale {
        return None;
    }
    let v_t = svd.v_t.as_ref()?;
    let kept: Vec<usize> = (0..d)
        .filter(|&k| svd.singular_values[k] <= 1e-10 * sigma_max)
        .collect();
    let n2 = DMatrix::from_fn(d, kept.len(), |i, c| v_t[(kept[c], i)]);
    Some((particular + nullspace * z0, nullspace * n2))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::overrides::SpringBounds;
    use counterpoise_balance::Attachment;

    fn planar_spring(column: usize) -> SpringSlot {
        SpringSlot {
            entry: 0,
            label: "K21".into(),
            body: 1,
            other: Attachment::Body(0),
            bodies: ["link2".into(), "link1".into()],
            axes_a: vec![0, 1],
            axes_b: vec![0, 1],
            column,
            bounds: SpringBounds {
                stiffness: [1000.0, 10000.0],
                anchor_a: [0.0, 1.0],
                anchor_b: [0.0, 1.0],
                box_a: [[f64::NEG_INFINITY, f64::INFINITY]; 3],
                box_b: [[f64::NEG_INFINITY, f64::INFINITY]; 3],
            },
        }
    }

    /// Free directions over one planar spring's nine lifted variables
    /// `(K, αx, αy, βx, βy, Wxx, Wxy, Wyx, Wyy)`: K moves αx by 1/4 (balance fixes a_x = 1/4),
    /// and each listed variable moves alone.
    fn quarter_anchor_family(free: impl IntoIterator<Item = usize>) -> DMatrix<f64> {
        let mut k_dir = DVector::zeros(9);
        k_dir[0] = 1.0;
        k_dir[1] = 0.25;
        let mut cols = vec![k_dir];
        for j in free {
            let mut e = DVector::zeros(9);
            e[j] = 1.0;
            cols.push(e);
        }
        DMatrix::from_columns(&cols)
    }

    /// A hand-made family over one planar spring, x = (K, αx, αy, βx, βy, Wxx, Wxy, Wyx, Wyy):
    /// balance fixes αx = K/4 (a_x = 1/4) and leaves everything else free. Every realizable
    /// point has Wxx = βx/4 and Wxy = βy/4; the restricted family must contain every physical
    /// point, keep Wyx, Wyy free, and satisfy those two rows.
    #[test]
    fn a_fixed_anchor_coordinate_makes_its_w_row_linear() {
        let n_vars = 9;
        let n = quarter_anchor_family(2..n_vars);
        let p = DVector::zeros(n_vars);
        let s = planar_spring(0);
        let rows = implied_rows(std::slice::from_ref(&s), &p, &n);
        assert_eq!(rows.len(), 2, "{rows:?}");
        let (p2, n2) = restrict(std::slice::from_ref(&s), &p, &n).expect("restricted");
        // 8 free directions less the 2 rows.
        assert_eq!(n2.ncols(), 6);
        // A physical spring: K = 2000, a = (1/4, 0.3), b = (0.1, -0.2).
        let (k, a, b) = (2000.0, [0.25, 0.3], [0.1, -0.2]);
        let x = DVector::from_vec(vec![
            k,
            k * a[0],
            k * a[1],
            k * b[0],
            k * b[1],
            k * a[0] * b[0],
            k * a[0] * b[1],
            k * a[1] * b[0],
            k * a[1] * b[1],
        ]);
        // x lies in the restricted family: least squares on N2 reproduces it.
        let z = n2
            .clone()
            .svd(true, true)
            .solve(&(&x - &p2), 1e-12)
            .expect("solve");
        assert!((&p2 + &n2 * z - &x).norm() < 1e-9 * x.norm());
        // Every member satisfies Wxx = βx/4 and Wxy = βy/4.
        for c in 0..n2.ncols() {
            let col = n2.column(c);
            assert!((col[5] - 0.25 * col[3]).abs() < 1e-12);
            assert!((col[6] - 0.25 * col[4]).abs() < 1e-12);
        }
    }

    /// The proportionality test's tolerance, by hand: 1e-9 of the row's size at an anchor of
    /// at least a metre, `1e-9·(‖α‖ + max(|c|, 1 m)·‖K‖)`.
    #[test]
    fn proportional_rows_are_told_apart_from_nearly_proportional_ones() {
        let family = |k: [f64; 3], a: [f64; 3]| {
            let p = DVector::from_vec(vec![k[0], a[0]]);
            let n = DMatrix::from_row_slice(2, 2, &[k[1], k[2], a[1], a[2]]);
            proportional(&p, &n, 1, 0)
        };
        // α = K/4 exactly: c = 1/4.
        let c = family([0.01, 0.02, 0.0], [0.0025, 0.005, 0.0]).unwrap();
        assert!((c - 0.25).abs() < 1e-15);
        // Off by 1e-10 on a row of size 0.01: the tolerance is 1e-9·(0.0025 + 1·0.01) =
        // 1.25e-11, so this row is not proportional.
        assert_eq!(family([0.01, 0.0, 0.0], [0.0025, 1e-10, 0.0]), None);
        // A coordinate fixed at zero up to 1e-10 on a row of size 1000: the tolerance is
        // 1e-9·(1e-10 + 1·1000) ≈ 1e-6, so it is proportional with c ≈ 0.
        let c = family([1000.0, 0.0, 0.0], [0.0, 1e-10, 0.0]).unwrap();
        assert!(c.abs() < 1e-15);
        // No K row, no proportionality.
        assert_eq!(family([0.0, 0.0, 0.0], [1.0, 0.0, 0.0]), None);
    }

    /// The same family shifted by a physical particular point (K = 1000, a = (1/4, 0.2),
    /// b = (0.4, −0.1)): the restricted particular point must itself meet the implied rows, and
    /// a family whose fixed W contradicts them is left alone (no spring is realizable there).
    #[test]
    fn a_shifted_family_keeps_its_rows_and_a_contradictory_one_is_left_alone() {
        let n_vars = 9;
        let n = quarter_anchor_family(2..n_vars);
        // A lifted point off the physical set (W = 0) but on the family: the restriction moves
        // its W to β/4.
        let p = DVector::from_vec(vec![
            1000.0, 250.0, 200.0, 400.0, -100.0, 0.0, 0.0, 0.0, 0.0,
        ]);
        let s = planar_spring(0);
        let (p2, n2) = restrict(std::slice::from_ref(&s), &p, &n).expect("restricted");
        assert!((p2[5] - 0.25 * p2[3]).abs() < 1e-9, "{p2}");
        assert!((p2[6] - 0.25 * p2[4]).abs() < 1e-9, "{p2}");
        assert!(n2.ncols() == 6);
        // W_xx fixed at 5 while β_x is fixed at 0: `W_xx = β_x/4` cannot hold.
        let n = quarter_anchor_family([2, 4, 6, 7, 8]);
        let p = DVector::from_vec(vec![0.0, 0.0, 0.0, 0.0, 0.0, 5.0, 0.0, 0.0, 0.0]);
        assert!(!implied_rows(std::slice::from_ref(&s), &p, &n).is_empty());
        assert!(restrict(std::slice::from_ref(&s), &p, &n).is_none());
    }

    #[test]
    fn nothing_is_restricted_when_no_anchor_is_fixed() {
        let n = DMatrix::<f64>::identity(9, 9);
        let p = DVector::zeros(9);
        let s = planar_spring(0);
        assert!(implied_rows(std::slice::from_ref(&s), &p, &n).is_empty());
        assert!(restrict(std::slice::from_ref(&s), &p, &n).is_none());
    }
}
