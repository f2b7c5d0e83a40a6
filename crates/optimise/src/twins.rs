//! Mirror-twin springs: two catalogue springs whose potential energies are the same function of
//! the joint coordinates once some anchor coordinates of one change sign.
//!
//! A spring's energy per unit of each lifted variable (`K`, `K·a_i`, `K·b_l`, `K·a_i·b_l`) is
//! a column of the exact balance system. When spring `T`'s columns are spring `R`'s with the
//! signs `s_i` on `K·a_i`, `t_l` on `K·b_l` and `s_i·t_l` on `K·a_i·b_l` (and `K`'s the same),
//! then `T` with anchors `(s ⊙ a, t ⊙ b)` stores exactly the energy `R` stores with `(a, b)`.
//! If their bounds also correspond (the same stiffness and anchor-length bounds, each anchor
//! box mirrored on the axes whose sign flips), a variant holding `T` and the same variant
//! holding `R` instead have the same balanced family up to those sign changes, the same
//! feasible counterweights, and — massless springs never change a balanced variant's motor
//! torques — the same objective and peak limits at every counterweight choice. The certified
//! search of one is the search of the other: its verdict, lower bound and design (anchors
//! mirrored) carry over. Joint reactions do not (the springs load other joints), so the twin's
//! spring choice and final evaluation stay its own.
//!
//! On the palletizer K42 (upper_arm–slider_h) and K53 (front_link–slider_v) are twins with
//! every anchor coordinate mirrored, and so are K43 and K52: the parallelograms move the two
//! pairs of bodies alike.
//!
//! Twins are taken from the exact basis only (rational cases): the columns are compared entry
//! by entry, so no rounding can make two springs twins.

use counterpoise_balance::exact::ExactField;
use counterpoise_balance::linear::LiftedBasis;
use counterpoise_balance::{Catalogue, Element};

use crate::overrides::{BoundsTable, ElementBounds, SpringBounds};

/// A catalogue spring's twin of lower catalogue index, and the signs that map it.
#[derive(Clone, Debug, PartialEq)]
pub struct SpringTwin {
    /// Catalogue index of the twin this spring follows (the lowest index of its class).
    pub leader: usize,
    /// Sign of each anchor-a component (in `axes_a` order): the follower's `a_i` is
    /// `sign_a[i]` times the leader's.
    pub sign_a: Vec<f64>,
    /// The same for anchor b.
    pub sign_b: Vec<f64>,
}

impl SpringTwin {
    /// A spring as its own twin: every sign `+1` (a spring that follows none keeps its
    /// anchors when a variant is mirrored).
    pub fn identity(spring: usize, na: usize, nb: usize) -> SpringTwin {
        SpringTwin {
            leader: spring,
            sign_a: vec![1.0; na],
            sign_b: vec![1.0; nb],
        }
    }

    /// The sign of each lifted variable of the spring (`K`, `K·a_i`, `K·b_l`, `K·a_i·b_l`):
    /// the follower's lifted value is the sign times the leader's.
    pub fn lifted_signs(&self) -> Vec<f64> {
        let mut out = vec![1.0];
        out.extend(&self.sign_a);
        out.extend(&self.sign_b);
        for sa in &self.sign_a {
            for sb in &self.sign_b {
                out.push(sa * sb);
            }
        }
        out
    }
}

/// Per catalogue entry, the twin it follows (`None` for counterweights, for springs without a
/// twin of lower index, and for every entry when the case has no exact rational basis).
pub fn spring_twins(
    basis: &LiftedBasis,
    catalogue: &Catalogue,
    bounds: &BoundsTable,
) -> Vec<Option<SpringTwin>> {
    let n = catalogue.entries.len();
    let mut out: Vec<Option<SpringTwin>> = vec![None; n];
    let Some(exact) = basis.exact.as_ref() else {
        return out;
    };
    for follower in 0..n {
        for leader in 0..follower {
            // A leader follows no one: classes are keyed by their lowest index.
            if out[leader].is_some() {
                continue;
            }
            if let Some(twin) = twin_of::<counterpoise_symbolic::Rational>(
                catalogue,
                bounds,
                &exact.elements[leader],
                &exact.elements[follower],
                leader,
                follower,
            ) {
                out[follower] = Some(twin);
                break;
            }
        }
    }
    out
}

