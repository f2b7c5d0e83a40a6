//! Number, angle and text formatting shared by the HTML, Markdown and CSV writers, so the three
//! outputs show the same digits.

use std::f64::consts::PI;

/// Escapes text for HTML/XML content and attribute values. Every case-provided string (names,
/// labels, paths, reasons) goes through this before it reaches report.html.
pub fn escape_html(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            // Characters XML 1.0 forbids would make the XHTML-compatible report ill-formed.
            c if (c as u32) < 0x20 && !matches!(c, '\t' | '\n' | '\r') => out.push('\u{FFFD}'),
            c => out.push(c),
        }
    }
    out
}

/// Escapes text for a Markdown table cell (pipes, newlines, emphasis and code markers, and
/// HTML-significant characters, since Markdown renderers pass raw HTML through).
pub fn escape_md(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '|' => out.push_str("\\|"),
            '\n' | '\r' => out.push(' '),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '&' => out.push_str("&amp;"),
            // `_` (GFM ignores it inside words) and brackets (no link without `(…)` after
            // them) stay as they are so the raw file reads well in a terminal.
            '*' | '`' | '\\' => {
                out.push('\\');
                out.push(c);
            }
            c => out.push(c),
        }
    }
    out
}

/// A CSV field (RFC 4180 quoting when needed).
pub fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// Fixed decimals without a negative zero.
pub fn fixed(x: f64, decimals: usize) -> String {
    if !x.is_finite() {
        return format!("{x}");
    }
    let s = format!("{x:.decimals$}");
    if s.starts_with('-') && s[1..].chars().all(|c| c == '0' || c == '.') {
        s[1..].to_string()
    } else {
        s
    }
}

/// A measured value with digits suited to its magnitude (about 4 significant figures).
pub fn value(x: f64) -> String {
    let a = x.abs();
    if x == 0.0 {
        "0".to_string()
    } else if !x.is_finite() {
        format!("{x}")
    } else if a >= 1000.0 {
        fixed(x, 0)
    } else if a >= 100.0 {
        fixed(x, 1)
    } else if a >= 1.0 {
        fixed(x, 2)
    } else if a >= 0.01 {
        fixed(x, 4)
    } else {
        format!("{x:.2e}")
    }
}

/// [`value`] without trailing zeros (`1.00` → `1`), for coefficients in formulas.
pub fn compact(x: f64) -> String {
    let s = value(x);
    if s.contains('.') && !s.contains('e') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// A percentage variation with an explicit sign, two decimals (resolution of the ranking).
pub fn percent(x: f64) -> String {
    let s = fixed(x, 2);
    if x > 0.0 && s != "0.00" {
        format!("+{s}")
    } else {
        s
    }
}

/// An angle in radians as in the paper's Table 1: multiples of π/2 by name, else three
/// decimals, normalised to [0, 2π).
pub fn angle(rad: f64) -> String {
    if !rad.is_finite() {
        return format!("{rad}");
    }
    let mut a = rad.rem_euclid(2.0 * PI);
    if (a - 2.0 * PI).abs() < 1e-6 {
        a = 0.0;
    }
    for (k, name) in [(0.0, "0"), (0.5, "π/2"), (1.0, "π"), (1.5, "3π/2")] {
        if (a - k * PI).abs() < 1e-6 {
            return name.to_string();
        }
    }
    fixed(a, 3)
}

/// Polar form (radius, angle) of a vector in a plane given by its two axes.
pub fn polar(v: [f64; 3], axes: (usize, usize)) -> (f64, f64) {
    let (x, y) = (v[axes.0], v[axes.1]);
    (x.hypot(y), y.atan2(x))
}

/// Seconds for the timings table.
pub fn seconds(s: f64) -> String {
    if s >= 10.0 {
        fixed(s, 1)
    } else if s >= 0.1 {
        fixed(s, 2)
    } else {
        fixed(s, 3)
    }
}

/// A mass for prose: `0 kg`, `12.00 kg`.
pub fn mass(kg: f64) -> String {
    format!("{} kg", value(kg))
}

/// A force with an engineering prefix: `850.0 N`, `3.00 kN`, `1.20 MN`.
pub fn force(n: f64) -> String {
    let a = n.abs();
    if a >= 1e6 {
        format!("{} MN", value(n / 1e6))
    } else if a >= 1e3 {
        format!("{} kN", value(n / 1e3))
    } else {
        format!("{} N", value(n))
    }
}

/// A task `[from, to]` for people.
pub fn task(t: [usize; 2]) -> String {
    format!("{}→{}", t[0], t[1])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escaping() {
        assert_eq!(
            escape_html(r#"<b a="x">&'"#),
            "&lt;b a=&quot;x&quot;&gt;&amp;&#39;"
        );
        assert_eq!(escape_html("a\u{1}b"), "a\u{FFFD}b");
        assert_eq!(escape_md("a|b<c>"), "a\\|b&lt;c&gt;");
        assert_eq!(csv_field("plain"), "plain");
        assert_eq!(csv_field("m4 + K43, x"), "\"m4 + K43, x\"");
        assert_eq!(csv_field("say \"hi\""), "\"say \"\"hi\"\"\"");
    }

    #[test]
    fn numbers() {
        assert_eq!(fixed(-0.0001, 2), "0.00");
        assert_eq!(value(1234.6), "1235");
        assert_eq!(value(17.482), "17.48");
        assert_eq!(value(0.5), "0.5000");
        assert_eq!(value(1.5e-6), "1.50e-6");
        assert_eq!(compact(1.0), "1");
        assert_eq!(compact(-0.5), "-0.5");
        assert_eq!(percent(-58.83), "-58.83");
        assert_eq!(percent(0.6), "+0.60");
        assert_eq!(percent(0.0), "0.00");
        assert_eq!(percent(-0.001), "0.00");
        assert_eq!(mass(0.0), "0 kg");
        assert_eq!(mass(2.0), "2.00 kg");
        assert_eq!(force(850.0), "850.0 N");
        assert_eq!(force(3000.0), "3.00 kN");
        assert_eq!(force(1.2e6), "1.20 MN");
    }

    #[test]
    fn angles() {
        assert_eq!(angle(0.0), "0");
        assert_eq!(angle(PI), "π");
        assert_eq!(angle(-PI / 2.0), "3π/2");
        assert_eq!(angle(PI / 2.0 + 1e-9), "π/2");
        assert_eq!(angle(2.0 * PI - 1e-9), "0");
        assert_eq!(angle(1.0), "1.000");
        let (r, phi) = polar([0.0, -0.5, 0.0], (0, 1));
        assert!((r - 0.5).abs() < 1e-15);
        assert_eq!(angle(phi), "3π/2");
    }
}
