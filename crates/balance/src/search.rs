//! The whole balance search: enumerate variants, decide each one, realize and verify the
//! balanced ones. Parallel over variants with rayon; output order is the enumeration order, so
//! results do not depend on the number of threads.

use rayon::prelude::*;
use serde::Serialize;

use crate::element::{Attachment, Catalogue, Element};
use crate::energy::MechanismEnergy;
use crate::enumerate::variants;
use crate::linear::{LiftedBasis, solve};
use crate::realize::{Realization, RealizationHints, Witness, realize};
use crate::relations::{FreeDirection, balance_relations, free_directions, variable_units};
use crate::verify::{Verification, VerificationSet};

/// What the search concluded about a variant.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Status {
    /// Verified physical parameters exist.
    Balanced,
    /// Balance forces an element to vanish (or a spring to act as a constant force): the variant
    /// is really a smaller one.
    Degenerate,
    /// Lifted parameters exist but no physical ones can (reason given).
    Unrealizable,
    /// `A_S x = −b` has no solution: no parameters balance this variant.
    Infeasible,
    /// The realization search gave up, or a witness failed verification (reason given).
    Undecided,
}

impl Status {
    pub const ALL: [Status; 5] = [
        Status::Balanced,
        Status::Degenerate,
        Status::Unrealizable,
        Status::Infeasible,
        Status::Undecided,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Status::Balanced => "balanced",
            Status::Degenerate => "degenerate",
            Status::Unrealizable => "unrealizable",
            Status::Infeasible => "infeasible",
            Status::Undecided => "undecided",
        }
    }
}

/// Counterweights only, springs only, or both (the paper's three classes).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Class {
    Counterweights,
    Springs,
    Hybrid,
}

impl Class {
    pub fn name(self) -> &'static str {
        match self {
            Class::Counterweights => "counterweights",
            Class::Springs => "springs",
            Class::Hybrid => "hybrid",
        }
    }
}

/// One installed element of a variant, named for people.
#[derive(Clone, Debug, Serialize)]
pub struct ElementRef {
    /// Index in the catalogue.
    pub entry: usize,
    pub label: String,
    /// `counterweight` or `spring`.
    #[serde(rename = "type")]
    pub kind: &'static str,
    /// Body names: one for a counterweight, two for a spring (`base` for the ground).
    pub bodies: Vec<String>,
}

/// Everything the search found about one variant.
#[derive(Clone, Debug, Serialize)]
pub struct VariantResult {
    pub elements: Vec<ElementRef>,
    pub class: Class,
    pub status: Status,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// Rank of `A_S` and dimension of the balanced family (free lifted parameters).
    pub rank: usize,
    pub nullity: usize,
    /// ‖A_S x_p + b‖/‖b‖ of the least-squares solution (the inconsistency measure).
    pub linear_residual: f64,
    /// Labels of installed elements that do not change the energy at all (any parameters work).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub redundant: Vec<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub witness: Option<Witness>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub verification: Option<Verification>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub relations: Vec<String>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub free_directions: Vec<FreeDirection>,
}

/// Settings of a search.
#[derive(Clone, Copy, Debug)]
pub struct SearchOptions {
    pub dmax: usize,
    pub hints: RealizationHints,
}

/// The search's output: the catalogue and every variant in enumeration order.
#[derive(Clone, Debug)]
pub struct SearchReport {
    pub catalogue: Catalogue,
    pub variants: Vec<VariantResult>,
}

impl SearchReport {
    /// Number of variants per status.
    pub fn count(&self, status: Status) -> usize {
        self.variants.iter().filter(|v| v.status == status).count()
    }

    /// Number of variants per status and class.
    pub fn count_class(&self, status: Status, class: Class) -> usize {
        self.variants
            .iter()
            .filter(|v| v.status == status && v.class == class)
            .count()
    }
}

/// Runs the search on the current rayon pool.
pub fn search(
    energy: &MechanismEnergy,
    catalogue: Catalogue,
    options: SearchOptions,
) -> SearchReport {
    let basis = LiftedBasis::build(energy, &catalogue);
    let checks = VerificationSet::new(energy);
    let sets: Vec<Vec<usize>> = variants(catalogue.len(), options.dmax).collect();
    let variants = sets
        .par_iter()
        .map(|set| decide(energy, &catalogue, &basis, &checks, set, options.hints))
        .collect();
    SearchReport {
        catalogue,
        variants,
    }
}

