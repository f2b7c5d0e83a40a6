//! Where the balance search spends its time on a case: `cargo run --release -p
//! counterpoise-balance --example timing -- cases/palletizer.json 2`.

use std::time::Instant;

use counterpoise_balance::linear::LiftedBasis;
use counterpoise_balance::{
    Catalogue, VerificationSet, catalogue_options, decide, mechanism_energy, realization_hints,
};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let model =
        counterpoise_model::Case::from_path(std::path::Path::new(&args[1])).expect("valid case");
    let dmax: usize = args.get(2).map_or(2, |s| s.parse().expect("dmax"));
    let t = Instant::now();
    let energy = mechanism_energy(&model);
    let catalogue = Catalogue::build(&energy, &catalogue_options(&model));
    let basis = LiftedBasis::build(&energy, &catalogue);
    let checks = VerificationSet::new(&energy);
    println!("setup {:.1} ms", t.elapsed().as_secs_f64() * 1e3);
    let sets: Vec<Vec<usize>> =
        counterpoise_balance::enumerate::variants(catalogue.len(), dmax).collect();
    if let Some(exact) = &basis.exact {
        let t = Instant::now();
        let consistent = sets.iter().filter(|s| exact.solve(s).consistent()).count();
        println!(
            "exact linear stage {} variants ({consistent} consistent): {:.1} ms",
            sets.len(),
            t.elapsed().as_secs_f64() * 1e3
        );
    }
    let mut by_status = std::collections::BTreeMap::new();
    for s in &sets {
        let t = Instant::now();
        let r = decide(
            &energy,
            &catalogue,
            &basis,
            &checks,
            s,
            realization_hints(&model),
        );
        let e = by_status.entry(r.status.name()).or_insert((0, 0.0));
        e.0 += 1;
        e.1 += t.elapsed().as_secs_f64();
    }
    for (k, (n, secs)) in by_status {
        println!("{k:<14} {n:>5} variants {:>9.1} ms", secs * 1e3);
    }
}
