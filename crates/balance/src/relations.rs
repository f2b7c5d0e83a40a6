//! Balance relations in readable form: what balance imposes on the lifted parameters, and the
//! freedom it leaves (like the paper's symbolic `solve` output, e.g. `m4·r4x = −68.59 kg·m`).

use nalgebra::{DMatrix, DVector};
use serde::Serialize;

use counterpoise_symbolic::RefArith;
use num_traits::Signed;

use crate::element::{CatalogueEntry, Element};
use crate::exact::positivity::{self, Bound};
use crate::exact::{ExactField, ExactSolution, exact_text};
use crate::linear::{FIXED_TOL, LinearSolution};

pub use crate::number_text::significant;

/// One free direction of the balanced family: moving along it keeps the energy constant.
#[derive(Clone, Debug, Serialize)]
pub struct FreeDirection {
    /// Lifted variable → component (largest component scaled to ±1; negligible ones omitted).
    pub components: Vec<(String, f64)>,
    /// Indices of the lifted variables listed in `components`, in the same order.
    #[serde(skip)]
    pub variables: Vec<usize>,
    /// The whole direction over the set's lifted variables, with the same normalisation
    /// (negligible components kept): the family is `x_p + Σ t_k·direction_k`.
    #[serde(skip)]
    pub direction: DVector<f64>,
    /// For a one-dimensional family `x_p + t·n`: the interval of `t` over which every installed
    /// mass and stiffness stays positive (`None` = unbounded on that side). Lifted positivity only;
    /// spring realizability is checked on the witness.
    pub positive_interval: Option<(Option<f64>, Option<f64>)>,
}

/// Unit of each lifted variable of an element, in the order of its variables.
pub fn variable_units(entry: &CatalogueEntry) -> Vec<&'static str> {
    match &entry.element {
        Element::Counterweight { axes, .. } => std::iter::once("kg")
            .chain(axes.iter().map(|_| "kg·m"))
            .collect(),
        Element::Spring { axes_a, axes_b, .. } => std::iter::once("N/m")
            .chain(axes_a.iter().map(|_| "N"))
            .chain(axes_b.iter().map(|_| "N"))
            .chain(std::iter::repeat_n("N·m", axes_a.len() * axes_b.len()))
            .collect(),
    }
}

fn format_number(x: f64) -> String {
    let s = format!("{x:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".to_string()
    } else {
        s.to_string()
    }
}

/// Reduced row-echelon form of `[A | −b]` in the variant's lifted variables, written as equations.
///
/// Gauss–Jordan with the pivot taken in variable order (so each relation is solved for the
/// earliest variable it involves), rows and columns scaled first so that the tolerance is
/// relative.
pub fn balance_relations(
    solution: &LinearSolution,
    b: &DVector<f64>,
    names: &[String],
    units: &[&str],
) -> Vec<String> {
    let (rows, cols) = solution.matrix.shape();
    let mut m = DMatrix::zeros(rows, cols + 1);
    for j in 0..cols {
        m.set_column(j, &(solution.matrix.column(j) / solution.column_scale[j]));
    }
    m.set_column(cols, &(-b));
    let tol = 1e-9 * m.amax().max(f64::MIN_POSITIVE);
    let mut pivot_row = 0;
    let mut pivots = Vec::new();
    for j in 0..cols {
        if pivot_row == rows {
            break;
        }
        let (best, value) = (pivot_row..rows)
            .map(|i| (i, m[(i, j)].abs()))
            .fold((pivot_row, 0.0), |acc, x| if x.1 > acc.1 { x } else { acc });
        if value <= tol {
            continue;
        }
        m.swap_rows(pivot_row, best);
        let p = m[(pivot_row, j)];
        m.row_mut(pivot_row).scale_mut(1.0 / p);
        for i in 0..rows {
            if i != pivot_row {
                let f = m[(i, j)];
                if f != 0.0 {
                    for c in 0..=cols {
                        let v = m[(pivot_row, c)];
                        m[(i, c)] -= f * v;
                    }
                }
            }
        }
        pivots.push((pivot_row, j));
        pivot_row += 1;
    }
    let mut relations = Vec::new();
    for (row, pivot) in pivots {
        // Undo column scaling: y_j = s_j x_j, so x_pivot + Σ c_j (s_j/s_p) x_j = rhs / s_p.
        let s_p = solution.column_scale[pivot];
        let mut lhs = names[pivot].clone();
        for j in (pivot + 1)..cols {
            let c = m[(row, j)] * solution.column_scale[j] / s_p;
            if m[(row, j)].abs() > 1e-9 {
                let sign = if c < 0.0 { "−" } else { "+" };
                lhs.push_str(&format!(" {sign} {}·{}", format_number(c.abs()), names[j]));
            }
        }
        let rhs = m[(row, cols)] / s_p;
        relations.push(format!("{lhs} = {} {}", format_number(rhs), units[pivot]));
    }
    relations
}

