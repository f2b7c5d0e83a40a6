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
//!
//! Springs are static: their forces depend on `q` only, not on `Δ`. Two parameter columns
//! with the same inertial parameters (every body block, counterweights included) therefore
//! differ by a `Δ`-independent amount in every output, `X_p(Δ) = X_r(Δ) + X_p(0) − X_r(0)`.
//! Columns are grouped by their inertial parameters; each group is represented by its inertia
//! without springs, evaluated at `Δ ∈ {0, 1, −1}`, and the columns themselves at `Δ = 0` alone.
//! Spring-only variants share the unbalanced robot's inertia, so a batch of them costs about
//! one third of the reaction solves. The representative depends on the column alone, never on
//! the rest of the batch, so a column's values are the same bits in any batch.
//!
//! Joint reactions are linear in the right-hand side of the reaction equations: per sample the
//! reaction operator `O` (see [`crate::reactions::ReactionSolver::prepare_operator`]) maps
//! every column's right-hand side at `Δ = 0` to its reactions, and each group's changes
//! `b_r(±1) − b_r(0)` to the changes `X_r(±1) − X_r(0)` — two products per group instead of
//! three. A column's reaction components are then `x₀ + Δ (D₊ − D₋)/2 + Δ² (D₊ + D₋)/2` with
//! `D±` its group's changes: at a sample at rest (`D± = 0`) every `Δ` gives the same bits,
//! so moves that share a static end pose tie exactly.

use std::collections::HashMap;

use counterpoise_symbolic::MAX_VARS;
use rayon::prelude::*;

use crate::coefficient_sweeps::*;
use crate::error::{FailureReason, TaskFailure};
use crate::evaluate_options::Combination;
use crate::indicators::{IndicatorAccumulator, StatsTable};
use crate::kernel::{ColumnBatch, actuator_forces_batch, required_wrenches_batch};
use crate::law::{quintic, quintic_move, sample_time};
use crate::lu::SmallLu;
use crate::mechanism::{BodyKin, Scratch};
use crate::params::ParameterSet;
use crate::progress::{GridProgress, Ticker};
use crate::reactions::ReactionWork;
use crate::regressor::{WrenchRegressor, wrench_regressor};
use crate::runner::Evaluator;
use crate::superposition::*;
use crate::symmetry::Cyclic;
use crate::tasks::TaskSet;

/// Every how many sub-tasks one is evaluated in full first, to seed the reaction floors.
const SEED_STRIDE: usize = 8;

#[derive(Default)]
struct Work {
    scratch: Scratch,
    kin: Vec<BodyKin>,
    regressors: Vec<WrenchRegressor>,
    reactions_work: ReactionWork,
    /// Required wrenches of a batch of columns, `[body row][column]`.
    wb: Vec<f64>,
    /// Actuator forces of a batch of columns, `[actuator][column]`.
    qb: Vec<f64>,
    lu_scratch: Vec<f64>,
    b: Vec<f64>,
    out: Vec<f64>,
    /// Motor torques at `Δ ∈ {0, 1, −1}`: `[Δ][actuator][column]`.
    torques: Vec<f64>,
    /// Motor torques of the group representatives at `Δ = ±1`: `[Δ][actuator][group]`.
    rep_torques: Vec<f64>,
    /// With [`Superposition`]: every column's motor torques, `[Δ][actuator][column]`, summed
    /// from the basis columns' in `torques`.
    sum_torques: Vec<f64>,
    /// With [`Superposition`]: every column's reaction components, per component row
    /// `[Δ = 0 | unused | change to +1 | change to −1]`, `cols` each (the layout of `out` with
    /// every column its own group).
    sum_out: Vec<f64>,
    /// With [`Superposition`] or [`InertiaSums`]: the buffers of the sums.
    sums: SumScratch,
    /// With [`InertiaSums`]: the basis's torque changes to `Δ = ±1`, `[±][actuator][basis]`.
    basis_changes: Vec<f64>,
    /// With [`InertiaSums`]: every group's torque changes, `[±][actuator][group]`.
    group_torque_changes: Vec<f64>,
    /// With [`InertiaSums`]: zeros, one per group.
    no_change: Vec<f64>,
    /// With [`InertiaSums`]: every group's reaction component changes,
    /// `[component row][+1 groups | −1 groups]`.
    group_changes: Vec<f64>,
    /// Coefficients of the current sub-task, per sample (`stride` values): the motor torques
    /// as quadratics in `Δ` — three arrays `[actuator][column]` — then, with reactions,
    /// `|F_j|²` and `|M_j|²` as quartics — five arrays `[force/moment][joint][column]`.
    /// Columns run innermost so that every task evaluation is a contiguous, vectorisable
    /// sweep. Reused from sub-task to sub-task (every value is overwritten).
    coefficients: Vec<f64>,
    /// Running sums and peaks of [`task_stats`], reused from sub-task to sub-task (fresh
    /// megabyte-sized buffers per sub-task cost more in page faults than the sums themselves).
    stats: StatsScratch,
}

