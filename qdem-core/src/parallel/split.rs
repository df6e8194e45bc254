//! What a model declares of a decomposed run: [`Reads`] (what it reads of the particles'
//! motion) and, for a model that one rank computes in part, its [`SplitModel`] facet: the
//! stages of its force evaluation and what it packs for the others, which the
//! [`crate::parallel::Exchange`] runs with its collectives in between. A model never calls
//! a collective; the way LAMMPS's pair styles give `pack_forward_comm` and
//! `unpack_forward_comm` to its `Comm`.
//!
//! One force evaluation of a split model, as the exchange runs it on every rank:
//!
//! 1. [`SplitModel::read_own`]: the rank reads its own particles; a model that keeps
//!    neighbour lists returns how far one has moved since they were built, and the exchange
//!    takes the largest over the ranks (a max: exact);
//! 2. [`SplitModel::needs_rebuild`] on that largest displacement: if so, every rank receives
//!    every item's record (**borders**: [`SplitModel::pack`] and [`SplitModel::unpack`] of
//!    each rank's own items) and [`SplitModel::rebuild`]s its lists;
//! 3. [`SplitModel::new_ghosts`]: the items of other ranks that the rank's lists now read,
//!    when they changed; the exchange learns who sends what to whom;
//! 4. [`SplitModel::read_partners`], then the **forward** exchange: each rank packs the
//!    items others read as ghosts, and unpacks its own ghosts;
//! 5. [`SplitModel::compute`], then a **reduction** when the model asks for one
//!    ([`SplitModel::reduction`], [`SplitModel::reduced`]: a time-delayed boundary's force,
//!    measured over every rank's pairs);
//! 6. the **reverse** exchange of [`SplitModel::partial_sums`] (a deformable body's block
//!    sums for nodes another rank owns);
//! 7. [`SplitModel::apply`]: the rank adds its own particles' forces.

use crate::parallel::decomposition::{BodySplit, SumExchange};
use crate::step::state::State;
use crate::Vec3;
use std::sync::Arc;

/// How a [`crate::Model`] (or a [`crate::PostStep`] hook) takes part in a run decomposed
/// over ranks: what it reads of the particles' motion at each step. The default,
/// [`Reads::All`], is always right.
///
/// ```
/// use qdem_core::{Gravity, Model, Reads, Vec3};
///
/// // Gravity reads the masses and nothing of the motion.
/// let mut g = Gravity::new(Vec3::new(0.0, 0.0, -9.81));
/// assert!(matches!(g.reads(), Reads::Own));
/// ```
pub enum Reads<'a> {
    /// Any particle's motion: every rank steps every particle and holds the state one
    /// process holds after every step.
    All,
    /// Only what a rank steps itself: nothing of the motion for gravity and nodal loads
    /// (they read the time and the masses).
    Own,
    /// Computed in part by each rank, through the model's split facet: it reads its own
    /// particles and receives what it declares of the others (deformable bodies, contacts,
    /// the periodic wrap).
    Split(&'a mut dyn SplitModel),
}

/// A model's part of a decomposed run, given to [`SplitModel::split`]: per particle, the
/// rank that owns it (`u32::MAX`: computed by every rank), and this rank.
#[derive(Clone)]
pub struct Part {
    /// Per particle, the rank that owns it (`u32::MAX`: computed by every rank).
    pub owner: Arc<[u32]>,
    /// This rank.
    pub rank: u32,
    /// A deformable body's blocks for this rank (the decomposition's).
    pub(crate) body: Option<BodySplit>,
}

/// A deformable body's block sums for the nodes that other ranks own, which the reverse
/// exchange sends to the owners ([`SplitModel::partial_sums`]).
pub struct PartialSums<'a> {
    /// The body's block sums (a slot per node of a block).
    pub(crate) sums: &'a mut [Vec3],
    /// Which slots go to and come from which rank.
    pub(crate) plan: &'a mut SumExchange,
}

/// The facet of a model that one rank of a decomposed run computes in part (see the module
/// documentation for the order in which the exchange calls it). Every method but
/// [`SplitModel::split`] has a default that does nothing, so a model declares only what it
/// exchanges.
pub trait SplitModel {
    /// The particles the model moves that no deformable body holds (one-sphere grains, rigid
    /// bodies): the decomposition gives them owners in runs of particle order, a rigid body
    /// whole to one rank.
    fn free_particles(&self) -> Vec<usize> {
        Vec::new()
    }