/// Decides one variant: linear consistency, degeneracy, realization, verification.
pub fn decide(
    energy: &MechanismEnergy,
    catalogue: &Catalogue,
    basis: &LiftedBasis,
    checks: &VerificationSet,
    set: &[usize],
    hints: RealizationHints,
) -> VariantResult {
    let solution = solve(basis, set);
    let entries: Vec<_> = set.iter().map(|&e| (e, &catalogue.entries[e])).collect();
    let elements = entries
        .iter()
        .map(|(e, entry)| element_ref(energy, *e, entry))
        .collect();
    let springs = entries
        .iter()
        .filter(|(_, e)| matches!(e.element, Element::Spring { .. }))
        .count();
    let class = match springs {
        0 => Class::Counterweights,
        n if n == entries.len() => Class::Springs,
        _ => Class::Hybrid,
    };
    let mut result = VariantResult {
        elements,
        class,
        status: Status::Infeasible,
        reason: None,
        rank: solution.rank,
        nullity: solution.nullspace.ncols(),
        linear_residual: solution.residual,
        redundant: Vec::new(),
        witness: None,
        verification: None,
        relations: Vec::new(),
        free_directions: Vec::new(),
    };
    if !solution.consistent {
        result.reason = Some(format!(
            "the balance equations have no solution (relative residual {:.2e})",
            solution.residual
        ));
        return result;
    }
    let b = &basis.unbalanced;
    let b_norm = b.norm();
    for (k, &(e, entry)) in entries.iter().enumerate() {
        if basis.elements[e].iter().all(|&v| v == 0.0) {
            result.redundant.push(entry.label.clone());
        } else if solution.contribution_forced_zero(k, b_norm) {
            result.status = Status::Degenerate;
            result.reason = Some(format!(
                "{} must contribute no energy: the variant is really a smaller one",
                entry.label
            ));
            return result;
        }
    }
    let names: Vec<String> = entries
        .iter()
        .flat_map(|(_, e)| e.variables.clone())
        .collect();
    let units: Vec<&str> = entries
        .iter()
        .flat_map(|(_, e)| variable_units(e))
        .collect();
    let positive: Vec<usize> = (0..entries.len()).map(|k| solution.offsets[k]).collect();
    result.relations = balance_relations(&solution, b, &names, &units);
    result.free_directions = free_directions(&solution, &names, &positive);

    match realize(&solution, b, &entries, hints) {
        Realization::Found(witness) => {
            let verification = checks.verify(&witness);
            if verification.passed {
                result.status = Status::Balanced;
            } else {
                result.status = Status::Undecided;
                result.reason = Some(format!(
                    "witness failed verification (relative energy spread {:.2e})",
                    verification.residual
                ));
            }
            result.witness = Some(witness);
            result.verification = Some(verification);
        }
        Realization::Impossible(reason) => {
            result.status = Status::Unrealizable;
            result.reason = Some(reason);
        }
        Realization::Degenerate(reason) => {
            result.status = Status::Degenerate;
            result.reason = Some(reason);
        }
        Realization::GaveUp(reason) => {
            result.status = Status::Undecided;
            result.reason = Some(reason);
        }
    }
    result
}

fn element_ref(
    energy: &MechanismEnergy,
    entry: usize,
    e: &crate::element::CatalogueEntry,
) -> ElementRef {
    let name = |i: usize| energy.bodies[i].name.clone();
    match &e.element {
        Element::Counterweight { body, .. } => ElementRef {
            entry,
            label: e.label.clone(),
            kind: "counterweight",
            bodies: vec![name(*body)],
        },
        Element::Spring { body, other, .. } => ElementRef {
            entry,
            label: e.label.clone(),
            kind: "spring",
            bodies: vec![
                name(*body),
                match other {
                    Attachment::Base => "base".to_string(),
                    Attachment::Body(s) => name(*s),
                },
            ],
        },
    }
}
