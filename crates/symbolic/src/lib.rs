//! Exact, fast trigonometric-polynomial algebra for mechanism models.
//!
//! Every body pose of a mechanism described in a suitable chart is a polynomial in `cos q_k`,
//! `sin q_k` (angles) and `q_k` (lengths). Keeping poses, energies and actuator maps in that form
//! turns "is the potential energy constant?" into "are all non-constant coefficients zero?", and
//! coefficient extraction into reading a map. This crate is that algebra: [`TrigPoly`] (canonical
//! sparse polynomials with `sin² = 1 − cos²` reduced), [`LinearAngle`] rotations,
//! [`PolyVec3`]/[`PolyMat3`] poses, and the case-file expression language in [`expr`].
//!
//! The algebra is generic over the coefficient [`Scalar`]: `f64` ([`TrigPoly`]) for kinematics
//! and dynamics, exact rationals ([`ExactPoly`]) for the balance decision, built by the same code.

pub mod angle;
pub mod display;
pub mod expr;
pub mod field;
pub mod field_surd;
pub mod geometry;
pub mod monomial;
pub mod ordered;
pub mod poly;
pub mod scalar;
pub mod surd;

pub use angle::LinearAngle;
pub use expr::{
    Context, ExactContext, ExprContext, ExprError, ExprLimits, MAX_EXPRESSION_DEPTH,
    MAX_EXPRESSION_LENGTH,
};
pub use field::{ExactConstant, Field};
pub use field_surd::SurdConstant;
pub use geometry::{ExactMat3, ExactVec3, Mat3, PolyMat3, PolyVec3, Vec3};
pub use monomial::{MAX_VARS, Monomial, VarKind};
pub use ordered::{Ordered, RefArith};
pub use poly::{ExactPoly, Point, Poly, TrigPoly};
pub use scalar::{Rational, Scalar, decimal_to_rational, rational_to_f64};
pub use surd::Surd;
