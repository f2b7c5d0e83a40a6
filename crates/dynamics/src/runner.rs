//! Running moves: kinematics along a move, then torques (and reactions) for many parameter
//! columns at every sample.
//!
//! The kinematic work of a sample — Newton for `q`, the pose polynomials, the body motions and
//! the regressor `Y` — is done once and shared by every parameter column: a column costs one
//! `Y·π` product (and one reaction right-hand side).

use counterpoise_model::Model;
use counterpoise_symbolic::MAX_VARS;

use crate::error::{DynamicsError, FailureReason};
use crate::indicators::{StatsAccumulator, TaskStats};
use crate::law::{quintic_move, sample_time};
use crate::lu::SmallLu;
use crate::mechanism::{Mechanism, Scratch};
use crate::params::ParameterSet;
use crate::reactions::{JointReactions, ReactionSolver};
use crate::regressor::SampleRegressor;

/// One sample of a move as seen by a consumer.
#[derive(Clone, Debug, Default)]
pub struct SampleView {
    pub t: f64,
    pub u: Vec<f64>,
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
    /// Per column: generalized force per chart coordinate, `Q_q`.
    pub chart_force: Vec<[f64; MAX_VARS]>,
    /// Per column: generalized force per actuated coordinate (before the ratio).
    pub actuator_force: Vec<[f64; MAX_VARS]>,
    /// Per column: motor torque per actuator.
    pub motor_torque: Vec<[f64; MAX_VARS]>,
    /// Per column (empty without reactions).
    pub reactions: Vec<JointReactions>,
}

/// Per-worker buffers.
#[derive(Clone, Debug, Default)]
pub struct Workspace {
    scratch: Scratch,
    reg: SampleRegressor,
    view: SampleView,
    reactions: crate::reactions::ReactionWork,
}

/// A compiled model ready to run moves.
#[derive(Clone, Debug)]
pub struct Evaluator<'m> {
    pub model: &'m Model,
    pub mech: Mechanism,
    pub reactions: ReactionSolver,
    pub ratios: Vec<f64>,
}

