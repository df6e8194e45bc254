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
//! - [`SplitModel`] ([`Model::split_model`]): a model that one rank of a decomposed run
//!   computes in part (DEM contacts: the contacts that touch the rank's particles).

use crate::checkpoint::{CheckpointError, Decoder, Encoder};
use crate::distributed::Communicator;
use crate::state::State;
use crate::step_settings::Stepping;
use crate::tangent::Tangent;
use crate::Vec3;
use std::sync::Arc;

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

    /// Which particles' motion the model reads when it adds its forces, for a run decomposed
    /// over processes ([`crate::distributed`]): with [`ParticleReads::Local`] from every model
    /// and hook, a rank keeps only its own particles and its halo current between whole
    /// gathers. The default, [`ParticleReads::All`], is always right.
    fn particle_reads(&self) -> ParticleReads {
        ParticleReads::All
    }

    /// Potential energy (J) if the model is conservative, `None` otherwise.
    fn potential_energy(&self, state: &State) -> Option<f64> {
        let _ = state;
        None
    }

    /// Learns how the run is stepped (implicit or explicit, the step), once, when the
    /// [`crate::World`] is made; a model whose forces depend on it (a bonded body whose
    /// contacts push only when active in an implicit run) keeps what it needs. The default
    /// ignores it.
    fn prepare(&mut self, stepping: &Stepping) {
        let _ = stepping;
    }

    /// After a step: a physical impossibility the model met at its last force evaluation at
    /// `state` (a tetrahedron turned inside out), which stops the run; `None` when all is
    /// well.
    fn failure(&self, state: &State) -> Option<crate::CoreError> {
        let _ = state;
        None
    }

    /// The model's linearisation for implicit and static solves; `None` (the default): the
    /// model cannot be stepped implicitly.
    fn linearized(&self) -> Option<&dyn Linearized> {
        None
    }

    /// The stiffness a modal analysis about the current state takes from the model
    /// ([`crate::lanczos`]); the default is its linearisation. A model may give one here that
    /// it cannot be stepped implicitly with: DEM contacts give their touching contacts as
    /// springs, but an implicit step would also need the events of contacts opening and
    /// closing.
    fn modal_stiffness(&self) -> Option<&dyn Linearized> {
        self.linearized()
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

    /// The model's part in a run decomposed with a halo exchange, for a model that a rank
    /// computes in part; `None` (the default): every rank computes it whole, or, with
    /// [`Model::particle_reads`] = [`ParticleReads::Local`], it reads nothing of other
    /// ranks' particles.
    fn split_model(&mut self) -> Option<&mut dyn SplitModel> {
        None
    }
}

/// What a [`SplitModel`] learns of a decomposed run: per particle, the rank that owns it
/// (`u32::MAX`: computed by every rank), and the ranks.
pub type Ownership = (Arc<[u32]>, Arc<dyn Communicator>);

/// The facet of a model that one rank of a run decomposed with a halo exchange
/// ([`crate::distributed`]) computes in part: DEM contacts evaluate only the contacts that
/// touch a sphere the rank owns, and fetch what they read of the other ranks' spheres
/// themselves. Such a model says [`ParticleReads::Local`].
pub trait SplitModel {
    /// The particles the model moves that no deformable body holds (one-sphere grains, rigid
    /// bodies): the decomposition gives them owners in runs of particle order, a rigid body
    /// whole to one rank.
    fn free_particles(&self) -> Vec<usize>;

    /// From now on, computes the forces on the particles `owner[p] == comm.rank()` only,
    /// each as one process sums it; `None`: whole again, on a state every rank holds whole
    /// (after a [`crate::World::gather`]). A collective: every rank calls it at once.
    fn split(&mut self, split: Option<Ownership>);

    /// Makes what the model records (contact lists, forces, histories) whole on every rank,
    /// as one process holds it after its last force evaluation: a collective that
    /// [`crate::World::gather`] runs. The next force evaluation goes on in part.
    fn gather(&mut self);

    /// Whether the model has rebuilt what decides its work (DEM contacts: their candidate
    /// lists) since the last call, the same on every rank: a decomposed world may then
    /// re-partition ([`crate::World::repartition`]). The default: never.
    fn rebuilt(&mut self) -> bool {
        false
    }

    /// This rank's work in the model at its last evaluation, in units of one particle's
    /// step (DEM contacts: three per candidate contact). The default: none.
    fn work(&self) -> f64 {
        0.0
    }

    /// Adds each particle's share of the model's work to `cost` (one entry per particle),
    /// from the whole records after a [`SplitModel::gather`]. The default adds nothing.
    fn add_costs(&self, cost: &mut [f64]) {
        let _ = cost;
    }
}

/// Which particles' motion a [`Model`] (or a [`crate::PostStep`] hook) reads at each step.
/// A [`SplitModel`] reads its own rank's particles and fetches what it needs of the others.
///
/// ```
/// use qdem_core::{Gravity, Model, ParticleReads, Vec3};
///
/// // Gravity reads the masses and nothing of the motion.
/// let g = Gravity::new(Vec3::new(0.0, 0.0, -9.81));
/// assert_eq!(g.particle_reads(), ParticleReads::Local);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ParticleReads {
    /// Only what a rank steps itself: nothing of the motion for gravity and nodal loads
    /// (they read the time and the masses), the nodes of its own tetrahedra for a deformable
    /// body (the decomposition's halo).
    Local,
    /// Any particle's.
    All,
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
