//! The ranking keeps its stated rule (issue 31, item 8): ΔQTR, then ΔQIT, then ΔR, each
//! rounded to the nearest multiple of the resolution; values in the same cell tie and the next
//! criterion decides.
//!
//! Two checks, each written from the rule's statement, not from the ranking's code:
//!
//! - [`against_rule`] looks at values only: a pair ranked i above j is *ordered against* a
//!   criterion when i is worse than j on it by more than the resolution although no earlier
//!   criterion puts i ahead (i is not lower on any of them). This is what issue 31 found at
//!   Dmax 3 (SB56 at ΔQTR −54.1045 ranked above SB57 at −54.1191), and what the earlier rule,
//!   which chained values closer than the resolution into one tie group, could do.
//! - [`out_of_cell_order`] recomputes every value's cell and checks each pair pairwise: the
//!   first criterion whose cells differ must favour the one ranked higher.
//!
//! On a generated population (proptest), on the palletizer at Dmax 2 (a full `run`, about
//! 20 s), and, `#[ignore]`d, on a results.json named by `COUNTERPOISE_RANKING_RESULTS` (a Dmax
//! 3 run takes minutes): `COUNTERPOISE_RANKING_RESULTS=out/p3/results.json cargo test --release
//! --test ranking_rule -- --ignored --nocapture` prints the counts of the stored order and of
//! the order this version gives the same variants.

mod common;

use std::cmp::Ordering;
use std::path::Path;

use common::{assert_success, counterpoise};
use counterpoise_report::{
    Class, RankItem, RankingOptions, RunResults, VariantRecord, rank, read_results,
};
use proptest::prelude::*;

/// Floating-point slack of "more than the resolution": cells come from `v / res`, whose rounding
/// can move a difference of exactly one resolution by a few ulps.
const SLACK: f64 = 1e-9;

/// Pairs (i above j) ordered against a criterion by more than `res`, per criterion (ΔQTR,
/// ΔQIT, ΔR): `rows` are the (ΔQTR, ΔQIT, ΔR) of the variants in rank order.
fn against_rule(rows: &[[f64; 3]], res: f64) -> [usize; 3] {
    let mut count = [0; 3];
    for (i, a) in rows.iter().enumerate() {
        for b in &rows[i + 1..] {
            for k in 0..3 {
                // An earlier criterion on which i is lower decided the pair in i's favour.
                if (0..k).any(|l| a[l] < b[l]) {
                    break;
                }
                if a[k] - b[k] > res * (1.0 + SLACK) {
                    count[k] += 1;
                    break;
                }
            }
        }
    }
    count
}

/// The cell of a value as the rule states it: the nearest multiple of `res`, in units of it
/// (the value itself at resolution 0).
fn rule_cell(v: f64, res: f64) -> f64 {
    if res == 0.0 { v } else { (v / res).round() }
}

/// Pairs (i above j) whose first differing cell favours j, or that share every cell while
/// i's tie-break key is after j's. `partial_cmp` makes −0 and +0 one cell.
fn out_of_cell_order(rows: &[([f64; 3], &str)], res: f64) -> usize {
    let mut count = 0;
    for (i, (a, ka)) in rows.iter().enumerate() {
        for (b, kb) in &rows[i + 1..] {
            let first = (0..3)
                .map(|k| {
                    rule_cell(a[k], res)
                        .partial_cmp(&rule_cell(b[k], res))
                        .unwrap()
                })
                .find(|o| o.is_ne());
            let wrong = match first {
                Some(o) => o == Ordering::Greater,
                None => ka > kb,
            };
            count += usize::from(wrong);
        }
    }
    count
}

fn values(v: &VariantRecord) -> [f64; 3] {
    [v.dqtr, v.dqit, v.dr].map(|x| x.expect("ranked variants have their indicators"))
}

/// (ΔQTR, ΔQIT, ΔR) and label of the ranked variants of `r`, in rank order.
fn ranked_rows(r: &RunResults) -> Vec<([f64; 3], String)> {
    r.ranked().iter().map(|v| (values(v), v.label())).collect()
}

