//! The 6-axis arm of `cases/arm6.json` (imported from `cases/arm6.urdf`) at the one variant of
//! Dmax ≤ 3 that made nalgebra's SVD panic ("Singular value was NaN"): m1 + K61 + K65. Its
//! system is finite — a counterweight on the pan link (four zero columns: its height never
//! changes) beside two wrist springs — yet nalgebra's implicit-shift QR turned it into a NaN.
//! The exact path asked for that SVD only to report an informative residual.

mod common;

use common::model_of;
use counterpoise_balance::linear::{LiftedBasis, least_squares_residual, numeric_solve};
use counterpoise_balance::{
    Catalogue, Status, VerificationSet, catalogue_options, decide, mechanism_energy,
    realization_hints,
};
use nalgebra::{DMatrix, DVector};

fn arm6() -> counterpoise_model::Model {
    let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../cases/arm6.json");
    model_of(&serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap())
}

fn index_of(catalogue: &Catalogue, label: &str) -> usize {
    catalogue
        .entries
        .iter()
        .position(|e| e.label == label)
        .unwrap_or_else(|| panic!("{label} not in the catalogue"))
}

#[test]
fn the_set_that_broke_nalgebras_svd_is_decided_exactly_without_a_panic() {
    let model = arm6();
    let energy = mechanism_energy(&model);
    let catalogue = Catalogue::build(&energy, &catalogue_options(&model));
    let basis = LiftedBasis::build(&energy, &catalogue);
    let set: Vec<usize> = ["m1", "K61", "K65"]
        .iter()
        .map(|l| index_of(&catalogue, l))
        .collect();
    let (matrix, _) = basis.system(&set);
    assert!(matrix.iter().all(|v| v.is_finite()), "the input was finite");
    let zero_columns = (0..matrix.ncols())
        .filter(|&j| matrix.column(j).iter().all(|&v| v == 0.0))
        .count();
    assert!(zero_columns >= 4, "m1's four columns are zero");

    let checks = VerificationSet::new(&energy);
    let result = decide(
        &energy,
        &catalogue,
        &basis,
        &checks,
        &set,
        realization_hints(&model),
    );
    assert_eq!(result.status, Status::Infeasible, "{:?}", result.reason);
    let exact = basis.exact.as_ref().expect("arm6 is exact").solve(&set);
    assert!(!exact.consistent());

    // The residual the search reports, against an independent least-squares solution: the
    // exact pivot columns are a basis of the column space (full column rank), so QR of them
    // projects b without any SVD.
    let reported = least_squares_residual(&basis, &set).expect("a finite residual");
    assert_eq!(result.linear_residual, reported);
    let pivots: Vec<usize> = exact
        .echelon
        .pivots
        .iter()
        .copied()
        .filter(|&c| c < matrix.ncols())
        .collect();
    assert_eq!(pivots.len(), exact.rank());
    let independent = DMatrix::from_columns(
        &pivots
            .iter()
            .map(|&c| matrix.column(c).into_owned())
            .collect::<Vec<DVector<f64>>>(),
    );
    let b = &basis.unbalanced;
    let q = independent.qr().q();
    let projected = &q * (q.transpose() * b);
    let by_qr = (b - projected).norm() / b.norm();
    assert!(by_qr > 1e-3, "inconsistent: a clear residual ({by_qr})");
    assert!(
        (reported - by_qr).abs() <= 1e-9 * by_qr.max(1.0),
        "SVD residual {reported} against QR {by_qr}"
    );

    // The numeric path on the same system decides the same way, with nalgebra's basis or
    // faer's, and returns finite numbers.
    let numeric = numeric_solve(&basis, &set);
    assert!(numeric.ambiguity.is_none(), "{:?}", numeric.ambiguity);
    assert!(!numeric.consistent);
    assert_eq!(numeric.rank, exact.rank());
    assert!(numeric.particular.iter().all(|v| v.is_finite()));
    assert!(numeric.nullspace.iter().all(|v| v.is_finite()));
}
