//! Fraction-free Gauss–Jordan elimination of an integer system `A x = r`.
//!
//! Rows are integer vectors; a step replaces `row ← pivot·row − row[c]·pivot_row` and then
//! divides the row by the gcd of its entries (its content), which keeps numbers as small as the
//! problem allows. Everything is exact: rank, consistency, pivots, the particular solution and
//! the null-space basis are facts over ℚ, not thresholds.
//!
//! Most palletizer systems stay within `i128`; each step is tried there with overflow checks
//! and the whole elimination is redone in [`BigInt`] when a value would overflow, so the result
//! never depends on which arithmetic ran.

use num_bigint::BigInt;
use num_integer::Integer;
use num_traits::{Signed, Zero};

use counterpoise_symbolic::Rational;

pub use super::field::{Echelon, Relation};

/// A ring the elimination can run in.
trait Ring: Clone + Sized {
    fn is_zero(&self) -> bool;
    /// `a·b − c·d`, or `None` on overflow.
    fn mul_sub(a: &Self, b: &Self, c: &Self, d: &Self) -> Option<Self>;
    fn gcd(&self, other: &Self) -> Self;
    fn div_exact(&self, d: &Self) -> Self;
    fn is_one(&self) -> bool;
    fn bits(&self) -> u64;
    fn is_negative(&self) -> bool;
    fn neg(&self) -> Self;
    fn to_big(&self) -> BigInt;
}

impl Ring for i128 {
    fn is_zero(&self) -> bool {
        *self == 0
    }
    fn mul_sub(a: &i128, b: &i128, c: &i128, d: &i128) -> Option<i128> {
        a.checked_mul(*b)?.checked_sub(c.checked_mul(*d)?)
    }
    fn gcd(&self, other: &i128) -> i128 {
        Integer::gcd(self, other)
    }
    fn div_exact(&self, d: &i128) -> i128 {
        self / d
    }
    fn is_one(&self) -> bool {
        *self == 1
    }
    fn bits(&self) -> u64 {
        u64::from(128 - self.unsigned_abs().leading_zeros())
    }
    fn is_negative(&self) -> bool {
        *self < 0
    }
    fn neg(&self) -> i128 {
        -self
    }
    fn to_big(&self) -> BigInt {
        BigInt::from(*self)
    }
}

impl Ring for BigInt {
    fn is_zero(&self) -> bool {
        Zero::is_zero(self)
    }
    fn mul_sub(a: &BigInt, b: &BigInt, c: &BigInt, d: &BigInt) -> Option<BigInt> {
        Some(a * b - c * d)
    }
    fn gcd(&self, other: &BigInt) -> BigInt {
        Integer::gcd(self, other)
    }
    fn div_exact(&self, d: &BigInt) -> BigInt {
        self / d
    }
    fn is_one(&self) -> bool {
        *self == BigInt::from(1)
    }
    fn bits(&self) -> u64 {
        self.magnitude().bits()
    }
    fn is_negative(&self) -> bool {
        Signed::is_negative(self)
    }
    fn neg(&self) -> BigInt {
        -self
    }
    fn to_big(&self) -> BigInt {
        self.clone()
    }
}

/// Eliminates `[A | r]`, given as rows of `columns + 1` integers.
pub fn eliminate(rows: &[Vec<BigInt>], columns: usize) -> Echelon<Rational> {
    if let Some(echelon) = eliminate_small(rows, columns) {
        return echelon;
    }
    gauss_jordan(rows.to_vec(), columns).expect("big integers do not overflow")
}

/// The elimination in checked `i128` alone: `None` when an entry does not fit or a step would
/// overflow.
fn eliminate_small(rows: &[Vec<BigInt>], columns: usize) -> Option<Echelon<Rational>> {
    let small: Option<Vec<Vec<i128>>> = rows
        .iter()
        .map(|row| row.iter().map(|v| i128::try_from(v).ok()).collect())
        .collect();
    gauss_jordan(small?, columns)
}

/// Divides a row by the gcd of its entries and makes its pivot positive.
fn remove_content<T: Ring>(row: &mut [T], pivot: Option<usize>) {
    let mut g: Option<T> = None;
    for v in row.iter().filter(|v| !v.is_zero()) {
        g = Some(match g {
            None => v.gcd(v),
            Some(g) => g.gcd(v),
        });
        if g.as_ref().is_some_and(Ring::is_one) {
            break;
        }
    }
    let Some(mut g) = g else { return };
    if pivot.is_some_and(|c| row[c].is_negative()) {
        g = g.neg();
    }
    if !g.is_one() {
        for v in row.iter_mut() {
            *v = v.div_exact(&g);
        }
    }
}

