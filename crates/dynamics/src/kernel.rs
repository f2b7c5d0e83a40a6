//! The per-sample dynamics kernel shared by the fast grid path: body wrenches computed
//! directly from each parameter column (no explicit regressor), generalized forces, actuator
//! forces and the reaction right-hand sides.
//!
//! For few parameter columns this is cheaper than forming `Y` and multiplying; it computes the
//! same Newton–Euler expressions as [`crate::regressor`] (the tests compare the two paths).
//! For many columns, [`ColumnBatch`] and the `_batch` kernels evaluate all columns of a motion
//! at once from the bodies' wrench regressors, with the columns innermost (vectorised).

use counterpoise_symbolic::MAX_VARS;
use nalgebra::{Matrix3, Vector3};

use crate::lu::SmallLu;
use crate::mechanism::{BodyKin, Mechanism};
use crate::params::{BODY_PARAMS, ParameterSet, SPRING_PARAMS, SpringSlot};
use crate::regressor::{SpringFrame, WrenchRegressor, spring_wrenches};

/// Symmetric inertia from `[Ixx, Iyy, Izz, Ixy, Ixz, Iyz]`.
#[inline]
fn inertia(p: &[f64]) -> Matrix3<f64> {
    Matrix3::new(p[0], p[3], p[4], p[3], p[1], p[5], p[4], p[5], p[2])
}

/// The wrench `(F, N_o)` the world must apply to a body with parameters `pi` (see
/// [`crate::regressor`]), world axes, moment about the body frame origin.
#[inline]
pub fn body_wrench(k: &BodyKin, pi: &[f64], g: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let m = pi[0];
    let h = k.r * Vector3::new(pi[1], pi[2], pi[3]);
    let at = k.a - g;
    let force = at * m + k.alpha.cross(&h) + k.w.cross(&k.w.cross(&h));
    let wb = k.r.tr_mul(&k.w);
    let ab = k.r.tr_mul(&k.alpha);
    let io = inertia(&pi[4..BODY_PARAMS]);
    let nb = io * ab + wb.cross(&(io * wb));
    let moment = h.cross(&at) + k.r * nb;
    (force, moment)
}

/// Required wrenches of every body (inertial minus spring forces) for one column, into `w`
/// (`6L`, `[F; N]` per body).
pub fn required_wrenches(
    mech: &Mechanism,
    pose: &[f64],
    kin: &[BodyKin],
    params: &ParameterSet,
    column: usize,
    w: &mut [f64],
) {
    let col = params.column(column);
    let l = kin.len();
    for (i, k) in kin.iter().enumerate() {
        let (f, n) = body_wrench(
            k,
            &col[BODY_PARAMS * i..BODY_PARAMS * (i + 1)],
            &mech.gravity,
        );
        w[6 * i..6 * i + 3].copy_from_slice(f.as_slice());
        w[6 * i + 3..6 * i + 6].copy_from_slice(n.as_slice());
    }
    subtract_springs(mech, pose, &params.springs, &col[BODY_PARAMS * l..], w);
}

/// Subtracts the applied wrenches of a spring with lifted parameters `x` from required wrenches
/// (row `r` of the column at `w[r · stride]`).
fn subtract_spring(
    mech: &Mechanism,
    pose: &[f64],
    slot: &SpringSlot,
    x: &[f64],
    w: &mut [f64],
    stride: usize,
) {
    subtract_spring_with(slot, spring_wrenches(mech, pose, slot, x), w, stride);
}

/// Subtracts the wrenches `(F_i, N_i, F_s, N_s)` of a spring in `slot` (see
/// [`subtract_spring`]).
#[inline]
fn subtract_spring_with(
    slot: &SpringSlot,
    (fi, ni, fs, ns): (Vector3<f64>, Vector3<f64>, Vector3<f64>, Vector3<f64>),
    w: &mut [f64],
    stride: usize,
) {
    for r in 0..3 {
        w[(6 * slot.body + r) * stride] -= fi[r];
        w[(6 * slot.body + 3 + r) * stride] -= ni[r];
        if let Some(o) = slot.other {
            w[(6 * o + r) * stride] -= fs[r];
            w[(6 * o + 3 + r) * stride] -= ns[r];
        }
    }
}

/// Subtracts every spring of one column (`springs`: its lifted spring parameters, slot after
/// slot) from its required wrenches `w`.
fn subtract_springs(
    mech: &Mechanism,
    pose: &[f64],
    slots: &[SpringSlot],
    springs: &[f64],
    w: &mut [f64],
) {
    for (slot, x) in slots.iter().zip(springs.chunks_exact(SPRING_PARAMS)) {
        if x.iter().any(|&v| v != 0.0) {
            subtract_spring(mech, pose, slot, x, w, 1);
        }
    }
}

