//! Gauss–Jordan elimination with exact division, for fields whose entries are their own elements
//! (ℚ(√2, √3)). Every pivot row is divided by its pivot, so the reduced rows are unique (the
//! reduced row-echelon form) and rank, consistency and the solution set are facts of the field.

use counterpoise_symbolic::{Rational, RefArith, Surd};

use super::field::Echelon;
use super::field::ExactField;

/// Eliminates `[A | r]`, given as rows of `columns + 1` field elements.
pub fn gauss_jordan<F>(mut rows: Vec<Vec<F>>, columns: usize) -> Echelon<F>
where
    F: ExactField<Entry = F>,
    for<'a> &'a F: RefArith<F>,
{
    rows.retain(|row| row.iter().any(|v| !v.is_zero()));
    let mut pivots = Vec::new();
    let mut done = 0;
    for c in 0..columns {
        let Some(p) = (done..rows.len()).find(|&r| !rows[r][c].is_zero()) else {
            continue;
        };
        rows.swap(done, p);
        let inverse = &F::one() / &rows[done][c];
        for v in rows[done].iter_mut() {
            if !v.is_zero() {
                *v = &*v * &inverse;
            }
        }
        let pivot_row = rows[done].clone();
        for (r, row) in rows.iter_mut().enumerate() {
            if r == done || row[c].is_zero() {
                continue;
            }
            let factor = row[c].clone();
            for k in 0..=columns {
                if !pivot_row[k].is_zero() {
                    row[k] = &row[k] - &(&factor * &pivot_row[k]);
                }
            }
        }
        pivots.push(c);
        done += 1;
    }
    let consistent = rows[done..]
        .iter()
        .all(|row| row.iter().all(|v| v.is_zero()));
    rows.truncate(done);
    Echelon {
        columns,
        rows,
        pivots,
        consistent,
    }
}

/// ℚ(√2, √3): entries are field elements, eliminated with exact division (above).
impl ExactField for Surd {
    type Entry = Surd;
    fn entry_is_zero(e: &Surd) -> bool {
        counterpoise_symbolic::Scalar::is_zero(e)
    }
    fn zero_entry() -> Surd {
        Surd::default()
    }
    fn neg_entry(e: &Surd) -> Surd {
        -e
    }
    fn entry_value(e: &Surd) -> Surd {
        e.clone()
    }
    fn ratio(a: &Surd, p: &Surd) -> Surd {
        a / p
    }
    /// No scaling: the factors are 1 (the elimination divides anyway).
    fn scale_rows(
        b: Vec<Surd>,
        columns: Vec<Vec<Vec<Surd>>>,
    ) -> (Vec<Surd>, Vec<Vec<Vec<Surd>>>, Vec<Surd>) {
        let factors = vec![Surd::from_rational(Rational::from_integer(1.into())); b.len()];
        (b, columns, factors)
    }
    fn equation_row(e: &[Surd]) -> Vec<Surd> {
        e.to_vec()
    }
    fn eliminate(rows: Vec<Vec<Surd>>, columns: usize) -> Echelon<Surd> {
        gauss_jordan(rows, columns)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use counterpoise_symbolic::{Rational, Scalar, Surd};

    fn s(a: i64, b: i64, c: i64, d: i64) -> Surd {
        let q = |n: i64| Rational::from_integer(n.into());
        Surd::new(q(a), q(b), q(c), q(d))
    }

    #[test]
    fn solves_a_system_with_surd_coefficients() {
        // √2·x + √3·y = 1, √3·x − √2·y = 0 (a rotation-like system, determinant −5):
        // y = √3/√2·x, so √2 x + 3/√2 x = 1 ⇒ x = √2/5, y = √3/5.
        let rows = vec![
            vec![s(0, 1, 0, 0), s(0, 0, 1, 0), s(1, 0, 0, 0)],
            vec![s(0, 0, 1, 0), s(0, -1, 0, 0), s(0, 0, 0, 0)],
        ];
        let e = gauss_jordan(rows, 2);
        assert!(e.consistent);
        assert_eq!(e.rank(), 2);
        let fifth = Rational::new(1.into(), 5.into());
        assert_eq!(
            e.particular(),
            vec![s(0, 1, 0, 0).scale(&fifth), s(0, 0, 1, 0).scale(&fifth)]
        );
    }

    #[test]
    fn dependent_rows_and_contradictions_are_exact() {
        // (1 + √2)·x = 1 and x = √2 − 1 are the same equation ((1 + √2)(√2 − 1) = 1): rank 1,
        // consistent; a third row x = √2 − 1 + 10⁻²⁰ is not.
        let rows = vec![
            vec![s(1, 1, 0, 0), s(1, 0, 0, 0)],
            vec![s(1, 0, 0, 0), s(-1, 1, 0, 0)],
        ];
        let e = gauss_jordan(rows.clone(), 1);
        assert!(e.consistent);
        assert_eq!(e.rank(), 1);
        assert_eq!(e.particular(), vec![s(-1, 1, 0, 0)]);
        let tiny = Surd::from_rational(Rational::new(
            1.into(),
            num_bigint::BigInt::from(10).pow(20),
        ));
        let mut off = rows;
        off.push(vec![s(1, 0, 0, 0), &s(-1, 1, 0, 0) + &tiny]);
        assert!(!gauss_jordan(off, 1).consistent);
        // A free column: x + √3·y = 2 leaves y free, with null direction (−√3, 1).
        let free = gauss_jordan(vec![vec![Surd::one(), s(0, 0, 1, 0), s(2, 0, 0, 0)]], 2);
        assert_eq!(free.nullspace(), vec![vec![s(0, 0, -1, 0), Surd::one()]]);
    }
}
