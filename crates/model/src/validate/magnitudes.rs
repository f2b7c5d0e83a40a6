//! The largest magnitudes a case may give, and the checked unit direction.
//!
//! Bounds like these keep the numerics (SVD, Newton, the dynamics) well conditioned; every
//! section of the validator checks against them, so they sit apart from the sections.

use nalgebra::Vector3;

/// Relative tolerance of the joint checks: deviations up to `JOINT_TOLERANCE · (1 + L)` pass,
/// `L` being the characteristic length of the mechanism.
pub const JOINT_TOLERANCE: f64 = 1e-9;

/// Relative tolerance of the check that an actuated coordinate moves like its joint.
pub const ACTUATOR_TOLERANCE: f64 = 1e-8;

/// Largest length a case may give (coordinate ranges, centres of mass, joint points, pose
/// translations, element bounds), m. Bounds like these keep the numerics (SVD, Newton, the
/// dynamics) well conditioned: a link of 1e308 m would otherwise spin in an SVD for minutes.
pub const MAX_LENGTH: f64 = 1e3;
/// Largest angle of a coordinate range, rad.
pub const MAX_ANGLE: f64 = 1e3;
/// Largest mass (bodies, payloads, counterweight bounds), kg.
pub const MAX_MASS: f64 = 1e6;
/// Largest inertia tensor entry, kg·m².
pub const MAX_INERTIA: f64 = 1e6;
/// Largest gravity component, m/s².
pub const MAX_GRAVITY: f64 = 1e3;
/// Largest parameter value (parameters are plain numbers; what they become is bounded where
/// they are used).
pub const MAX_PARAMETER: f64 = 1e9;
/// Largest actuator ratio, peak torque limit (N·m), spring stiffness bound (N/m) and
/// counterweight density (kg/m³).
pub const MAX_RATIO: f64 = 1e6;
pub const MAX_TORQUE: f64 = 1e9;
pub const MAX_STIFFNESS: f64 = 1e9;
pub const MAX_DENSITY: f64 = 1e6;
/// Move and segment durations, s: shorter moves make accelerations overflow, longer ones are
/// not tasks.
pub const DURATION_RANGE: [f64; 2] = [1e-3, 1e6];

/// Smallest norm of a vector used as a direction (a joint axis): shorter ones are refused.
pub const MIN_AXIS_NORM: f64 = 1e-12;

/// The unit vector along `v`, or why `v` gives no direction: it is zero, its norm is below
/// [`MIN_AXIS_NORM`] (it underflows, or is too short to be told from zero), or its norm
/// overflows (a component beyond about 1e154 squares to infinity; normalising by an infinite
/// norm would give the zero vector, and the NaN that follows hangs an SVD). The components
/// are known finite.
pub fn unit_direction(v: &Vector3<f64>) -> Result<Vector3<f64>, String> {
    let largest = v.amax();
    let norm = v.norm();
    if largest == 0.0 {
        return Err("axis must not be zero".into());
    }
    if !norm.is_finite() {
        return Err(format!(
            "the axis's length overflows (a component of magnitude {}): a direction needs components of moderate size, e.g. [0, 0, 1]",
            num(largest)
        ));
    }
    if norm < MIN_AXIS_NORM {
        return Err(format!(
            "the axis's length {} is below {}: too short to give a direction (an axis must not be zero); scale it up, e.g. [0, 0, 1]",
            num(norm.max(largest)),
            num(MIN_AXIS_NORM)
        ));
    }
    Ok(v / norm)
}

/// A number for a message: plain when moderate, in exponent form when huge or tiny (`1e308`
/// is not printed as 309 digits).
pub(super) fn num(x: f64) -> String {
    if x != 0.0 && x.is_finite() && !(1e-4..1e9).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}
