//! The palletizer's path Λ with the 150 kg payload picked at C and dropped at F.

mod common;

use common::case;
use counterpoise_dynamics::{ParameterSet, path_series};

#[test]
fn payload_adds_its_weight_while_carried() {
    let model = case("palletizer");
    let params = ParameterSet::unbalanced(&model);
    let per = 21;
    let with = path_series(&model, &params, 0, 0, per).unwrap();
    let mut bare_model = model.clone();
    bare_model.paths[0].payload = None;
    let bare = path_series(&bare_model, &params, 0, 0, per).unwrap();
    // 6 segments of 20 samples plus the final waypoint; 5 s in all
    assert_eq!(with.t.len(), 6 * (per - 1) + 1);
    assert!((with.t.last().unwrap() - 5.0).abs() < 1e-12);
    // carried on C→B, B→E, E→F (segments 1–3)
    let carried: Vec<usize> = (0..with.t.len()).filter(|&k| with.carried[k]).collect();
    assert_eq!(carried.first(), Some(&(per - 1)));
    assert_eq!(carried.last(), Some(&(4 * (per - 1) - 1)));
    // at rest at C (just picked): the payload at P adds ∂(m g p_y)/∂ρ3 = −5 m g to M3's force
    let k = per - 1;
    let d: Vec<f64> = (0..3)
        .map(|a| with.actuator_force[k][a] - bare.actuator_force[k][a])
        .collect();
    assert!(d[0].abs() < 1e-8 && d[1].abs() < 1e-6, "{d:?}");
    assert!((d[2] + 5.0 * 150.0 * 9.81).abs() < 1e-6, "{d:?}");
    // at F (just dropped) the robot is bare again
    let k = 4 * (per - 1);
    for a in 0..3 {
        assert!((with.actuator_force[k][a] - bare.actuator_force[k][a]).abs() < 1e-9);
    }
    assert!(with.rms[2] > bare.rms[2]);
    assert!(with.peak.iter().all(|p| p.is_finite()));
}
