//! Joint reactions: Newton–Euler per body with the joint constraint wrenches as unknowns.
//!
//! Each joint transmits a wrench from its first body to its second, at the joint point, with
//! the components the joint can carry (world axes, `e` the joint axis, `e₁ ⊥ e₂ ⊥ e`):
//!
//! | kind | force unknowns | moment unknowns |
//! |---|---|---|
//! | revolute | x, y, z | e₁, e₂ |
//! | prismatic | e₁, e₂ | x, y, z |
//! | spherical | x, y, z | – |
//! | universal | x, y, z | e × e' (e' the second axis) |
//! | fixed | x, y, z | x, y, z |
//! | orientation | – | x, y, z |
//!
//! For every body `Σ constraint wrenches = inertial wrench − applied wrenches` (applied:
//! springs and actuators), six equations per body (moments about the body frame origin):
//! `A(q) λ = b`. An actuator acts along its joint's axis — a torque about a revolute axis, a
//! force along a prismatic axis — equal and opposite on the joint's two bodies; its size is the
//! actuator force `Q_u` divided by `κ`, the joint displacement per unit actuated coordinate.
//!
//! Mechanisms with loops that are planar in space (the palletizer's pantograph) are
//! overconstrained: `A` has more columns than rank and the reactions are not unique. We report
//! the minimum-norm solution `λ = A⁺ b` (all unknowns in N and N·m; the pseudo-inverse drops
//! singular values below [`RANK_TOLERANCE`] times the largest) and flag it. The fast path uses
//! `A⁺ = Aᵀ (AAᵀ + UUᵀ)⁻¹` with `U` an orthonormal basis of the body velocity Jacobian — the
//! left null space of `A` (constraint wrenches do no work on admissible motions) — checked once
//! at set-up; otherwise a full SVD per sample.

use crate::linalg::checked_svd;
use counterpoise_model::{BodyId, JointKind, Model};
use nalgebra::{DMatrix, Vector3};

use crate::kernel::required_wrenches_with;
use crate::lu::SmallLu;
use crate::mechanism::{BodyKin, Mechanism, Scratch};
use crate::params::ParameterSet;
use crate::reaction_kernels::*;
use crate::regressor::{SampleRegressor, SpringFrame};

/// Relative singular-value threshold of the pseudo-inverse.
pub const RANK_TOLERANCE: f64 = 1e-10;

/// The pseudo-inverse `A⁺` (`K × 6L`) of a reaction matrix `a` (`6L × K`), dropping singular
/// values below [`RANK_TOLERANCE`] times the largest. The threshold is relative so that the rank
/// decision does not depend on the unit of length: `A`'s moment rows scale with the mechanism's
/// size, and an absolute threshold would call a metre-sized mechanism's rank differently from
/// the same mechanism drawn in millimetres. Without an SVD (a non-finite entry, no convergence)
/// every entry is NaN, so the sample's reactions are NaN (the task is then left out as
/// non-finite), not a made-up number.
fn pseudo_inverse(a: DMatrix<f64>) -> DMatrix<f64> {
    let (rows, k) = a.shape();
    match checked_svd(a, true) {
        Some(svd) => {
            let smax = svd.singular_values.max();
            svd.pseudo_inverse(RANK_TOLERANCE * smax)
                .unwrap_or_else(|_| DMatrix::zeros(k, rows))
        }
        None => DMatrix::from_element(k, rows, f64::NAN),
    }
}
#[derive(Clone, Debug)]
struct JointInfo {
    kind: JointKind,
    bodies: [BodyId; 2],
    points: [Vector3<f64>; 2],
    axis0: Vector3<f64>,
    axis2: Option<Vector3<f64>>,
    offset: usize,
}

impl JointInfo {
    fn counts(&self) -> (usize, usize) {
        match self.kind {
            JointKind::Revolute => (3, 2),
            JointKind::Prismatic => (2, 3),
            JointKind::Spherical => (3, 0),
            JointKind::Universal => (3, 1),
            JointKind::Fixed => (3, 3),
            JointKind::Orientation => (0, 3),
        }
    }
}

