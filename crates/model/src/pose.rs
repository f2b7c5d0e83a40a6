//! Body poses from pose steps: the symbolic forward kinematics of the case format.
//!
//! A body's world pose is its parent's world pose followed by its own steps, left to right.
//! Rotation angles must be integer combinations of angle coordinates plus a constant (so the
//! rotation stays a trigonometric polynomial); translations may be any trigonometric polynomial.

use counterpoise_symbolic::{Context, Field, Mat3, Poly, TrigPoly, Vec3};

use crate::case::{Expr, PoseStep};
use crate::error::ModelError;
use crate::limits::MAX_POSE_DEGREE;

/// A rigid transform `x ↦ R x + p` with polynomial entries over the field `C`.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct SymbolicPose<C> {
    pub rotation: Mat3<C>,
    pub origin: Vec3<C>,
}

/// The numeric pose the model is built from.
pub(crate) type PolyPose = SymbolicPose<f64>;

impl<C: Field> SymbolicPose<C> {
    pub fn identity() -> Self {
        SymbolicPose {
            rotation: Mat3::identity(),
            origin: Vec3::zero(),
        }
    }

    /// Highest power of one coordinate in the pose (rotation and origin).
    pub fn degree(&self) -> u32 {
        let rotation = self.rotation.0.iter().flatten().map(Poly::max_power);
        let origin = self.origin.0.iter().map(Poly::max_power);
        rotation.chain(origin).max().unwrap_or(0)
    }

    /// `self · (translation t)`, refused when the product would pass [`MAX_POSE_DEGREE`] (the
    /// symbolic core stores powers in a byte: an unchecked product could overflow it).
    fn translate(&mut self, t: &Vec3<C>, path: &str) -> Result<(), ModelError> {
        let step = t.0.iter().map(Poly::max_power).max().unwrap_or(0);
        self.check_degree(step, path)?;
        self.origin = self.origin.add(&self.rotation.mul_vec(t));
        Ok(())
    }

    /// `self · (rotation r)`, refused like [`SymbolicPose::translate`].
    fn rotate(&mut self, r: &Mat3<C>, path: &str) -> Result<(), ModelError> {
        let step = r.0.iter().flatten().map(Poly::max_power).max().unwrap_or(0);
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
    pub fn compose(&self, other: &Self) -> Self {
        SymbolicPose {
            rotation: self.rotation.mul_mat(&other.rotation),
            origin: self.origin.add(&self.rotation.mul_vec(&other.origin)),
        }
    }
}

impl PolyPose {
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

/// Parses expressions of one case file, attaching JSON paths to the errors. Lowers a case's expressions and pose steps over the field `F` (`f64` for the model, exact
/// rationals for the balance decision).
pub(crate) struct Parser<'a, F: Field = f64> {
    pub context: &'a Context<F>,
}

/// A literal number of the case file as a constant of `F`.
fn literal<F: Field>(x: f64, path: &str) -> Result<F::Constant, ModelError> {
    F::literal(x).map_err(|reason| ModelError::invalid(path, reason))
}

impl<F: Field> Parser<'_, F> {
    pub fn poly(&self, expr: &Expr, path: &str) -> Result<Poly<F>, ModelError> {
        let poly = match expr {
            Expr::Number(x) => Poly::constant(
                F::to_scalar(&literal::<F>(*x, path)?)
                    .map_err(|reason| ModelError::invalid(path, reason))?,
            ),
            Expr::Text(s) => {
                self.context
                    .parse_poly(s)
                    .map_err(|source| ModelError::Expression {
                        path: path.to_string(),
                        source,
                    })?
            }
        };
        if poly.terms_ref().any(|(_, c)| !c.to_f64().is_finite()) {
            return Err(ModelError::invalid(path, "expression is not finite"));
        }
        Ok(poly)
    }