    /// From now on, computes the forces on the particles `part.owner[p] == part.rank` only,
    /// each as one process sums it; `None`: whole again, on a state every rank holds whole.
    fn split(&mut self, part: Option<Part>);

    /// The particle of each item whose record the ranks exchange (contact spheres); empty
    /// (the default) for a model that exchanges none.
    fn items(&self) -> Vec<usize> {
        Vec::new()
    }

    /// Values per item record in [`SplitModel::pack`].
    fn record_values(&self) -> usize {
        0
    }

    /// Appends the records of `items` (this rank's own) to `out`.
    fn pack(&self, items: &[u32], out: &mut Vec<f64>) {
        let _ = (items, out);
    }

    /// Sets the records of `items` from what [`SplitModel::pack`] wrote on their owners.
    fn unpack(&mut self, items: &[u32], values: &[f64]) {
        let _ = (items, values);
    }

    /// Stage 1: reads this rank's own particles at `state`; returns, for a model that keeps
    /// neighbour lists, the largest distance one of its own items has moved since they were
    /// built (infinite before); `None` (the default) for a model without lists.
    fn read_own(&mut self, state: &State) -> Option<f64> {
        let _ = state;
        None
    }

    /// Stage 2: whether the lists must be rebuilt, given the largest displacement over every
    /// rank (the same answer on every rank).
    fn needs_rebuild(&self, moved: f64, time: f64) -> bool {
        let _ = (moved, time);
        false
    }

    /// Stage 2: rebuilds the lists near this rank's items, once every item's record is known.
    fn rebuild(&mut self, time: f64) {
        let _ = time;
    }

    /// Stage 3: the items of other ranks that this rank's lists read (ascending), when they
    /// changed since the last call; `None` when unchanged.
    fn new_ghosts(&mut self) -> Option<Vec<u32>> {
        None
    }

    /// Stage 4: reads the motion of the own items that the lists read, before the forward
    /// exchange sends them.
    fn read_partners(&mut self, state: &State) {
        let _ = state;
    }

    /// Stage 5: computes this rank's part from the state and the ghosts' records.
    fn compute(&mut self, state: &State);

    /// Stage 5: appends what the ranks must reduce together (a time-delayed boundary's
    /// contact forces) to `out` and returns true; false (the default) for none.
    fn reduction(&mut self, out: &mut Vec<f64>) -> bool {
        let _ = out;
        false
    }

    /// Stage 5: every rank's [`SplitModel::reduction`], in rank order.
    fn reduced(&mut self, time: f64, all: &[f64]) {
        let _ = (time, all);
    }

    /// Stage 6: the sums this rank computed for particles other ranks own; `None` (the
    /// default) for a model without.
    fn partial_sums(&mut self) -> Option<PartialSums<'_>> {
        None
    }

    /// Stage 7: adds the forces (and moments) on this rank's own particles.
    fn apply(&mut self, force: &mut [Vec3], torque: &mut [Vec3]);

    /// What a whole gather merges: appends this rank's records (contacts) to `out` and
    /// returns true; false (the default) when the model is whole already (the same answer on
    /// every rank).
    fn records(&self, out: &mut Vec<f64>) -> bool {
        let _ = out;
        false
    }

    /// Makes the model whole, as one process holds it after its last evaluation, from every
    /// rank's [`SplitModel::records`] (`all`, in rank order) and every item's record.
    fn merge(&mut self, all: &[f64]) {
        let _ = all;
    }

    /// After a step, for a post-step hook: appends what this rank decided (the groups whose
    /// anchor it owns that wrap) to `out`.
    fn decide(&self, state: &State, out: &mut Vec<f64>) {
        let _ = (state, out);
    }

    /// After a step, for a post-step hook: acts on every rank's decisions (`all`, in rank
    /// order).
    fn act(&mut self, state: &mut State, all: &[f64]) {
        let _ = (state, all);
    }

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
    /// from the whole records after a gather. The default adds nothing.
    fn add_costs(&self, cost: &mut [f64]) {
        let _ = cost;
    }
}