/// Both checks on `rows`: (per-criterion count of [`against_rule`], [`out_of_cell_order`]).
fn check(rows: &[([f64; 3], String)], res: f64) -> ([usize; 3], usize) {
    let values: Vec<[f64; 3]> = rows.iter().map(|(v, _)| *v).collect();
    let keyed: Vec<([f64; 3], &str)> = rows.iter().map(|(v, k)| (*v, k.as_str())).collect();
    (against_rule(&values, res), out_of_cell_order(&keyed, res))
}

fn item(key: usize, class: usize, v: [f64; 3]) -> RankItem {
    RankItem {
        key: format!("k{key}"),
        class: Class::ALL[class],
        dqtr: v[0],
        dqit: v[1],
        dr: v[2],
    }
}

/// Values in a few clusters (so that many are within a resolution of each other and chains
/// form), some exactly equal.
fn clustered() -> impl Strategy<Value = f64> {
    (
        prop::sample::select(vec![-54.1, -54.0, -10.0, 0.0, 3.0]),
        prop_oneof![Just(0.0), -0.03f64..0.03],
    )
        .prop_map(|(base, noise)| base + noise)
}

fn population() -> impl Strategy<Value = Vec<(usize, usize, [f64; 3])>> {
    prop::collection::vec(
        (
            0usize..8,
            0usize..3,
            [clustered(), clustered(), clustered()],
        ),
        0..16,
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    /// The order is a total order that follows the stated rule, and it does not depend on the
    /// order the variants are given in.
    #[test]
    fn ranking_follows_the_rule_and_ignores_input_order(
        (population, shuffled) in population().prop_flat_map(|p| {
            let n = p.len();
            (Just(p), Just((0..n).collect::<Vec<usize>>()).prop_shuffle())
        }),
        res in prop::sample::select(vec![0.0, 0.001, 0.01, 0.02, 0.25]),
    ) {
        let items: Vec<RankItem> =
            population.iter().map(|&(k, c, v)| item(k, c, v)).collect();
        let options = RankingOptions { resolution: res, ..Default::default() };
        let r = rank(&items, &options).unwrap();

        // A permutation, with ranks and class ranks its positions.
        let mut seen = r.order.clone();
        seen.sort_unstable();
        prop_assert_eq!(seen, (0..items.len()).collect::<Vec<_>>());
        let mut per_class = [0; 3];
        for (p, &i) in r.order.iter().enumerate() {
            prop_assert_eq!(r.rank[i], p + 1);
            let c = Class::ALL.iter().position(|&c| c == items[i].class).unwrap();
            per_class[c] += 1;
            prop_assert_eq!(r.class_rank[i], per_class[c]);
        }

        // The rule, on values and on cells.
        let rows: Vec<([f64; 3], String)> = r
            .order
            .iter()
            .map(|&i| ([items[i].dqtr, items[i].dqit, items[i].dr], items[i].key.clone()))
            .collect();
        let (against, cells) = check(&rows, res);
        prop_assert_eq!(against, [0, 0, 0], "ordered against a criterion: {:?}", rows);
        prop_assert_eq!(cells, 0, "out of cell order: {:?}", rows);

        // Tie groups are the runs of equal cells on all three criteria.
        for group in &r.tie_groups {
            prop_assert!(group.len() >= 2);
            for w in group.windows(2) {
                for k in 0..3 {
                    let cell = |i: usize| rule_cell([items[i].dqtr, items[i].dqit, items[i].dr][k], res);
                    prop_assert!(cell(w[0]) == cell(w[1]));
                }
            }
        }

        // Independent of the input order: the same variants in the same order.
        let permuted: Vec<RankItem> = shuffled.iter().map(|&i| items[i].clone()).collect();
        let rp = rank(&permuted, &options).unwrap();
        let sequence = |items: &[RankItem], order: &[usize]| -> Vec<RankItem> {
            order.iter().map(|&i| items[i].clone()).collect()
        };
        prop_assert_eq!(sequence(&items, &r.order), sequence(&permuted, &rp.order));
    }
}

/// `(before, after)`: the checks on the order stored in `results` and on the order this
/// version gives the same variants (`finalize` again at the stored resolution and tolerance).
fn before_and_after(mut results: RunResults) -> (([usize; 3], usize), ([usize; 3], usize)) {
    let res = results
        .ranking
        .as_ref()
        .expect("a ranked results.json")
        .resolution;
    let before = check(&ranked_rows(&results), res);
    let mut options = RankingOptions {
        resolution: res,
        ..Default::default()
    };
    if let Some(d) = &results.decision {
        options.tolerance = d.tolerance;
    }
    results.finalize(&options).unwrap();
    let after = check(&ranked_rows(&results), res);
    (before, after)
}

/// The palletizer at Dmax 2, run end to end: no pair of its ranking (results.json and the
/// rows of ranking.csv) is ordered against a criterion by more than the resolution, and the
/// reports state the rule.
#[test]
fn palletizer_dmax_2_ranking_keeps_its_rule() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("p2");
    let o = counterpoise(&[
        "run",
        "cases/palletizer.json",
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert_success(&o);
    let results = read_results(&out).unwrap();
    let res = results.ranking.as_ref().unwrap().resolution;
    assert_eq!(res, 0.01, "the default resolution");
    let rows = ranked_rows(&results);
    assert!(
        rows.len() >= 40,
        "the palletizer has about 50 feasible variants"
    );
    assert_eq!(check(&rows, res), ([0, 0, 0], 0), "{rows:?}");

    // ranking.csv as a spreadsheet reads it: rows in file order.
    let csv = std::fs::read_to_string(out.join("ranking.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (q, i, r) = (col("dqtr_percent"), col("dqit_percent"), col("dr_percent"));
    let csv_rows: Vec<[f64; 3]> = lines
        .map(|l| {
            // labels hold no comma ("m4 + K43"), so a plain split finds the columns
            let f: Vec<&str> = l.split(',').collect();
            [q, i, r].map(|c| f[c].parse().unwrap())
        })
        .collect();
    assert_eq!(csv_rows.len(), rows.len());
    assert_eq!(against_rule(&csv_rows, res), [0, 0, 0]);

    // Re-ranking the written results changes nothing, and the reports state the grid rule.
    let (before, after) = before_and_after(results);
    assert_eq!((before, after), (([0, 0, 0], 0), ([0, 0, 0], 0)));
    for file in ["report.html", "report.md"] {
        let text = std::fs::read_to_string(out.join(file)).unwrap();
        assert!(
            text.contains("rounded to the nearest multiple of 0.01 percentage points"),
            "{file} states the rule"
        );
    }
}

/// The same check on any results.json (a Dmax 3 run takes minutes): the order stored in it
/// (which an earlier version may have made) and the order this version gives it.
#[test]
#[ignore = "reads the results.json named by COUNTERPOISE_RANKING_RESULTS (e.g. a Dmax 3 run)"]
fn stored_results_ranking_keeps_its_rule() {
    let path = std::env::var("COUNTERPOISE_RANKING_RESULTS")
        .expect("set COUNTERPOISE_RANKING_RESULTS to a results.json or its directory");
    let path = Path::new(&path);
    let dir = if path.is_dir() {
        path
    } else {
        path.parent().unwrap()
    };
    let results = read_results(dir).unwrap();
    let ranked = results.ranked().len();
    let (before, after) = before_and_after(results);
    let total = |c: [usize; 3]| c.iter().sum::<usize>();
    println!(
        "{} ranked variants ({} pairs)",
        ranked,
        ranked * ranked.saturating_sub(1) / 2
    );
    println!(
        "stored order:  {} pairs ordered against a criterion by more than the resolution \
         (ΔQTR {}, ΔQIT {}, ΔR {}); {} pairs out of cell order",
        total(before.0),
        before.0[0],
        before.0[1],
        before.0[2],
        before.1
    );
    println!(
        "this version:  {} pairs ordered against a criterion by more than the resolution \
         (ΔQTR {}, ΔQIT {}, ΔR {}); {} pairs out of cell order",
        total(after.0),
        after.0[0],
        after.0[1],
        after.0[2],
        after.1
    );
    assert_eq!(after, ([0, 0, 0], 0));
}