#[derive(Default)]
struct StatsScratch {
    sum_sq: Vec<f64>,
    peak: Vec<f64>,
    total_peak: Vec<f64>,
    reaction_peak: Vec<f64>,
    tau: Vec<f64>,
    abs_sum: Vec<f64>,
    /// A spent [`TaskRows`] buffer handed back for the next sub-task.
    rows: Vec<f64>,
    /// Per reaction row, the bound of its peak over the sub-task.
    bound: Vec<f64>,
    /// The active rows' coefficients at two samples and their peaks per task.
    compact: Vec<f64>,
}

/// Outcome of one sub-task: the statistics of its distinct tasks and, per task, which one
/// it is; or the failure of the sub-task.
type SubTaskOutcome = Result<(TaskRows, Vec<(usize, usize)>), Vec<TaskFailure>>;

/// Statistics rows of the distinct tasks of one sub-task: per task, per column, one row in
/// the layout of [`StatsTable`].
struct TaskRows {
    width: usize,
    cols: usize,
    data: Vec<f64>,
}

impl TaskRows {
    fn len(&self) -> usize {
        self.data.len() / (self.width * self.cols).max(1)
    }

    fn task(&self, t: usize) -> &[f64] {
        let n = self.width * self.cols;
        &self.data[t * n..(t + 1) * n]
    }
}

