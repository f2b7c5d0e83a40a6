//! The two fields the exact decision runs in, and how each stores and eliminates a basis.
//!
//! Over ℚ every row of `[A | b]` is scaled to coprime integers and eliminated fraction-free
//! ([`super::elimination`]): the fast path every rational case (the palletizer) takes. Over
//! ℚ(√2, √3) entries are field elements and the elimination is plain Gauss–Jordan with exact
//! division ([`super::elimination_field`]); such systems are small (a variant has a few dozen
//! lifted variables), so the 4-rational arithmetic costs little. Everything downstream
//! (positivity, the rank-one test, relations) is written once over [`ExactField`].

use std::fmt::Debug;

use num_bigint::BigInt;
use num_integer::Integer;
use num_traits::Zero;

use counterpoise_symbolic::{Ordered, Rational, Surd};

use super::elimination::{Echelon, eliminate};

/// An exact ordered field with its basis storage and elimination.
pub trait ExactField: Ordered {
    /// One stored entry of the basis: a row-scaled integer over ℚ, the element itself otherwise.
    type Entry: Clone + Debug + PartialEq + Send + Sync;
    fn entry_is_zero(e: &Self::Entry) -> bool;
    fn zero_entry() -> Self::Entry;
    fn neg_entry(e: &Self::Entry) -> Self::Entry;
    /// The entry as a field element.
    fn entry_value(e: &Self::Entry) -> Self;
    /// `a / p` for a non-zero `p`.
    fn ratio(a: &Self::Entry, p: &Self::Entry) -> Self;
    /// Scales every row (monomial) of `[b | columns]` by a positive factor, returning the scaled
    /// `b`, the scaled columns and the factors (physical coefficient × factor = stored entry).
    #[allow(clippy::type_complexity)]
    fn scale_rows(
        b: Vec<Self>,
        columns: Vec<Vec<Vec<Self>>>,
    ) -> (Vec<Self::Entry>, Vec<Vec<Vec<Self::Entry>>>, Vec<Self>);
    /// A homogeneous equation over the field as a row of entries (any non-zero multiple).
    fn equation_row(e: &[Self]) -> Vec<Self::Entry>;
    /// Gauss–Jordan elimination of `[A | r]` (rows of `columns + 1` entries).
    fn eliminate(rows: Vec<Vec<Self::Entry>>, columns: usize) -> Echelon<Self>;
}

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
        super::elimination_field::gauss_jordan(rows, columns)
    }
}
