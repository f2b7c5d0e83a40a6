//! Property tests: the algebra agrees with plain floating-point evaluation of the same functions.

use counterpoise_symbolic::{LinearAngle, Monomial, Point, TrigPoly, VarKind};
use proptest::prelude::*;

const KINDS: [VarKind; 3] = [VarKind::Angle, VarKind::Angle, VarKind::Length];

/// A random polynomial built only through the public constructors and `+`, `*`.
fn poly() -> impl Strategy<Value = TrigPoly> {
    let term = (
        0u32..3,
        0u32..3,
        any::<bool>(),
        any::<bool>(),
        0u32..3,
        -2.0f64..2.0,
    );
    prop::collection::vec(term, 0..6).prop_map(|terms| {
        let mut p = TrigPoly::zero();
        for (c0, c1, s0, s1, x, coefficient) in terms {
            let mut t = TrigPoly::constant(coefficient);
            t = &t * &TrigPoly::cos(0).pow(c0);
            t = &t * &TrigPoly::cos(1).pow(c1);
            if s0 {
                t = &t * &TrigPoly::sin(0);
            }
            if s1 {
                t = &t * &TrigPoly::sin(1);
            }
            t = &t * &TrigPoly::length(2).pow(x);
            p += &t;
        }
        p
    })
}

fn point() -> impl Strategy<Value = [f64; 3]> {
    (-3.2f64..3.2, -3.2f64..3.2, -1.5f64..1.5).prop_map(|(a, b, x)| [a, b, x])
}

fn at(q: &[f64; 3]) -> Point {
    Point::new(q, &KINDS)
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + a.abs().max(b.abs()))
}

proptest! {
    #[test]
    fn evaluation_commutes_with_sum_and_product(p in poly(), q in poly(), x in point()) {
        let pt = at(&x);
        prop_assert!(close((&p + &q).eval(&pt), p.eval(&pt) + q.eval(&pt), 1e-12));
        prop_assert!(close((&p - &q).eval(&pt), p.eval(&pt) - q.eval(&pt), 1e-12));
        prop_assert!(close((&p * &q).eval(&pt), p.eval(&pt) * q.eval(&pt), 1e-11));
    }

    #[test]
    fn derivative_matches_central_differences(p in poly(), x in point(), var in 0usize..3) {
        let h = 1e-5;
        let mut plus = x;
        let mut minus = x;
        plus[var] += h;
        minus[var] -= h;
        let numeric = (p.eval(&at(&plus)) - p.eval(&at(&minus))) / (2.0 * h);
        let analytic = p.derivative(var, KINDS[var]).eval(&at(&x));
        prop_assert!(close(analytic, numeric, 1e-7), "analytic {analytic} numeric {numeric}");
    }

    #[test]
    fn product_rule_holds_symbolically(p in poly(), q in poly(), var in 0usize..3) {
        let kind = KINDS[var];
        let lhs = (&p * &q).derivative(var, kind);
        let rhs = &(&p.derivative(var, kind) * &q) + &(&p * &q.derivative(var, kind));
        prop_assert!(lhs.approx_eq(&rhs, 1e-12));
    }

    #[test]
    fn canonical_form_is_unique(n0 in -3i32..4, n1 in -3i32..4, offset in -3.0f64..3.0) {
        // cos(n0·a + n1·b + c) expanded in one go, versus built from the angle-sum formula of its
        // parts, versus cos² + sin² = 1 collapsing: identical coefficient maps.
        let whole = LinearAngle { terms: vec![(0, n0), (1, n1)].into_iter().filter(|t| t.1 != 0).collect(), offset };
        let (c, s) = whole.cos_sin();
        let (ca, sa) = LinearAngle { terms: if n0 != 0 { vec![(0, n0)] } else { vec![] }, offset: 0.0 }.cos_sin();
        let (cb, sb) = LinearAngle { terms: if n1 != 0 { vec![(1, n1)] } else { vec![] }, offset }.cos_sin();
        let from_parts = &(&ca * &cb) - &(&sa * &sb);
        prop_assert!(c.approx_eq(&from_parts, 1e-12));
        let mut one = &(&c * &c) + &(&s * &s);
        one.prune(1e-9);
        prop_assert!(one.approx_eq(&TrigPoly::constant(1.0), 1e-12));
        prop_assert!(one.is_constant(), "{one:?}");
    }
}

/// `(sin a + sin b)⁴` expanded by hand with `sin² = 1 − cos²`:
/// `s_a⁴ = 1 − 2c_a² + c_a⁴`, `4 s_a³ s_b = 4 s_a s_b − 4 c_a² s_a s_b`,
/// `6 s_a² s_b² = 6 − 6c_a² − 6c_b² + 6 c_a² c_b²`, and symmetrically, so
/// `8 − 8c_a² − 8c_b² + c_a⁴ + c_b⁴ + 6 c_a² c_b² + 8 s_a s_b − 4 c_a² s_a s_b − 4 c_b² s_a s_b`.
/// The canonical form must hold exactly these nine monomials (no sine squared survives).
#[test]
fn sin_squared_never_survives_a_product() {
    let p = (&TrigPoly::sin(0) + &TrigPoly::sin(1)).pow(4);
    // (cos a power, sin a, cos b power, sin b) → coefficient
    let expected: std::collections::BTreeMap<(u8, bool, u8, bool), f64> = [
        ((0, false, 0, false), 8.0),
        ((2, false, 0, false), -8.0),
        ((0, false, 2, false), -8.0),
        ((4, false, 0, false), 1.0),
        ((0, false, 4, false), 1.0),
        ((2, false, 2, false), 6.0),
        ((0, true, 0, true), 8.0),
        ((2, true, 0, true), -4.0),
        ((0, true, 2, true), -4.0),
    ]
    .into_iter()
    .collect();
    let mut actual = std::collections::BTreeMap::new();
    for (m, c) in p.terms() {
        let m: &Monomial = m;
        assert!(m.variables().all(|v| v < 2), "{m:?}");
        if c.abs() > 1e-12 {
            actual.insert((m.power(0), m.has_sine(0), m.power(1), m.has_sine(1)), c);
        }
    }
    assert_eq!(actual.len(), expected.len(), "{actual:?}");
    for (key, c) in &expected {
        let got = actual.get(key).copied().unwrap_or(f64::NAN);
        assert!((got - c).abs() < 1e-12, "{key:?}: {got} vs {c}");
    }
    let q = [0.3, 2.1, 0.0];
    let direct = (0.3f64.sin() + 2.1f64.sin()).powi(4);
    assert!(close(p.eval(&at(&q)), direct, 1e-13));
}