    /// `(cos φ, sin φ)` of a rotation angle `φ`.
    pub fn cos_sin(&self, expr: &Expr, path: &str) -> Result<(Poly<F>, Poly<F>), ModelError> {
        let (c, s) = match expr {
            Expr::Number(x) => {
                let (c, s) = F::cos_sin(&literal::<F>(*x, path)?)
                    .map_err(|reason| ModelError::invalid(path, reason))?;
                (Poly::constant(c), Poly::constant(s))
            }
            Expr::Text(src) => {
                self.context
                    .parse_cos_sin(src)
                    .map_err(|source| ModelError::Expression {
                        path: path.to_string(),
                        source,
                    })?
            }
        };
        if c.terms_ref()
            .chain(s.terms_ref())
            .any(|(_, v)| !v.to_f64().is_finite())
        {
            return Err(ModelError::invalid(path, "angle is not finite"));
        }
        Ok((c, s))
    }

    pub fn constant(&self, expr: &Expr, path: &str) -> Result<F::Constant, ModelError> {
        let value = match expr {
            Expr::Number(x) => literal::<F>(*x, path)?,
            Expr::Text(s) => {
                self.context
                    .parse_constant(s)
                    .map_err(|source| ModelError::Expression {
                        path: path.to_string(),
                        source,
                    })?
            }
        };
        let number = F::constant_value(&value);
        if !number.is_finite() {
            return Err(ModelError::invalid(
                path,
                format!("value {number} is not finite"),
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
    ) -> Option<[F::Constant; 3]> {
        let mut out = [F::zero_constant(), F::zero_constant(), F::zero_constant()];
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
    ) -> Option<SymbolicPose<F>> {
        let mut pose = SymbolicPose::identity();
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
        ok.then_some(pose)
    }

    fn apply_step(
        &self,
        pose: &mut SymbolicPose<F>,
        step: &PoseStep,
        path: &str,
    ) -> Result<(), Vec<ModelError>> {
        match step {
            PoseStep::Translate(t) => {
                let mut entries: [Poly<F>; 3] = Default::default();
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
                pose.translate(&Vec3(entries), path).map_err(|e| vec![e])?;
            }
            PoseStep::RotX(e) => {
                let (c, s) = self
                    .cos_sin(e, &format!("{path}.rot_x"))
                    .map_err(|e| vec![e])?;
                pose.rotate(&Mat3::rot_x_cs(c, s), path)
                    .map_err(|e| vec![e])?;
            }
            PoseStep::RotY(e) => {
                let (c, s) = self
                    .cos_sin(e, &format!("{path}.rot_y"))
                    .map_err(|e| vec![e])?;
                pose.rotate(&Mat3::rot_y_cs(c, s), path)
                    .map_err(|e| vec![e])?;
            }
            PoseStep::RotZ(e) => {
                let (c, s) = self
                    .cos_sin(e, &format!("{path}.rot_z"))
                    .map_err(|e| vec![e])?;
                pose.rotate(&Mat3::rot_z_cs(c, s), path)
                    .map_err(|e| vec![e])?;
            }
            PoseStep::Dh(dh) => {
                let theta = self.cos_sin(&dh.theta, &format!("{path}.dh.theta"));
                let d = self.poly(&dh.d, &format!("{path}.dh.d"));
                let a = self.poly(&dh.a, &format!("{path}.dh.a"));
                let alpha = self.cos_sin(&dh.alpha, &format!("{path}.dh.alpha"));
                match (theta, d, a, alpha) {
                    (Ok((ct, st)), Ok(d), Ok(a), Ok((ca, sa))) => {
                        // Rz(theta)·Tz(d)·Tx(a)·Rx(alpha)
                        let steps = pose
                            .rotate(&Mat3::rot_z_cs(ct, st), path)
                            .and_then(|()| pose.translate(&Vec3([a, Poly::zero(), d]), path))
                            .and_then(|()| pose.rotate(&Mat3::rot_x_cs(ca, sa), path));
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
