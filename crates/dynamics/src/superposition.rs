//! Parameter columns grouped by their inertia, and reactions by superposition over a basis.
//!
//! The cyclic grid evaluation (`fast`) evaluates few columns per sample and sums the others
//! from them; these are the groupings and the sums, in the terms' order so that a column's bits
//! do not depend on its batch (see `fast`'s module doc).

use std::collections::HashMap;

use crate::coefficient_sweeps::*;
use crate::kernel::ColumnBatch;
use crate::params::ParameterSet;

/// Parameter columns grouped by their inertial parameters (see the module doc).
///
/// Each group is represented by a column of its own: the group's inertial parameters with no
/// springs. A column's value at `Δ = ±1` is then `X_r(±1) + X_p(0) − X_r(0)` with `r` fixed by
/// the column's inertia alone, so its bits do not depend on which other columns share the batch
/// (a sharded study merges into exactly the single run's result).
pub(crate) struct InertiaGroups {
    /// Every column, in order.
    pub(crate) all: ColumnBatch,
    /// Per column, its group.
    pub(crate) group: Vec<u32>,
    /// The groups' spring-free representatives (one column per group).
    pub(crate) rep_params: ParameterSet,
    pub(crate) rep_batch: ColumnBatch,
}

impl InertiaGroups {
    pub(crate) fn new(params: &ParameterSet) -> InertiaGroups {
        let inertial = crate::params::BODY_PARAMS * params.bodies;
        let mut index: HashMap<Vec<u64>, usize> = HashMap::new();
        let mut rep_params = ParameterSet::empty(params.bodies, params.springs.clone());
        let group: Vec<u32> = (0..params.len())
            .map(|p| {
                let body_part = &params.column(p)[..inertial];
                let key = body_part.iter().map(|x| x.to_bits()).collect();
                *index.entry(key).or_insert_with(|| {
                    let mut column = body_part.to_vec();
                    column.resize(params.rows(), 0.0);
                    rep_params
                        .push_column(&column)
                        .expect("a column of the set's own shape");
                    rep_params.len() - 1
                }) as u32
            })
            .collect();
        let all: Vec<usize> = (0..params.len()).collect();
        let reps: Vec<usize> = (0..rep_params.len()).collect();
        InertiaGroups {
            all: ColumnBatch::new(params, &all),
            group,
            rep_batch: ColumnBatch::new(&rep_params, &reps),
            rep_params,
        }
    }

    /// Every column's value from its representative's, `dst[p] = rep[g] + (zero[p] −
    /// rep_zero[g])` with `g` the column's group, `zero` the columns' values at `Δ = 0` and
    /// `rep_zero` the representatives'.
    pub(crate) fn expand(&self, dst: &mut [f64], rep: &[f64], zero: &[f64], rep_zero: &[f64]) {
        expand_from_groups(&self.group, dst, rep, zero, rep_zero);
    }
}

/// Reactions (and torques) by superposition (`Combination::Superposition`).
///
/// Every output of a sample is linear in the column's lifted parameters `p`. A variant differs
/// from the model's own parameters `p₀` (its bodies and payloads, no springs) in the rows of its
/// few elements: a counterweight's body block, a spring's slot. So
/// `X(p) = X(p₀) + Σ_r (p_r − p₀_r) X(e_r)`, summed over the rows `r` where `p` differs from
/// `p₀`, with `e_r` the unit column of row `r`. Per sample the machinery evaluates `p₀` and the
/// unit columns of every row in which some column of the batch differs (the basis), then each
/// column is that sum — its own rows in ascending order, whatever else is in the batch, so a
/// column's bits do not depend on the batch, the shard or the thread count.
///
/// The unit column of a body row is its own inertia group (the row is inertial); a spring
/// row's unit column has no inertia and no change with `Δ` (springs are static), which the sum
/// skips. A column is then its own group: its changes to `Δ = ±1` are summed like its values.
pub(crate) struct Superposition {
    /// `p₀` and the unit columns, in row order.
    pub(crate) basis: ParameterSet,
    pub(crate) groups: InertiaGroups,
    /// Per basis column: whether it changes with `Δ` (`p₀` and the body rows).
    pub(crate) inertial: Vec<bool>,
    /// Per column: `(basis column, p_r − p₀_r)` over the rows where it differs, ascending.
    pub(crate) terms: Vec<Vec<(u32, f64)>>,
    /// Every column its own group.
    pub(crate) identity: Vec<u32>,
}

