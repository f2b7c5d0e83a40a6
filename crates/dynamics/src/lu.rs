//! Small dense LU with partial pivoting on the stack, for the `n × n` actuator Jacobian.
//!
//! The hot loop solves `G x = b` and `Gᵀ y = c` once or twice per sample with `n ≤ 12`; a
//! general-purpose dynamic matrix would allocate on every call. The pivot ratio
//! `min |u_ii| / max |u_ii|` is the cheap singularity test used everywhere in this crate.

use counterpoise_symbolic::MAX_VARS;

/// `P G = L U` of a square matrix of order `n ≤ MAX_VARS`.
#[derive(Clone, Copy, Debug)]
pub struct SmallLu {
    n: usize,
    /// Row-major, L below the diagonal (unit diagonal implied), U on and above.
    lu: [f64; MAX_VARS * MAX_VARS],
    perm: [usize; MAX_VARS],
    /// `min |u_ii| / max |u_ii|` (0 for an exactly singular matrix).
    pub pivot_ratio: f64,
    /// `min |u_ii|` and `max |u_ii|`.
    pub min_pivot: f64,
    pub max_pivot: f64,
}

impl SmallLu {
    /// Factors the row-major `n × n` matrix `a`.
    pub fn new(a: &[f64], n: usize) -> SmallLu {
        assert!(n <= MAX_VARS && a.len() >= n * n);
        let mut lu = [0.0; MAX_VARS * MAX_VARS];
        lu[..n * n].copy_from_slice(&a[..n * n]);
        let mut perm = [0usize; MAX_VARS];
        for (i, p) in perm.iter_mut().enumerate().take(n) {
            *p = i;
        }
        let (mut min_pivot, mut max_pivot) = (f64::INFINITY, 0.0f64);
        for k in 0..n {
            let mut best = k;
            for i in k + 1..n {
                if lu[i * n + k].abs() > lu[best * n + k].abs() {
                    best = i;
                }
            }
            if best != k {
                for j in 0..n {
                    lu.swap(k * n + j, best * n + j);
                }
                perm.swap(k, best);
            }
            let pivot = lu[k * n + k];
            min_pivot = min_pivot.min(pivot.abs());
            max_pivot = max_pivot.max(pivot.abs());
            if pivot == 0.0 {
                continue;
            }
            for i in k + 1..n {
                let factor = lu[i * n + k] / pivot;
                lu[i * n + k] = factor;
                for j in k + 1..n {
                    lu[i * n + j] -= factor * lu[k * n + j];
                }
            }
        }
        let pivot_ratio = if max_pivot > 0.0 && min_pivot.is_finite() {
            min_pivot / max_pivot
        } else {
            0.0
        };
        SmallLu {
            n,
            lu,
            perm,
            pivot_ratio,
            min_pivot: if min_pivot.is_finite() {
                min_pivot
            } else {
                0.0
            },
            max_pivot,
        }
    }

    /// Solves `G x = b` in place.
    pub fn solve(&self, b: &mut [f64]) {
        let n = self.n;
        let mut x = [0.0; MAX_VARS];
        for i in 0..n {
            x[i] = b[self.perm[i]];
        }
        for i in 0..n {
            for j in 0..i {
                x[i] -= self.lu[i * n + j] * x[j];
            }
        }
        for i in (0..n).rev() {
            for j in i + 1..n {
                x[i] -= self.lu[i * n + j] * x[j];
            }
            x[i] /= self.lu[i * n + i];
        }
        b[..n].copy_from_slice(&x[..n]);
    }

    /// Solves `Gᵀ y = c` in place (`Gᵀ = Uᵀ Lᵀ P`).
    pub fn solve_transpose(&self, c: &mut [f64]) {
        let n = self.n;
        let mut z = [0.0; MAX_VARS];
        z[..n].copy_from_slice(&c[..n]);
        // Uᵀ w = c
        for i in 0..n {
            for j in 0..i {
                z[i] -= self.lu[j * n + i] * z[j];
            }
            z[i] /= self.lu[i * n + i];
        }
        // Lᵀ v = w
        for i in (0..n).rev() {
            for j in i + 1..n {
                z[i] -= self.lu[j * n + i] * z[j];
            }
        }
        // y = Pᵀ v
        for i in 0..n {
            c[self.perm[i]] = z[i];
        }
    }

