//! The sweeps over coefficient arrays of the cyclic grid evaluation (`fast`): finiteness,
//! quadratic and quartic coefficients, peak bounds and peak updates.
//!
//! Each is a contiguous, vectorisable loop, multiversioned for FMA (the arithmetic is the same
//! fused multiply-adds on every path); they hold no state of the evaluation, so they sit apart
//! from it.

/// `v` as `n` zeros, reusing its allocation.
pub(crate) fn zeroed(v: &mut Vec<f64>, n: usize) -> &mut [f64] {
    v.clear();
    v.resize(n, 0.0);
    v
}
crate::simd::multiversion! {
/// Whether every value is finite (a branch-free reduction the compiler vectorises).
pub(crate) fn all_finite(xs: &[f64]) -> bool {
    !xs.iter().fold(false, |bad, x| bad | !x.is_finite())
}
}

crate::simd::multiversion! {
/// `dst[p] = rep[g] + (zero[p] − rep_zero[g])` with `g = group[p]` (see
/// [`InertiaGroups::expand`]).
pub(crate) fn expand_from_groups(group: &[u32], dst: &mut [f64], rep: &[f64], zero: &[f64], rep_zero: &[f64]) {
    let n = rep.len().min(rep_zero.len());
    assert!(group.iter().all(|&g| (g as usize) < n), "group index out of range");
    for ((d, &g), &z) in dst.iter_mut().zip(group).zip(zero) {
        let g = g as usize;
        // SAFETY: every group index is below the length of `rep` and `rep_zero` (asserted
        // above); unchecked loads let the compiler gather them in vectors.
        let (r, r0) = unsafe { (*rep.get_unchecked(g), *rep_zero.get_unchecked(g)) };
        *d = r + (z - r0);
    }
}
}

crate::simd::multiversion! {
/// The coefficients of `X(Δ) = X₀ + Δ X₁ + Δ² X₂` from its values at `Δ = 0, 1, −1`:
/// `X₀ = X(0)`, `X₁ = (X(1) − X(−1))/2`, `X₂ = (X(1) + X(−1))/2 − X(0)`.
pub(crate) fn quadratic_coefficients(x: [&[f64]; 3], c: [&mut [f64]; 3]) {
    let [x0, xp, xm] = x;
    let [c0, c1, c2] = c;
    let n = x0.len();
    let (xp, xm, c0, c1, c2) = (&xp[..n], &xm[..n], &mut c0[..n], &mut c1[..n], &mut c2[..n]);
    for i in 0..n {
        c0[i] = x0[i];
        c1[i] = 0.5 * (xp[i] - xm[i]);
        c2[i] = 0.5 * (xp[i] + xm[i]) - x0[i];
    }
}
}

crate::simd::multiversion! {
/// `|X(Δ)|²` of a three-component vector whose components are quadratics in `Δ`, as the five
/// coefficients of a quartic, per column. Component `i` of column `p` is given by its value
/// `x0` at `Δ = 0` and its group's changes `plus`, `minus` to `Δ = +1` and `−1`:
/// `X(Δ) = x0 + Δ (plus − minus)/2 + Δ² (plus + minus)/2`. Fused multiply-adds, components
/// in order.
pub(crate) fn squared_norm_quartic(group: &[u32], components: [[&[f64]; 3]; 3], q: [&mut [f64]; 5]) {
    let [q0, q1, q2, q3, q4] = q;
    let n = q0.len();
    let (q1, q2, q3, q4) = (&mut q1[..n], &mut q2[..n], &mut q3[..n], &mut q4[..n]);
    let group = &group[..n];
    let [[a0, ap, am], [b0, bp, bm], [d0, dp, dm]] = components;
    let (a0, b0, d0) = (&a0[..n], &b0[..n], &d0[..n]);
    let groups = ap.len().min(am.len()).min(bp.len()).min(bm.len()).min(dp.len()).min(dm.len());
    assert!(group.iter().all(|&g| (g as usize) < groups), "group index out of range");
    #[inline(always)]
    pub(crate) fn coefficients(x0: f64, changes: [&[f64]; 2], g: usize) -> [f64; 3] {
        // SAFETY: `g` is below the length of both change slices (asserted by the caller);
        // unchecked loads let the compiler gather them in vectors.
        let (plus, minus) = unsafe { (*changes[0].get_unchecked(g), *changes[1].get_unchecked(g)) };
        [x0, 0.5 * (plus - minus), 0.5 * (plus + minus)]
    }
    for p in 0..n {
        let g = group[p] as usize;
        let [a0, a1, a2] = coefficients(a0[p], [ap, am], g);
        let [b0, b1, b2] = coefficients(b0[p], [bp, bm], g);
        let [d0, d1, d2] = coefficients(d0[p], [dp, dm], g);
        q0[p] = d0.mul_add(d0, b0.mul_add(b0, a0 * a0));
        q1[p] = 2.0 * d0.mul_add(d1, b0.mul_add(b1, a0 * a1));
        let cross = d0.mul_add(d2, b0.mul_add(b2, a0 * a2));
        q2[p] = d1.mul_add(d1, b1.mul_add(b1, a1.mul_add(a1, 2.0 * cross)));
        q3[p] = 2.0 * d1.mul_add(d2, b1.mul_add(b2, a1 * a2));
        q4[p] = d2.mul_add(d2, b2.mul_add(b2, a2 * a2));
    }
}
}

