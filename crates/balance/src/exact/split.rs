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
//!
//! The same holds for any linear identity of one anchor row: when balance makes
//! `c·α_i + Σ_j d_j·W_ij = 0` on the whole family, a physical spring has
//! `a_i·(c·K + d·β) = 0` (`α_i = a_i K`, `W_ij = a_i β_j`), so `a_i = 0` (with `W_i· = 0`) or
//! `c·K + d·β = 0`; and for a column of `b`, `b_j·(c·K + d·α) = 0`. A zero block is the case
//! `c = 0`, `d` a unit vector ([`Factor`] splits the others).

use counterpoise_symbolic::RefArith;

use super::{ExactBasis, ExactField, ExactSolution, anchors, rank_one};
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

/// A linear identity of one anchor row (or column) on the family that is not a zero block:
/// `c·α_i + d·W_i· = 0` (`side_a`), or `c·β_j + d·W_·j = 0`, with `coefficients = (c, d)`.
struct Factor<F> {
    k: usize,
    side_a: bool,
    index: usize,
    coefficients: Vec<F>,
}

/// The identities of each spring's anchor rows and columns on the family: the null space of
/// the values `(α_i, W_i·)` (or `(β_j, W_·j)`) take over the family, in reduced echelon form;
/// those that only say some `W_ij = 0` are left to [`rectangles`], and a row whose `α_i` is
/// already zero has nothing to split.
fn factors<F: ExactField>(
    solution: &ExactSolution<F>,
    entries: &[(usize, &CatalogueEntry)],
) -> Vec<Factor<F>>
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
        for side_a in [true, false] {
            let (count, other) = if side_a { (na, nb) } else { (nb, na) };
            for index in 0..count {
                let head = start + 1 + if side_a { index } else { na + index };
                if zero(head) {
                    continue;
                }
                let mut variables = vec![head];
                variables.extend((0..other).map(
                    |t| {
                        if side_a { w(index, t) } else { w(t, index) }
                    },
                ));
                for coefficients in identities(solution, &variables) {
                    let only_w_unit = coefficients[0].is_zero()
                        && coefficients[1..].iter().filter(|c| !c.is_zero()).count() == 1;
                    if !only_w_unit {
                        out.push(Factor {
                            k,
                            side_a,
                            index,
                            coefficients,
                        });
                    }
                }
            }
        }
    }
    out
}

/// The vectors `c` with `Σ c_t·x_{variables[t]} = 0` on the whole family: the null space of
/// the matrix whose rows are the variables' constant part and their free directions.
fn identities<F: ExactField>(solution: &ExactSolution<F>, variables: &[usize]) -> Vec<Vec<F>>
where
    for<'a> &'a F: RefArith<F>,
{
    let mut rows: Vec<Vec<F::Entry>> = std::iter::once(&solution.particular)
        .chain(&solution.nullspace)
        .map(|v| {
            let values: Vec<F> = variables.iter().map(|&j| v[j].clone()).collect();
            let mut row = F::equation_row(&values);
            row.push(F::zero_entry());
            row
        })
        .collect();
    rows.retain(|r| r.iter().any(|e| !F::entry_is_zero(e)));
    F::eliminate(rows, variables.len()).nullspace()
}

/// The two branches of a [`Factor`]: the anchor part zero (`α_i = 0`, `W_i· = 0`), or the
/// other factor `c·K + d·β = 0` (`c·K + d·α = 0` for a column).
fn factor_rows<F: ExactField>(
    solution: &ExactSolution<F>,
    entries: &[(usize, &CatalogueEntry)],
    f: &Factor<F>,
    part_zero: bool,
) -> Vec<Vec<F>> {
    if part_zero {
        let r = Rectangle {
            k: f.k,
            rows: if f.side_a { vec![f.index] } else { Vec::new() },
            columns: if f.side_a { Vec::new() } else { vec![f.index] },
        };
        return branch_rows(solution, entries, &r, f.side_a);
    }
    let Element::Spring { axes_a, axes_b, .. } = &entries[f.k].1.element else {
        unreachable!("factors are found on springs only");
    };
    let (na, nb) = (axes_a.len(), axes_b.len());
    let start = solution.offsets[f.k];
    let mut row = vec![F::zero(); solution.echelon.columns];
    row[start] = f.coefficients[0].clone();
    // d·β for a row of a, d·α for a column of b.
    let first = if f.side_a { start + 1 + na } else { start + 1 };
    let count = if f.side_a { nb } else { na };
    row[first..first + count].clone_from_slice(&f.coefficients[1..]);
    vec![row]
}

