//! The whole balance search: enumerate variants, decide each one, realize and verify the
//! balanced ones. Parallel over variants with rayon; output order is the enumeration order, so
//! results do not depend on the number of threads.

use rayon::prelude::*;
use serde::Serialize;

use crate::element::{Attachment, Catalogue, CatalogueEntry, Element};
use crate::energy::MechanismEnergy;
use crate::enumerate::variants;
use crate::exact::anchors::fixed_anchor_equations;
use crate::exact::{ExactBasis, ExactField, ExactSolution, positivity, rank_one, split};
use crate::linear::{LiftedBasis, solve};
use crate::realize::{
    Realization, RealizationHints, Witness, find_witness, find_witness_on, realize,
};
use crate::relations::{
    AdmissibleRange, FreeDirection, admissible_ranges, balance_relations, exact_relations,
    free_directions, variable_units,
};
use crate::verify::{Verification, VerificationSet};
use counterpoise_symbolic::RefArith;

/// What the search concluded about a variant: the shared status (the search gives
/// [`Status::SEARCH_VERDICTS`]).
pub use counterpoise_vocabulary::Status;

/// Which arithmetic decided a variant.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Decision {
    /// Rational arithmetic: every linear fact is exact.
    Exact,
    /// Floating point with an explicit ambiguous zone (the case has an irrational constant).
    Numeric,
}

/// Counterweights only, springs only, or both (the paper's three classes), and what an
/// element is: the shared vocabulary.
pub use counterpoise_vocabulary::{Class, ElementKind};

/// One installed element of a variant, named for people.
#[derive(Clone, Debug, Serialize)]
pub struct ElementRef {
    /// Index in the catalogue.
    pub entry: usize,
    pub label: String,
    /// `counterweight` or `spring`.
    #[serde(rename = "type")]
    pub kind: ElementKind,
    /// Body names: one for a counterweight, two for a spring (`base` for the ground).
    pub bodies: Vec<String>,
}

/// Everything the search found about one variant.
#[derive(Clone, Debug, Serialize)]
pub struct VariantResult {
    pub elements: Vec<ElementRef>,
    pub class: Class,
    pub status: Status,
    /// Which arithmetic decided the variant.
    pub decision: Decision,
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
    /// Labels of elements whose energy contribution is zero in every balancing solution: with a
    /// positive mass or stiffness they can only idle.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub idle: Vec<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub witness: Option<Witness>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub verification: Option<Verification>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub relations: Vec<String>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub free_directions: Vec<FreeDirection>,
    /// Range of each mass, stiffness and first moment over the balanced family with every mass
    /// and stiffness positive (exact decision only).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub ranges: Vec<AdmissibleRange>,
}

impl VariantResult {
    /// A variant of these elements before the search has looked at it: `Infeasible` with no
    /// reason, rank, witness or relations; the search fills in what it finds.
    pub fn undecided(elements: Vec<ElementRef>, class: Class) -> VariantResult {
        VariantResult {
            elements,
            class,
            status: Status::Infeasible,
            decision: Decision::Numeric,
            reason: None,
            rank: 0,
            nullity: 0,
            linear_residual: 0.0,
            redundant: Vec::new(),
            idle: Vec::new(),
            witness: None,
            verification: None,
            relations: Vec::new(),
            free_directions: Vec::new(),
            ranges: Vec::new(),
        }
    }
}

/// Settings of a search.
#[derive(Clone, Copy, Debug)]
pub struct SearchOptions {
    pub dmax: usize,
    pub hints: RealizationHints,
}

/// The field a case's variants are decided in: the first of ℚ, ℚ(√2, √3) and floating point
/// that holds every constant of the case (the same for all its variants). A variant's
/// [`Decision`] only says exact or numeric; this says which exact field, so that output can name
/// it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Arithmetic {
    #[serde(rename = "Q")]
    Rational,
    #[serde(rename = "Q(sqrt2,sqrt3)")]
    Surd,
    #[serde(rename = "float")]
    Float,
}

