//! Phase 3 ranking (paper Sec. 2.3, Proc-9): lexicographic by ΔQTR, then ΔQIT, then ΔR, lower
//! is better for each.
//!
//! **Resolution: a fixed grid.** Indicators are compared at a resolution `res` (default 0.01
//! percentage points): each value is replaced by its *cell*, the nearest multiple of `res`
//! (`round(v / res)`; at the default, the two decimals the tables print), and variants are
//! ordered by their ΔQTR cells, then their ΔQIT cells, then their ΔR cells. Values in the same
//! cell tie and the next criterion decides.
//!
//! Why a grid. "Values closer than `res` tie" is not an equivalence (a ~ b and b ~ c within
//! `res` while a and c are not), so no order can follow it on every pair: with a = (0, 10),
//! b = (0.006, 0), c = (0.012, −10) on (ΔQTR, ΔQIT) it asks for c before b before a before c.
//! The previous rule joined such chains into one tie group, and a group could then span many
//! resolutions: at Dmax 3 on the palletizer SB56 (ΔQTR −54.1045) was ranked above SB57
//! (−54.1191). Cells are an equivalence, and rounding is monotone, so they give the guarantee
//! the rule is read for: **if i is ranked above j, then on the criterion that decides them
//! (the first whose cells differ) i is better, and on every criterion before it the two are
//! less than `res` apart**; no pair is ordered against a criterion by `res` or more unless an
//! earlier criterion put i ahead. The price, stated in the reports: two values closer than
//! `res` on either side of a half-way point `(n + ½)·res` are in different cells, and the
//! lower one wins on that criterion. A cell does not depend on the other variants either, so
//! adding or removing variants (another Dmax, a merge of shards) never reorders two others.
//!
//! `res = 0` compares the values exactly.
//!
//! **Final tie-break.** Variants in the same cell on all three criteria are ordered by their
//! tie-break key (the caller passes the element labels, e.g. `"K42 + K43"`), then by their
//! exact values and input position, so the order of distinct items never depends on the
//! order they are given in; the groups are returned so the report can say which ranks were
//! decided this way.
//!
//! **Class ranks** are positions within the global order restricted to the class, so the
//! per-class rankings never contradict the global one.

use std::cmp::Ordering;

use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Default tolerance of the equivalence, percentage points.
pub const DEFAULT_TOLERANCE: f64 = 0.5;

/// The paper's three classes of balanced variants (the shared vocabulary).
pub use counterpoise_vocabulary::Class;

/// Settings of the ranking.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RankingOptions {
    /// The grid of the comparison, percentage points: values rounded to the same multiple of
    /// it tie (see the module doc). Default 0.01; 0 compares exactly.
    pub resolution: f64,
    /// Tolerance of the decision section's equivalence groups, percentage points (see
    /// [`crate::decision`]); it does not change the ranking. Default 0.5.
    #[serde(default = "default_tolerance")]
    pub tolerance: f64,
}

fn default_tolerance() -> f64 {
    DEFAULT_TOLERANCE
}

impl Default for RankingOptions {
    fn default() -> Self {
        RankingOptions {
            resolution: 0.01,
            tolerance: default_tolerance(),
        }
    }
}

/// One variant to rank.
#[derive(Clone, Debug, PartialEq)]
pub struct RankItem {
    /// Deterministic final tie-break (ascending), e.g. the variant's element labels.
    pub key: String,
    pub class: Class,
    /// Percent, lower is better.
    pub dqtr: f64,
    pub dqit: f64,
    pub dr: f64,
}

/// The ranking of a list of [`RankItem`]s (indices refer to that list).
#[derive(Clone, Debug, PartialEq)]
pub struct Ranking {
    /// Item indices, best first.
    pub order: Vec<usize>,
    /// 1-based global rank of each item.
    pub rank: Vec<usize>,
    /// 1-based rank of each item within its class.
    pub class_rank: Vec<usize>,
    /// Groups (in rank order, each of size ≥ 2) in the same cell on all three criteria, hence
    /// ordered by the tie-break key.
    pub tie_groups: Vec<Vec<usize>>,
}

