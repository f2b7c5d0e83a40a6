//! Body poses from pose steps: the symbolic forward kinematics of the case format.
//!
//! A body's world pose is its parent's world pose followed by its own steps, left to right.
//! Rotation angles must be integer combinations of angle coordinates plus a constant (so the
//! rotation stays a trigonometric polynomial); translations may be any trigonometric polynomial.

use counterpoise_symbolic::{ExprContext, LinearAngle, PolyMat3, PolyVec3, TrigPoly};

use crate::case::{Expr, PoseStep};
use crate::error::ModelError;
use crate::limits::MAX_POSE_DEGREE;

/// A rigid transform `x ↦ R x + p` with polynomial entries.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct PolyPose {
    pub rotation: PolyMat3,
    pub origin: PolyVec3,
}

impl PolyPose {
    pub fn identity() -> PolyPose {
        PolyPose {
            rotation: PolyMat3::identity(),
            origin: PolyVec3::zero(),
        }
    }

    /// Highest power of one coordinate in the pose (rotation and origin).
    pub fn degree(&self) -> u32 {
        let rotation = self.rotation.0.iter().flatten().map(TrigPoly::max_power);
        let origin = self.origin.0.iter().map(TrigPoly::max_power);
        rotation.chain(origin).max().unwrap_or(0)
    }

    /// `self · (translation t)`, refused when the product would pass [`MAX_POSE_DEGREE`] (the
    /// symbolic core stores powers in a byte: an unchecked product could overflow it).
    fn translate(&mut self, t: &PolyVec3, path: &str) -> Result<(), ModelError> {
        let step = t.0.iter().map(TrigPoly::max_power).max().unwrap_or(0);
        self.check_degree(step, path)?;
        self.origin = self.origin.add(&self.rotation.mul_vec(t));
        Ok(())
    }

    /// `self · (rotation r)`, refused like [`PolyPose::translate`].
    fn rotate(&mut self, r: &PolyMat3, path: &str) -> Result<(), ModelError> {
        let step =
            r.0.iter()
                .flatten()
                .map(TrigPoly::max_power)
                .max()
                .unwrap_or(0);
        self.check_degree(step, path)?;
        self.rotation = self.rotation.mul_mat(r);
        Ok(())
    }

    fn check_degree(&self, step: u32, path: &str) -> Result<(), ModelError> {
        let degree = self.degree() + step;
        if degree > MAX_POSE_DEGREE {
            return Err(ModelError::invalid(
                path,
                format!(
                    "the pose reaches degree {degree} in one coordinate; at most {MAX_POSE_DEGREE} is supported"
                ),
            ));
        }
        Ok(())
    }

    /// `self · other`.
    pub fn compose(&self, other: &PolyPose) -> PolyPose {
        PolyPose {
            rotation: self.rotation.mul_mat(&other.rotation),
            origin: self.origin.add(&self.rotation.mul_vec(&other.origin)),
        }
    }

    /// Drops coefficients that are floating-point noise (e.g. `cos(pi/2) ≈ 6e-17`), so that
    /// coefficient maps stay sparse and exact-zero tests on energies are meaningful.
    pub fn prune(&mut self) {
        self.rotation.prune(1e-15);
        let scale = self
            .origin
            .0
            .iter()
            .map(TrigPoly::max_abs_coefficient)
            .fold(0.0, f64::max);
        for entry in &mut self.origin.0 {
            entry.prune(1e-15 * (1.0 + scale));
        }
    }
}

/// Parses expressions of one case file, attaching JSON paths to the errors.
pub(crate) struct Parser<'a> {
    pub context: &'a ExprContext,
}

