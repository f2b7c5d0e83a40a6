//! Scatter charts with labelled points, the labels placed clear of the points and of each
//! other.

use std::fmt::Write;

use crate::format::escape_html;

use super::placement::{self, Rect};
use super::primitives::*;

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
pub(crate) fn scatter_radius(size: f64, max: f64) -> f64 {
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
