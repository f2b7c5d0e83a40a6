//! Rest-to-rest motion laws in actuator space.
//!
//! The paper (Sec. 3.1) drives every actuator with one quintic polynomial between two grid
//! points in a fixed time: `s(τ) = 10τ³ − 15τ⁴ + 6τ⁵`, `τ = t/T`, which starts and ends with
//! zero velocity and zero acceleration. An actuator moving from `a` to `b` follows
//! `u(t) = a + (b − a)·s(t/T)`.

/// Normalised quintic profile: `(s, ds/dτ, d²s/dτ²)` at `τ ∈ [0, 1]`.
#[inline]
pub fn quintic(tau: f64) -> (f64, f64, f64) {
    let t2 = tau * tau;
    let t3 = t2 * tau;
    let s = t3 * (10.0 + tau * (-15.0 + 6.0 * tau));
    let ds = t2 * (30.0 + tau * (-60.0 + 30.0 * tau));
    let dds = tau * (60.0 + tau * (-180.0 + 120.0 * tau));
    (s, ds, dds)
}

/// Time of sample `k` of `samples` equally spaced samples over `[0, duration]`, both ends
/// included. Computed as `duration·k/(samples−1)` so that sample `k` of a move and sample
/// `samples−1−k` of the reversed move see exactly mirrored times.
#[inline]
pub fn sample_time(k: usize, samples: usize, duration: f64) -> f64 {
    if samples < 2 {
        return 0.0;
    }
    duration * k as f64 / (samples - 1) as f64
}

/// Actuator position, velocity and acceleration of a quintic move from `a` to `b` in
/// `duration` seconds, at time `t`.
#[inline]
pub fn quintic_move(a: f64, b: f64, duration: f64, t: f64) -> (f64, f64, f64) {
    let (s, ds, dds) = quintic((t / duration).clamp(0.0, 1.0));
    let d = b - a;
    (
        a + d * s,
        d * ds / duration,
        d * dds / (duration * duration),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quintic_is_rest_to_rest() {
        assert_eq!(quintic(0.0), (0.0, 0.0, 0.0));
        let (s, ds, dds) = quintic(1.0);
        assert!((s - 1.0).abs() < 1e-15 && ds.abs() < 1e-13 && dds.abs() < 1e-12);
    }

    #[test]
    fn derivatives_match_finite_differences() {
        let h = 1e-6;
        for k in 1..10 {
            let t = k as f64 / 10.0;
            let (_, ds, dds) = quintic(t);
            let fd1 = (quintic(t + h).0 - quintic(t - h).0) / (2.0 * h);
            let fd2 = (quintic(t + h).1 - quintic(t - h).1) / (2.0 * h);
            assert!((ds - fd1).abs() < 1e-8, "{ds} {fd1}");
            assert!((dds - fd2).abs() < 1e-7, "{dds} {fd2}");
        }
    }

    #[test]
    fn quintic_is_symmetric() {
        // s(1−τ) = 1 − s(τ): the reversed move is the same curve run backwards.
        for k in 0..=20 {
            let t = k as f64 / 20.0;
            let (s, ds, dds) = quintic(t);
            let (sr, dsr, ddsr) = quintic(1.0 - t);
            assert!((s + sr - 1.0).abs() < 1e-14);
            assert!((ds - dsr).abs() < 1e-12);
            assert!((dds + ddsr).abs() < 1e-11);
        }
    }
}