#[derive(Debug, Error, PartialEq)]
pub enum RankingError {
    #[error("ranking resolution must be finite and ≥ 0, got {0}")]
    BadResolution(f64),
    #[error("equivalence tolerance must be finite and ≥ 0 percentage points, got {0}")]
    BadTolerance(f64),
    #[error("variant {key}: {criterion} is not finite ({value})")]
    NotFinite {
        key: String,
        criterion: &'static str,
        value: f64,
    },
}

const CRITERIA: [&str; 3] = ["ΔQTR", "ΔQIT", "ΔR"];

fn criterion(item: &RankItem, k: usize) -> f64 {
    match k {
        0 => item.dqtr,
        1 => item.dqit,
        _ => item.dr,
    }
}

/// Ranks `items` (see the module doc).
pub fn rank(items: &[RankItem], options: &RankingOptions) -> Result<Ranking, RankingError> {
    let res = options.resolution;
    if !(res.is_finite() && res >= 0.0) {
        return Err(RankingError::BadResolution(res));
    }
    if !(options.tolerance.is_finite() && options.tolerance >= 0.0) {
        return Err(RankingError::BadTolerance(options.tolerance));
    }
    for item in items {
        for (k, name) in CRITERIA.iter().enumerate() {
            let value = criterion(item, k);
            if !value.is_finite() {
                return Err(RankingError::NotFinite {
                    key: item.key.clone(),
                    criterion: name,
                    value,
                });
            }
        }
    }
    let cells: Vec<[f64; 3]> = items
        .iter()
        .map(|item| std::array::from_fn(|k| cell(criterion(item, k), res)))
        .collect();
    let mut order: Vec<usize> = (0..items.len()).collect();
    // Cells first (the rule); then the key; then the class, the exact values and the
    // position, which only matter for items with equal keys, so that the order of distinct
    // items never depends on the order they are given in.
    order.sort_by(|&a, &b| {
        cmp_cells(&cells[a], &cells[b])
            .then_with(|| items[a].key.cmp(&items[b].key))
            .then_with(|| items[a].class.cmp(&items[b].class))
            .then_with(|| {
                (0..CRITERIA.len()).fold(Ordering::Equal, |o, k| {
                    o.then_with(|| criterion(&items[a], k).total_cmp(&criterion(&items[b], k)))
                })
            })
            .then(a.cmp(&b))
    });
    let mut tie_groups = Vec::new();
    let mut start = 0;
    for i in 1..=order.len() {
        if i == order.len() || cmp_cells(&cells[order[i - 1]], &cells[order[i]]).is_ne() {
            if i - start > 1 {
                tie_groups.push(order[start..i].to_vec());
            }
            start = i;
        }
    }

    let mut rank = vec![0; items.len()];
    let mut class_rank = vec![0; items.len()];
    let mut per_class = [0usize; 3];
    for (position, &i) in order.iter().enumerate() {
        rank[i] = position + 1;
        let c = Class::ALL
            .iter()
            .position(|&c| c == items[i].class)
            .unwrap_or(0);
        per_class[c] += 1;
        class_rank[i] = per_class[c];
    }
    Ok(Ranking {
        order,
        rank,
        class_rank,
        tie_groups,
    })
}

/// The cell of `value` on the grid of `resolution`: the nearest multiple of the resolution,
/// in units of it (`round(value / resolution)`, half-way values away from zero), or the value
/// itself at resolution 0. Two values tie on a criterion exactly when their cells are equal;
/// unlike "closer than the resolution", that is an equivalence (see the module doc). `-0`
/// becomes `+0` so that `total_cmp` does not split the zero cell.
pub fn cell(value: f64, resolution: f64) -> f64 {
    let c = if resolution > 0.0 {
        (value / resolution).round()
    } else {
        value
    };
    c + 0.0
}

/// Lexicographic comparison of two items' cells (ΔQTR, ΔQIT, ΔR).
fn cmp_cells(a: &[f64; 3], b: &[f64; 3]) -> Ordering {
    a.iter()
        .zip(b)
        .fold(Ordering::Equal, |o, (x, y)| o.then_with(|| x.total_cmp(y)))
}

