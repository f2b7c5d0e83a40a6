//! What `run` adds when no variant is feasible (issue 27): how many elements the mechanism needs
//! to balance at all, and the best it gets from the elements it was given — the partial
//! balancing of [`super::compute`] with the study's Dmax as the budget, every actuator's torque
//! minimised. The results go to `partial.json` and `partial.csv` beside `results.json`, a note in
//! `results.json`'s metadata, a block in the terminal summary, and the reports' partial-balancing
//! section ([`counterpoise_report::partial`], given the same numbers as plain data).

use std::fmt::Write as _;

use crate::error::Result;
use counterpoise_balance::exact::ExactField;
use counterpoise_balance::linear::LiftedBasis;
use counterpoise_balance::minimal::minimal_sets;
use counterpoise_balance::partial::counterweight_entries;
use counterpoise_balance::search::decide;
use counterpoise_balance::{
    Catalogue, SearchReport, Status, VariantResult, VerificationSet, catalogue_options,
    mechanism_energy, realization_hints,
};
use counterpoise_model::Model;
use counterpoise_report::{PartialBalancing, PartialDesign, PartialElement};
use counterpoise_symbolic::Rational;
use rayon::prelude::*;
use serde_json::json;

use super::{Computed, change, compute, design_line, set_guard};

/// How far past the study's Dmax the search for the smallest Dmax at which a variant balances
/// looks: two more elements (the 6-axis arm of `cases/arm6.json` needs one more than its
/// Dmax 2), each size within the `--minimal` guard.
pub const PROBE_BEYOND: usize = 2;

/// Most sets decided in full (witness search or proof) past the study's Dmax when looking for
/// the smallest Dmax. The statement needs one balanced example, not every one: the search stops
/// at the first, and this budget bounds the cost when the first comes late or never (about
/// 50 ms per set on the arm; `variants CASE --minimal` decides them all).
pub const DECISION_BUDGET: usize = 1_000;

/// Most candidate sets of one size collected from the minimal sets (a bound on memory: the
/// supersets of many small minimal sets grow as C(n, d)). Past it, the first candidates in the
/// walk's order are kept and the statement says so.
pub const CANDIDATE_CAP: usize = 200_000;

/// Sets decided together, in parallel. Fixed, so that the sets decided and the example found
/// (the first balanced set in lexicographic order) are the same for every thread count.
const CHUNK: usize = 8;

/// File names beside `results.json`.
pub const PARTIAL_JSON: &str = "partial.json";
pub const PARTIAL_CSV: &str = "partial.csv";

/// Designs shown per number of elements in the summary and the note.
pub const SHOWN_PER_SIZE: usize = 1;

/// `partial.json`, `partial.csv`, the note and the terminal block.
pub struct Fallback {
    /// One paragraph for `results.json`'s `metadata.notes` (shown by the reports).
    pub note: String,
    /// The block printed after the run's summary.
    pub text: String,
    pub json: serde_json::Value,
    pub csv: String,
    /// The reports' partial-balancing section (the same numbers as `json`).
    pub section: PartialBalancing,
}

/// The smallest Dmax at which a variant balances, as far as it was looked for.
struct Smallest {
    /// The sentence for the note and the terminal.
    sentence: String,
    json: serde_json::Value,
}

/// `1 element`, `2 elements`.
fn plural(n: usize, word: &str) -> String {
    if n == 1 {
        format!("1 {word}")
    } else {
        format!("{n} {word}s")
    }
}

fn labels(v: &VariantResult) -> String {
    v.elements
        .iter()
        .map(|e| e.label.as_str())
        .collect::<Vec<_>>()
        .join(" + ")
}

/// What the probe of one size found.
enum Probe {
    /// The first balanced set in lexicographic order.
    Balanced(Box<VariantResult>),
    /// None of the candidates balances (`undecided` of them undecided).
    None { undecided: usize },
    /// The decision budget ran out before every candidate was decided.
    Budget { candidates: usize, capped: bool },
}

/// The sets of exactly `size` elements whose balance equations are solvable: by monotonicity,
/// the minimal sets of that size and the supersets of the smaller ones. Sets with an element
/// whose energy is identically constant are left out: such an element changes nothing, so the
/// set balances only if the set without it does, and every smaller set was already decided
/// without a balanced one. Sorted (lexicographic order of the sorted entries); `true` when
/// [`CANDIDATE_CAP`] cut the list.
fn candidates(minimal: &[Vec<usize>], constant: &[bool], size: usize) -> (Vec<Vec<usize>>, bool) {
    let mut sets = std::collections::BTreeSet::new();
    for m in minimal.iter().filter(|m| m.len() <= size) {
        let rest: Vec<usize> = (0..constant.len())
            .filter(|e| !constant[*e] && !m.contains(e))
            .collect();
        let k = size - m.len();
        if k > rest.len() {
            continue;
        }
        // The k-combinations of `rest` in lexicographic order, as index vectors.
        let mut pick: Vec<usize> = (0..k).collect();
        loop {
            let mut s = m.clone();
            s.extend(pick.iter().map(|&i| rest[i]));
            s.sort_unstable();
            sets.insert(s);
            if sets.len() >= CANDIDATE_CAP {
                return (sets.into_iter().collect(), true);
            }
            let Some(i) = (0..k).rev().find(|&i| pick[i] < rest.len() - k + i) else {
                break;
            };
            pick[i] += 1;
            for j in i + 1..k {
                pick[j] = pick[j - 1] + 1;
            }
        }
    }
    (sets.into_iter().collect(), false)
}

