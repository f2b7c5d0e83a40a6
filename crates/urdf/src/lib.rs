//! Import a URDF robot description as a counterpoise case.
//!
//! Every link that moves becomes a body (named as the link) with its mass, centre of mass and
//! inertia; every `revolute`, `continuous` or `prismatic` joint becomes a chart coordinate, a
//! case joint and an actuator (ratio 1, the effort limit as peak limit); `fixed` joints merge
//! the child link into the body it is fixed to. Link poses are written as pose steps from the
//! joints' `<origin>` and `<axis>` (see [`steps`] for the exactness rule). The result is
//! validated by loading it as a case, so an imported case is always accepted by `check`.
//!
//! Conventions: a link without `<inertial>` is massless (as in the URDF specification); a link
//! with `<inertial>` but no `<inertia>` is a point mass. Gravity is `[0, 0, -9.81]` in the base
//! link's frame.

pub mod build;
pub mod error;
mod layout;
pub mod parse;
pub mod steps;
pub mod tree;

pub use build::ImportOptions;
pub use error::UrdfError;

/// An imported case: its JSON text and the validated model.
#[derive(Debug)]
pub struct Imported {
    pub json: String,
    pub model: counterpoise_model::Model,
}

/// Imports URDF text: parses it, checks the tree, builds the case and validates it.
pub fn import(urdf: &str, options: &ImportOptions) -> Result<Imported, UrdfError> {
    let robot = parse::parse(urdf)?;
    let tree = tree::Tree::build(&robot)?;
    let doc = build::build(&robot, &tree, options)?;
    let json = layout::layout(&serde_json::to_string(&doc).expect("a case document serialises"));
    match counterpoise_model::Case::from_json_str(&json) {
        Ok(model) => Ok(Imported { json, model }),
        Err(errors) => Err(UrdfError::Case(errors.lines().join("\n"))),
    }
}