/// Compares two values at a resolution as the ranking does, by their cells (see [`cell`]):
/// `Equal` when they share a cell, else the order of the values. For callers that need a
/// single comparison (e.g. to say whether two variants tie on one criterion).
pub fn compare_at(a: f64, b: f64, resolution: f64) -> Ordering {
    cell(a, resolution).total_cmp(&cell(b, resolution))
}

/// The ranking rule in words, as the reports state it.
pub fn rule_text(resolution: f64) -> String {
    if resolution <= 0.0 {
        return "Variants are ordered by ΔQTR, then ΔQIT, then ΔR, lower first, each compared \
                exactly (resolution 0): equal values tie and the next criterion decides."
            .into();
    }
    let res = format!("{resolution}");
    let res = res.strip_suffix(".0").unwrap_or(&res);
    // At the default the cells are the two decimals every table prints, which a reader can
    // check by eye; other resolutions get no such remark.
    let shown = if resolution == 0.01 {
        ": the two decimals the tables show"
    } else {
        ""
    };
    format!(
        "Variants are ordered by ΔQTR, then ΔQIT, then ΔR, lower first. Each value is rounded \
         to the nearest multiple of {res} percentage points (its cell{shown}); values in the \
         same cell tie and the next criterion decides, so dynamically identical spring-only \
         variants are separated by ΔR. A variant ranked above another is therefore better on \
         the criterion that decides them and less than {res} percentage points from it on \
         every criterion before. Two values less than {res} apart on either side of a \
         half-way point between multiples fall in different cells, and the lower one wins."
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn item(key: &str, class: Class, dqtr: f64, dqit: f64, dr: f64) -> RankItem {
        RankItem {
            key: key.into(),
            class,
            dqtr,
            dqit,
            dr,
        }
    }

    fn keys(items: &[RankItem], r: &Ranking) -> Vec<String> {
        r.order.iter().map(|&i| items[i].key.clone()).collect()
    }

    #[test]
    fn spring_only_variants_with_equal_motor_indicators_are_ordered_by_delta_r() {
        // Same ΔQTR/ΔQIT up to rounding noise; ΔR decides (lower first).
        let items = vec![
            item("K42 + K43", Class::Springs, -63.2, -48.1, 7.5),
            item(
                "K43 + K53",
                Class::Springs,
                -63.2 + 1e-12,
                -48.1 - 1e-12,
                2.25,
            ),
            item("K42 + K53", Class::Springs, -63.2, -48.1, 4.0),
        ];
        let r = rank(&items, &RankingOptions::default()).unwrap();
        assert_eq!(keys(&items, &r), ["K43 + K53", "K42 + K53", "K42 + K43"]);
        assert_eq!(r.rank, vec![3, 1, 2]);
        assert_eq!(r.class_rank, vec![3, 1, 2]);
        assert!(r.tie_groups.is_empty());
    }

    #[test]
    fn lexicographic_priority() {
        // A better ΔQTR wins even with a much worse ΔQIT and ΔR.
        let items = vec![
            item("a", Class::Hybrid, -50.0, -10.0, 1.0),
            item("b", Class::Hybrid, -51.0, 20.0, 90.0),
            item("c", Class::Hybrid, -50.0, -12.0, 50.0),
        ];
        let r = rank(&items, &RankingOptions::default()).unwrap();
        assert_eq!(keys(&items, &r), ["b", "c", "a"]);
    }

    #[test]
    fn resolution_boundary() {
        // Resolution 0.25: cells are round(v / 0.25). −10 → −40 and −9.9 → −39.6 → −40 tie
        // (ΔR decides); −9.8 → −39.2 → −39 is the next cell, so ΔQTR decides.
        let opts = RankingOptions {
            resolution: 0.25,
            ..Default::default()
        };
        let tie = vec![
            item("x", Class::Counterweights, -10.0, 0.0, 5.0),
            item("y", Class::Counterweights, -9.9, 0.0, 1.0),
        ];
        assert_eq!(keys(&tie, &rank(&tie, &opts).unwrap()), ["y", "x"]);
        let apart = vec![
            item("x", Class::Counterweights, -10.0, 0.0, 5.0),
            item("y", Class::Counterweights, -9.8, 0.0, 1.0),
        ];
        assert_eq!(keys(&apart, &rank(&apart, &opts).unwrap()), ["x", "y"]);
        // Default resolution: 0.996 and 1.004 are both in cell 100 (they print as 1.00) and
        // tie; 1.004 and 1.006 are 0.002 apart but in cells 100 and 101 (1.00 and 1.01), so
        // the lower one wins on ΔQTR: the price of a fixed grid, stated in the rule.
        let d = RankingOptions::default();
        let near = vec![
            item("x", Class::Springs, 0.996, 0.0, 5.0),
            item("y", Class::Springs, 1.004, 0.0, 1.0),
        ];
        assert_eq!(keys(&near, &rank(&near, &d).unwrap()), ["y", "x"]);
        let straddle = vec![
            item("x", Class::Springs, 1.004, 0.0, 5.0),
            item("y", Class::Springs, 1.006, 0.0, 1.0),
        ];
        assert_eq!(keys(&straddle, &rank(&straddle, &d).unwrap()), ["x", "y"]);
        // Zero resolution: exact comparison.
        let exact = RankingOptions {
            resolution: 0.0,
            ..Default::default()
        };
        assert_eq!(keys(&near, &rank(&near, &exact).unwrap()), ["x", "y"]);
    }

    /// The rule before the grid: values sorted per criterion and chained while consecutive
    /// gaps stay below the resolution, each chain a tie group ordered by the next criterion.
    /// Kept here only to show what it got wrong.
    fn chained_order(items: &[RankItem], res: f64) -> Vec<String> {
        fn go(items: &[RankItem], mut g: Vec<usize>, k: usize, res: f64, out: &mut Vec<usize>) {
            if k == 3 {
                g.sort_by(|&a, &b| items[a].key.cmp(&items[b].key));
                out.extend(g);
                return;
            }
            g.sort_by(|&a, &b| criterion(&items[a], k).total_cmp(&criterion(&items[b], k)));
            let mut start = 0;
            for i in 1..=g.len() {
                if i == g.len()
                    || criterion(&items[g[i]], k) - criterion(&items[g[i - 1]], k) >= res
                {
                    go(items, g[start..i].to_vec(), k + 1, res, out);
                    start = i;
                }
            }
        }
        let mut out = Vec::new();
        go(items, (0..items.len()).collect(), 0, res, &mut out);
        out.into_iter().map(|i| items[i].key.clone()).collect()
    }

    #[test]
    fn chained_ties_no_longer_order_a_variant_above_a_clearly_better_one() {
        // The Dmax 3 case in miniature: ΔQTR −54.1191, −54.1120, −54.1045 are each
        // within 0.01 pp of the next (gaps 0.0071 and 0.0075) but the ends are 0.0146 apart.
        // Chaining made one tie group of all three and let ΔQIT order them, so "far" (worst
        // ΔQTR, best ΔQIT) came first, 0.0146 pp worse than "near" on the first criterion.
        let chain = vec![
            item("near", Class::Hybrid, -54.1191, -48.0, 1.0),
            item("mid", Class::Hybrid, -54.1120, -48.2, 1.0),
            item("far", Class::Hybrid, -54.1045, -48.6, 1.0),
        ];
        let d = RankingOptions::default();
        assert_eq!(chained_order(&chain, 0.01), ["far", "mid", "near"]);
        // Cells (nearest 0.01, by hand): −54.12, −54.11, −54.10: all different, so ΔQTR alone
        // orders them.
        assert_eq!(
            keys(&chain, &rank(&chain, &d).unwrap()),
            ["near", "mid", "far"]
        );

        // A cycle no order can follow under "closer than 0.01 ties": on (ΔQTR, ΔQIT), a ~ b and
        // b ~ c on ΔQTR (0.006 apart) with ΔQIT putting b before a and c before b, while a and c
        // (0.012 apart) are decided by ΔQTR, a first.
        let cycle = vec![
            item("a", Class::Springs, 0.000, 10.0, 0.0),
            item("b", Class::Springs, 0.006, 0.0, 0.0),
            item("c", Class::Springs, 0.012, -10.0, 0.0),
        ];
        // Chaining puts c first, 0.012 pp worse than a on ΔQTR.
        assert_eq!(chained_order(&cycle, 0.01), ["c", "b", "a"]);
        // Cells of ΔQTR: a → 0, b → round(0.6) = 1, c → round(1.2) = 1. So a first; b and c
        // share a cell and ΔQIT decides (c: −10 before b: 0).
        let r = rank(&cycle, &d).unwrap();
        assert_eq!(keys(&cycle, &r), ["a", "c", "b"]);
        // Every pair: c above b with ΔQTR 0.006 worse (same cell) and better ΔQIT; a above
        // both with a better ΔQTR. Nothing is ranked above a variant that beats it by 0.01 pp
        // or more on the criterion that decides them.
        assert!(r.tie_groups.is_empty());
    }

    #[test]
    fn full_ties_are_broken_by_key_and_reported() {
        let items = vec![
            item("m6", Class::Counterweights, -40.0, -30.0, 0.0),
            item("m4", Class::Counterweights, -40.0, -30.0, 0.0),
            item("m5", Class::Counterweights, -45.0, -30.0, 0.0),
        ];
        let r = rank(&items, &RankingOptions::default()).unwrap();
        assert_eq!(keys(&items, &r), ["m5", "m4", "m6"]);
        assert_eq!(r.tie_groups, vec![vec![1, 0]]);
    }

    #[test]
    fn deterministic_under_permutation() {
        let base = vec![
            item("K42", Class::Springs, -60.0, -40.0, 3.0),
            item("K43", Class::Springs, -60.0, -40.0, 3.0),
            item("m4", Class::Counterweights, -30.0, -20.0, 1.0),
            item("m4 + K43", Class::Hybrid, -59.996, -40.0, 2.0),
            item("m5", Class::Counterweights, -30.004, -25.0, 0.0),
        ];
        let expected = keys(&base, &rank(&base, &RankingOptions::default()).unwrap());
        assert_eq!(expected, ["m4 + K43", "K42", "K43", "m5", "m4"]);
        for rotation in 1..base.len() {
            let mut items = base.clone();
            items.rotate_left(rotation);
            items.swap(0, 1);
            let r = rank(&items, &RankingOptions::default()).unwrap();
            assert_eq!(keys(&items, &r), expected);
        }
    }

    #[test]
    fn class_ranks_follow_the_global_order() {
        let items = vec![
            item("m4", Class::Counterweights, -30.0, 0.0, 0.0),
            item("K43", Class::Springs, -60.0, 0.0, 0.0),
            item("m5", Class::Counterweights, -35.0, 0.0, 0.0),
            item("m4 + K43", Class::Hybrid, -50.0, 0.0, 0.0),
        ];
        let r = rank(&items, &RankingOptions::default()).unwrap();
        assert_eq!(r.rank, vec![4, 1, 3, 2]);
        assert_eq!(r.class_rank, vec![2, 1, 1, 1]);
    }

    #[test]
    fn invalid_input_is_an_error() {
        let items = vec![item("x", Class::Springs, f64::NAN, 0.0, 0.0)];
        assert!(matches!(
            rank(&items, &RankingOptions::default()),
            Err(RankingError::NotFinite { .. })
        ));
        assert!(matches!(
            rank(
                &[],
                &RankingOptions {
                    resolution: -1.0,
                    ..Default::default()
                }
            ),
            Err(RankingError::BadResolution(_))
        ));
        assert!(
            rank(&[], &RankingOptions::default())
                .unwrap()
                .order
                .is_empty()
        );
    }

    #[test]
    fn compare_at_resolution() {
        // Cells at 0.01: 1.0 → 100, 1.004 → 100.4 → 100, 1.006 → 100.6 → 101, 1.02 → 102.
        assert_eq!(compare_at(1.0, 1.004, 0.01), Ordering::Equal);
        assert_eq!(compare_at(1.004, 1.006, 0.01), Ordering::Less);
        assert_eq!(compare_at(1.02, 1.0, 0.01), Ordering::Greater);
    }

    #[test]
    fn rule_text_states_the_grid() {
        let t = rule_text(0.01);
        assert!(
            t.contains("nearest multiple of 0.01 percentage points"),
            "{t}"
        );
        assert!(t.contains("same cell tie"), "{t}");
        assert!(rule_text(0.0).contains("exactly"));
    }
}