/// Decides `sets` in order, [`CHUNK`] at a time, until the first balanced one or the budget
/// (`left`, decremented by each decision) runs out.
fn probe(
    sets: &[Vec<usize>],
    capped: bool,
    left: &mut usize,
    decide: &(dyn Fn(&[usize]) -> VariantResult + Sync),
) -> Probe {
    let mut undecided = 0;
    for chunk in sets.chunks(CHUNK) {
        if *left == 0 {
            return Probe::Budget {
                candidates: sets.len(),
                capped,
            };
        }
        let chunk = &chunk[..chunk.len().min(*left)];
        *left -= chunk.len();
        let results: Vec<VariantResult> = chunk.par_iter().map(|s| decide(s)).collect();
        for v in results {
            match v.status {
                Status::Balanced => return Probe::Balanced(Box::new(v)),
                Status::Undecided => undecided += 1,
                _ => {}
            }
        }
    }
    if capped {
        return Probe::Budget {
            candidates: sets.len(),
            capped,
        };
    }
    Probe::None { undecided }
}

/// From the study's own search when something balances within its Dmax (then the bounds or the
/// peak limits are what excluded it); otherwise size by size past the study's Dmax, up to
/// Dmax + [`PROBE_BEYOND`] (an exact case only): the minimal-set walk to that size, then the
/// solvable sets of that size decided in lexicographic order until the first that balances
/// with verified parameters. The study's search decided every set up to its Dmax, and each
/// size is searched to the end before the next, so the first size with a balanced set is the
/// smallest Dmax.
fn smallest(model: &Model, dmax: usize, found: &SearchReport) -> Smallest {
    let within = plural(dmax, "element");
    let realizable: Vec<&VariantResult> = found
        .variants
        .iter()
        .filter(|v| matches!(v.status, Status::Balanced | Status::Degenerate))
        .collect();
    if let Some(size) = realizable.iter().map(|v| v.elements.len()).min() {
        let first = realizable.iter().find(|v| v.elements.len() == size);
        return Smallest {
            sentence: format!(
                "{} of at most {} balance exactly, the smallest with {} (e.g. {}), but none is \
                 feasible within the bounds and peak limits",
                plural(realizable.len(), "variant"),
                plural(dmax, "element"),
                plural(size, "element"),
                first.map_or(String::new(), |v| labels(v))
            ),
            json: json!({ "searched_to": dmax, "smallest_balanced": size, "source": "run" }),
        };
    }
    let not_looked = |why: &str| Smallest {
        sentence: format!("no variant of at most {within} balances; {why}"),
        json: json!({ "searched_to": dmax, "smallest_balanced": null, "source": "run" }),
    };
    let energy = mechanism_energy(model);
    let catalogue = Catalogue::build(&energy, &catalogue_options(model));
    let basis = LiftedBasis::build(&energy, &catalogue);
    let Some(exact) = &basis.exact else {
        return not_looked(
            "the smallest Dmax that does was not looked for (the minimal-set walk needs an \
             exact case)",
        );
    };
    let checks = VerificationSet::new(&energy);
    let hints = realization_hints(model);
    let decide_set = |set: &[usize]| decide(&energy, &catalogue, &basis, &checks, set, hints);
    let constant: Vec<bool> = exact
        .elements
        .iter()
        .map(|columns| columns.iter().flatten().all(Rational::entry_is_zero))
        .collect();
    let mut left = DECISION_BUDGET;
    let mut smallest_linear = None;
    let mut undecided = 0;
    let mut searched_to = dmax;
    for size in dmax + 1..=dmax + PROBE_BEYOND {
        if crate::variants::minimal_guard(exact, size, "--dmax").is_err() {
            break;
        }
        let walk = minimal_sets(exact, size);
        smallest_linear = walk.minimal.iter().map(Vec::len).min();
        let (sets, capped) = candidates(&walk.minimal, &constant, size);
        let outcome = probe(&sets, capped, &mut left, &decide_set);
        let decided = DECISION_BUDGET - left;
        match outcome {
            Probe::Balanced(v) => {
                let names: Vec<&str> = v.elements.iter().map(|e| e.label.as_str()).collect();
                return Smallest {
                    sentence: format!(
                        "no variant of at most {within} balances; the smallest Dmax at which one \
                         does is {size}, e.g. {} (`variants CASE --minimal --dmax {size}` lists \
                         every one)",
                        labels(&v)
                    ),
                    json: json!({
                        "searched_to": size,
                        "smallest_linear": smallest_linear,
                        "smallest_balanced": size,
                        "example": names,
                        "decided": decided,
                        "undecided": undecided,
                        "note": null,
                        "source": "variants --minimal",
                    }),
                };
            }
            Probe::Budget { candidates, capped } => {
                let note = format!(
                    "the budget of {DECISION_BUDGET} decisions past Dmax {dmax} ran out among \
                     the {}{} sets of {} whose balance equations are solvable, none of those \
                     decided balancing",
                    if capped { "first " } else { "" },
                    candidates,
                    plural(size, "element")
                );
                return Smallest {
                    sentence: format!(
                        "no variant of at most {} balances; the smallest Dmax at which one does \
                         is at least {size} ({note}; `variants CASE --minimal --dmax {size}` \
                         decides them all)",
                        plural(size - 1, "element"),
                    ),
                    json: json!({
                        "searched_to": size,
                        "smallest_linear": smallest_linear,
                        "smallest_balanced": null,
                        "at_least": size,
                        "example": null,
                        "decided": decided,
                        "undecided": undecided,
                        "note": note,
                        "source": "variants --minimal",
                    }),
                };
            }
            Probe::None { undecided: u } => undecided += u,
        }
        searched_to = size;
    }
    if searched_to == dmax {
        return not_looked(
            "a deeper search is past the limits (`variants CASE --minimal --dmax N`)",
        );
    }
    Smallest {
        sentence: format!(
            "no variant of at most {} balances (minimal-set walk to Dmax {searched_to}{}{})",
            plural(searched_to, "element"),
            smallest_linear.map_or(String::new(), |d| format!(
                "; the balance equations are solvable from {d} elements, not realizably"
            )),
            if undecided > 0 {
                format!("; {undecided} sets undecided")
            } else {
                String::new()
            }
        ),
        json: json!({
            "searched_to": searched_to,
            "smallest_linear": smallest_linear,
            "smallest_balanced": null,
            "example": null,
            "decided": DECISION_BUDGET - left,
            "undecided": undecided,
            "note": null,
            "source": "variants --minimal",
        }),
    }
}

