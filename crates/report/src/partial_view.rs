//! The partial-balancing section drawn: the designs table and the bar chart of each
//! actuator's RMS gravity torque (the data and its sentences are in `partial`).

use crate::partial::{
    PartialBalancing, TABLE_ROWS, best_of_each_size, change_text, element_text, loaded, rms,
};
use crate::svg::{BarChart, PALETTE, bar_chart_in};
use crate::tables::{Cell, Table};

/// The designs table: the unbalanced robot first (its RMS per actuator), then the
/// [`TABLE_ROWS`] best sets (the change of each actuator's RMS).
pub fn table(p: &PartialBalancing) -> Table {
    let columns = loaded(p);
    let mut header = vec![
        "Rank".to_string(),
        "Set".to_string(),
        "Counterweights (mass at the centre of mass, body frame)".to_string(),
        "Total RMS [N·m]".to_string(),
        "Δ total".to_string(),
    ];
    header.extend(columns.iter().map(|&j| format!("Δ {}", p.actuators[j])));
    header.push("Exact".to_string());
    let mut t = Table {
        header,
        rows: Vec::new(),
        group_starts: Vec::new(),
        highlighted: Vec::new(),
    };
    let mut unbalanced = vec![
        Cell::text("—"),
        Cell::text("none (unbalanced)"),
        Cell::empty(),
        Cell::num(rms(p.unbalanced_total)),
        Cell::empty(),
    ];
    unbalanced.extend(
        columns
            .iter()
            .map(|&j| Cell::num(format!("{} N·m", rms(p.unbalanced_rms[j])))),
    );
    unbalanced.push(Cell::empty());
    t.rows.push(unbalanced);
    t.group_starts.push(false);
    t.highlighted.push(false);
    let best = best_of_each_size(p);
    for (i, d) in p.designs.iter().enumerate().take(TABLE_ROWS) {
        let mut row = vec![
            Cell::num(d.rank.to_string()),
            Cell::text(d.set()),
            Cell::prose(
                d.elements
                    .iter()
                    .map(element_text)
                    .collect::<Vec<_>>()
                    .join("; "),
            ),
            Cell::num(rms(d.total_rms)),
            Cell::num(change_text(d.total_rms, p.unbalanced_total).unwrap_or_default()),
        ];
        for &j in &columns {
            let v = d.rms[j];
            // An actuator the unbalanced robot does not load has no change: its RMS instead.
            row.push(Cell::num(
                change_text(v, p.unbalanced_rms[j]).unwrap_or_else(|| format!("{} N·m", rms(v))),
            ));
        }
        row.push(Cell::text(d.exact.clone().unwrap_or_default()));
        t.rows.push(row);
        t.group_starts.push(i == 0);
        // The best design of each size stands out, as the recommended variants do elsewhere.
        t.highlighted.push(best.contains(&i));
    }
    t
}

/// The bar chart: per actuator, the RMS gravity torque of the unbalanced robot and of the best
/// design of each size (`None` without designs).
pub fn chart(p: &PartialBalancing) -> Option<String> {
    let best = best_of_each_size(p);
    if best.is_empty() {
        return None;
    }
    let mut series = vec![("unbalanced".to_string(), PALETTE[0].to_string())];
    let mut values: Vec<Vec<f64>> = p.unbalanced_rms.iter().map(|v| vec![*v]).collect();
    for (k, &i) in best.iter().enumerate() {
        let d = &p.designs[i];
        let n = d.elements.len();
        series.push((
            format!(
                "{} (best of {n} counterweight{}, rank {})",
                d.set(),
                if n == 1 { "" } else { "s" },
                d.rank
            ),
            PALETTE[1 + k % (PALETTE.len() - 1)].to_string(),
        ));
        for (a, v) in values.iter_mut().zip(&d.rms) {
            a.push(*v);
        }
    }
    let chart = BarChart {
        title: "RMS gravity torque per actuator: unbalanced and the best design of each size"
            .into(),
        y_label: "RMS gravity torque [N·m]".into(),
        categories: p
            .actuators
            .iter()
            .zip(&p.unbalanced_rms)
            .map(|(a, u)| (a.clone(), format!("unbalanced {}", rms(*u))))
            .collect(),
        series,
        values,
        clip: None,
        min_width: 720.0,
        height: 340.0,
    };
    Some(bar_chart_in(&chart, "N·m", rms))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::partial::tests::sample;

    /// The table: the unbalanced row (RMS per loaded actuator), then the designs in rank order
    /// with their numbers; the unloaded actuator `pan` has no column.
    #[test]
    fn table_rows_carry_the_designs_numbers() {
        let t = table(&sample());
        assert_eq!(t.header[5], "Δ lift");
        assert_eq!(t.header.len(), 7);
        assert_eq!(t.rows.len(), 4);
        assert_eq!(t.rows[0][3].text, "8.000");
        assert_eq!(t.rows[0][5].text, "8.000 N·m");
        assert_eq!(t.rows[2][1].text, "m2");
        assert_eq!(t.rows[2][3].text, "2.000");
        assert_eq!(t.rows[2][4].text, "-75.0 %");
        assert_eq!(t.rows[2][5].text, "-75.0 %");
        assert_eq!(
            t.rows[2][2].text,
            "m2 on link: 2.000 kg at (0.0, 0.0, -425.5) mm (|r| = 425.5 mm)"
        );
        assert!(t.rows[1][2].text.starts_with("m1 on link: unused (0 kg)"));
        assert_eq!(t.highlighted, vec![false, false, true, false]);
    }

    /// The chart: one group per actuator, the unbalanced bar and one per best design, values in
    /// N·m in the tooltips.
    #[test]
    fn chart_has_a_bar_per_actuator_and_series() {
        let svg = chart(&sample()).unwrap();
        assert!(svg.contains("lift unbalanced: 8.000 N·m"), "{svg}");
        assert!(svg.contains("lift m2 (best of 1 counterweight, rank 2): 2.000 N·m"));
        let mut without = sample();
        without.designs.clear();
        assert!(chart(&without).is_none());
    }
}
