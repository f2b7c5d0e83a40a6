//! A schematic drawn as SVG: the bodies in the plane of the gravity and their widest spread,
//! counterweights as discs by volume, springs as zig-zags, with labels placed clear of each
//! other (the data attributes that tests read back are described in `schematic`).

use std::fmt::Write;

use crate::format::{escape_html as esc, fixed, mass, value};
use crate::labels::{self, Label, Obstacles, Rect};
use crate::results::{RunResults, VariantRecord};

use crate::schematic::{Schematic, dot};

/// Drawing size, px.
const WIDTH: f64 = 560.0;
const PLOT_HEIGHT: f64 = 380.0;
const MARGIN: f64 = 46.0;
const LINE: f64 = 15.0;

/// Radius of a counterweight's disc, px: its volume (the cube of the radius) in proportion to
/// its mass, 16 px for a tenth of the moving mass, at least 3 px so a light one stays visible.
pub fn disc_radius(mass_kg: f64, moving_mass: Option<f64>) -> f64 {
    let reference = moving_mass
        .filter(|m| *m > 0.0)
        .unwrap_or(10.0 * mass_kg.max(1e-9));
    (16.0 * (mass_kg.max(0.0) / (0.1 * reference)).cbrt()).clamp(3.0, 30.0)
}

/// The zig-zag of a spring from `a` to `b` (px), with straight ends: `points` attribute text.
fn zigzag(a: (f64, f64), b: (f64, f64)) -> String {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let len = dx.hypot(dy);
    if len < 1e-9 {
        return format!("{:.2},{:.2}", a.0, a.1);
    }
    let (ux, uy) = (dx / len, dy / len);
    let (nx, ny) = (-uy, ux);
    let end = (0.15 * len).min(12.0);
    let zig = 10usize;
    let amp = (0.08 * len).clamp(3.0, 7.0);
    let mut pts = vec![a];
    pts.push((a.0 + ux * end, a.1 + uy * end));
    for k in 1..zig {
        let t = end + (len - 2.0 * end) * k as f64 / zig as f64;
        let side = if k % 2 == 1 { amp } else { -amp };
        pts.push((a.0 + ux * t + nx * side, a.1 + uy * t + ny * side));
    }
    pts.push((b.0 - ux * end, b.1 - uy * end));
    pts.push(b);
    pts.iter()
        .map(|(x, y)| format!("{x:.2},{y:.2}"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// The SVG of a schematic of variant `v` (its parameters label the elements), or of the
/// unbalanced mechanism.
pub fn svg(r: &RunResults, v: Option<&VariantRecord>, s: &Schematic) -> String {
    let idle: Vec<String> = v.map(|v| v.idle.clone()).unwrap_or_default();
    let proj = s.projection();
    let pts = s.points();
    let xy = |p: [f64; 3]| (dot(p, proj.right), dot(p, proj.up));
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for p in &pts {
        let (x, y) = xy(*p);
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if !x0.is_finite() {
        (x0, x1, y0, y1) = (-1.0, 1.0, -1.0, 1.0);
    }
    let span = (x1 - x0).max(y1 - y0).max(1e-6);
    let scale = ((WIDTH - 2.0 * MARGIN) / (x1 - x0).max(span * 0.2))
        .min((PLOT_HEIGHT - 2.0 * MARGIN) / (y1 - y0).max(span * 0.2));
    let ox = WIDTH / 2.0 - scale * (x0 + x1) / 2.0;
    let oy = PLOT_HEIGHT / 2.0 + scale * (y0 + y1) / 2.0;
    let px = |p: [f64; 3]| {
        let (x, y) = xy(p);
        (ox + scale * x, oy - scale * y)
    };
    let params = v.and_then(|v| v.parameters.clone()).unwrap_or_default();
    // The legend: one line per element, then the pose.
    let mut legend: Vec<String> = Vec::new();
    for c in &params.counterweights {
        let r = dot(c.offset, c.offset).sqrt();
        let idle = if idle.contains(&c.label) {
            " (idle)"
        } else {
            ""
        };
        legend.push(format!(
            "{}{idle}: {} at {} mm from the origin of {}",
            c.label,
            mass(c.mass),
            fixed(r * 1000.0, 1),
            c.body
        ));
    }
    for sp in &params.springs {
        let idle = if idle.contains(&sp.label) {
            " (idle)"
        } else {
            ""
        };
        let n = |a: [f64; 3]| fixed(dot(a, a).sqrt() * 1000.0, 1);
        legend.push(format!(
            "{}{idle}: K = {} N/mm, a {} mm on {}, b {} mm on {}",
            sp.label,
            value(sp.stiffness / 1000.0),
            n(sp.anchor_a),
            sp.body,
            n(sp.anchor_b),
            sp.other
        ));
    }
    legend.push(format!("Pose: {}", s.pose));
    let height = PLOT_HEIGHT + 8.0 + LINE * legend.len() as f64;
    let title = match v {
        Some(v) => format!("{} at one pose", v.display_name()),
        None => "The unbalanced mechanism at one pose".to_string(),
    };
    let mut o = String::new();
    let vec3 = |a: [f64; 3]| format!("{:.9} {:.9} {:.9}", a[0], a[1], a[2]);
    let _ = write!(
        o,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"chart schematic\" width=\"{WIDTH}\" height=\"{height:.0}\" viewBox=\"0 0 {WIDTH} {height:.0}\" role=\"img\" aria-label=\"{}\" data-variant=\"{}\" data-right=\"{}\" data-up=\"{}\" data-scale=\"{scale:.9}\" data-ox=\"{ox:.6}\" data-oy=\"{oy:.6}\" data-q=\"{}\">",
        esc(&title),
        v.map_or("UB".to_string(), |v| v.id.to_string()),
        vec3(proj.right),
        vec3(proj.up),
        s.q.iter()
            .map(|x| format!("{x:.12}"))
            .collect::<Vec<_>>()
            .join(" ")
    );
    let _ = write!(
        o,
        "<text x=\"10\" y=\"18\" font-size=\"13\" font-weight=\"600\" fill=\"#1d2327\">{}</text>",
        esc(&title)
    );
    // Gravity arrow, top right.
    let _ = write!(
        o,
        "<g stroke=\"#5f6b73\" fill=\"#5f6b73\"><line x1=\"{x:.1}\" y1=\"14\" x2=\"{x:.1}\" y2=\"40\" stroke-width=\"1.5\"/><path d=\"M{l:.1},36 L{x:.1},44 L{r:.1},36 Z\" stroke=\"none\"/></g><text x=\"{t:.1}\" y=\"32\" font-size=\"11\" fill=\"#5f6b73\">g</text>",
        x = WIDTH - 20.0,
        l = WIDTH - 24.0,
        r = WIDTH - 16.0,
        t = WIDTH - 34.0
    );
    // What the labels keep clear of, and the labels, most important first (placed at the end,
    // drawn on top): the elements' names, then the bodies'.
    let mut obstacles = Obstacles::default();
    let mut element_labels: Vec<(Label, &'static str)> = Vec::new();
    let mut body_labels: Vec<(Label, &'static str)> = Vec::new();
    // Bodies: bars from the first point to the others.
    for b in &s.bodies {
        let Some(&first) = b.points.first() else {
            continue;
        };
        let (fx, fy) = px(first);
        for &p in b.points.iter().skip(1).chain(std::iter::once(&b.com)) {
            let (x, y) = px(p);
            obstacles.bars.push(((fx, fy), (x, y), 3.5));
            let _ = write!(
                o,
                "<line x1=\"{fx:.2}\" y1=\"{fy:.2}\" x2=\"{x:.2}\" y2=\"{y:.2}\" stroke=\"#9aa5ad\" stroke-width=\"7\" stroke-linecap=\"round\"/>"
            );
        }
    }
    for b in &s.bodies {
        let (x, y) = px(b.com);
        let _ = write!(
            o,
            "<circle cx=\"{x:.2}\" cy=\"{y:.2}\" r=\"2.5\" fill=\"#5f6b73\" data-com=\"{}\"/>",
            esc(&b.name),
        );
        body_labels.push((
            Label {
                text: b.name.clone(),
                at: (x, y),
                clear: 2.5,
                size: 10.5,
                bold: false,
            },
            "#5f6b73",
        ));
    }
    // Counterweights: an arm from their body, a disc sized by mass.
    for c in &s.counterweights {
        let m = params
            .counterweights
            .iter()
            .find(|p| p.label == c.label)
            .map_or(0.0, |p| p.mass);
        let (fx, fy) = px(c.from);
        let (x, y) = px(c.at);
        let rr = disc_radius(m, r.moving_mass);
        let idle = idle.contains(&c.label);
        let _ = write!(
            o,
            "<line x1=\"{fx:.2}\" y1=\"{fy:.2}\" x2=\"{x:.2}\" y2=\"{y:.2}\" stroke=\"#0072B2\" stroke-width=\"2\"/><circle cx=\"{x:.2}\" cy=\"{y:.2}\" r=\"{rr:.1}\" fill=\"{}\" fill-opacity=\"0.85\" stroke=\"#0072B2\" stroke-width=\"1.5\" data-cw=\"{}\"/>",
            if idle { "#ffffff" } else { "#0072B2" },
            esc(&c.label),
        );
        obstacles.circles.push(((x, y), rr));
        obstacles.bars.push(((fx, fy), (x, y), 1.0));
        element_labels.push((
            Label {
                text: format!("{}{}", c.label, if idle { " (idle)" } else { "" }),
                at: (x, y),
                clear: rr + 1.0,
                size: 12.0,
                bold: true,
            },
            "#0072B2",
        ));
    }
    // Springs: attachment lines, the zig-zag, the anchors.
    for sp in &s.springs {
        let (a, b) = (px(sp.a), px(sp.b));
        for (from, to) in [(sp.a_from, a), (sp.b_from, b)] {
            let f = px(from);
            let _ = write!(
                o,
                "<line x1=\"{:.2}\" y1=\"{:.2}\" x2=\"{:.2}\" y2=\"{:.2}\" stroke=\"#009E73\" stroke-width=\"1.2\" stroke-dasharray=\"4 3\"/>",
                f.0, f.1, to.0, to.1
            );
        }
        let _ = write!(
            o,
            "<polyline points=\"{}\" fill=\"none\" stroke=\"#009E73\" stroke-width=\"1.8\" stroke-linejoin=\"round\" data-spring-line=\"{}\"/>",
            zigzag(a, b),
            esc(&sp.label)
        );
        for (end, (x, y)) in [("a", a), ("b", b)] {
            obstacles.circles.push(((x, y), 3.5));
            let _ = write!(
                o,
                "<circle cx=\"{x:.2}\" cy=\"{y:.2}\" r=\"3.5\" fill=\"#ffffff\" stroke=\"#009E73\" stroke-width=\"1.8\" data-spring=\"{}\" data-end=\"{end}\"/>",
                esc(&sp.label)
            );
        }
        obstacles.bars.push((a, b, 7.0));
        element_labels.push((
            Label {
                text: format!(
                    "{}{}",
                    sp.label,
                    if idle.contains(&sp.label) {
                        " (idle)"
                    } else {
                        ""
                    }
                ),
                at: ((a.0 + b.0) / 2.0, (a.1 + b.1) / 2.0),
                clear: 7.0,
                size: 12.0,
                bold: true,
            },
            "#009E73",
        ));
    }
    // Joints on top.
    for j in &s.joints {
        let (x, y) = px(j.at);
        obstacles.circles.push(((x, y), 5.5));
        if j.grounded {
            let _ = write!(
                o,
                "<path d=\"M{:.1},{:.1} L{:.1},{:.1} M{:.1},{:.1} l-5,6 M{:.1},{:.1} l-5,6 M{:.1},{:.1} l-5,6\" stroke=\"#1d2327\" stroke-width=\"1.2\" fill=\"none\"/>",
                x - 10.0,
                y + 8.0,
                x + 10.0,
                y + 8.0,
                x - 5.0,
                y + 8.0,
                x + 1.0,
                y + 8.0,
                x + 7.0,
                y + 8.0
            );
        }
        let _ = write!(
            o,
            "<circle cx=\"{x:.2}\" cy=\"{y:.2}\" r=\"4.5\" fill=\"#ffffff\" stroke=\"#1d2327\" stroke-width=\"1.8\" data-joint=\"{}\"><title>{}</title></circle>",
            esc(&j.name),
            esc(&j.name)
        );
    }
    // Scale bar: a round length near a fifth of the width.
    let target = (WIDTH / 5.0) / scale;
    let mag = 10f64.powf(target.log10().floor());
    let bar = [1.0, 2.0, 5.0]
        .iter()
        .map(|k| k * mag)
        .rfind(|l| *l <= target)
        .unwrap_or(mag);
    let _ = write!(
        o,
        "<g stroke=\"#5f6b73\"><line x1=\"12\" y1=\"{y:.1}\" x2=\"{x2:.1}\" y2=\"{y:.1}\" stroke-width=\"2\"/></g><text x=\"12\" y=\"{ty:.1}\" font-size=\"11\" fill=\"#5f6b73\">{} mm</text>",
        fixed(bar * 1000.0, 0),
        y = PLOT_HEIGHT - 12.0,
        x2 = 12.0 + bar * scale,
        ty = PLOT_HEIGHT - 18.0
    );
    // Labels last, over everything, with a white halo; far ones with a leader line.
    obstacles.taken.extend([
        // The title, the gravity arrow, the scale bar.
        Rect {
            x0: 0.0,
            y0: 0.0,
            x1: 10.0 + labels::text_width(&title, 13.0, true),
            y1: 24.0,
        },
        Rect {
            x0: WIDTH - 40.0,
            y0: 8.0,
            x1: WIDTH,
            y1: 48.0,
        },
        Rect {
            x0: 0.0,
            y0: PLOT_HEIGHT - 32.0,
            x1: 24.0 + bar * scale,
            y1: PLOT_HEIGHT,
        },
    ]);
    let all: Vec<(Label, &str)> = element_labels.into_iter().chain(body_labels).collect();
    let area = Rect {
        x0: 4.0,
        y0: 4.0,
        x1: WIDTH - 4.0,
        y1: PLOT_HEIGHT - 4.0,
    };
    let placed = labels::place(
        &all.iter().map(|(l, _)| l.clone()).collect::<Vec<_>>(),
        &obstacles,
        area,
    );
    for ((l, color), p) in all.iter().zip(&placed) {
        if let Some((from, to)) = p.leader {
            let _ = write!(
                o,
                "<line x1=\"{:.2}\" y1=\"{:.2}\" x2=\"{:.2}\" y2=\"{:.2}\" stroke=\"{color}\" stroke-width=\"0.8\" data-leader=\"{}\"/>",
                from.0,
                from.1,
                to.0,
                to.1,
                esc(&l.text)
            );
        }
        let _ = write!(
            o,
            "<text x=\"{:.1}\" y=\"{:.1}\" font-size=\"{}\"{} fill=\"{color}\" stroke=\"#ffffff\" stroke-width=\"3\" stroke-linejoin=\"round\" paint-order=\"stroke\" data-label-x=\"{:.2}\" data-label-y=\"{:.2}\">{}</text>",
            p.rect.x0,
            p.baseline,
            l.size,
            if l.bold { " font-weight=\"600\"" } else { "" },
            l.at.0,
            l.at.1,
            esc(&l.text)
        );
    }
    for (k, line) in legend.iter().enumerate() {
        let _ = write!(
            o,
            "<text x=\"12\" y=\"{:.1}\" font-size=\"11.5\" fill=\"#1d2327\">{}</text>",
            PLOT_HEIGHT + 6.0 + LINE * (k as f64 + 0.7),
            esc(line)
        );
    }
    o.push_str("</svg>");
    o
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn discs_by_volume() {
        // A tenth of the moving mass: 16 px; 1/8 of that mass: half the radius.
        assert!((disc_radius(10.0, Some(100.0)) - 16.0).abs() < 1e-12);
        assert!((disc_radius(1.25, Some(100.0)) - 8.0).abs() < 1e-12);
        assert_eq!(disc_radius(1e-6, Some(100.0)), 3.0);
    }
}
