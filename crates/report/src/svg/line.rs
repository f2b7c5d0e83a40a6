//! Line charts (torque curves over a task), with dashes and markers per series.

use std::fmt::Write;

use crate::format::escape_html;

use super::primitives::*;

/// One line of a [`LineChart`].
#[derive(Clone, Debug)]
pub struct LineSeries {
    pub label: String,
    pub color: String,
    /// `stroke-dasharray`, e.g. `"6 3"`; `None` for a solid line.
    pub dash: Option<String>,
    /// Marker drawn every few samples (staggered between series so they do not cover each
    /// other) and in the legend.
    pub marker: Option<Marker>,
    pub x: Vec<f64>,
    pub y: Vec<f64>,
}

/// Dash patterns of the curves after the first, in order: coinciding curves stay visible as
/// interleaved dashes (the first, the reference, has its own pattern set by the caller).
pub const DASHES: [Option<&str>; 4] = [None, Some("9 4"), Some("3 3"), Some("12 3 3 3")];

/// Values below this fraction of the chart's scale are round-off and drawn as zero (see
/// [`LineChart::noise_scale`]). 1e-6 is far above the round-off of a balanced mechanism's
/// static torque (1e-13 of the robot's torques on the palletizer) and far below anything a
/// reader could see on a chart (a pixel is about 1e-3 of the scale).
pub const NOISE_FLOOR: f64 = 1e-6;

/// A line chart with labelled axes and a legend.
#[derive(Clone, Debug)]
pub struct LineChart {
    pub title: String,
    /// A smaller second line under the title (e.g. why this task is shown).
    pub subtitle: Option<String>,
    pub x_label: String,
    pub y_label: String,
    /// Unit of the values, for the noise note (e.g. `N·m`).
    pub y_unit: String,
    pub series: Vec<LineSeries>,
    pub include_zero: bool,
    /// The scale the noise floor refers to: the largest |value| of the figure this chart is
    /// part of (e.g. every actuator's torque along a path), so a chart of pure round-off
    /// (±1e-11 N·m for a motor whose static torque is zero) is recognised as such. `None`: the
    /// chart's own largest |value|.
    pub noise_scale: Option<f64>,
    pub width: f64,
    pub height: f64,
}

/// The series with values below the noise floor set to exactly zero, the floor, and the labels
/// of the series that had nonzero values and are now all zero (the ones the reader must be
/// told about: elsewhere the change is far below a pixel).
pub fn denoise(series: &[LineSeries], scale: Option<f64>) -> (Vec<LineSeries>, f64, Vec<String>) {
    let own = series
        .iter()
        .flat_map(|s| s.y.iter())
        .filter(|v| v.is_finite())
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let scale = scale.unwrap_or(own).max(own);
    let floor = NOISE_FLOOR * scale;
    let mut silenced = Vec::new();
    let out = series
        .iter()
        .map(|s| {
            let mut s = s.clone();
            let had_signal = s.y.iter().any(|v| v.is_finite() && *v != 0.0);
            for v in &mut s.y {
                if v.is_finite() && v.abs() < floor {
                    *v = 0.0;
                }
            }
            if had_signal && s.y.iter().all(|v| *v == 0.0 || !v.is_finite()) {
                silenced.push(s.label.clone());
            }
            s
        })
        .collect();
    (out, floor, silenced)
}

/// Renders a line chart as an `<svg>` element.
pub fn line_chart(chart: &LineChart) -> String {
    let (width, height) = (chart.width, chart.height);
    let right = 18.0;
    let (series, floor, silenced) = denoise(&chart.series, chart.noise_scale);
    let (y_lo, y_hi) = range(
        series.iter().flat_map(|s| s.y.iter().copied()),
        chart.include_zero,
    );
    let left = left_margin(y_lo, y_hi);
    let (mut out, legend_y) = svg_open(width, height, &chart.title, chart.subtitle.as_deref());
    let items: Vec<LegendItem> = series
        .iter()
        .map(|s| LegendItem {
            label: s.label.clone(),
            color: s.color.clone(),
            dash: s.dash.clone(),
            marker: s.marker,
            bar: false,
        })
        .collect();
    let (legend_svg, legend_h) = legend(&items, left, legend_y, width - left - right);
    out.push_str(&legend_svg);
    let mut top = legend_y + legend_h + 4.0;
    if !silenced.is_empty() {
        let unit = if chart.y_unit.is_empty() {
            String::new()
        } else {
            format!(" {}", chart.y_unit)
        };
        let who = if silenced.len() == series.len() {
            "every curve".to_string()
        } else {
            silenced.join(", ")
        };
        let text = format!(
            "{who}: all values below the noise floor ({floor:.1e}{unit}, 1e-6 of the figure's scale), drawn as zero"
        );
        top += note_lines(&mut out, &text, left, top + 6.0, width - left - right) + 2.0;
    }
    let bottom = 50.0;
    let xs = || series.iter().flat_map(|s| s.x.iter().copied());
    let (x_lo, x_hi) = {
        // No padding on x: curves span the task.
        let lo = xs().filter(|x| x.is_finite()).fold(f64::INFINITY, f64::min);
        let hi = xs()
            .filter(|x| x.is_finite())
            .fold(f64::NEG_INFINITY, f64::max);
        if lo.is_finite() && hi > lo {
            (lo, hi)
        } else {
            range(xs(), false)
        }
    };
    let f = Frame {
        left,
        top,
        w: width - left - right,
        h: height - top - bottom,
        x_lo,
        x_hi,
        y_lo,
        y_hi,
    };
    y_axis(&mut out, &f, &chart.y_label);
    x_axis(&mut out, &f, height, &chart.x_label);
    // Drawn last-to-first, so the first series (the reference) lies on top; coinciding curves
    // stay distinguishable by their dash patterns and staggered markers.
    let n = series.len().max(1);
    for (k, s) in series.iter().enumerate().rev() {
        let mut points = String::new();
        for (x, y) in s.x.iter().zip(&s.y) {
            if x.is_finite() && y.is_finite() {
                let _ = write!(points, "{:.1},{:.1} ", f.x(*x), f.y(*y));
            }
        }
        let dash = s
            .dash
            .as_ref()
            .map(|d| format!(r#" stroke-dasharray="{d}""#))
            .unwrap_or_default();
        let _ = write!(
            out,
            r#"<polyline points="{}" fill="none" stroke="{}" stroke-width="2" stroke-linejoin="round"{dash}><title>{}</title></polyline>"#,
            points.trim_end(),
            s.color,
            escape_html(&s.label)
        );
        if let Some(m) = s.marker {
            // About 8 markers per curve, shifted by a fraction of the spacing per series.
            let len = s.x.len().min(s.y.len());
            let every = (len / 8).max(1);
            let offset = every * k / n;
            for i in (offset..len).step_by(every) {
                let (x, y) = (s.x[i], s.y[i]);
                if x.is_finite() && y.is_finite() {
                    marker(&mut out, m, f.x(x), f.y(y), 3.5, &s.color, true);
                }
            }
        }
    }
    out.push_str("</svg>");
    out
}
