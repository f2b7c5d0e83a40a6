//! Splitting a study into shards: the shard spec `I/N`, the expected cost of optimising a
//! balanced variant, and the deterministic partition of the balanced variants into `N` shards
//! of about equal expected cost.
//!
//! Every shard repeats Phase 1 and the balance search (a few seconds even at Dmax 3) and then
//! computes the same partition from the same search, so shards need no shared state and no
//! coordinator: shard `I` of `N` knows its variants from the case, Dmax and `N` alone.

use std::fmt;
use std::str::FromStr;

use counterpoise_balance::{ElementKind, VariantResult};
use thiserror::Error;

/// Shard `index` (1-based, as `SLURM_ARRAY_TASK_ID` runs over `--array=1-N`) of `count`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShardSpec {
    pub index: usize,
    pub count: usize,
}

/// Why a shard spec is refused.
#[derive(Debug, Error, PartialEq, Eq)]
pub enum ShardSpecError {
    #[error("`{0}` is not a shard: expected I/N, e.g. 2/4 (shard 2 of 4)")]
    Shape(String),
    #[error("`{text}`: {part} `{value}` is not a whole number")]
    Number {
        text: String,
        part: &'static str,
        value: String,
    },
    #[error("`{0}`: the number of shards N must be at least 1")]
    NoShards(String),
    #[error("`{text}`: shards are numbered 1 to {count} (1-based, like SLURM_ARRAY_TASK_ID)")]
    OutOfRange { text: String, count: usize },
}

impl FromStr for ShardSpec {
    type Err = ShardSpecError;

    fn from_str(text: &str) -> Result<ShardSpec, ShardSpecError> {
        let (i, n) = text
            .split_once('/')
            .ok_or_else(|| ShardSpecError::Shape(text.to_string()))?;
        let number = |part: &'static str, value: &str| {
            value
                .trim()
                .parse::<usize>()
                .map_err(|_| ShardSpecError::Number {
                    text: text.to_string(),
                    part,
                    value: value.to_string(),
                })
        };
        let (index, count) = (number("shard index I", i)?, number("shard count N", n)?);
        if count == 0 {
            return Err(ShardSpecError::NoShards(text.to_string()));
        }
        if index == 0 || index > count {
            return Err(ShardSpecError::OutOfRange {
                text: text.to_string(),
                count,
            });
        }
        Ok(ShardSpec { index, count })
    }
}

impl fmt::Display for ShardSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// What the expected cost of a variant is computed from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CostFeatures {
    pub counterweights: usize,
    pub springs: usize,
    /// Free lifted parameters of the balanced family (the optimiser's search dimension).
    pub free: usize,
}

impl CostFeatures {
    pub fn of(v: &VariantResult) -> CostFeatures {
        let springs = v
            .elements
            .iter()
            .filter(|e| e.kind == ElementKind::Spring)
            .count();
        CostFeatures {
            counterweights: v.elements.len() - springs,
            springs,
            free: v.nullity,
        }
    }
}

/// Expected cost of optimising one balanced variant, in arbitrary units (only ratios matter).
///
/// Every shard pays the same fixed costs (Phase 1, the search, and the kinematics of each
/// all-task evaluation, which every variant column of the batch shares); the partition balances
/// what each variant adds. Measured on the palletizer at Dmax 2 (2 cores), a variant adds
/// 0.1–0.25 s: the relaxation and local refinement, which grow with the family's dimension;
/// its columns in the all-task evaluations, where a counterweight changes the inertia and its
/// column is evaluated at three amplitudes while variants with the robot's inertia share one
/// (README, Performance: the rotation about gravity); and for springs the multi-start
/// realization and the choice among realizations by joint reactions. Whether a variant
/// survives to the final evaluation (the largest single cost) is not known before it is
/// optimised, so the model cannot see it.
pub fn expected_cost(f: CostFeatures) -> u64 {
    const BASE: u64 = 8;
    const PER_COUNTERWEIGHT: u64 = 6;
    const PER_SPRING: u64 = 4;
    const PER_FREE: u64 = 1;
    BASE + PER_COUNTERWEIGHT * f.counterweights as u64
        + PER_SPRING * f.springs as u64
        + PER_FREE * f.free as u64
}

