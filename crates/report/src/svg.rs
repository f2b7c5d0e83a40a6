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

mod placement;
use placement::Rect;

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

/// Tick label with as many decimals as the step needs; steps below 1e-3 or from 1e5 up are
/// written with an exponent (`2e-11`, `1.5e6`) so a label never runs to a dozen digits.
fn tick_label(v: f64, step: f64) -> String {
    if !(1e-3..1e5).contains(&step) {
        if v.abs() < step * 1e-9 {
            return "0".into();
        }
        // Enough significant digits for neighbouring ticks to differ.
        let digits = ((v.abs().log10().floor() - step.log10().floor()).max(0.0) as usize).min(6);
        let s = format!("{v:.digits$e}");
        return s.replace("e0", "").replace("e-0", "e-");
    }
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

/// A marker shape, drawn every few samples on a curve and at each point of a scatter chart, so
/// curves stay distinguishable where they coincide and without colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Marker {
    Circle,
    Square,
    Triangle,
    Diamond,
}

impl Marker {
    pub const ALL: [Marker; 4] = [
        Marker::Circle,
        Marker::Square,
        Marker::Triangle,
        Marker::Diamond,
    ];
}

/// One marker centred at (x, y) with "radius" r; hollow markers have a white fill.
fn marker(out: &mut String, m: Marker, x: f64, y: f64, r: f64, color: &str, hollow: bool) {
    let fill = if hollow { "#ffffff" } else { color };
    let style = format!(r#"fill="{fill}" stroke="{color}" stroke-width="1.4""#);
    let _ = match m {
        Marker::Circle => write!(
            out,
            r#"<circle cx="{x:.1}" cy="{y:.1}" r="{r:.1}" {style}/>"#
        ),
        Marker::Square => write!(
            out,
            r#"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" {style}/>"#,
            x - r * 0.9,
            y - r * 0.9,
            r * 1.8,
            r * 1.8
        ),
        Marker::Triangle => write!(
            out,
            r#"<polygon points="{:.1},{:.1} {:.1},{:.1} {:.1},{:.1}" {style}/>"#,
            x,
            y - r * 1.15,
            x - r,
            y + r * 0.75,
            x + r,
            y + r * 0.75
        ),
        Marker::Diamond => write!(
            out,
            r#"<polygon points="{:.1},{:.1} {:.1},{:.1} {:.1},{:.1} {:.1},{:.1}" {style}/>"#,
            x,
            y - r * 1.2,
            x + r,
            y,
            x,
            y + r * 1.2,
            x - r,
            y
        ),
    };
}

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

/// One legend entry.
struct LegendItem {
    label: String,
    color: String,
    dash: Option<String>,
    marker: Option<Marker>,
    bar: bool,
}

/// Legend items laid out in rows under the title; returns (svg, height used).
fn legend(items: &[LegendItem], x0: f64, y0: f64, width: f64) -> (String, f64) {
    let mut out = String::new();
    let (mut x, mut y) = (x0, y0);
    let row = 18.0;
    for item in items {
        let label = &item.label;
        let color = &item.color;
        let w = 30.0 + text_width(label, SMALL) + 16.0;
        if x + w > x0 + width && x > x0 {
            x = x0;
            y += row;
        }
        if item.bar {
            let _ = write!(
                out,
                r#"<rect x="{:.1}" y="{:.1}" width="12" height="10" fill="{color}"/>"#,
                x + 4.0,
                y - 9.0
            );
        } else {
            let dash = item
                .dash
                .as_ref()
                .map(|d| format!(r#" stroke-dasharray="{d}""#))
                .unwrap_or_default();
            let _ = write!(
                out,
                r#"<line x1="{:.1}" y1="{:.1}" x2="{:.1}" y2="{:.1}" stroke="{color}" stroke-width="2.5"{dash}/>"#,
                x,
                y - 4.0,
                x + 24.0,
                y - 4.0
            );
            if let Some(m) = item.marker {
                marker(&mut out, m, x + 12.0, y - 4.0, 3.5, color, true);
            }
        }
        let _ = write!(
            out,
            r#"<text x="{:.1}" y="{:.1}" font-size="{SMALL}">{}</text>"#,
            x + 30.0,
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

/// The widest y tick label of a range, in px: the left margin is made to fit it, so a tick
/// label never runs over the axis title or out of the chart.
fn y_label_room(y_lo: f64, y_hi: f64) -> f64 {
    let (ticks, step) = nice_ticks(y_lo, y_hi, 6);
    ticks
        .iter()
        .map(|t| text_width(&tick_label(*t, step), SMALL))
        .fold(0.0, f64::max)
}

/// Left margin for a y range: axis title, gap, the widest tick label, tick gap.
fn left_margin(y_lo: f64, y_hi: f64) -> f64 {
    (30.0 + y_label_room(y_lo, y_hi) + 10.0).max(58.0)
}

/// The x ticks below the frame, the frame itself and the x-axis title (`height`: the chart's).
fn x_axis(out: &mut String, f: &Frame, height: f64, x_label: &str) {
    let (ticks, step) = nice_ticks(f.x_lo, f.x_hi, 8);
    for t in ticks
        .iter()
        .filter(|t| **t >= f.x_lo - 1e-9 * step && **t <= f.x_hi + 1e-9 * step)
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
        r##"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" fill="none" stroke="#888888" stroke-width="1"/><text x="{:.1}" y="{:.1}" font-size="{FONT}" text-anchor="middle">{}</text>"##,
        f.left,
        f.top,
        f.w,
        f.h,
        f.left + f.w / 2.0,
        height - 10.0,
        escape_html(x_label)
    );
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

/// A small grey note inside a chart (e.g. the noise floor), wrapped at word boundaries to
/// `width`; returns the height used.
fn note_lines(out: &mut String, text: &str, x: f64, y: f64, width: f64) -> f64 {
    let mut lines: Vec<String> = Vec::new();
    for word in text.split(' ') {
        match lines.last_mut() {
            Some(line) if text_width(&format!("{line} {word}"), 10.5) <= width => {
                line.push(' ');
                line.push_str(word);
            }
            _ => lines.push(word.to_string()),
        }
    }
    for (k, line) in lines.iter().enumerate() {
        let _ = write!(
            out,
            r##"<text x="{x:.1}" y="{:.1}" font-size="10.5" fill="#555555" font-style="italic">{}</text>"##,
            y + 14.0 * k as f64,
            escape_html(line)
        );
    }
    14.0 * lines.len() as f64
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

/// One point of a [`ScatterChart`].
#[derive(Clone, Debug)]
pub struct ScatterPoint {
    pub x: f64,
    pub y: f64,
    /// Drawn as the marker's size: area proportional to `size` (≥ 0) up to the chart's
    /// `size_max`, where larger values are drawn at the largest size.
    pub size: f64,
    pub color: String,
    pub marker: Marker,
    /// Tooltip.
    pub label: String,
    /// Text written next to the point (e.g. the recommended variants), ringed.
    pub callout: Option<String>,
}

/// A scatter chart: the Pareto view of the decision section.
#[derive(Clone, Debug)]
pub struct ScatterChart {
    pub title: String,
    pub subtitle: Option<String>,
    pub x_label: String,
    pub y_label: String,
    pub points: Vec<ScatterPoint>,
    /// Legend of colours and markers: (label, colour, marker).
    pub legend: Vec<(String, String, Marker)>,
    /// The size scale's top and its description, e.g. (12.8, "ΔR").
    pub size_max: f64,
    pub size_label: String,
    /// A horizontal band (y from, y to) with a label, e.g. the equivalence tolerance.
    pub band: Option<(f64, f64, String)>,
    /// Points of the non-dominated front, joined by a step line.
    pub front: Vec<(f64, f64)>,
    pub width: f64,
    pub height: f64,
}

/// Marker radius for a size value: 3.5 px at 0, 11 px at the top of the scale (area ∝ value).
fn scatter_radius(size: f64, max: f64) -> f64 {
    let t = if max > 0.0 {
        (size.max(0.0) / max).min(1.0)
    } else {
        0.0
    };
    (3.5f64.powi(2) + t * (11.0f64.powi(2) - 3.5f64.powi(2))).sqrt()
}

/// Renders a scatter chart as an `<svg>` element.
pub fn scatter_chart(chart: &ScatterChart) -> String {
    let (width, height) = (chart.width, chart.height);
    let right = 24.0;
    let ys = chart
        .points
        .iter()
        .map(|p| p.y)
        .chain(chart.band.iter().flat_map(|(a, b, _)| [*a, *b]));
    let (y_lo, y_hi) = range(ys, false);
    let left = left_margin(y_lo, y_hi);
    let (mut out, legend_y) = svg_open(width, height, &chart.title, chart.subtitle.as_deref());
    let mut items: Vec<LegendItem> = chart
        .legend
        .iter()
        .map(|(l, c, m)| LegendItem {
            label: l.clone(),
            color: c.clone(),
            dash: Some("0 100".into()),
            marker: Some(*m),
            bar: false,
        })
        .collect();
    items.push(LegendItem {
        label: if chart.size_max > 0.0 {
            format!(
                "marker area ∝ {} (largest: {} % and above)",
                chart.size_label,
                crate::format::compact(chart.size_max)
            )
        } else {
            format!("{} is 0 for every variant", chart.size_label)
        },
        color: "#ffffff".into(),
        dash: None,
        marker: None,
        bar: false,
    });
    let (legend_svg, legend_h) = legend(&items, left, legend_y, width - left - right);
    out.push_str(&legend_svg);
    let top = legend_y + legend_h + 8.0;
    let bottom = 50.0;
    let (x_lo, x_hi) = range(chart.points.iter().map(|p| p.x), true);
    // Room left of the lightest points for their markers, clear of the tick labels.
    let x_lo = x_lo - 0.04 * (x_hi - x_lo);
    let (w, h) = (width - left - right, height - top - bottom);
    // Room for the largest marker and its ring inside the frame on every side, so none is
    // clipped at an edge.
    let pad = chart
        .points
        .iter()
        .map(|p| scatter_radius(p.size, chart.size_max))
        .fold(0.0f64, f64::max)
        + 5.0;
    let (dy, dx) = (
        pad / h.max(1.0) * (y_hi - y_lo),
        pad / w.max(1.0) * (x_hi - x_lo),
    );
    let f = Frame {
        left,
        top,
        w,
        h,
        x_lo,
        x_hi: x_hi + dx,
        y_lo: y_lo - dy,
        y_hi: y_hi + dy,
    };
    let mut band_label = None;
    if let Some((a, b, label)) = &chart.band {
        let (ya, yb) = (f.y(*a), f.y(*b));
        band_label = Some(Rect {
            x0: left + f.w - 6.0 - text_width(label, 10.5),
            y0: ya.max(yb) - 3.0 - 9.0,
            x1: left + f.w - 6.0,
            y1: ya.max(yb) - 3.0 + 2.0,
        });
        let _ = write!(
            out,
            r##"<rect x="{left:.1}" y="{:.1}" width="{:.1}" height="{:.1}" fill="#fff3cd"/><text x="{:.1}" y="{:.1}" font-size="10.5" fill="#7a5b00" text-anchor="end">{}</text>"##,
            ya.min(yb),
            f.w,
            (ya - yb).abs().max(1.0),
            left + f.w - 6.0,
            ya.max(yb) - 3.0,
            escape_html(label)
        );
    }
    y_axis(&mut out, &f, &chart.y_label);
    x_axis(&mut out, &f, height, &chart.x_label);
    // The front over the band (it lies inside it), under the markers and the callouts' cards.
    if chart.front.len() > 1 {
        let mut pts = String::new();
        for (k, (x, y)) in chart.front.iter().enumerate() {
            if k > 0 {
                // Step: the next point's mass at the previous point's ΔQTR.
                let _ = write!(pts, "{:.1},{:.1} ", f.x(*x), f.y(chart.front[k - 1].1));
            }
            let _ = write!(pts, "{:.1},{:.1} ", f.x(*x), f.y(*y));
        }
        let _ = write!(
            out,
            r##"<polyline points="{}" fill="none" stroke="#333333" stroke-width="1.4" stroke-dasharray="5 3"><title>non-dominated front (no variant is lighter and better on ΔQTR)</title></polyline>"##,
            pts.trim_end()
        );
    }
    // The callouts' white cards go here, under the markers (inserted once they are placed).
    let cards_at = out.len();
    // Points drawn at the same pixel (e.g. every spring-only variant: no added mass, the same
    // ΔQTR) are one marker, the largest of them, with their count beside it and all of them
    // in its tooltip.
    let mut groups: Vec<(i64, i64, Vec<&ScatterPoint>)> = Vec::new();
    for p in &chart.points {
        if !(p.x.is_finite() && p.y.is_finite()) {
            continue;
        }
        let key = (f.x(p.x).round() as i64, f.y(p.y).round() as i64);
        match groups
            .iter_mut()
            .find(|g| g.0 == key.0 && g.1 == key.1 && g.2[0].marker == p.marker)
        {
            Some(g) => g.2.push(p),
            None => groups.push((key.0, key.1, vec![p])),
        }
    }
    // Largest markers first, so small ones stay visible on top.
    groups.sort_by(|a, b| {
        let size = |g: &[&ScatterPoint]| g.iter().map(|p| p.size).fold(0.0f64, f64::max);
        size(&b.2).total_cmp(&size(&a.2))
    });
    // Count labels that would overprint another are left out (the tooltip still lists the
    // group).
    let mut counts: Vec<(f64, f64)> = Vec::new();
    // What the callouts must not overprint: markers, counts, the band's label, then rings and
    // the callouts themselves.
    let mut obstacles: Vec<Rect> = band_label.into_iter().collect();
    for (_, _, g) in &groups {
        let big = g
            .iter()
            .copied()
            .max_by(|a, b| a.size.total_cmp(&b.size))
            .expect("a group has a point");
        let (x, y) = (f.x(big.x), f.y(big.y));
        let r = scatter_radius(big.size, chart.size_max);
        let tip = if g.len() == 1 {
            big.label.clone()
        } else {
            let mut lines: Vec<String> = g.iter().take(12).map(|p| p.label.clone()).collect();
            if g.len() > 12 {
                lines.push(format!("… and {} more", g.len() - 12));
            }
            format!("{} variants at this point:\n{}", g.len(), lines.join("\n"))
        };
        let _ = write!(out, "<g><title>{}</title>", escape_html(&tip));
        marker(&mut out, big.marker, x, y, r, &big.color, false);
        // Triangles and diamonds reach 1.2 r above or below their centre.
        obstacles.push(Rect::around(x, y, r + 1.0, 1.2 * r + 1.0));
        let (cx, cy) = (x + r + 2.0, y - r + 2.0);
        let free = counts
            .iter()
            .all(|&(px, py)| (px - cx).abs() > 24.0 || (py - cy).abs() > 11.0);
        if g.len() > 2 && free {
            counts.push((cx, cy));
            obstacles.push(Rect {
                x0: cx,
                y0: cy - 8.0,
                x1: cx + text_width(&format!("×{}", g.len()), 10.0),
                y1: cy + 2.0,
            });
            let _ = write!(
                out,
                r##"<text x="{cx:.1}" y="{cy:.1}" font-size="10" fill="#333333">×{}</text>"##,
                g.len()
            );
        }
        out.push_str("</g>");
    }
    // Callouts: points at nearly the same pixel share one label; labels are stacked so none
    // overprints another.
    let mut callouts: Vec<(f64, f64, f64, String)> = Vec::new();
    for p in chart.points.iter().filter(|p| p.callout.is_some()) {
        if !(p.x.is_finite() && p.y.is_finite()) {
            continue;
        }
        let (x, y) = (f.x(p.x), f.y(p.y));
        let r = scatter_radius(p.size, chart.size_max) + 4.0;
        let text = p.callout.clone().unwrap_or_default();
        match callouts
            .iter_mut()
            .find(|c| (c.0 - x).abs() < 6.0 && (c.1 - y).abs() < 6.0)
        {
            Some(c) => {
                c.2 = c.2.max(r);
                c.3 = format!("{}; {text}", c.3);
            }
            None => callouts.push((x, y, r, text)),
        }
    }
    // Each label goes where it overprints no marker, ring, count or other label
    // ([`placement`]); a label moved away from its point is tied to the ring by a leader.
    for (x, y, r, _) in &callouts {
        obstacles.push(Rect::around(*x, *y, r + 1.0, r + 1.0));
    }
    let bounds = Rect {
        x0: left,
        y0: top,
        x1: left + f.w,
        y1: top + f.h,
    };
    let mut cards = String::new();
    for (x, y, r, text) in &callouts {
        let tw = text_width(text, SMALL);
        // A white card under the text hides the front's dashed step where it runs through
        // the label (a halo alone leaves it showing between the letters); bold text runs
        // about 10 % wider than the estimate, hence the wider card, which is also the box
        // kept clear of everything else.
        let card = tw * 1.12 + 4.0;
        let b = placement::place(*x, *y, *r, card, SMALL + 3.0, &obstacles, &bounds);
        obstacles.push(b);
        // The text hugs the side of the card nearest the point.
        let (tx, anchor) = if b.x0 >= *x {
            (b.x0 + 2.0, "start")
        } else if b.x1 <= *x {
            (b.x1 - 2.0, "end")
        } else {
            ((b.x0 + b.x1) / 2.0, "middle")
        };
        let ty = b.y0 + 0.8 * SMALL + 1.0;
        let _ = write!(
            cards,
            r##"<rect x="{:.1}" y="{:.1}" width="{card:.1}" height="{:.1}" fill="#ffffff" class="card"/>"##,
            b.x0,
            b.y0,
            SMALL + 3.0,
        );
        let _ = write!(
            out,
            r##"<circle cx="{x:.1}" cy="{y:.1}" r="{r:.1}" fill="none" stroke="#111111" stroke-width="1.6"/>"##
        );
        if b.distance(*x, *y) > r + placement::GAP + placement::CLEARANCE + 1.0 {
            // From the ring's edge towards the nearest point of the card.
            let (nx, ny) = (x.clamp(b.x0, b.x1), y.clamp(b.y0, b.y1));
            let d = (nx - x).hypot(ny - y).max(1e-9);
            let _ = write!(
                out,
                r##"<line x1="{:.1}" y1="{:.1}" x2="{nx:.1}" y2="{ny:.1}" stroke="#111111" stroke-width="0.8" class="leader"/>"##,
                x + (nx - x) * r / d,
                y + (ny - y) * r / d
            );
        }
        let _ = write!(
            out,
            r##"<text x="{tx:.1}" y="{ty:.1}" font-size="{SMALL}" font-weight="600" text-anchor="{anchor}" stroke="#ffffff" stroke-width="3" paint-order="stroke" class="callout">{}</text>"##,
            escape_html(text)
        );
    }
    out.insert_str(cards_at, &cards);
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
            y_unit: "N·m".into(),
            series: vec![LineSeries {
                label: "UB & co".into(),
                color: PALETTE[0].into(),
                dash: None,
                marker: None,
                x: vec![0.0, 1.0, 2.0],
                y: vec![1.0, -2.0, 3.0],
            }],
            include_zero: true,
            noise_scale: None,
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
            clip: None,
            min_width: 300.0,
            height: 300.0,
        });
        assert_eq!(bars.matches("<rect").count(), 4, "{bars}");
    }

    fn series(label: &str, y: Vec<f64>) -> LineSeries {
        LineSeries {
            label: label.into(),
            color: PALETTE[1].into(),
            dash: None,
            marker: Some(Marker::Square),
            x: (0..y.len()).map(|k| k as f64).collect(),
            y,
        }
    }

    fn chart(series: Vec<LineSeries>, noise_scale: Option<f64>) -> LineChart {
        LineChart {
            title: "static torque — M1".into(),
            subtitle: None,
            x_label: "time [s]".into(),
            y_label: "motor torque [N·m]".into(),
            y_unit: "N·m".into(),
            series,
            include_zero: true,
            noise_scale,
            width: 560.0,
            height: 330.0,
        }
    }

    #[test]
    fn round_off_below_the_noise_floor_is_drawn_as_zero() {
        // A balanced motor's static torque: ±1e-11 N·m of round-off, in a figure whose other
        // charts reach 250 N·m. The floor is 1e-6 · 250 = 2.5e-4 N·m: every value is below it.
        let noise = vec![1e-11, -2e-11, 0.0, 1.5e-11, -0.7e-11];
        let (out, floor, silenced) = denoise(&[series("SB1", noise.clone())], Some(250.0));
        assert_eq!(floor, 2.5e-4);
        assert!(out[0].y.iter().all(|v| *v == 0.0));
        assert_eq!(silenced, vec!["SB1".to_string()]);
        let svg = line_chart(&chart(vec![series("SB1", noise.clone())], Some(250.0)));
        assert!(
            svg.contains("every curve: all values below the noise floor (2.5e-4 N·m"),
            "{svg}"
        );
        // The axis then shows the fallback ±1 range, not ±2e-11.
        assert!(!svg.contains("e-11"), "{svg}");
        // Values above the floor are kept exactly; a series with signal is not silenced, and
        // there is then no note (the change is far below a pixel).
        let mixed = vec![3.0, 1e-9, -4.0];
        let (out, floor, silenced) = denoise(&[series("UB", mixed.clone())], None);
        assert_eq!(out[0].y, vec![3.0, 0.0, -4.0]);
        assert_eq!(floor, 4e-6);
        assert!(silenced.is_empty());
        let svg = line_chart(&chart(vec![series("UB", mixed)], None));
        assert!(!svg.contains("noise floor"), "{svg}");
        // Without a figure scale the chart's own scale applies: 1e-11 alone is its own signal.
        let (out, _, silenced) = denoise(&[series("SB1", noise.clone())], None);
        assert_eq!(out[0].y, noise);
        assert!(silenced.is_empty());
    }

    #[test]
    fn tick_labels_stay_short_and_fit_the_margin() {
        // The ±2e-11 chart of round-off: exponent labels, never "-0.00000000002".
        let (ticks, step) = nice_ticks(-2.2e-11, 2.2e-11, 6);
        let labels: Vec<String> = ticks.iter().map(|t| tick_label(*t, step)).collect();
        assert!(labels.contains(&"-2e-11".to_string()), "{labels:?}");
        assert!(labels.contains(&"0".to_string()), "{labels:?}");
        assert!(labels.iter().all(|l| l.len() <= 8), "{labels:?}");
        assert_eq!(tick_label(1.4e6, 2e5), "1.4e6");
        assert_eq!(tick_label(150000.0, 50000.0), "150000");
        // The margin grows with the widest label: 5 characters at 0.6 em of 11 px = 33 px.
        assert!((y_label_room(-2000.0, 1000.0) - 5.0 * 6.6).abs() < 1e-9);
        assert!(left_margin(-2000.0, 1000.0) >= 30.0 + 33.0);
    }

    #[test]
    fn an_outlier_bar_is_clipped_with_its_value_printed() {
        let bars = bar_chart(&BarChart {
            title: "Pendulum".into(),
            y_label: "%".into(),
            categories: vec![("SB1".into(), "m1".into()), ("SB2".into(), "K10".into())],
            series: vec![
                ("ΔQTR".into(), PALETTE[1].into()),
                ("ΔR".into(), PALETTE[5].into()),
            ],
            values: vec![vec![-90.0, 21768.0], vec![-85.0, 0.0]],
            clip: Some(180.0),
            min_width: 300.0,
            height: 300.0,
        });
        assert!(bars.contains(">+21768.00</text>"), "{bars}");
        assert!(bars.contains("bars beyond ±180 are cut"), "{bars}");
        // No tick reaches the outlier: the axis stops near the clip.
        assert!(!bars.contains(">20000<"), "{bars}");
    }

    #[test]
    fn markers_are_staggered_between_series() {
        let a = series("A", vec![1.0; 16]);
        let mut b = series("B", vec![1.0; 16]);
        b.marker = Some(Marker::Triangle);
        let svg = line_chart(&chart(vec![a, b], None));
        // 16 samples: a marker every 2; series 0 starts at 0, series 1 at 1: 8 each, + legend.
        assert_eq!(
            svg.matches("<rect x=").count() - 2,
            8 + 1,
            "squares (minus background, frame)"
        );
        assert_eq!(svg.matches("<polygon").count(), 8 + 1, "triangles");
    }

    #[test]
    fn pareto_groups_shared_points_merges_callouts_and_clips_nothing() {
        let pt = |x: f64, y: f64, size: f64, label: &str, callout: Option<&str>| ScatterPoint {
            x,
            y,
            size,
            color: PALETTE[2].into(),
            marker: Marker::Square,
            label: label.into(),
            callout: callout.map(str::to_string),
        };
        // Five spring variants at (0 kg, −54 %), two of them recommended (two callouts at one
        // point), and the top point with the largest marker.
        let mut points: Vec<ScatterPoint> = (0..5)
            .map(|k| pt(0.0, -54.0, 0.0, &format!("SB{k}"), None))
            .collect();
        points[1].callout = Some("SB1 (overall)".into());
        points[2].callout = Some("SB2 (springs)".into());
        points.push(pt(500.0, -40.0, 10.0, "SB9", None));
        let svg = scatter_chart(&ScatterChart {
            title: "t".into(),
            subtitle: None,
            x_label: "x".into(),
            y_label: "y".into(),
            points,
            legend: vec![],
            size_max: 10.0,
            size_label: "ΔR".into(),
            band: Some((-54.0, -53.5, "band".into())),
            front: vec![(0.0, -54.0), (500.0, -55.0)],
            width: 600.0,
            height: 400.0,
        });
        // One marker for the five, with their count and all of them in the tooltip.
        assert!(svg.contains("×5"), "{svg}");
        assert!(svg.contains("5 variants at this point:"));
        assert_eq!(svg.matches("<title>SB9").count(), 1);
        // The two callouts share one label.
        assert!(svg.contains("SB1 (overall); SB2 (springs)"));
        // The front is drawn after the band (on top of it).
        assert!(svg.find("<polyline").unwrap() > svg.find("fill=\"#fff3cd\"").unwrap());
        // Then the callouts' white cards, hiding the front under the labels, then the markers
        // over the cards (no point hidden), then the labels.
        let card = svg.find("class=\"card\"").unwrap();
        assert!(svg.find("<polyline").unwrap() < card);
        assert!(card < svg.find("<g><title>").unwrap());
        assert!(svg.find("<g><title>").unwrap() < svg.find("SB1 (overall); SB2").unwrap());
        // The largest marker (11 px) stays inside the frame: its top below the frame's top.
        let frame_top: f64 = {
            let k = svg.find("<rect x=").unwrap();
            let rest = &svg[k..];
            let rects: Vec<&str> = rest.split("<rect ").collect();
            // The plot frame is the rect with fill="none".
            let frame = rects.iter().find(|r| r.contains("fill=\"none\"")).unwrap();
            let y = frame
                .split("y=\"")
                .nth(1)
                .unwrap()
                .split('"')
                .next()
                .unwrap();
            y.parse().unwrap()
        };
        let poly = svg.split("<polygon").count();
        let _ = poly;
        let square_tops: Vec<f64> = svg
            .split("<rect ")
            .filter(|r| {
                r.contains("fill=\"#009E73\"") || r.contains(&format!("fill=\"{}\"", PALETTE[2]))
            })
            .filter_map(|r| r.split("y=\"").nth(1)?.split('"').next()?.parse().ok())
            .collect();
        assert!(!square_tops.is_empty(), "{svg}");
        assert!(
            square_tops.iter().all(|t| *t >= frame_top),
            "{square_tops:?} vs {frame_top}"
        );
    }
}
