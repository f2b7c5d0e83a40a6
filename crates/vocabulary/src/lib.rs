//! The words every stage of counterpoise shares, declared once on the ground floor.
//!
//! The case format, the balance search, the optimiser, the study and the reports all speak of
//! the kind of an element, the class of a variant, the plane of a vector, the status of a
//! variant, the physical parameters of its elements and the paper's indicators (ΔQTR, ΔQIT,
//! ΔR); each is one type here, serialised as results.json, the shard files and the
//! `variants --json` document write it, so no stage converts between copies and an exhaustive
//! `match` lists every place a new kind must be handled. Plain data and the paper's arithmetic
//! on it: serde and thiserror are the only dependencies.

pub mod element;
pub mod indicators;
pub mod parameters;
pub mod status;

pub use element::{Class, ElementKind, Plane};
pub use indicators::{
    DeltaR, IndicatorError, JointReaction, JointVariation, delta_r, percent_variation,
};
pub use parameters::{BASE, Counterweight, PhysicalParameters, Spring};
pub use status::Status;