fn gauss_jordan<T: Ring>(mut rows: Vec<Vec<T>>, columns: usize) -> Option<Echelon<Rational>> {
    rows.retain(|row| row.iter().any(|v| !v.is_zero()));
    for row in &mut rows {
        remove_content(row, None);
    }
    let mut pivots = Vec::new();
    let mut done = 0; // rows[..done] hold pivots
    for c in 0..columns {
        // The smallest non-zero entry keeps the growth down.
        let Some(p) = (done..rows.len())
            .filter(|&r| !rows[r][c].is_zero())
            .min_by_key(|&r| rows[r][c].bits())
        else {
            continue;
        };
        rows.swap(done, p);
        remove_content(&mut rows[done], Some(c));
        let pivot_row = rows[done].clone();
        let pivot = pivot_row[c].clone();
        for (r, row) in rows.iter_mut().enumerate() {
            if r == done || row[c].is_zero() {
                continue;
            }
            let factor = row[c].clone();
            for k in 0..=columns {
                if !(row[k].is_zero() && pivot_row[k].is_zero()) {
                    row[k] = T::mul_sub(&row[k], &pivot, &factor, &pivot_row[k])?;
                }
            }
            remove_content(row, None);
        }
        pivots.push(c);
        done += 1;
    }
    let consistent = rows[done..]
        .iter()
        .all(|row| row[columns].is_zero() && row[..columns].iter().all(Ring::is_zero));
    rows.truncate(done);
    for (row, &c) in rows.iter_mut().zip(&pivots) {
        remove_content(row, Some(c));
    }
    Some(Echelon {
        columns,
        rows: rows
            .into_iter()
            .map(|row| row.iter().map(Ring::to_big).collect())
            .collect(),
        pivots,
        consistent,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn big(rows: &[&[i64]]) -> Vec<Vec<BigInt>> {
        rows.iter()
            .map(|r| r.iter().map(|&v| BigInt::from(v)).collect())
            .collect()
    }

    fn q(n: i64, d: i64) -> Rational {
        Rational::new(BigInt::from(n), BigInt::from(d))
    }

    #[test]
    fn solves_a_rank_deficient_system_exactly() {
        // x + 2y + 3z = 6, 2x + 4y + 6z = 12, y − z = 1/2 ⇒ (scaled) 2y − 2z = 1.
        let e = eliminate(&big(&[&[1, 2, 3, 6], &[2, 4, 6, 12], &[0, 2, -2, 1]]), 3);
        assert_eq!(e.rank(), 2);
        assert!(e.consistent);
        assert_eq!(e.pivots, vec![0, 1]);
        // z = 0: y = 1/2, x = 6 − 1 = 5.
        assert_eq!(e.particular(), vec![q(5, 1), q(1, 2), q(0, 1)]);
        // Null direction: z = 1, y = 1, x = −5.
        assert_eq!(e.nullspace(), vec![vec![q(-5, 1), q(1, 1), q(1, 1)]]);
    }

    #[test]
    fn relations_read_off_the_reduced_rows() {
        // The system of the test above, reduced by hand: y − z = 1/2 and x + 2y + 3z = 6 give
        // x + 5z = 5. Only the free column z appears, never the pivot itself or a zero entry.
        let e = eliminate(&big(&[&[1, 2, 3, 6], &[2, 4, 6, 12], &[0, 2, -2, 1]]), 3);
        assert_eq!(
            e.relations(),
            vec![
                (0, vec![(2, q(5, 1))], q(5, 1)),
                (1, vec![(2, q(-1, 1))], q(1, 2)),
            ]
        );
        // A full-rank system has no free terms: x = 9/5, y = 3/5 (solved by hand below).
        let full = eliminate(&big(&[&[2, 4, 6], &[-3, 9, 0]]), 2);
        assert_eq!(
            full.relations(),
            vec![(0, vec![], q(9, 5)), (1, vec![], q(3, 5))]
        );
    }

    /// The i128 and the big-integer arithmetic must reach the same reduced rows (the fallback is
    /// only for overflow): the same elimination run in both rings is a second computation.
    #[test]
    fn both_arithmetics_give_the_same_reduced_rows() {
        let systems: [&[&[i64]]; 4] = [
            &[&[2, 4, 6], &[-3, 9, 0]],
            &[&[-2, 4, 6]],
            &[&[1, 2, 3, 6], &[2, 4, 6, 12], &[0, 2, -2, 1]],
            &[&[0, -6, 4, 2], &[0, 9, -6, 1], &[-4, 2, 0, 8]],
        ];
        for rows in systems {
            let rows = big(rows);
            let columns = rows[0].len() - 1;
            let small = eliminate_small(&rows, columns).expect("small numbers stay in i128");
            let big = gauss_jordan(rows.clone(), columns).expect("no overflow");
            assert_eq!(small, big, "{rows:?}");
        }
        // By hand for the last one: −6y + 4z = 2 and 9y − 6z = 1 are 3y − 2z = −1 and
        // 3y − 2z = 1/9: inconsistent; the pivots are x (from −4x + 2y = 8) and y.
        let last = gauss_jordan(big(&[&[0, -6, 4, 2], &[0, 9, -6, 1], &[-4, 2, 0, 8]]), 3).unwrap();
        assert!(!last.consistent);
        assert_eq!(last.pivots, vec![0, 1]);
        // Every reduced row is primitive with a positive pivot, in the big ring too.
        let flipped = gauss_jordan(big(&[&[-2, 4, 6]]), 2).unwrap();
        assert_eq!(flipped.rows, big(&[&[1, -2, -3]]));
    }

    #[test]
    fn rows_end_in_lowest_terms_with_positive_pivots_on_the_small_path() {
        // 2x + 4y = 6 and −3x + 9y = 0: solved in i128, each row divided by its content.
        let rows = big(&[&[2, 4, 6], &[-3, 9, 0]]);
        let small = eliminate_small(&rows, 2).expect("small numbers stay in i128");
        assert_eq!(small, eliminate(&rows, 2));
        for (row, &p) in small.rows.iter().zip(&small.pivots) {
            let content = row.iter().fold(BigInt::zero(), |g, v| Integer::gcd(&g, v));
            assert_eq!(content, BigInt::from(1), "{row:?}");
            assert!(Signed::is_positive(&row[p]), "{row:?}");
        }
        // x = 6/5·… : 2x + 4y = 6, −3x + 9y = 0 ⇒ x = 3y, 10y = 6 ⇒ y = 3/5, x = 9/5.
        assert_eq!(small.particular(), vec![q(9, 5), q(3, 5)]);
        // A negative pivot is made positive: −2x + 4y = 6 becomes x − 2y = −3.
        let flipped = eliminate_small(&big(&[&[-2, 4, 6]]), 2).expect("small");
        assert_eq!(flipped.rows, big(&[&[1, -2, -3]]));
        assert_eq!(flipped.particular(), vec![q(-3, 1), q(0, 1)]);
        // Entries beyond i128 leave the small path.
        let huge = BigInt::from(2).pow(130);
        assert!(eliminate_small(&[vec![huge.clone(), huge]], 1).is_none());
    }

    #[test]
    fn detects_inconsistency_exactly() {
        // x + y = 1 and 3x + 3y = 3 + 10⁻³⁰ (as integers): inconsistent by a hair.
        let tiny = BigInt::from(10).pow(30);
        let rows = vec![
            vec![tiny.clone(), tiny.clone(), tiny.clone()],
            vec![&tiny * 3, &tiny * 3, &tiny * 3 + 1],
        ];
        let e = eliminate(&rows, 2);
        assert_eq!(e.rank(), 1);
        assert!(!e.consistent);
    }

    #[test]
    fn overflowing_small_path_falls_back_to_big_integers() {
        // Entries near 2^100 fit in i128 but their products do not: the result must still be
        // Cramer's rule, computed here independently in rationals.
        let v = |k: i64| BigInt::from(2).pow(100) + BigInt::from(k * k * 7919 + k);
        let (a, b, e) = (v(1), v(2), v(3));
        let (c, d, f) = (v(4), v(5), v(6));
        let e_form = eliminate(
            &[
                vec![a.clone(), b.clone(), e.clone()],
                vec![c.clone(), d.clone(), f.clone()],
            ],
            2,
        );
        let det = &a * &d - &b * &c;
        let x = Rational::new(&e * &d - &b * &f, det.clone());
        let y = Rational::new(&a * &f - &e * &c, det);
        assert_eq!(e_form.rank(), 2);
        assert!(e_form.consistent);
        assert_eq!(e_form.particular(), vec![x, y]);
    }
}