/// A joint's geometry at one sample (world axes): its point, its axis, and the directions of
/// its force and moment unknowns (held inline: frames are rebuilt at every sample).
#[derive(Clone, Debug, Default)]
pub struct JointFrame {
    pub point: Vector3<f64>,
    pub axis: Vector3<f64>,
    directions: [Vector3<f64>; 6],
    force_count: usize,
    moment_count: usize,
}

impl JointFrame {
    fn new(
        point: Vector3<f64>,
        axis: Vector3<f64>,
        forces: &[Vector3<f64>],
        moments: &[Vector3<f64>],
    ) -> JointFrame {
        let mut directions = [Vector3::zeros(); 6];
        directions[..forces.len()].copy_from_slice(forces);
        directions[forces.len()..forces.len() + moments.len()].copy_from_slice(moments);
        JointFrame {
            point,
            axis,
            directions,
            force_count: forces.len(),
            moment_count: moments.len(),
        }
    }

    /// Directions of the force unknowns.
    pub fn forces(&self) -> &[Vector3<f64>] {
        &self.directions[..self.force_count]
    }

    /// Directions of the moment unknowns.
    pub fn moments(&self) -> &[Vector3<f64>] {
        &self.directions[self.force_count..self.force_count + self.moment_count]
    }
}

/// Two unit vectors completing `e` to an orthonormal basis (deterministic).
fn perpendiculars(e: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let helper = if e.x.abs() <= e.y.abs() && e.x.abs() <= e.z.abs() {
        Vector3::x()
    } else if e.y.abs() <= e.z.abs() {
        Vector3::y()
    } else {
        Vector3::z()
    };
    let e1 = e.cross(&helper).normalize();
    let e2 = e.cross(&e1);
    (e1, e2)
}

/// Joint reactions of one sample for one parameter column: per joint the force and the
/// moment (about the joint point) that the joint's first body exerts on its second, world axes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct JointReactions {
    pub force: Vec<Vector3<f64>>,
    pub moment: Vec<Vector3<f64>>,
}

impl JointReactions {
    /// `|F_j|` per joint.
    pub fn force_magnitudes(&self) -> impl Iterator<Item = f64> + '_ {
        self.force.iter().map(|f| f.norm())
    }

    /// `|M_j|` per joint.
    pub fn moment_magnitudes(&self) -> impl Iterator<Item = f64> + '_ {
        self.moment.iter().map(|m| m.norm())
    }
}

/// Builds and solves the reaction equations.
#[derive(Clone, Debug)]
pub struct ReactionSolver {
    joints: Vec<JointInfo>,
    unknowns: usize,
    bodies: usize,
    /// `(actuator, joint)`.
    actuated: Vec<(usize, usize)>,
    /// The solution is a minimum-norm choice (more unknowns than independent equations).
    pub minimum_norm: bool,
    /// Rank of `A` at the reference configuration.
    pub rank: usize,
    fast: bool,
    /// Rows of `A` each column can touch (the rows of the joint's bodies).
    pattern: Vec<Vec<usize>>,
}

