//! The [`Model`] trait: anything that contributes forces to the [`State`].
//!
//! A scene is a list of models (continuum bodies, loads, gravity, contacts, bonds); a stepper
//! asks each for its forces and for the largest step it tolerates. Models a scene does not
//! need are never built. That is all a model must say. What only some models have is reached
//! through optional facets:
//!
//! - [`Linearized`] ([`Model::linearized`]): the tangent stiffness and damping that implicit
//!   and static solves need (paper 001 Eq. 26); a model without it cannot be stepped
//!   implicitly;
//! - [`StepEvents`] ([`Model::events`]): events within a step (a bond reaching its strength, a
//!   contact opening) that make an adaptive stepper retake it (paper 001 Eqs. 29–30), and
//!   their commitment;
//! - [`Persistent`] ([`Model::persistence`]): the history a checkpoint must keep for a resumed
//!   run to continue bit for bit;
//! - [`Deformable`] ([`Model::deformable`]): a deformable body of tetrahedra, what the outputs,
//!   the modal analysis, the checks and a decomposed run read of it without its type;
//! - [`Reads`] ([`Model::reads`]): what the model reads of the particles' motion in a run
//!   decomposed over ranks, and for a model that one rank computes in part (deformable
//!   bodies, DEM contacts) its [`crate::step::split::Facets`]: the stages of its
//!   force evaluation and what it exchanges, which the world's [`crate::parallel::ParallelRuntime`]
//!   runs.

use crate::checkpoint::{CheckpointError, Decoder, Encoder};
use crate::error::CoreError;
use crate::step::split::Reads;
use crate::step::state::State;
use crate::step::step_settings::StepSettings;
use crate::step::tangent::Tangent;
use crate::{Mat3, Vec3};

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

    /// The largest step (s) explicit central-difference stepping tolerates for this model, from
    /// a rigorous bound; `None` if the model does not limit the step.
    fn stable_dt(&self, state: &State) -> Option<f64> {
        let _ = state;
        None
    }

    /// The step (s) above which explicit stepping of this model is unstable at `state`
    /// whatever else happens, so that a requested step above it is refused; a model whose
    /// [`Model::stable_dt`] is an estimate rather than a rigorous bound (the contacts present)
    /// gives a lower bound of the highest frequency here, and a step between the two is
    /// warned of only. The default is [`Model::stable_dt`].
    fn unstable_above(&self, state: &State) -> Option<f64> {
        self.stable_dt(state)
    }

    /// How the model takes part in a run decomposed over ranks ([`crate::parallel`]): what
    /// it reads of the particles' motion, and its split facet if a rank computes it in part.
    /// With [`Reads::Own`] or [`Reads::Split`] from every model and hook, a rank keeps only
    /// its own particles and its halo current between whole gathers. The default,
    /// [`Reads::All`], is always right.
    fn reads(&mut self) -> Reads<'_> {
        Reads::All
    }

    /// `Some(g)` when the model's force on every particle is its mass times the uniform
    /// acceleration `g` (m/s²) and it exerts no moment (gravity): a stepper may then add m g
    /// in its own pass over the particles instead of calling [`Model::add_forces`] (Verlet
    /// does, when the model comes last and no rigid body's members add into their centre).
    /// The default, `None`, is always right.
    fn uniform_acceleration(&self) -> Option<Vec3> {
        None
    }

    /// Potential energy (J) if the model is conservative, `None` otherwise.
    fn potential_energy(&self, state: &State) -> Option<f64> {
        let _ = state;
        None
    }

    /// Learns how the run is stepped (implicit or explicit, the step), once, when the
    /// [`crate::world::World`] is made; a model whose forces depend on it (a bonded body whose
    /// contacts push only when active in an implicit run) keeps what it needs. The default
    /// ignores it.
    fn prepare(&mut self, settings: &StepSettings) {
        let _ = settings;
    }

    /// After a step: a physical impossibility the model met at its last force evaluation at
    /// `state` (a tetrahedron turned inside out), which stops the run; `None` when all is
    /// well.
    fn failure(&self, state: &State) -> Option<CoreError> {
        let _ = state;
        None
    }

    /// The model's linearisation for implicit and static solves; `None` (the default): the
    /// model cannot be stepped implicitly.
    fn linearized(&self) -> Option<&dyn Linearized> {
        None
    }

    /// The stiffness a modal analysis about the current state takes from the model
    /// ([`crate::modal::lanczos`]); the default is its linearisation. A model may give one here that
    /// it cannot be stepped implicitly with: DEM contacts give their touching contacts as
    /// springs, but an implicit step would also need the events of contacts opening and
    /// closing.
    fn modal_stiffness(&self) -> Option<&dyn Linearized> {
        self.linearized()
    }

    /// The model as a deformable body of tetrahedra; `None` (the default) for every other
    /// model (loads, contacts, bonds).
    fn deformable(&self) -> Option<&dyn Deformable> {
        None
    }

    /// The model's step events; `None` (the default): it has none.
    fn events(&mut self) -> Option<&mut dyn StepEvents> {
        None
    }

    /// What a checkpoint keeps of the model. The default, [`Persistence::Unsupported`], makes
    /// a scene with the model refuse checkpoints.
    fn persistence(&self) -> Persistence<'_> {
        Persistence::Unsupported
    }

    /// The history to restore into, for a model whose [`Model::persistence`] is
    /// [`Persistence::Saved`]; `None` for the others.
    fn persistent_mut(&mut self) -> Option<&mut dyn Persistent> {
        None
    }
}

