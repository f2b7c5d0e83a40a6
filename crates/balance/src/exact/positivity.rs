//! Exact linear feasibility over the balanced family: can every mass and stiffness be positive,
//! and how far can each lifted variable range while they are?
//!
//! The family is `x = x_p + N z`; each installed element's mass or stiffness is an affine
//! function `h_i(z)`, and positivity asks for `z` with every `h_i(z) > 0`. Fourier–Motzkin
//! elimination decides this exactly in rationals (a variant has at most `Dmax` such constraints,
//! so the elimination stays tiny), and carries the non-negative multipliers of every derived
//! inequality: when it ends in `0 < c ≤ 0`, those multipliers are a Farkas certificate,
//! `Σ λ_i h_i(z) ≡ c ≤ 0`, that anyone can check by hand.

use counterpoise_symbolic::{Rational, RefArith};

use super::field::ExactField;

/// An affine function `constant + Σ coefficients[k]·z_k`.
#[derive(Clone, Debug, PartialEq)]
pub struct Affine<F = Rational> {
    pub constant: F,
    pub coefficients: Vec<F>,
}

impl<F: ExactField> Affine<F>
where
    for<'a> &'a F: RefArith<F>,
{
    fn combine(&self, a: &F, other: &Affine<F>, b: &F) -> Affine<F> {
        Affine {
            constant: &self.constant * a + &other.constant * b,
            coefficients: self
                .coefficients
                .iter()
                .zip(&other.coefficients)
                .map(|(x, y)| x * a + y * b)
                .collect(),
        }
    }

    pub fn is_constant(&self) -> bool {
        self.coefficients.iter().all(|c| c.is_zero())
    }
}

/// `f(z) > 0` (strict) or `f(z) ≥ 0`, with the multipliers of the original constraints that
/// produced it.
#[derive(Clone, Debug)]
struct Inequality<F> {
    f: Affine<F>,
    strict: bool,
    multipliers: Vec<F>,
}

/// Why no `z` satisfies the constraints: `Σ multipliers[i]·h_i(z) ≡ value` for every `z`, with
/// non-negative multipliers, while the constraints demand it be positive.
#[derive(Clone, Debug, PartialEq)]
pub struct Infeasibility<F = Rational> {
    pub multipliers: Vec<F>,
    pub value: F,
}

/// Eliminates every variable but the last `keep` ones; `Err` on a contradiction.
fn eliminate<F: ExactField>(
    mut rows: Vec<Inequality<F>>,
    keep: usize,
) -> Result<Vec<Inequality<F>>, Infeasibility<F>>
where
    for<'a> &'a F: RefArith<F>,
{
    let n = rows.first().map_or(0, |r| r.f.coefficients.len());
    for var in 0..n.saturating_sub(keep) {
        let (mut positive, mut negative, mut rest) = (Vec::new(), Vec::new(), Vec::new());
        for row in rows {
            let c = &row.f.coefficients[var];
            if c.is_zero() {
                rest.push(row);
            } else if c.is_positive() {
                positive.push(row);
            } else {
                negative.push(row);
            }
        }
        for p in &positive {
            for q in &negative {
                // (−q_var)·p + p_var·q cancels the variable; both factors are positive.
                let a = -q.f.coefficients[var].clone();
                let b = p.f.coefficients[var].clone();
                rest.push(Inequality {
                    f: p.f.combine(&a, &q.f, &b),
                    strict: p.strict || q.strict,
                    multipliers: p
                        .multipliers
                        .iter()
                        .zip(&q.multipliers)
                        .map(|(x, y)| x * &a + y * &b)
                        .collect(),
                });
            }
        }
        rows = rest;
        check_constants(&rows)?;
    }
    Ok(rows)
}

/// A row without variables must hold as it stands.
fn check_constants<F: ExactField>(rows: &[Inequality<F>]) -> Result<(), Infeasibility<F>>
where
    for<'a> &'a F: RefArith<F>,
{
    for row in rows.iter().filter(|r| r.f.is_constant()) {
        let c = &row.f.constant;
        let violated = if row.strict {
            !c.is_positive()
        } else {
            c.is_negative()
        };
        if violated {
            return Err(Infeasibility {
                multipliers: row.multipliers.clone(),
                value: c.clone(),
            });
        }
    }
    Ok(())
}

fn strict_rows<F: ExactField>(constraints: &[Affine<F>]) -> Vec<Inequality<F>> {
    let m = constraints.len();
    constraints
        .iter()
        .enumerate()
        .map(|(i, f)| Inequality {
            f: f.clone(),
            strict: true,
            multipliers: (0..m)
                .map(|j| if i == j { F::one() } else { F::zero() })
                .collect(),
        })
        .collect()
}

