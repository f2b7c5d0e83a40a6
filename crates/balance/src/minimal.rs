//! Minimal balancing sets: every set of at most `Dmax` elements whose balance equations
//! `A_S x = −b` are solvable while those of each of its proper subsets are not — without
//! testing all `C(n, ≤ Dmax)` sets.
//!
//! Solvability is monotone (adding columns to `A_S` can only enlarge its column space), so the
//! search is a depth-first walk over sets in lexicographic order that
//!
//! - stops at the first solvable set of a branch (its supersets are not minimal);
//! - skips an element that adds nothing to the column space at the point it is added (every
//!   solvable superset would stay solvable without it, so none is minimal);
//! - skips an element whose energy is identically constant (a counterweight on the pan link);
//! - prunes by *reach*: an element only produces the energy monomials its body poses depend on
//!   (one on link k, only terms in joints ≤ k), so a row of `b` that neither the set nor any
//!   later element in the order reaches, or that the remaining budget cannot reach, ends the
//!   branch.
//!
//! The walk's linear algebra is exact arithmetic modulo the prime `2⁶¹ − 1`, incremental along
//! the branch (one element's columns reduced per step). Every set it reports is then confirmed
//! in rational arithmetic — solvable, and each subset with one element fewer not (which, by
//! monotonicity, proves minimality) — so a reported set is a fact. Completeness rests on the
//! modular rank equalling the rational one on the walk's sets; it can only be lower when the
//! prime divides a non-zero minor, and the confirmations count any disagreement they see.

use num_bigint::BigInt;
use num_traits::{ToPrimitive, Zero};
use rayon::prelude::*;

use crate::exact::ExactBasis;

/// The prime of the modular screen: a Mersenne prime, so that products reduce cheaply.
const P: u64 = (1 << 61) - 1;

fn mul(a: u64, b: u64) -> u64 {
    let t = u128::from(a) * u128::from(b);
    let lo = (t as u64) & P;
    let hi = (t >> 61) as u64;
    let s = lo + hi;
    if s >= P { s - P } else { s }
}

fn sub(a: u64, b: u64) -> u64 {
    if a >= b { a - b } else { a + P - b }
}

fn pow(mut a: u64, mut e: u64) -> u64 {
    let mut r = 1;
    while e > 0 {
        if e & 1 == 1 {
            r = mul(r, a);
        }
        a = mul(a, a);
        e >>= 1;
    }
    r
}

fn inverse(a: u64) -> u64 {
    pow(a, P - 2)
}

fn modp(x: &BigInt) -> u64 {
    let p = BigInt::from(P);
    let r = ((x % &p) + &p) % &p;
    r.to_u64().unwrap_or(0)
}

/// A set of row indices, as bits.
#[derive(Clone, Debug, PartialEq, Eq)]
struct Rows(Vec<u64>);

impl Rows {
    fn empty(n: usize) -> Rows {
        Rows(vec![0; n.div_ceil(64)])
    }
    fn insert(&mut self, i: usize) {
        self.0[i / 64] |= 1 << (i % 64);
    }
    fn union(&self, other: &Rows) -> Rows {
        Rows(self.0.iter().zip(&other.0).map(|(a, b)| a | b).collect())
    }
    /// Rows of `self` not in `other`.
    fn minus(&self, other: &Rows) -> Rows {
        Rows(self.0.iter().zip(&other.0).map(|(a, b)| a & !b).collect())
    }
    fn is_empty(&self) -> bool {
        self.0.iter().all(|&w| w == 0)
    }
    fn count(&self) -> u32 {
        self.0.iter().map(|w| w.count_ones()).sum()
    }
    fn intersection_count(&self, other: &Rows) -> u32 {
        self.0
            .iter()
            .zip(&other.0)
            .map(|(a, b)| (a & b).count_ones())
            .sum()
    }
}

/// What the walk needs of one element: a basis of its column space modulo `P` and the rows
/// its energy reaches.
#[derive(Clone, Debug)]
struct Entry {
    basis: Vec<Vec<u64>>,
    reach: Rows,
    /// Identically constant energy (every exact coefficient zero): never part of a minimal set.
    constant: bool,
}