/// Where the statistics of the grid go: a table of every task and column, or running maxima
/// (the indicators only, a few values per column).
pub(crate) enum GridSink<'a> {
    Table(&'a mut StatsTable),
    Maxima(&'a mut IndicatorAccumulator),
}

/// Runs the grid through the cyclic decomposition into `sink`; returns the failures in task
/// order and the number of distinct moves evaluated. `progress` hears of every sub-task as it
/// ends (counted inside the parallel loops, whatever the sink).
#[allow(clippy::too_many_arguments)]
pub(crate) fn evaluate_cyclic(
    ev: &Evaluator,
    cyc: Cyclic,
    tasks: &TaskSet,
    params: &ParameterSet,
    with_reactions: bool,
    combination: Combination,
    sink: GridSink,
    progress: GridProgress,
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
    let groups = InertiaGroups::new(params);
    let superposition = (combination == Combination::Superposition)
        .then(|| Superposition::new(&crate::params::model_body_params(ev.model), params));
    let inertia_sums = (combination == Combination::InertiaSuperposition)
        .then(|| InertiaSums::new(&crate::params::model_body_params(ev.model), &groups));
    let one_sub_task = |work: &mut Work, st: usize, floor: Option<&[f64]>| -> SubTaskOutcome {
        let (s1, s2) = st_pairs[st];
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
        // With floors, the reaction rows' bounds over the tasks' largest step are summed as the
        // quartics are formed (see `reaction_rows_above`).
        let reach = (floor.is_some() && nj > 0).then(|| largest_step(&unique));
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
                &groups,
                superposition.as_ref(),
                inertia_sums.as_ref(),
                combination == Combination::Substitution,
                with_reactions,
                per_sample_stride,
                reach,
                work,
            ),
        };
        match data {
            Ok(()) => {}
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
        }
        let rows = task_stats(
            &work.coefficients,
            per_sample_stride,
            &unique,
            ns,
            params.len(),
            na,
            nj,
            floor,
            &mut work.stats,
        );
        Ok((rows, users[st].iter().map(|u| u.0).zip(slot).collect()))
    };
    let ticker = Ticker::start(progress, st_pairs.len());
    let mut distinct = 0;
    match sink {
        GridSink::Table(table) => {
            let computed: Vec<SubTaskOutcome> = (0..st_pairs.len())
                .into_par_iter()
                .map_init(Work::default, |work, st| {
                    let outcome = one_sub_task(work, st, None);
                    ticker.tick();
                    outcome
                })
                .collect();
            for outcome in computed {
                match outcome {
                    Ok((rows, assignment)) => {
                        distinct += rows.len();
                        for (w, u) in assignment {
                            table.set_rows(w, rows.task(u));
                        }
                    }
                    Err(f) => failures.extend(f),
                }
            }
        }
        GridSink::Maxima(acc) => {
            // Each worker folds its sub-tasks into its own maxima; the merge is order-free
            // (ties to the lowest task), so the result does not depend on the split.
            //
            // Two rounds: every `SEED_STRIDE`-th sub-task in full, then the others with the
            // seeds' reaction peaks as a floor — a joint reaction row whose bound over a
            // sub-task stays below the peak already reached elsewhere cannot be the maximum,
            // and its quartics are not evaluated (the maxima are the same bits).
            let empty = IndicatorAccumulator::new(acc.columns, acc.actuators, acc.joints);
            let round = |sts: Vec<usize>, floor: Option<&[f64]>| {
                sts.into_par_iter()
                    .fold(
                        || (Work::default(), empty.clone(), Vec::new(), 0usize),
                        |(mut work, mut m, mut failed, mut count), st| {
                            let outcome = one_sub_task(&mut work, st, floor);
                            ticker.tick();
                            match outcome {
                                Ok((rows, assignment)) => {
                                    count += rows.len();
                                    for (w, u) in assignment {
                                        m.add_rows(w, rows.task(u));
                                    }
                                    work.stats.rows = rows.data;
                                }
                                Err(f) => failed.extend(f),
                            }
                            (work, m, failed, count)
                        },
                    )
                    .map(|(_, m, failed, count)| ((), m, failed, count))
                    .reduce(
                        || ((), empty.clone(), Vec::new(), 0usize),
                        |(_, m, mut f1, c1), (_, other, f2, c2)| {
                            f1.extend(f2);
                            ((), m.merge(&other), f1, c1 + c2)
                        },
                    )
            };
            let (seeds, rest): (Vec<usize>, Vec<usize>) =
                (0..st_pairs.len()).partition(|st| st % SEED_STRIDE == 0);
            let (_, seeded, mut failed, mut count) = round(seeds, None);
            let floor = (nj > 0).then(|| seeded.reaction_floor(FLOOR_MARGIN));
            let (_, others, failed_others, count_others) = round(rest, floor.as_deref());
            failed.extend(failed_others);
            count += count_others;
            let maxima = seeded.merge(&others);
            *acc = acc.clone().merge(&maxima);
            failures.extend(failed);
            distinct = count;
        }
    }
    failures.sort_by_key(|f| f.task);
    (failures, distinct)
}