/// The fallback of a study at `dmax` whose search found `found` and whose ranking has no
/// feasible variant. The partial search is skipped, with the reason in the note, when the case
/// allows no counterweight or the sets pass the variant limit.
pub fn fallback(model: &Model, dmax: usize, found: &SearchReport) -> Result<Fallback> {
    let smallest = smallest(model, dmax, found);
    let catalogue = &found.catalogue;
    let skipped = if counterweight_entries(catalogue).is_empty() {
        Some(
            "`balancing` allows no counterweight (partial balancing covers counterweights only)"
                .to_string(),
        )
    } else {
        set_guard(catalogue, dmax).err().map(|e| e.to_string())
    };
    let computed = match skipped {
        Some(reason) => Err(reason),
        None => compute(
            model,
            dmax,
            (0..model.actuators.len()).collect(),
            None,
            SHOWN_PER_SIZE,
        )
        .map_err(|e| format!("{e:#}")),
    };
    let mut json = match &computed {
        Ok(c) => super::to_json(model, c),
        Err(reason) => {
            json!({ "schema_version": super::SCHEMA_VERSION, "case": model.name, "skipped": reason })
        }
    };
    json["smallest_dmax"] = smallest.json;
    let first = format!("No feasible variant at Dmax {dmax}: {}.", smallest.sentence);
    let mut note = first.clone();
    let wrap = |t: &str| counterpoise_report::text::wrap(t, counterpoise_report::text::WIDTH);
    let mut text = format!("\n{}", wrap(&first));
    match &computed {
        Ok(c) => {
            let (head, lines) = best_lines(model, c);
            let _ = write!(
                note,
                " {head}: {}; every set in partial.json and partial.csv.",
                lines.join("; ")
            );
            text.push_str(&wrap(&format!(
                "{head} (every set in partial.json, partial.csv):"
            )));
            for line in &lines {
                // Each design indented, its continuation lines further.
                let wrapped =
                    counterpoise_report::text::wrap(line, counterpoise_report::text::WIDTH - 6);
                for (k, l) in wrapped.lines().enumerate() {
                    let _ = writeln!(text, "{}{l}", if k == 0 { "  " } else { "      " });
                }
            }
            text.push_str(&wrap(
                "`counterpoise partial CASE --joints A,B --budget N` minimises the joints that \
                 matter with another budget.",
            ));
        }
        Err(reason) => {
            let _ = write!(note, " Partial balancing not computed: {reason}.");
            text.push_str(&wrap(&format!("Partial balancing not computed: {reason}.")));
        }
    }
    let csv = computed
        .as_ref()
        .map_or_else(|_| String::new(), |c| csv(model, c));
    let section = section(model, first, &computed);
    Ok(Fallback {
        note,
        text,
        json,
        csv,
        section,
    })
}

