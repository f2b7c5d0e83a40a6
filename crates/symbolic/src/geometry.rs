//! 3-vectors and 3×3 matrices of trigonometric polynomials: symbolic body poses.

use crate::angle::LinearAngle;
use crate::monomial::VarKind;
use crate::poly::{Point, Poly};
use crate::scalar::{Rational, Scalar};

/// A 3-vector whose entries are trigonometric polynomials over the field `C`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Vec3<C>(pub [Poly<C>; 3]);

/// A 3×3 matrix (row-major) whose entries are trigonometric polynomials over the field `C`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mat3<C>(pub [[Poly<C>; 3]; 3]);

/// Numeric symbolic vector (kinematics, dynamics).
pub type PolyVec3 = Vec3<f64>;
/// Numeric symbolic matrix (kinematics, dynamics).
pub type PolyMat3 = Mat3<f64>;
/// Exact symbolic vector (balance decision).
pub type ExactVec3 = Vec3<Rational>;
/// Exact symbolic matrix (balance decision).
pub type ExactMat3 = Mat3<Rational>;

impl<C: Scalar> Vec3<C> {
    pub fn zero() -> Self {
        Vec3(Default::default())
    }

    pub fn constant(v: [C; 3]) -> Self {
        Vec3(v.map(Poly::constant))
    }

    pub fn add(&self, other: &Self) -> Self {
        Vec3(std::array::from_fn(|i| &self.0[i] + &other.0[i]))
    }

    pub fn sub(&self, other: &Self) -> Self {
        Vec3(std::array::from_fn(|i| &self.0[i] - &other.0[i]))
    }

    pub fn scale(&self, s: C) -> Self {
        Vec3(std::array::from_fn(|i| self.0[i].scale(s.clone())))
    }

    pub fn dot(&self, other: &Self) -> Poly<C> {
        let mut out = Poly::zero();
        for i in 0..3 {
            out += &(&self.0[i] * &other.0[i]);
        }
        out
    }

    /// Dot product with a constant vector.
    pub fn dot_const(&self, v: [C; 3]) -> Poly<C> {
        let mut out = Poly::zero();
        for (entry, scale) in self.0.iter().zip(v) {
            out += &entry.scale(scale);
        }
        out
    }

    pub fn derivative(&self, var: usize, kind: VarKind) -> Self {
        Vec3(std::array::from_fn(|i| self.0[i].derivative(var, kind)))
    }

    pub fn eval(&self, at: &Point) -> [f64; 3] {
        std::array::from_fn(|i| self.0[i].eval(at))
    }
}

impl PolyMat3 {
    /// Rotation about x by `angle`.
    pub fn rot_x(angle: &LinearAngle) -> PolyMat3 {
        let (c, s) = angle.cos_sin();
        Mat3::rot_x_cs(c, s)
    }

    /// Rotation about y by `angle`.
    pub fn rot_y(angle: &LinearAngle) -> PolyMat3 {
        let (c, s) = angle.cos_sin();
        Mat3::rot_y_cs(c, s)
    }

    /// Rotation about z by `angle`.
    pub fn rot_z(angle: &LinearAngle) -> PolyMat3 {
        let (c, s) = angle.cos_sin();
        Mat3::rot_z_cs(c, s)
    }

    /// Drops coefficients of magnitude at most `tol` in every entry (see
    /// [`crate::TrigPoly::prune`]).
    pub fn prune(&mut self, tol: f64) {
        for row in &mut self.0 {
            for entry in row {
                entry.prune(tol);
            }
        }
    }
}

impl<C: Scalar> Mat3<C> {
    pub fn identity() -> Self {
        let (o, z) = (C::one(), C::zero());
        Mat3::constant([
            [o.clone(), z.clone(), z.clone()],
            [z.clone(), o.clone(), z.clone()],
            [z.clone(), z, o],
        ])
    }

    pub fn constant(m: [[C; 3]; 3]) -> Self {
        Mat3(m.map(|row| row.map(Poly::constant)))
    }

    /// Rotation about x given its cosine and sine.
    pub fn rot_x_cs(c: Poly<C>, s: Poly<C>) -> Self {
        let (o, z) = (Poly::constant(C::one()), Poly::zero());
        Mat3([
            [o, z.clone(), z.clone()],
            [z.clone(), c.clone(), -&s],
            [z, s, c],
        ])
    }

    /// Rotation about y given its cosine and sine.
    pub fn rot_y_cs(c: Poly<C>, s: Poly<C>) -> Self {
        let (o, z) = (Poly::constant(C::one()), Poly::zero());
        Mat3([
            [c.clone(), z.clone(), s.clone()],
            [z.clone(), o, z.clone()],
            [-&s, z, c],
        ])
    }

    /// Rotation about z given its cosine and sine.
    pub fn rot_z_cs(c: Poly<C>, s: Poly<C>) -> Self {
        let (o, z) = (Poly::constant(C::one()), Poly::zero());
        Mat3([
            [c.clone(), -&s, z.clone()],
            [s, c, z.clone()],
            [z.clone(), z, o],
        ])
    }

    pub fn mul_mat(&self, other: &Self) -> Self {
        Mat3(std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                let mut acc = Poly::zero();
                for k in 0..3 {
                    acc += &(&self.0[i][k] * &other.0[k][j]);
                }
                acc
            })
        }))
    }

    pub fn mul_vec(&self, v: &Vec3<C>) -> Vec3<C> {
        Vec3(std::array::from_fn(|i| {
            let mut acc = Poly::zero();
            for k in 0..3 {
                acc += &(&self.0[i][k] * &v.0[k]);
            }
            acc
        }))
    }

    /// Product with a constant vector: cheaper than building a constant [`PolyVec3`].
    pub fn mul_const_vec(&self, v: [C; 3]) -> Vec3<C> {
        Vec3(std::array::from_fn(|i| {
            let mut acc = Poly::zero();
            for (entry, scale) in self.0[i].iter().zip(&v) {
                acc += &entry.scale(scale.clone());
            }
            acc
        }))
    }

    pub fn transpose(&self) -> Self {
        Mat3(std::array::from_fn(|i| {
            std::array::from_fn(|j| self.0[j][i].clone())
        }))
    }

    pub fn column(&self, j: usize) -> Vec3<C> {
        Vec3(std::array::from_fn(|i| self.0[i][j].clone()))
    }

    pub fn derivative(&self, var: usize, kind: VarKind) -> Self {
        Mat3(std::array::from_fn(|i| {
            std::array::from_fn(|j| self.0[i][j].derivative(var, kind))
        }))
    }

    pub fn eval(&self, at: &Point) -> [[f64; 3]; 3] {
        std::array::from_fn(|i| std::array::from_fn(|j| self.0[i][j].eval(at)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_is_orthogonal_symbolically() {
        let r = PolyMat3::rot_z(&LinearAngle::coordinate(0))
            .mul_mat(&PolyMat3::rot_x(&LinearAngle::coordinate(1)))
            .mul_mat(&PolyMat3::rot_y(&LinearAngle {
                terms: vec![(0, 1), (1, -1)],
                offset: 0.2,
            }));
        let mut rtr = r.transpose().mul_mat(&r);
        rtr.prune(1e-12);
        assert_eq!(rtr, PolyMat3::identity());
    }
}