/// Relative margin between a reaction row's bound and its floor: far above the rounding of
/// the bound and of the quartic's evaluation (a few units in the last place), so a row is
/// skipped only when its peak is certainly below a value reached elsewhere.
pub(crate) const FLOOR_MARGIN: f64 = 1e-12;

/// The flat indices `row · cols + column` of the reaction rows whose peak over the sub-task can
/// reach `floor`, from each row's `bound`: `max_k Σ_i |c_i| D^i` over the samples, with `D` the
/// largest `|Δ|` of the tasks ([`quartic_bound_max`], summed as each sample's quartics are
/// formed), which bounds every task's `|F|²` or `|M|²` (the computed quartic exceeds its exact
/// value by far less than [`FLOOR_MARGIN`]).
pub(crate) fn reaction_rows_above(bound: &[f64], floor: &[f64]) -> Vec<usize> {
    (0..bound.len())
        .filter(|&i| bound[i] * (1.0 + FLOOR_MARGIN) >= floor[i])
        .collect()
}

/// The largest `|Δ|` of a sub-task's `(reversed, Δ)` tasks: the `D` of [`quartic_bound_max`].
pub(crate) fn largest_step(tasks: &[(bool, f64)]) -> f64 {
    tasks
        .iter()
        .fold(0.0f64, |m, &(_, delta)| m.max(delta.abs()))
}

crate::simd::multiversion! {
/// `bound[i] = max(bound[i], Σ_p |c_p[i]| d^p)` for the five coefficient arrays `c`.
pub(crate) fn quartic_bound_max(c: [&[f64]; 5], d: f64, bound: &mut [f64]) {
    let n = bound.len();
    let [c0, c1, c2, c3, c4] = c.map(|x| &x[..n]);
    for i in 0..n {
        let b = c4[i]
            .abs()
            .mul_add(d, c3[i].abs())
            .mul_add(d, c2[i].abs())
            .mul_add(d, c1[i].abs())
            .mul_add(d, c0[i].abs());
        if b > bound[i] {
            bound[i] = b;
        }
    }
}
}

/// The reaction peaks of the `active` rows only (the others stay 0: below their floor), from
/// the rows' coefficients gathered per sample into contiguous arrays. Same arithmetic as the
/// full sweep of [`task_stats`].
#[allow(clippy::too_many_arguments)]
pub(crate) fn pruned_reaction_peaks(
    coefficients: &[f64],
    stride: usize,
    offset: usize,
    rq: usize,
    ns: usize,
    tasks: &[(bool, f64)],
    active: &[usize],
    reaction_peak: &mut [f64],
    compact: &mut Vec<f64>,
) {
    let n = active.len();
    if n == 0 {
        return;
    }
    let nt = tasks.len();
    // [forward sample: 5 × n | reversed sample: 5 × n | peaks: nt × n]
    let compact = zeroed(compact, 10 * n + nt * n);
    let (samples, peaks) = compact.split_at_mut(10 * n);
    let gather = |dst: &mut [f64], kk: usize| {
        let base = &coefficients[kk * stride + offset..kk * stride + offset + 5 * rq];
        for p in 0..5 {
            for (x, &i) in dst[p * n..(p + 1) * n].iter_mut().zip(active) {
                *x = base[p * rq + i];
            }
        }
    };
    for k in 0..ns {
        let (forward, reversed) = samples.split_at_mut(5 * n);
        gather(forward, k);
        gather(reversed, ns - 1 - k);
        for (t, &(rev, delta)) in tasks.iter().enumerate() {
            let dd = if rev { -delta } else { delta };
            let c = if rev { &*reversed } else { &*forward };
            quartic_peak_max(c, n, dd, &mut peaks[t * n..(t + 1) * n]);
        }
    }
    for t in 0..nt {
        for (p, &i) in active.iter().enumerate() {
            reaction_peak[t * rq + i] = peaks[t * n + p];
        }
    }
}

crate::simd::multiversion! {
/// `peak[i] = max(peak[i], ((((c4 Δ + c3) Δ + c2) Δ + c1) Δ + c0)[i])` by fused multiply-adds
/// (the arithmetic of [`task_stats`]), for the five contiguous coefficient arrays of `c`.
pub(crate) fn quartic_peak_max(c: &[f64], n: usize, dd: f64, peak: &mut [f64]) {
    quartic_peak_update(quartic_arrays(c, n), dd, peak);
}
}

/// The five coefficient arrays `[c0, …, c4]` of `n` values each at the start of `c`.
#[inline(always)]
pub(crate) fn quartic_arrays(c: &[f64], n: usize) -> [&[f64]; 5] {
    std::array::from_fn(|p| &c[p * n..(p + 1) * n])
}

/// `peak[i] = max(peak[i], ((((c4 Δ + c3) Δ + c2) Δ + c1) Δ + c0)[i])` by fused multiply-adds,
/// for the coefficient arrays `c = [c0, …, c4]` (as long as `peak`).
#[inline(always)]
pub(crate) fn quartic_peak_update(c: [&[f64]; 5], dd: f64, peak: &mut [f64]) {
    let n = peak.len();
    let [c0, c1, c2, c3, c4] = c.map(|x| &x[..n]);
    for i in 0..n {
        let v = c4[i]
            .mul_add(dd, c3[i])
            .mul_add(dd, c2[i])
            .mul_add(dd, c1[i])
            .mul_add(dd, c0[i]);
        if v > peak[i] {
            peak[i] = v;
        }
    }
}
