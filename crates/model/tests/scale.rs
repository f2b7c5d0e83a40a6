//! The mechanism's reach, from which the bounds of a case without `bounds` are derived
//! (docs/case-format.md, balancing): per body, |c| plus √3 times its largest radius of
//! gyration about the centre of mass, the largest over the bodies.

use counterpoise_model::{Case, MechanismScale};
use nalgebra::Vector3;

fn pendulum() -> counterpoise_model::Model {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../cases/pendulum.json");
    Case::from_path(&path).expect("the pendulum loads")
}

/// The pendulum's rod: mass 2 kg, CoM 0.5 m from the joint, inertia diag(0.001, 0.1667,
/// 0.1667) kg·m² about the CoM. Its largest radius of gyration is √(0.1667/2), so its reach is
/// 0.5 + √3·√(0.08335) = 0.5 + 0.50005 m (a uniform 1 m rod reaches 1 m: √3·ℓ/√12 = ℓ/2).
#[test]
fn a_rods_reach_is_its_length() {
    let model = pendulum();
    let scale = MechanismScale::of(&model.bodies, Vector3::new(0.0, -9.81, 0.0));
    let expected = 0.5 + 3f64.sqrt() * (0.1667f64 / 2.0).sqrt();
    assert!((scale.reach - expected).abs() <= 1e-12, "{}", scale.reach);
    assert!((scale.gravity - 9.81).abs() <= 1e-12);
}

/// A massless body has no radius of gyration (its inertia, whatever the numbers, divides by no
/// mass): its reach is |c| alone, 0.5 m, not infinity.
#[test]
fn a_massless_bodys_reach_is_its_centre() {
    let mut bodies = pendulum().bodies;
    bodies[0].mass = 0.0;
    let scale = MechanismScale::of(&bodies, Vector3::new(0.0, -9.81, 0.0));
    assert_eq!(scale.reach, 0.5);
}
