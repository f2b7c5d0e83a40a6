//! The parts every chart is drawn from: palette, ticks, markers, legend, frame and axes.
//!
//! Text widths are estimated (0.6 em per character) only to lay out legends and groups.

use std::fmt::Write;

use crate::format::escape_html;

/// Colour-blind-safe palette (Okabe–Ito).
pub const PALETTE: [&str; 8] = [
    "#444444", "#0072B2", "#009E73", "#D55E00", "#CC79A7", "#E69F00", "#56B4E9", "#F0E442",
];

pub(crate) const FONT: f64 = 12.0;
pub(crate) const SMALL: f64 = 11.0;

pub(crate) fn text_width(s: &str, size: f64) -> f64 {
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
pub(crate) fn tick_label(v: f64, step: f64) -> String {
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
pub(crate) fn range(values: impl Iterator<Item = f64>, include_zero: bool) -> (f64, f64) {
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
pub(crate) fn marker(
    out: &mut String,
    m: Marker,
    x: f64,
    y: f64,
    r: f64,
    color: &str,
    hollow: bool,
) {
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

/// One legend entry.
pub(crate) struct LegendItem {
    pub(crate) label: String,
    pub(crate) color: String,
    pub(crate) dash: Option<String>,
    pub(crate) marker: Option<Marker>,
    pub(crate) bar: bool,
}

/// Legend items laid out in rows under the title; returns (svg, height used).
pub(crate) fn legend(items: &[LegendItem], x0: f64, y0: f64, width: f64) -> (String, f64) {
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
pub(crate) fn centred_text(
    out: &mut String,
    text: &str,
    width: f64,
    y: f64,
    size: f64,
    extra: &str,
) {
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
pub(crate) fn svg_open(
    width: f64,
    height: f64,
    title: &str,
    subtitle: Option<&str>,
) -> (String, f64) {
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
pub(crate) struct Frame {
    pub(crate) left: f64,
    pub(crate) top: f64,
    pub(crate) w: f64,
    pub(crate) h: f64,
    pub(crate) x_lo: f64,
    pub(crate) x_hi: f64,
    pub(crate) y_lo: f64,
    pub(crate) y_hi: f64,
}

impl Frame {
    pub(crate) fn x(&self, v: f64) -> f64 {
        self.left + (v - self.x_lo) / (self.x_hi - self.x_lo) * self.w
    }
    pub(crate) fn y(&self, v: f64) -> f64 {
        self.top + (self.y_hi - v) / (self.y_hi - self.y_lo) * self.h
    }
}

/// The widest y tick label of a range, in px: the left margin is made to fit it, so a tick
/// label never runs over the axis title or out of the chart.
pub(crate) fn y_label_room(y_lo: f64, y_hi: f64) -> f64 {
    let (ticks, step) = nice_ticks(y_lo, y_hi, 6);
    ticks
        .iter()
        .map(|t| text_width(&tick_label(*t, step), SMALL))
        .fold(0.0, f64::max)
}

/// Left margin for a y range: axis title, gap, the widest tick label, tick gap.
pub(crate) fn left_margin(y_lo: f64, y_hi: f64) -> f64 {
    (30.0 + y_label_room(y_lo, y_hi) + 10.0).max(58.0)
}

/// The x ticks below the frame, the frame itself and the x-axis title (`height`: the chart's).
pub(crate) fn x_axis(out: &mut String, f: &Frame, height: f64, x_label: &str) {
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

pub(crate) fn y_axis(out: &mut String, f: &Frame, y_label: &str) {
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
pub(crate) fn note_lines(out: &mut String, text: &str, x: f64, y: f64, width: f64) -> f64 {
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