/// The signs under which `follower`'s exact columns are `leader`'s and the bounds correspond,
/// if any.
fn twin_of<F: ExactField>(
    catalogue: &Catalogue,
    bounds: &BoundsTable,
    leader_columns: &[Vec<F::Entry>],
    follower_columns: &[Vec<F::Entry>],
    leader: usize,
    follower: usize,
) -> Option<SpringTwin> {
    let (
        Element::Spring {
            axes_a: la,
            axes_b: lb,
            ..
        },
        Element::Spring {
            axes_a: fa,
            axes_b: fb,
            ..
        },
    ) = (
        &catalogue.entries[leader].element,
        &catalogue.entries[follower].element,
    )
    else {
        return None;
    };
    if la != fa || lb != fb || leader_columns.len() != follower_columns.len() {
        return None;
    }
    let (ElementBounds::Spring(lbounds), ElementBounds::Spring(fbounds)) =
        (&bounds.entries[leader], &bounds.entries[follower])
    else {
        return None;
    };
    let (na, nb) = (la.len(), lb.len());
    // Every sign pattern of the anchor components (at most 2⁶ for spatial springs).
    for pattern in 0u32..(1 << (na + nb)) {
        let sign = |k: usize| if pattern >> k & 1 == 1 { -1.0 } else { 1.0 };
        let twin = SpringTwin {
            leader,
            sign_a: (0..na).map(sign).collect(),
            sign_b: (na..na + nb).map(sign).collect(),
        };
        let signs = twin.lifted_signs();
        let columns_match = signs
            .iter()
            .zip(leader_columns.iter().zip(follower_columns))
            .all(|(&s, (l, f))| {
                l.len() == f.len()
                    && l.iter().zip(f).all(|(le, fe)| {
                        if s > 0.0 {
                            le == fe
                        } else {
                            &F::neg_entry(le) == fe
                        }
                    })
            });
        if columns_match && bounds_correspond(lbounds, fbounds, la, &twin.sign_a, lb, &twin.sign_b)
        {
            return Some(twin);
        }
    }
    None
}

