//! Placing a drawing's labels clear of each other and of what is drawn.
//!
//! A schematic names bodies, counterweights and springs that often crowd into a few
//! centimetres of the page (the palletizer's sliders, rear link and column meet at one joint,
//! and a spring between them is labelled there too). Each label is placed in turn, the most
//! important first, at the candidate position around its point that costs least: overlapping
//! a label already placed costs most, then covering a marker (a joint, an anchor, a disc),
//! then crossing a body's bar, then the distance from the point. A label that ends farther
//! than a step from its point gets a leader line back to it, so it still names one thing.
//!
//! Text widths are estimated, not measured (the SVG is written without a font at hand): an
//! average advance of 0.6 em (0.66 em bold) is a little wider than DejaVu Sans's or
//! Helvetica's lower-case text, so boxes err on the side of clearance. The placement is
//! deterministic (a fixed candidate order, ties to the first).

/// A point, px.
pub type Point = (f64, f64);

/// A bar: its ends and half its width, px.
pub type Bar = (Point, Point, f64);

/// An axis-aligned box, px (y down, as in SVG).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rect {
    pub x0: f64,
    pub y0: f64,
    pub x1: f64,
    pub y1: f64,
}

impl Rect {
    fn overlap(&self, o: &Rect) -> f64 {
        let w = self.x1.min(o.x1) - self.x0.max(o.x0);
        let h = self.y1.min(o.y1) - self.y0.max(o.y0);
        if w > 0.0 && h > 0.0 { w * h } else { 0.0 }
    }

    fn grown(&self, by: f64) -> Rect {
        Rect {
            x0: self.x0 - by,
            y0: self.y0 - by,
            x1: self.x1 + by,
            y1: self.y1 + by,
        }
    }

    fn inside(&self, area: &Rect) -> bool {
        self.x0 >= area.x0 && self.y0 >= area.y0 && self.x1 <= area.x1 && self.y1 <= area.y1
    }

    /// The point of the box nearest to `p`.
    fn nearest(&self, p: (f64, f64)) -> (f64, f64) {
        (p.0.clamp(self.x0, self.x1), p.1.clamp(self.y0, self.y1))
    }

    /// Whether a circle of radius `r` about `c` reaches into the box.
    fn meets_circle(&self, c: (f64, f64), r: f64) -> bool {
        let n = self.nearest(c);
        (n.0 - c.0).hypot(n.1 - c.1) < r
    }

    /// Whether the segment `a`–`b` passes through the box (Liang–Barsky clipping).
    fn meets_segment(&self, a: (f64, f64), b: (f64, f64)) -> bool {
        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
        let (mut t0, mut t1) = (0.0f64, 1.0f64);
        for (p, q) in [
            (-dx, a.0 - self.x0),
            (dx, self.x1 - a.0),
            (-dy, a.1 - self.y0),
            (dy, self.y1 - a.1),
        ] {
            if p == 0.0 {
                if q < 0.0 {
                    return false;
                }
            } else {
                let t = q / p;
                if p < 0.0 {
                    t0 = t0.max(t);
                } else {
                    t1 = t1.min(t);
                }
                if t0 > t1 {
                    return false;
                }
            }
        }
        true
    }
}

/// A label to place next to the point it names.
#[derive(Clone, Debug, PartialEq)]
pub struct Label {
    pub text: String,
    /// The point it names, px.
    pub at: (f64, f64),
    /// Radius about `at` the label keeps off (the marker drawn there), px.
    pub clear: f64,
    /// Font size, px.
    pub size: f64,
    pub bold: bool,
}

/// Where a label went.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placed {
    /// Its box (text from `x0`, baseline at `baseline`).
    pub rect: Rect,
    pub baseline: f64,
    /// Start and end of the leader line back to the point, when it is far from it.
    pub leader: Option<((f64, f64), (f64, f64))>,
}

/// What the labels must keep clear of.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Obstacles {
    /// Markers: centre and radius, px.
    pub circles: Vec<(Point, f64)>,
    /// Bars: ends and half-width, px.
    pub bars: Vec<Bar>,
    /// Boxes already taken (a title, an arrow, a scale bar).
    pub taken: Vec<Rect>,
}

/// Estimated width of `text` at font size `size`, px (see the module doc).
pub fn text_width(text: &str, size: f64, bold: bool) -> f64 {
    let em = if bold { 0.66 } else { 0.6 };
    text.chars().count() as f64 * em * size
}

/// Distances of the candidate rings beyond a label's clearance, px: the first two are beside
/// the point, the others need a leader.
const RINGS: [f64; 7] = [3.0, 10.0, 22.0, 36.0, 54.0, 76.0, 104.0];
/// Rings at or beyond this index get a leader line.
const LEADER_FROM: usize = 2;
/// Directions, degrees clockwise from the right (SVG's y points down), in order of preference:
/// beside the point on the right, then above and below, then the left.
const ANGLES: [f64; 12] = [
    -25.0, 25.0, -65.0, 65.0, -90.0, 90.0, -155.0, 155.0, -115.0, 115.0, 0.0, 180.0,
];