/// Like [`required_wrenches`] from precomputed wrench regressors of the bodies (cheaper when
/// many columns share one motion): `w_i = W_i π_i` minus spring forces, with `frames` the
/// [`SpringFrame`] of every slot of `params` at this pose.
pub fn required_wrenches_with(
    regressors: &[WrenchRegressor],
    frames: &[SpringFrame],
    params: &ParameterSet,
    column: usize,
    w: &mut [f64],
) {
    let col = params.column(column);
    let l = regressors.len();
    for (i, reg) in regressors.iter().enumerate() {
        let pi = &col[BODY_PARAMS * i..BODY_PARAMS * (i + 1)];
        for r in 0..6 {
            let mut acc = 0.0;
            for c in 0..BODY_PARAMS {
                acc += reg[r][c] * pi[c];
            }
            w[6 * i + r] = acc;
        }
    }
    let springs = &col[BODY_PARAMS * l..];
    for ((slot, frame), x) in params
        .springs
        .iter()
        .zip(frames)
        .zip(springs.chunks_exact(SPRING_PARAMS))
    {
        if x.iter().any(|&v| v != 0.0) {
            subtract_spring_with(slot, frame.wrenches(x), w, 1);
        }
    }
}

/// `Q_q = Σ_i J_v,iᵀ F_i + J_ω,iᵀ N_i`, then `Q_u = G⁻ᵀ Q_q` (returned).
pub fn actuator_forces(kin: &[BodyKin], w: &[f64], n: usize, lu: &SmallLu) -> [f64; MAX_VARS] {
    let mut q = [0.0; MAX_VARS];
    for (i, k) in kin.iter().enumerate() {
        let f = Vector3::new(w[6 * i], w[6 * i + 1], w[6 * i + 2]);
        let m = Vector3::new(w[6 * i + 3], w[6 * i + 4], w[6 * i + 5]);
        for j in 0..n {
            q[j] += k.jv[j].dot(&f) + k.jw[j].dot(&m);
        }
    }
    lu.solve_transpose(&mut q);
    q
}

/// Columns evaluated together in registers by the batched kernels.
const LANES: usize = 8;

/// Parameter columns laid out for batched evaluation. Variants usually share most body
/// parameters (the robot's own); per body, the most common parameter block is the *base*, and
/// only the columns whose block differs from it (a counterweight on that body) are evaluated
/// separately — with the same expression, so every column gets the value a full evaluation
/// would give.
#[derive(Clone, Debug)]
pub struct ColumnBatch {
    /// The columns of the parameter set, in batch order.
    pub columns: Vec<usize>,
    /// Per body, its base parameter block.
    base: Vec<[f64; BODY_PARAMS]>,
    /// Per body, the batch columns whose block differs from the base.
    touched: Vec<Vec<usize>>,
    /// Per body, the blocks of its touched columns: `BODY_PARAMS` rows of whole lanes.
    touched_params: Vec<Vec<f64>>,
    /// Per batch column, its spring slots with non-zero lifted parameters.
    springs: Vec<Vec<(usize, [f64; SPRING_PARAMS])>>,
}

impl ColumnBatch {
    pub fn new(params: &ParameterSet, columns: &[usize]) -> ColumnBatch {
        let body_rows = BODY_PARAMS * params.bodies;
        let block = |p: usize, i: usize| -> [f64; BODY_PARAMS] {
            params.column(p)[BODY_PARAMS * i..BODY_PARAMS * (i + 1)]
                .try_into()
                .expect("body block")
        };
        let bits = |b: &[f64; BODY_PARAMS]| b.map(f64::to_bits);
        let mut base = Vec::with_capacity(params.bodies);
        let mut touched = Vec::with_capacity(params.bodies);
        let mut touched_params = Vec::with_capacity(params.bodies);
        for i in 0..params.bodies {
            // the most common block (ties: the first seen)
            let mut counts: Vec<([u64; BODY_PARAMS], usize)> = Vec::new();
            for &p in columns {
                let key = bits(&block(p, i));
                match counts.iter_mut().find(|(k, _)| *k == key) {
                    Some((_, n)) => *n += 1,
                    None => counts.push((key, 1)),
                }
            }
            let best = counts
                .iter()
                .enumerate()
                .max_by(|(ia, (_, a)), (ib, (_, b))| a.cmp(b).then(ib.cmp(ia)))
                .map(|(_, (k, _))| *k);
            let base_block = best.map_or([0.0; BODY_PARAMS], |k| k.map(f64::from_bits));
            let list: Vec<usize> = (0..columns.len())
                .filter(|&c| bits(&block(columns[c], i)) != bits(&base_block))
                .collect();
            let stride = list.len().div_ceil(LANES) * LANES;
            let mut values = vec![0.0; BODY_PARAMS * stride];
            for (k, &c) in list.iter().enumerate() {
                for (x, v) in block(columns[c], i).iter().enumerate() {
                    values[x * stride + k] = *v;
                }
            }
            base.push(base_block);
            touched.push(list);
            touched_params.push(values);
        }
        let springs = columns
            .iter()
            .map(|&p| {
                let col = params.column(p);
                (0..params.springs.len())
                    .filter_map(|s| {
                        let off = body_rows + SPRING_PARAMS * s;
                        let x: [f64; SPRING_PARAMS] =
                            col[off..off + SPRING_PARAMS].try_into().expect("slot");
                        x.iter().any(|&v| v != 0.0).then_some((s, x))
                    })
                    .collect()
            })
            .collect();
        ColumnBatch {
            columns: columns.to_vec(),
            base,
            touched,
            touched_params,
            springs,
        }
    }