/// Partitions items of the given costs into `shards` bins by greedy longest-processing-time:
/// items in decreasing cost (ties: lower index first) each go to the bin with the least cost so
/// far (ties: the lower bin). Returns, per bin, its item indices in increasing order.
///
/// Deterministic (integer costs, total orders), every item in exactly one bin, and the largest
/// bin exceeds the mean by less than the largest single cost (Graham's bound for LPT is 4/3 of
/// the optimum).
pub fn partition(costs: &[u64], shards: usize) -> Vec<Vec<usize>> {
    let shards = shards.max(1);
    let mut order: Vec<usize> = (0..costs.len()).collect();
    order.sort_by(|&a, &b| costs[b].cmp(&costs[a]).then(a.cmp(&b)));
    let mut load = vec![0u64; shards];
    let mut bins = vec![Vec::new(); shards];
    for k in order {
        let bin = (0..shards)
            .min_by(|&a, &b| load[a].cmp(&load[b]).then(a.cmp(&b)))
            .expect("at least one shard");
        load[bin] += costs[k];
        bins[bin].push(k);
    }
    for bin in &mut bins {
        bin.sort_unstable();
    }
    bins
}

/// The units the partition keeps whole, as indices into `variants` (balanced variants only,
/// each unit in enumeration order, units in the order of their first variant). The optimiser
/// lets the variants with the same counterweights and at least one spring try each other's
/// designs (its `critical::siblings`, grouped by [`counterpoise_optimise::sibling_group`],
/// the key used here too), so a variant's result depends on which of them the study holds:
/// such a group is one unit, and a shard holds all of it or none, so that the
/// merged shards equal the single run. Every other balanced variant is a unit of its own.
pub fn shard_units(variants: &[VariantResult]) -> Vec<Vec<usize>> {
    let mut units: Vec<Vec<usize>> = Vec::new();
    let mut group_of: std::collections::BTreeMap<Vec<usize>, usize> = Default::default();
    for (k, v) in variants.iter().enumerate() {
        if v.status != counterpoise_balance::Status::Balanced {
            continue;
        }
        let counterweights = v
            .elements
            .iter()
            .filter(|e| e.kind == ElementKind::Counterweight)
            .map(|e| e.entry);
        let has_spring = v.elements.iter().any(|e| e.kind == ElementKind::Spring);
        let Some(group) = counterpoise_optimise::sibling_group(counterweights, has_spring) else {
            units.push(vec![k]);
            continue;
        };
        let unit = *group_of.entry(group).or_insert_with(|| {
            units.push(Vec::new());
            units.len() - 1
        });
        units[unit].push(k);
    }
    units
}

/// Indices (into `variants`, the search's enumeration) of the balanced variants of shard
/// `spec`, in enumeration order: the units of [`shard_units`], each whole, partitioned by their
/// summed expected costs.
pub fn shard_variants(variants: &[VariantResult], spec: ShardSpec) -> Vec<usize> {
    let units = shard_units(variants);
    let costs: Vec<u64> = units
        .iter()
        .map(|unit| {
            unit.iter()
                .map(|&k| expected_cost(CostFeatures::of(&variants[k])))
                .sum()
        })
        .collect();
    let mut chosen: Vec<usize> = partition(&costs, spec.count)
        .swap_remove(spec.index - 1)
        .into_iter()
        .flat_map(|u| units[u].iter().copied())
        .collect();
    chosen.sort_unstable();
    chosen
}

#[cfg(test)]
mod tests {
    use super::*;
    use ElementKind::{Counterweight, Spring};
    use counterpoise_balance::search::ElementRef;
    use counterpoise_balance::{Class, Status};

    /// A variant of the given element kinds and family dimension; the other fields are not
    /// read by the cost model.
    fn variant(kinds: &[ElementKind], nullity: usize, status: Status) -> VariantResult {
        let elements = kinds
            .iter()
            .enumerate()
            .map(|(entry, &kind)| ElementRef {
                entry,
                label: format!("E{entry}"),
                kind,
                bodies: Vec::new(),
            })
            .collect();
        VariantResult {
            status,
            nullity,
            ..VariantResult::undecided(elements, Class::Hybrid)
        }
    }

    #[test]
    fn the_cost_model_by_hand() {
        let cost = |counterweights, springs, free| {
            expected_cost(CostFeatures {
                counterweights,
                springs,
                free,
            })
        };
        // 8 + 6·counterweights + 4·springs + 1·free, term by term
        assert_eq!(cost(0, 0, 0), 8);
        assert_eq!(cost(1, 0, 0), 14);
        assert_eq!(cost(0, 1, 0), 12);
        assert_eq!(cost(0, 0, 1), 9);
        assert_eq!(cost(2, 1, 5), 8 + 12 + 4 + 5);
        let hybrid = variant(&[Counterweight, Spring, Spring], 4, Status::Balanced);
        assert_eq!(
            CostFeatures::of(&hybrid),
            CostFeatures {
                counterweights: 1,
                springs: 2,
                free: 4
            }
        );
    }

