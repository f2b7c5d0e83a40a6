//! Everything shared by the variants of one case: the balance search's lifted basis and
//! verification set, the element bounds, the task grid, the unbalanced indicators and the cache
//! of task torques.

use counterpoise_balance::linear::LiftedBasis;
use counterpoise_balance::{
    Catalogue, Element, MechanismEnergy, VerificationSet, catalogue_options, mechanism_energy,
};
use counterpoise_dynamics::{EvaluateOptions, Indicators, TaskSet, evaluate_unbalanced_grid};
use counterpoise_model::Model;

use crate::error::OptimiseError;
use crate::overrides::BoundsTable;
use crate::torque::TorqueCache;

/// Shared inputs of the optimisation of every variant of a case.
pub struct Context {
    pub model: Model,
    pub energy: MechanismEnergy,
    pub catalogue: Catalogue,
    pub basis: LiftedBasis,
    pub checks: VerificationSet,
    pub bounds: BoundsTable,
    pub tasks: TaskSet,
    /// Indicators of the unbalanced mechanism over all tasks (with joint reactions, for ΔR).
    pub unbalanced: Indicators,
    pub torques: TorqueCache,
}

impl Context {
    /// Builds the context. `unbalanced` are the Phase-1 indicators when the caller already has
    /// them (they must come from the same task grid, with reactions for ΔR); otherwise they are
    /// computed here (all tasks, with reactions).
    // Options are built from the default and then set, so that fields the dynamics crate adds
    // keep their defaults.
    #[allow(clippy::field_reassign_with_default)]
    pub fn new(model: &Model, unbalanced: Option<Indicators>) -> Result<Context, OptimiseError> {
        if model.balancing.is_none() {
            return Err(OptimiseError::NoBalancing);
        }
        let energy = mechanism_energy(model);
        let catalogue = Catalogue::build(&energy, &catalogue_options(model));
        let basis = LiftedBasis::build(&energy, &catalogue);
        let checks = VerificationSet::new(&energy);
        let bounds = BoundsTable::new(model, &catalogue)?;
        let spec = model
            .tasks
            .as_ref()
            .ok_or_else(|| OptimiseError::Other("the case has no tasks to optimise over".into()))?;
        let tasks = TaskSet::new(spec, None)?;
        let unbalanced = match unbalanced {
            Some(u) => u,
            None => {
                let mut options = EvaluateOptions::default();
                options.samples = None;
                options.reactions = true;
                let mut grid = evaluate_unbalanced_grid(model, &options)?;
                grid.indicators.swap_remove(0)
            }
        };
        let cw_bodies: Vec<usize> = catalogue
            .entries
            .iter()
            .filter_map(|e| match e.element {
                Element::Counterweight { body, .. } => Some(body),
                Element::Spring { .. } => None,
            })
            .collect();
        Ok(Context {
            torques: TorqueCache::new(model, cw_bodies),
            model: model.clone(),
            energy,
            catalogue,
            basis,
            checks,
            bounds,
            tasks,
            unbalanced,
        })
    }

    /// Task index of grid pair `[i, j]`.
    pub fn task_index(&self, pair: [usize; 2]) -> Option<usize> {
        self.tasks
            .index_of(pair[0], pair[1])
            .or_else(|| self.tasks.index_of(pair[1], pair[0]))
    }

    pub fn pair(&self, task: usize) -> [usize; 2] {
        let (i, j) = self.tasks.pair(task);
        [i, j]
    }
}