impl<'m> Evaluator<'m> {
    pub fn new(model: &'m Model) -> Result<Evaluator<'m>, DynamicsError> {
        let mech = Mechanism::new(model)?;
        let reactions = ReactionSolver::new(model, &mech);
        Ok(Evaluator {
            model,
            ratios: model.actuators.iter().map(|a| a.ratio).collect(),
            mech,
            reactions,
        })
    }

    pub fn actuator_names(&self) -> Vec<String> {
        self.model
            .actuators
            .iter()
            .map(|a| a.name.clone())
            .collect()
    }

    pub fn joint_names(&self) -> Vec<String> {
        self.model.joints.iter().map(|j| j.name.clone()).collect()
    }

    /// `q` with `f(q) = u`: from the reference configuration (range midpoints), first directly,
    /// then by continuation along the straight line from `f(q_ref)` to `u`; if that fails
    /// (e.g. `G` is singular at the reference), directly from 32 deterministic pseudo-random
    /// configurations in the coordinate ranges. The first success wins.
    pub fn solve_point(&self, u: &[f64]) -> Result<Vec<f64>, FailureReason> {
        let n = self.mech.n;
        let q_ref = self.model.reference_configuration();
        let mut scratch = Scratch::default();
        let mut u_ref = [0.0; MAX_VARS];
        let mut g = [0.0; MAX_VARS * MAX_VARS];
        self.mech
            .actuator_map(&q_ref, &mut scratch, &mut u_ref, &mut g);
        let mut first_error = None;
        for steps in [1usize, 8, 64] {
            let mut q = q_ref.clone();
            let mut ok = true;
            for s in 1..=steps {
                let w = s as f64 / steps as f64;
                let target: Vec<f64> = (0..n).map(|a| u_ref[a] + w * (u[a] - u_ref[a])).collect();
                if let Err(e) = self.mech.solve(&target, &mut q, &mut scratch) {
                    first_error.get_or_insert(e);
                    ok = false;
                    break;
                }
            }
            if ok {
                return Ok(q);
            }
        }
        let mut rng = counterpoise_model::sampling::SplitMix64::new(0x7374_6172_7473);
        for _ in 0..32 {
            let mut q: Vec<f64> = self
                .mech
                .ranges
                .iter()
                .map(|r| rng.uniform(r[0], r[1]))
                .collect();
            if self.mech.solve(u, &mut q, &mut scratch).is_ok() {
                return Ok(q);
            }
        }
        Err(first_error.unwrap_or(FailureReason::NotConverged { residual: f64::NAN }))
    }

    /// Runs a quintic rest-to-rest move from `ua` to `ub`, calling `sink` at every sample.
    /// `q` holds the starting guess and is updated along the move. Fails at the first sample
    /// whose kinematics fail.
    #[allow(clippy::too_many_arguments)]
    pub fn run_move(
        &self,
        ua: &[f64],
        ub: &[f64],
        duration: f64,
        samples: usize,
        q: &mut [f64],
        params: &ParameterSet,
        columns: &[usize],
        with_reactions: bool,
        ws: &mut Workspace,
        mut sink: impl FnMut(usize, &SampleView),
    ) -> Result<(), (usize, FailureReason)> {
        let n = self.mech.n;
        let mut u = [0.0; MAX_VARS];
        let mut ud = [0.0; MAX_VARS];
        let mut udd = [0.0; MAX_VARS];
        let mut qd = [0.0; MAX_VARS];
        let mut qdd = [0.0; MAX_VARS];
        for k in 0..samples {
            let t = sample_time(k, samples, duration);
            for a in 0..n {
                (u[a], ud[a], udd[a]) = quintic_move(ua[a], ub[a], duration, t);
            }
            let lu = self
                .mech
                .sample_state(&u, &ud, &udd, q, &mut qd, &mut qdd, &mut ws.scratch)
                .map_err(|e| (k, e))?;
            self.sample(
                t,
                &u[..n],
                q,
                &qd[..n],
                &qdd[..n],
                &lu,
                params,
                columns,
                with_reactions,
                ws,
            )
            .map_err(|e| (k, e))?;
            sink(k, &ws.view);
        }
        Ok(())
    }

    /// Dynamics of one kinematic state for the given columns into `ws.view`.
    #[allow(clippy::too_many_arguments)]
    pub fn sample(
        &self,
        t: f64,
        u: &[f64],
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        lu: &SmallLu,
        params: &ParameterSet,
        columns: &[usize],
        with_reactions: bool,
        ws: &mut Workspace,
    ) -> Result<(), FailureReason> {
        let n = self.mech.n;
        self.mech.eval_poses(q, &mut ws.scratch);
        ws.reg
            .compute(&self.mech, &ws.scratch.pose, qd, qdd, &params.springs);
        let view = &mut ws.view;
        view.t = t;
        view.u.clear();
        view.u.extend_from_slice(u);
        view.q.clear();
        view.q.extend_from_slice(&q[..n]);
        view.qd.clear();
        view.qd.extend_from_slice(qd);
        view.qdd.clear();
        view.qdd.extend_from_slice(qdd);
        view.actuator_force.clear();
        view.motor_torque.clear();
        view.chart_force.clear();
        for &p in columns {
            let mut f = [0.0; MAX_VARS];
            ws.reg.generalized_force(n, params.column(p), &mut f);
            view.chart_force.push(f);
            lu.solve_transpose(&mut f);
            let mut m = [0.0; MAX_VARS];
            for a in 0..n {
                if !f[a].is_finite() {
                    return Err(FailureReason::NonFinite);
                }
                m[a] = f[a] * self.ratios[a];
            }
            view.actuator_force.push(f);
            view.motor_torque.push(m);
        }
        view.reactions.clear();
        if with_reactions {
            view.reactions = self.reactions.solve(
                &self.mech,
                &ws.scratch.pose,
                &ws.reg,
                lu,
                params,
                columns,
                &view.actuator_force,
                &mut ws.reactions,
            );
            if view.reactions.iter().any(|r| {
                r.force
                    .iter()
                    .chain(&r.moment)
                    .any(|x| !x.iter().all(|v| v.is_finite()))
            }) {
                return Err(FailureReason::NonFinite);
            }
        }
        Ok(())
    }

    /// Dynamics at an arbitrary state `(q, q̇, q̈)` (no Newton: `q` is taken as given).
    #[allow(clippy::too_many_arguments)]
    pub fn at_state(
        &self,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        params: &ParameterSet,
        columns: &[usize],
        with_reactions: bool,
    ) -> Result<SampleView, FailureReason> {
        let n = self.mech.n;
        let mut ws = Workspace::default();
        let mut u = [0.0; MAX_VARS];
        let mut g = [0.0; MAX_VARS * MAX_VARS];
        self.mech.actuator_map(q, &mut ws.scratch, &mut u, &mut g);
        let lu = SmallLu::new(&g, n);
        self.mech.singularity(&lu)?;
        self.sample(
            0.0,
            &u[..n],
            q,
            qd,
            qdd,
            &lu,
            params,
            columns,
            with_reactions,
            &mut ws,
        )?;
        Ok(ws.view)
    }

    /// Statistics of one move for every column.
    #[allow(clippy::too_many_arguments)]
    pub fn move_stats(
        &self,
        ua: &[f64],
        ub: &[f64],
        duration: f64,
        samples: usize,
        q: &mut [f64],
        params: &ParameterSet,
        with_reactions: bool,
        ws: &mut Workspace,
    ) -> Result<Vec<TaskStats>, (usize, FailureReason)> {
        let columns: Vec<usize> = (0..params.len()).collect();
        let na = self.mech.n;
        let nj = if with_reactions {
            self.reactions.joint_count()
        } else {
            0
        };
        let mut acc = vec![StatsAccumulator::new(na, nj); columns.len()];
        self.run_move(
            ua,
            ub,
            duration,
            samples,
            q,
            params,
            &columns,
            with_reactions,
            ws,
            |_, view| {
                for (c, a) in acc.iter_mut().enumerate() {
                    a.add_torques(&view.motor_torque[c][..na]);
                    if with_reactions {
                        let r = &view.reactions[c];
                        a.add_reactions(r.force_magnitudes(), r.moment_magnitudes());
                    }
                }
            },
        )?;
        Ok(acc.iter().map(|a| a.finish(with_reactions)).collect())
    }
}
