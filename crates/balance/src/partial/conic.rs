//! A small convex quadratic program over clarabel: `min ½ zᵀ P z + qᵀ z` subject to linear
//! inequalities and second-order cones.
//!
//! Partial balancing needs only this shape (a least-squares objective, box and norm bounds), so
//! it gets its own thin builder rather than the optimiser's, which has no quadratic term.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};

/// One constraint row `Σ c_j z_j` as `(j, c_j)`.
pub type Row = Vec<(usize, f64)>;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Cone {
    Zero,
    Nonneg,
    Soc(usize),
}

/// A quadratic program under construction.
#[derive(Clone, Debug)]
pub struct Qp {
    n: usize,
    /// Dense symmetric `P` (row-major, `n × n`).
    p: Vec<f64>,
    q: Vec<f64>,
    rows: Vec<Row>,
    rhs: Vec<f64>,
    cones: Vec<Cone>,
}

/// The solver's answer.
#[derive(Clone, Debug)]
pub struct QpSolution {
    /// clarabel's status, by name (`Solved`, `AlmostSolved`, `PrimalInfeasible`, …).
    pub status: String,
    pub solved: bool,
    pub z: Vec<f64>,
    pub objective: f64,
    /// The dual objective: a lower bound on the optimum when the dual is feasible.
    pub dual_objective: f64,
}

impl Qp {
    /// `min ½ zᵀ P z + qᵀ z` with `P` dense symmetric row-major.
    pub fn new(p: Vec<f64>, q: Vec<f64>) -> Qp {
        let n = q.len();
        assert_eq!(p.len(), n * n, "P must be n × n");
        Qp {
            n,
            p,
            q,
            rows: Vec::new(),
            rhs: Vec::new(),
            cones: Vec::new(),
        }
    }

    /// `row · z ≤ rhs`.
    pub fn at_most(&mut self, row: Row, rhs: f64) {
        self.rows.push(row);
        self.rhs.push(rhs);
        self.cones.push(Cone::Nonneg);
    }

    /// `row · z = rhs`.
    pub fn equal(&mut self, row: Row, rhs: f64) {
        self.rows.push(row);
        self.rhs.push(rhs);
        self.cones.push(Cone::Zero);
    }

    /// `head(z) ≥ ‖tail(z)‖` with every expression linear (`Σ c_j z_j`, no constant).
    pub fn norm_at_most(&mut self, head: Row, tail: Vec<Row>) {
        // clarabel: s = b − A z ∈ K, so each expression e(z) enters as the row −e, rhs 0.
        let k = 1 + tail.len();
        for e in std::iter::once(head).chain(tail) {
            self.rows
                .push(e.into_iter().map(|(j, c)| (j, -c)).collect());
            self.rhs.push(0.0);
        }
        self.cones.push(Cone::Soc(k));
    }

    /// Solves (quiet; clarabel is deterministic for the same data).
    pub fn solve(&self) -> QpSolution {
        let n = self.n;
        let m = self.rows.len();
        let mut columns: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
        for (i, row) in self.rows.iter().enumerate() {
            for &(j, c) in row {
                if c != 0.0 {
                    columns[j].push((i, c));
                }
            }
        }
        let a = csc(m, n, &columns);
        // P: upper triangle, column by column.
        let mut p_cols: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
        for (j, col) in p_cols.iter_mut().enumerate() {
            for i in 0..=j {
                let v = 0.5 * (self.p[i * n + j] + self.p[j * n + i]);
                if v != 0.0 {
                    col.push((i, v));
                }
            }
        }
        let p = csc(n, n, &p_cols);
        // Consecutive scalar rows of one kind form one cone.
        let mut cones: Vec<SupportedConeT<f64>> = Vec::new();
        for c in &self.cones {
            match (*c, cones.last_mut()) {
                (Cone::Zero, Some(SupportedConeT::ZeroConeT(k)))
                | (Cone::Nonneg, Some(SupportedConeT::NonnegativeConeT(k))) => *k += 1,
                (Cone::Zero, _) => cones.push(SupportedConeT::ZeroConeT(1)),
                (Cone::Nonneg, _) => cones.push(SupportedConeT::NonnegativeConeT(1)),
                (Cone::Soc(k), _) => cones.push(SupportedConeT::SecondOrderConeT(k)),
            }
        }
        let settings = DefaultSettings {
            verbose: false,
            max_iter: 200,
            ..DefaultSettings::default()
        };
        let failed = |status: &str| QpSolution {
            status: status.to_string(),
            solved: false,
            z: vec![0.0; n],
            objective: f64::NAN,
            dual_objective: f64::NAN,
        };
        if !self.p.iter().chain(&self.q).all(|v| v.is_finite())
            || !self.rows.iter().flatten().all(|(_, c)| c.is_finite())
            || !self.rhs.iter().all(|v| v.is_finite())
        {
            return failed("NonFiniteData");
        }
        let Ok(mut solver) = DefaultSolver::new(&p, &self.q, &a, &self.rhs, &cones, settings)
        else {
            return failed("SetupFailed");
        };
        solver.solve();
        let s = &solver.solution;
        let solved = matches!(s.status, SolverStatus::Solved | SolverStatus::AlmostSolved)
            && s.x.iter().all(|v| v.is_finite());
        QpSolution {
            status: format!("{:?}", s.status),
            solved,
            z: s.x.clone(),
            objective: s.obj_val,
            dual_objective: s.obj_val_dual,
        }
    }
}

fn csc(m: usize, n: usize, columns: &[Vec<(usize, f64)>]) -> CscMatrix<f64> {
    let mut colptr = Vec::with_capacity(n + 1);
    let mut rowval = Vec::new();
    let mut nzval = Vec::new();
    colptr.push(0);
    for col in columns {
        for &(i, c) in col {
            rowval.push(i);
            nzval.push(c);
        }
        colptr.push(rowval.len());
    }
    CscMatrix::new(m, n, colptr, rowval, nzval)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn norm_bounded_least_squares() {
        // min (z1 + 2)² with |z1| ≤ 0.5·z0 and z0 ≤ 2 (a counterweight's moment bounded by
        // radius × mass): z0 = 2, z1 = −1, (z1 + 2)² = 1; clarabel's objective omits the
        // constant 4, so it is 1 − 4 = −3.
        let mut qp = Qp::new(vec![0.0, 0.0, 0.0, 2.0], vec![0.0, 4.0]);
        qp.at_most(vec![(0, 1.0)], 2.0);
        qp.norm_at_most(vec![(0, 0.5)], vec![vec![(1, 1.0)]]);
        let s = qp.solve();
        assert!(s.solved, "{}", s.status);
        assert!(
            (s.z[0] - 2.0).abs() < 1e-6 && (s.z[1] + 1.0).abs() < 1e-6,
            "{:?}",
            s.z
        );
        assert!((s.objective + 3.0).abs() < 1e-6, "{}", s.objective);
        assert!(s.dual_objective <= s.objective + 1e-6);
    }
}
