//! A force shared equally by a set of particles, scaled by a time function (the scene's
//! `[[load]]`).

use crate::loads::time_function::TimeFunction;
use crate::parallel::split::Reads;
use crate::solvers::tangent::Tangent;
use crate::state::State;
use crate::step::model::{Linearized, Model, Persistence};
use crate::Vec3;

/// A total force F·φ(t) divided equally among a set of particles.
#[derive(Clone, Debug)]
pub struct NodalLoad {
    name: String,
    particles: Vec<u32>,
    per_particle: Vec3,
    factor: TimeFunction,
}

impl NodalLoad {
    /// The total force `total` (N) shared by `particles` (non-empty), scaled by `factor`.
    pub fn new(name: &str, particles: Vec<u32>, total: Vec3, factor: TimeFunction) -> NodalLoad {
        let per_particle = total / particles.len().max(1) as f64;
        NodalLoad {
            name: name.to_string(),
            particles,
            per_particle,
            factor,
        }
    }
}

impl Model for NodalLoad {
    fn name(&self) -> &str {
        &self.name
    }

    /// The time only.
    fn reads(&mut self) -> Reads<'_> {
        Reads::Own
    }

    fn add_forces(&mut self, state: &State, force: &mut [Vec3], _torque: &mut [Vec3]) {
        let f = self.per_particle * self.factor.value(state.time);
        for &p in &self.particles {
            force[p as usize] += f;
        }
    }

    fn linearized(&self) -> Option<&dyn Linearized> {
        Some(self)
    }

    /// No history: the forces follow from the state alone.
    fn persistence(&self) -> Persistence<'_> {
        Persistence::Stateless
    }
}

impl Linearized for NodalLoad {
    /// Position- and velocity-independent: no tangent.
    fn add_tangent(&self, _state: &State, _tangent: &mut Tangent) {}
}
