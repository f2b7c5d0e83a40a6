//! The exact rank-one test: a spring's lifted `W = α βᵀ / K` shown impossible on the family.
//!
//! A spring is realizable only where `A_W (K·W − α βᵀ) = 0` (just the combinations of `W` that
//! change the energy matter). Along the family `x = x_p + N z` every component of that residual
//! is a quadratic polynomial in `z`, computed here exactly. When it is identically
//! `c₀ + c₁·K(z)` — no quadratic part, a linear part parallel to `K`'s — a spring exists only at
//! `K = −c₀/c₁`; if that value is not a positive stiffness the whole family admits (or two rows
//! demand different values, or `c₁ = 0 ≠ c₀`), no spring does: a proof, not a threshold.

use counterpoise_symbolic::RefArith;

use super::positivity::{self, Affine};
use super::{ExactBasis, ExactField, ExactSolution, exact_text};
use crate::element::{CatalogueEntry, Element};

/// A quadratic polynomial in `z`: constant, linear and (unsymmetrised) quadratic coefficients.
struct Quadratic<F> {
    constant: F,
    linear: Vec<F>,
    quadratic: Vec<Vec<F>>,
}

impl<F: ExactField> Quadratic<F>
where
    for<'a> &'a F: RefArith<F>,
{
    fn zero(n: usize) -> Quadratic<F> {
        Quadratic {
            constant: F::zero(),
            linear: vec![F::zero(); n],
            quadratic: vec![vec![F::zero(); n]; n],
        }
    }

    /// `self += s · f · g`.
    fn add_product(&mut self, s: &F, f: &Affine<F>, g: &Affine<F>) {
        if s.is_zero() {
            return;
        }
        self.constant += s * &f.constant * &g.constant;
        let n = self.linear.len();
        for u in 0..n {
            let lin = &f.constant * &g.coefficients[u] + &g.constant * &f.coefficients[u];
            if !lin.is_zero() {
                self.linear[u] += s * lin;
            }
            if f.coefficients[u].is_zero() {
                continue;
            }
            let fu = s * &f.coefficients[u];
            for v in 0..n {
                if !g.coefficients[v].is_zero() {
                    self.quadratic[u][v] += &fu * &g.coefficients[v];
                }
            }
        }
    }

    fn has_quadratic_part(&self) -> bool {
        let n = self.linear.len();
        (0..n).any(|u| (u..n).any(|v| !(&self.quadratic[u][v] + &self.quadratic[v][u]).is_zero()))
    }
}

/// What one residual row demands of the stiffness.
enum Demand<F> {
    /// Not of the form `c₀ + c₁ K`: this test says nothing.
    Unknown,
    /// Zero everywhere: no condition.
    Nothing,
    /// `c₀ + c₁·K` with `c₁ = 0 ≠ c₀`: never zero.
    Impossible(F),
    /// `c₀ + c₁·K` with `c₁ ≠ 0`: zero exactly at `K = −c₀/c₁`.
    Stiffness { c0: F, c1: F },
}

fn demand<F: ExactField>(residual: &Quadratic<F>, stiffness: &Affine<F>) -> Demand<F>
where
    for<'a> &'a F: RefArith<F>,
{
    if residual.has_quadratic_part() {
        return Demand::Unknown;
    }
    let c1 = match stiffness.coefficients.iter().position(|c| !c.is_zero()) {
        Some(u) => &residual.linear[u] / &stiffness.coefficients[u],
        None => F::zero(),
    };
    let parallel = residual
        .linear
        .iter()
        .zip(&stiffness.coefficients)
        .all(|(r, k)| *r == &c1 * k);
    if !parallel {
        return Demand::Unknown;
    }
    let c0 = &residual.constant - &c1 * &stiffness.constant;
    match (c0.is_zero(), c1.is_zero()) {
        (true, true) => Demand::Nothing,
        (false, true) => Demand::Impossible(c0),
        (_, false) => Demand::Stiffness { c0, c1 },
    }
}

