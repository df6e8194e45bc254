//! The [`ParallelRuntime`] as a stepper's [`Seam`]: a decomposed run's force evaluations,
//! the particles a rank steps and the share of each integration, through the exchange's own
//! methods.

use crate::error::CoreError;
use crate::parallel::ParallelRuntime;
use crate::step::local_particles::ParticleRuns;
use crate::step::model::Model;
use crate::step::seam::Seam;
use crate::step::stages::StageTimes;
use crate::step::state::State;
use crate::Vec3;

impl Seam for ParallelRuntime {
    fn add_forces(
        &mut self,
        state: &State,
        models: &mut [Box<dyn Model>],
        force: &mut [Vec3],
        torque: &mut [Vec3],
        stages: &mut StageTimes,
    ) {
        ParallelRuntime::add_forces(self, state, models, force, torque, stages);
    }

    fn sum_forces(
        &mut self,
        state: &State,
        models: &mut [Box<dyn Model>],
        force: &mut Vec<Vec3>,
        torque: &mut Vec<Vec3>,
        stages: &mut StageTimes,
    ) {
        ParallelRuntime::sum_forces(self, state, models, force, torque, stages);
    }

    fn stepped(&self) -> Option<&ParticleRuns> {
        ParallelRuntime::stepped(self)
    }

    fn computed(&self) -> Option<&ParticleRuns> {
        ParallelRuntime::computed(self)
    }

    fn complete(
        &mut self,
        state: &mut State,
        stages: &mut StageTimes,
        outcome: Result<(), CoreError>,
        agree: bool,
    ) -> Result<(), CoreError> {
        ParallelRuntime::complete(self, state, stages, outcome, agree)
    }
}