/// The reports' section: the statement and partial.json's designs as plain numbers.
fn section(
    model: &Model,
    statement: String,
    computed: &Result<Computed, String>,
) -> PartialBalancing {
    let actuators: Vec<String> = model.actuators.iter().map(|a| a.name.clone()).collect();
    let mut section = PartialBalancing {
        smallest_dmax: statement,
        skipped: None,
        budget: 0,
        points: 0,
        actuators: actuators.clone(),
        minimised: Vec::new(),
        unbalanced_rms: Vec::new(),
        unbalanced_total: 0.0,
        sets: 0,
        designs: Vec::new(),
    };
    let c = match computed {
        Ok(c) => c,
        Err(reason) => {
            section.skipped = Some(reason.clone());
            return section;
        }
    };
    let r = &c.report;
    section.budget = r.budget;
    section.points = r.points;
    section.minimised = r.joints.iter().map(|&j| actuators[j].clone()).collect();
    section.unbalanced_rms = r.unbalanced_rms.clone();
    section.unbalanced_total = r.unbalanced_total;
    section.sets = r.sets;
    section.designs = r
        .designs
        .iter()
        .enumerate()
        .map(|(i, d)| PartialDesign {
            rank: i + 1,
            elements: d
                .counterweights
                .iter()
                .map(|cw| PartialElement {
                    unused: d.unused.contains(&cw.label),
                    counterweight: cw.clone(),
                })
                .collect(),
            total_rms: d.total_rms,
            rms: d.rms.clone(),
            exact: c
                .shown
                .iter()
                .zip(&c.verdicts)
                .find(|(s, _)| **s == i)
                .map(|(_, v)| v.name().to_string()),
        })
        .collect();
    section
}

/// The heading and one line per shown design: set, total change, the change of each actuator
/// the design changes, and the design.
fn best_lines(model: &Model, c: &Computed) -> (String, Vec<String>) {
    let r = &c.report;
    let head = format!(
        "Best partial balancing with at most {}, RMS gravity torque of every actuator over {} \
         workspace points (unbalanced total {:.3})",
        plural(r.budget, "counterweight"),
        r.points,
        r.unbalanced_total
    );
    let lines = c
        .shown
        .iter()
        .map(|&i| {
            let d = &r.designs[i];
            let per_joint: Vec<String> = model
                .actuators
                .iter()
                .zip(d.rms.iter().zip(&r.unbalanced_rms))
                .filter(|(_, (v, u))| (*v - *u).abs() > 1e-9 * u.abs().max(1e-12))
                .map(|(a, (v, u))| format!("{} {:+.1} %", a.name, change(*v, *u)))
                .collect();
            format!(
                "{}: total {:.3} ({:+.1} %; {}) with {}",
                d.labels.join(" + "),
                d.total_rms,
                change(d.total_rms, r.unbalanced_total),
                if per_joint.is_empty() {
                    "no joint changes".into()
                } else {
                    per_joint.join(", ")
                },
                design_line(d)
            )
        })
        .collect();
    (head, lines)
}

/// Every set's best design, one row each, best first: rank, set, size, total RMS and its change
/// in %, certified lower bound, solver status, unused elements, each actuator's RMS, the design.
pub fn csv(model: &Model, c: &Computed) -> String {
    let quote = |s: &str| format!("\"{}\"", s.replace('"', "\"\""));
    let mut out =
        String::from("rank,set,size,total_rms,total_change_pct,lower_bound,status,unused");
    for a in &model.actuators {
        let _ = write!(out, ",{}", quote(&format!("rms_{}", a.name)));
    }
    out.push_str(",design\n");
    for (i, d) in c.report.designs.iter().enumerate() {
        let _ = write!(
            out,
            "{},{},{},{},{},{},{},{}",
            i + 1,
            quote(&d.labels.join(" + ")),
            d.entries.len(),
            d.total_rms,
            change(d.total_rms, c.report.unbalanced_total),
            d.lower_bound,
            quote(&d.status),
            quote(&d.unused.join(" ")),
        );
        for v in &d.rms {
            let _ = write!(out, ",{v}");
        }
        let _ = writeln!(out, ",{}", quote(&design_line(d)));
    }
    out
}