/// The free directions of the solution set, with the positivity interval for a 1-D family.
pub fn free_directions(
    solution: &LinearSolution,
    names: &[String],
    positive_variables: &[usize],
) -> Vec<FreeDirection> {
    let n = &solution.nullspace;
    let one_dimensional = n.ncols() == 1;
    (0..n.ncols())
        .map(|k| {
            let column = n.column(k);
            let scaled: Vec<f64> = (0..column.len())
                .map(|j| column[j] * solution.column_scale[j])
                .collect();
            let biggest = scaled.iter().enumerate().fold((0, 0.0f64), |acc, (j, v)| {
                if v.abs() > acc.1 { (j, v.abs()) } else { acc }
            });
            let norm = column[biggest.0];
            let direction: DVector<f64> = column.map(|v| v / norm);
            let variables: Vec<usize> = (0..column.len())
                .filter(|&j| scaled[j].abs() > FIXED_TOL * biggest.1.max(f64::MIN_POSITIVE) * 1e3)
                .collect();
            let components = variables
                .iter()
                .map(|&j| (names[j].clone(), direction[j]))
                .collect();
            let positive_interval = one_dimensional.then(|| {
                let mut lo: Option<f64> = None;
                let mut hi: Option<f64> = None;
                for &j in positive_variables {
                    // x_p[j] + t·n[j]/norm > 0
                    let slope = direction[j];
                    if (column[j] * solution.column_scale[j]).abs() <= FIXED_TOL {
                        continue;
                    }
                    let bound = -solution.particular[j] / slope;
                    if slope > 0.0 {
                        lo = Some(lo.map_or(bound, |l: f64| l.max(bound)));
                    } else {
                        hi = Some(hi.map_or(bound, |h: f64| h.min(bound)));
                    }
                }
                (lo, hi)
            });
            FreeDirection {
                components,
                variables,
                direction,
                positive_interval,
            }
        })
        .collect()
}

/// The balance relations of an exact solution, solved for the earliest variable of each and
/// written exactly: `m4 = 1829/8 (228.625) kg`, `K43·ax − 1/4 (0.25)·K43·bx = 0 N`.
pub fn exact_relations<F: ExactField>(
    solution: &ExactSolution<F>,
    names: &[String],
    units: &[&str],
) -> Vec<String>
where
    for<'a> &'a F: RefArith<F>,
{
    solution
        .echelon
        .relations()
        .into_iter()
        .map(|(pivot, terms, value)| {
            let mut lhs = names[pivot].clone();
            for (j, c) in terms {
                let sign = if c.is_negative() { "−" } else { "+" };
                let magnitude = if c.is_negative() { -c } else { c };
                if magnitude == F::one() {
                    lhs.push_str(&format!(" {sign} {}", names[j]));
                } else {
                    lhs.push_str(&format!(" {sign} {}·{}", exact_text(&magnitude), names[j]));
                }
            }
            format!("{lhs} = {} {}", exact_text(&value), units[pivot])
        })
        .collect()
}

/// The interval a lifted variable can take over the balanced family while every mass and
/// stiffness is positive.
#[derive(Clone, Debug, Serialize)]
pub struct AdmissibleRange {
    pub variable: String,
    pub unit: &'static str,
    /// `None`: unbounded below.
    pub low: Option<f64>,
    /// `None`: unbounded above.
    pub high: Option<f64>,
    /// Exact interval, e.g. `(0, 9/28 (0.321429)]`.
    pub interval: String,
}

fn interval_text<F: ExactField>(low: &Option<Bound<F>>, high: &Option<Bound<F>>) -> String {
    let open = match low {
        Some(b) if b.closed => format!("[{}", exact_text(&b.value)),
        Some(b) => format!("({}", exact_text(&b.value)),
        None => "(−∞".to_string(),
    };
    let close = match high {
        Some(b) if b.closed => format!("{}]", exact_text(&b.value)),
        Some(b) => format!("{})", exact_text(&b.value)),
        None => "+∞)".to_string(),
    };
    format!("{open}, {close}")
}

/// Ranges of every mass, stiffness, first moment `m·r` and spring moment `K·a`, `K·b` (the
/// products `K·a·b` are left out: they follow from the others) over the positive family.
pub fn admissible_ranges<F: ExactField>(
    solution: &ExactSolution<F>,
    entries: &[(usize, &CatalogueEntry)],
    names: &[String],
    units: &[&'static str],
) -> Vec<AdmissibleRange>
where
    for<'a> &'a F: RefArith<F>,
{
    let heads = solution.heads();
    let mut out = Vec::new();
    for (k, (_, entry)) in entries.iter().enumerate() {
        let range = solution.element_range(k);
        let count = match &entry.element {
            Element::Counterweight { axes, .. } => 1 + axes.len(),
            Element::Spring { axes_a, axes_b, .. } => 1 + axes_a.len() + axes_b.len(),
        };
        for j in range.start..range.start + count {
            let Ok(r) = positivity::range(&heads, &solution.affine(j)) else {
                continue;
            };
            out.push(AdmissibleRange {
                variable: names[j].clone(),
                unit: units[j],
                low: r.low.as_ref().map(|b| b.value.to_f64()),
                high: r.high.as_ref().map(|b| b.value.to_f64()),
                interval: interval_text(&r.low, &r.high),
            });
        }
    }
    out
}
