//! Which charts the report shows, built from the results: the Fig. 7-style bars per class, the
//! torque curves on critical tasks (Fig. 10-style) and the path simulation curves (Figs. 9–10).
//! Shared by the HTML writer and the tests that count one `<svg>` per chart.

use crate::ranking::Class;
use crate::results::{Curve, PathRun, RunResults, VariantRecord};
use crate::svg::{
    BarChart, DASHES, LineChart, LineSeries, Marker, PALETTE, ScatterChart, ScatterPoint,
    bar_chart, line_chart, scatter_chart,
};

/// A rendered chart and the section it belongs to.
#[derive(Clone, Debug)]
pub struct Chart {
    pub section: Section,
    pub title: String,
    pub svg: String,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Section {
    Decision,
    /// The potential energy along a motion (after the schematics).
    Energy,
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

/// Marker of a class in every chart (the unbalanced robot has none).
pub fn class_marker(class: Option<Class>) -> Option<Marker> {
    match class {
        None => None,
        Some(Class::Counterweights) => Some(Marker::Circle),
        Some(Class::Springs) => Some(Marker::Square),
        Some(Class::Hybrid) => Some(Marker::Triangle),
    }
}

/// Variants per bar chart: 16 groups fit the page width without shrinking the text.
pub const BARS_PER_CHART: usize = 16;
/// Most variants of one class shown as bars (the ranking table lists all of them).
pub const MAX_BARS: usize = 48;
/// A class with fewer ranked variants than this shares its bar chart with the other small
/// classes (a chart of one bar compares nothing).
pub const MIN_BARS: usize = 3;

/// Every chart of the report, in display order.
pub fn all(r: &RunResults) -> Vec<Chart> {
    let mut charts: Vec<Chart> = pareto(r).into_iter().collect();
    charts.extend(energy(r));
    charts.extend(ranking_bars(r));
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

/// Bars beyond this are clipped: twice the largest |ΔQTR| or |ΔQIT| of the ranked variants, at
/// least 10 percentage points, rounded up to a multiple of 10, so an outlier ΔR (+21768 % on the pendulum) cannot flatten the
/// motor indicators.
pub fn bar_clip(r: &RunResults) -> f64 {
    let motor = r
        .ranked()
        .iter()
        .flat_map(|v| [v.dqtr, v.dqit])
        .flatten()
        .fold(0.0f64, |m, x| m.max(x.abs()));
    // Rounded up to a multiple of 10, so the note reads "beyond ±70", not "±64.19".
    ((2.0 * motor).max(10.0) / 10.0).ceil() * 10.0
}

/// `chunks` of about equal size (33 → 11, 11, 11, never 16, 16, 1).
fn even_chunks<T: Copy>(items: &[T], most: usize) -> Vec<Vec<T>> {
    if items.is_empty() {
        return Vec::new();
    }
    let n = items.len().div_ceil(most);
    let size = items.len().div_ceil(n);
    items.chunks(size).map(|c| c.to_vec()).collect()
}

fn short_class(c: Class) -> &'static str {
    match c {
        Class::Counterweights => "cw",
        Class::Springs => "springs",
        Class::Hybrid => "hybrid",
    }
}

/// Fig. 7: ΔQTR, ΔQIT, ΔR of each variant of a class, best on the left; long classes are
/// split into charts of at most [`BARS_PER_CHART`] variants of about equal size, classes with
/// fewer than [`MIN_BARS`] variants share one chart, and a lone leftover variant joins the
/// smallest chart: no chart holds a single bar (unless only one variant is ranked at all, when
/// there is no chart: the table says it all).
fn ranking_bars(r: &RunResults) -> Vec<Chart> {
    let ranked = r.ranked();
    if ranked.len() < 2 {
        return Vec::new();
    }
    // (title, variants, mixed classes)
    let mut groups: Vec<(String, Vec<&VariantRecord>, bool)> = Vec::new();
    let mut small: Vec<&VariantRecord> = Vec::new();
    for class in Class::ALL {
        let mut vs: Vec<&VariantRecord> = ranked
            .iter()
            .copied()
            .filter(|v| v.class == class)
            .collect();
        vs.sort_by_key(|v| v.class_rank);
        let total = vs.len();
        if total < MIN_BARS {
            small.extend(vs);
            continue;
        }
        vs.truncate(MAX_BARS);
        let chunks = even_chunks(&vs, BARS_PER_CHART);
        let single = chunks.len() == 1 && total == vs.len();
        let mut first = 1;
        for chunk in chunks {
            let title = if single {
                format!("{} — ranking indicators", class.title())
            } else {
                format!(
                    "{} — class ranks {first}–{} of {total}",
                    class.title(),
                    first + chunk.len() - 1
                )
            };
            first += chunk.len();
            groups.push((title, chunk, false));
        }
    }
    let small_title = |vs: &[&VariantRecord]| {
        Class::ALL
            .iter()
            .filter(|c| vs.iter().any(|v| v.class == **c))
            .map(|c| c.title())
            .collect::<Vec<_>>()
            .join(" and ")
    };
    match small.len() {
        0 => {}
        1 if !groups.is_empty() => {
            let k = (0..groups.len())
                .min_by_key(|&k| groups[k].1.len())
                .unwrap_or(0);
            let g = &mut groups[k];
            g.0 = format!("{}, with {}", g.0, small_title(&small));
            g.1.push(small[0]);
            g.2 = true;
        }
        _ => {
            small.sort_by_key(|v| v.rank);
            let title = format!("{} — ranking indicators", small_title(&small));
            groups.push((title, small, true));
        }
    }
    let clip = bar_clip(r);
    groups
        .into_iter()
        .map(|(title, vs, mixed)| {
            let chart = BarChart {
                title: title.clone(),
                y_label: "variation vs unbalanced [%]".into(),
                categories: vs
                    .iter()
                    .map(|v| {
                        let sub = if mixed {
                            format!("{} ({})", v.label(), short_class(v.class))
                        } else {
                            v.label()
                        };
                        (v.name.clone().unwrap_or_default(), sub)
                    })
                    .collect(),
                series: vec![
                    ("ΔQTR (total RMS torque)".into(), "#0072B2".into()),
                    ("ΔQIT (total peak torque)".into(), "#56B4E9".into()),
                    ("ΔR (joint reactions)".into(), "#E69F00".into()),
                ],
                values: vs
                    .iter()
                    .map(|v| {
                        vec![
                            v.dqtr.unwrap_or(f64::NAN),
                            v.dqit.unwrap_or(f64::NAN),
                            v.dr.unwrap_or(f64::NAN),
                        ]
                    })
                    .collect(),
                clip: Some(clip),
                min_width: 560.0,
                height: 340.0,
            };
            Chart {
                section: Section::Ranking,
                title,
                svg: bar_chart(&chart),
            }
        })
        .collect()
}

/// The Pareto view of the decision: ΔQTR against added mass, ΔR as the marker size, class as
/// colour and shape, the equivalence band, the non-dominated front and the recommendations.
fn pareto(r: &RunResults) -> Option<Chart> {
    let ranked = r.ranked();
    let leader = ranked.first()?;
    let decision = r.decision.as_ref()?;
    let mass = |v: &VariantRecord| v.practical.as_ref().map_or(0.0, |p| p.added_mass);
    let clip = bar_clip(r);
    let size_max = ranked
        .iter()
        .filter_map(|v| v.dr)
        .fold(0.0f64, f64::max)
        .min(clip);
    let mut callouts: Vec<(usize, Vec<String>)> = Vec::new();
    for rec in decision.overall.iter().chain(&decision.classes) {
        let scope = match rec.class {
            None => "overall".to_string(),
            Some(c) => c.name().to_string(),
        };
        match callouts.iter_mut().find(|(id, _)| *id == rec.chosen) {
            Some((_, s)) => s.push(scope),
            None => callouts.push((rec.chosen, vec![scope])),
        }
    }
    let points: Vec<ScatterPoint> = ranked
        .iter()
        .map(|v| {
            let name = v.name.clone().unwrap_or_default();
            ScatterPoint {
                x: mass(v),
                y: v.dqtr.unwrap_or(f64::NAN),
                size: v.dr.unwrap_or(0.0),
                color: class_color(Some(v.class)).into(),
                marker: class_marker(Some(v.class)).unwrap_or(Marker::Circle),
                label: format!(
                    "{}: added mass {}, ΔQTR {} %, ΔQIT {} %, ΔR {} %",
                    v.display_name(),
                    crate::format::mass(mass(v)),
                    crate::format::percent(v.dqtr.unwrap_or(f64::NAN)),
                    crate::format::percent(v.dqit.unwrap_or(f64::NAN)),
                    crate::format::percent(v.dr.unwrap_or(f64::NAN))
                ),
                callout: callouts
                    .iter()
                    .find(|(id, _)| *id == v.id)
                    .map(|(_, scopes)| format!("{} ({})", name, scopes.join(", "))),
            }
        })
        .collect();
    // Non-dominated on (added mass, ΔQTR): sorted by mass, each point better than all lighter.
    let mut sorted: Vec<(f64, f64)> = points.iter().map(|p| (p.x, p.y)).collect();
    sorted.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let mut front: Vec<(f64, f64)> = Vec::new();
    for (x, y) in sorted {
        if front.last().is_none_or(|&(_, best)| y < best) {
            front.push((x, y));
        }
    }
    let best = leader.dqtr?;
    let x_label = match r.moving_mass {
        Some(m) => format!(
            "added mass [kg] (the moving mass is {})",
            crate::format::mass(m)
        ),
        None => "added mass [kg]".into(),
    };
    let chart = ScatterChart {
        title: "Motor effort against added mass".into(),
        subtitle: Some(
            "lower left is better; dashed: no variant is both lighter and lower on ΔQTR".into(),
        ),
        x_label,
        y_label: "ΔQTR [%]".into(),
        points,
        legend: Class::ALL
            .iter()
            .filter(|c| ranked.iter().any(|v| v.class == **c))
            .map(|&c| {
                (
                    c.title().to_string(),
                    class_color(Some(c)).to_string(),
                    class_marker(Some(c)).unwrap_or(Marker::Circle),
                )
            })
            .collect(),
        size_max,
        size_label: "ΔR".into(),
        band: Some((
            best,
            best + decision.tolerance,
            format!(
                "within {} pp of {}",
                crate::format::compact(decision.tolerance),
                leader.name.clone().unwrap_or_default()
            ),
        )),
        front,
        width: 760.0,
        height: 430.0,
    };
    Some(Chart {
        section: Section::Decision,
        title: chart.title.clone(),
        svg: scatter_chart(&chart),
    })
}

fn curve_class(r: &RunResults, variant: Option<usize>) -> Option<Class> {
    variant.and_then(|id| r.variant(id)).map(|v| v.class)
}

/// Line style of the `k`-th curve of a chart: the unbalanced robot dashed grey without marker,
/// the variants in their class colour and marker, with a dash pattern by position.
fn curve_style(
    r: &RunResults,
    k: usize,
    variant: Option<usize>,
) -> (String, Option<String>, Option<Marker>) {
    let class = curve_class(r, variant);
    let dash = match variant {
        None => Some("6 3".to_string()),
        Some(_) => DASHES[k.saturating_sub(1) % DASHES.len()].map(str::to_string),
    };
    (class_color(class).to_string(), dash, class_marker(class))
}

/// Largest |value| of a set of curves: the scale of a figure's noise floor.
fn scale<'a>(values: impl Iterator<Item = &'a f64>) -> f64 {
    values
        .filter(|v| v.is_finite())
        .fold(0.0f64, |m, v| m.max(v.abs()))
}

/// One line per curve over the abscissa `t`, styled as every chart of the report styles that
/// mechanism (UB, the recommended and the best-ranked variants look alike in every figure).
fn curve_series(r: &RunResults, t: &[f64], curves: &[Curve]) -> Vec<LineSeries> {
    curves
        .iter()
        .enumerate()
        .map(|(k, curve)| {
            let (color, dash, marker) = curve_style(r, k, curve.variant);
            LineSeries {
                label: curve.label.clone(),
                color,
                dash,
                marker,
                x: t.to_vec(),
                y: curve.values.clone(),
            }
        })
        .collect()
}

/// Potential energy of UB and the recommended variants along one motion: the proof a reader
/// sees (a balanced variant's line is flat).
fn energy(r: &RunResults) -> Option<Chart> {
    let e = r.energy.as_ref()?;
    let title = format!("Potential energy along {}", e.along);
    let chart = LineChart {
        title: title.clone(),
        subtitle: Some("relative to the start; flat = statically balanced".into()),
        x_label: "time [s]".into(),
        y_label: "potential energy [J]".into(),
        y_unit: "J".into(),
        series: curve_series(r, &e.t, &e.curves),
        include_zero: true,
        noise_scale: None,
        width: 560.0,
        height: 330.0,
    };
    Some(Chart {
        section: Section::Energy,
        title,
        svg: line_chart(&chart),
    })
}

/// Motor torque of UB and the best variants on the critical tasks.
fn torque(r: &RunResults) -> Vec<Chart> {
    let figure_scale = scale(
        r.torque_charts
            .iter()
            .flat_map(|c| c.curves.iter().flat_map(|k| k.values.iter())),
    );
    r.torque_charts
        .iter()
        .map(|c| {
            let title = format!("{} — task {}", c.actuator, crate::format::task(c.task));
            let chart = LineChart {
                title: title.clone(),
                subtitle: Some(critical_summary(&c.critical_for)),
                x_label: "time [s]".into(),
                y_label: "motor torque [N·m]".into(),
                y_unit: "N·m".into(),
                series: curve_series(r, &c.t, &c.curves),
                include_zero: true,
                noise_scale: Some(figure_scale),
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
    let figure_scale = scale(
        run.mechanisms
            .iter()
            .flat_map(|m| m.torques.iter().flat_map(|t| t.iter())),
    );
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
                y_unit: "N·m".into(),
                series: run
                    .mechanisms
                    .iter()
                    .enumerate()
                    .filter_map(|(k, m)| {
                        let (color, dash, marker) = curve_style(r, k, m.variant);
                        Some(LineSeries {
                            label: m.label.clone(),
                            color,
                            dash,
                            marker,
                            x: run.x.clone(),
                            y: m.torques.get(a)?.clone(),
                        })
                    })
                    .collect(),
                include_zero: true,
                noise_scale: Some(figure_scale),
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
    fn long_classes_split_into_charts_of_about_equal_size() {
        let sizes = |n: usize| -> Vec<usize> {
            let items: Vec<usize> = (0..n).collect();
            even_chunks(&items, BARS_PER_CHART)
                .iter()
                .map(|c| c.len())
                .collect()
        };
        // 33 = 16 + 16 + 1 would leave a lone bar ("class ranks 33–33 of 33")
        assert_eq!(sizes(33), vec![11, 11, 11]);
        assert_eq!(sizes(17), vec![9, 8]);
        assert_eq!(sizes(16), vec![16]);
        assert_eq!(sizes(2), vec![2]);
        assert!(sizes(0).is_empty());
        for n in 2..=48 {
            assert!(
                sizes(n).iter().all(|k| (2..=BARS_PER_CHART).contains(k)),
                "{n}"
            );
            assert_eq!(sizes(n).iter().sum::<usize>(), n);
        }
    }

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
