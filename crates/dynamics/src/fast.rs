//! Grid evaluation for mechanisms with a cyclic coordinate (see [`crate::symmetry`]).
//!
//! With a cyclic coordinate `q_c` driven by actuator `a`, a grid task from point `i` to point
//! `j` is determined by its *sub-task* — the move of the other actuators from `i`'s to `j`'s
//! values — and by `Δ = u_a(j) − u_a(i)`; the value of `q_c` itself does not matter. Along a
//! sub-task sample, `q̇` is affine and `q̈` quadratic in `Δ` (`u̇_a = Δ·s'(τ)/T`,
//! `ü_a = Δ·s''(τ)/T²`), so every output (generalized forces, actuator forces, joint reaction
//! vectors — all of the form `M q̈ + q̇ᵀΓq̇ + g`) is a quadratic polynomial in `Δ`:
//! `X(Δ) = X₀ + Δ X₁ + Δ² X₂`. We evaluate each sub-task sample at `Δ ∈ {0, 1, −1}` (exactly
//! recovering the three coefficients), once per sub-task, and then every task that uses the
//! sub-task costs a few multiply-adds per sample.
//!
//! Sub-tasks are unordered pairs of sub-points (including a sub-point with itself: a pure
//! rotation about the cyclic axis); a task whose sub-task runs backwards uses the time-reversal
//! identity of [`crate::tasks`]: the reversed sub-task with `Δ` at time `t` equals the forward
//! sub-task with `−Δ` at `T − t` (all velocities negated, accelerations unchanged). Tasks with
//! the same sub-task, direction and `Δ` have identical statistics and are computed once.
//! The palletizer's 343 points have 49 sub-points: 1,225 sub-tasks instead of 58,653 tasks.

use std::collections::HashMap;

use counterpoise_symbolic::MAX_VARS;
use rayon::prelude::*;

use crate::error::{FailureReason, TaskFailure};
use crate::indicators::{StatsAccumulator, StatsTable, TaskStats};
use crate::kernel::{actuator_forces, required_wrenches, required_wrenches_with};
use crate::law::{quintic, quintic_move, sample_time};
use crate::lu::SmallLu;
use crate::mechanism::{BodyKin, Scratch};
use crate::params::ParameterSet;
use crate::reactions::ReactionWork;
use crate::regressor::{WrenchRegressor, wrench_regressor};
use crate::runner::Evaluator;
use crate::symmetry::Cyclic;
use crate::tasks::TaskSet;

/// Coefficients of one sub-task: per sample, per power of `Δ` (3), per column, the motor
/// torques (`n`) and, with reactions, the joint wrenches (`6J`).
struct SubTaskData {
    stride: usize,
    values: Vec<f64>,
}

#[derive(Default)]
struct Work {
    scratch: Scratch,
    kin: Vec<BodyKin>,
    regressors: Vec<WrenchRegressor>,
    reactions: ReactionWork,
    w: Vec<f64>,
    b: Vec<f64>,
    out: Vec<f64>,
    states: Vec<f64>,
}

/// Outcome of one sub-task: the statistics of its distinct tasks and, per task, which one
/// it is; or the failure of the sub-task.
type SubTaskOutcome = Result<(Vec<Vec<TaskStats>>, Vec<(usize, usize)>), Vec<TaskFailure>>;

