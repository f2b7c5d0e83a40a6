//! Where a chart's callout labels go: beside their point, clear of every marker, ring and
//! label already drawn, inside the plot frame.
//!
//! A greedy search, label by label in the caller's order: each label tries a fixed set of
//! candidate boxes around its point (right, left, centred above or below, and the same
//! shifted up and down in half-line steps) and takes the nearest one that collides with
//! nothing; the boxes it takes become obstacles for the labels after it. When every candidate
//! collides, the one overlapping least is taken (a crowded chart still gets its label). A few
//! labels on a few dozen markers cost a few thousand box tests: no optimisation needed.

/// An axis-aligned box in SVG pixels (y down).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Rect {
    pub x0: f64,
    pub y0: f64,
    pub x1: f64,
    pub y1: f64,
}

impl Rect {
    /// The box of a circle (or a marker of that radius).
    pub fn around(x: f64, y: f64, rx: f64, ry: f64) -> Rect {
        Rect {
            x0: x - rx,
            y0: y - ry,
            x1: x + rx,
            y1: y + ry,
        }
    }

    /// Area shared with `other` (0 when they only touch).
    pub fn overlap(&self, other: &Rect) -> f64 {
        let w = self.x1.min(other.x1) - self.x0.max(other.x0);
        let h = self.y1.min(other.y1) - self.y0.max(other.y0);
        if w > 0.0 && h > 0.0 { w * h } else { 0.0 }
    }

    fn inside(&self, bounds: &Rect) -> bool {
        self.x0 >= bounds.x0 && self.x1 <= bounds.x1 && self.y0 >= bounds.y0 && self.y1 <= bounds.y1
    }

    /// Distance from the point `(x, y)` to the box (0 inside).
    pub fn distance(&self, x: f64, y: f64) -> f64 {
        let dx = (self.x0 - x).max(x - self.x1).max(0.0);
        let dy = (self.y0 - y).max(y - self.y1).max(0.0);
        dx.hypot(dy)
    }
}

/// Gap between a ring and a label beside it, px.
pub(crate) const GAP: f64 = 3.0;

/// Clearance a label keeps from every obstacle, px (a label 1 px from a ring reads as
/// touching it).
pub(crate) const CLEARANCE: f64 = 2.0;

/// The box for a `w` × `h` label of the point at `(x, y)` ringed with radius `r`: the nearest
/// candidate that overlaps neither an obstacle nor the ring and stays inside `bounds`; failing
/// that, the one overlapping least (then the nearest).
pub(crate) fn place(
    x: f64,
    y: f64,
    r: f64,
    w: f64,
    h: f64,
    obstacles: &[Rect],
    bounds: &Rect,
) -> Rect {
    let columns = [
        x + r + GAP,     // right of the ring
        x - r - GAP - w, // left of it
        x - w / 2.0,     // centred (above or below)
        x - r,           // starting at the ring's left edge
        x + r - w,       // ending at its right edge
    ];
    let step = h / 2.0 + 1.0;
    let ring = Rect::around(x, y, r, r);
    let mut best: Option<(f64, f64, Rect)> = None;
    for j in 0..=32 {
        // 0, +1, −1, +2, −2, …: rows nearest the point first.
        let k = if j % 2 == 1 { (j + 1) / 2 } else { -(j / 2) } as f64;
        let y0 = y - h / 2.0 + k * step;
        for (order, &x0) in columns.iter().enumerate() {
            let b = Rect {
                x0,
                y0,
                x1: x0 + w,
                y1: y0 + h,
            };
            // Outside the frame: clipped, never taken.
            if !b.inside(bounds) {
                continue;
            }
            let padded = Rect {
                x0: b.x0 - CLEARANCE,
                y0: b.y0 - CLEARANCE,
                x1: b.x1 + CLEARANCE,
                y1: b.y1 + CLEARANCE,
            };
            // The point's own ring is an obstacle too.
            let overlap: f64 = obstacles
                .iter()
                .chain([&ring])
                .map(|o| o.overlap(&padded))
                .sum();
            // Nearest first; the order of the columns breaks ties (right before left).
            let cost = b.distance(x, y) + 1e-3 * order as f64;
            if best
                .as_ref()
                .is_none_or(|&(o, c, _)| (overlap, cost) < (o, c))
            {
                best = Some((overlap, cost, b));
            }
        }
    }
    best.map_or(
        Rect {
            x0: x + r + GAP,
            y0: y - h / 2.0,
            x1: x + r + GAP + w,
            y1: y + h / 2.0,
        },
        |(_, _, b)| b,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame() -> Rect {
        Rect {
            x0: 0.0,
            y0: 0.0,
            x1: 400.0,
            y1: 300.0,
        }
    }

    #[test]
    fn a_free_label_sits_right_of_its_ring() {
        let b = place(100.0, 100.0, 8.0, 60.0, 14.0, &[], &frame());
        assert_eq!(
            b,
            Rect {
                x0: 111.0,
                y0: 93.0,
                x1: 171.0,
                y1: 107.0
            }
        );
    }

    #[test]
    fn a_label_goes_left_near_the_right_edge() {
        let b = place(380.0, 100.0, 8.0, 60.0, 14.0, &[], &frame());
        assert_eq!((b.x0, b.x1), (380.0 - 11.0 - 60.0, 380.0 - 11.0));
    }

    #[test]
    fn a_label_avoids_a_marker_on_its_right() {
        // A marker right of the point blocks the right side at the point's height; the
        // nearest free box is left of the ring (11 px from the point): the rows above and
        // below start 17 px away (the first one clear of the ring by the clearance).
        let marker = Rect::around(130.0, 100.0, 10.0, 10.0);
        let b = place(100.0, 100.0, 8.0, 60.0, 14.0, &[marker], &frame());
        assert_eq!(b.overlap(&marker), 0.0);
        assert_eq!((b.x1, b.y0), (89.0, 93.0));
    }

    #[test]
    fn a_label_moves_out_of_a_crowded_band() {
        // The top 60 px are taken: the label goes to the first row below them.
        let wall = Rect {
            x0: 0.0,
            y0: 0.0,
            x1: 400.0,
            y1: 60.0,
        };
        let b = place(100.0, 40.0, 8.0, 60.0, 14.0, &[wall], &frame());
        // Rows are 8 px apart from y0 = 33: the first at least 62 (60 + clearance) is 65.
        assert_eq!(b.y0, 65.0, "{b:?}");
    }
}