    /// [`Self::solve_transpose`] for `nc` right-hand sides at once: `c` holds `n` rows of `nc`
    /// values (row-major); `z` is scratch. Each column undergoes exactly the operations of
    /// the single solve, in the same order.
    pub fn solve_transpose_rows(&self, c: &mut [f64], nc: usize, z: &mut Vec<f64>) {
        let n = self.n;
        z.clear();
        z.extend_from_slice(&c[..n * nc]);
        for i in 0..n {
            let (above, rest) = z.split_at_mut(i * nc);
            let zi = &mut rest[..nc];
            for j in 0..i {
                let f = self.lu[j * n + i];
                for (x, &y) in zi.iter_mut().zip(&above[j * nc..(j + 1) * nc]) {
                    *x -= f * y;
                }
            }
            let d = self.lu[i * n + i];
            for x in zi.iter_mut() {
                *x /= d;
            }
        }
        for i in (0..n).rev() {
            let (head, below) = z.split_at_mut((i + 1) * nc);
            let zi = &mut head[i * nc..];
            for j in i + 1..n {
                let f = self.lu[j * n + i];
                let zj = &below[(j - i - 1) * nc..(j - i) * nc];
                for (x, &y) in zi.iter_mut().zip(zj) {
                    *x -= f * y;
                }
            }
        }
        for i in 0..n {
            let to = self.perm[i];
            c[to * nc..(to + 1) * nc].copy_from_slice(&z[i * nc..(i + 1) * nc]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The batched transposed solve gives each column exactly the single solve's result.
    #[test]
    fn batched_transposed_solve_matches_single_solves() {
        let a = [0.0, 2.0, 1.0, 1.0, 1.0, 0.0, 3.0, 0.5, 4.0];
        let lu = SmallLu::new(&a, 3);
        let columns = [
            [1.0, -2.0, 0.5],
            [0.3, 7.0, -1.5],
            [-4.0, 0.25, 2.0],
            [1e3, -1e-3, 5.0],
        ];
        let nc = columns.len();
        let mut rows = vec![0.0; 3 * nc];
        for (p, col) in columns.iter().enumerate() {
            for i in 0..3 {
                rows[i * nc + p] = col[i];
            }
        }
        lu.solve_transpose_rows(&mut rows, nc, &mut Vec::new());
        for (p, col) in columns.iter().enumerate() {
            let mut single = *col;
            lu.solve_transpose(&mut single);
            for i in 0..3 {
                assert_eq!(rows[i * nc + p].to_bits(), single[i].to_bits());
            }
            // and it is the solution of Gᵀ x = c
            for i in 0..3 {
                let gx: f64 = (0..3).map(|k| a[k * 3 + i] * single[k]).sum();
                assert!((gx - col[i]).abs() < 1e-9 * col[i].abs().max(1.0));
            }
        }
    }

    #[test]
    fn solves_and_transposed_solves() {
        let a = [0.0, 2.0, 1.0, 1.0, 1.0, 0.0, 3.0, 0.5, 4.0];
        let lu = SmallLu::new(&a, 3);
        let x = [1.0, -2.0, 0.5];
        let mut b = [0.0; 3];
        let mut c = [0.0; 3];
        for i in 0..3 {
            for j in 0..3 {
                b[i] += a[i * 3 + j] * x[j];
                c[i] += a[j * 3 + i] * x[j];
            }
        }
        lu.solve(&mut b);
        lu.solve_transpose(&mut c);
        for i in 0..3 {
            assert!((b[i] - x[i]).abs() < 1e-14);
            assert!((c[i] - x[i]).abs() < 1e-14);
        }
        assert!(lu.pivot_ratio > 0.1);
        assert_eq!(SmallLu::new(&[1.0, 2.0, 2.0, 4.0], 2).pivot_ratio, 0.0);
    }
}
