//! Exact, fast trigonometric-polynomial algebra for mechanism models.
//!
//! Every body pose of a mechanism described in a suitable chart is a polynomial in `cos q_k`,
//! `sin q_k` (angles) and `q_k` (lengths). Keeping poses, energies and actuator maps in that form
//! turns "is the potential energy constant?" into "are all non-constant coefficients zero?", and
//! coefficient extraction into reading a map. This crate is that algebra: [`TrigPoly`] (canonical
//! sparse polynomials with `sin² = 1 − cos²` reduced), [`LinearAngle`] rotations,
//! [`PolyVec3`]/[`PolyMat3`] poses, and the case-file expression language in [`expr`].

pub mod angle;
pub mod display;
pub mod expr;
pub mod geometry;
pub mod monomial;
pub mod poly;

pub use angle::LinearAngle;
pub use expr::{ExprContext, ExprError, ExprLimits, MAX_EXPRESSION_DEPTH, MAX_EXPRESSION_LENGTH};
pub use geometry::{PolyMat3, PolyVec3};
pub use monomial::{MAX_VARS, Monomial, VarKind};
pub use poly::{Point, TrigPoly};
