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
    /// Per column: `(basis column, p_r − p₀_r)` over the rows where it differs, ascending.
    pub(crate) terms: Vec<Vec<(u32, f64)>>,
    /// Per column: `(group, p_r − p₀_r)` over its inertial terms (the ones that change with
    /// `Δ`), in the terms' order.
    change_terms: Vec<Vec<(u32, f64)>>,
    /// Every column its own group.
    pub(crate) identity: Vec<u32>,
}

impl Superposition {
    pub(crate) fn new(base_bodies: &[f64], params: &ParameterSet) -> Superposition {
        let UnitBasis { basis, rows, terms } = UnitBasis::new(base_bodies, params);
        let inertial_rows = crate::params::BODY_PARAMS * params.bodies;
        // per basis column: `p₀` and the body rows change with Δ, spring rows do not
        let inertial: Vec<bool> = std::iter::once(true)
            .chain(rows.iter().map(|&r| r < inertial_rows))
            .collect();
        let groups = InertiaGroups::new(&basis);
        let change_terms = terms
            .iter()
            .map(|t| {
                t.iter()
                    .filter(|&&(k, _)| inertial[k as usize])
                    .map(|&(k, c)| (groups.group[k as usize], c))
                    .collect()
            })
            .collect();
        Superposition {
            groups,
            basis,
            terms,
            change_terms,
            identity: (0..params.len() as u32).collect(),
        }
    }

    /// Every column's torques `[Δ][actuator][column]` from the basis's `[Δ][actuator][basis]`
    /// (`scratch` holds the transposed basis and the columns' sums between calls).
    pub(crate) fn torques(
        &self,
        basis: &[f64],
        n: usize,
        dst: &mut Vec<f64>,
        scratch: &mut SumScratch,
    ) {
        let (nb, cols, len) = (self.basis.len(), self.terms.len(), 3 * n);
        dst.resize(len * cols, 0.0);
        let (src_at, dst_at) = (RowLayout::new(nb, 0), RowLayout::new(cols, 0));
        scratch.sum(&self.terms, 0, len, (basis, nb, src_at), (dst, dst_at));
    }

    /// Every column's reaction components (the layout of `Work::sum_out`) from the basis's
    /// (`out`, `solved` values per component row: the basis columns at `Δ = 0`, the groups at
    /// `Δ = 0` (unused), their changes to `+1`, to `−1`).
    ///
    /// The basis's values are transposed to one contiguous vector per basis column (or group),
    /// so that each term of a column's sum is one vectorised multiply-add over all the
    /// component rows; each value is still the fold of its own terms in their order, the same
    /// bits as a scalar sum per row (`the_vector_sums_are_the_scalar_folds`).
    pub(crate) fn reactions(
        &self,
        out: &[f64],
        solved: usize,
        component_rows: usize,
        dst: &mut Vec<f64>,
        scratch: &mut SumScratch,
    ) {
        let (nb, nreps, cols) = (
            self.basis.len(),
            self.groups.rep_batch.len(),
            self.terms.len(),
        );
        let len = component_rows;
        dst.resize(len * 4 * cols, 0.0);
        // Δ = 0: the basis columns.
        let at_zero = (out, nb, RowLayout::new(solved, 0));
        let into = RowLayout::new(4 * cols, 0);
        scratch.sum(&self.terms, 0, len, at_zero, (dst, into));
        // The changes to Δ = +1 and −1: the groups' of the inertial terms.
        let first = self.groups.group[0] as usize;
        for (side, offset) in [(0, 2 * cols), (1, 3 * cols)] {
            let changes = (out, nreps, RowLayout::new(solved, nb + (1 + side) * nreps));
            let into = RowLayout::new(4 * cols, offset);
            scratch.sum(&self.change_terms, first, len, changes, (dst, into));
        }
    }
}

/// The inertia groups' changes with `Δ` by superposition (`Combination::InertiaSuperposition`).
///
/// A group's change from `Δ = 0` to `Δ = ±1` is linear in its inertial parameters and
/// independent of springs; a group differs from the model's own inertia `p₀` only in the
/// bodies its counterweights load. Per sample the machinery evaluates `p₀` and one unit column
/// per inertial row in which some group differs (the basis, spring-free, as a batch of
/// representatives), and each group's change is `D(p₀) + Σ (p_r − p₀_r) D(e_r)` over its own
/// rows in ascending order — the same bits whatever the batch, as [`Superposition`]'s sums.
/// Every column itself is still evaluated directly at `Δ = 0`. It pays when a batch holds many
/// inertia groups (each hybrid variant its own): three right-hand sides per group become
/// three per basis column and a short sum.
pub(crate) struct InertiaSums {
    /// `p₀` and the unit columns, spring-free, in row order.
    pub(crate) basis: ParameterSet,
    pub(crate) batch: ColumnBatch,
    /// Per group: `(basis column, p_r − p₀_r)` over the rows where its inertia differs,
    /// ascending.
    terms: Vec<Vec<(u32, f64)>>,
}