impl Arithmetic {
    /// The field the search takes for this basis (the order of [`decide`]).
    pub fn of(basis: &LiftedBasis) -> Arithmetic {
        match (&basis.exact, &basis.surd) {
            (Some(_), _) => Arithmetic::Rational,
            (None, Some(_)) => Arithmetic::Surd,
            (None, None) => Arithmetic::Float,
        }
    }

    /// The field's name for people: `ℚ`, `ℚ(√2, √3)`, `floating point`.
    pub fn name(self) -> &'static str {
        match self {
            Arithmetic::Rational => "ℚ",
            Arithmetic::Surd => "ℚ(√2, √3)",
            Arithmetic::Float => "floating point",
        }
    }
}

/// The search's output: the catalogue, every variant in enumeration order, and the field they
/// were decided in.
#[derive(Clone, Debug)]
pub struct SearchReport {
    pub catalogue: Catalogue,
    pub variants: Vec<VariantResult>,
    pub arithmetic: Arithmetic,
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
        arithmetic: Arithmetic::of(&basis),
        catalogue,
        variants,
    }
}

/// Decides one variant: linear consistency, degeneracy, realizability, verification — exactly
/// when the case allows it, numerically otherwise.
pub fn decide(
    energy: &MechanismEnergy,
    catalogue: &Catalogue,
    basis: &LiftedBasis,
    checks: &VerificationSet,
    set: &[usize],
    hints: RealizationHints,
) -> VariantResult {
    let entries: Vec<_> = set.iter().map(|&e| (e, &catalogue.entries[e])).collect();
    let mut result = new_result(energy, &entries);
    // ℚ first, then ℚ(√2, √3), then floating point (the basis holds the first that applies).
    match (&basis.exact, &basis.surd) {
        (Some(exact), _) => decide_exact(basis, exact, checks, &entries, hints, &mut result),
        (None, Some(surd)) => decide_exact(basis, surd, checks, &entries, hints, &mut result),
        (None, None) => decide_numeric(basis, checks, &entries, hints, &mut result),
    }
    result
}

fn new_result(energy: &MechanismEnergy, entries: &[(usize, &CatalogueEntry)]) -> VariantResult {
    let springs = entries
        .iter()
        .filter(|(_, e)| matches!(e.element, Element::Spring { .. }))
        .count();
    let class = match springs {
        0 => Class::Counterweights,
        n if n == entries.len() => Class::Springs,
        _ => Class::Hybrid,
    };
    let elements = entries
        .iter()
        .map(|(e, entry)| element_ref(energy, *e, entry))
        .collect();
    VariantResult::undecided(elements, class)
}

fn names_and_units(entries: &[(usize, &CatalogueEntry)]) -> (Vec<String>, Vec<&'static str>) {
    let names = entries
        .iter()
        .flat_map(|(_, e)| e.variables.clone())
        .collect();
    let units = entries
        .iter()
        .flat_map(|(_, e)| variable_units(e))
        .collect();
    (names, units)
}