/// An echelon basis modulo `P`, grown and shrunk along a branch: each vector has a pivot row
/// where it is 1 and every vector after it is 0.
#[derive(Clone, Debug, Default)]
struct Echelon {
    pivots: Vec<usize>,
    vectors: Vec<Vec<u64>>,
}

impl Echelon {
    /// `v` minus its components along the basis.
    fn reduce(&self, v: &mut [u64]) {
        for (&p, w) in self.pivots.iter().zip(&self.vectors) {
            let f = v[p];
            if f != 0 {
                for (x, &y) in v.iter_mut().zip(w) {
                    if y != 0 {
                        *x = sub(*x, mul(f, y));
                    }
                }
            }
        }
    }

    /// Adds the vectors of `basis` not already in the span; returns how many were added.
    fn extend(&mut self, basis: &[Vec<u64>]) -> usize {
        let mut added = 0;
        for v in basis {
            let mut v = v.clone();
            self.reduce(&mut v);
            if let Some(p) = v.iter().position(|&x| x != 0) {
                let inv = inverse(v[p]);
                for x in v.iter_mut() {
                    *x = mul(*x, inv);
                }
                self.pivots.push(p);
                self.vectors.push(v);
                added += 1;
            }
        }
        added
    }

    fn truncate(&mut self, len: usize) {
        self.pivots.truncate(len);
        self.vectors.truncate(len);
    }
}

/// The screen's view of a case: every element's column space and reach, and `b`.
#[derive(Clone, Debug)]
pub struct Screen {
    entries: Vec<Entry>,
    b: Vec<u64>,
    /// Rows of `b` that are non-zero: each must be reached by some element of a balancing set.
    needed: Rows,
    /// `later[e]`: rows reached by the elements `e..` (the union of their reach).
    later: Vec<Rows>,
}

impl Screen {
    pub fn new(exact: &ExactBasis) -> Screen {
        let rows = exact.monomials.len();
        let entries: Vec<Entry> = exact
            .elements
            .iter()
            .map(|columns| {
                let mut reach = Rows::empty(rows);
                let mut constant = true;
                for c in columns {
                    for (r, x) in c.iter().enumerate() {
                        if !x.is_zero() {
                            reach.insert(r);
                            constant = false;
                        }
                    }
                }
                let mut echelon = Echelon::default();
                let vectors: Vec<Vec<u64>> = columns
                    .iter()
                    .map(|c| c.iter().map(modp).collect())
                    .collect();
                echelon.extend(&vectors);
                Entry {
                    basis: echelon.vectors,
                    reach,
                    constant,
                }
            })
            .collect();
        let mut needed = Rows::empty(rows);
        for (r, x) in exact.unbalanced.iter().enumerate() {
            if !x.is_zero() {
                needed.insert(r);
            }
        }
        let mut later = vec![Rows::empty(rows); entries.len() + 1];
        for e in (0..entries.len()).rev() {
            later[e] = later[e + 1].union(&entries[e].reach);
        }
        Screen {
            entries,
            b: exact.unbalanced.iter().map(modp).collect(),
            needed,
            later,
        }
    }

    /// Whether `set` balances modulo `P`.
    fn solvable(&self, set: &[usize]) -> bool {
        let mut echelon = Echelon::default();
        for &e in set {
            echelon.extend(&self.entries[e].basis);
        }
        let mut b = self.b.clone();
        echelon.reduce(&mut b);
        b.iter().all(|&x| x == 0)
    }

    /// Whether a branch that has reached `covered` and may add at most `budget` elements from
    /// `from..` can still reach every needed row: each missing row must be reached by some
    /// later element, and the `budget` later elements that reach most of them must together
    /// reach at least as many (a count bound, so never a wrong prune).
    fn reachable(&self, covered: &Rows, from: usize, budget: usize) -> bool {
        let missing = self.needed.minus(covered);
        if missing.is_empty() {
            return true;
        }
        if budget == 0 || !missing.minus(&self.later[from]).is_empty() {
            return false;
        }
        let mut best: Vec<u32> = self.entries[from..]
            .iter()
            .map(|e| e.reach.intersection_count(&missing))
            .collect();
        best.sort_unstable_by(|a, b| b.cmp(a));
        best.iter().take(budget).sum::<u32>() >= missing.count()
    }
}

