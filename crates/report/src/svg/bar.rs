//! Grouped bar charts (the paper's Fig. 7).

use std::fmt::Write;

use crate::format::escape_html;

use super::primitives::*;

/// A grouped bar chart: one group per category, one bar per series.
#[derive(Clone, Debug)]
pub struct BarChart {
    pub title: String,
    pub y_label: String,
    /// Category labels: a name and a smaller second line (e.g. `SB3` / `m4 + K43`).
    pub categories: Vec<(String, String)>,
    /// Series labels and colours.
    pub series: Vec<(String, String)>,
    /// `values[category][series]`.
    pub values: Vec<Vec<f64>>,
    /// Bars beyond ±this are drawn to it, with a break mark and their value printed, so one
    /// outlier cannot flatten the others. `None`: no clipping.
    pub clip: Option<f64>,
    pub min_width: f64,
    pub height: f64,
}

/// Renders a grouped bar chart of percentages as an `<svg>` element.
pub fn bar_chart(chart: &BarChart) -> String {
    bar_chart_in(chart, "%", crate::format::percent)
}

/// [`bar_chart`] of values in `unit` (`N·m`), each written by `number` in its tooltip (with the
/// unit) and beside a clipped bar.
pub fn bar_chart_in(chart: &BarChart, unit: &str, number: fn(f64) -> String) -> String {
    let n_series = chart.series.len().max(1);
    let bar = 16.0;
    let label_w = chart
        .categories
        .iter()
        .map(|(a, b)| text_width(a, SMALL).max(text_width(b, 10.0)))
        .fold(0.0, f64::max);
    let group = (n_series as f64 * bar + 20.0).max(label_w + 12.0);
    let clip = chart.clip.filter(|c| c.is_finite() && *c > 0.0);
    let shown = |v: f64| match clip {
        Some(c) => v.clamp(-c, c),
        None => v,
    };
    let clipped_any = chart
        .values
        .iter()
        .flatten()
        .any(|v| v.is_finite() && shown(*v) != *v);
    let (mut y_lo, mut y_hi) = range(chart.values.iter().flatten().copied().map(shown), true);
    if clipped_any {
        // Room above (below) a clipped bar for its printed value.
        let pad = 0.12 * (y_hi - y_lo);
        if chart.values.iter().flatten().any(|v| shown(*v) < *v) {
            y_hi += pad;
        }
        if chart.values.iter().flatten().any(|v| shown(*v) > *v) {
            y_lo -= pad;
        }
    }
    let left = left_margin(y_lo, y_hi);
    let right = 18.0;
    let width = (left + right + group * chart.categories.len() as f64).max(chart.min_width);
    let height = chart.height;
    let (mut out, legend_y) = svg_open(width, height, &chart.title, None);
    let items: Vec<LegendItem> = chart
        .series
        .iter()
        .map(|(l, c)| LegendItem {
            label: l.clone(),
            color: c.clone(),
            dash: None,
            marker: None,
            bar: true,
        })
        .collect();
    let (legend_svg, legend_h) = legend(&items, left, legend_y, width - left - right);
    out.push_str(&legend_svg);
    let mut top = legend_y + legend_h + 4.0;
    if let (true, Some(c)) = (clipped_any, clip) {
        let text = format!(
            "bars beyond ±{} are cut (zigzag) and their value printed",
            crate::format::compact(c)
        );
        top += note_lines(&mut out, &text, left, top + 6.0, width - left - right) + 2.0;
    }
    let bottom = 44.0;
    let plot_w = width - left - right;
    let f = Frame {
        left,
        top,
        w: plot_w,
        h: height - top - bottom,
        x_lo: 0.0,
        x_hi: 1.0,
        y_lo,
        y_hi,
    };
    y_axis(&mut out, &f, &chart.y_label);
    let used = group * chart.categories.len() as f64;
    let x0 = left + (plot_w - used) / 2.0;
    let zero = f.y(0.0);
    for (c, (name, sub)) in chart.categories.iter().enumerate() {
        let gx = x0 + c as f64 * group;
        let bars_x = gx + (group - n_series as f64 * bar) / 2.0;
        for (s, (label, color)) in chart.series.iter().enumerate() {
            let v = chart
                .values
                .get(c)
                .and_then(|r| r.get(s))
                .copied()
                .unwrap_or(f64::NAN);
            if !v.is_finite() {
                continue;
            }
            let drawn = shown(v);
            let y = f.y(drawn);
            let (ry, rh) = if drawn >= 0.0 {
                (y, zero - y)
            } else {
                (zero, y - zero)
            };
            let bx = bars_x + s as f64 * bar;
            let _ = write!(
                out,
                r#"<rect x="{bx:.1}" y="{ry:.1}" width="{:.1}" height="{:.1}" fill="{color}"><title>{} {}: {} {}</title></rect>"#,
                bar - 2.0,
                rh.max(0.5),
                escape_html(name),
                escape_html(label),
                number(v),
                escape_html(unit)
            );
            if drawn != v {
                // A white zigzag across the bar near its end, and the true value beyond it.
                let (edge, dir) = if v > 0.0 { (ry, 1.0) } else { (ry + rh, -1.0) };
                let zy = edge + dir * 10.0;
                let _ = write!(
                    out,
                    r##"<polyline points="{:.1},{:.1} {:.1},{:.1} {:.1},{:.1} {:.1},{:.1}" fill="none" stroke="#ffffff" stroke-width="2.2"/><text x="{:.1}" y="{:.1}" font-size="10.5" font-weight="600" text-anchor="middle">{}</text>"##,
                    bx - 1.0,
                    zy + 3.0,
                    bx + 4.0,
                    zy - 3.0,
                    bx + 10.0,
                    zy + 3.0,
                    bx + bar - 1.0,
                    zy - 3.0,
                    bx + (bar - 2.0) / 2.0,
                    if v > 0.0 { edge - 4.0 } else { edge + 12.0 },
                    escape_html(&number(v))
                );
            }
        }
        let cx = gx + group / 2.0;
        let _ = write!(
            out,
            r##"<text x="{cx:.1}" y="{:.1}" font-size="{SMALL}" font-weight="600" text-anchor="middle">{}</text><text x="{cx:.1}" y="{:.1}" font-size="10" fill="#555555" text-anchor="middle">{}</text>"##,
            f.top + f.h + 16.0,
            escape_html(name),
            f.top + f.h + 30.0,
            escape_html(sub)
        );
    }
    let _ = write!(
        out,
        r##"<line x1="{left:.1}" y1="{zero:.1}" x2="{:.1}" y2="{zero:.1}" stroke="#444444" stroke-width="1.2"/><rect x="{left:.1}" y="{top:.1}" width="{:.1}" height="{:.1}" fill="none" stroke="#888888" stroke-width="1"/>"##,
        left + f.w,
        f.w,
        f.h
    );
    out.push_str("</svg>");
    out
}
