//! Rank-one case splits: a spring whose balance zeroes a block of `W` must lose an anchor part.
//!
//! A physical spring has `K·W = α βᵀ` with `K > 0`. When balance fixes a block `W_IJ` (rows `I`
//! of anchor `a`'s axes, columns `J` of `b`'s) at zero on the whole family — springs between
//! two chains of a spatial mechanism, whose cross terms `cos qᵢ cos qⱼ`, … nothing else can
//! cancel — then `α_I β_Jᵀ = 0`, so `α_I = 0` or `β_J = 0`: the anchor `a` lies on the axes
//! `I` zero, or `b` on `J` zero. Each branch is linear (with `α_I = 0` also `W_I· = 0`), so it is
//! decided exactly like the variant itself: inconsistent, a sign proof, a rank-one contradiction,
//! or a further split. When every branch is refuted the variant is proved unrealizable; a branch
//! left open is a smaller linear family where the witness search can look.

use counterpoise_symbolic::RefArith;

use super::{ExactBasis, ExactField, ExactSolution, rank_one};
use crate::element::{CatalogueEntry, Element};

/// At most this many families are solved for one variant (the splits branch twice each).
const NODE_BUDGET: usize = 256;

/// What the splits found: a proof, or the branches no test refuted (extra equations each).
pub enum Outcome<F> {
    Proof(String),
    Open(Vec<Vec<Vec<F>>>),
}

/// A block of a spring's `W` fixed at zero: variant element `k`, rows `I`, columns `J`.
struct Rectangle {
    k: usize,
    rows: Vec<usize>,
    columns: Vec<usize>,
}

fn axis_names(axes: &[usize], picked: &[usize]) -> String {
    let names: Vec<&str> = picked.iter().map(|&i| ["x", "y", "z"][axes[i]]).collect();
    names.join(", ")
}

/// The maximal zero blocks of each spring's `W` on the family whose two sides are not already
/// zero (a split of those would change nothing).
fn rectangles<F: ExactField>(
    solution: &ExactSolution<F>,
    entries: &[(usize, &CatalogueEntry)],
) -> Vec<Rectangle>
where
    for<'a> &'a F: RefArith<F>,
{
    let zero = |j: usize| solution.is_fixed(j) && solution.particular[j].is_zero();
    let mut out = Vec::new();
    for (k, (_, entry)) in entries.iter().enumerate() {
        let Element::Spring { axes_a, axes_b, .. } = &entry.element else {
            continue;
        };
        let (na, nb) = (axes_a.len(), axes_b.len());
        let start = solution.offsets[k];
        let w = |i: usize, j: usize| start + 1 + na + nb + i * nb + j;
        let mut seen: Vec<(Vec<usize>, Vec<usize>)> = Vec::new();
        for mask in 1u32..(1 << na) {
            let rows: Vec<usize> = (0..na).filter(|i| mask & (1 << i) != 0).collect();
            let columns: Vec<usize> = (0..nb)
                .filter(|&j| rows.iter().all(|&i| zero(w(i, j))))
                .collect();
            if columns.is_empty() {
                continue;
            }
            // Maximal: every row zero on these columns is in the block.
            let closed: Vec<usize> = (0..na)
                .filter(|&i| columns.iter().all(|&j| zero(w(i, j))))
                .collect();
            if closed != rows || seen.contains(&(rows.clone(), columns.clone())) {
                continue;
            }
            let alpha_zero = rows.iter().all(|&i| zero(start + 1 + i));
            let beta_zero = columns.iter().all(|&j| zero(start + 1 + na + j));
            seen.push((rows.clone(), columns.clone()));
            if !alpha_zero && !beta_zero {
                out.push(Rectangle {
                    k,
                    rows: rows.clone(),
                    columns,
                });
            }
        }
    }
    out
}

/// Equations `α_I = 0` and `W_I· = 0` (`side_a`), or `β_J = 0` and `W_·J = 0`.
fn branch_rows<F: ExactField>(
    solution: &ExactSolution<F>,
    entries: &[(usize, &CatalogueEntry)],
    r: &Rectangle,
    side_a: bool,
) -> Vec<Vec<F>> {
    let Element::Spring { axes_a, axes_b, .. } = &entries[r.k].1.element else {
        unreachable!("rectangles are found on springs only");
    };
    let (na, nb) = (axes_a.len(), axes_b.len());
    let n = solution.echelon.columns;
    let start = solution.offsets[r.k];
    let unit = |j: usize| {
        let mut row = vec![F::zero(); n];
        row[j] = F::one();
        row
    };
    let mut rows = Vec::new();
    if side_a {
        for &i in &r.rows {
            rows.push(unit(start + 1 + i));
            rows.extend((0..nb).map(|j| unit(start + 1 + na + nb + i * nb + j)));
        }
    } else {
        for &j in &r.columns {
            rows.push(unit(start + 1 + na + j));
            rows.extend((0..na).map(|i| unit(start + 1 + na + nb + i * nb + j)));
        }
    }
    rows
}

