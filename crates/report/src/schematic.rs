//! Schematics: a drawing of a variant — the mechanism's bodies and joints at one pose, each
//! counterweight as a disc at its offset sized by its mass, each spring as a zig-zag between
//! its anchors, labelled (the paper's Fig. 6, for any case).
//!
//! The geometry is world coordinates (m) computed from the model's kinematics by the caller
//! (the `run` and `report` commands: this crate does not depend on the model), stored in
//! results.json as [`Schematic`]s and drawn here. The drawing is an orthographic projection
//! onto the plane spanned by the *up* direction (against gravity) and the horizontal direction
//! along which the drawn points spread most (the principal axis of their horizontal
//! components): a planar mechanism in a vertical plane is drawn in that plane, a spatial one
//! (a base rotating about the vertical) in the vertical plane its arm is in.
//!
//! The SVG states its projection on its root element (`data-right`, `data-up`: unit world
//! vectors; `data-scale`: px per m; `data-ox`, `data-oy`: the pixel of the world origin; and
//! `data-q`: the configuration), so a point `p` is drawn at
//! `x = ox + scale·(p·right)`, `y = oy − scale·(p·up)`; joints, counterweight centres and
//! spring anchors are circles carrying `data-joint`, `data-cw` and `data-spring` +
//! `data-end` (`a`, `b`). tests/report_schematic.rs reads them back and compares them with
//! the model's kinematics.

use serde::{Deserialize, Serialize};

/// The geometry of one drawing, world frame, m.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Schematic {
    /// Variant id; `None` for the unbalanced mechanism (drawn when no variant is recommended).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub variant: Option<usize>,
    /// The pose in words, e.g. `waypoint A of path cycle`.
    pub pose: String,
    /// The configuration drawn (the case's coordinates).
    pub q: Vec<f64>,
    /// Gravity, m/s² (its direction is down in the drawing).
    pub gravity: [f64; 3],
    pub bodies: Vec<DrawnBody>,
    pub joints: Vec<DrawnJoint>,
    pub counterweights: Vec<DrawnCounterweight>,
    pub springs: Vec<DrawnSpring>,
}

/// A body: drawn as bars from its first point (where it hangs from its parent) to each other
/// point (its other joints, its centre of mass).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DrawnBody {
    pub name: String,
    pub points: Vec<[f64; 3]>,
    /// Centre of mass (where the label goes).
    pub com: [f64; 3],
}

/// A joint centre.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DrawnJoint {
    pub name: String,
    pub at: [f64; 3],
    /// One side is the base (drawn with a ground mark).
    pub grounded: bool,
}

/// A counterweight: its centre of mass, and the point of its body it hangs from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DrawnCounterweight {
    pub label: String,
    pub at: [f64; 3],
    pub from: [f64; 3],
}

/// A spring: its anchors, and the points of their bodies they are fixed to.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DrawnSpring {
    pub label: String,
    pub a: [f64; 3],
    pub b: [f64; 3],
    pub a_from: [f64; 3],
    pub b_from: [f64; 3],
}

/// The projection of a drawing (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Projection {
    pub right: [f64; 3],
    pub up: [f64; 3],
}

pub(crate) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(crate) fn unit(v: [f64; 3]) -> Option<[f64; 3]> {
    let n = dot(v, v).sqrt();
    (n > 1e-12 && n.is_finite()).then(|| [v[0] / n, v[1] / n, v[2] / n])
}

impl Schematic {
    /// Every point drawn.
    pub fn points(&self) -> Vec<[f64; 3]> {
        let mut p: Vec<[f64; 3]> = Vec::new();
        for b in &self.bodies {
            p.extend(&b.points);
            p.push(b.com);
        }
        p.extend(self.joints.iter().map(|j| j.at));
        for c in &self.counterweights {
            p.extend([c.at, c.from]);
        }
        for s in &self.springs {
            p.extend([s.a, s.b, s.a_from, s.b_from]);
        }
        p
    }

    /// Up against gravity (world y when gravity is zero); right the principal horizontal
    /// direction of the points, its largest component positive (deterministic sign).
    pub fn projection(&self) -> Projection {
        let up =
            unit([-self.gravity[0], -self.gravity[1], -self.gravity[2]]).unwrap_or([0.0, 1.0, 0.0]);
        let pts = self.points();
        let n = pts.len().max(1) as f64;
        let mean = pts.iter().fold([0.0; 3], |m, p| {
            [m[0] + p[0] / n, m[1] + p[1] / n, m[2] + p[2] / n]
        });
        // Horizontal components, centred; covariance; power iteration from the horizontal
        // axis of a fixed start (deterministic).
        let horizontal = |v: [f64; 3]| {
            let d = dot(v, up);
            [v[0] - d * up[0], v[1] - d * up[1], v[2] - d * up[2]]
        };
        let mut cov = [[0.0; 3]; 3];
        for p in &pts {
            let h = horizontal([p[0] - mean[0], p[1] - mean[1], p[2] - mean[2]]);
            for i in 0..3 {
                for j in 0..3 {
                    cov[i][j] += h[i] * h[j];
                }
            }
        }
        let fallback = [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]]
            .into_iter()
            .find_map(|a| unit(horizontal(a)))
            .unwrap_or([1.0, 0.0, 0.0]);
        let mut right = fallback;
        for start in [[1.0, 0.3, 0.1], [0.1, 0.3, 1.0]] {
            let mut v = match unit(horizontal(start)) {
                Some(v) => v,
                None => continue,
            };
            let mut ok = true;
            for _ in 0..200 {
                let w = [dot(cov[0], v), dot(cov[1], v), dot(cov[2], v)];
                match unit(horizontal(w)) {
                    Some(u) => v = u,
                    None => {
                        ok = false;
                        break;
                    }
                }
            }
            if ok {
                right = v;
                break;
            }
        }
        let k = (0..3)
            .max_by(|&i, &j| right[i].abs().total_cmp(&right[j].abs()))
            .unwrap_or(0);
        if right[k] < 0.0 {
            right = [-right[0], -right[1], -right[2]];
        }
        Projection { right, up }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Schematic {
        Schematic {
            variant: Some(0),
            pose: "test".into(),
            q: vec![0.0],
            gravity: [0.0, 0.0, -9.81],
            bodies: vec![DrawnBody {
                name: "arm".into(),
                points: vec![[0.0, 0.0, 0.0], [1.0, 1.0, 0.5]],
                com: [0.5, 0.5, 0.25],
            }],
            joints: vec![],
            counterweights: vec![],
            springs: vec![],
        }
    }

    #[test]
    fn projection_is_up_and_the_horizontal_spread() {
        // Gravity along −z: up = +z. The points spread horizontally along (1, 1, 0)/√2.
        let p = sample().projection();
        assert_eq!(p.up, [0.0, 0.0, 1.0]);
        let h = std::f64::consts::FRAC_1_SQRT_2;
        assert!((p.right[0] - h).abs() < 1e-9 && (p.right[1] - h).abs() < 1e-9);
        assert!(p.right[2].abs() < 1e-12);
    }
}
