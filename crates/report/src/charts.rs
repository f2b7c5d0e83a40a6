//! Which charts the report shows, built from the results: the Fig. 7-style bars per class, the
//! torque curves on critical tasks (Fig. 10-style) and the path simulation curves (Figs. 9–10).
//! Shared by the HTML writer and the tests that count one `<svg>` per chart.

use crate::ranking::Class;
use crate::results::{PathRun, RunResults};
use crate::svg::{BarChart, LineChart, LineSeries, PALETTE, bar_chart, line_chart};

/// A rendered chart and the section it belongs to.
#[derive(Clone, Debug)]
pub struct Chart {
    pub section: Section,
    pub title: String,
    pub svg: String,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Section {
    Ranking,
    Torque,
    PathStatic,
    PathDynamic,
}

/// Colour of a class in every chart.
pub fn class_color(class: Option<Class>) -> &'static str {
    match class {
        None => PALETTE[0],
        Some(Class::Counterweights) => PALETTE[1],
        Some(Class::Springs) => PALETTE[2],
        Some(Class::Hybrid) => PALETTE[3],
    }
}

/// Variants per bar chart: 16 groups fit the page width without shrinking the text.
pub const BARS_PER_CHART: usize = 16;
/// Most variants of one class shown as bars (the ranking table lists all of them).
pub const MAX_BARS: usize = 48;

/// Every chart of the report, in display order.
pub fn all(r: &RunResults) -> Vec<Chart> {
    let mut charts = ranking_bars(r);
    charts.extend(torque(r));
    if let Some(p) = &r.path {
        if let Some(run) = &p.static_run {
            charts.extend(path_charts(
                r,
                &p.name,
                &p.actuators,
                run,
                "Static",
                Section::PathStatic,
            ));
        }
        if let Some(run) = &p.dynamic_run {
            charts.extend(path_charts(
                r,
                &p.name,
                &p.actuators,
                run,
                "Dynamic",
                Section::PathDynamic,
            ));
        }
    }
    charts
}

/// Fig. 7: ΔQTR, ΔQIT, ΔR of each variant of a class, best on the left; long classes are
/// split into charts of [`BARS_PER_CHART`] variants.
fn ranking_bars(r: &RunResults) -> Vec<Chart> {
    let ranked = r.ranked();
    let mut charts = Vec::new();
    for class in Class::ALL {
        let mut vs: Vec<_> = ranked.iter().filter(|v| v.class == class).collect();
        vs.sort_by_key(|v| v.class_rank);
        let total = vs.len();
        vs.truncate(MAX_BARS);
        let chunks = vs.len().div_ceil(BARS_PER_CHART);
        for (k, chunk) in vs.chunks(BARS_PER_CHART).enumerate() {
            let title = if chunks == 1 && total == vs.len() {
                format!("{} — ranking indicators", class.title())
            } else {
                let first = k * BARS_PER_CHART + 1;
                format!(
                    "{} — class ranks {first}–{} of {total}",
                    class.title(),
                    first + chunk.len() - 1
                )
            };
            let chart = BarChart {
                title: title.clone(),
                y_label: "variation vs unbalanced [%]".into(),
                categories: chunk
                    .iter()
                    .map(|v| (v.name.clone().unwrap_or_default(), v.label()))
                    .collect(),
                series: vec![
                    ("ΔQTR (total RMS torque)".into(), "#0072B2".into()),
                    ("ΔQIT (total peak torque)".into(), "#56B4E9".into()),
                    ("ΔR (joint reactions)".into(), "#E69F00".into()),
                ],
                values: chunk
                    .iter()
                    .map(|v| {
                        vec![
                            v.dqtr.unwrap_or(f64::NAN),
                            v.dqit.unwrap_or(f64::NAN),
                            v.dr.unwrap_or(f64::NAN),
                        ]
                    })
                    .collect(),
                min_width: 560.0,
                height: 340.0,
            };
            charts.push(Chart {
                section: Section::Ranking,
                title,
                svg: bar_chart(&chart),
            });
        }
    }
    charts
}

fn curve_class(r: &RunResults, variant: Option<usize>) -> Option<Class> {
    variant.and_then(|id| r.variant(id)).map(|v| v.class)
}