crate::simd::multiversion! {
/// Statistics of every `(reversed, Δ)` task of one sub-task. Samples run in the outer loop
/// so that a sample's coefficients are read from cache once for all the tasks; within a task
/// every step is a contiguous sweep over the columns of one actuator or joint.
fn task_stats(
    coefficients: &[f64],
    stride: usize,
    tasks: &[(bool, f64)],
    ns: usize,
    cols: usize,
    na: usize,
    nj: usize,
    floor: Option<&[f64]>,
    scratch: &mut StatsScratch,
) -> TaskRows {
    let nt = tasks.len();
    let tq = na * cols;
    let rq = 2 * nj * cols;
    // Reaction rows that may reach their floor (see `reaction_rows_above`, the bounds formed
    // by `sub_task` whenever there are floors); `None`: every row.
    let active = match floor {
        Some(floor) if nj > 0 => Some(reaction_rows_above(&scratch.bound[..rq], floor)),
        _ => None,
    };
    let sum_sq = zeroed(&mut scratch.sum_sq, nt * tq);
    let peak = zeroed(&mut scratch.peak, nt * tq);
    let total_peak = zeroed(&mut scratch.total_peak, nt * cols);
    // peaks of |F|², |M|² (square roots taken once at the end)
    let reaction_peak = zeroed(&mut scratch.reaction_peak, nt * rq);
    let tau = zeroed(&mut scratch.tau, tq);
    let abs_sum = zeroed(&mut scratch.abs_sum, cols);
    // (Blocking the columns so that a block's sums stay in L2 was measured slower: the
    // coefficients are then read in short strided runs.)
    {
        for k in 0..ns {
            for (t, &(rev, delta)) in tasks.iter().enumerate() {
                let dd = if rev { -delta } else { delta };
                let d2 = dd * dd;
                let kk = if rev { ns - 1 - k } else { k };
                let base = &coefficients[kk * stride..(kk + 1) * stride];
                let (t0, rest) = base.split_at(tq);
                let (t1, rest) = rest.split_at(tq);
                let (t2, rest) = rest.split_at(tq);
                abs_sum.fill(0.0);
                for a in 0..na {
                    let r = a * cols..(a + 1) * cols;
                    let tau = &mut tau[r.clone()];
                    let (t0, t1, t2) = (&t0[r.clone()], &t1[r.clone()], &t2[r.clone()]);
                    let ss = &mut sum_sq[t * tq..(t + 1) * tq][r.clone()];
                    let pk = &mut peak[t * tq..(t + 1) * tq][r];
                    for i in 0..tau.len() {
                        tau[i] = t0[i] + dd * t1[i] + d2 * t2[i];
                    }
                    for i in 0..tau.len() {
                        ss[i] += tau[i] * tau[i];
                        let x = tau[i].abs();
                        if x > pk[i] {
                            pk[i] = x;
                        }
                    }
                    for (s, x) in abs_sum.iter_mut().zip(tau.iter()) {
                        *s += x.abs();
                    }
                }
                for (m, &s) in total_peak[t * cols..(t + 1) * cols]
                    .iter_mut()
                    .zip(abs_sum.iter())
                {
                    if s > *m {
                        *m = s;
                    }
                }
                if nj > 0 && active.is_none() {
                    let pk = &mut reaction_peak[t * rq..(t + 1) * rq];
                    quartic_peak_update(quartic_arrays(rest, rq), dd, pk);
                }
            }
        }
    }
    if let Some(active) = &active {
        pruned_reaction_peaks(
            coefficients,
            stride,
            3 * tq,
            rq,
            ns,
            tasks,
            active,
            reaction_peak,
            &mut scratch.compact,
        );
    }
    let width = 2 * na + 1 + 2 * nj;
    let n = ns.max(1) as f64;
    // every value is written below
    let mut data = std::mem::take(&mut scratch.rows);
    data.clear();
    data.resize(nt * cols * width, 0.0);
    for t in 0..nt {
        for p in 0..cols {
            let row = &mut data[(t * cols + p) * width..(t * cols + p + 1) * width];
            for a in 0..na {
                row[a] = (sum_sq[t * tq + a * cols + p] / n).sqrt();
                row[na + a] = peak[t * tq + a * cols + p];
            }
            row[2 * na] = total_peak[t * cols + p];
            for part in 0..2 {
                for j in 0..nj {
                    let v = reaction_peak[t * rq + (part * nj + j) * cols + p];
                    row[2 * na + 1 + part * nj + j] = v.max(0.0).sqrt();
                }
            }
        }
    }
    TaskRows { width, cols, data }
}
}