/// Whether the follower's bounds are the leader's with each mirrored axis's box interval
/// reflected.
fn bounds_correspond(
    leader: &SpringBounds,
    follower: &SpringBounds,
    axes_a: &[usize],
    sign_a: &[f64],
    axes_b: &[usize],
    sign_b: &[f64],
) -> bool {
    let mirrored = |r: [f64; 2], s: f64| if s > 0.0 { r } else { [-r[1], -r[0]] };
    let boxes_match = |lb: &[[f64; 2]; 3], fb: &[[f64; 2]; 3], axes: &[usize], signs: &[f64]| {
        (0..3).all(|axis| match axes.iter().position(|&a| a == axis) {
            Some(k) => mirrored(lb[axis], signs[k]) == fb[axis],
            None => lb[axis] == fb[axis],
        })
    };
    leader.stiffness == follower.stiffness
        && leader.anchor_a == follower.anchor_a
        && leader.anchor_b == follower.anchor_b
        && boxes_match(&leader.box_a, &follower.box_a, axes_a, sign_a)
        && boxes_match(&leader.box_b, &follower.box_b, axes_b, sign_b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::context::Context;
    use counterpoise_symbolic::Point;

    fn palletizer() -> Context {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../cases/palletizer.json");
        let model = counterpoise_model::Case::from_path(std::path::Path::new(path)).expect("case");
        Context::new(&model, None).expect("context")
    }

    fn entry(ctx: &Context, label: &str) -> usize {
        ctx.catalogue
            .entries
            .iter()
            .position(|e| e.label == label)
            .expect("a catalogue label")
    }

    /// The palletizer's parallelograms give two pairs of twins: K53 is K42 with both anchors
    /// negated (the balance relations of m4 + K42 and m4 + K53 differ by the signs of the
    /// terms odd in the anchors), and K52 stores K43's energy as it is. No other spring has one.
    #[test]
    fn the_palletizer_has_two_pairs_of_twins() {
        let ctx = palletizer();
        let twins = spring_twins(&ctx.basis, &ctx.catalogue, &ctx.bounds);
        let found: Vec<(String, String)> = twins
            .iter()
            .enumerate()
            .filter_map(|(k, t)| {
                t.as_ref().map(|t| {
                    (
                        ctx.catalogue.entries[k].label.clone(),
                        ctx.catalogue.entries[t.leader].label.clone(),
                    )
                })
            })
            .collect();
        assert_eq!(
            found,
            [("K52".into(), "K43".into()), ("K53".into(), "K42".into())]
        );
        let k53 = twins[entry(&ctx, "K53")].as_ref().unwrap();
        assert_eq!(k53.sign_a, [-1.0, -1.0]);
        assert_eq!(k53.sign_b, [-1.0, -1.0]);
        assert_eq!(
            k53.lifted_signs(),
            [1.0, -1.0, -1.0, -1.0, -1.0, 1.0, 1.0, 1.0, 1.0]
        );
        let k52 = twins[entry(&ctx, "K52")].as_ref().unwrap();
        assert_eq!(k52.sign_a, [1.0, 1.0]);
        assert_eq!(k52.sign_b, [1.0, 1.0]);
    }

    /// The energy of a zero-free-length spring, `½K|p_a − p_b|²`, from the body poses: K53 with
    /// anchors `(−a, −b)` and K42 with `(a, b)` differ by one constant at every configuration.
    #[test]
    fn twins_store_the_same_energy_at_sampled_configurations() {
        let ctx = palletizer();
        let energy = &ctx.energy;
        let body = |name: &str| {
            energy
                .bodies
                .iter()
                .position(|b| b.name == name)
                .expect("a body")
        };
        let spring_energy = |at: &Point, a_body: &str, b_body: &str, a: [f64; 3], b: [f64; 3]| {
            let (ra, oa) = energy.pose(body(a_body), at);
            let (rb, ob) = energy.pose(body(b_body), at);
            let pa: Vec<f64> = (0..3)
                .map(|i| oa[i] + (0..3).map(|j| ra[i][j] * a[j]).sum::<f64>())
                .collect();
            let pb: Vec<f64> = (0..3)
                .map(|i| ob[i] + (0..3).map(|j| rb[i][j] * b[j]).sum::<f64>())
                .collect();
            0.5 * 3000.0 * (0..3).map(|i| (pa[i] - pb[i]).powi(2)).sum::<f64>()
        };
        let (a, b) = ([0.31, -0.72, 0.0], [-0.18, 0.44, 0.0]);
        let neg = |v: [f64; 3]| v.map(|x| -x);
        let bodies42 = &ctx.catalogue.entries[entry(&ctx, "K42")].bodies;
        let bodies53 = &ctx.catalogue.entries[entry(&ctx, "K53")].bodies;
        let differences: Vec<f64> =
            counterpoise_balance::verify::sample_configurations(energy, 40, 17)
                .iter()
                .map(|q| {
                    let at = Point::new(q, &energy.kinds);
                    spring_energy(&at, &bodies53[0], &bodies53[1], neg(a), neg(b))
                        - spring_energy(&at, &bodies42[0], &bodies42[1], a, b)
                })
                .collect();
        let spread = differences
            .iter()
            .fold(0.0f64, |m, d| m.max((d - differences[0]).abs()));
        assert!(
            spread < 1e-9,
            "the energies differ by more than a constant: {spread}"
        );
        // Without the mirror, they do not.
        let q0 = counterpoise_balance::verify::sample_configurations(energy, 2, 17);
        let plain: Vec<f64> = q0
            .iter()
            .map(|q| {
                let at = Point::new(q, &energy.kinds);
                spring_energy(&at, &bodies53[0], &bodies53[1], a, b)
                    - spring_energy(&at, &bodies42[0], &bodies42[1], a, b)
            })
            .collect();
        assert!((plain[0] - plain[1]).abs() > 1e-3, "{plain:?}");
    }

    /// A bound that does not mirror breaks the twins: with K53's anchor-a box on x narrowed to
    /// [−0.2, 0.5] while K42's stays free, no sign pattern maps K42's bounds onto K53's. With
    /// K42's box [−0.5, 0.2] (whose mirror is K53's) they are twins again; a stiffness bound
    /// of K53's own breaks them once more.
    #[test]
    fn twins_need_mirrored_bounds() {
        let mut ctx = palletizer();
        let k53 = entry(&ctx, "K53");
        let ElementBounds::Spring(original) = ctx.bounds.entries[k53] else {
            panic!("K53 is a spring")
        };
        let mut narrowed = original;
        narrowed.box_a[0] = [-0.2, 0.5];
        ctx.bounds.entries[k53] = ElementBounds::Spring(narrowed);
        assert!(spring_twins(&ctx.basis, &ctx.catalogue, &ctx.bounds)[k53].is_none());
        // The same box on K42, mirrored onto K53: twins again.
        let k42 = entry(&ctx, "K42");
        let ElementBounds::Spring(mut leader) = ctx.bounds.entries[k42] else {
            panic!("K42 is a spring")
        };
        leader.box_a[0] = [-0.5, 0.2];
        ctx.bounds.entries[k42] = ElementBounds::Spring(leader);
        let twin = spring_twins(&ctx.basis, &ctx.catalogue, &ctx.bounds)[k53].clone();
        assert_eq!(twin.map(|t| t.leader), Some(k42));
        // A stiffness bound of its own breaks them too.
        narrowed.stiffness[1] *= 2.0;
        ctx.bounds.entries[k53] = ElementBounds::Spring(narrowed);
        assert!(spring_twins(&ctx.basis, &ctx.catalogue, &ctx.bounds)[k53].is_none());
    }

    /// Two planar springs to the base with hand-made columns: `[j + 1, 2j + 3]` for lifted
    /// variable `j` (`K`, `K·ax`, `K·ay`, `K·bx`, `K·by`, `K·ax·bx`, `K·ax·by`, `K·ay·bx`,
    /// `K·ay·by`), the follower's with the signs given and its `axes_b`.
    fn pair(
        signs: [i64; 9],
        axes_b: Vec<usize>,
        boxes: ([f64; 2], [f64; 2]),
    ) -> Option<SpringTwin> {
        use counterpoise_balance::{Attachment, CatalogueEntry};
        use counterpoise_symbolic::Rational;
        let spring = |label: &str, axes_b: Vec<usize>| CatalogueEntry {
            element: Element::Spring {
                body: 0,
                other: Attachment::Base,
                axes_a: vec![0, 1],
                axes_b,
            },
            label: label.into(),
            description: String::new(),
            bodies: Vec::new(),
            variables: Vec::new(),
            energy: Vec::new(),
        };
        let catalogue = Catalogue {
            entries: vec![spring("K10", vec![0, 1]), spring("K20", axes_b)],
        };
        let bounds = |box_ax: [f64; 2]| {
            let mut box_a = [crate::overrides::FREE_AXIS; 3];
            box_a[0] = box_ax;
            ElementBounds::Spring(SpringBounds {
                stiffness: [1000.0, 10000.0],
                anchor_a: [0.0, 1.0],
                anchor_b: [0.0, 0.5],
                box_a,
                box_b: [crate::overrides::FREE_AXIS; 3],
            })
        };
        let table = BoundsTable {
            entries: vec![bounds(boxes.0), bounds(boxes.1)],
        };
        let int = |k: i64| Rational::from_integer(k.into()).numer().clone();
        let leader: Vec<Vec<_>> = (0..9).map(|j| vec![int(j + 1), int(2 * j + 3)]).collect();
        let follower: Vec<Vec<_>> = (0..9)
            .map(|j| {
                vec![
                    int(signs[j as usize] * (j + 1)),
                    int(signs[j as usize] * (2 * j + 3)),
                ]
            })
            .collect();
        twin_of::<Rational>(&catalogue, &table, &leader, &follower, 0, 1)
    }

    const FREE: [f64; 2] = crate::overrides::FREE_AXIS;

    /// [`pair`] for springs on `axes` (both anchors), free boxes, with the follower's columns
    /// the leader's times the lifted signs of `sign_a`, `sign_b`.
    fn pair_on(axes: Vec<usize>, sign_a: Vec<f64>, sign_b: Vec<f64>) -> Option<SpringTwin> {
        use counterpoise_balance::{Attachment, CatalogueEntry};
        use counterpoise_symbolic::Rational;
        let spring = || CatalogueEntry {
            element: Element::Spring {
                body: 0,
                other: Attachment::Base,
                axes_a: axes.clone(),
                axes_b: axes.clone(),
            },
            label: String::new(),
            description: String::new(),
            bodies: Vec::new(),
            variables: Vec::new(),
            energy: Vec::new(),
        };
        let catalogue = Catalogue {
            entries: vec![spring(), spring()],
        };
        let free = ElementBounds::Spring(SpringBounds {
            stiffness: [1000.0, 10000.0],
            anchor_a: [0.0, 1.0],
            anchor_b: [0.0, 0.5],
            box_a: [FREE; 3],
            box_b: [FREE; 3],
        });
        let table = BoundsTable {
            entries: vec![free, free],
        };
        let signs = SpringTwin {
            leader: 0,
            sign_a,
            sign_b,
        }
        .lifted_signs();
        let int = |k: i64| Rational::from_integer(k.into()).numer().clone();
        let leader: Vec<Vec<_>> = (0..signs.len() as i64).map(|j| vec![int(j + 1)]).collect();
        let follower: Vec<Vec<_>> = signs
            .iter()
            .zip(0..)
            .map(|(&s, j)| vec![int(s as i64 * (j + 1))])
            .collect();
        twin_of::<Rational>(&catalogue, &table, &leader, &follower, 0, 1)
    }

    /// Springs on one axis and on three: every sign pattern of `a` and `b` is tried, `b`'s
    /// signs read from the bits after `a`'s.
    #[test]
    fn every_sign_pattern_is_tried_on_one_and_three_axes() {
        let one = pair_on(vec![0], vec![1.0], vec![-1.0]).expect("b mirrored on one axis");
        assert_eq!((one.sign_a, one.sign_b), (vec![1.0], vec![-1.0]));
        let three = pair_on(vec![0, 1, 2], vec![-1.0, 1.0, 1.0], vec![1.0, 1.0, -1.0])
            .expect("a_x and b_z mirrored");
        assert_eq!(
            (three.sign_a, three.sign_b),
            (vec![-1.0, 1.0, 1.0], vec![1.0, 1.0, -1.0])
        );
    }

    /// The sign pattern is read off the columns: `K·ax` and the two products holding `ax`
    /// negated make `a_x` the mirrored coordinate; a column negated alone matches no pattern
    /// (`K·ax` flips but `K·ax·bx` does not); springs on other anchor axes are never twins;
    /// a box on a mirrored axis must be the leader's reflected.
    #[test]
    fn a_twin_is_found_by_its_sign_pattern() {
        assert_eq!(SpringTwin::identity(3, 2, 2).lifted_signs(), [1.0; 9]);
        let same = pair([1; 9], vec![0, 1], (FREE, FREE)).expect("identical columns");
        assert_eq!(
            (same.leader, same.sign_a, same.sign_b),
            (0, vec![1.0, 1.0], vec![1.0, 1.0])
        );
        let ax = [1, -1, 1, 1, 1, -1, -1, 1, 1];
        let mirrored = pair(ax, vec![0, 1], (FREE, FREE)).expect("a_x mirrored");
        assert_eq!(
            (mirrored.sign_a.clone(), mirrored.sign_b.clone()),
            (vec![-1.0, 1.0], vec![1.0, 1.0])
        );
        assert_eq!(mirrored.lifted_signs(), ax.map(|s| s as f64));
        let by = [1, 1, 1, 1, -1, 1, -1, 1, -1];
        let mirrored = pair(by, vec![0, 1], (FREE, FREE)).expect("b_y mirrored");
        assert_eq!(
            (mirrored.sign_a, mirrored.sign_b),
            (vec![1.0, 1.0], vec![1.0, -1.0])
        );
        assert!(pair([1, -1, 1, 1, 1, 1, 1, 1, 1], vec![0, 1], (FREE, FREE)).is_none());
        assert!(
            pair([-1; 9], vec![0, 1], (FREE, FREE)).is_none(),
            "K never flips"
        );
        assert!(
            pair([1; 9], vec![0, 2], (FREE, FREE)).is_none(),
            "b on x and z"
        );
        assert!(pair(ax, vec![0, 1], ([-0.5, 0.2], [-0.2, 0.5])).is_some());
        assert!(pair(ax, vec![0, 1], ([-0.5, 0.2], [-0.5, 0.2])).is_none());
        assert!(pair([1; 9], vec![0, 1], ([-0.5, 0.2], [-0.5, 0.2])).is_some());
    }
}
