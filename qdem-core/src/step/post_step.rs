//! [`PostStep`]: what a world does after every step (periodic wrapping, a watch that ends the
//! run), and the [`Halt`] a hook ends a run with. Declared here, beside the models, so that
//! the parallel runtime can run the hooks of a decomposed run as it runs the models.

use crate::step::model::Model;
use crate::step::split::Reads;
use crate::step::state::State;

/// Something a world does after every step, once the step has passed the failure check:
/// periodic wrapping of bodies, a watch that ends the run when a body has failed.
pub trait PostStep: std::any::Any + Send + Sync {
    /// A short name for the stage counters.
    fn name(&self) -> &str;

    /// Acts on the state after a step; returns a [`Halt`] to end the run after this step.
    fn after_step(&mut self, state: &mut State, models: &[Box<dyn Model>]) -> Option<Halt>;

    /// How the hook takes part in a decomposed run ([`Model::reads`]); the default,
    /// [`Reads::All`], is always right. A split hook decides for its own particles and acts
    /// on every rank's decisions ([`crate::step::split::Decisions`]).
    fn reads(&mut self) -> Reads<'_> {
        Reads::All
    }
}

/// Why a post-step hook ended a run early (not a failure: the outputs are complete).
#[derive(Clone, Debug, PartialEq)]
pub struct Halt {
    /// The hook's name.
    pub hook: String,
    /// Simulated time (s).
    pub time: f64,
    /// The particle that triggered it.
    pub particle: usize,
    /// The quantity that passed its limit (a displacement in m for the collapse watch).
    pub value: f64,
}