impl InertiaSums {
    pub(crate) fn new(base_bodies: &[f64], groups: &InertiaGroups) -> InertiaSums {
        // The representatives are spring-free: only their inertial rows can differ from `p₀`.
        let UnitBasis { basis, terms, .. } = UnitBasis::new(base_bodies, &groups.rep_params);
        let all: Vec<usize> = (0..basis.len()).collect();
        InertiaSums {
            batch: ColumnBatch::new(&basis, &all),
            basis,
            terms,
        }
    }

    /// The number of groups.
    pub(crate) fn groups(&self) -> usize {
        self.terms.len()
    }

    /// Every group's changes of `len` values, `dst[r·stride + offset + g]`, from the basis's
    /// changes `src[r·src_stride + from + k]`.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn changes(
        &self,
        src: &[f64],
        src_stride: usize,
        from: usize,
        len: usize,
        dst: &mut [f64],
        stride: usize,
        offset: usize,
        scratch: &mut SumScratch,
    ) {
        let basis = (src, self.basis.len(), RowLayout::new(src_stride, from));
        let into = RowLayout::new(stride, offset);
        scratch.sum(&self.terms, 0, len, basis, (dst, into));
    }
}

/// The model's own parameters `p₀` (its bodies, no springs) and one unit column per row in
/// which some column of a set differs from them, in row order, with each column as its
/// differences from `p₀`.
struct UnitBasis {
    /// `p₀`, then the unit columns.
    basis: ParameterSet,
    /// The row of each unit column.
    rows: Vec<usize>,
    /// Per column: `(basis column, p_r − p₀_r)` over the rows where it differs, ascending.
    terms: Vec<Vec<(u32, f64)>>,
}

impl UnitBasis {
    fn new(base_bodies: &[f64], params: &ParameterSet) -> UnitBasis {
        let rows = params.rows();
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
        let mut index = vec![u32::MAX; rows];
        for &r in &used {
            let mut unit = vec![0.0; rows];
            unit[r] = 1.0;
            basis
                .push_column(&unit)
                .expect("a column of the set's own shape");
            index[r] = (basis.len() - 1) as u32;
        }
        let terms = (0..params.len())
            .map(|p| {
                used.iter()
                    .filter(|&&r| differs(p, r))
                    .map(|&r| (index[r], params.column(p)[r] - base[r]))
                    .collect()
            })
            .collect();
        UnitBasis {
            basis,
            rows: used,
            terms,
        }
    }
}

/// Buffers of [`Superposition`]'s sums, reused from sample to sample.
#[derive(Default)]
pub(crate) struct SumScratch {
    /// The basis's values, one contiguous vector per basis column or group.
    basis: Vec<f64>,
    /// Every column's sums, one contiguous vector per column.
    sums: Vec<f64>,
}

/// Where values laid out row by row sit: row `r`'s value `k` at `r·stride + offset + k`.
#[derive(Clone, Copy)]
struct RowLayout {
    stride: usize,
    offset: usize,
}

impl RowLayout {
    fn new(stride: usize, offset: usize) -> RowLayout {
        RowLayout { stride, offset }
    }
}

impl SumScratch {
    /// Every column's sum over `len` rows: `dst`'s value `p` of row `r` is `src`'s value `first`
    /// plus `c` times its value `k` over column `p`'s terms `(k, c)`, in their order (`src`
    /// holds `count` values per row). The basis is transposed to one contiguous vector per
    /// value, the sums taken as vectors ([`sum_vectors`]) and transposed back.
    fn sum(
        &mut self,
        terms: &[Vec<(u32, f64)>],
        first: usize,
        len: usize,
        (src, count, src_at): (&[f64], usize, RowLayout),
        (dst, dst_at): (&mut [f64], RowLayout),
    ) {
        let width = len.next_multiple_of(8);
        transpose_into(&mut self.basis, src, len, width, count, src_at);
        self.sums.resize(terms.len() * width, 0.0);
        sum_vectors(terms, first, &self.basis, width, &mut self.sums);
        transpose_from(dst, &self.sums, len, width, terms.len(), dst_at);
    }
}