impl ReactionSolver {
    pub fn new(model: &Model, mech: &Mechanism) -> ReactionSolver {
        let mut offset = 0;
        let joints: Vec<JointInfo> = model
            .joints
            .iter()
            .map(|j| {
                let mut info = JointInfo {
                    kind: j.kind,
                    bodies: j.bodies,
                    points: j.points,
                    axis0: j.axes.map(|a| a[0].normalize()).unwrap_or_else(Vector3::z),
                    axis2: j.axis2.map(|a| a.normalize()),
                    offset,
                };
                let (f, m) = info.counts();
                offset += f + m;
                info.offset = offset - f - m;
                info
            })
            .collect();
        let actuated = model
            .actuators
            .iter()
            .enumerate()
            .map(|(a, act)| (a, act.joint))
            .collect();
        let mut solver = ReactionSolver {
            joints,
            unknowns: offset,
            bodies: model.bodies.len(),
            actuated,
            minimum_norm: false,
            rank: 0,
            fast: false,
            pattern: Vec::new(),
        };
        for j in &solver.joints {
            let (f, m) = j.counts();
            for c in 0..f + m {
                let part = if c < f { 0..6 } else { 3..6 };
                let mut rows: Vec<usize> = Vec::new();
                for side in j.bodies {
                    if let BodyId::Body(b) = side {
                        rows.extend(part.clone().map(|r| 6 * b + r));
                    }
                }
                rows.sort_unstable();
                rows.dedup();
                solver.pattern.push(rows);
            }
        }
        // Rank and null-space check at the reference configuration.
        let q = model.reference_configuration();
        let mut scratch = Scratch::default();
        mech.eval_poses(&q, &mut scratch);
        let zeros = vec![0.0; mech.n];
        let kin: Vec<BodyKin> = (0..mech.body_count)
            .map(|b| mech.body_kin(&scratch.pose, b, &zeros, &zeros))
            .collect();
        let frames = solver.frames(mech, &scratch.pose);
        let a = solver.matrix(&frames, &kin);
        // A non-finite matrix (an overflow in the case's numbers) leaves the rank at 0 and the
        // slow path: nalgebra's uncapped SVD never returns on a NaN.
        if a.ncols() > 0
            && a.nrows() > 0
            && let Some(svd) = checked_svd(a.clone(), false)
        {
            let smax = svd.singular_values.max();
            solver.rank = svd
                .singular_values
                .iter()
                .filter(|&&s| s > RANK_TOLERANCE * smax)
                .count();
            let u = mobility_basis(&kin, mech.n);
            let leak = (a.transpose() * &u).amax();
            solver.fast = u.ncols() == mech.n
                && solver.rank + mech.n == a.nrows()
                && leak <= 1e-9 * smax.max(1.0);
        }
        solver.minimum_norm = solver.rank < solver.unknowns;
        solver
    }

    pub fn joint_count(&self) -> usize {
        self.joints.len()
    }

    pub fn unknowns(&self) -> usize {
        self.unknowns
    }

    /// Whether the fast normal-equation path is in use (see the module doc).
    pub fn is_fast(&self) -> bool {
        self.fast
    }

    /// Joint geometry at the sample whose poses are in `pose`.
    pub fn frames(&self, mech: &Mechanism, pose: &[f64]) -> Vec<JointFrame> {
        let mut frames = Vec::with_capacity(self.joints.len());
        self.frames_into(mech, pose, &mut frames);
        frames
    }

    /// [`Self::frames`] into a reused buffer.
    fn frames_into(&self, mech: &Mechanism, pose: &[f64], frames: &mut Vec<JointFrame>) {
        frames.clear();
        frames.extend(self.joints.iter().map(|j| {
            let (r0, p0) = mech.pose_of(pose, j.bodies[0]);
            let (r1, p1) = mech.pose_of(pose, j.bodies[1]);
            let point = if j.kind == JointKind::Prismatic {
                p1 + r1 * j.points[1]
            } else {
                p0 + r0 * j.points[0]
            };
            let axis = r0 * j.axis0;
            let (e1, e2) = perpendiculars(&axis);
            let xyz = [Vector3::x(), Vector3::y(), Vector3::z()];
            match j.kind {
                JointKind::Revolute => JointFrame::new(point, axis, &xyz, &[e1, e2]),
                JointKind::Prismatic => JointFrame::new(point, axis, &[e1, e2], &xyz),
                JointKind::Spherical => JointFrame::new(point, axis, &xyz, &[]),
                JointKind::Universal => {
                    let second = r1 * j.axis2.unwrap_or(e1);
                    let normal = axis.cross(&second);
                    let normal = if normal.norm() > 1e-12 {
                        normal.normalize()
                    } else {
                        e1
                    };
                    JointFrame::new(point, axis, &xyz, &[normal])
                }
                JointKind::Fixed => JointFrame::new(point, axis, &xyz, &xyz),
                JointKind::Orientation => JointFrame::new(point, axis, &[], &xyz),
            }
        }));
    }