/// Runs the grid through the cyclic decomposition into `table`; returns the failures in task
/// order and the number of distinct moves evaluated.
pub(crate) fn evaluate_cyclic(
    ev: &Evaluator,
    cyc: Cyclic,
    tasks: &TaskSet,
    params: &ParameterSet,
    with_reactions: bool,
    table: &mut StatsTable,
) -> (Vec<TaskFailure>, usize) {
    let mech = &ev.mech;
    let n = mech.n;
    let ns = tasks.samples;
    let ac = cyc.actuator;
    let c = cyc.coordinate;
    let q_ref = ev.model.reference_configuration();
    let mut u_ref = [0.0; MAX_VARS];
    let mut g = [0.0; MAX_VARS * MAX_VARS];
    mech.actuator_map(&q_ref, &mut Scratch::default(), &mut u_ref, &mut g);
    let uc_ref = u_ref[ac];

    // Sub-points: grid points with the cyclic actuator at its reference value.
    let mut sub_index: HashMap<Vec<u64>, usize> = HashMap::new();
    let mut sub_u: Vec<Vec<f64>> = Vec::new();
    let mut sub_of = Vec::with_capacity(tasks.points.len());
    for p in &tasks.points {
        let mut u = p.clone();
        u[ac] = uc_ref;
        let key: Vec<u64> = u.iter().map(|x| x.to_bits()).collect();
        let id = *sub_index.entry(key).or_insert_with(|| {
            sub_u.push(u);
            sub_u.len() - 1
        });
        sub_of.push(id);
    }
    // The cyclic coordinate of every grid point must lie in its range.
    let cyclic_ok: Vec<Result<(), FailureReason>> = tasks
        .points
        .iter()
        .map(|p| {
            let mut q = q_ref.clone();
            q[c] = q_ref[c] + (p[ac] - uc_ref) / cyc.scale;
            mech.into_ranges(&mut q)
        })
        .collect();
    let sub_q: Vec<Result<Vec<f64>, FailureReason>> =
        sub_u.par_iter().map(|u| ev.solve_point(u)).collect();

    // Sub-tasks and the tasks that use them.
    let mut st_index: HashMap<(usize, usize), usize> = HashMap::new();
    let mut st_pairs: Vec<(usize, usize)> = Vec::new();
    let mut users: Vec<Vec<(usize, bool, f64)>> = Vec::new();
    let mut failures: Vec<TaskFailure> = Vec::new();
    for w in 0..tasks.len() {
        let (i, j) = tasks.pair(w);
        if let Err(reason) = &cyclic_ok[i] {
            failures.push(TaskFailure {
                task: w,
                sample: 0,
                reason: reason.clone(),
            });
            continue;
        }
        if let Err(reason) = &cyclic_ok[j] {
            failures.push(TaskFailure {
                task: w,
                sample: ns - 1,
                reason: reason.clone(),
            });
            continue;
        }
        let (si, sj) = (sub_of[i], sub_of[j]);
        let (key, rev) = if si <= sj {
            ((si, sj), false)
        } else {
            ((sj, si), true)
        };
        let st = *st_index.entry(key).or_insert_with(|| {
            st_pairs.push(key);
            users.push(Vec::new());
            st_pairs.len() - 1
        });
        users[st].push((w, rev, tasks.points[j][ac] - tasks.points[i][ac]));
    }

    let span = tasks
        .points
        .iter()
        .map(|p| p[ac])
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
            (lo.min(x), hi.max(x))
        });
    let delta_quantum = 1e-12 * (span.1 - span.0).abs().max(1e-300);
    let na = n;
    let nj = if with_reactions {
        ev.reactions.joint_count()
    } else {
        0
    };
    let per_sample_stride = params.len() * (3 * na + 10 * nj);
    let computed: Vec<SubTaskOutcome> = (0..st_pairs.len())
        .into_par_iter()
        .map_init(Work::default, |work, st| {
            let (s1, s2) = st_pairs[st];
            let data = match &sub_q[s1] {
                Err(reason) => Err((0, reason.clone())),
                Ok(q0) => sub_task(
                    ev,
                    cyc,
                    &sub_u[s1],
                    &sub_u[s2],
                    q0,
                    tasks.duration,
                    ns,
                    params,
                    with_reactions,
                    per_sample_stride,
                    work,
                ),
            };
            let d = match data {
                Ok(d) => d,
                Err((k, reason)) => {
                    return Err(users[st]
                        .iter()
                        .map(|&(w, rev, _)| {
                            let sample = if rev { ns - 1 - k } else { k };
                            let reason = reason.clone();
                            TaskFailure {
                                task: w,
                                sample,
                                reason,
                            }
                        })
                        .collect());
                }
            };
            // Tasks whose Δ agree to 1e-12 of the cyclic span share one evaluation (grid
            // differences such as θ(3) − θ(1) and θ(4) − θ(2) differ in the last bits); the
            // first task of a group (lowest index) provides its Δ.
            let mut index: HashMap<(bool, i64), usize> = HashMap::new();
            let mut unique: Vec<(bool, f64)> = Vec::new();
            let slot: Vec<usize> = users[st]
                .iter()
                .map(|&(_, rev, delta)| {
                    let key = (rev, (delta / delta_quantum).round() as i64);
                    *index.entry(key).or_insert_with(|| {
                        unique.push((rev, delta));
                        unique.len() - 1
                    })
                })
                .collect();
            let stats = task_stats(&d, &unique, ns, params.len(), na, nj);
            Ok((stats, users[st].iter().map(|u| u.0).zip(slot).collect()))
        })
        .collect();
    let mut distinct = 0;
    for outcome in computed {
        match outcome {
            Ok((stats, assignment)) => {
                distinct += stats.len();
                for (w, u) in assignment {
                    table.set(w, &stats[u]);
                }
            }
            Err(f) => failures.extend(f),
        }
    }
    failures.sort_by_key(|f| f.task);
    (failures, distinct)
}