/// Whether some `z` makes every constraint strictly positive; the certificate when none does.
pub fn strictly_feasible<F: ExactField>(constraints: &[Affine<F>]) -> Result<(), Infeasibility<F>>
where
    for<'a> &'a F: RefArith<F>,
{
    let rows = strict_rows(constraints);
    check_constants(&rows)?;
    eliminate(rows, 0).map(|_| ())
}

/// One end of an interval: `None` for ±∞.
#[derive(Clone, Debug, PartialEq)]
pub struct Bound<F = Rational> {
    pub value: F,
    /// Whether the end is attained.
    pub closed: bool,
}

/// The range of an affine function over `{z : every constraint > 0}` (assumed non-empty).
#[derive(Clone, Debug, PartialEq)]
pub struct Range<F = Rational> {
    pub low: Option<Bound<F>>,
    pub high: Option<Bound<F>>,
}

/// The range of `target(z)` while every constraint is strictly positive.
pub fn range<F: ExactField>(
    constraints: &[Affine<F>],
    target: &Affine<F>,
) -> Result<Range<F>, Infeasibility<F>>
where
    for<'a> &'a F: RefArith<F>,
{
    let Some(pivot) = target.coefficients.iter().position(|c| !c.is_zero()) else {
        strictly_feasible(constraints)?;
        let fixed = Bound {
            value: target.constant.clone(),
            closed: true,
        };
        return Ok(Range {
            low: Some(fixed.clone()),
            high: Some(fixed),
        });
    };
    // z_pivot = (t − target.constant − Σ_{k≠pivot} g_k z_k) / g_pivot; the variables become
    // (z without pivot, t), t last.
    let g = &target.coefficients;
    // A constraint without the pivot is unchanged but for the new variable's zero, and a zero
    // of `g` leaves its coefficient as it is: both skip the exact products (most constraints
    // of a balanced family hold a few of its free parameters).
    let substitute = |f: &Affine<F>| -> Affine<F> {
        let ratio = &f.coefficients[pivot] / &g[pivot];
        let keep = ratio.is_zero();
        let mut coefficients: Vec<F> = f
            .coefficients
            .iter()
            .zip(g)
            .enumerate()
            .filter(|(k, _)| *k != pivot)
            .map(|(_, (fk, gk))| {
                if keep || gk.is_zero() {
                    fk.clone()
                } else {
                    fk - &ratio * gk
                }
            })
            .collect();
        coefficients.push(ratio.clone());
        let constant = if keep || target.constant.is_zero() {
            f.constant.clone()
        } else {
            &f.constant - &ratio * &target.constant
        };
        Affine {
            constant,
            coefficients,
        }
    };
    let transformed: Vec<Affine<F>> = constraints.iter().map(substitute).collect();
    let rows = strict_rows(&transformed);
    check_constants(&rows)?;
    let rows = eliminate(rows, 1)?;
    let mut low: Option<Bound<F>> = None;
    let mut high: Option<Bound<F>> = None;
    for row in rows {
        let a = row.f.coefficients.last().cloned().unwrap_or_else(F::zero);
        if a.is_zero() {
            continue; // checked as a constant row by the elimination
        }
        // a t + c > 0 (or ≥): t > −c/a when a > 0, t < −c/a when a < 0.
        let value = -&row.f.constant / &a;
        let bound = Bound {
            value,
            closed: !row.strict,
        };
        if a.is_positive() {
            let tighter = low
                .as_ref()
                .is_none_or(|l| bound.value > l.value || (bound.value == l.value && !bound.closed));
            if tighter {
                low = Some(bound);
            }
        } else {
            let tighter = high
                .as_ref()
                .is_none_or(|h| bound.value < h.value || (bound.value == h.value && !bound.closed));
            if tighter {
                high = Some(bound);
            }
        }
    }
    Ok(Range { low, high })
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_bigint::BigInt;

    fn q(n: i64) -> Rational {
        Rational::from_integer(BigInt::from(n))
    }

    fn affine(constant: i64, coefficients: &[i64]) -> Affine {
        Affine {
            constant: q(constant),
            coefficients: coefficients.iter().map(|&c| q(c)).collect(),
        }
    }

    #[test]
    fn opposite_stiffnesses_cannot_both_be_positive() {
        // K21 = z, K51 = −z: the relation K21 + K51 = 0 of the palletizer's {K21, K51, m4}.
        let constraints = [affine(0, &[1]), affine(0, &[-1]), affine(5, &[0])];
        let err = strictly_feasible(&constraints).unwrap_err();
        // 1·K21 + 1·K51 ≡ 0 — the certificate is the relation itself.
        assert_eq!(err.multipliers, vec![q(1), q(1), q(0)]);
        assert_eq!(err.value, q(0));
    }

    #[test]
    fn a_shared_load_has_the_hand_computed_share() {
        // K1 = z1, K2 = 9 − z1 − 28 z2, m = z2: K1 ranges over (0, 9), K2 too, m over (0, 9/28).
        let constraints = [
            affine(0, &[1, 0]),
            affine(9, &[-1, -28]),
            affine(0, &[0, 1]),
        ];
        assert!(strictly_feasible(&constraints).is_ok());
        let m = range(&constraints, &affine(0, &[0, 1])).unwrap();
        let nine_28 = Rational::new(BigInt::from(9), BigInt::from(28));
        assert_eq!(
            m.low,
            Some(Bound {
                value: q(0),
                closed: false
            })
        );
        assert_eq!(
            m.high,
            Some(Bound {
                value: nine_28,
                closed: false
            })
        );
        // A combination that grows without bound in one direction.
        let free = range(&[affine(0, &[1, 0])], &affine(1, &[1, 1])).unwrap();
        assert_eq!(free.low, None);
        assert_eq!(free.high, None);
        let half_line = range(&[affine(-2, &[1])], &affine(0, &[3])).unwrap();
        assert_eq!(
            half_line.low,
            Some(Bound {
                value: q(6),
                closed: false
            })
        );
        assert_eq!(half_line.high, None);
    }

    fn open(n: i64, d: i64) -> Option<Bound> {
        Some(Bound {
            value: Rational::new(BigInt::from(n), BigInt::from(d)),
            closed: false,
        })
    }

    #[test]
    fn the_certificate_carries_non_unit_multipliers() {
        // By hand: 2z − 1 > 0 needs z > 1/2 and 1 − 3z > 0 needs z < 1/3. Cancelling z takes
        // 3·(2z − 1) + 2·(1 − 3z) = −1 ≤ 0, so the multipliers are (3, 2) and the value −1.
        let err = strictly_feasible(&[affine(-1, &[2]), affine(1, &[-3])]).unwrap_err();
        assert_eq!(err.multipliers, vec![q(3), q(2)]);
        assert_eq!(err.value, q(-1));
        // With z < 1 instead the interval (1/2, 1) is not empty.
        assert!(strictly_feasible(&[affine(-1, &[2]), affine(1, &[-1])]).is_ok());
    }

    #[test]
    fn the_tightest_of_several_bounds_wins_in_any_order() {
        // z > 1, z > 3, z < 7, z < 10: by hand the range of z is (3, 7). The tighter lower bound
        // comes second, the tighter upper bound first, and the other way round.
        let constraints = [
            affine(-1, &[1]),
            affine(-3, &[1]),
            affine(7, &[-1]),
            affine(10, &[-1]),
        ];
        let z = affine(0, &[1]);
        for order in [[0, 1, 2, 3], [1, 0, 3, 2]] {
            let reordered: Vec<Affine> = order.iter().map(|&i| constraints[i].clone()).collect();
            let r = range(&reordered, &z).unwrap();
            assert_eq!((r.low, r.high), (open(3, 1), open(7, 1)), "{order:?}");
        }
        // Equal bounds twice: still the open interval (3, 7).
        let twice = [affine(-3, &[1]), affine(-3, &[1]), affine(7, &[-1])];
        let r = range(&twice, &z).unwrap();
        assert_eq!((r.low, r.high), (open(3, 1), open(7, 1)));
    }

    #[test]
    fn a_target_with_several_coefficients_ranges_between_the_vertex_values() {
        // The open triangle z1 > 0, z2 > 0, z1 + z2 < 4 has vertices (0,0), (4,0), (0,4); the
        // affine target 1 + 2 z1 + z2 takes 1, 9 and 5 there, so its range is (1, 9). The same
        // with 5 − z1 + 3 z2 (pivot on a negative coefficient): 5, 1 and 17, range (1, 17).
        let triangle = [affine(0, &[1, 0]), affine(0, &[0, 1]), affine(4, &[-1, -1])];
        let r = range(&triangle, &affine(1, &[2, 1])).unwrap();
        assert_eq!((r.low, r.high), (open(1, 1), open(9, 1)));
        let r = range(&triangle, &affine(5, &[-1, 3])).unwrap();
        assert_eq!((r.low, r.high), (open(1, 1), open(17, 1)));
        // Scaled so the pivot ratio is a fraction: 3·z1 over the triangle ranges over (0, 12).
        let r = range(&triangle, &affine(0, &[3, 0])).unwrap();
        assert_eq!((r.low, r.high), (open(0, 1), open(12, 1)));
        // A constant target is its own range, closed, when the constraints are feasible...
        let r = range(&triangle, &affine(2, &[0, 0])).unwrap();
        let two = Some(Bound {
            value: q(2),
            closed: true,
        });
        assert_eq!((r.low, r.high), (two.clone(), two));
        // ...and an error when they are not.
        assert!(range(&[affine(-1, &[0])], &affine(2, &[0])).is_err());
    }

    #[test]
    fn a_fixed_negative_mass_is_infeasible() {
        let err = strictly_feasible(&[affine(-3, &[])]).unwrap_err();
        assert_eq!(err.value, q(-3));
    }
}
