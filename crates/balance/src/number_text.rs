//! Numbers as people read them in the balance relations and the exact solutions' text.
//!
//! Both the relations (`relations`) and the exact solutions (`exact`) print values this way;
//! the formatting lives apart so that neither depends on the other for it.

/// A value with six significant digits, without trailing zeros: `228.625`, `1.23457e-7`.
pub fn significant(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let magnitude = x.abs().log10().floor();
    if !(-4.0..6.0).contains(&magnitude) {
        return format!("{x:.5e}");
    }
    let decimals = (5.0 - magnitude).max(0.0) as usize;
    let s = format!("{x:.decimals$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    };
    if s == "-0" { "0".to_string() } else { s }
}