/// `c·K + d·β` (or `d·α`) of a [`Factor`] in the spring's variable names, for proofs.
fn factor_text<F: ExactField>(entry: &CatalogueEntry, f: &Factor<F>) -> (String, String)
where
    for<'a> &'a F: RefArith<F>,
{
    let Element::Spring { axes_a, axes_b, .. } = &entry.element else {
        unreachable!("factors are found on springs only");
    };
    let axis = |axes: &[usize], t: usize| ["x", "y", "z"][axes[t]];
    let (part, others, other_side) = if f.side_a {
        (format!("a{}", axis(axes_a, f.index)), axes_b, "b")
    } else {
        (format!("b{}", axis(axes_b, f.index)), axes_a, "a")
    };
    let mut terms = Vec::new();
    let mut push = |c: &F, name: String| {
        if !c.is_zero() {
            terms.push(format!("{}·{name}", super::exact_text(c)));
        }
    };
    push(&f.coefficients[0], "K".to_string());
    for t in 0..others.len() {
        push(
            &f.coefficients[1 + t],
            format!("K·{other_side}{}", axis(others, t)),
        );
    }
    (part, terms.join(" + "))
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
    let mut solution = basis.solve_with(set, extra);
    if !solution.consistent() {
        return Outcome::Proof("the balance equations have no solution".to_string());
    }
    // A branch can fix anchor components the family left free (a_i = 0 once α_i = 0): impose
    // what that means for W, until nothing new follows (the rank only grows, so this ends).
    let mut extra = extra.to_vec();
    loop {
        let (_, rows) = anchors::fixed_anchor_equations(&solution, entries);
        if rows.is_empty() {
            break;
        }
        let mut more = extra.clone();
        more.extend(rows);
        let restricted = basis.solve_with(set, &more);
        if !restricted.consistent() {
            return Outcome::Proof(
                "with the anchor components balance then fixes, the balance equations have no \
                 solution"
                    .to_string(),
            );
        }
        if restricted.rank() == solution.rank() {
            break;
        }
        (extra, solution) = (more, restricted);
    }
    let extra = &extra[..];
    let open = || Outcome::Open(vec![extra.to_vec()]);
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
    for f in factors(&solution, entries) {
        let mut proofs = Vec::new();
        let mut open_here = Vec::new();
        for part_zero in [true, false] {
            let mut rows = extra.to_vec();
            rows.extend(factor_rows(&solution, entries, &f, part_zero));
            match node(basis, set, entries, &rows, depth - 1, sign_proof, budget) {
                Outcome::Proof(p) => proofs.push(p),
                Outcome::Open(l) => open_here.extend(l),
            }
        }
        if proofs.len() == 2 {
            let entry = entries[f.k].1;
            let (part, other) = factor_text(entry, &f);
            return Outcome::Proof(format!(
                "{label}: balance makes {part}·({other}) = 0, so {part} = 0 or \
                 {other} = 0; with {part} = 0, {p}; with {other} = 0, {q}",
                label = entry.label,
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
            bodies: vec!["rod".into(), "base".into()],
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

    /// The one-spring basis with the given columns (one entry per balance row) and a zero
    /// unbalanced energy: every row reads `Σ columns[j][r]·x_j = 0`.
    fn homogeneous(columns: Vec<Vec<BigInt>>) -> ExactBasis<Rational> {
        let rows = columns[0].len();
        ExactBasis {
            monomials: (0..rows).map(Monomial::sine).collect(),
            unbalanced: vec![BigInt::from(0); rows],
            elements: vec![columns],
            row_factors: vec![Rational::from_integer(1.into()); rows],
        }
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
    /// The one spring with the single hand-written balance row `αy + 2·Wyy = 0` (every other
    /// variable free). For a physical spring `αy = ay·K` and `Wyy = ay·βy`, so the row says
    /// `ay·(K + 2·βy) = 0`: the one identity of an anchor row or column (no `W` component is
    /// zero, no other row or column is constrained), with the branches `αy = 0, Wyx = Wyy = 0`
    /// and `K + 2·βy = 0`.
    #[test]
    fn a_row_identity_splits_into_a_zero_part_or_the_other_factor() {
        let mut columns = vec![vec![BigInt::from(0)]; 9];
        columns[2] = vec![BigInt::from(1)];
        columns[8] = vec![BigInt::from(2)];
        let basis = homogeneous(columns);
        let solution = basis.solve(&[0]);
        let entry = spring();
        let entries = [(0, &entry)];
        assert!(rectangles(&solution, &entries).is_empty());
        let found = factors(&solution, &entries);
        assert_eq!(found.len(), 1);
        let f = &found[0];
        assert!(f.side_a && f.index == 1, "row y of a");
        let q = |n: i64| Rational::from_integer(n.into());
        // (c, d_x, d_y) ∝ (1, 0, 2).
        let c = f.coefficients[0].clone();
        assert_ne!(c, q(0));
        let scaled: Vec<Rational> = f.coefficients.iter().map(|v| v / &c).collect();
        assert_eq!(scaled, vec![q(1), q(0), q(2)]);
        assert_eq!(
            zeroed(&factor_rows(&solution, &entries, f, true)),
            vec![2, 7, 8]
        );
        let other = factor_rows(&solution, &entries, f, false);
        assert_eq!(other.len(), 1);
        let row: Vec<Rational> = other[0].iter().map(|v| v / &c).collect();
        let mut expected = vec![q(0); 9];
        expected[0] = q(1);
        expected[4] = q(2);
        assert_eq!(row, expected, "K + 2·βy = 0");
        let (part, text) = factor_text(&entry, f);
        assert_eq!(part, "ay");
        assert!(text.contains("·K") && text.contains("·K·by"), "{text}");
    }
    /// The column version: the single row `βy + 2·Wyy = 0` says `by·(K + 2·αy) = 0`
    /// (`βy = by·K`, `Wyy = αy·by`), with the branches `βy = 0, Wxy = Wyy = 0` and
    /// `K + 2·αy = 0`.
    #[test]
    fn a_column_identity_splits_into_a_zero_part_or_the_other_factor() {
        let mut columns = vec![vec![BigInt::from(0)]; 9];
        columns[4] = vec![BigInt::from(1)];
        columns[8] = vec![BigInt::from(2)];
        let basis = homogeneous(columns);
        let solution = basis.solve(&[0]);
        let entry = spring();
        let entries = [(0, &entry)];
        let found = factors(&solution, &entries);
        assert_eq!(found.len(), 1);
        let f = &found[0];
        assert!(!f.side_a && f.index == 1, "column y of b");
        let q = |n: i64| Rational::from_integer(n.into());
        let c = f.coefficients[0].clone();
        assert_ne!(c, q(0));
        let scaled: Vec<Rational> = f.coefficients.iter().map(|v| v / &c).collect();
        assert_eq!(scaled, vec![q(1), q(0), q(2)]);
        assert_eq!(
            zeroed(&factor_rows(&solution, &entries, f, true)),
            vec![4, 6, 8]
        );
        let other = factor_rows(&solution, &entries, f, false);
        let row: Vec<Rational> = other[0].iter().map(|v| v / &c).collect();
        let mut expected = vec![q(0); 9];
        expected[0] = q(1);
        expected[2] = q(2);
        assert_eq!(row, expected, "K + 2·αy = 0");
        let (part, text) = factor_text(&entry, f);
        assert_eq!(part, "by");
        assert!(text.contains("·K·ay"), "{text}");
    }
    /// Rows `αy + 2·Wyy = 0` and `Wyx − Wyy = 0`: over the family `(αy, Wyx, Wyy)` moves along
    /// `(−2, 1, 1)` only, so row y of `a` has exactly two independent identities, `(1, 0, 2)` and
    /// `(0, 1, −1)`, and no other row or column has one.
    #[test]
    fn identities_are_the_null_space_of_the_family_directions() {
        let mut columns = vec![vec![BigInt::from(0); 2]; 9];
        columns[2] = vec![BigInt::from(1), BigInt::from(0)];
        columns[7] = vec![BigInt::from(0), BigInt::from(1)];
        columns[8] = vec![BigInt::from(2), BigInt::from(-1)];
        let basis = homogeneous(columns);
        let solution = basis.solve(&[0]);
        let entry = spring();
        let found = factors(&solution, &[(0, &entry)]);
        assert_eq!(found.len(), 2);
        assert!(found.iter().all(|f| f.side_a && f.index == 1));
        let q = |n: i64| Rational::from_integer(n.into());
        let dot = |f: &Factor<Rational>, v: [i64; 3]| {
            f.coefficients
                .iter()
                .zip(v)
                .fold(q(0), |acc, (c, x)| acc + c * q(x))
        };
        for f in &found {
            assert_eq!(dot(f, [-2, 1, 1]), q(0), "an identity along the family");
        }
        assert_ne!(found[0].coefficients, found[1].coefficients);
    }
}
