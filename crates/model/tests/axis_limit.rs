//! The shortest axis a case may give (docs/case-format.md: an axis's length is at least
//! 1e-12): exactly that length is a direction, anything shorter is refused.

use counterpoise_model::validate::{MIN_AXIS_NORM, unit_direction};
use nalgebra::Vector3;

#[test]
fn an_axis_of_exactly_the_smallest_length_is_a_direction() {
    assert_eq!(MIN_AXIS_NORM, 1e-12);
    // |(1e-12, 0, 0)| = 1e-12 exactly (one non-zero component), so the unit is (1, 0, 0)
    let unit = unit_direction(&Vector3::new(0.0, 1e-12, 0.0)).unwrap();
    assert_eq!(unit, Vector3::new(0.0, 1.0, 0.0));
    // the next double below is too short
    let shorter = f64::from_bits(1e-12f64.to_bits() - 1);
    let err = unit_direction(&Vector3::new(0.0, shorter, 0.0)).unwrap_err();
    assert!(err.contains("too short"), "{err}");
}