    /// `A` (`6L × K`): column per unknown, rows `[F; N_o]` per body.
    pub fn matrix(&self, frames: &[JointFrame], kin: &[BodyKin]) -> DMatrix<f64> {
        let mut a = DMatrix::zeros(6 * self.bodies, self.unknowns);
        for (j, f) in self.joints.iter().zip(frames) {
            let mut col = j.offset;
            for e in f.forces() {
                for (side, sign) in [(1usize, 1.0), (0, -1.0)] {
                    if let BodyId::Body(b) = j.bodies[side] {
                        let m = (f.point - kin[b].p).cross(e);
                        for r in 0..3 {
                            a[(6 * b + r, col)] += sign * e[r];
                            a[(6 * b + 3 + r, col)] += sign * m[r];
                        }
                    }
                }
                col += 1;
            }
            for e in f.moments() {
                for (side, sign) in [(1usize, 1.0), (0, -1.0)] {
                    if let BodyId::Body(b) = j.bodies[side] {
                        for r in 0..3 {
                            a[(6 * b + 3 + r, col)] += sign * e[r];
                        }
                    }
                }
                col += 1;
            }
        }
        a
    }

    /// Joint reactions for every parameter column at one sample.
    ///
    /// `reg` holds the sample's body kinematics and wrench regressors, `lu` the LU of `G`,
    /// `actuator_forces[p]` the actuator forces `Q_u` of column `p`; `work` is reused scratch.
    /// The same factorisation and solve as the grid path ([`Self::prepare`],
    /// [`Self::solve_prepared`]).
    #[allow(clippy::too_many_arguments)]
    pub fn solve(
        &self,
        mech: &Mechanism,
        pose: &[f64],
        reg: &SampleRegressor,
        lu: &SmallLu,
        params: &ParameterSet,
        columns: &[usize],
        actuator_forces: &[[f64; counterpoise_symbolic::MAX_VARS]],
        work: &mut ReactionWork,
    ) -> Vec<JointReactions> {
        let kin = &reg.kin;
        let rows = 6 * self.bodies;
        let m = columns.len();
        self.prepare(mech, pose, kin, lu, work);
        let mut w = vec![0.0; rows];
        let mut b = vec![0.0; rows * m];
        let frames: Vec<SpringFrame> = params
            .springs
            .iter()
            .map(|slot| SpringFrame::new(mech, pose, slot))
            .collect();
        for (c, &p) in columns.iter().enumerate() {
            required_wrenches_with(&reg.wrench, &frames, params, p, &mut w);
            self.subtract_actuators_batch(work, kin, &actuator_forces[c], 1, &mut w, 1);
            for (r, &x) in w.iter().enumerate() {
                b[r * m + c] = x;
            }
        }
        let mut out = vec![0.0; 6 * self.joints.len() * m];
        self.solve_prepared(work, &mut b, m, &mut out);
        (0..m)
            .map(|c| {
                let component = |j: usize, r: usize| out[(6 * j + r) * m + c];
                JointReactions {
                    force: (0..self.joints.len())
                        .map(|j| Vector3::new(component(j, 0), component(j, 1), component(j, 2)))
                        .collect(),
                    moment: (0..self.joints.len())
                        .map(|j| Vector3::new(component(j, 3), component(j, 4), component(j, 5)))
                        .collect(),
                }
            })
            .collect()
    }

    /// Joint displacement per unit actuated coordinate, per actuator: `κ` with
    /// `j_row = κ·G_a` (`j_row` the joint's relative rate along its axis as a row in `q̇`),
    /// i.e. `κ = (G⁻ᵀ j_rowᵀ)_a`.
    fn kappas(&self, frames: &[JointFrame], kin: &[BodyKin], lu: &SmallLu, n: usize) -> Vec<f64> {
        self.actuated
            .iter()
            .map(|&(act, joint)| {
                let j = &self.joints[joint];
                let f = &frames[joint];
                let mut row = [0.0; counterpoise_symbolic::MAX_VARS];
                for (k, value) in row.iter_mut().enumerate().take(n) {
                    let rate = |side: usize| -> Vector3<f64> {
                        match j.bodies[side] {
                            BodyId::Base => Vector3::zeros(),
                            BodyId::Body(b) => {
                                if j.kind == JointKind::Prismatic {
                                    kin[b].jv[k] + kin[b].jw[k].cross(&(f.point - kin[b].p))
                                } else {
                                    kin[b].jw[k]
                                }
                            }
                        }
                    };
                    *value = f.axis.dot(&(rate(1) - rate(0)));
                }
                lu.solve_transpose(&mut row);
                row[act]
            })
            .collect()
    }

