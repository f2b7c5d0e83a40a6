//! The equations a physical spring satisfies where balance fixes its anchors, in whole or in
//! part: `K·a = a₀·K` on the whole family means `a = a₀`, so `W = K·a·bᵀ = a₀·βᵀ` is linear.

use counterpoise_symbolic::RefArith;

use super::{ExactField, ExactSolution};
use crate::element::{CatalogueEntry, Element};

/// For every spring whose anchor `a` (or `b`) balance fixes — `K·a = a₀·K` on the whole family —
/// the equations `W = a₀ βᵀ` (or `W = α b₀ᵀ`) a physical spring must satisfy, as rows over the
/// variant's variables; for a spring whose anchors balance fixes only in some components, the
/// rows and columns of `W` those components determine; and the anchors, described.
#[allow(clippy::type_complexity)]
pub fn fixed_anchor_equations<F: ExactField>(
    solution: &ExactSolution<F>,
    entries: &[(usize, &CatalogueEntry)],
) -> (Vec<String>, Vec<Vec<F>>)
where
    for<'a> &'a F: RefArith<F>,
{
    let n = solution.echelon.columns;
    let mut anchors = Vec::new();
    let mut rows = Vec::new();
    for (k, (_, entry)) in entries.iter().enumerate() {
        let Element::Spring { axes_a, axes_b, .. } = &entry.element else {
            continue;
        };
        let (na, nb) = (axes_a.len(), axes_b.len());
        let start = solution.offsets[k];
        let (alpha, beta, w) = (start + 1, start + 1 + na, start + 1 + na + nb);
        let describe = |side: &str, v: &[F]| {
            let values: Vec<String> = v.iter().map(super::exact_text).collect();
            format!("{}'s anchor {side} = ({})", entry.label, values.join(", "))
        };
        // W_ij − (fixed factor)·(free factor) = 0 for every component.
        let mut push_rows = |fixed: &[F], free_start: usize, a_fixed: bool| {
            for i in 0..na {
                for j in 0..nb {
                    let mut row = vec![F::zero(); n];
                    row[w + i * nb + j] = F::one();
                    let (f, v) = if a_fixed { (i, j) } else { (j, i) };
                    row[free_start + v] = -fixed[f].clone();
                    rows.push(row);
                }
            }
        };
        let a_parts = solution.proportional_components(start, alpha..alpha + na);
        let b_parts = solution.proportional_components(start, beta..beta + nb);
        if let Some(a0) = a_parts.iter().cloned().collect::<Option<Vec<F>>>() {
            push_rows(&a0, beta, true);
            anchors.push(describe("a", &a0));
        } else if let Some(b0) = b_parts.iter().cloned().collect::<Option<Vec<F>>>() {
            push_rows(&b0, alpha, false);
            anchors.push(describe("b", &b0));
        } else {
            // Neither anchor is fixed whole, but some of their components may be: `a_i = a₀ᵢ`
            // gives `W_ij = a₀ᵢ·β_j` for every j (row i of W), `b_j = b₀ⱼ` gives
            // `W_ij = b₀ⱼ·α_i` for every i (column j). In particular `K·a_i = 0` on the family
            // means `a_i = 0` (K > 0), so the whole row `W_i·` of a physical spring is zero.
            for (i, ai) in a_parts.iter().enumerate() {
                let Some(ai) = ai else { continue };
                for j in 0..nb {
                    let mut row = vec![F::zero(); n];
                    row[w + i * nb + j] = F::one();
                    row[beta + j] = -ai.clone();
                    rows.push(row);
                }
            }
            for (j, bj) in b_parts.iter().enumerate() {
                let Some(bj) = bj else { continue };
                for i in 0..na {
                    let mut row = vec![F::zero(); n];
                    row[w + i * nb + j] = F::one();
                    row[alpha + i] = -bj.clone();
                    rows.push(row);
                }
            }
            let part = |side: &str, parts: &[Option<F>]| {
                let values: Vec<String> = parts
                    .iter()
                    .map(|v| v.as_ref().map_or("free".to_string(), super::exact_text))
                    .collect();
                format!("{side} = ({})", values.join(", "))
            };
            if a_parts.iter().chain(&b_parts).any(Option::is_some) {
                anchors.push(format!(
                    "{}'s anchor components {} and {}",
                    entry.label,
                    part("a", &a_parts),
                    part("b", &b_parts)
                ));
            }
        }
    }
    (anchors, rows)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::element::Attachment;
    use crate::exact::ExactBasis;
    use counterpoise_symbolic::{Monomial, Rational};

    /// A spring's variables `(K, αx, αy, βx, βy, Wxx, Wxy, Wyx, Wyy)` with the hand-written
    /// balance equations `αy = 2·K` and `βx = 3·K`: `ay = 2` and `bx = 3` are fixed, `ax` and
    /// `by` free. A physical spring then has row y of `W` equal to `2·β` (`Wyx − 2βx = 0`,
    /// `Wyy − 2βy = 0`) and column x equal to `3·α` (`Wxx − 3αx = 0`, `Wyx − 3αy = 0`).
    #[test]
    fn fixed_components_give_their_row_and_column_of_w() {
        let int = |v: &[i64]| -> Vec<num_bigint::BigInt> { v.iter().map(|&x| x.into()).collect() };
        let q = |n: i64| Rational::from_integer(n.into());
        let mut columns = vec![int(&[0, 0]); 9];
        columns[0] = int(&[-2, -3]);
        columns[2] = int(&[1, 0]);
        columns[3] = int(&[0, 1]);
        let basis = ExactBasis {
            monomials: vec![Monomial::sine(0), Monomial::sine(1)],
            unbalanced: int(&[0, 0]),
            elements: vec![columns],
            row_factors: vec![q(1), q(1)],
        };
        let entry = CatalogueEntry {
            element: Element::Spring {
                body: 0,
                other: Attachment::Base,
                axes_a: vec![0, 1],
                axes_b: vec![0, 1],
            },
            label: "K1".into(),
            description: "a spring".into(),
            bodies: vec!["rod".into(), "base".into()],
            variables: Vec::new(),
            energy: Vec::new(),
        };
        let (anchors, rows) = fixed_anchor_equations(&basis.solve(&[0]), &[(0, &entry)]);
        assert_eq!(
            anchors,
            vec!["K1's anchor components a = (free, 2) and b = (3, free)".to_string()]
        );
        let row = |terms: &[(usize, i64)]| {
            let mut r = vec![q(0); 9];
            for &(j, c) in terms {
                r[j] = q(c);
            }
            r
        };
        assert_eq!(
            rows,
            vec![
                row(&[(7, 1), (3, -2)]),
                row(&[(8, 1), (4, -2)]),
                row(&[(5, 1), (1, -3)]),
                row(&[(7, 1), (2, -3)]),
            ]
        );
    }
}
