//! What `run` adds when no variant is feasible (issue 27): how many elements the mechanism needs
//! to balance at all, and the best it gets from the elements it was given — the partial
//! balancing of [`super::compute`] with the study's Dmax as the budget, every actuator's torque
//! minimised. The results go to `partial.json` and `partial.csv` beside `results.json`, a note in
//! `results.json`'s metadata (which the reports print) and a block in the terminal summary; the
//! report crate has no partial section of its own.

use std::fmt::Write as _;

use anyhow::Result;
use counterpoise_balance::minimal::minimal_search;
use counterpoise_balance::partial::counterweight_entries;
use counterpoise_balance::{
    Catalogue, SearchOptions, SearchReport, Status, VariantResult, catalogue_options,
    mechanism_energy, realization_hints,
};
use counterpoise_model::Model;
use serde_json::json;

use super::{Computed, change, compute, design_line, set_guard};

/// How far past the study's Dmax the minimal-set walk looks for the smallest Dmax at which a
/// variant balances: two more elements (the 6-axis arm of `cases/arm6.json` needs one more than
/// its Dmax 2, found in about 10 s), within the `--minimal` guard.
pub const PROBE_BEYOND: usize = 2;

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

/// From the study's own search when something balances within its Dmax (then the bounds or the
/// peak limits are what excluded it); otherwise from the minimal-set walk up to
/// Dmax + [`PROBE_BEYOND`] (an exact case only).
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
    let energy = mechanism_energy(model);
    let catalogue = Catalogue::build(&energy, &catalogue_options(model));
    let exact = match &energy.exact {
        Ok(mechanism) => counterpoise_balance::exact::ExactBasis::build(mechanism, &catalogue),
        Err(_) => {
            return Smallest {
                sentence: format!(
                    "no variant of at most {within} balances; the smallest Dmax that does \
                     was not looked for (the minimal-set walk needs an exact case)"
                ),
                json: json!({ "searched_to": dmax, "smallest_balanced": null, "source": "run" }),
            };
        }
    };
    // The deepest probe the `--minimal` guard allows.
    let probe = (dmax + 1..=dmax + PROBE_BEYOND)
        .rev()
        .find(|&d| super::super::variants::minimal_guard(&exact, d, "--dmax").is_ok());
    let Some(probe) = probe else {
        return Smallest {
            sentence: format!(
                "no variant of at most {within} balances; a deeper search is past the \
                 limits (`variants CASE --minimal --dmax N`)"
            ),
            json: json!({ "searched_to": dmax, "smallest_balanced": null, "source": "run" }),
        };
    };
    let report = match minimal_search(
        &energy,
        catalogue,
        SearchOptions {
            dmax: probe,
            hints: realization_hints(model),
        },
    ) {
        Ok(r) => r,
        Err(e) => {
            return Smallest {
                sentence: format!(
                    "no variant of at most {within} balances; the minimal-set walk failed: \
                     {e}"
                ),
                json: json!({ "searched_to": dmax, "smallest_balanced": null, "source": "run" }),
            };
        }
    };
    let json = json!({
        "searched_to": probe,
        "smallest_linear": report.smallest_linear,
        "smallest_balanced": report.smallest_balanced,
        "note": report.smallest_balanced_note,
        "source": "variants --minimal",
    });
    let sentence = match report.smallest_balanced {
        Some(d) => {
            let example = report
                .sets
                .iter()
                .filter(|v| v.status == Status::Balanced && v.elements.len() == d)
                .chain(&report.first_balanced)
                .next()
                .map_or(String::new(), |v| format!(", e.g. {}", labels(v)));
            let at_most = if report.smallest_balanced_note.is_some() {
                "at most "
            } else {
                ""
            };
            format!(
                "no variant of at most {within} balances; the smallest Dmax at which one \
                 does is {at_most}{d}{example} (`variants CASE --minimal --dmax {probe}`)"
            )
        }
        None => format!(
            "no variant of at most {} balances (minimal-set walk to Dmax {probe}{})",
            plural(probe, "element"),
            report.smallest_linear.map_or(String::new(), |d| format!(
                "; the balance equations are solvable from {d} elements, not realizably"
            ))
        ),
    };
    Smallest { sentence, json }
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
    Ok(Fallback {
        note,
        text,
        json,
        csv,
    })
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
                design_line(model, d)
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
        let _ = writeln!(out, ",{}", quote(&design_line(model, d)));
    }
    out
}
