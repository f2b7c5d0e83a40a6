//! ℚ as an [`ExactField`]: each row of `[A | b]` scaled to coprime integers by a positive
//! factor, then eliminated fraction-free. The fast path every rational case takes.

use num_bigint::BigInt;
use num_integer::Integer;
use num_traits::Zero;

use counterpoise_symbolic::Rational;

use super::elimination::eliminate;
use super::field::{Echelon, ExactField};

/// ℚ: rows scaled to coprime integers, eliminated fraction-free ([`super::elimination`]).
impl ExactField for Rational {
    type Entry = BigInt;
    fn entry_is_zero(e: &BigInt) -> bool {
        e.is_zero()
    }
    fn zero_entry() -> BigInt {
        BigInt::zero()
    }
    fn neg_entry(e: &BigInt) -> BigInt {
        -e
    }
    fn entry_value(e: &BigInt) -> Rational {
        Rational::from_integer(e.clone())
    }
    fn ratio(a: &BigInt, p: &BigInt) -> Rational {
        Rational::new(a.clone(), p.clone())
    }
    fn scale_rows(
        b: Vec<Rational>,
        columns: Vec<Vec<Vec<Rational>>>,
    ) -> (Vec<BigInt>, Vec<Vec<Vec<BigInt>>>, Vec<Rational>) {
        let rows = b.len();
        // One positive factor per row: the lcm of its denominators over the gcd of its
        // numerators.
        let mut factors = Vec::with_capacity(rows);
        for r in 0..rows {
            let entries = std::iter::once(&b[r]).chain(columns.iter().flatten().map(|c| &c[r]));
            let (mut lcm, mut gcd) = (BigInt::from(1), BigInt::zero());
            for q in entries.filter(|q| !q.is_zero()) {
                lcm = lcm.lcm(q.denom());
                gcd = gcd.gcd(q.numer());
            }
            let gcd = if gcd.is_zero() { BigInt::from(1) } else { gcd };
            factors.push(Rational::new(lcm, gcd));
        }
        let scale = |v: &[Rational]| -> Vec<BigInt> {
            v.iter()
                .zip(&factors)
                .map(|(q, f)| {
                    let s = q * f;
                    debug_assert!(s.is_integer());
                    s.to_integer()
                })
                .collect()
        };
        let scaled_b = scale(&b);
        let scaled = columns
            .iter()
            .map(|entry| entry.iter().map(|c| scale(c)).collect())
            .collect();
        (scaled_b, scaled, factors)
    }
    fn equation_row(e: &[Rational]) -> Vec<BigInt> {
        let lcm = e.iter().fold(BigInt::from(1), |acc, q| acc.lcm(q.denom()));
        e.iter()
            .map(|q| (q * Rational::from_integer(lcm.clone())).to_integer())
            .collect()
    }
    fn eliminate(rows: Vec<Vec<BigInt>>, columns: usize) -> Echelon<Rational> {
        eliminate(&rows, columns)
    }
}
