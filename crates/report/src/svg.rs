//! Minimal hand-written SVG charts: line charts (torque curves) and grouped bar charts
//! (the paper's Fig. 7).
//!
//! Why not `plotters`: its chart layout measures text through a font backend (`ttf` →
//! font-kit → system fonts), which would tie report generation to fonts installed on the
//! machine; without it, labelled axes are not available. Two chart kinds with axes, ticks and a
//! legend are a few hundred lines, produce small, well-formed XML (the report is
//! XHTML-compatible), let the browser render text with its own fonts, and give full control over
//! escaping. Text widths are estimated (0.6 em per character) only to lay out the legend and
//! the bar groups, with generous spacing.

use std::fmt::Write;

use crate::format::escape_html;

/// Colour-blind-safe palette (Okabe–Ito).
pub const PALETTE: [&str; 8] = [
    "#444444", "#0072B2", "#009E73", "#D55E00", "#CC79A7", "#E69F00", "#56B4E9", "#F0E442",
];

const FONT: f64 = 12.0;
const SMALL: f64 = 11.0;

fn text_width(s: &str, size: f64) -> f64 {
    s.chars().count() as f64 * size * 0.6
}

/// Round numbers for axis ticks covering `[lo, hi]` with about `target` intervals.
pub fn nice_ticks(lo: f64, hi: f64, target: usize) -> (Vec<f64>, f64) {
    let span = (hi - lo).abs().max(f64::MIN_POSITIVE);
    let raw = span / target.max(1) as f64;
    let magnitude = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 2.5, 5.0, 10.0]
        .iter()
        .map(|m| m * magnitude)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * magnitude);
    let first = (lo / step).floor() * step;
    let mut ticks = Vec::new();
    let mut k = 0;
    loop {
        let t = first + k as f64 * step;
        ticks.push(if t.abs() < step * 1e-9 { 0.0 } else { t });
        if t >= hi - step * 1e-9 || k > 1000 {
            break;
        }
        k += 1;
    }
    (ticks, step)
}

/// Tick label with as many decimals as the step needs.
fn tick_label(v: f64, step: f64) -> String {
    let decimals = if step >= 1.0 {
        if (step - step.round()).abs() < 1e-9 {
            0
        } else {
            1
        }
    } else {
        let d = (-step.log10()).ceil() as usize;
        if ((step * 10f64.powi(d as i32)) - (step * 10f64.powi(d as i32)).round()).abs() > 1e-6 {
            d + 1
        } else {
            d
        }
    };
    crate::format::fixed(v, decimals)
}

/// Data range of the values, padded, optionally including zero; never empty.
fn range(values: impl Iterator<Item = f64>, include_zero: bool) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    if include_zero {
        lo = lo.min(0.0);
        hi = hi.max(0.0);
    }
    if hi - lo < 1e-12 * (1.0 + hi.abs()) {
        let d = if hi.abs() > 0.0 { hi.abs() * 0.1 } else { 1.0 };
        return (lo - d, hi + d);
    }
    let pad = 0.04 * (hi - lo);
    (
        if lo == 0.0 && include_zero {
            0.0
        } else {
            lo - pad
        },
        if hi == 0.0 && include_zero {
            0.0
        } else {
            hi + pad
        },
    )
}

/// One line of a [`LineChart`].
#[derive(Clone, Debug)]
pub struct LineSeries {
    pub label: String,
    pub color: String,
    pub dashed: bool,
    pub x: Vec<f64>,
    pub y: Vec<f64>,
}

/// A line chart with labelled axes and a legend.
#[derive(Clone, Debug)]
pub struct LineChart {
    pub title: String,
    /// A smaller second line under the title (e.g. why this task is shown).
    pub subtitle: Option<String>,
    pub x_label: String,
    pub y_label: String,
    pub series: Vec<LineSeries>,
    pub include_zero: bool,
    pub width: f64,
    pub height: f64,
}