    /// Factors the reaction equations of one sample into `work` (geometry and `q` only: the
    /// factorisation serves every velocity state and parameter column of the sample).
    pub fn prepare(
        &self,
        mech: &Mechanism,
        pose: &[f64],
        kin: &[BodyKin],
        lu: &SmallLu,
        work: &mut ReactionWork,
    ) {
        let rows = 6 * self.bodies;
        let k = self.unknowns;
        work.rows = rows;
        work.k = k;
        self.frames_into(mech, pose, &mut work.frames);
        work.kappas = self.kappas(&work.frames, kin, lu, mech.n);
        work.a.clear();
        work.a.resize(rows * k, 0.0);
        for (j, f) in self.joints.iter().zip(&work.frames) {
            let mut col = j.offset;
            for e in f.forces() {
                for (side, sign) in [(1usize, 1.0), (0, -1.0)] {
                    if let BodyId::Body(b) = j.bodies[side] {
                        let m = (f.point - kin[b].p).cross(e);
                        for r in 0..3 {
                            work.a[col * rows + 6 * b + r] += sign * e[r];
                            work.a[col * rows + 6 * b + 3 + r] += sign * m[r];
                        }
                    }
                }
                col += 1;
            }
            for e in f.moments() {
                for (side, sign) in [(1usize, 1.0), (0, -1.0)] {
                    if let BodyId::Body(b) = j.bodies[side] {
                        for r in 0..3 {
                            work.a[col * rows + 6 * b + 3 + r] += sign * e[r];
                        }
                    }
                }
                col += 1;
            }
        }
        if work.nz.len() != k
            || work
                .nz
                .iter()
                .zip(&self.pattern)
                .any(|(a, b)| a.len() != b.len())
        {
            work.nz.clone_from(&self.pattern);
        }
        work.pinv = None;
        if self.fast {
            // S = A Aᵀ + U Uᵀ (upper triangle, row-major), then S = Rᵀ R in place with
            // R = Lᵀ upper triangular.
            let stride = padded(rows);
            work.stride = stride;
            work.lt.clear();
            work.lt.resize(rows * stride, 0.0);
            for c in 0..k {
                let col = &work.a[c * rows..(c + 1) * rows];
                let nz = &work.nz[c];
                for (i, &r1) in nz.iter().enumerate() {
                    let x = col[r1];
                    if x == 0.0 {
                        continue;
                    }
                    let row = &mut work.lt[r1 * stride..r1 * stride + rows];
                    for &r2 in &nz[i..] {
                        row[r2] += x * col[r2];
                    }
                }
            }
            let count = mobility_basis_flat(kin, mech.n, &mut work.u);
            for uc in work.u.chunks_exact(rows).take(count) {
                for (r1, &x) in uc.iter().enumerate() {
                    if x == 0.0 {
                        continue;
                    }
                    let row = &mut work.lt[r1 * stride + r1..r1 * stride + rows];
                    for (v, &y) in row.iter_mut().zip(&uc[r1..]) {
                        *v += x * y;
                    }
                }
            }
            if cholesky_upper_in_place(&mut work.lt, rows, stride) {
                work.l.clear();
                work.l.resize(rows * rows, 0.0);
                for i in 0..rows {
                    for j in i..rows {
                        work.l[j * rows + i] = work.lt[i * stride + j];
                    }
                }
                work.inv_diag.clear();
                work.inv_diag
                    .extend((0..rows).map(|i| 1.0 / work.lt[i * stride + i]));
                return;
            }
        }
        work.pinv = Some(pseudo_inverse(DMatrix::from_column_slice(rows, k, &work.a)));
    }