/// The exact path: every linear fact and every proof in exact arithmetic (over ℚ or
/// ℚ(√2, √3)); only the witness is found in floating point, and it is verified by sampling the
/// physical energy.
fn decide_exact<F: ExactField>(
    numeric: &LiftedBasis,
    exact: &ExactBasis<F>,
    checks: &VerificationSet,
    entries: &[(usize, &CatalogueEntry)],
    hints: RealizationHints,
    result: &mut VariantResult,
) where
    for<'a> &'a F: RefArith<F>,
{
    result.decision = Decision::Exact;
    let set: Vec<usize> = entries.iter().map(|(e, _)| *e).collect();
    let solution = exact.solve(&set);
    result.rank = solution.rank();
    if !solution.consistent() {
        // Only informative (the verdict is exact): the least-squares residual of one SVD, or
        // NaN (`null` in JSON) when no SVD of the system converges.
        result.linear_residual =
            crate::linear::least_squares_residual(numeric, &set).unwrap_or(f64::NAN);
        result.reason = Some(format!(
            "the balance equations have no solution (exact: rank {} of the element columns, \
             {} with the unbalanced energy)",
            solution.rank(),
            solution.rank() + 1
        ));
        return;
    }
    result.nullity = solution.nullity();
    for (k, &(e, entry)) in entries.iter().enumerate() {
        if exact.elements[e].iter().flatten().all(F::entry_is_zero) {
            result.redundant.push(entry.label.clone());
        } else if solution.contribution_forced_zero(exact, k) {
            result.idle.push(entry.label.clone());
        }
    }
    let (names, units) = names_and_units(entries);
    result.relations = exact_relations(&solution, &names, &units);
    let linear = crate::linear::from_exact(numeric, &solution);
    if let Err(e) = linear.ensure_finite() {
        // The exact family exists, but rounded to doubles it overflows: no witness search or
        // optimisation can work on it.
        result.status = Status::Undecided;
        result.reason = Some(format!(
            "the exact solution set cannot be used in floating point: {e}"
        ));
        return;
    }
    let positive: Vec<usize> = (0..entries.len()).map(|k| solution.offsets[k]).collect();
    result.free_directions = free_directions(&linear, &names, &positive);

    if let Some(reason) = exact_sign_proof(&solution, entries) {
        result.status = Status::Unrealizable;
        result.reason = Some(reason);
        return;
    }
    // The exact rank-one test is costly; a floating-point screen says when it is worth running
    // (the screen decides nothing: only the exact test can prove).
    let refs: Vec<&CatalogueEntry> = entries.iter().map(|(_, e)| *e).collect();
    let screened = crate::realize::rank_one_contradiction(&linear, entries).is_some();
    if screened && let Some(reason) = rank_one::contradiction(exact, &solution, &refs) {
        result.status = Status::Unrealizable;
        result.reason = Some(reason);
        return;
    }
    result.ranges = admissible_ranges(&solution, entries, &names, &units);
    // A verified witness settles it; the remaining proofs run only when none is found.
    let mut failed = None;
    let witness = match find_witness(&linear, &numeric.unbalanced, entries, hints) {
        Ok(witness) => {
            if try_witness(checks, witness, result, &mut failed) {
                return;
            }
            "the witness found failed verification".to_string()
        }
        Err(reason) => reason,
    };
    if !screened && let Some(reason) = rank_one::contradiction(exact, &solution, &refs) {
        result.status = Status::Unrealizable;
        result.reason = Some(reason);
        return;
    }
    // Springs whose anchor balance fixes: W = a₀ βᵀ (or α b₀ᵀ) is then linear; impose it.
    let (anchors, extra) = fixed_anchor_equations(&solution, entries);
    if !extra.is_empty() {
        let restricted = exact.solve_with(&set, &extra);
        let context = format!("with {} fixed by balance, ", anchors.join(" and "));
        if !restricted.consistent() {
            result.status = Status::Unrealizable;
            result.reason = Some(format!(
                "{context}no spring of that anchor satisfies the balance equations"
            ));
            return;
        }
        let proof = exact_sign_proof(&restricted, entries)
            .or_else(|| rank_one::contradiction(exact, &restricted, &refs));
        if let Some(reason) = proof {
            result.status = Status::Unrealizable;
            result.reason = Some(format!("{context}{reason}"));
            return;
        }
        let linear = crate::linear::from_exact(numeric, &restricted);
        if let Ok(witness) = find_witness(&linear, &numeric.unbalanced, entries, hints)
            && try_witness(checks, witness, result, &mut failed)
        {
            return;
        }
    }
    // Springs whose balance zeroes a block of W: split on which anchor part vanishes.
    let springs = refs
        .iter()
        .filter(|e| matches!(e.element, Element::Spring { .. }))
        .count();
    if springs > 0 {
        let sign_proof = |s: &ExactSolution<F>| exact_sign_proof(s, entries);
        match split::refute(exact, &set, entries, &[], springs, &sign_proof) {
            split::Outcome::Proof(reason) => {
                result.status = Status::Unrealizable;
                result.reason = Some(reason);
                return;
            }
            split::Outcome::Open(leaves) => {
                for rows in leaves.iter().filter(|rows| !rows.is_empty()).take(4) {
                    let restricted = exact.solve_with(&set, rows);
                    let linear = crate::linear::from_exact(numeric, &restricted);
                    if linear.ensure_finite().is_err() {
                        continue;
                    }
                    // The branch's anchor parts are zero: hold them there in the search.
                    let zero = unit_columns(rows);
                    let found =
                        find_witness_on(&linear, &numeric.unbalanced, entries, hints, &zero);
                    if let Ok(w) = found
                        && try_witness(checks, w, result, &mut failed)
                    {
                        return;
                    }
                }
            }
        }
    }
    // The same family in the SVD's basis, where floating point agrees with the exact facts: the
    // witness search starts from another point of it (any witness is verified all the same).
    let svd = crate::linear::numeric_solve(numeric, &set);
    if svd.ambiguity.is_none()
        && svd.consistent
        && svd.rank == solution.rank()
        && let Ok(w) = find_witness(&svd, &numeric.unbalanced, entries, hints)
        && try_witness(checks, w, result, &mut failed)
    {
        return;
    }
    if let Some((w, verification)) = failed {
        return record_witness(w, verification, result);
    }
    result.status = Status::Undecided;
    result.reason = Some(witness);
}

