//! 3-vectors and 3×3 matrices of trigonometric polynomials: symbolic body poses.

use crate::angle::LinearAngle;
use crate::monomial::VarKind;
use crate::poly::{Point, TrigPoly};

/// A 3-vector whose entries are trigonometric polynomials.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PolyVec3(pub [TrigPoly; 3]);

/// A 3×3 matrix (row-major) whose entries are trigonometric polynomials.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PolyMat3(pub [[TrigPoly; 3]; 3]);

impl PolyVec3 {
    pub fn zero() -> PolyVec3 {
        PolyVec3::default()
    }

    pub fn constant(v: [f64; 3]) -> PolyVec3 {
        PolyVec3(v.map(TrigPoly::constant))
    }

    pub fn add(&self, other: &PolyVec3) -> PolyVec3 {
        PolyVec3(std::array::from_fn(|i| &self.0[i] + &other.0[i]))
    }

    pub fn sub(&self, other: &PolyVec3) -> PolyVec3 {
        PolyVec3(std::array::from_fn(|i| &self.0[i] - &other.0[i]))
    }

    pub fn scale(&self, s: f64) -> PolyVec3 {
        PolyVec3(std::array::from_fn(|i| self.0[i].scale(s)))
    }

    pub fn dot(&self, other: &PolyVec3) -> TrigPoly {
        let mut out = TrigPoly::zero();
        for i in 0..3 {
            out += &(&self.0[i] * &other.0[i]);
        }
        out
    }

    /// Dot product with a constant vector.
    pub fn dot_const(&self, v: [f64; 3]) -> TrigPoly {
        let mut out = TrigPoly::zero();
        for (entry, &scale) in self.0.iter().zip(&v) {
            out += &entry.scale(scale);
        }
        out
    }

    pub fn derivative(&self, var: usize, kind: VarKind) -> PolyVec3 {
        PolyVec3(std::array::from_fn(|i| self.0[i].derivative(var, kind)))
    }

    pub fn eval(&self, at: &Point) -> [f64; 3] {
        std::array::from_fn(|i| self.0[i].eval(at))
    }
}

impl PolyMat3 {
    pub fn identity() -> PolyMat3 {
        PolyMat3::constant([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    }

    pub fn constant(m: [[f64; 3]; 3]) -> PolyMat3 {
        PolyMat3(m.map(|row| row.map(TrigPoly::constant)))
    }

    /// Rotation about x by `angle`.
    pub fn rot_x(angle: &LinearAngle) -> PolyMat3 {
        let (c, s) = angle.cos_sin();
        let (o, z) = (TrigPoly::constant(1.0), TrigPoly::zero());
        PolyMat3([
            [o, z.clone(), z.clone()],
            [z.clone(), c.clone(), -&s],
            [z, s, c],
        ])
    }

    /// Rotation about y by `angle`.
    pub fn rot_y(angle: &LinearAngle) -> PolyMat3 {
        let (c, s) = angle.cos_sin();
        let (o, z) = (TrigPoly::constant(1.0), TrigPoly::zero());
        PolyMat3([
            [c.clone(), z.clone(), s.clone()],
            [z.clone(), o, z.clone()],
            [-&s, z, c],
        ])
    }

    /// Rotation about z by `angle`.
    pub fn rot_z(angle: &LinearAngle) -> PolyMat3 {
        let (c, s) = angle.cos_sin();
        let (o, z) = (TrigPoly::constant(1.0), TrigPoly::zero());
        PolyMat3([
            [c.clone(), -&s, z.clone()],
            [s, c, z.clone()],
            [z.clone(), z, o],
        ])
    }

    pub fn mul_mat(&self, other: &PolyMat3) -> PolyMat3 {
        PolyMat3(std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                let mut acc = TrigPoly::zero();
                for k in 0..3 {
                    acc += &(&self.0[i][k] * &other.0[k][j]);
                }
                acc
            })
        }))
    }

    pub fn mul_vec(&self, v: &PolyVec3) -> PolyVec3 {
        PolyVec3(std::array::from_fn(|i| {
            let mut acc = TrigPoly::zero();
            for k in 0..3 {
                acc += &(&self.0[i][k] * &v.0[k]);
            }
            acc
        }))
    }

    /// Product with a constant vector: cheaper than building a constant [`PolyVec3`].
    pub fn mul_const_vec(&self, v: [f64; 3]) -> PolyVec3 {
        PolyVec3(std::array::from_fn(|i| {
            let mut acc = TrigPoly::zero();
            for (entry, &scale) in self.0[i].iter().zip(&v) {
                acc += &entry.scale(scale);
            }
            acc
        }))
    }

    pub fn transpose(&self) -> PolyMat3 {
        PolyMat3(std::array::from_fn(|i| {
            std::array::from_fn(|j| self.0[j][i].clone())
        }))
    }

    pub fn column(&self, j: usize) -> PolyVec3 {
        PolyVec3(std::array::from_fn(|i| self.0[i][j].clone()))
    }

    pub fn derivative(&self, var: usize, kind: VarKind) -> PolyMat3 {
        PolyMat3(std::array::from_fn(|i| {
            std::array::from_fn(|j| self.0[i][j].derivative(var, kind))
        }))
    }

    pub fn eval(&self, at: &Point) -> [[f64; 3]; 3] {
        std::array::from_fn(|i| std::array::from_fn(|j| self.0[i][j].eval(at)))
    }

    /// Drops coefficients of magnitude at most `tol` in every entry (see [`TrigPoly::prune`]).
    pub fn prune(&mut self, tol: f64) {
        for row in &mut self.0 {
            for entry in row {
                entry.prune(tol);
            }
        }
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
