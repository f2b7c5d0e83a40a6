//! The bodies' tree: cycles of the parent relation, world poses, the mechanism's
//! characteristic length, and which body a name carries.

use counterpoise_symbolic::{Point, TrigPoly, VarKind};
use nalgebra::Vector3;

use super::magnitudes::*;
use super::validator::*;
use crate::case::Case;
use crate::error::ModelError;
use crate::limits::MAX_POSE_DEGREE;
use crate::model::{BodyId, Coordinate};
use crate::pose::{Parser, PolyPose};

/// Reports every cycle of the parent relation once (at its first body in file order) and
/// returns which bodies lie on or hang from a cycle (they have no world pose).
pub(super) fn find_cycles(v: &mut Validator, case: &Case, parents: &[Option<BodyId>]) -> Vec<bool> {
    #[derive(Clone, Copy, PartialEq)]
    enum State {
        New,
        Active,
        Done(bool),
    }
    let n = parents.len();
    let mut state = vec![State::New; n];
    for start in 0..n {
        let mut chain = Vec::new();
        let mut current = start;
        let broken = loop {
            match state[current] {
                State::Done(b) => break b,
                State::Active => {
                    let at = chain.iter().position(|&c| c == current).unwrap_or(0);
                    let cycle = &chain[at..];
                    let first = *cycle.iter().min().unwrap_or(&current);
                    let mut names: Vec<&str> = cycle
                        .iter()
                        .map(|&c| case.bodies[c].name.as_str())
                        .collect();
                    names.push(&case.bodies[current].name);
                    v.push(ModelError::Cycle {
                        path: format!("bodies[{first}].parent"),
                        cycle: names.join(" → "),
                    });
                    break true;
                }
                State::New => {
                    state[current] = State::Active;
                    chain.push(current);
                    match parents[current] {
                        Some(BodyId::Body(p)) => current = p,
                        Some(BodyId::Base) | None => break false,
                    }
                }
            }
        };
        for c in chain {
            state[c] = State::Done(broken);
        }
    }
    state.into_iter().map(|s| s == State::Done(true)).collect()
}

/// World poses `parent world · relative`, or `None` where a pose step, a parent, or a cycle
/// prevents it. Iterative (a chain of thousands of bodies must not deepen the call stack), and
/// a composition whose degree would pass [`MAX_POSE_DEGREE`] is refused at the body's pose.
pub(super) fn world_poses(
    v: &mut Validator,
    parents: &[Option<BodyId>],
    relative: &[Option<PolyPose>],
    on_cycle: &[bool],
) -> Vec<Option<PolyPose>> {
    let n = parents.len();
    let mut memo: Vec<Option<Option<PolyPose>>> = vec![None; n];
    for start in 0..n {
        // Walk up to a resolved body or the base, then resolve the chain back down.
        let mut chain = Vec::new();
        let mut current = start;
        while memo[current].is_none() {
            chain.push(current);
            match parents[current] {
                Some(BodyId::Body(p)) if !on_cycle[current] => current = p,
                _ => break,
            }
        }
        for &i in chain.iter().rev() {
            let pose = if on_cycle[i] {
                None
            } else {
                let parent = match parents[i] {
                    None => None,
                    Some(BodyId::Base) => Some(PolyPose::identity()),
                    Some(BodyId::Body(p)) => memo[p].clone().flatten(),
                };
                parent.zip(relative[i].as_ref()).and_then(|(parent, rel)| {
                    let degree = parent.degree() + rel.degree();
                    if degree > MAX_POSE_DEGREE {
                        v.invalid(
                            format!("bodies[{i}].pose"),
                            format!(
                                "the world pose reaches degree {degree} in one coordinate; at most {MAX_POSE_DEGREE} is supported"
                            ),
                        );
                        return None;
                    }
                    let mut pose = parent.compose(rel);
                    pose.prune();
                    Some(pose)
                })
            };
            memo[i] = Some(pose);
        }
    }
    memo.into_iter().map(Option::flatten).collect()
}

/// Checks a body's relative pose: translations within [`MAX_LENGTH`] and degree within
/// [`MAX_POSE_DEGREE`].
pub(super) fn pose_in_bounds(v: &mut Validator, pose: &PolyPose, path: &str) -> bool {
    let degree = pose.degree();
    if degree > MAX_POSE_DEGREE {
        v.invalid(
            path,
            format!("the pose reaches degree {degree} in one coordinate; at most {MAX_POSE_DEGREE} is supported"),
        );
        return false;
    }
    let largest = pose
        .origin
        .0
        .iter()
        .map(TrigPoly::max_abs_coefficient)
        .fold(0.0, f64::max);
    if !largest.is_finite() || largest > MAX_LENGTH {
        v.invalid(
            path,
            format!(
                "its translations reach {} m, beyond the supported magnitude ±{} m",
                num(largest),
                num(MAX_LENGTH)
            ),
        );
        return false;
    }
    true
}

/// The length scale of joint tolerances: the largest distance of a body origin from the base
/// origin at the reference configuration, or of a joint point from its first body's origin.
pub(super) fn characteristic_length(
    case: &Case,
    coordinates: &[Coordinate],
    world: &[Option<PolyPose>],
    parser: &Parser,
    coordinates_ok: bool,
) -> f64 {
    let mut length: f64 = 0.0;
    if coordinates_ok {
        let q: Vec<f64> = coordinates.iter().map(Coordinate::midpoint).collect();
        let kinds: Vec<VarKind> = coordinates.iter().map(|c| c.kind).collect();
        let at = Point::new(&q, &kinds);
        for pose in world.iter().flatten() {
            length = length.max(Vector3::from(pose.origin.eval(&at)).norm());
        }
    }
    for j in &case.joints {
        if let Some(point) = &j.point {
            let mut ignored = Vec::new();
            if let Some(p) = parser.constant_vec(point, "", &mut ignored) {
                length = length.max(Vector3::from(p).norm());
            }
        }
    }
    if length.is_finite() { length } else { 0.0 }
}

/// Resolves a body that carries something (a payload): the base cannot.
pub(super) fn carried_body(
    v: &mut Validator,
    body_id: &dyn Fn(&str) -> Option<BodyId>,
    name: &str,
    path: &str,
) -> Option<usize> {
    match body_id(name) {
        None => {
            v.unknown(path, "body", name);
            None
        }
        Some(BodyId::Base) => {
            v.invalid(
                path,
                "a payload must be carried by a moving body, not the base",
            );
            None
        }
        Some(BodyId::Body(i)) => Some(i),
    }
}