/// The variables that extra rows of the form `x_j = 0` (a split branch's) set to zero.
fn unit_columns<F: ExactField>(rows: &[Vec<F>]) -> Vec<usize>
where
    for<'a> &'a F: RefArith<F>,
{
    rows.iter()
        .filter_map(|row| {
            let mut nonzero = row.iter().enumerate().filter(|(_, v)| !v.is_zero());
            match (nonzero.next(), nonzero.next()) {
                (Some((j, _)), None) => Some(j),
                _ => None,
            }
        })
        .collect()
}

/// Proofs of unrealizability from signs, in exact arithmetic: a mass or stiffness fixed at zero
/// or below, or no positive point of the family (Farkas certificate).
fn exact_sign_proof<F: ExactField>(
    solution: &ExactSolution<F>,
    entries: &[(usize, &CatalogueEntry)],
) -> Option<String>
where
    for<'a> &'a F: RefArith<F>,
{
    for (k, (_, entry)) in entries.iter().enumerate() {
        let head = solution.offsets[k];
        if !solution.is_fixed(head) || solution.fixed_positive(head) {
            continue;
        }
        let value = &solution.particular[head];
        let (what, unit) = match entry.element {
            Element::Counterweight { .. } => ("mass", "kg"),
            Element::Spring { .. } => ("stiffness", "N/m"),
        };
        return Some(if value.is_zero() {
            format!("{}: balance forces its {what} to zero", entry.label)
        } else {
            format!(
                "{}: balance forces its {what} to {} {unit}",
                entry.label,
                crate::exact::exact_text(value)
            )
        });
    }
    let heads = solution.heads();
    if let Err(certificate) = positivity::strictly_feasible(&heads) {
        let terms: Vec<String> = certificate
            .multipliers
            .iter()
            .zip(entries)
            .filter(|(m, _)| !m.is_zero())
            .map(|(m, (_, entry))| {
                if *m == F::one() {
                    entry.label.clone()
                } else {
                    format!("{}·{}", crate::exact::exact_text(m), entry.label)
                }
            })
            .collect();
        return Some(format!(
            "no positive masses and stiffnesses balance it: every solution has {} = {} ≤ 0",
            terms.join(" + "),
            crate::exact::exact_text(&certificate.value)
        ));
    }
    None
}

/// Verifies a witness by sampling the physical energy; balanced (or degenerate, when some
/// element can only idle) if it passes, undecided if not.
fn accept_witness(checks: &VerificationSet, witness: Witness, result: &mut VariantResult) {
    let verification = checks.verify(&witness);
    record_witness(witness, verification, result);
}

