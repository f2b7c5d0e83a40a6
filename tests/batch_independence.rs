//! Sharding a study is exact only if the optimiser's result for a variant does not depend on the
//! other variants it is batched with, beyond the variants with the same counterweights that a
//! shard holds with it: `optimise_all_reporting` runs the critical-task loop, the
//! all-task evaluations and the final evaluation over every balanced variant at once (one
//! parameter column per variant in the dynamics crate). This test optimises subsets of the
//! balanced variants — whole units of the shard partition, as a shard holds them — and
//! compares each record with the one from the full batch, bit for bit
//! (their serde_json values: every f64 is written in its shortest round-trip form, so two
//! values are equal exactly when the numbers are).

mod common;

use counterpoise_balance::{
    Catalogue, SearchOptions, Status, catalogue_options, mechanism_energy, realization_hints,
    search,
};
use counterpoise_model::Case;
use counterpoise_optimise::{Context, OptimiseOptions, optimise_all};

#[test]
fn each_variant_optimises_to_the_same_bits_whatever_its_batch() {
    // The palletizer on a 3 × 3 × 3 grid with 11 samples per move: every structure the
    // dynamics batches over (counterweights, springs sharing the robot's inertia, the θ1
    // rotation about gravity) is there, at a cost a test can afford.
    let case = common::reduced_palletizer(3, 11);
    let model = Case::from_json_str(&serde_json::to_string(&case).unwrap()).unwrap();
    let energy = mechanism_energy(&model);
    let catalogue = Catalogue::build(&energy, &catalogue_options(&model));
    let found = search(
        &energy,
        catalogue,
        SearchOptions {
            dmax: 2,
            hints: realization_hints(&model),
        },
    );
    let balanced: Vec<_> = found
        .variants
        .iter()
        .filter(|v| v.status == Status::Balanced)
        .cloned()
        .collect();
    // README: 97 balanced variants at Dmax 2 (the grid does not change the balance search)
    assert_eq!(balanced.len(), 97);
    let ctx = Context::new(&model, None).unwrap();
    let options = OptimiseOptions::default();
    let full: Vec<serde_json::Value> = optimise_all(&ctx, &balanced, &options)
        .iter()
        .map(|o| serde_json::to_value(o).unwrap())
        .collect();
    assert_eq!(full.len(), balanced.len());

    // Subsets as a sharded run makes them, of whole units (`shard_units`: the variants with
    // the same counterweights and springs try each other's designs, so a shard holds all of
    // them or none): every third unit (a stride mixing classes and sizes), the second half of
    // the units, and single variants that are units of their own (springs alone or
    // counterweights alone: every hybrid shares its counterweights with a sibling here).
    let units = counterpoise::shard::shard_units(&balanced);
    assert!(units.iter().any(|u| u.len() > 1), "{units:?}");
    let whole = |picked: Vec<&Vec<usize>>| -> Vec<usize> {
        let mut ids: Vec<usize> = picked.into_iter().flatten().copied().collect();
        ids.sort_unstable();
        ids
    };
    let stride = whole(units.iter().skip(1).step_by(3).collect());
    let half = whole(units.iter().skip(units.len() / 2).collect());
    let alone: Vec<usize> = units
        .iter()
        .filter(|u| u.len() == 1)
        .map(|u| u[0])
        .collect();
    let singles = [alone[0], alone[alone.len() / 2], alone[alone.len() - 1]];
    let mut subsets = vec![stride, half];
    subsets.extend(singles.iter().map(|&k| vec![k]));
    for subset in subsets {
        let variants: Vec<_> = subset.iter().map(|&k| balanced[k].clone()).collect();
        let ctx = Context::new(&model, None).unwrap();
        let part = optimise_all(&ctx, &variants, &options);
        assert_eq!(part.len(), subset.len());
        for (&k, record) in subset.iter().zip(&part) {
            let value = serde_json::to_value(record).unwrap();
            assert!(
                value == full[k],
                "variant {} ({}) differs when optimised with {} variant(s) instead of {}:\n\
                 subset: {}\nfull:   {}",
                k,
                record.elements.join(" + "),
                subset.len(),
                balanced.len(),
                first_difference(&value, &full[k]),
                first_difference(&full[k], &value),
            );
        }
    }
}

/// The first leaves of `a` that differ from `b`, with their JSON paths (for the failure
/// message).
fn first_difference(a: &serde_json::Value, b: &serde_json::Value) -> String {
    fn walk(a: &serde_json::Value, b: &serde_json::Value, path: String, out: &mut Vec<String>) {
        use serde_json::Value;
        match (a, b) {
            (Value::Object(x), Value::Object(y)) => {
                for (k, v) in x {
                    walk(
                        v,
                        y.get(k).unwrap_or(&Value::Null),
                        format!("{path}.{k}"),
                        out,
                    );
                }
            }
            (Value::Array(x), Value::Array(y)) if x.len() == y.len() => {
                for (i, (v, w)) in x.iter().zip(y).enumerate() {
                    walk(v, w, format!("{path}[{i}]"), out);
                }
            }
            _ if a != b => out.push(format!("{path} = {a}")),
            _ => {}
        }
    }
    let mut out = Vec::new();
    walk(a, b, String::new(), &mut out);
    let n = out.len();
    out.truncate(12);
    format!("{n} leaves differ: {}", out.join(", "))
}