    pub fn len(&self) -> usize {
        self.columns.len()
    }

    pub fn is_empty(&self) -> bool {
        self.columns.is_empty()
    }
}

crate::simd::multiversion! {
/// [`required_wrenches_with`] for every column of `batch` into `w` (`6L` rows of
/// `batch.len()` values, row-major, rows `row_stride` apart — a block of a wider right-hand
/// side): the same expressions and summation order per column.
pub fn required_wrenches_batch(
    mech: &Mechanism,
    pose: &[f64],
    regressors: &[WrenchRegressor],
    slots: &[SpringSlot],
    batch: &ColumnBatch,
    w: &mut [f64],
    row_stride: usize,
) {
    let nc = batch.len();
    for (i, reg) in regressors.iter().enumerate() {
        // the base block, then the columns that differ, eight at a time: the six wrench rows
        // are six independent accumulators sharing each load of the parameters
        let base = &batch.base[i];
        for (r, coefficients) in reg.iter().enumerate() {
            let mut value = 0.0;
            for (c, v) in coefficients.iter().zip(base) {
                value += c * v;
            }
            let row = (6 * i + r) * row_stride;
            w[row..row + nc].fill(value);
        }
        let touched = &batch.touched[i];
        let values = &batch.touched_params[i];
        let stride = values.len() / BODY_PARAMS;
        for k0 in (0..touched.len()).step_by(LANES) {
            let mut acc = [[0.0; LANES]; 6];
            for x in 0..BODY_PARAMS {
                let pi: &[f64; LANES] = values[x * stride + k0..x * stride + k0 + LANES]
                    .try_into()
                    .expect("padded row");
                for (a, coefficients) in acc.iter_mut().zip(reg) {
                    let c = coefficients[x];
                    for l in 0..LANES {
                        a[l] += c * pi[l];
                    }
                }
            }
            for (l, &p) in touched[k0..].iter().take(LANES).enumerate() {
                for (r, a) in acc.iter().enumerate() {
                    w[(6 * i + r) * row_stride + p] = a[l];
                }
            }
        }
    }
    // The frames of every slot a column uses, once for the whole batch.
    let mut frames: Vec<Option<SpringFrame>> = vec![None; slots.len()];
    for (p, springs) in batch.springs.iter().enumerate() {
        for (s, x) in springs {
            let frame = frames[*s].get_or_insert_with(|| SpringFrame::new(mech, pose, &slots[*s]));
            subtract_spring_with(&slots[*s], frame.wrenches(x), &mut w[p..], row_stride);
        }
    }
}
}

crate::simd::multiversion! {
/// [`actuator_forces`] for `nc` columns of wrenches `w` (`6L × nc`, row-major, rows
/// `row_stride` apart) into `qu` (`n × nc`, row-major; `z` scratch). Same summation order per
/// column.
#[allow(clippy::too_many_arguments)]
pub fn actuator_forces_batch(
    kin: &[BodyKin],
    w: &[f64],
    row_stride: usize,
    nc: usize,
    n: usize,
    lu: &SmallLu,
    qu: &mut [f64],
    z: &mut Vec<f64>,
) {
    qu[..n * nc].fill(0.0);
    for (i, k) in kin.iter().enumerate() {
        let row = |r: usize| &w[(6 * i + r) * row_stride..(6 * i + r) * row_stride + nc];
        let (f0, f1, f2) = (row(0), row(1), row(2));
        let (m0, m1, m2) = (row(3), row(4), row(5));
        for j in 0..n {
            let (jv, jw) = (k.jv[j], k.jw[j]);
            let out = &mut qu[j * nc..(j + 1) * nc];
            for p in 0..nc {
                let force = jv.x * f0[p] + jv.y * f1[p] + jv.z * f2[p];
                let moment = jw.x * m0[p] + jw.y * m1[p] + jw.z * m2[p];
                out[p] += force + moment;
            }
        }
    }
    lu.solve_transpose_rows(qu, nc, z);
}
}