crate::simd::multiversion! {
/// Statistics of every `(reversed, Δ)` task of one sub-task. Samples run in the outer loop
/// so that a sample's coefficients are read from cache once for all the tasks.
fn task_stats(
    d: &SubTaskData,
    tasks: &[(bool, f64)],
    ns: usize,
    cols: usize,
    na: usize,
    nj: usize,
) -> Vec<Vec<TaskStats>> {
    let block = 3 * na + 10 * nj;
    let nt = tasks.len();
    let mut acc = vec![StatsAccumulator::new(na, nj); cols * nt];
    // peaks of |F|², |M|² per task, column and joint (square roots taken once at the end)
    let mut f2max = vec![0.0f64; nt * cols * nj];
    let mut m2max = vec![0.0f64; nt * cols * nj];
    let mut tau = [0.0; MAX_VARS];
    for k in 0..ns {
        for (t, &(rev, delta)) in tasks.iter().enumerate() {
            let dd = if rev { -delta } else { delta };
            let d2 = dd * dd;
            let kk = if rev { ns - 1 - k } else { k };
            let base = &d.values[kk * d.stride..(kk + 1) * d.stride];
            for p in 0..cols {
                let x = &base[p * block..(p + 1) * block];
                for a in 0..na {
                    tau[a] = x[a] + dd * x[na + a] + d2 * x[2 * na + a];
                }
                acc[t * cols + p].add_torques(&tau[..na]);
                if nj > 0 {
                    let off = (t * cols + p) * nj;
                    for (q, peaks) in [(&x[3 * na..3 * na + 5 * nj], &mut f2max), (&x[3 * na + 5 * nj..], &mut m2max)] {
                        let (c0, rest) = q.split_at(nj);
                        let (c1, rest) = rest.split_at(nj);
                        let (c2, rest) = rest.split_at(nj);
                        let (c3, c4) = rest.split_at(nj);
                        let pk = &mut peaks[off..off + nj];
                        for j in 0..nj {
                            let v = (((c4[j] * dd + c3[j]) * dd + c2[j]) * dd + c1[j]) * dd + c0[j];
                            pk[j] = pk[j].max(v);
                        }
                    }
                }
            }
        }
    }
    (0..nt)
        .map(|t| {
            (0..cols)
                .map(|p| {
                    let a = &mut acc[t * cols + p];
                    let off = (t * cols + p) * nj;
                    if nj > 0 {
                        a.add_reactions(
                            f2max[off..off + nj].iter().map(|v| v.max(0.0).sqrt()),
                            m2max[off..off + nj].iter().map(|v| v.max(0.0).sqrt()),
                        );
                    }
                    a.finish(nj > 0)
                })
                .collect()
        })
        .collect()
}
}