/// Legend items laid out in rows under the title; returns (svg, height used).
fn legend(items: &[(String, String, bool, bool)], x0: f64, y0: f64, width: f64) -> (String, f64) {
    // (label, colour, dashed, is_bar)
    let mut out = String::new();
    let (mut x, mut y) = (x0, y0);
    let row = 18.0;
    for (label, color, dashed, bar) in items {
        let w = 26.0 + text_width(label, SMALL) + 16.0;
        if x + w > x0 + width && x > x0 {
            x = x0;
            y += row;
        }
        if *bar {
            let _ = write!(
                out,
                r#"<rect x="{:.1}" y="{:.1}" width="12" height="10" fill="{color}"/>"#,
                x + 4.0,
                y - 9.0
            );
        } else {
            let dash = if *dashed {
                r#" stroke-dasharray="6 3""#
            } else {
                ""
            };
            let _ = write!(
                out,
                r#"<line x1="{:.1}" y1="{:.1}" x2="{:.1}" y2="{:.1}" stroke="{color}" stroke-width="2.5"{dash}/>"#,
                x,
                y - 4.0,
                x + 20.0,
                y - 4.0
            );
        }
        let _ = write!(
            out,
            r#"<text x="{:.1}" y="{:.1}" font-size="{SMALL}">{}</text>"#,
            x + 26.0,
            y,
            escape_html(label)
        );
        x += w;
    }
    (out, y - y0 + row)
}

