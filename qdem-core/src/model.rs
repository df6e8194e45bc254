//! The [`Model`] trait: anything that contributes forces to the [`State`].
//!
//! A scene is a list of models (continuum bodies, loads, gravity, later contacts and bonds);
//! a stepper asks each for its forces and for the largest step it tolerates. Models a scene
//! does not need are never built.

use crate::state::State;
use crate::Vec3;

/// A source of particle forces. Models are `Any` so that the output can reach a body's
/// element fields by downcasting.
pub trait Model: std::any::Any + Send + Sync {
    /// A short name for messages (the body or load it stands for).
    fn name(&self) -> &str;

    /// Adds this model's force on every particle it acts on into `force` (one entry per particle
    /// of `state`), at `state.time`, `state.position` and `state.velocity`.
    fn add_forces(&mut self, state: &State, force: &mut [Vec3]);

    /// The largest step (s) explicit central-difference stepping tolerates for this model, from
    /// a rigorous bound; `None` if the model does not limit the step.
    fn stable_dt(&self, state: &State) -> Option<f64> {
        let _ = state;
        None
    }

    /// Potential energy (J) if the model is conservative, `None` otherwise.
    fn potential_energy(&self, state: &State) -> Option<f64> {
        let _ = state;
        None
    }
}
