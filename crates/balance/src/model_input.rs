//! The bridge from a validated case model to the balance search's inputs.

use counterpoise_model::{BodyId, Model, PayloadMode};

use crate::element::{Attachment, CatalogueOptions};
use crate::energy::{BodyFrame, MechanismEnergy};
use crate::realize::RealizationHints;

/// The mechanism as the search sees it: every body's pose and the unbalanced energy of the bodies
/// plus the payloads marked `in_balance`.
pub fn mechanism_energy(model: &Model) -> MechanismEnergy {
    let (exact, surd) = exact_fields(model);
    MechanismEnergy {
        kinds: model.kinds(),
        ranges: model
            .coordinates
            .iter()
            .map(|c| (c.range[0], c.range[1]))
            .collect(),
        gravity: [model.gravity.x, model.gravity.y, model.gravity.z],
        bodies: model
            .bodies
            .iter()
            .map(|b| BodyFrame {
                name: b.name.clone(),
                rotation: b.rotation.clone(),
                origin: b.origin.clone(),
            })
            .collect(),
        unbalanced: model.potential_energy(PayloadMode::InBalance),
        exact,
        surd,
    }
}

/// The case over ℚ, else over ℚ(√2, √3) (built only when ℚ refuses it), each with the reason it
/// cannot be taken.
#[allow(clippy::type_complexity)]
fn exact_fields(
    model: &Model,
) -> (
    Result<counterpoise_model::ExactMechanism, String>,
    Result<counterpoise_model::SurdMechanism, String>,
) {
    match counterpoise_model::exact_mechanism(model) {
        Ok(m) => (Ok(m), Err("the case is exact over ℚ".to_string())),
        Err(e) => (
            Err(e.to_string()),
            counterpoise_model::exact_mechanism_in::<counterpoise_symbolic::Surd>(model)
                .map_err(|e| e.to_string()),
        ),
    }
}

/// Which elements the case allows (none when it has no `balancing` section).
pub fn catalogue_options(model: &Model) -> CatalogueOptions {
    let Some(balancing) = &model.balancing else {
        return CatalogueOptions::default();
    };
    let mut options = CatalogueOptions::default();
    if let Some(cw) = &balancing.counterweights {
        options.counterweight_bodies = cw.bodies.clone();
        options.counterweight_plane = cw.plane;
    }
    if let Some(springs) = &balancing.springs {
        options.spring_plane = springs.plane;
        options.spring_pairs = springs
            .pairs()
            .into_iter()
            .filter_map(|(i, s)| {
                let i = i.index()?;
                let other = match s {
                    BodyId::Base => Attachment::Base,
                    BodyId::Body(s) => Attachment::Body(s),
                };
                Some((i, other))
            })
            .collect();
    }
    options
}

/// Starting scales for realization from the case's design bounds: the middle of each range, so
/// that witnesses look like parts a designer could build.
pub fn realization_hints(model: &Model) -> RealizationHints {
    let Some(balancing) = &model.balancing else {
        return RealizationHints::default();
    };
    let b = &balancing.bounds;
    let middle = |r: [f64; 2], fallback: f64| {
        let m = 0.5 * (r[0] + r[1]);
        if m > 0.0 && m.is_finite() {
            m
        } else {
            fallback
        }
    };
    let defaults = RealizationHints::default();
    RealizationHints {
        mass: middle(b.mass, defaults.mass),
        stiffness: middle(b.stiffness, defaults.stiffness),
        length: middle(b.anchor_a, defaults.length).min(middle(b.radius, defaults.length)),
    }
}