/// A centred line of text that never overflows the chart: when its estimated width exceeds
/// the room, `textLength` squeezes it to fit.
fn centred_text(out: &mut String, text: &str, width: f64, y: f64, size: f64, extra: &str) {
    let room = width - 24.0;
    let fit = if text_width(text, size) > room {
        format!(r#" textLength="{room:.0}" lengthAdjust="spacingAndGlyphs""#)
    } else {
        String::new()
    };
    let _ = write!(
        out,
        r#"<text x="{:.1}" y="{y:.1}" font-size="{size}" text-anchor="middle"{fit}{extra}>{}</text>"#,
        width / 2.0,
        escape_html(text)
    );
}

/// Opens the `<svg>` with a white background, the title and an optional subtitle; returns the
/// markup and the y where the legend starts.
fn svg_open(width: f64, height: f64, title: &str, subtitle: Option<&str>) -> (String, f64) {
    let mut out = format!(
        r##"<svg xmlns="http://www.w3.org/2000/svg" class="chart" viewBox="0 0 {width:.0} {height:.0}" width="{width:.0}" height="{height:.0}" role="img" aria-label="{t}"><title>{t}</title><rect x="0" y="0" width="{width:.0}" height="{height:.0}" fill="#ffffff"/>"##,
        t = escape_html(title)
    );
    centred_text(&mut out, title, width, 20.0, 14.0, r#" font-weight="600""#);
    match subtitle {
        Some(sub) if !sub.is_empty() => {
            centred_text(&mut out, sub, width, 37.0, SMALL, r##" fill="#555555""##);
            (out, 58.0)
        }
        _ => (out, 42.0),
    }
}

/// Axis frame, grid lines and tick labels; returns the y mapping.
struct Frame {
    left: f64,
    top: f64,
    w: f64,
    h: f64,
    x_lo: f64,
    x_hi: f64,
    y_lo: f64,
    y_hi: f64,
}

impl Frame {
    fn x(&self, v: f64) -> f64 {
        self.left + (v - self.x_lo) / (self.x_hi - self.x_lo) * self.w
    }
    fn y(&self, v: f64) -> f64 {
        self.top + (self.y_hi - v) / (self.y_hi - self.y_lo) * self.h
    }
}

fn y_axis(out: &mut String, f: &Frame, y_label: &str) {
    let (ticks, step) = nice_ticks(f.y_lo, f.y_hi, 6);
    for t in ticks
        .iter()
        .filter(|t| **t >= f.y_lo - 1e-9 * step && **t <= f.y_hi + 1e-9 * step)
    {
        let y = f.y(*t);
        let zero = t.abs() < step * 1e-9;
        let _ = write!(
            out,
            r#"<line x1="{:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="{}" stroke-width="1"/><text x="{:.1}" y="{:.1}" font-size="{SMALL}" text-anchor="end">{}</text>"#,
            f.left,
            f.left + f.w,
            if zero { "#888888" } else { "#e3e3e3" },
            f.left - 6.0,
            y + 4.0,
            tick_label(*t, step)
        );
    }
    let cy = f.top + f.h / 2.0;
    let _ = write!(
        out,
        r#"<text x="16" y="{cy:.1}" font-size="{FONT}" text-anchor="middle" transform="rotate(-90 16 {cy:.1})">{}</text>"#,
        escape_html(y_label)
    );
}

/// Renders a line chart as an `<svg>` element.
pub fn line_chart(chart: &LineChart) -> String {
    let (width, height) = (chart.width, chart.height);
    let left = 70.0;
    let right = 18.0;
    let (mut out, legend_y) = svg_open(width, height, &chart.title, chart.subtitle.as_deref());
    let items: Vec<_> = chart
        .series
        .iter()
        .map(|s| (s.label.clone(), s.color.clone(), s.dashed, false))
        .collect();
    let (legend_svg, legend_h) = legend(&items, left, legend_y, width - left - right);
    out.push_str(&legend_svg);
    let top = legend_y + legend_h + 4.0;
    let bottom = 50.0;
    let (x_lo, x_hi) = {
        let (lo, hi) = range(chart.series.iter().flat_map(|s| s.x.iter().copied()), false);
        // No padding on x: curves span the task.
        let lo2 = chart
            .series
            .iter()
            .flat_map(|s| s.x.iter().copied())
            .fold(f64::INFINITY, f64::min);
        let hi2 = chart
            .series
            .iter()
            .flat_map(|s| s.x.iter().copied())
            .fold(f64::NEG_INFINITY, f64::max);
        if lo2.is_finite() && hi2 > lo2 {
            (lo2, hi2)
        } else {
            (lo, hi)
        }
    };
    let (y_lo, y_hi) = range(
        chart.series.iter().flat_map(|s| s.y.iter().copied()),
        chart.include_zero,
    );
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
    let (ticks, step) = nice_ticks(x_lo, x_hi, 8);
    for t in ticks
        .iter()
        .filter(|t| **t >= x_lo - 1e-9 * step && **t <= x_hi + 1e-9 * step)
    {
        let x = f.x(*t);
        let _ = write!(
            out,
            r##"<line x1="{x:.1}" y1="{:.1}" x2="{x:.1}" y2="{:.1}" stroke="#888888" stroke-width="1"/><text x="{x:.1}" y="{:.1}" font-size="{SMALL}" text-anchor="middle">{}</text>"##,
            f.top + f.h,
            f.top + f.h + 5.0,
            f.top + f.h + 18.0,
            tick_label(*t, step)
        );
    }
    let _ = write!(
        out,
        r##"<rect x="{left:.1}" y="{top:.1}" width="{:.1}" height="{:.1}" fill="none" stroke="#888888" stroke-width="1"/><text x="{:.1}" y="{:.1}" font-size="{FONT}" text-anchor="middle">{}</text>"##,
        f.w,
        f.h,
        left + f.w / 2.0,
        height - 10.0,
        escape_html(&chart.x_label)
    );
    // Drawn last-to-first, each later series a little wider, so coinciding curves (a spring-only
    // and a hybrid variant often have identical torques) show as nested bands instead of
    // hiding each other, and the first series (the reference, dashed) lies on top.
    for (k, s) in chart.series.iter().enumerate().rev() {
        let stroke = 1.8 + 0.7 * k.saturating_sub(1) as f64;
        let mut points = String::new();
        for (x, y) in s.x.iter().zip(&s.y) {
            if x.is_finite() && y.is_finite() {
                let _ = write!(points, "{:.1},{:.1} ", f.x(*x), f.y(*y));
            }
        }
        let dash = if s.dashed {
            r#" stroke-dasharray="6 3""#
        } else {
            ""
        };
        let _ = write!(
            out,
            r#"<polyline points="{}" fill="none" stroke="{}" stroke-width="{stroke:.1}" stroke-linejoin="round"{dash}><title>{}</title></polyline>"#,
            points.trim_end(),
            s.color,
            escape_html(&s.label)
        );
    }
    out.push_str("</svg>");
    out
}

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
    pub min_width: f64,
    pub height: f64,
}

/// Renders a grouped bar chart as an `<svg>` element.
pub fn bar_chart(chart: &BarChart) -> String {
    let n_series = chart.series.len().max(1);
    let bar = 16.0;
    let label_w = chart
        .categories
        .iter()
        .map(|(a, b)| text_width(a, SMALL).max(text_width(b, 10.0)))
        .fold(0.0, f64::max);
    let group = (n_series as f64 * bar + 20.0).max(label_w + 12.0);
    let left = 70.0;
    let right = 18.0;
    let width = (left + right + group * chart.categories.len() as f64).max(chart.min_width);
    let height = chart.height;
    let (mut out, legend_y) = svg_open(width, height, &chart.title, None);
    let items: Vec<_> = chart
        .series
        .iter()
        .map(|(l, c)| (l.clone(), c.clone(), false, true))
        .collect();
    let (legend_svg, legend_h) = legend(&items, left, legend_y, width - left - right);
    out.push_str(&legend_svg);
    let top = legend_y + legend_h + 4.0;
    let bottom = 44.0;
    let (y_lo, y_hi) = range(chart.values.iter().flatten().copied(), true);
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
            let y = f.y(v);
            let (ry, rh) = if v >= 0.0 {
                (y, zero - y)
            } else {
                (zero, y - zero)
            };
            let _ = write!(
                out,
                r#"<rect x="{:.1}" y="{ry:.1}" width="{:.1}" height="{:.1}" fill="{color}"><title>{} {}: {} %</title></rect>"#,
                bars_x + s as f64 * bar,
                bar - 2.0,
                rh.max(0.5),
                escape_html(name),
                escape_html(label),
                crate::format::percent(v)
            );
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_round_and_cover_the_range() {
        let (t, step) = nice_ticks(-63.2, 8.4, 6);
        assert_eq!(step, 20.0);
        assert_eq!(t.first().copied(), Some(-80.0));
        assert!(*t.last().unwrap() >= 8.4);
        let (t, step) = nice_ticks(0.0, 2.5, 8);
        assert!((step - 0.5).abs() < 1e-12, "{step}");
        assert_eq!(t.len(), 6);
        assert_eq!(tick_label(0.25, 0.25), "0.25");
        assert_eq!(tick_label(2.5, 2.5), "2.5");
        assert_eq!(tick_label(-40.0, 20.0), "-40");
    }

    #[test]
    fn ranges_are_never_empty() {
        let (lo, hi) = range([3.0, 3.0].into_iter(), false);
        assert!((lo - 2.7).abs() < 1e-12 && (hi - 3.3).abs() < 1e-12);
        assert_eq!(range(std::iter::empty(), true), (0.0, 1.0));
        let (lo, hi) = range([-5.0, 10.0].into_iter(), true);
        assert!(lo < -5.0 && hi > 10.0);
        assert_eq!(range([1.0, 2.0].into_iter(), true).0, 0.0);
    }

    #[test]
    fn charts_escape_labels_and_are_single_svg_elements() {
        let line = line_chart(&LineChart {
            title: "M<1>".into(),
            subtitle: Some("a very long subtitle that certainly does not fit into the width of this small chart at all".into()),
            x_label: "time [s]".into(),
            y_label: "torque [N·m]".into(),
            series: vec![LineSeries {
                label: "UB & co".into(),
                color: PALETTE[0].into(),
                dashed: false,
                x: vec![0.0, 1.0, 2.0],
                y: vec![1.0, -2.0, 3.0],
            }],
            include_zero: true,
            width: 600.0,
            height: 300.0,
        });
        assert!(line.starts_with("<svg") && line.ends_with("</svg>"));
        assert_eq!(line.matches("<svg").count(), 1);
        assert!(line.contains("M&lt;1&gt;") && line.contains("UB &amp; co"));
        assert_eq!(
            line.matches("textLength").count(),
            1,
            "only the long subtitle is squeezed"
        );
        let bars = bar_chart(&BarChart {
            title: "Springs".into(),
            y_label: "%".into(),
            categories: vec![("SB1".into(), "K42 + K43".into())],
            series: vec![("ΔQTR".into(), PALETTE[1].into())],
            values: vec![vec![-60.0]],
            min_width: 300.0,
            height: 300.0,
        });
        assert_eq!(bars.matches("<rect").count(), 4, "{bars}");
    }
}