/// Places `labels` in order within `area`, clear of `obstacles` and of each other as far as
/// the candidates allow.
pub fn place(labels: &[Label], obstacles: &Obstacles, area: Rect) -> Vec<Placed> {
    let mut taken: Vec<Rect> = obstacles.taken.clone();
    let mut out = Vec::with_capacity(labels.len());
    for l in labels {
        let (w, h) = (text_width(&l.text, l.size, l.bold), l.size);
        let mut best: Option<(f64, Placed)> = None;
        for (ring, extra) in RINGS.iter().enumerate() {
            let r = l.clear + extra;
            for (k, deg) in ANGLES.iter().enumerate() {
                let (dy, dx) = deg.to_radians().sin_cos();
                // The box's near side at distance r along the direction.
                let cx = l.at.0 + dx * (r + w / 2.0);
                let cy = l.at.1 + dy * (r + h / 2.0);
                let rect = Rect {
                    x0: cx - w / 2.0,
                    y0: cy - h / 2.0,
                    x1: cx + w / 2.0,
                    y1: cy + h / 2.0,
                };
                let padded = rect.grown(2.0);
                let mut cost = ring as f64 * 4.0 + k as f64 * 0.1;
                if !rect.inside(&area) {
                    cost += 1e6;
                }
                cost += 100.0 * taken.iter().map(|t| padded.overlap(t)).sum::<f64>();
                cost += 300.0
                    * obstacles
                        .circles
                        .iter()
                        .filter(|(c, rad)| padded.meets_circle(*c, *rad))
                        .count() as f64;
                cost += 12.0
                    * obstacles
                        .bars
                        .iter()
                        .filter(|(a, b, half)| rect.grown(*half).meets_segment(*a, *b))
                        .count() as f64;
                if best.as_ref().is_none_or(|(c, _)| cost < *c) {
                    let leader = (ring >= LEADER_FROM).then(|| {
                        let end = rect.nearest(l.at);
                        let (ex, ey) = (end.0 - l.at.0, end.1 - l.at.1);
                        let d = ex.hypot(ey).max(1e-9);
                        let start = (l.at.0 + ex / d * l.clear, l.at.1 + ey / d * l.clear);
                        (start, end)
                    });
                    best = Some((
                        cost,
                        Placed {
                            rect,
                            baseline: rect.y0 + 0.78 * h,
                            leader,
                        },
                    ));
                }
            }
        }
        let (_, p) = best.expect("at least one candidate");
        taken.push(p.rect);
        out.push(p);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn label(text: &str, at: (f64, f64)) -> Label {
        Label {
            text: text.into(),
            at,
            clear: 4.0,
            size: 12.0,
            bold: false,
        }
    }

    const AREA: Rect = Rect {
        x0: 0.0,
        y0: 0.0,
        x1: 400.0,
        y1: 300.0,
    };

    #[test]
    fn a_lone_label_sits_beside_its_point_without_a_leader() {
        let p = place(&[label("m4", (100.0, 100.0))], &Obstacles::default(), AREA);
        assert!(p[0].leader.is_none());
        // First candidate: right and a little up, its near side 7 px out along −25°.
        assert!(p[0].rect.x0 > 100.0 && p[0].rect.y1 < 110.0 && p[0].rect.y0 > 80.0);
    }

    #[test]
    fn labels_of_one_point_do_not_overlap_and_the_far_ones_have_leaders() {
        let labels: Vec<Label> = (0..8)
            .map(|k| label(&format!("label number {k}"), (200.0, 150.0)))
            .collect();
        let p = place(&labels, &Obstacles::default(), AREA);
        for (i, a) in p.iter().enumerate() {
            for b in &p[i + 1..] {
                assert_eq!(a.rect.overlap(&b.rect), 0.0, "{a:?} {b:?}");
            }
            assert!(a.rect.inside(&AREA));
            if let Some((s, e)) = a.leader {
                // The leader starts on the marker's edge and ends on the box.
                assert!(((s.0 - 200.0).hypot(s.1 - 150.0) - 4.0).abs() < 1e-9);
                assert_eq!(a.rect.nearest(e), e);
            }
        }
        assert!(p.iter().any(|x| x.leader.is_some()));
    }

    #[test]
    fn a_label_keeps_off_a_marker_and_a_bar() {
        // A marker where the first candidate would go, and a bar through the second: the
        // label takes another side.
        let obstacles = Obstacles {
            circles: vec![((120.0, 95.0), 6.0)],
            bars: vec![((100.0, 100.0), (160.0, 130.0), 3.5)],
            taken: vec![],
        };
        let p = place(&[label("m4", (100.0, 100.0))], &obstacles, AREA);
        let r = p[0].rect;
        assert!(!r.grown(2.0).meets_circle((120.0, 95.0), 6.0));
        assert!(!r.grown(3.5).meets_segment((100.0, 100.0), (160.0, 130.0)));
    }

    #[test]
    fn segment_and_box() {
        let r = Rect {
            x0: 0.0,
            y0: 0.0,
            x1: 10.0,
            y1: 10.0,
        };
        assert!(r.meets_segment((-5.0, 5.0), (15.0, 5.0)));
        assert!(r.meets_segment((5.0, 5.0), (6.0, 6.0)));
        assert!(!r.meets_segment((-5.0, -5.0), (-1.0, 20.0)));
        assert!(!r.meets_segment((11.0, 0.0), (20.0, 10.0)));
    }
}
