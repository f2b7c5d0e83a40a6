use super::bar::*;
use super::line::*;
use super::primitives::*;
use super::scatter::*;

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
