//! One variant as the results document records it: the search's verdict and, for a balanced
//! variant, the optimiser's, converted from the stages' types into the report's; and the
//! dynamics crate's description of an optimised variant.

use std::time::{SystemTime, UNIX_EPOCH};

use counterpoise_balance::{Status, VariantResult};
use counterpoise_dynamics::Indicators;
use counterpoise_model::Model;
use counterpoise_report as report;
use report::{
    ActuatorSummary, ElementInfo, Evaluation, FreeDirection, JointPeak, OptimiserInfo,
    PhysicalParameters, VariantRecord,
};

use crate::shard_file::OptimisedRecord;

pub(crate) fn capitalised(s: &str) -> String {
    let mut c = s.chars();
    c.next()
        .map(|f| f.to_uppercase().chain(c).collect())
        .unwrap_or_default()
}

pub(crate) fn utc_now() -> String {
    let secs = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    // civil-from-days (Howard Hinnant's algorithm): no date crate for one timestamp
    let days = (secs / 86_400) as i64;
    let rem = secs % 86_400;
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}-{month:02}-{day:02}T{:02}:{:02}:{:02}Z",
        rem / 3600,
        (rem % 3600) / 60,
        rem % 60
    )
}

/// Indicators in the report's schema.
pub(crate) fn evaluation(
    ind: &Indicators,
    (tasks, excluded, minimum_norm): (usize, usize, bool),
) -> Evaluation {
    Evaluation {
        qtr: ind.qtr,
        qtr_task: ind.qtr_task,
        qit: ind.qit,
        qit_task: ind.qit_task,
        actuators: ind
            .actuators
            .iter()
            .map(|a| ActuatorSummary {
                name: a.name.clone(),
                crt: a.crt,
                crt_rms: a.crt_rms,
                cpt: a.cpt,
                cpt_peak: a.cpt_peak,
            })
            .collect(),
        joints: ind
            .joints
            .iter()
            .map(|j| JointPeak {
                name: j.name.clone(),
                force: j.force,
                force_task: Some(j.force_task),
                moment: j.moment,
                moment_task: Some(j.moment_task),
            })
            .collect(),
        tasks: tasks - excluded,
        excluded_tasks: excluded,
        reactions_minimum_norm: minimum_norm,
    }
}

/// One variant's record: the search's verdict, and the optimiser's for balanced ones.
pub(crate) fn record(
    model: &Model,
    id: usize,
    v: &VariantResult,
    opt: Option<&OptimisedRecord>,
    grid_info: (usize, usize, bool),
) -> VariantRecord {
    let elements = v
        .elements
        .iter()
        .map(|e| ElementInfo {
            label: e.label.clone(),
            kind: e.kind,
            bodies: e.bodies.clone(),
        })
        .collect();
    // A balanced variant starts as feasible (its verified witness is within the bounds the
    // search used); the optimiser's verdict, applied below, replaces it.
    let status = match v.status {
        Status::Balanced => Status::Feasible,
        verdict => verdict,
    };
    let mut r = VariantRecord::new(id, elements, v.class, status);
    r.reason = v.reason.clone();
    r.relations = v.relations.clone();
    r.free_directions = v
        .free_directions
        .iter()
        .map(|f| FreeDirection {
            // Nine significant digits: the reports show four, and at Dmax 3 the directions
            // of the ranked variants are half of results.json.
            components: f
                .components
                .iter()
                .map(|(name, c)| (name.clone(), significant(*c, 9)))
                .collect(),
            positive_interval: f.positive_interval,
        })
        .collect();
    r.verification_residual = v.verification.map(|x| x.residual);
    let Some(opt) = opt else {
        r.relations.clear();
        r.free_directions.clear();
        return r;
    };
    r.optimiser = Some(OptimiserInfo {
        objective: opt.objective,
        lower_bound: opt.lower_bound,
        gap: opt.gap,
        iterations: Some(opt.iterations),
        boxes: Some(opt.boxes),
        message: opt.reason.clone(),
    });
    let (cw_plane, spring_plane) = (model.counterweight_plane(), model.spring_plane());
    // The planes are the case's (a shard file written before planes were recorded in it
    // still gives the report its polar form).
    r.parameters = Some(PhysicalParameters {
        counterweights: opt
            .counterweights
            .iter()
            .map(|c| report::Counterweight {
                plane: cw_plane,
                ..c.clone()
            })
            .collect(),
        springs: opt
            .springs
            .iter()
            .map(|s| report::Spring {
                plane: spring_plane,
                ..s.clone()
            })
            .collect(),
    });
    match (opt.outcome == Status::Feasible, &opt.indicators) {
        (true, Some(ind)) => {
            r.status = Status::Feasible;
            r.evaluation = Some(evaluation(ind, grid_info));
            if let Some(res) = opt.residual {
                r.verification_residual = Some(res);
            }
        }
        (true, None) => {
            r.status = Status::Discarded;
            r.reason = Some("optimised, but not re-evaluated over all tasks".into());
        }
        (false, _) => {
            r.status = if opt.outcome == Status::Undecided {
                Status::Undecided
            } else {
                Status::Discarded
            };
            r.reason = opt.reason.clone();
        }
    }
    if r.status != Status::Feasible {
        // The reports show the balance relations of ranked variants only; the free directions
        // of thousands of unranked variants at Dmax 3 were most of results.json.
        r.relations.clear();
        r.free_directions.clear();
    }
    r
}

/// `x` rounded to `digits` significant digits (through the decimal representation, so the JSON
/// holds the short form).
fn significant(x: f64, digits: usize) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    format!("{x:.*e}", digits.saturating_sub(1))
        .parse()
        .unwrap_or(x)
}
