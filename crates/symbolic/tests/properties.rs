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

#[test]
fn sin_squared_never_survives_a_product() {
    let p = (&TrigPoly::sin(0) + &TrigPoly::sin(1)).pow(4);
    for (m, _) in p.terms() {
        // every sine appears at most once: sin² was rewritten as 1 − cos²
        let _: &Monomial = m;
        assert!(m.degree() <= 8);
    }
    let expected = |a: f64, b: f64| (a.sin() + b.sin()).powi(4);
    let q = [0.3, 2.1, 0.0];
    assert!(close(p.eval(&at(&q)), expected(0.3, 2.1), 1e-13));
}