/// What the walk found.
#[derive(Clone, Debug, Default)]
pub struct Walk {
    /// The minimal sets, confirmed exactly, in lexicographic order of their sorted elements.
    pub minimal: Vec<Vec<usize>>,
    /// Sets whose solvability the walk tested (the linear test, not a full decision).
    pub tested: u64,
    /// Sets where the modular screen and the exact confirmation disagreed (expected 0).
    pub disagreements: u64,
}

impl Walk {
    fn merge(mut self, other: Walk) -> Walk {
        self.minimal.extend(other.minimal);
        self.tested += other.tested;
        self.disagreements += other.disagreements;
        self
    }
}

/// Every minimal balancing set of at most `dmax` elements (parallel over the first element;
/// the result does not depend on the number of threads).
pub fn minimal_sets(exact: &ExactBasis, dmax: usize) -> Walk {
    let screen = Screen::new(exact);
    let n = screen.entries.len();
    let walk = (0..n)
        .into_par_iter()
        .map(|first| {
            let mut walk = Walk::default();
            let mut state = State {
                screen: &screen,
                exact,
                dmax,
                set: Vec::new(),
                echelon: Echelon::default(),
                walk: &mut walk,
            };
            let covered = Rows::empty(screen.b.len());
            state.visit(first, &covered, &screen.b);
            walk
        })
        .reduce(Walk::default, Walk::merge);
    let mut walk = walk;
    walk.minimal
        .sort_by(|a, b| a.len().cmp(&b.len()).then_with(|| a.cmp(b)));
    walk
}

struct State<'a> {
    screen: &'a Screen,
    exact: &'a ExactBasis,
    dmax: usize,
    set: Vec<usize>,
    echelon: Echelon,
    walk: &'a mut Walk,
}

impl State<'_> {
    /// Adds element `e` to the branch (the current set, reduced `b`, reached rows) and walks on.
    fn visit(&mut self, e: usize, covered: &Rows, b: &[u64]) {
        let entry = &self.screen.entries[e];
        if entry.constant {
            return;
        }
        let covered = covered.union(&entry.reach);
        let depth = self.set.len() + 1;
        if !self.screen.reachable(&covered, e + 1, self.dmax - depth) {
            return;
        }
        let mark = self.echelon.pivots.len();
        let added = self.echelon.extend(&entry.basis);
        self.set.push(e);
        if added > 0 {
            let mut b = b.to_vec();
            let tail = Echelon {
                pivots: self.echelon.pivots[mark..].to_vec(),
                vectors: self.echelon.vectors[mark..].to_vec(),
            };
            tail.reduce(&mut b);
            self.walk.tested += 1;
            if b.iter().all(|&x| x == 0) {
                self.candidate();
            } else if depth < self.dmax {
                for next in e + 1..self.screen.entries.len() {
                    self.visit(next, &covered, &b);
                }
            }
        }
        self.set.pop();
        self.echelon.truncate(mark);
    }

    /// A solvable set all of whose prefixes are not: minimal if no subset with one element fewer
    /// is solvable either. Confirmed exactly; if the exact test finds the set unsolvable after
    /// all, the walk goes on past it.
    fn candidate(&mut self) {
        let set = self.set.clone();
        let without = |k: usize| -> Vec<usize> {
            set.iter()
                .enumerate()
                .filter(|&(i, _)| i != k)
                .map(|(_, &e)| e)
                .collect()
        };
        // The prefix without the last element is known unsolvable; the others are tested.
        for k in 0..set.len().saturating_sub(1) {
            self.walk.tested += 1;
            if self.screen.solvable(&without(k)) {
                return;
            }
        }
        if !self.exact.solve(&set).consistent() {
            self.walk.disagreements += 1;
            return;
        }
        for k in 0..set.len() {
            if set.len() > 1 && self.exact.solve(&without(k)).consistent() {
                self.walk.disagreements += 1;
                return;
            }
        }
        self.walk.minimal.push(set);
    }
}

