//! Phase 3 ranking (paper Sec. 2.3, Proc-9): lexicographic by ΔQTR, then ΔQIT, then ΔR, lower
//! is better for each.
//!
//! **Resolution.** Indicators are compared at a resolution (default 0.01 percentage points).
//! Spring-only variants are dynamically identical (massless springs cannot change the motor
//! torques of a balanced mechanism), so their ΔQTR and ΔQIT agree up to rounding noise and must
//! tie on those criteria for ΔR to separate them. Rounding each value to a grid would split two
//! values 1e-12 apart that straddle a grid line, so instead values are sorted and *chained*:
//! consecutive values less than one resolution apart belong to the same tie group (gap ≥
//! resolution separates). This is an equivalence relation, so the order is a true total order
//! and does not depend on the input order. Within a tie group the next criterion decides.
//!
//! **Final tie-break.** Variants that tie on all three criteria are ordered by their tie-break
//! key (the caller passes the element labels, e.g. `"K42 + K43"`), then by input position; the
//! groups are returned so the report can say which ranks were decided this way.
//!
//! **Class ranks** are positions within the global order restricted to the class, so the
//! per-class rankings never contradict the global one (a separate chaining per class could).

use std::cmp::Ordering;

use serde::{Deserialize, Serialize};
use thiserror::Error;

/// The paper's three classes of balanced variants.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Class {
    Counterweights,
    Springs,
    Hybrid,
}

impl Class {
    pub const ALL: [Class; 3] = [Class::Counterweights, Class::Springs, Class::Hybrid];

    /// The machine name used in results.json and CSV.
    pub fn name(self) -> &'static str {
        match self {
            Class::Counterweights => "counterweights",
            Class::Springs => "springs",
            Class::Hybrid => "hybrid",
        }
    }

    /// The paper's wording, for reports.
    pub fn title(self) -> &'static str {
        match self {
            Class::Counterweights => "Counterweights only",
            Class::Springs => "Springs only",
            Class::Hybrid => "Hybrid",
        }
    }
}

/// Settings of the ranking.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RankingOptions {
    /// Values closer than this (percentage points) compare equal. Default 0.01.
    pub resolution: f64,
    /// Tolerance of the decision section's equivalence groups, percentage points (see
    /// [`crate::decision`]); it does not change the ranking. Default 0.5.
    #[serde(default = "default_tolerance")]
    pub tolerance: f64,
}

fn default_tolerance() -> f64 {
    crate::decision::DEFAULT_TOLERANCE
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
    /// Groups (in rank order, each of size ≥ 2) tied on all three criteria at the resolution,
    /// hence ordered by the tie-break key.
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
    let mut order = Vec::with_capacity(items.len());
    let mut tie_groups = Vec::new();
    order_group(
        items,
        (0..items.len()).collect(),
        0,
        res,
        &mut order,
        &mut tie_groups,
    );

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

/// Appends `group` to `out` ordered by criteria `k..`, recursing into tie groups.
fn order_group(
    items: &[RankItem],
    mut group: Vec<usize>,
    k: usize,
    res: f64,
    out: &mut Vec<usize>,
    tie_groups: &mut Vec<Vec<usize>>,
) {
    if k == CRITERIA.len() {
        group.sort_by(|&a, &b| items[a].key.cmp(&items[b].key).then(a.cmp(&b)));
        if group.len() > 1 {
            tie_groups.push(group.clone());
        }
        out.extend(group);
        return;
    }
    // Key and index make the sort order of equal values independent of the input order.
    group.sort_by(|&a, &b| {
        criterion(&items[a], k)
            .total_cmp(&criterion(&items[b], k))
            .then_with(|| items[a].key.cmp(&items[b].key))
            .then(a.cmp(&b))
    });
    let mut start = 0;
    for i in 1..=group.len() {
        let split = i == group.len()
            || criterion(&items[group[i]], k) - criterion(&items[group[i - 1]], k) >= res;
        if split {
            order_group(items, group[start..i].to_vec(), k + 1, res, out, tie_groups);
            start = i;
        }
    }
}

/// Compares two values at a resolution, for callers that need a single comparison (e.g. to
/// say in a report whether two variants are equivalent on one criterion).
pub fn compare_at(a: f64, b: f64, resolution: f64) -> Ordering {
    if (a - b).abs() < resolution {
        Ordering::Equal
    } else {
        a.total_cmp(&b)
    }
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
        // Gap below the resolution ties (ΔR decides); gap of exactly the resolution separates.
        let opts = RankingOptions {
            resolution: 0.25,
            ..Default::default()
        };
        let tie = vec![
            item("x", Class::Counterweights, -10.0, 0.0, 5.0),
            item("y", Class::Counterweights, -10.0 + 0.125, 0.0, 1.0),
        ];
        assert_eq!(keys(&tie, &rank(&tie, &opts).unwrap()), ["y", "x"]);
        let apart = vec![
            item("x", Class::Counterweights, -10.0, 0.0, 5.0),
            item("y", Class::Counterweights, -10.0 + 0.25, 0.0, 1.0),
        ];
        assert_eq!(keys(&apart, &rank(&apart, &opts).unwrap()), ["x", "y"]);
        // Default resolution: 0.009 pp apart ties, 0.011 pp apart does not.
        let d = RankingOptions::default();
        let near = vec![
            item("x", Class::Springs, 1.000, 0.0, 5.0),
            item("y", Class::Springs, 1.009, 0.0, 1.0),
        ];
        assert_eq!(keys(&near, &rank(&near, &d).unwrap()), ["y", "x"]);
        let far = vec![
            item("x", Class::Springs, 1.000, 0.0, 5.0),
            item("y", Class::Springs, 1.011, 0.0, 1.0),
        ];
        assert_eq!(keys(&far, &rank(&far, &d).unwrap()), ["x", "y"]);
        // Zero resolution: exact comparison.
        let exact = RankingOptions {
            resolution: 0.0,
            ..Default::default()
        };
        assert_eq!(keys(&near, &rank(&near, &exact).unwrap()), ["x", "y"]);
    }

    #[test]
    fn chaining_is_transitive() {
        // 0, 0.006, 0.012: neighbours within 0.01, ends 0.012 apart — one tie group, so ΔR
        // orders all three (a rounding grid would have split them arbitrarily).
        let items = vec![
            item("p", Class::Springs, 0.0, 0.0, 3.0),
            item("q", Class::Springs, 0.006, 0.0, 2.0),
            item("r", Class::Springs, 0.012, 0.0, 1.0),
        ];
        let r = rank(&items, &RankingOptions::default()).unwrap();
        assert_eq!(keys(&items, &r), ["r", "q", "p"]);
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
            item("m4 + K43", Class::Hybrid, -59.995, -40.0, 2.0),
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
        assert_eq!(compare_at(1.0, 1.005, 0.01), Ordering::Equal);
        assert_eq!(compare_at(1.0, 1.02, 0.01), Ordering::Less);
    }
}