    /// Subtracts the actuator wrenches of actuator forces `qu` (`n × nc`, row-major) from the
    /// right-hand sides `b` (`6L` rows of `nc` values, `stride` apart) of a prepared sample.
    /// Each value receives the same operations in the same order whatever `nc`.
    pub fn subtract_actuators_batch(
        &self,
        work: &ReactionWork,
        kin: &[BodyKin],
        qu: &[f64],
        nc: usize,
        b: &mut [f64],
        stride: usize,
    ) {
        for (&(act, joint), &kappa) in self.actuated.iter().zip(&work.kappas) {
            let j = &self.joints[joint];
            let f = &work.frames[joint];
            let forces = &qu[act * nc..(act + 1) * nc];
            for (side, sign) in [(1usize, 1.0), (0, -1.0)] {
                let BodyId::Body(bi) = j.bodies[side] else {
                    continue;
                };
                if j.kind == JointKind::Prismatic {
                    let d = f.point - kin[bi].p;
                    for (c, &q) in forces.iter().enumerate() {
                        let force = f.axis * (sign * (q / kappa));
                        let moment = d.cross(&force);
                        for r in 0..3 {
                            b[(6 * bi + r) * stride + c] -= force[r];
                            b[(6 * bi + 3 + r) * stride + c] -= moment[r];
                        }
                    }
                } else {
                    for r in 0..3 {
                        let axis = f.axis[r];
                        let row = &mut b[(6 * bi + 3 + r) * stride..][..nc];
                        for (x, &q) in row.iter_mut().zip(forces) {
                            *x -= sign * (q / kappa) * axis;
                        }
                    }
                }
            }
        }
    }

    /// Solves a prepared sample for `m` right-hand sides `b` (`6L × m`, row-major; destroyed)
    /// and writes per joint the force and moment vectors into `out` (`6J × m`, row-major: row
    /// `6j + r` holds component `r` of joint `j`'s force for `r < 3`, of its moment otherwise).
    pub fn solve_prepared(
        &self,
        work: &mut ReactionWork,
        b: &mut [f64],
        m: usize,
        out: &mut [f64],
    ) {
        let rows = work.rows;
        let k = work.k;
        if let Some(pinv) = &work.pinv {
            work.y.clear();
            work.y.resize(k * m, 0.0);
            for c in 0..k {
                for r in 0..rows {
                    let x = pinv[(c, r)];
                    if x != 0.0 {
                        for p in 0..m {
                            work.y[c * m + p] += x * b[r * m + p];
                        }
                    }
                }
            }
        } else {
            // every value is written by the substitution (no zero fill: at thousands of
            // right-hand sides per sample the fill costs as much memory traffic as the solve)
            if work.y.len() < k * m {
                work.y.resize(k * m, 0.0);
            }
            let factor = Factor {
                rows,
                l: &work.l,
                lt: &work.lt,
                stride: work.stride,
                inv_diag: &work.inv_diag,
            };
            chunk_solve(factor, &work.a, &work.nz, k, b, m, &mut work.y, &mut work.z);
        }
        // Each output row is the sum of its basis vectors' contributions in a fixed order. The
        // first contribution is written as `0.0 + e·λ` — the bits of adding it to a zeroed
        // row — so rows need no zero fill; rows without a contribution are zeroed at the end.
        let out_rows = 6 * self.joints.len();
        work.written.clear();
        work.written.resize(out_rows, false);
        for (jn, (j, f)) in self.joints.iter().zip(&work.frames).enumerate() {
            let bases = f
                .forces()
                .iter()
                .map(|e| (e, 0))
                .chain(f.moments().iter().map(|e| (e, 3)));
            for (col, (e, base)) in (j.offset..).zip(bases) {
                let lam = &work.y[col * m..(col + 1) * m];
                for r in 0..3 {
                    if e[r] != 0.0 {
                        let row = 6 * jn + base + r;
                        let o = &mut out[row * m..(row + 1) * m];
                        let x = e[r];
                        if work.written[row] {
                            for (o, &l) in o.iter_mut().zip(lam) {
                                *o += x * l;
                            }
                        } else {
                            for (o, &l) in o.iter_mut().zip(lam) {
                                *o = 0.0 + x * l;
                            }
                            work.written[row] = true;
                        }
                    }
                }
            }
        }
        for (row, &w) in work.written.iter().enumerate() {
            if !w {
                out[row * m..(row + 1) * m].fill(0.0);
            }
        }
    }