/// An upper bound on the sets [`minimal_sets`] tests, from the reach pruning alone (no linear
/// algebra): what the variant guard compares with its limit. Counting stops once past `cap`.
pub fn estimate_tested(exact: &ExactBasis, dmax: usize, cap: u64) -> u64 {
    let screen = Screen::new(exact);
    let mut count = 0u64;
    let rows = screen.b.len();
    fn walk(
        screen: &Screen,
        from: usize,
        covered: &Rows,
        depth: usize,
        dmax: usize,
        cap: u64,
        count: &mut u64,
    ) {
        for e in from..screen.entries.len() {
            if *count > cap {
                return;
            }
            let entry = &screen.entries[e];
            if entry.constant {
                continue;
            }
            let covered = covered.union(&entry.reach);
            if !screen.reachable(&covered, e + 1, dmax - depth - 1) {
                continue;
            }
            *count += 1;
            if depth + 1 < dmax {
                walk(screen, e + 1, &covered, depth + 1, dmax, cap, count);
            }
        }
    }
    walk(&screen, 0, &Rows::empty(rows), 0, dmax, cap, &mut count);
    count
}

/// The minimal balancing sets of at most `dmax` elements by brute force, for tests: every one
/// of the `C(n, ≤ dmax)` sets eliminated exactly, and a solvable set kept when none of its
/// proper subsets (all of them, not only those one element smaller) is solvable.
pub fn brute_force_minimal(exact: &ExactBasis, dmax: usize) -> Vec<Vec<usize>> {
    let n = exact.elements.len();
    let solvable: std::collections::HashSet<Vec<usize>> = crate::enumerate::variants(n, dmax)
        .collect::<Vec<_>>()
        .into_par_iter()
        .filter(|s| exact.solve(s).consistent())
        .collect();
    let mut minimal: Vec<Vec<usize>> = solvable
        .iter()
        .filter(|s| {
            // Proper non-empty subsets by bit mask over the set's positions.
            (1..(1u32 << s.len()) - 1).all(|mask| {
                let subset: Vec<usize> = (0..s.len())
                    .filter(|i| mask & (1 << i) != 0)
                    .map(|i| s[i])
                    .collect();
                !solvable.contains(&subset)
            })
        })
        .cloned()
        .collect();
    minimal.sort_by(|a, b| a.len().cmp(&b.len()).then_with(|| a.cmp(b)));
    minimal
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn modular_arithmetic_by_hand() {
        assert_eq!(mul(P - 1, P - 1), 1, "(−1)² = 1");
        assert_eq!(mul(inverse(3), 3), 1);
        assert_eq!(sub(0, 1), P - 1);
        assert_eq!(modp(&BigInt::from(-1)), P - 1);
        assert_eq!(modp(&(BigInt::from(P) * 5 + 7)), 7);
    }
}

/// Why the minimal-set search cannot run.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MinimalError {
    /// The walk's pruning and its confirmations are exact: a case decided in floating point
    /// (an irrational constant) has no exact basis to walk.
    #[error("minimal sets need an exact case: {0}")]
    NotExact(String),
}

/// Most non-minimal balancing sets decided in full when looking for the smallest Dmax at which
/// a variant balances (supersets of minimal sets that are not realizable themselves).
pub const SUPERSET_DECISIONS: usize = 5_000;

/// The minimal sets, each fully decided, and the smallest Dmax at which something balances.
#[derive(Clone, Debug)]
pub struct MinimalReport {
    pub catalogue: crate::element::Catalogue,
    /// Every minimal balancing set with its verdict (balanced, unrealizable, …), smallest
    /// first, then in lexicographic order.
    pub sets: Vec<crate::search::VariantResult>,
    /// Sets the walk tested for solvability (linear test only).
    pub tested: u64,
    /// Sets the reach pruning alone would test (the guard's estimate).
    pub estimate: u64,
    /// `C(n, ≤ Dmax)`: what testing every combination would take.
    pub combinations: u128,
    /// Modular screen against exact confirmation disagreements (expected 0).
    pub disagreements: u64,
    /// Fewest elements whose balance equations are solvable (the smallest minimal set).
    pub smallest_linear: Option<usize>,
    /// Fewest elements of a variant that balances with verified physical parameters, when
    /// found within Dmax (looking past the minimal sets when the smallest are not realizable).
    pub smallest_balanced: Option<usize>,
    /// Non-minimal sets decided to find `smallest_balanced`.
    pub supersets_decided: usize,
    /// Why `smallest_balanced` may be an overestimate (the superset budget ran out).
    pub smallest_balanced_note: Option<String>,
    /// When no minimal set of the smallest balancing size is realizable: the balanced
    /// non-minimal sets of that size (a minimal set plus elements that make it realizable).
    pub first_balanced: Vec<crate::search::VariantResult>,
}