impl Parser<'_> {
    pub fn poly(&self, expr: &Expr, path: &str) -> Result<TrigPoly, ModelError> {
        let poly = match expr {
            Expr::Number(x) => TrigPoly::constant(*x),
            Expr::Text(s) => {
                self.context
                    .parse_poly(s)
                    .map_err(|source| ModelError::Expression {
                        path: path.to_string(),
                        source,
                    })?
            }
        };
        if poly.terms().any(|(_, c)| !c.is_finite()) {
            return Err(ModelError::invalid(path, "expression is not finite"));
        }
        Ok(poly)
    }

    pub fn angle(&self, expr: &Expr, path: &str) -> Result<LinearAngle, ModelError> {
        let angle = match expr {
            Expr::Number(x) => LinearAngle::constant(*x),
            Expr::Text(s) => {
                self.context
                    .parse_angle(s)
                    .map_err(|source| ModelError::Expression {
                        path: path.to_string(),
                        source,
                    })?
            }
        };
        if !angle.offset.is_finite() {
            return Err(ModelError::invalid(path, "angle is not finite"));
        }
        Ok(angle)
    }

    pub fn constant(&self, expr: &Expr, path: &str) -> Result<f64, ModelError> {
        let value = match expr {
            Expr::Number(x) => *x,
            Expr::Text(s) => {
                self.context
                    .parse_constant(s)
                    .map_err(|source| ModelError::Expression {
                        path: path.to_string(),
                        source,
                    })?
            }
        };
        if !value.is_finite() {
            return Err(ModelError::invalid(
                path,
                format!("value {value} is not finite"),
            ));
        }
        Ok(value)
    }

    /// A constant 3-vector; every component's error is reported.
    pub fn constant_vec(
        &self,
        exprs: &[Expr; 3],
        path: &str,
        errors: &mut Vec<ModelError>,
    ) -> Option<[f64; 3]> {
        let mut out = [0.0; 3];
        let mut ok = true;
        for (k, e) in exprs.iter().enumerate() {
            match self.constant(e, &format!("{path}[{k}]")) {
                Ok(v) => out[k] = v,
                Err(err) => {
                    errors.push(err);
                    ok = false;
                }
            }
        }
        ok.then_some(out)
    }

    /// The transform of a body's pose steps relative to its parent frame, or `None` if a step
    /// failed (its errors are pushed).
    pub fn pose(
        &self,
        steps: &[PoseStep],
        path: &str,
        errors: &mut Vec<ModelError>,
    ) -> Option<PolyPose> {
        let mut pose = PolyPose::identity();
        let mut ok = true;
        for (n, step) in steps.iter().enumerate() {
            let step_path = format!("{path}[{n}]");
            if let Err(e) = self.apply_step(&mut pose, step, &step_path) {
                // Past the degree limit every further step fails the same way: report it once.
                let degree = e
                    .iter()
                    .any(|e| e.to_string().contains("pose reaches degree"));
                errors.extend(e);
                ok = false;
                if degree {
                    break;
                }
            }
        }
        ok.then(|| {
            pose.prune();
            pose
        })
    }

    fn apply_step(
        &self,
        pose: &mut PolyPose,
        step: &PoseStep,
        path: &str,
    ) -> Result<(), Vec<ModelError>> {
        match step {
            PoseStep::Translate(t) => {
                let mut entries: [TrigPoly; 3] = Default::default();
                let mut errors = Vec::new();
                for (k, e) in t.iter().enumerate() {
                    match self.poly(e, &format!("{path}.translate[{k}]")) {
                        Ok(p) => entries[k] = p,
                        Err(err) => errors.push(err),
                    }
                }
                if !errors.is_empty() {
                    return Err(errors);
                }
                pose.translate(&PolyVec3(entries), path)
                    .map_err(|e| vec![e])?;
            }
            PoseStep::RotX(e) => {
                let a = self
                    .angle(e, &format!("{path}.rot_x"))
                    .map_err(|e| vec![e])?;
                pose.rotate(&PolyMat3::rot_x(&a), path)
                    .map_err(|e| vec![e])?;
            }
            PoseStep::RotY(e) => {
                let a = self
                    .angle(e, &format!("{path}.rot_y"))
                    .map_err(|e| vec![e])?;
                pose.rotate(&PolyMat3::rot_y(&a), path)
                    .map_err(|e| vec![e])?;
            }
            PoseStep::RotZ(e) => {
                let a = self
                    .angle(e, &format!("{path}.rot_z"))
                    .map_err(|e| vec![e])?;
                pose.rotate(&PolyMat3::rot_z(&a), path)
                    .map_err(|e| vec![e])?;
            }
            PoseStep::Dh(dh) => {
                let theta = self.angle(&dh.theta, &format!("{path}.dh.theta"));
                let d = self.poly(&dh.d, &format!("{path}.dh.d"));
                let a = self.poly(&dh.a, &format!("{path}.dh.a"));
                let alpha = self.angle(&dh.alpha, &format!("{path}.dh.alpha"));
                match (theta, d, a, alpha) {
                    (Ok(theta), Ok(d), Ok(a), Ok(alpha)) => {
                        // Rz(theta)·Tz(d)·Tx(a)·Rx(alpha)
                        let steps = pose
                            .rotate(&PolyMat3::rot_z(&theta), path)
                            .and_then(|()| {
                                pose.translate(&PolyVec3([a, TrigPoly::zero(), d]), path)
                            })
                            .and_then(|()| pose.rotate(&PolyMat3::rot_x(&alpha), path));
                        steps.map_err(|e| vec![e])?;
                    }
                    (theta, d, a, alpha) => {
                        let mut errors = Vec::new();
                        errors.extend(theta.err());
                        errors.extend(d.err());
                        errors.extend(a.err());
                        errors.extend(alpha.err());
                        return Err(errors);
                    }
                }
            }
        }
        Ok(())
    }
}