    /// The reaction operator of a prepared sample: the `6J × 6L` matrix `O` (row-major) that
    /// maps a right-hand side to the joint wrench rows of [`Self::solve_prepared`], obtained
    /// by solving for the `6L` unit right-hand sides. With thousands of right-hand sides per
    /// sample (a grid batch), applying `O` by [`Self::apply_operator`] costs about a third of
    /// the substitutions per right-hand side.
    pub fn prepare_operator(&self, work: &mut ReactionWork) {
        let rows = work.rows;
        let mut unit = std::mem::take(&mut work.unit);
        unit.clear();
        unit.resize(rows * rows, 0.0);
        for i in 0..rows {
            unit[i * rows + i] = 1.0;
        }
        let mut op = std::mem::take(&mut work.op);
        op.resize(6 * self.joints.len() * rows, 0.0);
        self.solve_prepared(work, &mut unit, rows, &mut op);
        work.op = op;
        work.unit = unit;
    }

    /// `out = O b` for `m` right-hand sides `b` (`6L` rows of `m` values, `ld` apart) with
    /// the operator of [`Self::prepare_operator`]; `out` (`6J` rows of `m` values, `ld`
    /// apart) as in [`Self::solve_prepared`]. Each value is the same fused multiply-add chain
    /// whatever `m` and the column's position, so a column's bits do not depend on its batch.
    pub fn apply_operator(
        &self,
        work: &ReactionWork,
        b: &[f64],
        ld: usize,
        m: usize,
        out: &mut [f64],
    ) {
        let nr = 6 * self.joints.len();
        apply_operator_kernel(&work.op, nr, work.rows, b, ld, m, out);
    }
}

/// Per-sample reaction factorisation (see [`ReactionSolver::prepare`]).
#[derive(Clone, Debug, Default)]
pub struct ReactionWork {
    rows: usize,
    k: usize,
    frames: Vec<JointFrame>,
    kappas: Vec<f64>,
    /// `A`, column-major.
    a: Vec<f64>,
    /// Non-zero rows of each column of `A`.
    nz: Vec<Vec<usize>>,
    /// Orthonormal mobility basis, column-major.
    u: Vec<f64>,
    /// `Lᵀ` (upper triangular) of `AAᵀ + UUᵀ = L Lᵀ`, row-major with row stride `stride`.
    lt: Vec<f64>,
    stride: usize,
    /// `L`, row-major.
    l: Vec<f64>,
    /// `1 / L_ii`.
    inv_diag: Vec<f64>,
    /// `A⁺` when the fast path is off or failed.
    pinv: Option<DMatrix<f64>>,
    y: Vec<f64>,
    z: SolveScratch,
    /// Output rows of [`ReactionSolver::solve_prepared`] that have received a contribution.
    written: Vec<bool>,
    /// The reaction operator (see [`ReactionSolver::prepare_operator`]), `6J × 6L` row-major.
    op: Vec<f64>,
    /// The unit right-hand sides the operator is solved for.
    unit: Vec<f64>,
}

#[cfg(test)]
mod tests {
    use super::pseudo_inverse;
    use crate::params::{ParameterSet, Variant};
    use crate::runner::{Evaluator, Workspace};
    use counterpoise_model::Case;

