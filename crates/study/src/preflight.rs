//! Checks that need a valid model and guard the costly stages: the variant count before the
//! balance search, the sample count before the dynamics, the paths and the task grid as
//! `evaluate` and `run` will see them. `check` runs all of them, so that a case it accepts does
//! not fail later in `variants`, `evaluate` or `run`.

use std::sync::OnceLock;

use counterpoise_balance::enumerate::variant_count;
use counterpoise_balance::{Catalogue, catalogue_options, mechanism_energy};
use counterpoise_dynamics::{
    EvaluateOptions, Evaluator, ParameterSet, evaluate_unbalanced_grid, path_series,
};
use counterpoise_model::limits::{Limit, Limits, format_count};
use counterpoise_model::{Model, ModelError};

/// Samples per segment of the path simulation of `run` (its `PATH_SAMPLES_PER_SEGMENT`).
const PATH_SAMPLES_PER_SEGMENT: usize = 60;

static LIMITS: OnceLock<Limits> = OnceLock::new();

/// Sets the limits of this process (from `--limit`); call once, before any command.
pub fn set_limits(limits: Limits) {
    // A second call keeps the first value: the limits never change during a command.
    let _ = LIMITS.set(limits);
}

/// The limits in force.
pub fn limits() -> &'static Limits {
    LIMITS.get_or_init(Limits::default)
}

fn too_large(path: &str, what: String, found: f64, limit: Limit, advice: &str) -> ModelError {
    ModelError::Invalid {
        path: path.to_string(),
        reason: format!(
            "{} {what}; the limit is {}; {advice}{}",
            format_count(found),
            format_count(limits().get(limit) as f64),
            limit.hint()
        ),
    }
}

/// `Σ_{d=1..dmax} C(e, d)` in floating point, which cannot overflow (the exact count is only
/// asked of `variant_count` when it fits its integers comfortably).
fn variant_estimate(elements: u64, dmax: u64) -> f64 {
    let mut term = 1.0f64;
    let mut sum = 0.0;
    for d in 1..=dmax.min(elements) {
        term *= (elements - d + 1) as f64 / d as f64;
        sum += term;
        if !sum.is_finite() {
            break;
        }
    }
    sum
}

/// Refuses a balance search that would enumerate more variants than the limit, before it
/// starts; returns the number of variants. `source` names where Dmax came from (`--dmax` or
/// `balancing.dmax`).
pub fn variant_guard(model: &Model, dmax: usize, source: &str) -> Result<u128, ModelError> {
    let limits = limits();
    if dmax as u64 > limits.dmax {
        return Err(too_large(
            source,
            "elements per variant".into(),
            dmax as f64,
            Limit::Dmax,
            "",
        ));
    }
    let Some(b) = &model.balancing else {
        return Ok(0);
    };
    let counterweights = b.counterweights.as_ref().map_or(0, |c| c.bodies.len()) as u64;
    let springs = b.springs.as_ref().map_or(0, |s| s.pairs().len()) as u64;
    let estimate = variant_estimate(counterweights + springs, dmax as u64);
    if estimate > limits.variants as f64 {
        return Err(too_large(
            source,
            format!(
                "variants ({counterweights} counterweights and {springs} springs, at most {dmax} per variant)"
            ),
            estimate,
            Limit::Variants,
            "lower --dmax or restrict the elements (balancing.counterweights.bodies, balancing.springs.bodies), or ",
        ));
    }
    Ok(variant_count(counterweights, springs, dmax as u64))
}

/// Refuses a sample count (`--samples`) over the limits.
pub fn samples_guard(model: &Model, samples: usize) -> Result<(), ModelError> {
    let limits = limits();
    if samples as u64 > limits.samples {
        return Err(too_large(
            "--samples",
            "samples per task".into(),
            samples as f64,
            Limit::Samples,
            "",
        ));
    }
    if let Some(tasks) = &model.tasks {
        let points: f64 = tasks.grid.iter().map(|g| g.n as f64).product();
        let pairs = counterpoise_model::validate::task_count(points, tasks.pairs);
        let evaluations = pairs * samples as f64;
        if evaluations > limits.task_samples as f64 {
            return Err(too_large(
                "--samples",
                format!(
                    "evaluations ({} tasks × {samples} samples)",
                    format_count(pairs)
                ),
                evaluations,
                Limit::TaskSamples,
                "",
            ));
        }
    }
    Ok(())
}

