//! The task set: moves between the points of a grid in actuator space.
//!
//! Grid points are indexed with the first actuator varying slowest, each actuator's values
//! running from `from` to `to` (the model's [`Tasks::grid_points`]). With `pairs: "all"` every
//! unordered pair `i < j` is one task, moving from point `i` to point `j`, numbered
//! lexicographically: `(0,1), (0,2), …, (0,N−1), (1,2), …` — the palletizer's 343 points give
//! 343·342/2 = 58,653 tasks. With `pairs: "ordered"` both directions are tasks, numbered
//! `(0,1), (0,2), …, (1,0), (1,2), …`.
//!
//! **Why one direction is enough without friction.** The reversed rest-to-rest move runs
//! `q_rev(t) = q(T − t)` (the quintic law is symmetric, `s(1 − τ) = 1 − s(τ)`), so
//! `q̇_rev(t) = −q̇(T − t)` and `q̈_rev(t) = q̈(T − t)`. The inverse dynamics
//! `τ = M(q) q̈ + C(q, q̇) q̇ + g(q)` is quadratic in `q̇` and so invariant under `q̇ → −q̇` at the
//! same `q`, `q̈`: `τ_rev(t) = τ(T − t)`. The same holds for joint reactions (built from the same
//! accelerations and velocity products). A time-mirrored series has the same RMS (the sample
//! times are mirrored too) and the same peaks. Friction (odd in `q̇`) would break this.

use counterpoise_model::{PairMode, Tasks};

use crate::error::DynamicsError;

/// The grid tasks of a model.
#[derive(Clone, Debug, PartialEq)]
pub struct TaskSet {
    /// Grid points in actuator space (actuator order).
    pub points: Vec<Vec<f64>>,
    /// `(from, to)` grid indices per task.
    pub pairs: Vec<(u32, u32)>,
    pub duration: f64,
    pub samples: usize,
    pub mode: PairMode,
}

impl TaskSet {
    /// The task set of the model's grid, with an optional override of the sample count.
    pub fn new(tasks: &Tasks, samples: Option<usize>) -> Result<TaskSet, DynamicsError> {
        let samples = samples.unwrap_or(tasks.samples);
        if samples < 2 {
            return Err(DynamicsError::BadGrid(format!(
                "{samples} samples per task; at least 2 (both ends) are needed"
            )));
        }
        if tasks.duration.is_nan() || tasks.duration <= 0.0 {
            return Err(DynamicsError::BadGrid(format!(
                "duration {} must be positive",
                tasks.duration
            )));
        }
        // The size is checked before the grid is built: a model made without validation could
        // ask for 1e30 points.
        let n = tasks
            .grid
            .iter()
            .try_fold(1usize, |acc, axis| acc.checked_mul(axis.n))
            .filter(|&n| n <= u32::MAX as usize)
            .ok_or_else(|| DynamicsError::BadGrid("too many grid points".into()))?;
        if n < 2 {
            return Err(DynamicsError::BadGrid(
                "the grid has a single point, so there is no move between two points".into(),
            ));
        }
        let points = tasks.grid_points();
        let mut pairs = Vec::new();
        match tasks.pairs {
            PairMode::All => {
                for i in 0..n {
                    for j in i + 1..n {
                        pairs.push((i as u32, j as u32));
                    }
                }
            }
            PairMode::Ordered => {
                for i in 0..n {
                    for j in 0..n {
                        if i != j {
                            pairs.push((i as u32, j as u32));
                        }
                    }
                }
            }
        }
        Ok(TaskSet {
            points,
            pairs,
            duration: tasks.duration,
            samples,
            mode: tasks.pairs,
        })
    }

    pub fn len(&self) -> usize {
        self.pairs.len()
    }

    pub fn is_empty(&self) -> bool {
        self.pairs.is_empty()
    }

    /// Grid indices `(from, to)` of a task.
    pub fn pair(&self, task: usize) -> (usize, usize) {
        let (i, j) = self.pairs[task];
        (i as usize, j as usize)
    }

    /// Index of the task moving from point `i` to point `j`, if it exists.
    pub fn index_of(&self, i: usize, j: usize) -> Option<usize> {
        let n = self.points.len();
        if i >= n || j >= n || i == j {
            return None;
        }
        match self.mode {
            PairMode::All => {
                if i > j {
                    return None;
                }
                // tasks before row i: Σ_{r<i} (n − 1 − r)
                Some(i * (2 * n - i - 1) / 2 + (j - i - 1))
            }
            PairMode::Ordered => Some(i * (n - 1) + if j > i { j - 1 } else { j }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use counterpoise_model::{GridAxis, MotionLaw};

    fn tasks(mode: PairMode) -> Tasks {
        Tasks {
            grid: vec![
                GridAxis {
                    from: 0.0,
                    to: 1.0,
                    n: 3,
                },
                GridAxis {
                    from: 2.0,
                    to: 3.0,
                    n: 2,
                },
            ],
            pairs: mode,
            law: MotionLaw::Quintic,
            duration: 1.0,
            samples: 5,
        }
    }

    #[test]
    fn grid_order_and_pair_indices() {
        let set = TaskSet::new(&tasks(PairMode::All), None).unwrap();
        assert_eq!(set.points[1], vec![0.0, 3.0]);
        assert_eq!(set.points[2], vec![0.5, 2.0]);
        assert_eq!(set.len(), 15);
        for t in 0..set.len() {
            let (i, j) = set.pair(t);
            assert_eq!(set.index_of(i, j), Some(t));
        }
        let ordered = TaskSet::new(&tasks(PairMode::Ordered), None).unwrap();
        assert_eq!(ordered.len(), 30);
        for t in 0..ordered.len() {
            let (i, j) = ordered.pair(t);
            assert_eq!(ordered.index_of(i, j), Some(t));
        }
    }

    #[test]
    fn a_single_point_or_an_overflowing_grid_is_an_error_not_a_panic() {
        let mut single = tasks(PairMode::All);
        for axis in &mut single.grid {
            axis.n = 1;
        }
        let err = TaskSet::new(&single, None).unwrap_err();
        assert!(err.to_string().contains("single point"), "{err}");
        let mut huge = tasks(PairMode::Ordered);
        huge.grid[0].n = usize::MAX / 2;
        huge.grid[1].n = 3;
        assert!(TaskSet::new(&huge, None).is_err());
    }

    #[test]
    fn palletizer_count() {
        let t = Tasks {
            grid: vec![
                GridAxis {
                    from: 0.0,
                    to: 1.0,
                    n: 7
                };
                3
            ],
            ..tasks(PairMode::All)
        };
        assert_eq!(TaskSet::new(&t, None).unwrap().len(), 58_653);
    }
}