    /// The palletizer's closed loops overconstrain its joints: the reactions are the
    /// minimum-norm solution. The fast path gets it from a Cholesky factor of `A Aᵀ + U Uᵀ`; the
    /// fallback (used when that factorisation is not safe) from the SVD pseudo-inverse of `A`.
    /// Forced onto the fallback, the same move gives the same reactions.
    #[test]
    fn the_pseudo_inverse_fallback_gives_the_fast_path_minimum_norm_reactions() {
        let path = format!("{}/../../cases/palletizer.json", env!("CARGO_MANIFEST_DIR"));
        let model = Case::from_path(std::path::Path::new(&path)).unwrap();
        let fast = Evaluator::new(&model).unwrap();
        assert!(fast.reactions.fast && fast.reactions.minimum_norm);
        let mut fallback = Evaluator::new(&model).unwrap();
        fallback.reactions.fast = false;
        let params = ParameterSet::from_variants(&model, &[Variant::default()]).unwrap();
        let tasks = model.tasks.as_ref().unwrap();
        let (from, to): (Vec<f64>, Vec<f64>) =
            tasks.grid.iter().map(|axis| (axis.from, axis.to)).unzip();
        let reactions = |ev: &Evaluator| {
            let mut q = ev.solve_point(&from).unwrap();
            let mut out = Vec::new();
            ev.run_move(
                &from,
                &to,
                tasks.duration,
                11,
                &mut q,
                &params,
                &[0],
                true,
                &mut Workspace::default(),
                |_, view| out.push(view.reactions[0].clone()),
            )
            .unwrap();
            out
        };
        let (a, b) = (reactions(&fast), reactions(&fallback));
        assert_eq!(a.len(), 11);
        let scale = a
            .iter()
            .flat_map(|r| r.force.iter().chain(&r.moment))
            .fold(0.0f64, |m, v| m.max(v.amax()));
        for (ra, rb) in a.iter().zip(&b) {
            for (x, y) in ra
                .force
                .iter()
                .zip(&rb.force)
                .chain(ra.moment.iter().zip(&rb.moment))
            {
                assert!((x - y).amax() <= 1e-9 * scale, "{x} vs {y}");
            }
        }
    }

    /// The rank decision is relative to the largest singular value, so it is the same whatever
    /// the unit of length. `A = σ₁ q₁ p₁ᵀ + σ₂ q₂ p₂ᵀ` with `q₁ = (0.6, 0.8)`,
    /// `q₂ = (−0.8, 0.6)`, `p` the unit vectors, `σ₁ = s` a scale far from 1 either way (10⁴: a
    /// mechanism drawn in tenths of a millimetre; 10⁻⁴) and `σ₂ = ρ s`. By hand
    /// `A⁺ = Σ pᵢ qᵢᵀ / σᵢ` over the kept values: row `i` is `qᵢ / σᵢ`, 0 where `σᵢ` is dropped.
    /// At `s = 10⁴`, `ρ = 10⁻¹²` is relatively below [`super::RANK_TOLERANCE`] (numerically
    /// rank 1): dropped, where a threshold of 10⁻¹⁰ divided by `s` (or not scaled) would keep it
    /// and put about 10⁸ in the second row. At `s = 10⁻⁴`, `ρ = 10⁻⁸` is above it: kept (second
    /// row `q₂ / 10⁻¹²`), where the divided threshold (10⁻⁶, or the unscaled 10⁻¹⁰) would drop it.
    #[test]
    fn the_pseudo_inverse_rank_decision_does_not_depend_on_the_scale() {
        let q = [[0.6, 0.8], [-0.8, 0.6]];
        for (s, rho, kept) in [(1e4, 1e-12, false), (1e-4, 1e-8, true)] {
            let sigma = [s, rho * s];
            // A[r][c] = σ_c q_c[r] (p_c the unit vector c)
            let a = nalgebra::DMatrix::from_fn(2, 2, |r, c| sigma[c] * q[c][r]);
            let pinv = pseudo_inverse(a);
            for i in 0..2 {
                let row = if i == 0 || kept {
                    [q[i][0] / sigma[i], q[i][1] / sigma[i]]
                } else {
                    [0.0, 0.0]
                };
                for c in 0..2 {
                    assert!(
                        (pinv[(i, c)] - row[c]).abs() <= 1e-9 / sigma[i],
                        "s = {s}, ρ = {rho}: A⁺ = {pinv}"
                    );
                }
            }
        }
    }
}