/// Motor torque of UB and the best variants on the critical tasks.
fn torque(r: &RunResults) -> Vec<Chart> {
    r.torque_charts
        .iter()
        .map(|c| {
            let title = format!("{} — task {}", c.actuator, crate::format::task(c.task));
            let chart = LineChart {
                title: title.clone(),
                subtitle: Some(critical_summary(&c.critical_for)),
                x_label: "time [s]".into(),
                y_label: "motor torque [N·m]".into(),
                series: c
                    .curves
                    .iter()
                    .map(|curve| LineSeries {
                        label: curve.label.clone(),
                        color: class_color(curve_class(r, curve.variant)).into(),
                        dashed: curve.variant.is_none(),
                        x: c.t.clone(),
                        y: curve.values.clone(),
                    })
                    .collect(),
                include_zero: true,
                width: 560.0,
                height: 330.0,
            };
            Chart {
                section: Section::Torque,
                title,
                svg: line_chart(&chart),
            }
        })
        .collect()
}

/// `["CRT of UB", "CPT of UB", "CPT of SB1"]` → `"critical: CRT, CPT of UB; CPT of SB1"`:
/// mechanisms with the same kinds are listed together, in order of first mention.
pub fn critical_summary(reasons: &[String]) -> String {
    let mut by_who: Vec<(String, Vec<String>)> = Vec::new();
    for r in reasons {
        let (kind, who) = r.split_once(" of ").unwrap_or((r.as_str(), ""));
        match by_who.iter_mut().find(|(w, _)| w == who) {
            Some((_, kinds)) if !kinds.iter().any(|k| k == kind) => kinds.push(kind.to_string()),
            Some(_) => {}
            None => by_who.push((who.to_string(), vec![kind.to_string()])),
        }
    }
    let mut groups: Vec<(Vec<String>, Vec<String>)> = Vec::new();
    for (who, kinds) in by_who {
        match groups.iter_mut().find(|(k, _)| *k == kinds) {
            Some((_, whos)) => whos.push(who),
            None => groups.push((kinds, vec![who])),
        }
    }
    if groups.is_empty() {
        return String::new();
    }
    let parts: Vec<String> = groups
        .iter()
        .map(|(kinds, whos)| {
            let whos: Vec<&str> = whos
                .iter()
                .map(|w| w.as_str())
                .filter(|w| !w.is_empty())
                .collect();
            if whos.is_empty() {
                kinds.join(", ")
            } else {
                format!("{} of {}", kinds.join(", "), whos.join(", "))
            }
        })
        .collect();
    format!("critical task: {}", parts.join("; "))
}

fn path_charts(
    r: &RunResults,
    name: &str,
    actuators: &[String],
    run: &PathRun,
    kind: &str,
    section: Section,
) -> Vec<Chart> {
    let x_label = if run.x_unit.is_empty() {
        run.x_label.clone()
    } else {
        format!("{} [{}]", run.x_label, run.x_unit)
    };
    actuators
        .iter()
        .enumerate()
        .map(|(a, actuator)| {
            let title = format!("{kind} torque along {name} — {actuator}");
            let chart = LineChart {
                title: title.clone(),
                subtitle: None,
                x_label: x_label.clone(),
                y_label: "motor torque [N·m]".into(),
                series: run
                    .mechanisms
                    .iter()
                    .filter_map(|m| {
                        Some(LineSeries {
                            label: m.label.clone(),
                            color: class_color(curve_class(r, m.variant)).into(),
                            dashed: m.variant.is_none(),
                            x: run.x.clone(),
                            y: m.torques.get(a)?.clone(),
                        })
                    })
                    .collect(),
                include_zero: true,
                width: 560.0,
                height: 330.0,
            };
            Chart {
                section,
                title,
                svg: line_chart(&chart),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn critical_reasons_are_grouped() {
        let r = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        assert_eq!(
            critical_summary(&r(&[
                "CRT of UB",
                "CPT of UB",
                "CPT of SB73",
                "CPT of SB1",
                "CRT of SB57",
                "CPT of SB57"
            ])),
            "critical task: CRT, CPT of UB, SB57; CPT of SB73, SB1"
        );
        assert_eq!(
            critical_summary(&r(&["CRT of UB"])),
            "critical task: CRT of UB"
        );
        assert_eq!(critical_summary(&[]), "");
    }
}
