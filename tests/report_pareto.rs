//! The Pareto chart's labels overprint nothing (issue 31, item 7): on the palletizer at Dmax 2
//! (a full `run`, about 20 s), every callout label's box is read back from the SVG and checked
//! against every other label, every ring, every marker and every "×N" count, and against the
//! plot frame (nothing clipped). At Dmax 2 the overall and spring-only pick SB6 sits at 0 kg
//! and the hybrid pick SB37 at 172 kg on nearly the same ΔQTR: SB6's label used to run into
//! SB37's ring.
//!
//! The label boxes are computed here from each `<text>`'s position, anchor and length, at
//! 0.62 em per character: Chromium renders the 11 px bold labels at about 0.56 em per
//! character (SB6's 22-character label spans 135 px in a screenshot), so the box holds the
//! drawn text.

mod common;

use common::{assert_success, counterpoise};

/// A box, SVG pixels (y down).
#[derive(Clone, Copy, Debug)]
struct Box {
    x0: f64,
    y0: f64,
    x1: f64,
    y1: f64,
}

impl Box {
    fn overlaps(&self, o: &Box) -> bool {
        self.x0 < o.x1 && o.x0 < self.x1 && self.y0 < o.y1 && o.y0 < self.y1
    }

    fn inside(&self, o: &Box) -> bool {
        self.x0 >= o.x0 && self.x1 <= o.x1 && self.y0 >= o.y0 && self.y1 <= o.y1
    }

    /// Whether a circle's stroke (radius `r` ± half the stroke) crosses or lies in the box.
    fn meets_circle(&self, cx: f64, cy: f64, r: f64) -> bool {
        let nx = cx.clamp(self.x0, self.x1);
        let ny = cy.clamp(self.y0, self.y1);
        (nx - cx).hypot(ny - cy) < r + 0.8
    }
}

/// The value of attribute `name` in one tag's text.
fn attr<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let key = format!(" {name}=\"");
    let start = tag.find(&key)? + key.len();
    Some(&tag[start..start + tag[start..].find('"')?])
}

fn num(tag: &str, name: &str) -> f64 {
    attr(tag, name)
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no number {name} in {tag}"))
}

/// Every tag of `svg` with the text up to the next tag (`<text …>content`).
fn tags(svg: &str) -> Vec<&str> {
    svg.split('<').skip(1).collect()
}

fn text_content(tag: &str) -> String {
    let raw = &tag[tag.find('>').unwrap() + 1..];
    raw.replace("&amp;", "&")
        .replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&#39;", "'")
        .replace("&quot;", "\"")
}

/// The box of a `<text>` of `size` px at `em` per character.
fn text_box(tag: &str, em: f64) -> Box {
    let size = num(tag, "font-size");
    let (x, y) = (num(tag, "x"), num(tag, "y"));
    let w = text_content(tag).chars().count() as f64 * em * size;
    let x0 = match attr(tag, "text-anchor").unwrap_or("start") {
        "end" => x - w,
        "middle" => x - w / 2.0,
        _ => x,
    };
    // Cap height above the baseline, descenders below.
    Box {
        x0,
        y0: y - 0.8 * size,
        x1: x0 + w,
        y1: y + 0.25 * size,
    }
}

/// The box of a marker element (circle, rect or polygon).
fn shape_box(tag: &str) -> Option<Box> {
    if tag.starts_with("circle ") {
        let (x, y, r) = (num(tag, "cx"), num(tag, "cy"), num(tag, "r"));
        Some(Box {
            x0: x - r,
            y0: y - r,
            x1: x + r,
            y1: y + r,
        })
    } else if tag.starts_with("rect ") {
        let (x, y) = (num(tag, "x"), num(tag, "y"));
        Some(Box {
            x0: x,
            y0: y,
            x1: x + num(tag, "width"),
            y1: y + num(tag, "height"),
        })
    } else if tag.starts_with("polygon ") {
        let pts: Vec<f64> = attr(tag, "points")?
            .split([' ', ','])
            .filter_map(|v| v.parse().ok())
            .collect();
        let xs = pts.iter().step_by(2);
        let ys = pts.iter().skip(1).step_by(2);
        Some(Box {
            x0: xs.clone().cloned().fold(f64::INFINITY, f64::min),
            x1: xs.cloned().fold(f64::NEG_INFINITY, f64::max),
            y0: ys.clone().cloned().fold(f64::INFINITY, f64::min),
            y1: ys.cloned().fold(f64::NEG_INFINITY, f64::max),
        })
    } else {
        None
    }
}

