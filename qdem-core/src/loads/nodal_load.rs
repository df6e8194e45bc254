//! Forces on a set of particles scaled by a time function (the scene's `[[load]]`): a total
//! force shared equally by the particles, or each particle's own force (a pressure or
//! traction lumped to the nodes, [`crate::loads::surface_load`]).

use crate::loads::time_function::TimeFunction;
use crate::step::model::{Linearized, Model, Persistence};
use crate::step::split::Reads;
use crate::step::state::State;
use crate::step::tangent::Tangent;
use crate::Vec3;

/// Forces F_i·φ(t) on a set of particles: a total force divided equally among them
/// ([`NodalLoad::new`]) or one force per particle ([`NodalLoad::per_particle`]).
#[derive(Clone, Debug)]
pub struct NodalLoad {
    name: String,
    particles: Vec<u32>,
    /// The force on each particle at factor 1 (N), in the order of `particles`.
    forces: Vec<Vec3>,
    factor: TimeFunction,
}

impl NodalLoad {
    /// The total force `total` (N) shared by `particles` (non-empty), scaled by `factor`.
    pub fn new(name: &str, particles: Vec<u32>, total: Vec3, factor: TimeFunction) -> NodalLoad {
        let share = total / particles.len().max(1) as f64;
        let forces = vec![share; particles.len()];
        NodalLoad {
            name: name.to_string(),
            particles,
            forces,
            factor,
        }
    }

    /// Each particle's own force (N, at factor 1), scaled by `factor`: e.g. a pressure lumped
    /// to the nodes by [`crate::loads::surface_load::lump_traction`].
    ///
    /// ```
    /// use qdem_core::{loads::NodalLoad, loads::TimeFunction, Vec3};
    /// let forces = vec![(0, Vec3::new(0.0, 0.0, -1.0)), (3, Vec3::new(0.0, 0.0, -2.0))];
    /// let load = NodalLoad::per_particle("top", forces, TimeFunction::constant(1.0));
    /// assert_eq!(load.total(), Vec3::new(0.0, 0.0, -3.0));
    /// ```
    pub fn per_particle(name: &str, forces: Vec<(u32, Vec3)>, factor: TimeFunction) -> NodalLoad {
        let (particles, forces) = forces.into_iter().unzip();
        NodalLoad {
            name: name.to_string(),
            particles,
            forces,
            factor,
        }
    }

    /// The sum of the forces at factor 1 (N).
    pub fn total(&self) -> Vec3 {
        self.forces.iter().sum()
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
        let factor = self.factor.value(state.time);
        for (&p, f) in self.particles.iter().zip(&self.forces) {
            force[p as usize] += f * factor;
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
