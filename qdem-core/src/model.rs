//! The [`Model`] trait: anything that contributes forces to the [`State`].
//!
//! A scene is a list of models (continuum bodies, loads, gravity, later contacts and bonds);
//! a stepper asks each for its forces and for the largest step it tolerates. Models a scene
//! does not need are never built. For implicit and static solves a model also adds its tangent
//! stiffness and damping into a [`Tangent`] (the optional implicit hook).

use crate::checkpoint::{CheckpointError, Decoder, Encoder};
use crate::sparse::Tangent;
use crate::state::State;
use crate::step_settings::Stepping;
use crate::Vec3;

/// A source of particle forces. Models are `Any` so that the output can reach a body's
/// element fields by downcasting.
pub trait Model: std::any::Any + Send + Sync {
    /// A short name for messages (the body or load it stands for).
    fn name(&self) -> &str;

    /// Adds this model's force on every particle it acts on into `force` (one entry per particle
    /// of `state`), at `state.time`, `state.position` and `state.velocity`, and the torque it
    /// exerts on rigid bodies beyond that of its particle forces into `torque` (one entry per
    /// rigid body of `state.rigid`, empty when there is none). A force on a particle of a rigid
    /// body acts on the body through that particle; only a force applied away from every
    /// particle (a contact on a rigid sphere's surface) needs `torque`. When the particles have
    /// rotational DOFs (`state.spin`), `torque` goes on with one moment per particle: entry
    /// `state.rigid.len() + i` is the moment on particle `i`.
    fn add_forces(&mut self, state: &State, force: &mut [Vec3], torque: &mut [Vec3]);

    /// Learns how the run is stepped (implicit or explicit, the step), once, when the
    /// [`crate::World`] is made; a model whose forces depend on it (a bonded body whose
    /// contacts push only when active in an implicit run) keeps what it needs. The default
    /// ignores it.
    fn prepare(&mut self, stepping: &Stepping) {
        let _ = stepping;
    }

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

    /// Adds this model's tangent stiffness K = −∂f/∂x and damping C = −∂f/∂v, linearised at
    /// `state`, into `tangent` (3×3 blocks per particle pair, DOF 3·particle + axis), and
    /// returns `true`; a model whose force does not depend on positions or velocities adds
    /// nothing and returns `true`. The default returns `false`: the model cannot be stepped
    /// implicitly (paper 001 Eq. 26 needs K and C).
    fn add_tangent(&self, state: &State, tangent: &mut Tangent) -> bool {
        let _ = (state, tangent);
        false
    }

    /// After a trial step to `state`: the fraction α ∈ (0, 1) of the step's displacement
    /// increment at which one of the model's events (a bond reaching its strength, an unbonded
    /// contact opening) would have happened, if the step overshot it by more than the model
    /// tolerates; the stepper then retakes the step with ∆t·√α (paper 001 Eqs. 29–30). `None`
    /// when the step is acceptable. `forces_here` says whether the last
    /// [`Model::add_forces`] was evaluated at exactly this state (explicit steps), so a model
    /// may reuse what it computed there. May be called several times before
    /// [`Model::commit_step`]; must not change the model's physics.
    fn check_step(&mut self, state: &State, forces_here: bool) -> Option<f64> {
        let _ = (state, forces_here);
        None
    }

    /// Whether the last [`Model::check_step`] of an implicit trial step made the model's
    /// tangent stale (a contact met within the step was activated): the stepper then redoes
    /// the step with the new tangent, so that the contact is implicit from its first step.
    fn tangent_stale(&self) -> bool {
        false
    }

    /// Accepts the step that ended at `state` (after [`Model::check_step`]): applies its
    /// events (breaks bonds, opens and closes contacts) and returns whether the tangent
    /// ([`Model::add_tangent`]) changed, so that an implicit stepper refactorises.
    fn commit_step(&mut self, state: &State) -> bool {
        let _ = state;
        false
    }

    /// The particles this model's elements join, in ascending order (the nodes of a deformable
    /// body), used to name a body that is not constrained against rigid motion when an
    /// implicit or static system is singular. The default, for models that own no particles
    /// (loads, gravity, springs to ground), is empty.
    fn particles(&self) -> Vec<usize> {
        Vec::new()
    }

    /// After a step: a physical impossibility the model met at its last force evaluation at
    /// `state` (a tetrahedron turned inside out), which stops the run; `None` when all is
    /// well.
    fn failure(&self, state: &State) -> Option<crate::CoreError> {
        let _ = state;
        None
    }

    /// Whether [`Model::save`] writes everything the model's future forces depend on beyond
    /// the [`State`] (its history: tangential springs, broken bonds, running estimates), so
    /// that a run resumed from a checkpoint continues bit for bit. The default, `false`, makes
    /// a scene with the model refuse checkpoints; a model without history says `true` and
    /// keeps the empty [`Model::save`].
    fn checkpointable(&self) -> bool {
        false
    }

    /// Writes the model's history into a checkpoint.
    fn save(&self, out: &mut Encoder) {
        let _ = out;
    }

    /// Reads back what [`Model::save`] wrote, into a model built from the same scene.
    fn restore(&mut self, input: &mut Decoder<'_>) -> Result<(), CheckpointError> {
        let _ = input;
        Ok(())
    }
}