/// The first of `models` of type `M`, if any (models are `Any`: a body's element fields, a
/// contact set's counts).
pub fn find_model<M: Model>(models: &[Box<dyn Model>]) -> Option<&M> {
    models.iter().find_map(|m| {
        let m: &dyn std::any::Any = m.as_ref();
        m.downcast_ref::<M>()
    })
}

/// The implicit facet of a model: its tangent and the particles it joins.
pub trait Linearized {
    /// Adds the tangent stiffness K = −∂f/∂x and damping C = −∂f/∂v, linearised at `state`,
    /// into `tangent` (3×3 blocks per particle pair, DOF 3·particle + axis); a model whose
    /// force depends on neither positions nor velocities adds nothing.
    fn add_tangent(&self, state: &State, tangent: &mut Tangent);

    /// The particles this model's elements join, in ascending order (the nodes of a deformable
    /// body), used to name a body that is not constrained against rigid motion when an
    /// implicit or static system is singular. The default, for models that own no particles
    /// (loads, gravity, springs to ground), is empty.
    fn particles(&self) -> Vec<usize> {
        Vec::new()
    }
}

/// The facet of a deformable body of tetrahedra (a [`Model`] whose
/// [`Model::deformable`] is itself): its mesh and its element fields, what the outputs, the
/// modal analysis and the checks read of it.
pub trait Deformable: Model {
    /// The body's tetrahedra (indices into the state's particles).
    fn tets(&self) -> &[[u32; 4]];

    /// The stress (Pa) of every tetrahedron at `state`, the tensor its forces follow from,
    /// and its volumetric strain det F − 1.
    fn tet_fields(&self, state: &State) -> (Vec<Mat3>, Vec<f64>);

    /// The small-strain stress of every tetrahedron at `state`'s displacements (the stress
    /// that belongs to a static solve's answer).
    fn small_strain_stresses(&self, state: &State) -> Vec<Mat3>;

    /// Whether the tetrahedra average their pressure over the nodes (the locking-free
    /// formulation for nearly incompressible materials), which needs the nodal averages of
    /// the whole body at every force evaluation.
    fn averages_pressure(&self) -> bool;
}

/// The events facet of a model: what happens within a step that the stepper must resolve.
pub trait StepEvents {
    /// After a trial step to `state`: the fraction α ∈ (0, 1) of the step's displacement
    /// increment at which one of the model's events (a bond reaching its strength, an unbonded
    /// contact opening) would have happened, if the step overshot it by more than the model
    /// tolerates; the stepper then retakes the step with ∆t·√α (paper 001 Eqs. 29–30). `None`
    /// when the step is acceptable. `forces_here` says whether the last
    /// [`Model::add_forces`] was evaluated at exactly this state (explicit steps), so a model
    /// may reuse what it computed there. May be called several times before
    /// [`StepEvents::commit_step`]; must not change the model's physics.
    fn check_step(&mut self, state: &State, forces_here: bool) -> Option<f64>;

    /// Whether the last [`StepEvents::check_step`] of an implicit trial step made the model's
    /// tangent stale (a contact met within the step was activated): the stepper then redoes
    /// the step with the new tangent, so that the contact is implicit from its first step.
    fn tangent_stale(&self) -> bool {
        false
    }

    /// Accepts the step that ended at `state` (after [`StepEvents::check_step`]): applies its
    /// events (breaks bonds, opens and closes contacts) and returns whether the tangent
    /// changed, so that an implicit stepper refactorises.
    fn commit_step(&mut self, state: &State) -> bool;
}

/// What a checkpoint keeps of a model.
pub enum Persistence<'a> {
    /// The model cannot be checkpointed: a scene with it refuses checkpoints.
    Unsupported,
    /// The model's forces follow from the [`State`] alone: nothing to keep.
    Stateless,
    /// The model keeps a history (tangential springs, broken bonds, running estimates),
    /// written and read through this facet.
    Saved(&'a dyn Persistent),
}

/// The persistence facet of a model with a history.
pub trait Persistent {
    /// Writes everything the model's future forces depend on beyond the [`State`], so that a
    /// run resumed from a checkpoint continues bit for bit.
    fn save(&self, out: &mut Encoder);

    /// Reads back what [`Persistent::save`] wrote, into a model built from the same scene.
    fn restore(&mut self, input: &mut Decoder<'_>) -> Result<(), CheckpointError>;
}