/// The verdict a verified (or failed) witness gives.
fn record_witness(witness: Witness, verification: Verification, result: &mut VariantResult) {
    if verification.passed {
        if result.idle.is_empty() {
            result.status = Status::Balanced;
        } else {
            result.status = Status::Degenerate;
            result.reason = Some(format!(
                "{} can only idle: {} no energy in any balancing solution, so the variant is \
                 really a smaller one",
                result.idle.join(", "),
                if result.idle.len() == 1 {
                    "it contributes"
                } else {
                    "they contribute"
                }
            ));
        }
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

/// Accepts `witness` when it passes verification (`true`). A witness that fails is kept in
/// `failed` (the first one) and the search goes on: another route may find one that passes,
/// or a proof; only if neither turns up is the failed one the variant's (undecided) answer.
fn try_witness(
    checks: &VerificationSet,
    witness: Witness,
    result: &mut VariantResult,
    failed: &mut Option<(Witness, Verification)>,
) -> bool {
    let verification = checks.verify(&witness);
    if verification.passed {
        record_witness(witness, verification, result);
        true
    } else {
        failed.get_or_insert((witness, verification));
        false
    }
}

/// The numeric path, for cases with irrational constants: floating-point consistency and
/// proofs.
fn decide_numeric(
    basis: &LiftedBasis,
    checks: &VerificationSet,
    entries: &[(usize, &CatalogueEntry)],
    hints: RealizationHints,
    result: &mut VariantResult,
) {
    let set: Vec<usize> = entries.iter().map(|(e, _)| *e).collect();
    let solution = solve(basis, &set);
    result.rank = solution.rank;
    result.nullity = solution.nullspace.ncols();
    result.linear_residual = solution.residual;
    if let Some(ambiguity) = &solution.ambiguity {
        result.status = Status::Undecided;
        result.reason = Some(format!("numerically ambiguous: {ambiguity}"));
        return;
    }
    if !solution.consistent {
        result.reason = Some(format!(
            "the balance equations have no solution (relative residual {:.2e})",
            solution.residual
        ));
        return;
    }
    let b = &basis.unbalanced;
    let b_norm = b.norm();
    for (k, &(e, entry)) in entries.iter().enumerate() {
        if basis.elements[e].iter().all(|&v| v == 0.0) {
            result.redundant.push(entry.label.clone());
        } else if solution.contribution_forced_zero(k, b_norm) {
            result.idle.push(entry.label.clone());
        }
    }
    let (names, units) = names_and_units(entries);
    let positive: Vec<usize> = (0..entries.len()).map(|k| solution.offsets[k]).collect();
    result.relations = balance_relations(&solution, b, &names, &units);
    result.free_directions = free_directions(&solution, &names, &positive);

    match realize(&solution, b, entries, hints) {
        Realization::Found(witness) => accept_witness(checks, witness, result),
        Realization::Impossible(reason) => {
            result.status = Status::Unrealizable;
            result.reason = Some(reason);
        }
        Realization::GaveUp(reason) => {
            result.status = Status::Undecided;
            result.reason = Some(reason);
        }
    }
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
            kind: ElementKind::Counterweight,
            bodies: vec![name(*body)],
        },
        Element::Spring { body, other, .. } => ElementRef {
            entry,
            label: e.label.clone(),
            kind: ElementKind::Spring,
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::realize::Counterweight;
    use counterpoise_symbolic::{PolyMat3, PolyVec3, TrigPoly, VarKind};

    /// A rod of mass 2 kg with its centre 0.5 m out, hinged about z under gravity −y:
    /// `V = 2·9.81·0.5·sin θ`; one counterweight on it.
    fn rod() -> MechanismEnergy {
        let rotation = PolyMat3::rot_z(&counterpoise_symbolic::LinearAngle::coordinate(0));
        MechanismEnergy {
            kinds: vec![VarKind::Angle],
            ranges: vec![(-3.0, 3.0)],
            gravity: [0.0, -9.81, 0.0],
            bodies: vec![crate::energy::BodyFrame {
                name: "rod".into(),
                rotation,
                origin: PolyVec3::zero(),
            }],
            unbalanced: TrigPoly::sin(0).scale(9.81),
            exact: Err("built by hand".into()),
            surd: Err("built by hand".into()),
        }
    }

    fn fresh(energy: &MechanismEnergy) -> VariantResult {
        let catalogue = Catalogue::build(
            energy,
            &crate::element::CatalogueOptions {
                counterweight_bodies: vec![0],
                counterweight_plane: Some(crate::Plane::Xy),
                ..Default::default()
            },
        );
        new_result(energy, &[(0, &catalogue.entries[0])])
    }

    /// The names people read are the ones the JSON output carries (serde's lowercase renaming,
    /// a second spelling of each name that does not go through `name`).
    #[test]
    fn status_and_class_names_are_the_serialized_ones() {
        let serialized = |v: serde_json::Value| v.as_str().unwrap().to_string();
        let statuses: Vec<String> = Status::SEARCH_VERDICTS
            .iter()
            .map(|s| serialized(serde_json::to_value(s).unwrap()))
            .collect();
        assert_eq!(
            statuses,
            [
                "balanced",
                "degenerate",
                "unrealizable",
                "infeasible",
                "undecided"
            ]
        );
        for (status, name) in Status::SEARCH_VERDICTS.iter().zip(&statuses) {
            assert_eq!(status.name(), name);
        }
        for (class, name) in [
            (Class::Counterweights, "counterweights"),
            (Class::Springs, "springs"),
            (Class::Hybrid, "hybrid"),
        ] {
            assert_eq!(serialized(serde_json::to_value(class).unwrap()), name);
            assert_eq!(class.name(), name);
        }
    }

    /// A spring's variables `(K, αx, αy, βx, βy, Wxx, Wxy, Wyx, Wyy)` with the hand-written
    /// balance equations `βx = 2·K`, `βy = 0`: its anchor `b = β/K = (2, 0)` is fixed, `α` is free.
    /// A physical spring then has `W = α·b₀ᵀ`, i.e. `Wxx − 2αx = 0`, `Wxy = 0`, `Wyx − 2αy = 0`,
    /// `Wyy = 0`.
    #[test]
    fn a_fixed_second_anchor_gives_the_hand_written_rows() {
        use crate::exact::ExactBasis;
        use counterpoise_symbolic::{Monomial, Rational};
        let int = |v: &[i64]| -> Vec<num_bigint::BigInt> { v.iter().map(|&x| x.into()).collect() };
        let q = |n: i64| Rational::from_integer(n.into());
        // Rows: −2K + βx = 0 and βy = 0; the other seven variables appear in no equation.
        let mut columns = vec![int(&[0, 0]); 9];
        columns[0] = int(&[-2, 0]);
        columns[3] = int(&[1, 0]);
        columns[4] = int(&[0, 1]);
        let basis = ExactBasis {
            monomials: vec![Monomial::sine(0), Monomial::sine(1)],
            unbalanced: int(&[0, 0]),
            elements: vec![columns],
            row_factors: vec![q(1), q(1)],
        };
        let solution = basis.solve(&[0]);
        let entry = CatalogueEntry {
            element: Element::Spring {
                body: 0,
                other: Attachment::Base,
                axes_a: vec![0, 1],
                axes_b: vec![0, 1],
            },
            label: "K1".into(),
            description: "a spring".into(),
            bodies: vec!["rod".into(), "base".into()],
            variables: Vec::new(),
            energy: Vec::new(),
        };
        let (anchors, rows) = fixed_anchor_equations(&solution, &[(0, &entry)]);
        assert_eq!(anchors, vec!["K1's anchor b = (2, 0)".to_string()]);
        let row = |terms: &[(usize, i64)]| {
            let mut r = vec![q(0); 9];
            for &(j, c) in terms {
                r[j] = q(c);
            }
            r
        };
        assert_eq!(
            rows,
            vec![
                row(&[(5, 1), (1, -2)]),
                row(&[(6, 1)]),
                row(&[(7, 1), (2, -2)]),
                row(&[(8, 1)]),
            ]
        );
        // The same with one axis per anchor, variables (K, αx, βx, Wxx) and βx = 3·K: b = (3),
        // and the one row Wxx − 3αx = 0.
        let mut columns = vec![int(&[0]); 4];
        columns[0] = int(&[-3]);
        columns[2] = int(&[1]);
        let basis = ExactBasis {
            monomials: vec![Monomial::sine(0)],
            unbalanced: int(&[0]),
            elements: vec![columns],
            row_factors: vec![q(1)],
        };
        let entry = CatalogueEntry {
            element: Element::Spring {
                body: 0,
                other: Attachment::Base,
                axes_a: vec![0],
                axes_b: vec![0],
            },
            ..entry
        };
        let (anchors, rows) = fixed_anchor_equations(&basis.solve(&[0]), &[(0, &entry)]);
        assert_eq!(anchors, vec!["K1's anchor b = (3)".to_string()]);
        assert_eq!(rows, vec![vec![q(0), q(-3), q(0), q(1)]]);
    }

    /// A spring's variables `(K, αx, αy, βx, βy, Wxx, Wxy, Wyx, Wyy)` with the hand-written
    /// balance equations `αx = 0` and `K + Wxx = 0`: the lifted family has positive stiffnesses
    /// (`K = −Wxx` for any `Wxx < 0`) and neither anchor is fixed whole, but `K·ax = 0` with
    /// `K > 0` means `ax = 0`, so a physical spring has the row `Wx· = ax·β = 0`: `Wxx = 0`,
    /// `Wxy = 0`. Then `K = −Wxx = 0`: no spring balances it (the proof the arm6 set m5 + K30
    /// needs, where `K30·az = 0` and the mass of m5 hangs on `K30·az·bz`).
    #[test]
    fn a_zero_anchor_component_zeroes_its_row_of_w() {
        use crate::exact::ExactBasis;
        use counterpoise_symbolic::{Monomial, Rational};
        let int = |v: &[i64]| -> Vec<num_bigint::BigInt> { v.iter().map(|&x| x.into()).collect() };
        let q = |n: i64| Rational::from_integer(n.into());
        let mut columns = vec![int(&[0, 0]); 9];
        columns[1] = int(&[1, 0]);
        columns[0] = int(&[0, 1]);
        columns[5] = int(&[0, 1]);
        let basis = ExactBasis {
            monomials: vec![Monomial::sine(0), Monomial::sine(1)],
            unbalanced: int(&[0, 0]),
            elements: vec![columns],
            row_factors: vec![q(1), q(1)],
        };
        let solution = basis.solve(&[0]);
        let entry = CatalogueEntry {
            element: Element::Spring {
                body: 0,
                other: Attachment::Base,
                axes_a: vec![0, 1],
                axes_b: vec![0, 1],
            },
            label: "K1".into(),
            description: "a spring".into(),
            bodies: vec!["rod".into(), "base".into()],
            variables: Vec::new(),
            energy: Vec::new(),
        };
        let entries = [(0, &entry)];
        // The family alone proves nothing: K = −Wxx is positive where Wxx < 0.
        assert!(exact_sign_proof(&solution, &entries).is_none());
        let (anchors, rows) = fixed_anchor_equations(&solution, &entries);
        assert_eq!(
            anchors,
            vec!["K1's anchor components a = (0, free) and b = (free, free)".to_string()]
        );
        let unit = |j: usize| {
            let mut r = vec![q(0); 9];
            r[j] = q(1);
            r
        };
        // Row x of W: Wxx − 0·βx and Wxy − 0·βy.
        assert_eq!(rows, vec![unit(5), unit(6)]);
        let restricted = basis.solve_with(&[0], &rows);
        assert!(restricted.consistent());
        let proof =
            exact_sign_proof(&restricted, &entries).expect("K = 0 on the restricted family");
        assert!(proof.contains("K1"), "{proof}");
    }

    /// A spring whose balance equations fix `α = (2, 1)`, `β = (3, 2)`, `Wxx = Wyy = 1` and leave
    /// `K`, `Wxy`, `Wyx` free. By hand, `K·W = α·βᵀ` needs `K = 2·3/1 = 6` from `xx` and
    /// `K = 1·2/1 = 2` from `yy`: no spring exists. Each row alone has a positive root, so the
    /// floating-point screen lets it pass; the exact rank-one test, run once no witness is found,
    /// proves it unrealizable.
    #[test]
    fn a_rank_one_contradiction_the_screen_misses_is_still_proven() {
        use crate::exact::ExactBasis;
        use counterpoise_symbolic::{Monomial, Rational};
        use nalgebra::{DMatrix, DVector};
        // Row r fixes variable fixed[r] to value[r]: coefficient 1, unbalanced −value.
        let fixed = [1usize, 2, 3, 4, 5, 8];
        let value = [2i64, 1, 3, 2, 1, 1];
        let rows = fixed.len();
        let exact = ExactBasis {
            monomials: (0..rows).map(Monomial::sine).collect(),
            unbalanced: value.iter().map(|&v| (-v).into()).collect(),
            elements: vec![
                (0..9)
                    .map(|j| (0..rows).map(|r| i64::from(fixed[r] == j).into()).collect())
                    .collect(),
            ],
            row_factors: vec![Rational::from_integer(1.into()); rows],
        };
        let basis = LiftedBasis {
            monomials: exact.monomials.clone(),
            unbalanced: DVector::from_iterator(rows, value.iter().map(|&v| -v as f64)),
            elements: vec![DMatrix::from_fn(rows, 9, |r, j| f64::from(fixed[r] == j))],
            exact: Some(exact),
            surd: None,
        };
        let names = ["K1", "K1·ax", "K1·ay", "K1·bx", "K1·by"]
            .into_iter()
            .map(String::from)
            .chain(["xx", "xy", "yx", "yy"].map(|ij| format!("K1·a{}·b{}", &ij[..1], &ij[1..])))
            .collect();
        let catalogue = Catalogue {
            entries: vec![CatalogueEntry {
                element: Element::Spring {
                    body: 0,
                    other: Attachment::Base,
                    axes_a: vec![0, 1],
                    axes_b: vec![0, 1],
                },
                label: "K1".into(),
                description: "spring rod–base".into(),
                bodies: vec!["rod".into(), "base".into()],
                variables: names,
                energy: Vec::new(),
            }],
        };
        let energy = rod();
        let checks = VerificationSet::new(&energy);
        let hints = RealizationHints::default();
        let linear = crate::linear::from_exact(&basis, &basis.exact.as_ref().unwrap().solve(&[0]));
        let entries = [(0, &catalogue.entries[0])];
        assert!(crate::realize::rank_one_contradiction(&linear, &entries).is_none());
        let result = decide(&energy, &catalogue, &basis, &checks, &[0], hints);
        assert_eq!(result.decision, Decision::Exact);
        assert_eq!((result.rank, result.nullity), (6, 3));
        assert_eq!(result.status, Status::Unrealizable, "{:?}", result.reason);
        assert_eq!(
            result.reason.as_deref(),
            Some("K1: balance would need the stiffness to be both 6 and 2 N/m")
        );
    }

    #[test]
    fn a_witness_that_fails_verification_is_undecided_not_balanced() {
        let energy = rod();
        let checks = VerificationSet::new(&energy);
        // m·r = −1 kg·m along x balances the rod; −0.9 leaves 10 % of the energy swing.
        for (moment, status) in [(-1.0, Status::Balanced), (-0.9, Status::Undecided)] {
            let mut result = fresh(&energy);
            let witness = Witness {
                counterweights: vec![Counterweight {
                    label: "m1".into(),
                    body: "rod".into(),
                    mass: 2.0,
                    offset: [moment / 2.0, 0.0, 0.0],
                    plane: None,
                }],
                springs: Vec::new(),
            };
            accept_witness(&checks, witness, &mut result);
            assert_eq!(result.status, status, "{moment}");
            assert!(result.verification.is_some());
            if status == Status::Undecided {
                // The spread is 0.1 of the unbalanced one.
                let residual = result.verification.unwrap().residual;
                assert!((residual - 0.1).abs() < 1e-9, "{residual}");
                assert!(result.reason.unwrap().contains("failed verification"));
            }
        }
    }

    #[test]
    fn an_idle_element_makes_a_verified_variant_degenerate() {
        let energy = rod();
        let checks = VerificationSet::new(&energy);
        let mut result = fresh(&energy);
        result.idle.push("m1".into());
        let witness = Witness {
            counterweights: vec![Counterweight {
                label: "m1".into(),
                body: "rod".into(),
                mass: 2.0,
                offset: [-0.5, 0.0, 0.0],
                plane: None,
            }],
            springs: Vec::new(),
        };
        accept_witness(&checks, witness, &mut result);
        assert_eq!(result.status, Status::Degenerate);
        assert!(result.reason.unwrap().starts_with("m1 can only idle"));
    }
}