/// Splits the family restricted by `extra` until every branch is refuted, up to `depth` nested
/// splits; `sign_proof` is the caller's proof from signs (fixed heads, Farkas).
pub fn refute<F: ExactField>(
    basis: &ExactBasis<F>,
    set: &[usize],
    entries: &[(usize, &CatalogueEntry)],
    extra: &[Vec<F>],
    depth: usize,
    sign_proof: &dyn Fn(&ExactSolution<F>) -> Option<String>,
) -> Outcome<F>
where
    for<'a> &'a F: RefArith<F>,
{
    let mut budget = NODE_BUDGET;
    node(basis, set, entries, extra, depth, sign_proof, &mut budget)
}

fn node<F: ExactField>(
    basis: &ExactBasis<F>,
    set: &[usize],
    entries: &[(usize, &CatalogueEntry)],
    extra: &[Vec<F>],
    depth: usize,
    sign_proof: &dyn Fn(&ExactSolution<F>) -> Option<String>,
    budget: &mut usize,
) -> Outcome<F>
where
    for<'a> &'a F: RefArith<F>,
{
    let open = || Outcome::Open(vec![extra.to_vec()]);
    if *budget == 0 {
        return open();
    }
    *budget -= 1;
    let solution = basis.solve_with(set, extra);
    if !solution.consistent() {
        return Outcome::Proof("the balance equations have no solution".to_string());
    }
    let refs: Vec<&CatalogueEntry> = entries.iter().map(|(_, e)| *e).collect();
    if let Some(reason) =
        sign_proof(&solution).or_else(|| rank_one::contradiction(basis, &solution, &refs))
    {
        return Outcome::Proof(reason);
    }
    if depth == 0 {
        return open();
    }
    let mut leaves = Vec::new();
    for r in rectangles(&solution, entries) {
        let mut proofs = Vec::new();
        let mut open_here = Vec::new();
        for side_a in [true, false] {
            let mut rows = extra.to_vec();
            rows.extend(branch_rows(&solution, entries, &r, side_a));
            match node(basis, set, entries, &rows, depth - 1, sign_proof, budget) {
                Outcome::Proof(p) => proofs.push(p),
                Outcome::Open(l) => open_here.extend(l),
            }
        }
        if proofs.len() == 2 {
            let Element::Spring { axes_a, axes_b, .. } = &entries[r.k].1.element else {
                unreachable!("rectangles are found on springs only");
            };
            let (ai, bj) = (axis_names(axes_a, &r.rows), axis_names(axes_b, &r.columns));
            return Outcome::Proof(format!(
                "{label}: balance makes K·a_i·b_j = 0 for i ∈ {{{ai}}}, j ∈ {{{bj}}}, so its \
                 anchor a has no {ai} part or b no {bj} part; with a's {ai} zero, {p}; with b's \
                 {bj} zero, {q}",
                label = entries[r.k].1.label,
                p = proofs[0],
                q = proofs[1],
            ));
        }
        if leaves.is_empty() {
            leaves = open_here;
        }
    }
    if leaves.is_empty() {
        open()
    } else {
        Outcome::Open(leaves)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::element::Attachment;
    use counterpoise_symbolic::{Monomial, Rational};
    use num_bigint::BigInt;

    /// One spring `(K, αx, αy, βx, βy, Wxx, Wxy, Wyx, Wyy)` with the balance rows given as
    /// `(variable, right-hand side)`: `x_variable = value`.
    fn rectangles_of(rows: &[(usize, i64)]) -> Vec<(Vec<usize>, Vec<usize>)> {
        let entry = spring();
        let solution = solved(rows);
        rectangles(&solution, &[(0, &entry)])
            .into_iter()
            .map(|r| (r.rows, r.columns))
            .collect()
    }

    fn spring() -> CatalogueEntry {
        CatalogueEntry {
            element: Element::Spring {
                body: 0,
                other: Attachment::Base,
                axes_a: vec![0, 1],
                axes_b: vec![0, 1],
            },
            label: "K1".into(),
            description: "spring".into(),
            variables: Vec::new(),
            energy: Vec::new(),
        }
    }

    /// The one-spring variant solved with the balance rows `x_variable = value`.
    fn solved(rows: &[(usize, i64)]) -> ExactSolution<Rational> {
        let mut columns = vec![vec![BigInt::from(0); rows.len()]; 9];
        for (r, &(j, _)) in rows.iter().enumerate() {
            columns[j][r] = BigInt::from(1);
        }
        let basis = ExactBasis {
            monomials: (0..rows.len()).map(Monomial::sine).collect(),
            unbalanced: rows.iter().map(|&(_, v)| BigInt::from(-v)).collect(),
            elements: vec![columns],
            row_factors: vec![Rational::from_integer(1.into()); rows.len()],
        };
        basis.solve(&[0])
    }

    /// The variables a branch sets to zero (each row is a unit row).
    fn zeroed(rows: &[Vec<Rational>]) -> Vec<usize> {
        let zero = Rational::from_integer(0.into());
        rows.iter()
            .map(|row| {
                assert_eq!(row.iter().filter(|v| **v != zero).count(), 1);
                row.iter().position(|v| *v != zero).unwrap()
            })
            .collect()
    }

    #[test]
    fn a_branch_zeroes_the_anchor_part_and_its_whole_row_or_column_of_w() {
        // Variables 0 K, 1 αx, 2 αy, 3 βx, 4 βy, 5 Wxx, 6 Wxy, 7 Wyx, 8 Wyy (W_ij at 5 + 2i + j).
        let entry = spring();
        let solution = solved(&[(0, 1)]);
        let block = Rectangle {
            k: 0,
            rows: vec![1],
            columns: vec![0],
        };
        // a's y part zero: αy and the row y of W, (Wyx, Wyy) = variables 7, 8.
        let side_a = branch_rows(&solution, &[(0, &entry)], &block, true);
        assert_eq!(zeroed(&side_a), vec![2, 7, 8]);
        // b's x part zero: βx and the column x of W, (Wxx, Wyx) = variables 5, 7.
        let side_b = branch_rows(&solution, &[(0, &entry)], &block, false);
        assert_eq!(zeroed(&side_b), vec![3, 5, 7]);
        // The other corner: a's x part (αx; Wxx, Wxy), b's y part (βy; Wxy, Wyy).
        let corner = Rectangle {
            k: 0,
            rows: vec![0],
            columns: vec![1],
        };
        let side_a = branch_rows(&solution, &[(0, &entry)], &corner, true);
        assert_eq!(zeroed(&side_a), vec![1, 5, 6]);
        let side_b = branch_rows(&solution, &[(0, &entry)], &corner, false);
        assert_eq!(zeroed(&side_b), vec![4, 6, 8]);
        assert!(side_b.iter().all(|row| row.len() == 9));
    }

    #[test]
    fn zero_blocks_are_found_maximal_and_only_when_a_split_says_something() {
        // K = 1, Wxx = 0: the one block is {x}×{x} (Wxy, Wyx, Wyy are free).
        assert_eq!(rectangles_of(&[(0, 1), (5, 0)]), vec![(vec![0], vec![0])]);
        // Wxx = Wxy = 0: the row x of W is zero, a block {x}×{x, y}, not {x}×{x}.
        assert_eq!(
            rectangles_of(&[(0, 1), (5, 0), (6, 0)]),
            vec![(vec![0], vec![0, 1])]
        );
        // Wxx = Wyx = 0: the column x, {x, y}×{x}.
        assert_eq!(
            rectangles_of(&[(0, 1), (5, 0), (7, 0)]),
            vec![(vec![0, 1], vec![0])]
        );
        // With αx = 0 already, splitting on {x}×{x} changes nothing: no block.
        assert!(rectangles_of(&[(0, 1), (5, 0), (1, 0)]).is_empty());
        // Likewise with βx = 0.
        assert!(rectangles_of(&[(0, 1), (5, 0), (3, 0)]).is_empty());
        // Wxy = 0 with βy (variable 4) = 0 already: the block {x}×{y} says nothing either.
        assert!(rectangles_of(&[(0, 1), (6, 0), (4, 0)]).is_empty());
        // Wxx = 1: nothing is zero.
        assert!(rectangles_of(&[(0, 1), (5, 1)]).is_empty());
    }
}