/// Checks the Pareto chart in `svg`; returns the callouts' texts.
fn check_pareto(svg: &str) -> Vec<String> {
    let tags = tags(svg);
    // The plot frame: the unfilled rect.
    let frame = tags
        .iter()
        .filter(|t| t.starts_with("rect ") && attr(t, "fill") == Some("none"))
        .find_map(|t| shape_box(t))
        .expect("a frame");
    let labels: Vec<(String, Box)> = tags
        .iter()
        .filter(|t| t.starts_with("text ") && attr(t, "class") == Some("callout"))
        .map(|t| (text_content(t), text_box(t, 0.62)))
        .collect();
    let rings: Vec<(f64, f64, f64)> = tags
        .iter()
        .filter(|t| {
            t.starts_with("circle ")
                && attr(t, "fill") == Some("none")
                && attr(t, "stroke") == Some("#111111")
        })
        .map(|t| (num(t, "cx"), num(t, "cy"), num(t, "r")))
        .collect();
    // Markers: the shape after each group's tooltip; counts: the "×N" texts.
    let mut markers = Vec::new();
    for (k, t) in tags.iter().enumerate() {
        if t.starts_with("g>") && tags.get(k + 1).is_some_and(|n| n.starts_with("title>")) {
            let shape = tags[k + 2..]
                .iter()
                .find(|n| !n.starts_with('/'))
                .expect("a marker after the tooltip");
            markers.push(shape_box(shape).expect("a marker shape"));
        }
    }
    let counts: Vec<Box> = tags
        .iter()
        .filter(|t| t.starts_with("text ") && text_content(t).starts_with('×'))
        .map(|t| text_box(t, 0.62))
        .collect();
    assert!(!labels.is_empty() && !markers.is_empty(), "{svg}");
    for (i, (name, b)) in labels.iter().enumerate() {
        assert!(b.inside(&frame), "{name} {b:?} leaves the frame {frame:?}");
        for (other, o) in &labels[i + 1..] {
            assert!(!b.overlaps(o), "{name} {b:?} overprints {other} {o:?}");
        }
        for &(x, y, r) in &rings {
            assert!(
                !b.meets_circle(x, y, r),
                "{name} {b:?} touches the ring at {x}, {y}"
            );
        }
        for m in &markers {
            assert!(!b.overlaps(m), "{name} {b:?} overprints a marker {m:?}");
        }
        for c in &counts {
            assert!(!b.overlaps(c), "{name} {b:?} overprints a count {c:?}");
        }
    }
    labels.into_iter().map(|(n, _)| n).collect()
}

#[test]
fn pareto_labels_overprint_nothing_on_the_palletizer_at_dmax_2() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    assert_success(&counterpoise(&[
        "run",
        "cases/palletizer.json",
        "--dmax",
        "2",
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]));
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    let at = html
        .find("aria-label=\"Motor effort against added mass\"")
        .expect("a Pareto chart");
    let start = html[..at].rfind("<svg").unwrap();
    let end = at + html[at..].find("</svg>").unwrap();
    let labels = check_pareto(&html[start..end]);
    // The three picks of issue 31 at Dmax 2, each labelled once.
    for pick in [
        "SB6 (overall, springs)",
        "SB37 (hybrid)",
        "SB44 (counterweights)",
    ] {
        assert_eq!(
            labels.iter().filter(|l| l.as_str() == pick).count(),
            1,
            "{labels:?}"
        );
    }
}