impl Superposition {
    pub(crate) fn new(base_bodies: &[f64], params: &ParameterSet) -> Superposition {
        let rows = params.rows();
        let inertial_rows = crate::params::BODY_PARAMS * params.bodies;
        let mut base = base_bodies.to_vec();
        base.resize(rows, 0.0);
        let differs = |p: usize, r: usize| params.column(p)[r].to_bits() != base[r].to_bits();
        let used: Vec<usize> = (0..rows)
            .filter(|&r| (0..params.len()).any(|p| differs(p, r)))
            .collect();
        let mut basis = ParameterSet::empty(params.bodies, params.springs.clone());
        basis
            .push_column(&base)
            .expect("a column of the set's own shape");
        let mut inertial = vec![true];
        let mut index = vec![u32::MAX; rows];
        for &r in &used {
            let mut unit = vec![0.0; rows];
            unit[r] = 1.0;
            basis
                .push_column(&unit)
                .expect("a column of the set's own shape");
            index[r] = (basis.len() - 1) as u32;
            inertial.push(r < inertial_rows);
        }
        let terms = (0..params.len())
            .map(|p| {
                used.iter()
                    .filter(|&&r| differs(p, r))
                    .map(|&r| (index[r], params.column(p)[r] - base[r]))
                    .collect()
            })
            .collect();
        Superposition {
            groups: InertiaGroups::new(&basis),
            basis,
            inertial,
            terms,
            identity: (0..params.len() as u32).collect(),
        }
    }

    /// Every column's torques `[Δ][actuator][column]` from the basis's `[Δ][actuator][basis]`.
    pub(crate) fn torques(&self, basis: &[f64], n: usize, dst: &mut Vec<f64>) {
        let (nb, cols) = (self.basis.len(), self.terms.len());
        dst.resize(3 * n * cols, 0.0);
        for da in 0..3 * n {
            let src = &basis[da * nb..(da + 1) * nb];
            sum_terms(&self.terms, src, &mut dst[da * cols..(da + 1) * cols]);
        }
    }

    /// Every column's reaction components (the layout of `Work::sum_out`) from the basis's
    /// (`out`, `solved` values per component row: the basis columns at `Δ = 0`, the groups at
    /// `Δ = 0` (unused), their changes to `+1`, to `−1`).
    pub(crate) fn reactions(
        &self,
        out: &[f64],
        solved: usize,
        component_rows: usize,
        dst: &mut Vec<f64>,
    ) {
        let (nb, nreps, cols) = (
            self.basis.len(),
            self.groups.rep_batch.len(),
            self.terms.len(),
        );
        let group = &self.groups.group;
        dst.resize(component_rows * 4 * cols, 0.0);
        for row in 0..component_rows {
            let src = &out[row * solved..(row + 1) * solved];
            let (at_zero, rest) = src.split_at(nb);
            let changes = &rest[nreps..];
            let (plus, minus) = changes.split_at(nreps);
            let dst = &mut dst[row * 4 * cols..(row + 1) * 4 * cols];
            let (d0, rest) = dst.split_at_mut(2 * cols);
            let (dp, dm) = rest.split_at_mut(cols);
            sum_terms(&self.terms, at_zero, &mut d0[..cols]);
            sum_changes(&self.terms, &self.inertial, group, [plus, minus], [dp, dm]);
        }
    }
}

crate::simd::multiversion! {
/// `dst[p] = src[0] + Σ c·src[k]` over column `p`'s terms `(k, c)`, fused multiply-adds in the
/// terms' order (multiversioned: without the FMA instruction `mul_add` is a library call).
pub(crate) fn sum_terms(terms: &[Vec<(u32, f64)>], src: &[f64], dst: &mut [f64]) {
    for (d, terms) in dst.iter_mut().zip(terms) {
        *d = terms
            .iter()
            .fold(src[0], |acc, &(k, c)| c.mul_add(src[k as usize], acc));
    }
}
}

crate::simd::multiversion! {
/// Every column's changes to `Δ = ±1`: the base column's group's plus `c` times each inertial
/// term's group's (spring rows do not change with `Δ`), in the terms' order.
pub(crate) fn sum_changes(
    terms: &[Vec<(u32, f64)>],
    inertial: &[bool],
    group: &[u32],
    changes: [&[f64]; 2],
    dst: [&mut [f64]; 2],
) {
    let [plus, minus] = changes;
    let [dp, dm] = dst;
    let g0 = group[0] as usize;
    for (p, terms) in terms.iter().enumerate() {
        let (mut sp, mut sm) = (plus[g0], minus[g0]);
        for &(k, c) in terms {
            if inertial[k as usize] {
                let g = group[k as usize] as usize;
                sp = c.mul_add(plus[g], sp);
                sm = c.mul_add(minus[g], sm);
            }
        }
        dp[p] = sp;
        dm[p] = sm;
    }
}
}
