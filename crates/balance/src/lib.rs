//! Exact static balancing search (docs/design.md §2 Phase 2, §3; paper Eqs. 9–10, A3–A8).
//!
//! Given a mechanism's symbolic body poses and its unbalanced potential energy, find every set of
//! at most `Dmax` counterweights and zero-free-length springs that makes the total potential
//! energy constant, with physical parameters that prove it:
//!
//! 1. [`element`]: the catalogue of elements and the energy per unit of each lifted parameter,
//!    computed once per element;
//! 2. [`enumerate`]: every variant (Eq. 9) and its count (Eq. A8);
//! 3. [`linear`]: the per-variant linear system `A_S x = −b` — consistency, particular solution,
//!    free directions;
//! 4. [`realize`]: physical parameters (m, r, K, a, b) in the lifted solution set, or the reason
//!    there are none;
//! 5. [`verify`]: the witness's total energy sampled at random configurations;
//! 6. [`relations`]: the balance relations and free directions in readable form;
//! 7. [`search`]: all of it, in parallel, in a deterministic order;
//! 8. [`minimal`]: the minimal balancing sets up to a high Dmax, by a pruned walk instead of
//!    every combination;
//! 9. [`partial`]: when nothing small balances exactly, the sets and parameters within the
//!    bounds that leave the least gravity torque on the joints that matter.

pub mod element;
pub mod energy;
pub mod enumerate;
pub mod exact;
pub mod linear;
pub mod minimal;
pub mod model_input;
pub mod number_text;
pub mod partial;
pub mod realize;
pub mod relations;
pub mod search;
pub mod verify;

pub use element::{Attachment, Catalogue, CatalogueEntry, CatalogueOptions, Element, Plane};
pub use energy::{BodyFrame, MechanismEnergy};
pub use model_input::{catalogue_options, mechanism_energy, realization_hints};
pub use realize::{Counterweight, RealizationHints, Spring, Witness};
pub use search::{
    Arithmetic, Class, Decision, ElementKind, SearchOptions, SearchReport, Status, VariantResult,
    decide, search,
};
pub use verify::{VERIFY_SAMPLES, VERIFY_TOL, Verification, VerificationSet};