/// Columns per tile of the transposes: a tile's vectors stay in the first-level cache while
/// its rows are copied.
const TILE: usize = 32;

/// `dst[k·width + r] = src[r·stride + offset + k]` for `k < count`, `r < len` (the rows from
/// `len` to `width` zero).
fn transpose_into(
    dst: &mut Vec<f64>,
    src: &[f64],
    len: usize,
    width: usize,
    count: usize,
    RowLayout { stride, offset }: RowLayout,
) {
    dst.resize(count * width, 0.0);
    for k0 in (0..count).step_by(TILE) {
        let k1 = (k0 + TILE).min(count);
        for r in 0..len {
            let row = &src[r * stride + offset + k0..][..k1 - k0];
            for (k, &x) in (k0..k1).zip(row) {
                dst[k * width + r] = x;
            }
        }
    }
    for vector in dst.chunks_exact_mut(width) {
        vector[len..].fill(0.0);
    }
}

/// `dst[r·stride + offset + p] = src[p·width + r]` for `p < count`, `r < len`.
fn transpose_from(
    dst: &mut [f64],
    src: &[f64],
    len: usize,
    width: usize,
    count: usize,
    RowLayout { stride, offset }: RowLayout,
) {
    for p0 in (0..count).step_by(TILE) {
        let p1 = (p0 + TILE).min(count);
        for r in 0..len {
            let row = &mut dst[r * stride + offset + p0..][..p1 - p0];
            for (p, d) in (p0..p1).zip(row) {
                *d = src[p * width + r];
            }
        }
    }
}

crate::simd::multiversion! {
/// Every column's sum, `dst[p] = src[first] + Σ c·src[k]` over column `p`'s terms `(k, c)` in
/// their order, as vectors of `width` values (`src` one vector per basis column or group,
/// `dst` one per column; `width` a multiple of 8). The rows are taken in blocks held in
/// registers across the terms: fused multiply-adds (multiversioned: without the FMA
/// instruction `mul_add` is a library call), each value the fold of its terms in order.
fn sum_vectors(terms: &[Vec<(u32, f64)>], first: usize, src: &[f64], width: usize, dst: &mut [f64]) {
    for (acc, terms) in dst.chunks_exact_mut(width).zip(terms) {
        // A vector of up to 72 rows is held whole (nine 512-bit registers: enough independent
        // multiply-adds per term to hide their latency); a longer one in blocks.
        match width {
            8 => sum_block::<8>(terms, src, width, first, 0, acc),
            16 => sum_block::<16>(terms, src, width, first, 0, acc),
            24 => sum_block::<24>(terms, src, width, first, 0, acc),
            32 => sum_block::<32>(terms, src, width, first, 0, acc),
            40 => sum_block::<40>(terms, src, width, first, 0, acc),
            48 => sum_block::<48>(terms, src, width, first, 0, acc),
            56 => sum_block::<56>(terms, src, width, first, 0, acc),
            64 => sum_block::<64>(terms, src, width, first, 0, acc),
            72 => sum_block::<72>(terms, src, width, first, 0, acc),
            _ => {
                let mut r = 0;
                while r + SUM_BLOCK <= width {
                    sum_block::<SUM_BLOCK>(terms, src, width, first, r, acc);
                    r += SUM_BLOCK;
                }
                while r < width {
                    sum_block::<8>(terms, src, width, first, r, acc);
                    r += 8;
                }
            }
        }
    }
}
}

/// Rows per register block of [`sum_vectors`] for vectors longer than 72 rows.
const SUM_BLOCK: usize = 32;