/// Minimal balancing sets up to `options.dmax`, each decided in full (realization and
/// verification as in [`crate::search::search`]), and the smallest Dmax at which a variant
/// balances.
pub fn minimal_search(
    energy: &crate::energy::MechanismEnergy,
    catalogue: crate::element::Catalogue,
    options: crate::search::SearchOptions,
) -> Result<MinimalReport, MinimalError> {
    use crate::search::{Status, decide};
    let basis = crate::linear::LiftedBasis::build(energy, &catalogue);
    let Some(exact) = &basis.exact else {
        return Err(MinimalError::NotExact(
            energy.exact.as_ref().err().cloned().unwrap_or_default(),
        ));
    };
    let checks = crate::verify::VerificationSet::new(energy);
    let dmax = options.dmax;
    let walk = minimal_sets(exact, dmax);
    let estimate = estimate_tested(exact, dmax, u64::MAX);
    let decide_all = |sets: &[Vec<usize>]| -> Vec<crate::search::VariantResult> {
        sets.par_iter()
            .map(|s| decide(energy, &catalogue, &basis, &checks, s, options.hints))
            .collect()
    };
    let sets = decide_all(&walk.minimal);
    let realizable = |v: &crate::search::VariantResult| v.status == Status::Balanced;
    let smallest_linear = walk.minimal.iter().map(Vec::len).min();
    let mut smallest_balanced = sets
        .iter()
        .filter(|v| realizable(v))
        .map(|v| v.elements.len())
        .min();
    // A set larger than a minimal one may balance where the minimal one is unrealizable: decide
    // the solvable non-minimal sets of each size below the best found (supersets of minimal
    // sets), smallest size first, within a budget.
    let mut supersets_decided = 0;
    let mut note = None;
    let mut first_balanced = Vec::new();
    if let Some(d0) = smallest_linear {
        let limit = smallest_balanced.map_or(dmax, |d| d - 1);
        let n = catalogue.len();
        'sizes: for d in d0 + 1..=limit {
            let mut supersets: Vec<Vec<usize>> = Vec::new();
            for m in walk.minimal.iter().filter(|m| m.len() < d) {
                let rest: Vec<usize> = (0..n).filter(|e| !m.contains(e)).collect();
                use itertools::Itertools;
                for extra in rest.into_iter().combinations(d - m.len()) {
                    let mut s = m.clone();
                    s.extend(extra);
                    s.sort_unstable();
                    supersets.push(s);
                    if supersets.len() + supersets_decided > SUPERSET_DECISIONS * 4 {
                        break;
                    }
                }
            }
            supersets.sort_unstable();
            supersets.dedup();
            if supersets_decided + supersets.len() > SUPERSET_DECISIONS {
                note = Some(format!(
                    "not looked past Dmax {}: the {} balancing sets of {d} elements that are not \
                     minimal exceed the budget of {SUPERSET_DECISIONS} decisions",
                    d - 1,
                    supersets.len()
                ));
                break 'sizes;
            }
            supersets_decided += supersets.len();
            let balanced: Vec<_> = decide_all(&supersets)
                .into_iter()
                .filter(realizable)
                .collect();
            if !balanced.is_empty() {
                smallest_balanced = Some(d);
                first_balanced = balanced;
                break;
            }
        }
    }
    Ok(MinimalReport {
        combinations: crate::enumerate::variant_count(catalogue.len() as u64, 0, dmax as u64),
        catalogue,
        sets,
        tested: walk.tested,
        estimate,
        disagreements: walk.disagreements,
        smallest_linear,
        smallest_balanced,
        supersets_decided,
        smallest_balanced_note: note,
        first_balanced,
    })
}