/// Every waypoint of every path reachable, and every path followable by the path simulation
/// of `run`; each problem names the path and the waypoint.
pub fn path_problems(model: &Model) -> Vec<ModelError> {
    if model.paths.is_empty() {
        return Vec::new();
    }
    let ev = match Evaluator::new(model) {
        Ok(ev) => ev,
        Err(e) => return vec![ModelError::invalid("paths", e.to_string())],
    };
    let mut problems = Vec::new();
    for (i, path) in model.paths.iter().enumerate() {
        let before = problems.len();
        let mut used: Vec<usize> = path.sequence.clone();
        used.sort_unstable();
        used.dedup();
        for w in used {
            let waypoint = &path.waypoints[w];
            if let Err(reason) = ev.solve_point(&waypoint.u) {
                problems.push(ModelError::invalid(
                    format!("paths[{i}].waypoints.{}", waypoint.name),
                    format!(
                        "waypoint `{}` u = {:?} of path `{}` is not reachable: {reason}",
                        waypoint.name, waypoint.u, path.name
                    ),
                ));
            }
        }
        if problems.len() == before {
            let params = ParameterSet::unbalanced(model);
            if let Err(e) = path_series(model, &params, 0, i, PATH_SAMPLES_PER_SEGMENT) {
                problems.push(ModelError::invalid(
                    format!("paths[{i}]"),
                    format!("path `{}` cannot be followed: {e}", path.name),
                ));
            }
        }
    }
    problems
}

/// A `balancing` section must allow at least one element (else `variants` and `run` refuse).
pub fn catalogue_problem(model: &Model) -> Option<ModelError> {
    model.balancing.as_ref()?;
    let energy = mechanism_energy(model);
    Catalogue::build(&energy, &catalogue_options(model))
        .is_empty()
        .then(|| {
            ModelError::invalid(
                "balancing",
                "allows no counterweight and no spring (give counterweights or springs with at least one body)",
            )
        })
}

/// How `evaluate` and `run` will treat the task grid: the tasks they evaluate and those they
/// leave out (the same evaluation, without reactions).
pub struct GridReach {
    pub points: usize,
    pub tasks: usize,
    pub evaluable: usize,
    /// Points that are an end of at least one evaluable task.
    pub reached_points: usize,
    pub by_reason: Vec<(String, usize)>,
    /// Grid indices of the first excluded tasks.
    pub examples: Vec<(usize, usize, String)>,
}

pub fn grid_reach(model: &Model) -> Result<Option<GridReach>, ModelError> {
    if model.tasks.is_none() {
        return Ok(None);
    }
    let options = EvaluateOptions {
        reactions: false,
        ..EvaluateOptions::default()
    };
    let grid = evaluate_unbalanced_grid(model, &options)
        .map_err(|e| ModelError::invalid("tasks", e.to_string()))?;
    let tasks = &grid.tasks;
    let mut reached = vec![false; tasks.points.len()];
    let mut evaluable = 0;
    for w in 0..tasks.len() {
        if grid.stats(w, 0).is_some() {
            let (i, j) = tasks.pair(w);
            reached[i] = true;
            reached[j] = true;
            evaluable += 1;
        }
    }
    let examples = grid
        .excluded
        .examples
        .iter()
        .take(5)
        .map(|f| {
            let (i, j) = tasks.pair(f.task);
            (i, j, f.reason.to_string())
        })
        .collect();
    Ok(Some(GridReach {
        points: tasks.points.len(),
        tasks: tasks.len(),
        evaluable,
        reached_points: reached.iter().filter(|&&r| r).count(),
        by_reason: grid.excluded.by_reason.into_iter().collect(),
        examples,
    }))
}

/// Everything `check` verifies beyond validation: the problems `variants`, `evaluate` and `run`
/// would otherwise meet later.
pub fn problems(model: &Model) -> (Vec<ModelError>, Option<GridReach>) {
    let mut problems = Vec::new();
    if let Some(b) = &model.balancing {
        if let Err(e) = variant_guard(model, b.dmax, "balancing.dmax") {
            problems.push(e);
        }
        problems.extend(catalogue_problem(model));
    }
    problems.extend(path_problems(model));
    let reach = match grid_reach(model) {
        Ok(reach) => reach,
        Err(e) => {
            problems.push(e);
            None
        }
    };
    if let Some(r) = &reach
        && r.evaluable == 0
    {
        let reasons: Vec<String> = r
            .by_reason
            .iter()
            .map(|(k, n)| format!("{k} {n}"))
            .collect();
        problems.push(ModelError::invalid(
            "tasks.grid",
            format!(
                "none of the {} tasks can be evaluated ({}): the grid lies outside the mechanism's reach or coordinate ranges",
                r.tasks,
                reasons.join(", ")
            ),
        ));
    }
    (problems, reach)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_estimate_matches_the_exact_count_and_does_not_overflow() {
        for (e, d) in [(28u64, 2u64), (28, 3), (28, 4), (5, 9)] {
            let exact = variant_count(e, 0, d) as f64;
            assert!(
                (variant_estimate(e, d) - exact).abs() <= 1e-9 * exact,
                "{e} {d}"
            );
        }
        // 35 elements (7 bodies, springs to the base), Dmax 50: every subset, 2^35 − 1.
        let all = 2f64.powi(35) - 1.0;
        assert!((variant_estimate(35, 50) - all).abs() <= 1e-9 * all);
        assert!(variant_estimate(80_000, 8) > 1e30);
        assert!(variant_estimate(u64::MAX / 2, 1_000) > 1e30);
    }
}
