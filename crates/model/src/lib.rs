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
mod joints;
pub mod kinematics;
pub mod model;
pub mod newton;
mod pose;
pub mod sampling;
pub mod validate;

use std::path::Path;

pub use case::Case;
pub use error::{CaseErrors, ModelError};
pub use exact::{ExactFrame, ExactMechanism, NotExact, exact_mechanism};
pub use kinematics::{BodyJacobian, BodyMotion, Kinematics, Pose};
pub use model::{
    Actuator, ActuatorMap, Balancing, Body, BodyId, Bounds, Coordinate, CounterweightOptions,
    CounterweightShape, GridAxis, Joint, JointKind, Model, MotionLaw, PairMode, PathPayload,
    Payload, PayloadMode, Plane, SpringOptions, TaskPath, Tasks, Waypoint,
};
pub use newton::{KinematicsError, NewtonOptions};

impl Case {
    /// Parses and validates a case from JSON text.
    pub fn from_json_str(text: &str) -> Result<Model, CaseErrors> {
        validate::validate(Case::parse(text)?)
    }

    /// Reads, parses and validates a case file.
    pub fn from_path(path: &Path) -> Result<Model, CaseErrors> {
        let text = std::fs::read_to_string(path).map_err(|e| ModelError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
        Case::from_json_str(&text)
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
