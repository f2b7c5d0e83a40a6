//! Readable rendering of polynomials with coordinate names, for summaries and reports.

use crate::monomial::{MAX_VARS, Monomial};
use crate::poly::TrigPoly;

/// Renders a monomial as `cos(th2)^2·sin(th3)·rho` (`1` for the constant monomial).
///
/// A coordinate whose kind is a length is rendered by name; `names[k]` names coordinate `k`, and
/// `is_angle[k]` says whether it is an angle.
pub fn format_monomial(m: &Monomial, names: &[&str], is_angle: &[bool]) -> String {
    let mut factors = Vec::new();
    for k in 0..MAX_VARS.min(names.len()) {
        let p = m.power(k);
        let base = if is_angle[k] {
            format!("cos({})", names[k])
        } else {
            names[k].to_string()
        };
        match p {
            0 => {}
            1 => factors.push(base),
            _ => factors.push(format!("{base}^{p}")),
        }
        if m.has_sine(k) {
            factors.push(format!("sin({})", names[k]));
        }
    }
    if factors.is_empty() {
        "1".to_string()
    } else {
        factors.join("·")
    }
}

impl TrigPoly {
    /// Renders the polynomial as `−672.84·sin(th2) + 2830.49·sin(th3)`, terms in canonical order,
    /// coefficients with `digits` decimals; `skip_constant` leaves out the constant term.
    pub fn format_with(
        &self,
        names: &[&str],
        is_angle: &[bool],
        digits: usize,
        skip_constant: bool,
    ) -> String {
        let mut out = String::new();
        for (m, c) in self.terms() {
            if skip_constant && m.is_one() {
                continue;
            }
            let magnitude = format!("{:.*}", digits, c.abs());
            let sign = if c < 0.0 { "−" } else { "+" };
            if out.is_empty() {
                if c < 0.0 {
                    out.push('−');
                }
            } else {
                out.push_str(&format!(" {sign} "));
            }
            if m.is_one() {
                out.push_str(&magnitude);
            } else {
                out.push_str(&format!(
                    "{magnitude}·{}",
                    format_monomial(m, names, is_angle)
                ));
            }
        }
        if out.is_empty() { "0".to_string() } else { out }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn renders_terms_with_names() {
        let p = &(&TrigPoly::sin(0).scale(-672.84) + &TrigPoly::sin(1).scale(2830.49))
            + &TrigPoly::constant(5.0);
        let text = p.format_with(&["th2", "th3"], &[true, true], 2, true);
        assert_eq!(text, "−672.84·sin(th2) + 2830.49·sin(th3)");
        let q = &TrigPoly::cos(0).pow(2) * &TrigPoly::length(1);
        assert_eq!(
            q.format_with(&["a", "x"], &[true, false], 1, false),
            "1.0·cos(a)^2·x"
        );
    }
}