/// `acc[r..r + W] = src[first][r..r + W] + Σ c·src[k][r..r + W]` over `terms`, in order
/// (vectors `width` apart in `src`).
#[inline(always)]
fn sum_block<const W: usize>(
    terms: &[(u32, f64)],
    src: &[f64],
    width: usize,
    first: usize,
    r: usize,
    acc: &mut [f64],
) {
    let block = |k: usize| -> &[f64; W] {
        let start = k * width + r;
        src[start..start + W]
            .try_into()
            .expect("a block of W values")
    };
    let mut a = *block(first);
    for &(k, c) in terms {
        let x = block(k as usize);
        for i in 0..W {
            a[i] = c.mul_add(x[i], a[i]);
        }
    }
    acc[r..r + W].copy_from_slice(&a);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The scalar sums the vector ones replace: per value, the fold of its column's terms (the
    /// changes with `Δ` over the inertial ones: unit columns of a body row).
    fn scalar_sums(sup: &Superposition, out: &[f64], solved: usize, len: usize) -> Vec<f64> {
        let (nb, nreps, cols) = (sup.basis.len(), sup.groups.rep_batch.len(), sup.terms.len());
        let group = &sup.groups.group;
        let inertial_rows = crate::params::BODY_PARAMS * sup.basis.bodies;
        let inertial: Vec<bool> = (0..nb)
            .map(|k| k == 0 || sup.basis.column(k)[..inertial_rows].contains(&1.0))
            .collect();
        let mut dst = vec![0.0; len * 4 * cols];
        for r in 0..len {
            let row = &out[r * solved..(r + 1) * solved];
            for (p, terms) in sup.terms.iter().enumerate() {
                let zero = terms
                    .iter()
                    .fold(row[0], |acc, &(k, c)| c.mul_add(row[k as usize], acc));
                dst[r * 4 * cols + p] = zero;
                for side in 0..2 {
                    let change = |g: u32| row[nb + (1 + side) * nreps + g as usize];
                    let sum = terms
                        .iter()
                        .filter(|&&(k, _)| inertial[k as usize])
                        .fold(change(group[0]), |acc, &(k, c)| {
                            c.mul_add(change(group[k as usize]), acc)
                        });
                    dst[r * 4 * cols + (2 + side) * cols + p] = sum;
                }
            }
        }
        dst
    }

    #[test]
    fn the_vector_sums_are_the_scalar_folds() {
        // Few columns and short vectors (one block in registers), then more columns and basis
        // columns than a transpose tile and vectors longer than the registers hold.
        check_sums(0, 11);
        check_sums(40, 90);
    }

    /// Superposition's sums against the scalar folds, on columns that differ from the base in
    /// body rows (inertial) and spring rows, some in several rows, one not at all, and `extra`
    /// more, over `len` component rows.
    fn check_sums(extra: usize, len: usize) {
        // Two bodies, a spring slot.
        let bodies = 2;
        let slot = crate::params::SpringSlot {
            body: 0,
            other: None,
        };
        let mut params = ParameterSet::empty(bodies, vec![slot]);
        let rows = params.rows();
        let base: Vec<f64> = (0..crate::params::BODY_PARAMS * bodies)
            .map(|r| 1.0 + r as f64 / 7.0)
            .collect();
        let mut full = base.clone();
        full.resize(rows, 0.0);
        let mut x = 0.3f64;
        let mut next = || {
            x = (x * 3.7 + 0.11).fract();
            x - 0.5
        };
        let mut changes = vec![
            vec![],
            vec![0],
            vec![3, 12],
            vec![rows - 1],
            vec![1, 5, rows - 2],
        ];
        changes.extend((0..extra).map(|i| vec![i % rows, (7 * i + 3) % rows]));
        for changed in changes {
            let mut column = full.clone();
            for r in changed {
                column[r] += next();
            }
            params.push_column(&column).unwrap();
        }
        let sup = Superposition::new(&base, &params);
        let nb = sup.basis.len();
        let nreps = sup.groups.rep_batch.len();
        assert!(nreps >= 3, "inertial unit columns are groups of their own");
        if extra > 0 {
            assert!(nb > TILE && params.len() > TILE && len > 72);
        }
        let solved = nb + 3 * nreps + 2;
        let out: Vec<f64> = (0..len * solved).map(|_| next() * 1e3).collect();
        let mut dst = Vec::new();
        sup.reactions(&out, solved, len, &mut dst, &mut SumScratch::default());
        let expected = scalar_sums(&sup, &out, solved, len);
        let cols = sup.terms.len();
        for r in 0..len {
            for part in [0, 2, 3] {
                for p in 0..cols {
                    let i = r * 4 * cols + part * cols + p;
                    assert_eq!(
                        dst[i].to_bits(),
                        expected[i].to_bits(),
                        "row {r} part {part} column {p}"
                    );
                }
            }
        }
        // A column with no terms is the base column; the torques are the same sums at Δ = 0.
        assert_eq!(dst[0].to_bits(), out[0].to_bits());
        let n = 2;
        let torques: Vec<f64> = (0..3 * n * nb).map(|_| next()).collect();
        let mut summed = Vec::new();
        sup.torques(&torques, n, &mut summed, &mut SumScratch::default());
        for da in 0..3 * n {
            let src = &torques[da * nb..(da + 1) * nb];
            for (p, terms) in sup.terms.iter().enumerate() {
                let fold = terms
                    .iter()
                    .fold(src[0], |acc, &(k, c)| c.mul_add(src[k as usize], acc));
                assert_eq!(summed[da * cols + p].to_bits(), fold.to_bits());
            }
        }
    }
}
