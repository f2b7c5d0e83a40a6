//! The minimal-set walk against brute force on the 6-axis arm of `cases/arm6.json` (27
//! catalogue entries): at Dmax 4 every one of the C(27, ≤ 4) = 20,853 sets is eliminated
//! exactly and the minimal solvable ones kept by checking all their proper subsets.

mod common;

use common::model_of;
use counterpoise_balance::linear::LiftedBasis;
use counterpoise_balance::minimal::{brute_force_minimal, estimate_tested, minimal_sets};
use counterpoise_balance::{Catalogue, catalogue_options, mechanism_energy};

fn arm6_exact() -> counterpoise_balance::exact::ExactBasis {
    let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../cases/arm6.json");
    let model = model_of(&serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap());
    let energy = mechanism_energy(&model);
    let catalogue = Catalogue::build(&energy, &catalogue_options(&model));
    assert_eq!(catalogue.len(), 27);
    LiftedBasis::build(&energy, &catalogue)
        .exact
        .expect("arm6 is exact")
}

#[test]
fn the_walk_finds_exactly_the_brute_force_minimal_sets_at_dmax_4() {
    let exact = arm6_exact();
    let brute = brute_force_minimal(&exact, 4);
    let walk = minimal_sets(&exact, 4);
    assert_eq!(walk.disagreements, 0);
    assert_eq!(walk.minimal, brute);
    // 27 pairs and 27 triples (the full Dmax 2 search finds 27 solvable pairs: 25
    // unrealizable and 2 undecided of its 378 variants), none of 4.
    let sizes: Vec<usize> = (1..=4)
        .map(|d| brute.iter().filter(|s| s.len() == d).count())
        .collect();
    assert_eq!(sizes, [0, 27, 27, 0]);
    // Pruned: far fewer tests than the 20,853 combinations.
    assert!(walk.tested < 20_853 / 2, "{}", walk.tested);
    assert!(estimate_tested(&exact, 4, u64::MAX) < 20_853);
}

/// The walk's answer does not depend on the number of threads.
#[test]
fn the_walk_is_the_same_on_one_thread() {
    let exact = arm6_exact();
    let many = minimal_sets(&exact, 5);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let one = pool.install(|| minimal_sets(&exact, 5));
    assert_eq!(many.minimal, one.minimal);
    assert_eq!(many.tested, one.tested);
}