/// Evaluates one sub-task at `Δ ∈ {0, 1, −1}` per sample and stores the coefficients.
#[allow(clippy::too_many_arguments)]
fn sub_task(
    ev: &Evaluator,
    cyc: Cyclic,
    ua: &[f64],
    ub: &[f64],
    q0: &[f64],
    duration: f64,
    ns: usize,
    params: &ParameterSet,
    with_reactions: bool,
    stride: usize,
    work: &mut Work,
) -> Result<SubTaskData, (usize, FailureReason)> {
    let mech = &ev.mech;
    let n = mech.n;
    let l = mech.body_count;
    let cols = params.len();
    let nj = if with_reactions {
        ev.reactions.joint_count()
    } else {
        0
    };
    let block = n + 6 * nj;
    let rows = 6 * l;
    let mut values = vec![0.0; ns * stride];
    let mut q = q0.to_vec();
    let mut u = [0.0; MAX_VARS];
    let mut ud = [0.0; MAX_VARS];
    let mut udd = [0.0; MAX_VARS];
    let mut f = [0.0; MAX_VARS];
    let mut g = [0.0; MAX_VARS * MAX_VARS];
    work.w.resize(rows, 0.0);
    work.states.resize(3 * cols * block, 0.0);
    if with_reactions {
        work.b.resize(rows * 3 * cols, 0.0);
        work.out.resize(6 * nj * 3 * cols, 0.0);
    }
    for k in 0..ns {
        let t = sample_time(k, ns, duration);
        for a in 0..n {
            (u[a], ud[a], udd[a]) = quintic_move(ua[a], ub[a], duration, t);
        }
        let (_, ds, dds) = quintic(t / duration);
        let (vel, acc) = (ds / duration, dds / (duration * duration));
        mech.solve(&u[..n], &mut q, &mut work.scratch)
            .map_err(|e| (k, e))?;
        mech.actuator_map(&q, &mut work.scratch, &mut f, &mut g);
        let lu = SmallLu::new(&g, n);
        mech.singularity(&lu).map_err(|e| (k, e))?;
        mech.eval_poses(&q, &mut work.scratch);
        let pose = std::mem::take(&mut work.scratch.pose);
        work.kin.clear();
        work.kin.extend((0..l).map(|b| mech.body_frame(&pose, b)));
        if with_reactions {
            ev.reactions
                .prepare(mech, &pose, &work.kin, &lu, &mut work.reactions);
        }
        for (si, d) in [0.0, 1.0, -1.0].into_iter().enumerate() {
            let mut qd = ud;
            let mut qdd = udd;
            qd[cyc.actuator] += d * vel;
            qdd[cyc.actuator] += d * acc;
            lu.solve(&mut qd);
            let mut bias = [0.0; MAX_VARS];
            mech.actuator_bias(&q, &qd, &mut work.scratch, &mut bias);
            for a in 0..n {
                qdd[a] -= bias[a];
            }
            lu.solve(&mut qdd);
            // With several columns, one wrench regressor per body serves them all; with one,
            // the direct Newton–Euler wrench is cheaper.
            let shared = cols > 2;
            work.regressors.clear();
            for (b, kin) in work.kin.iter_mut().enumerate() {
                mech.set_motion(&pose, b, kin, &qd, &qdd);
                if shared {
                    work.regressors.push(wrench_regressor(kin, &mech.gravity));
                }
            }
            for p in 0..cols {
                if shared {
                    required_wrenches_with(mech, &pose, &work.regressors, params, p, &mut work.w);
                } else {
                    required_wrenches(mech, &pose, &work.kin, params, p, &mut work.w);
                }
                let qu = actuator_forces(&work.kin, &work.w, n, &lu);
                let st = &mut work.states[(si * cols + p) * block..(si * cols + p + 1) * block];
                for a in 0..n {
                    if !qu[a].is_finite() {
                        return Err((k, FailureReason::NonFinite));
                    }
                    st[a] = qu[a] * ev.ratios[a];
                }
                if with_reactions {
                    ev.reactions
                        .subtract_actuators(&work.reactions, &work.kin, &qu, &mut work.w);
                    let m = 3 * cols;
                    let col = si * cols + p;
                    for r in 0..rows {
                        work.b[r * m + col] = work.w[r];
                    }
                }
            }
        }
        if with_reactions {
            let m = 3 * cols;
            ev.reactions
                .solve_prepared(&mut work.reactions, &mut work.b, m, &mut work.out);
            for si in 0..3 {
                for p in 0..cols {
                    let col = si * cols + p;
                    let st = &mut work.states[col * block..(col + 1) * block];
                    // joint-major rows (6j + r) → component-major (r·J + j)
                    for j in 0..nj {
                        for r in 0..6 {
                            st[n + r * nj + j] = work.out[(6 * j + r) * m + col];
                        }
                    }
                }
            }
        }
        work.scratch.pose = pose;
        // X0 = X(0), X1 = (X(1) − X(−1))/2, X2 = (X(1) + X(−1))/2 − X(0); per column the
        // torque coefficients, then |F_j(Δ)|² and |M_j(Δ)|² as quartics in Δ.
        let dst = &mut values[k * stride..(k + 1) * stride];
        let len = cols * block;
        let out_block = 3 * n + 10 * nj;
        let mut coef = [[0.0f64; 3]; 3];
        for p in 0..cols {
            let get = |si: usize, i: usize| work.states[si * len + p * block + i];
            let o = &mut dst[p * out_block..(p + 1) * out_block];
            for i in 0..block {
                let (x0, xp, xm) = (get(0, i), get(1, i), get(2, i));
                if !(x0.is_finite() && xp.is_finite() && xm.is_finite()) {
                    return Err((k, FailureReason::NonFinite));
                }
            }
            for a in 0..n {
                let (x0, xp, xm) = (get(0, a), get(1, a), get(2, a));
                o[a] = x0;
                o[n + a] = 0.5 * (xp - xm);
                o[2 * n + a] = 0.5 * (xp + xm) - x0;
            }
            for j in 0..nj {
                for (part, base) in [(0usize, 3 * n), (3, 3 * n + 5 * nj)] {
                    for r in 0..3 {
                        let i = n + (part + r) * nj + j;
                        let (x0, xp, xm) = (get(0, i), get(1, i), get(2, i));
                        coef[r] = [x0, 0.5 * (xp - xm), 0.5 * (xp + xm) - x0];
                    }
                    let d =
                        |u: usize, v: usize| (0..3).map(|r| coef[r][u] * coef[r][v]).sum::<f64>();
                    o[base + j] = d(0, 0);
                    o[base + nj + j] = 2.0 * d(0, 1);
                    o[base + 2 * nj + j] = d(1, 1) + 2.0 * d(0, 2);
                    o[base + 3 * nj + j] = 2.0 * d(1, 2);
                    o[base + 4 * nj + j] = d(2, 2);
                }
            }
        }
    }
    Ok(SubTaskData { stride, values })
}
