//! Variant enumeration (paper Eq. 9) and its count (Eqs. A6–A8).

use itertools::Itertools;

/// Every set of 1..=`dmax` distinct element indices out of `elements`, by size then in
/// lexicographic order: lazily generated, and always in the same order.
pub fn variants(elements: usize, dmax: usize) -> impl Iterator<Item = Vec<usize>> {
    (1..=dmax.min(elements)).flat_map(move |d| (0..elements).combinations(d))
}

/// `C(n, k)` in u128 (exact for every catalogue this tool can enumerate).
pub fn binomial(n: u64, k: u64) -> u128 {
    if k > n {
        return 0;
    }
    let k = k.min(n - k);
    (0..k).fold(1u128, |acc, i| acc * u128::from(n - i) / u128::from(i + 1))
}

/// Paper Eq. A8: the number of variants with at most `dmax` of `counterweights + springs`
/// elements, where Eq. A6 gives `counterweights = L` and Eq. A7 `springs = C(L+1, 2)` (or
/// `C(L, 2)` without base springs).
pub fn variant_count(counterweights: u64, springs: u64, dmax: u64) -> u128 {
    let e = counterweights + springs;
    (1..=dmax.min(e)).map(|d| binomial(e, d)).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Paper Eqs. A6–A8 with `L` members: `L` counterweights, `L(L+1)/2` springs with the base,
    /// `L(L−1)/2` without.
    fn paper_count(members: u64, base: bool, dmax: u64) -> u128 {
        let springs = if base {
            members * (members + 1) / 2
        } else {
            members * (members - 1) / 2
        };
        variant_count(members, springs, dmax)
    }

    #[test]
    fn palletizer_counts_match_the_paper() {
        // Paper Sec. 3 / App. A.3: L = 7, no base springs, Dmax = 2 → 406 variants.
        assert_eq!(paper_count(7, false, 2), 406);
        assert_eq!(paper_count(7, false, 3), 3682);
        assert_eq!(variants(28, 2).count(), 406);
        assert_eq!(variants(28, 3).count(), 3682);
    }

    #[test]
    fn enumeration_matches_eq_a8_for_several_settings() {
        for members in 1..=5u64 {
            for base in [false, true] {
                for dmax in 1..=4u64 {
                    let springs = if base {
                        members * (members + 1) / 2
                    } else {
                        members * (members - 1) / 2
                    };
                    let n = (members + springs) as usize;
                    let enumerated = variants(n, dmax as usize).count() as u128;
                    // independent count: sum of binomials by Pascal's rule, built row by row
                    let mut row = vec![1u128];
                    for _ in 0..n {
                        let mut next = vec![1u128; row.len() + 1];
                        for k in 1..row.len() {
                            next[k] = row[k - 1] + row[k];
                        }
                        row = next;
                    }
                    let pascal: u128 = (1..=(dmax as usize).min(n)).map(|d| row[d]).sum();
                    assert_eq!(enumerated, pascal, "L={members} base={base} dmax={dmax}");
                    assert_eq!(paper_count(members, base, dmax), pascal);
                }
            }
        }
    }

    /// `C(n, k) = C(n, n − k)`: near `k = n` the product runs over the short side, so large
    /// catalogues do not overflow u128 on the way. By hand: `C(n, n−1) = n`,
    /// `C(200, 2) = 200·199/2 = 19900`, and `C(n, k) = 0` for `k > n`.
    #[test]
    fn binomials_near_k_equal_n_use_the_short_side() {
        assert_eq!(binomial(200, 199), 200);
        assert_eq!(binomial(200, 198), 19_900);
        assert_eq!(binomial(200, 2), 19_900);
        assert_eq!(binomial(200, 200), 1);
        assert_eq!(binomial(200, 0), 1);
        assert_eq!(binomial(5, 6), 0);
    }

    #[test]
    fn variants_are_distinct_sorted_sets() {
        let all: Vec<_> = variants(6, 3).collect();
        for v in &all {
            assert!(v.windows(2).all(|w| w[0] < w[1]));
        }
        let mut dedup = all.clone();
        dedup.sort();
        dedup.dedup();
        assert_eq!(dedup.len(), all.len());
    }
}