/// Evaluates one sub-task at `Δ ∈ {0, 1, −1}` per sample and stores the coefficients in
/// `work.coefficients`; with `reach` (the tasks' largest `|Δ|`), also each reaction row's bound
/// over the samples in `work.stats.bound` ([`quartic_bound_max`], on each slot's quartics
/// while they are in cache).
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
    groups: &InertiaGroups,
    superposition: Option<&Superposition>,
    inertia_sums: Option<&InertiaSums>,
    substitute: bool,
    with_reactions: bool,
    stride: usize,
    reach: Option<f64>,
    work: &mut Work,
) -> Result<(), (usize, FailureReason)> {
    let mech = &ev.mech;
    let n = mech.n;
    let l = mech.body_count;
    // The columns evaluated: the batch's own, or the superposition's basis.
    let (params_in, groups) = match superposition {
        Some(sup) => (params, &sup.groups),
        None => (params, groups),
    };
    let params = match superposition {
        Some(sup) => &sup.basis,
        None => params_in,
    };
    let cols = params.len();
    // The columns whose coefficients are stored.
    let out_cols = params_in.len();
    let nj = if with_reactions {
        ev.reactions.joint_count()
    } else {
        0
    };
    let rows = 6 * l;
    let tq = n * cols;
    let rq = 2 * nj * out_cols;
    // The representatives evaluated at every Δ: the groups', or the basis of their sums.
    let (rep_batch, rep_slots) = match inertia_sums {
        Some(sums) => (&sums.batch, &sums.basis.springs),
        None => (&groups.rep_batch, &groups.rep_params.springs),
    };
    let nreps = rep_batch.len();
    // right-hand sides solved: every column at Δ = 0, the representatives at Δ = 0, ±1
    let solved = cols + 3 * nreps;
    work.coefficients.resize(ns * stride, 0.0);
    let mut q = q0.to_vec();
    let mut u = [0.0; MAX_VARS];
    let mut ud = [0.0; MAX_VARS];
    let mut udd = [0.0; MAX_VARS];
    let mut f = [0.0; MAX_VARS];
    let mut g = [0.0; MAX_VARS * MAX_VARS];
    work.torques.resize(3 * tq, 0.0);
    work.rep_torques.resize(3 * n * nreps, 0.0);
    if with_reactions {
        work.b.resize(rows * solved, 0.0);
        work.out.resize(6 * nj * solved, 0.0);
    }
    let reach = reach.filter(|_| with_reactions);
    if reach.is_some() {
        zeroed(&mut work.stats.bound, rq);
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
                .prepare(mech, &pose, &work.kin, &lu, &mut work.reactions_work);
            if !substitute {
                ev.reactions.prepare_operator(&mut work.reactions_work);
            }
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
            work.regressors.clear();
            for (b, kin) in work.kin.iter_mut().enumerate() {
                mech.set_motion(&pose, b, kin, &qd, &qdd);
                work.regressors.push(wrench_regressor(kin, &mech.gravity));
            }
            // Every column at Δ = 0; the representatives at every Δ. One wrench regressor per
            // body serves all the columns of a batch, whatever its size, so that a column's
            // arithmetic is the same in every batch.
            let representatives = (true, rep_batch);
            let jobs: &[(bool, &ColumnBatch)] = if si == 0 {
                &[(false, &groups.all), representatives]
            } else {
                &[representatives]
            };
            for &(is_rep, batch) in jobs {
                let nc = batch.len();
                // the batch's first right-hand side among those solved
                let first = if is_rep { cols + si * nreps } else { 0 };
                let slots = if is_rep { rep_slots } else { &params.springs };
                // The wrenches go straight into the batch's block of the right-hand sides
                // (rows `solved` apart), or into a buffer of their own without reactions.
                let (w, row_stride) = if with_reactions {
                    (&mut work.b[first..], solved)
                } else {
                    work.wb.resize(rows * nc, 0.0);
                    (&mut work.wb[..], nc)
                };
                work.qb.resize(n * nc, 0.0);
                required_wrenches_batch(mech, &pose, &work.regressors, slots, batch, w, row_stride);
                actuator_forces_batch(
                    &work.kin,
                    w,
                    row_stride,
                    nc,
                    n,
                    &lu,
                    &mut work.qb,
                    &mut work.lu_scratch,
                );
                for c in 0..nc {
                    let mut qu = [0.0; MAX_VARS];
                    for a in 0..n {
                        qu[a] = work.qb[a * nc + c];
                    }
                    for a in 0..n {
                        let torque = qu[a] * ev.ratios[a];
                        if is_rep {
                            work.rep_torques[(si * n + a) * nreps + c] = torque;
                        } else {
                            work.torques[a * cols + c] = torque;
                        }
                    }
                }
                if with_reactions {
                    ev.reactions.subtract_actuators_batch(
                        &work.reactions_work,
                        &work.kin,
                        &work.qb,
                        nc,
                        w,
                        row_stride,
                    );
                }
            }
        }
        if with_reactions {
            // The representatives' reactions are needed only as the changes from Δ = 0 to
            // Δ = ±1, `O (b_r(±1) − b_r(0))`: their right-hand sides at Δ = 0 are subtracted and
            // not applied (two products per group instead of three).
            for r in 0..rows {
                let row = &mut work.b[r * solved + cols..(r + 1) * solved];
                let (at_zero, at_pm) = row.split_at_mut(nreps);
                for (d, z) in at_pm.iter_mut().zip(at_zero.iter().cycle()) {
                    *d -= z;
                }
            }
            let ops = &ev.reactions;
            if substitute {
                // Every right-hand side by substitution (the representatives' at Δ = 0 too,
                // whose reactions are not read).
                ops.solve_prepared(&mut work.reactions_work, &mut work.b, solved, &mut work.out);
            } else {
                let (b, out) = (&work.b, &mut work.out);
                ops.apply_operator(&work.reactions_work, b, solved, cols, out);
                let pm = cols + nreps;
                ops.apply_operator(
                    &work.reactions_work,
                    &b[pm..],
                    solved,
                    2 * nreps,
                    &mut out[pm..],
                );
            }
        }
        work.scratch.pose = pose;
        // Every (evaluated) column at Δ = ±1 from its representative:
        // X_p(±1) = X_r(±1) + X_p(0) − X_r(0).
        if let Some(sums) = inertia_sums {
            // X_p(±1) = X_p(0) + D_g(±), the group's change summed over the basis's changes.
            let ng = sums.groups();
            work.basis_changes.resize(2 * n * nreps, 0.0);
            for side in 0..2 {
                for a in 0..n {
                    let at = |d: usize| &work.rep_torques[(d * n + a) * nreps..][..nreps];
                    let (to, zero) = (at(side + 1), at(0));
                    let dst = &mut work.basis_changes[(side * n + a) * nreps..][..nreps];
                    for ((d, &x), &z) in dst.iter_mut().zip(to).zip(zero) {
                        *d = x - z;
                    }
                }
            }
            work.group_torque_changes.resize(2 * n * ng, 0.0);
            sums.changes(
                &work.basis_changes,
                nreps,
                0,
                2 * n,
                &mut work.group_torque_changes,
                ng,
                0,
                &mut work.sums,
            );
            work.no_change.clear();
            work.no_change.resize(ng, 0.0);
            let (at_zero, at_pm) = work.torques.split_at_mut(tq);
            for si in 0..2 {
                for a in 0..n {
                    let zero = &at_zero[a * cols..(a + 1) * cols];
                    let change = &work.group_torque_changes[(si * n + a) * ng..][..ng];
                    let dst = &mut at_pm[(si * n + a) * cols..(si * n + a + 1) * cols];
                    groups.expand(dst, change, zero, &work.no_change);
                }
            }
        } else {
            let (at_zero, at_pm) = work.torques.split_at_mut(tq);
            for si in 0..2 {
                for a in 0..n {
                    let zero = &at_zero[a * cols..(a + 1) * cols];
                    let reps =
                        |d: usize| &work.rep_torques[(d * n + a) * nreps..(d * n + a + 1) * nreps];
                    let dst = &mut at_pm[(si * n + a) * cols..(si * n + a + 1) * cols];
                    groups.expand(dst, reps(si + 1), zero, reps(0));
                }
            }
        }
        // With inertia sums, every group's reaction changes to Δ = +1 and −1:
        // `[component row][+1 groups | −1 groups]`.
        if let (Some(sums), true) = (inertia_sums, with_reactions) {
            let ng = sums.groups();
            let len = 6 * nj;
            work.group_changes.resize(len * 2 * ng, 0.0);
            for side in 0..2 {
                sums.changes(
                    &work.out,
                    solved,
                    cols + (1 + side) * nreps,
                    len,
                    &mut work.group_changes,
                    2 * ng,
                    side * ng,
                    &mut work.sums,
                );
            }
        }
        // The stored columns' values: the evaluated ones, or their sums over the basis.
        let (torques, out, solved, nreps, group, cols) = match superposition {
            Some(sup) => {
                sup.torques(&work.torques, n, &mut work.sum_torques, &mut work.sums);
                if with_reactions {
                    sup.reactions(&work.out, solved, 6 * nj, &mut work.sum_out, &mut work.sums);
                }
                let c = out_cols;
                let group = &sup.identity[..];
                (&work.sum_torques[..], &work.sum_out[..], 4 * c, c, group, c)
            }
            None => (
                &work.torques[..],
                &work.out[..],
                solved,
                nreps,
                &groups.group[..],
                cols,
            ),
        };
        let tq = n * cols;
        // Each component row's groups' changes to Δ = +1 and −1.
        let ng = inertia_sums.map_or(nreps, InertiaSums::groups);
        let changes_of = |row: usize| -> (&[f64], &[f64]) {
            let both = match inertia_sums {
                Some(_) => &work.group_changes[row * 2 * ng..(row + 1) * 2 * ng],
                None => &out[row * solved + cols + nreps..(row + 1) * solved],
            };
            both.split_at(ng)
        };
        let mut finite = all_finite(torques);
        if with_reactions {
            // every column at Δ = 0 and every group's change
            for row in 0..6 * nj {
                let (plus, minus) = changes_of(row);
                finite &= all_finite(&out[row * solved..row * solved + cols]);
                finite &= all_finite(plus) && all_finite(minus);
            }
        }
        if !finite {
            return Err((k, FailureReason::NonFinite));
        }
        // X0 = X(0), X1 = (X(1) − X(−1))/2, X2 = (X(1) + X(−1))/2 − X(0), per column; then
        // |F_j(Δ)|² and |M_j(Δ)|² as quartics in Δ from the three components' quadratics.
        let dst = &mut work.coefficients[k * stride..(k + 1) * stride];
        let (torque_coefs, reaction_coefs) = dst.split_at_mut(3 * tq);
        let (tc0, rest) = torque_coefs.split_at_mut(tq);
        let (tc1, tc2) = rest.split_at_mut(tq);
        let (x0, rest) = torques.split_at(tq);
        let (xp, xm) = rest.split_at(tq);
        quadratic_coefficients([x0, xp, xm], [tc0, tc1, tc2]);
        if with_reactions {
            let (q0, rest) = reaction_coefs.split_at_mut(rq);
            let (q1, rest) = rest.split_at_mut(rq);
            let (q2, rest) = rest.split_at_mut(rq);
            let (q3, q4) = rest.split_at_mut(rq);
            for part in 0..2 {
                for j in 0..nj {
                    let slot = (part * nj + j) * cols..(part * nj + j + 1) * cols;
                    // the three components: every column at Δ = 0, the groups' changes to
                    // Δ = +1 and −1
                    let component = |r: usize| {
                        let row = 6 * j + 3 * part + r;
                        let x0 = &out[row * solved..][..cols];
                        let (plus, minus) = changes_of(row);
                        [x0, plus, minus]
                    };
                    squared_norm_quartic(
                        group,
                        [component(0), component(1), component(2)],
                        [
                            &mut q0[slot.clone()],
                            &mut q1[slot.clone()],
                            &mut q2[slot.clone()],
                            &mut q3[slot.clone()],
                            &mut q4[slot.clone()],
                        ],
                    );
                    if let Some(d) = reach {
                        quartic_bound_max(
                            [
                                &q0[slot.clone()],
                                &q1[slot.clone()],
                                &q2[slot.clone()],
                                &q3[slot.clone()],
                                &q4[slot.clone()],
                            ],
                            d,
                            &mut work.stats.bound[slot],
                        );
                    }
                }
            }
        }
    }
    Ok(())
}