    #[test]
    fn only_balanced_variants_are_sharded_and_specs_print_as_parsed() {
        // costs 8 + 6 = 14 (index 0), 12 (index 2), 8 + 12 = 20 (index 3); index 1 is not
        // balanced. LPT into 2: 20 → shard 1, 14 → shard 2, 12 → shard 2.
        let variants = vec![
            variant(&[Counterweight], 0, Status::Balanced),
            variant(&[Counterweight], 0, Status::Infeasible),
            variant(&[Spring], 0, Status::Balanced),
            variant(&[Spring, Spring, Spring], 0, Status::Balanced),
        ];
        let spec = |index| ShardSpec { index, count: 2 };
        assert_eq!(shard_variants(&variants, spec(1)), vec![3]);
        assert_eq!(shard_variants(&variants, spec(2)), vec![0, 2]);
        assert_eq!(spec(2).to_string(), "2/2");
        assert_eq!("2/2".parse::<ShardSpec>(), Ok(spec(2)));
    }

    #[test]
    fn shard_specs_parse_one_based_and_refuse_the_rest() {
        assert_eq!(
            "2/3".parse::<ShardSpec>(),
            Ok(ShardSpec { index: 2, count: 3 })
        );
        assert_eq!(
            "1/1".parse::<ShardSpec>(),
            Ok(ShardSpec { index: 1, count: 1 })
        );
        for bad in ["3/2", "0/2", "a/b", "2", "1/0", "-1/2", "1/2/3"] {
            assert!(bad.parse::<ShardSpec>().is_err(), "{bad} accepted");
        }
        let e = "3/2".parse::<ShardSpec>().unwrap_err().to_string();
        assert!(e.contains("numbered 1 to 2"), "{e}");
        let e = "a/b".parse::<ShardSpec>().unwrap_err().to_string();
        assert!(e.contains("`a` is not a whole number"), "{e}");
    }

    #[test]
    fn lpt_partition_of_a_hand_example() {
        // costs 5 4 3 3 3 into 2 bins, by hand: 5→A, 4→B, 3 (idx 2)→B (7), 3 (idx 3)→A (8),
        // 3 (idx 4)→B (10): A = {0, 3} (8), B = {1, 2, 4} (10)
        assert_eq!(
            partition(&[5, 4, 3, 3, 3], 2),
            vec![vec![0, 3], vec![1, 2, 4]]
        );
        // more bins than items: the extra bins are empty
        assert_eq!(partition(&[1, 2], 3), vec![vec![1], vec![0], vec![]]);
    }

    #[test]
    fn partition_covers_every_item_once_and_is_balanced() {
        // a deterministic spread of costs like the palletizer's (4…14)
        let costs: Vec<u64> = (0..1169u64).map(|k| 4 + (k * 7919) % 11).collect();
        for shards in 1..=7 {
            let bins = partition(&costs, shards);
            assert_eq!(bins.len(), shards);
            let mut all: Vec<usize> = bins.iter().flatten().copied().collect();
            all.sort_unstable();
            assert_eq!(all, (0..costs.len()).collect::<Vec<_>>());
            let loads: Vec<u64> = bins
                .iter()
                .map(|b| b.iter().map(|&k| costs[k]).sum())
                .collect();
            let (lo, hi) = (*loads.iter().min().unwrap(), *loads.iter().max().unwrap());
            // LPT: the bins differ by at most the largest cost (14)
            assert!(hi - lo <= 14, "{shards} shards: loads {loads:?}");
            assert_eq!(partition(&costs, shards), bins, "not deterministic");
        }
    }

    #[test]
    fn expected_cost_grows_with_each_feature() {
        let base = CostFeatures {
            counterweights: 1,
            springs: 1,
            free: 1,
        };
        let c = expected_cost(base);
        assert!(
            expected_cost(CostFeatures {
                counterweights: 2,
                ..base
            }) > c
        );
        assert!(expected_cost(CostFeatures { springs: 2, ..base }) > c);
        assert!(expected_cost(CostFeatures { free: 2, ..base }) > c);
    }
}
