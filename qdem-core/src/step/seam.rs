//! [`Seam`]: where a stepper's force evaluations and integrations meet the rest of the run,
//! so that a stepper is written once for one process and for many ranks without knowing
//! which. A run of one process passes [`OneProcess`]; a decomposed run passes the parallel
//! runtime ([`crate::parallel::ParallelRuntime`]), which evaluates the models that one rank
//! computes in part stage by stage with the ranks' exchanges in between, steps only a rank's
//! particles when it can ([`Seam::stepped`], [`Seam::computed`]) and shares each
//! integration's outcome ([`Seam::complete`]).

use crate::error::CoreError;
use crate::step::local_particles::ParticleRuns;
use crate::step::model::Model;
use crate::step::rigid_body::reduce_member_forces;
use crate::step::stages::{Stage, StageTimes};
use crate::step::state::State;
use crate::Vec3;

/// How a stepper evaluates the models' forces and ends an integration: in a run of one
/// process ([`OneProcess`]) or on one rank of a decomposed run.
pub trait Seam {
    /// [`Seam::sum_forces`] into `force` and `torque` that the caller has sized and zeroed
    /// (Verlet zeroes them in its drift sweep).
    fn add_forces(
        &mut self,
        state: &State,
        models: &mut [Box<dyn Model>],
        force: &mut [Vec3],
        torque: &mut [Vec3],
        stages: &mut StageTimes,
    );

    /// Sums the forces and torques of all `models` at `state` into `force` and `torque`
    /// (resized and zeroed here; rigid bodies' torques, then particles' moments), then moves
    /// the forces on members of rigid bodies onto their bodies. Each model's force
    /// evaluation is marked as its own stage on `stages` (the caller marks the stage before).
    fn sum_forces(
        &mut self,
        state: &State,
        models: &mut [Box<dyn Model>],
        force: &mut Vec<Vec3>,
        torque: &mut Vec<Vec3>,
        stages: &mut StageTimes,
    ) {
        force.clear();
        force.resize(state.len(), Vec3::zeros());
        torque.clear();
        torque.resize(state.rigid.len() + state.spin.len(), Vec3::zeros());
        self.add_forces(state, models, force, torque, stages);
    }

    /// The particles a stepper predicts (a rank's own and its halo); `None` (the default):
    /// every particle.
    fn stepped(&self) -> Option<&ParticleRuns> {
        None
    }

    /// The particles a stepper integrates (those whose forces this rank sums); `None` (the
    /// default): every particle.
    fn computed(&self) -> Option<&ParticleRuns> {
        None
    }

    /// Ends an integration whose outcome is `outcome`; with `agree` (a stepper that reads
    /// the outcome before the step ends: the sub-steps of an adaptive step) every rank goes
    /// on with the same outcome. A run of one process (the default) goes on with `outcome`.
    fn complete(
        &mut self,
        state: &mut State,
        stages: &mut StageTimes,
        outcome: Result<(), CoreError>,
        agree: bool,
    ) -> Result<(), CoreError> {
        let _ = (state, stages, agree);
        outcome
    }
}

/// The seam of a run of one process: every model's forces, summed in model order.
///
/// ```
/// use qdem_core::step::seam::{OneProcess, Seam};
/// use qdem_core::step::{model::Model, stages::StageTimes, state::State};
/// use qdem_core::{loads::Gravity, Vec3};
///
/// let mut state = State::at_rest(vec![Vec3::zeros()]);
/// state.mass[0] = 2.0;
/// let mut models: Vec<Box<dyn Model>> = vec![Box::new(Gravity::new(Vec3::new(0.0, 0.0, -9.81)))];
/// let (mut force, mut torque) = (Vec::new(), Vec::new());
/// OneProcess.sum_forces(&state, &mut models, &mut force, &mut torque, &mut StageTimes::off());
/// assert_eq!(force[0].z, -19.62);
/// ```
#[derive(Clone, Copy, Debug, Default)]
pub struct OneProcess;

impl Seam for OneProcess {
    /// Every model's forces in model order, each marked as its own stage, then the forces on
    /// members of rigid bodies moved onto their bodies.
    fn add_forces(
        &mut self,
        state: &State,
        models: &mut [Box<dyn Model>],
        force: &mut [Vec3],
        torque: &mut [Vec3],
        stages: &mut StageTimes,
    ) {
        add_model_forces(state, models, force, torque, stages, |_, model, f, t| {
            model.add_forces(state, f, t)
        });
    }
}

/// The loop every seam runs: each model's forces in model order through `evaluate` (given the
/// model's index), each marked as its own stage on `stages`, then the forces on members of
/// rigid bodies moved onto their bodies.
pub fn add_model_forces(
    state: &State,
    models: &mut [Box<dyn Model>],
    force: &mut [Vec3],
    torque: &mut [Vec3],
    stages: &mut StageTimes,
    mut evaluate: impl FnMut(usize, &mut dyn Model, &mut [Vec3], &mut [Vec3]),
) {
    for (i, model) in models.iter_mut().enumerate() {
        evaluate(i, model.as_mut(), force, torque);
        stages.mark(Stage::Forces(i));
    }
    if !state.rigid.is_empty() {
        reduce_member_forces(state, force, torque);
    }
}
