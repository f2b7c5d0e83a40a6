//! The mechanism model of counterpoise: the case-file format, its validation into a
//! [`Model`] whose body poses are trigonometric polynomials in the chart coordinates, and the
//! numeric [`Kinematics`] every later stage (balance, dynamics, optimisation) builds on.
//!
//! ```no_run
//! use counterpoise_model::{Case, Kinematics};
//! let model = Case::from_path(std::path::Path::new("cases/palletizer.json")).unwrap();
//! let kin = Kinematics::new(&model);
//! let q = nalgebra::DVector::from_vec(model.reference_configuration());
//! println!("u = {}", kin.actuator_values(&q));
//! ```

pub mod case;
pub mod error;
pub mod exact;
pub mod inertia;
mod jacobian_lu;
mod joints;
pub mod kinematics;
pub mod limits;
mod locate;
pub mod model;
pub mod newton;
mod pose;
mod reader;
pub mod sampling;
pub mod validate;

use std::path::Path;

pub use case::Case;
pub use error::{CaseErrors, ModelError, Position};
pub use exact::{
    ExactFrame, ExactMechanism, NotExact, SurdMechanism, exact_mechanism, exact_mechanism_in,
};
pub use kinematics::{BodyJacobian, BodyMotion, Kinematics, Pose};
pub use limits::{Limit, Limits};
pub use model::{
    Actuator, ActuatorMap, Balancing, Body, BodyId, Bounds, Coordinate, CounterweightOptions,
    CounterweightShape, GridAxis, Joint, JointKind, MechanismScale, Model, MotionLaw, PairMode,
    PathPayload, Payload, PayloadMode, Plane, SpringOptions, TaskPath, Tasks, Waypoint,
};
pub use newton::{KinematicsError, NewtonOptions};

impl Case {
    /// Parses and validates a case from JSON text, with the default [`Limits`].
    pub fn from_json_str(text: &str) -> Result<Model, CaseErrors> {
        Case::from_json_str_with(text, &Limits::default())
    }

    /// Parses and validates a case from JSON text: every error found (unknown fields, bad
    /// values, bad references), sorted by path and located in the text.
    pub fn from_json_str_with(text: &str, limits: &Limits) -> Result<Model, CaseErrors> {
        let (case, mut errors) = reader::parse(text, limits);
        if let Some(case) = case {
            match validate::validate_with(case, limits) {
                Ok(model) if errors.is_empty() => return Ok(model),
                Ok(_) => {}
                Err(e) => errors.extend(e.errors),
            }
        }
        Err(CaseErrors::sorted_and_located(errors, text))
    }

    /// Reads, parses and validates a case file, with the default [`Limits`].
    pub fn from_path(path: &Path) -> Result<Model, CaseErrors> {
        Case::from_path_with(path, &Limits::default())
    }

    /// Reads, parses and validates a case file; a file over the size limit is refused before
    /// it is read.
    pub fn from_path_with(path: &Path, limits: &Limits) -> Result<Model, CaseErrors> {
        let text = reader::read_text(path, limits)?;
        Case::from_json_str_with(&text, limits)
    }

    /// Parses the JSON text of a case file without validating its meaning. Every shape error
    /// is reported, each with its JSON path, line and column.
    pub fn parse(text: &str) -> Result<Case, CaseErrors> {
        match reader::parse(text, &Limits::default()) {
            (Some(case), errors) if errors.is_empty() => Ok(case),
            (_, errors) => Err(CaseErrors::sorted_and_located(errors, text)),
        }
    }

    /// Validates an already parsed case.
    pub fn validate(self) -> Result<Model, CaseErrors> {
        validate::validate(self)
    }
}

/// Reads, parses and validates a case file (same as [`Case::from_path`]).
pub fn load_case(path: &Path) -> Result<Model, CaseErrors> {
    Case::from_path(path)
}