/// The proof that some spring of the variant cannot be rank-one, when this test finds one.
pub fn contradiction<F: ExactField>(
    basis: &ExactBasis<F>,
    solution: &ExactSolution<F>,
    entries: &[&CatalogueEntry],
) -> Option<String>
where
    for<'a> &'a F: RefArith<F>,
{
    let heads = solution.heads();
    let n = solution.nullity();
    for (k, entry) in entries.iter().enumerate() {
        let Element::Spring { axes_a, axes_b, .. } = &entry.element else {
            continue;
        };
        let (na, nb) = (axes_a.len(), axes_b.len());
        let start = solution.offsets[k];
        let w_start = start + 1 + na + nb;
        let columns = &basis.elements[solution.elements[k]];
        let stiffness = solution.affine(start);
        let mut required: Option<F> = None;
        let mut form = String::new();
        for (r, factor) in basis.row_factors.iter().enumerate() {
            let weights: Vec<F> = (0..na * nb)
                .map(|ij| F::entry_value(&columns[1 + na + nb + ij][r]))
                .collect();
            if weights.iter().all(|w| w.is_zero()) {
                continue;
            }
            let mut residual = Quadratic::zero(n);
            for i in 0..na {
                for j in 0..nb {
                    let a = &weights[i * nb + j];
                    residual.add_product(a, &stiffness, &solution.affine(w_start + i * nb + j));
                    residual.add_product(
                        &-a.clone(),
                        &solution.affine(start + 1 + i),
                        &solution.affine(start + 1 + na + j),
                    );
                }
            }
            match demand(&residual, &stiffness) {
                // A row this test cannot read adds conditions, but takes none away.
                Demand::Unknown | Demand::Nothing => {}
                Demand::Impossible(c0) => {
                    return Some(format!(
                        "{}: no spring has the anchors balance requires (K·W − α·βᵀ = {} for \
                         every K)",
                        entry.label,
                        exact_text(&(c0 / factor))
                    ));
                }
                Demand::Stiffness { c0, c1 } => {
                    let value = -&c0 / &c1;
                    // In physical units (J per unit), undoing the row's integer scaling.
                    let (c0, c1) = (c0 / factor, c1 / factor);
                    form = if c0.is_zero() {
                        format!("K·W − α·βᵀ = {}·K", exact_text(&c1))
                    } else {
                        format!("K·W − α·βᵀ = {} + {}·K", exact_text(&c0), exact_text(&c1))
                    };
                    if let Some(previous) = &required
                        && *previous != value
                    {
                        return Some(format!(
                            "{}: balance would need the stiffness to be both {} and {} N/m",
                            entry.label,
                            exact_text(previous),
                            exact_text(&value)
                        ));
                    }
                    required = Some(value);
                }
            }
        }
        let Some(value) = required else { continue };
        if !value.is_positive() {
            return Some(format!(
                "{}: no spring has the anchors balance requires ({form} on every solution, zero \
                 only at K = {} N/m)",
                entry.label,
                exact_text(&value)
            ));
        }
        // The forced stiffness must also be reachable with every head positive.
        if let Ok(range) = positivity::range(&heads, &stiffness) {
            let below = range
                .low
                .as_ref()
                .is_some_and(|l| value < l.value || (value == l.value && !l.closed));
            let above = range
                .high
                .as_ref()
                .is_some_and(|h| value > h.value || (value == h.value && !h.closed));
            if below || above {
                return Some(format!(
                    "{}: no spring has the anchors balance requires ({form} on every solution, \
                     zero only at K = {} N/m, outside what positive masses and stiffnesses allow)",
                    entry.label,
                    exact_text(&value)
                ));
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::element::Attachment;
    use counterpoise_symbolic::{Monomial, Rational};
    use num_bigint::BigInt;

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

    fn counterweight() -> CatalogueEntry {
        CatalogueEntry {
            element: Element::Counterweight {
                body: 0,
                axes: vec![0, 1],
            },
            label: "m1".into(),
            description: "counterweight".into(),
            bodies: vec!["rod".into()],
            variables: Vec::new(),
            energy: Vec::new(),
        }
    }

    /// Counterweight `(m, m·rx, m·ry)` and spring `(K, αx, αy, βx, βy, Wxx, Wxy, Wyx, Wyy)` with
    /// the balance rows `m + s·K = c` (`s = ±1`), `α = (2, 1)`, `β = (3, 2)` and `w·Wxx = 6`
    /// (scaled by `factor` from the physical row). By hand, `K·Wxx = αx·βx` forces
    /// `K = 2·3/(6/w) = w`, and positive heads allow `K < c` (`s = 1`) or `K > −c` (`s = −1`).
    fn decide(s: i64, c: i64, w: i64, factor: i64) -> Option<String> {
        // (column of the variant, coefficient) per row, and the row's right-hand side.
        let rows: [(&[(usize, i64)], i64); 6] = [
            (&[(0, 1), (3, s)], c),
            (&[(4, 1)], 2),
            (&[(5, 1)], 1),
            (&[(6, 1)], 3),
            (&[(7, 1)], 2),
            (&[(8, w)], 6),
        ];
        let column = |j: usize| -> Vec<BigInt> {
            rows.iter()
                .map(|(terms, _)| {
                    let c = terms.iter().find(|(k, _)| *k == j).map_or(0, |&(_, v)| v);
                    BigInt::from(c)
                })
                .collect()
        };
        let mut row_factors = vec![Rational::from_integer(1.into()); rows.len()];
        row_factors[5] = Rational::from_integer(factor.into());
        let basis = ExactBasis {
            monomials: (0..rows.len()).map(Monomial::sine).collect(),
            unbalanced: rows.iter().map(|&(_, v)| BigInt::from(-v)).collect(),
            elements: vec![(0..3).map(column).collect(), (3..12).map(column).collect()],
            row_factors,
        };
        let solution = basis.solve(&[0, 1]);
        assert!(solution.consistent());
        contradiction(&basis, &solution, &[&counterweight(), &spring()])
    }

    /// A lone one-axis spring `(K, α, β, W)` with balance rows `Σ coefficient·x = rhs`.
    fn lone_spring(rows: &[(&[(usize, i64)], i64)]) -> Option<String> {
        let column = |j: usize| -> Vec<BigInt> {
            rows.iter()
                .map(|(terms, _)| {
                    let c = terms.iter().find(|(k, _)| *k == j).map_or(0, |&(_, v)| v);
                    BigInt::from(c)
                })
                .collect()
        };
        let basis = ExactBasis {
            monomials: (0..rows.len()).map(Monomial::sine).collect(),
            unbalanced: rows.iter().map(|&(_, v)| BigInt::from(-v)).collect(),
            elements: vec![(0..4).map(column).collect()],
            row_factors: vec![Rational::from_integer(1.into()); rows.len()],
        };
        let solution = basis.solve(&[0]);
        assert!(solution.consistent());
        let entry = CatalogueEntry {
            element: Element::Spring {
                body: 0,
                other: Attachment::Base,
                axes_a: vec![0],
                axes_b: vec![0],
            },
            ..spring()
        };
        contradiction(&basis, &solution, &[&entry])
    }

    #[test]
    fn a_quadratic_residual_proves_nothing_unless_its_square_terms_cancel() {
        // K = 1 and W = 1 fixed, α = z1 and β = z2 free: K·W − α·β = 1 − z1·z2 is zero on the
        // hyperbola z1·z2 = 1 (a = b = 1 is a spring), so there is no proof.
        assert_eq!(lone_spring(&[(&[(0, 1)], 1), (&[(3, 1)], 1)]), None);
        // K = z, α = β = 2z, W = 4z + 1: K·W − α·β = 4z² + z − 4z² = z, zero only at K = 0.
        assert_eq!(
            lone_spring(&[
                (&[(3, 1), (0, -4)], 1),
                (&[(1, 1), (0, -2)], 0),
                (&[(2, 1), (0, -2)], 0),
            ]),
            Some(
                "K1: no spring has the anchors balance requires (K·W − α·βᵀ = 1·K on every \
                 solution, zero only at K = 0 N/m)"
                    .to_string()
            )
        );
        // K = 1, W = 4, α = β = z: K·W − α·β = 4 − z², zero at z = ±2 (a = b = 2): no proof.
        assert_eq!(
            lone_spring(&[(&[(0, 1)], 1), (&[(3, 1)], 4), (&[(1, 1), (2, -1)], 0)]),
            None
        );
    }

    #[test]
    fn a_stiffness_with_a_constant_part_demands_the_hand_computed_value() {
        // W = 4, 2β = 6 and K − α = 1 (K = 1 + z, α = z): K·W − α·β = 4K − 3(K − 1) = K + 3,
        // zero only at K = −3: no positive spring. Only the row where W appears (weight 1) is
        // read, so the form is K + 3, not a multiple of it.
        assert_eq!(
            lone_spring(&[(&[(3, 1)], 4), (&[(2, 2)], 6), (&[(0, 1), (1, -1)], 1)]),
            Some(
                "K1: no spring has the anchors balance requires (K·W − α·βᵀ = 3 + 1·K on every \
                 solution, zero only at K = -3 N/m)"
                    .to_string()
            )
        );
    }

    #[test]
    fn a_forced_stiffness_outside_the_positive_range_is_a_contradiction() {
        let outside = |form: &str, k: i64| {
            Some(format!(
                "K1: no spring has the anchors balance requires ({form} on every solution, zero \
                 only at K = {k} N/m, outside what positive masses and stiffnesses allow)"
            ))
        };
        // w = 6: Wxx = 1, residual of the Wxx row 6·(K·1 − 6) = −36 + 6·K, zero at K = 6; but
        // m = 5 − K > 0 needs K < 5.
        assert_eq!(decide(1, 5, 6, 1), outside("K·W − α·βᵀ = -36 + 6·K", 6));
        // m = K − 7 > 0 needs K > 7: K = 6 is below.
        assert_eq!(decide(-1, -7, 6, 1), outside("K·W − α·βᵀ = -36 + 6·K", 6));
        // 5·(K·6/5 − 6) = 6K − 30, in physical units (row factor 2) −15 + 3·K: K = 5 is the open
        // end of K < 5, which positive masses never reach.
        assert_eq!(decide(1, 5, 5, 2), outside("K·W − α·βᵀ = -15 + 3·K", 5));
        // 7·(K·6/7 − 6) = −42 + 6·K: K = 7 is the open end of K > 7.
        assert_eq!(decide(-1, -7, 7, 1), outside("K·W − α·βᵀ = -42 + 6·K", 7));
        // K = 4 inside (0, 5) and K = 8 inside (7, ∞): a spring may exist, no proof.
        assert_eq!(decide(1, 5, 4, 1), None);
        assert_eq!(decide(-1, -7, 8, 1), None);
    }
}
