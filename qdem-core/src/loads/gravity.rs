//! Uniform gravity: the force m g on every particle.

use crate::step::model::{Linearized, Model, Persistence};
use crate::step::split::Reads;
use crate::step::state::State;
use crate::step::tangent::Tangent;
use crate::Vec3;

/// Uniform gravitational acceleration acting on every particle.
#[derive(Clone, Debug)]
pub struct Gravity {
    g: Vec3,
}

impl Gravity {
    /// Gravity with acceleration `g` (m/s²).
    pub fn new(g: Vec3) -> Gravity {
        Gravity { g }
    }
}

impl Model for Gravity {
    fn name(&self) -> &str {
        "gravity"
    }

    /// The masses only.
    fn reads(&mut self) -> Reads<'_> {
        Reads::Own
    }

    fn add_forces(&mut self, state: &State, force: &mut [Vec3], _torque: &mut [Vec3]) {
        for (f, m) in force.iter_mut().zip(&state.mass) {
            *f += *m * self.g;
        }
    }

    fn uniform_acceleration(&self) -> Option<Vec3> {
        Some(self.g)
    }

    fn potential_energy(&self, state: &State) -> Option<f64> {
        Some(
            -state
                .mass
                .iter()
                .zip(&state.position)
                .map(|(m, x)| m * self.g.dot(x))
                .sum::<f64>(),
        )
    }

    fn linearized(&self) -> Option<&dyn Linearized> {
        Some(self)
    }

    /// No history: the forces follow from the state alone.
    fn persistence(&self) -> Persistence<'_> {
        Persistence::Stateless
    }
}

impl Linearized for Gravity {
    /// Position- and velocity-independent: no tangent.
    fn add_tangent(&self, _state: &State, _tangent: &mut Tangent) {}
}
