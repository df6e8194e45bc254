//! What a model declares of a decomposed run: [`Reads`] (what it reads of the particles'
//! motion) and, for a model (or hook) that one rank computes in part, its [`Facets`]: small
//! traits with one job each, which the [`crate::parallel::ParallelRuntime`] runs with its
//! collectives in between. A model implements only the facets it uses and never calls a
//! collective; the way LAMMPS's pair styles give `pack_forward_comm` and
//! `unpack_forward_comm` to its `Comm`.
//!
//! - [`Ownership`]: the model's part ([`Part`]) and the particles it moves that no
//!   deformable body holds;
//! - [`Facets::body`]: a deformable body's blocks, which the decomposition cuts between
//!   the ranks ([`BodyLayout`]);
//! - [`Evaluation`]: its force evaluation in two stages, computing and adding;
//! - [`Facets::averaging`]: nodal averages a body's forces read, summed over ranks first
//!   ([`Averaging`]: the averaged-pressure tetrahedron's volumetric strain);
//! - [`Lists`]: neighbour lists and when they are rebuilt;
//! - [`Halo`]: the item records it exchanges forward (contact spheres), and its ghosts;
//! - [`Reduction`]: what the ranks reduce together within an evaluation;
//! - [`Facets::reverse_sums`]: the sums it computed for other ranks' particles
//!   ([`PartialSums`]);
//! - [`Merge`]: its records, merged into the whole model a single process holds;
//! - [`Balance`]: its work, by which the free particles are re-partitioned;
//! - [`Decisions`]: a post-step hook's decisions for its own particles, and its acts on
//!   every rank's.
//!
//! One force evaluation of a split model, as the runtime runs it on every rank:
//!
//! 1. [`Lists::moved`]: the rank reads its own particles and returns how far one has moved
//!    since its lists were built, and the runtime takes the largest over the ranks (a max:
//!    exact);
//! 2. [`Lists::needs_rebuild`] on that largest displacement: if so, every rank receives
//!    every item's record (**borders**: [`Halo::pack`] and [`Halo::unpack`] of each rank's
//!    own items) and [`Lists::rebuild`]s its lists;
//! 3. [`Halo::new_ghosts`]: the items of other ranks that the rank's lists now read, when
//!    they changed; the runtime learns who sends what to whom;
//! 4. [`Halo::read_partners`], then the **forward** exchange: each rank packs the items
//!    others read as ghosts, and unpacks its own ghosts;
//! 5. for a body with nodal averages ([`Averaging`]): its partial sums, their **reverse**
//!    exchange to the particles' owners, the owners' averages and their **forward** exchange
//!    back to the ranks whose blocks read them; then [`Evaluation::compute`], then a **reduction** when the model has one
//!    ([`Reduction::mine`], [`Reduction::reduced`]: a time-delayed boundary's force,
//!    measured over every rank's pairs);
//! 6. the **reverse** exchange of [`Facets::reverse_sums`] (a deformable body's block sums
//!    for nodes another rank owns);
//! 7. [`Evaluation::apply`]: the rank adds its own particles' forces.
//!
//! A post-step hook that decides for its own particles ([`crate::step::PostStep::reads`]) has
//! [`Ownership`] and [`Decisions`] only:
//!
//! ```
//! use qdem_core::step::split::{Decisions, Facets, Ownership};
//! use qdem_core::{step::Halt, step::Model, step::Part, step::PostStep, step::Reads, step::State};
//!
//! /// Pins particle 0 back to x = 0 after every step; the rank that owns it decides.
//! struct Pin {
//!     part: Option<Part>,
//! }
//!
//! impl PostStep for Pin {
//!     fn name(&self) -> &str { "pin" }
//!     fn after_step(&mut self, state: &mut State, _: &[Box<dyn Model>]) -> Option<Halt> {
//!         state.position[0].x = 0.0;
//!         None
//!     }
//!     fn reads(&mut self) -> Reads<'_> { Reads::Split(self) }
//! }
//!
//! impl Ownership for Pin {
//!     fn split(&mut self, part: Option<Part>) { self.part = part; }
//! }
//!
//! impl Facets for Pin {
//!     fn decisions(&mut self) -> Option<&mut dyn Decisions> { Some(self) }
//! }
//!
//! impl Decisions for Pin {
//!     fn decide(&self, state: &State, out: &mut Vec<f64>) {
//!         let owns = self.part.as_ref().is_some_and(|p| p.owner[0] == p.rank);
//!         if owns && state.position[0].x != 0.0 {
//!             out.push(0.0);
//!         }
//!     }
//!     fn act(&mut self, state: &mut State, all: &[f64]) {
//!         if !all.is_empty() {
//!             state.position[0].x = 0.0;
//!         }
//!     }
//! }
//!
//! let mut pin = Pin { part: None };
//! let Reads::Split(facets) = pin.reads() else { unreachable!() };
//! assert!(facets.decisions().is_some() && facets.evaluation().is_none());
//! ```

use crate::step::state::State;
use crate::Vec3;
use std::ops::Range;
use std::sync::Arc;

/// How a [`crate::step::Model`] (or a [`crate::step::PostStep`] hook) takes part in a run decomposed
/// over ranks: what it reads of the particles' motion at each step. The default,
/// [`Reads::All`], is always right.
///
/// ```
/// use qdem_core::{loads::Gravity, step::Model, step::Reads, Vec3};
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
    /// Computed in part by each rank, through the model's facets: it reads its own
    /// particles and receives what it declares of the others (deformable bodies, contacts,
    /// the periodic wrap).
    Split(&'a mut dyn Facets),
}

/// A model's part of a decomposed run, given to [`Ownership::split`]: per particle, the
/// rank that owns it (`u32::MAX`: computed by every rank), this rank, and for a deformable
/// body ([`Facets::body`]) its share of the blocks.
///
/// ```
/// use qdem_core::step::Part;
/// use std::sync::Arc;
///
/// // Rank 1 of a run whose three particles are owned by ranks 0, 1 and every rank.
/// let part = Part { owner: Arc::from([0, 1, u32::MAX]), rank: 1, body: None };
/// let own: Vec<usize> = (0..3).filter(|&p| part.owner[p] == part.rank).collect();
/// assert_eq!(own, [1]);
/// ```
#[derive(Clone)]
pub struct Part {
    /// Per particle, the rank that owns it (`u32::MAX`: computed by every rank); empty for
    /// a deformable body, whose owners are its [`BodySplit::owner`].
    pub owner: Arc<[u32]>,
    /// This rank.
    pub rank: u32,
    /// A deformable body's blocks for this rank (the decomposition's of its
    /// [`Facets::body`]); `None` for the other models.
    pub body: Option<BodySplit>,
}

/// A deformable body's block sums for the nodes that other ranks own, which the reverse
/// exchange sends to the owners ([`Facets::reverse_sums`]); a body builds it from its
/// sums and the exchange of its [`BodySplit`].
///
/// ```
/// use qdem_core::step::split::BodySplit;
/// use qdem_core::{step::PartialSums, Vec3};
///
/// /// A body's sums per slot of its blocks, and its share of a decomposed run.
/// struct Body {
///     sums: Vec<Vec3>,
///     split: Option<BodySplit>,
/// }
///
/// impl Body {
///     /// What the reverse exchange sends: only a body cut between ranks has an exchange.
///     fn reverse_sums(&mut self) -> Option<PartialSums<'_>> {
///         let plan = self.split.as_mut()?.exchange.as_mut()?;
///         Some(PartialSums { sums: &mut self.sums, plan })
///     }
/// }
///
/// let mut whole = Body { sums: vec![Vec3::zeros(); 4], split: None };
/// assert!(whole.reverse_sums().is_none());
/// ```
pub struct PartialSums<'a> {
    /// The body's block sums (a slot per node of a block, laid out as its
    /// [`BodyLayout::nodes`]).
    pub sums: &'a mut [Vec3],
    /// Which slots go to and come from which rank.
    pub plan: &'a mut SumExchange,
}

/// Who owns what of a split model: the facet every split model (and split hook) has.
pub trait Ownership {
    /// From now on, computes the forces on the particles `part.owner[p] == part.rank` only
    /// (a deformable body: on the particles its [`BodySplit`] gives this rank), each as one
    /// process sums it; `None`: whole again, on a state every rank holds whole.
    fn split(&mut self, part: Option<Part>);

    /// The particles the model moves that no deformable body holds (one-sphere grains, rigid
    /// bodies): the decomposition gives them owners in runs of particle order, a rigid body
    /// whole to one rank. The default: none.
    fn free_particles(&self) -> Vec<usize> {
        Vec::new()
    }
}

/// The facets of a model that one rank of a decomposed run computes in part: its
/// [`Ownership`], and each facet it has (`None`, the default, for those it has not). See
/// the module documentation for the order in which the runtime uses them.
pub trait Facets: Ownership {
    /// A deformable body's blocks, which the decomposition cuts between the ranks.
    fn body(&self) -> Option<BodyLayout<'_>> {
        None
    }

    /// The nodal averages a deformable body's forces read (the averaged-pressure
    /// tetrahedron), run before [`Evaluation::compute`].
    fn averaging(&mut self) -> Option<&mut dyn Averaging> {
        None
    }

    /// The stages of a model's force evaluation (every split model has them; a hook not).
    fn evaluation(&mut self) -> Option<&mut dyn Evaluation> {
        None
    }

    /// Neighbour lists, rebuilt when the ranks agree they must be.
    fn lists(&mut self) -> Option<&mut dyn Lists> {
        None
    }

    /// Item records exchanged forward: every rank's own at a rebuild, the ghosts' at each
    /// evaluation.
    fn halo(&mut self) -> Option<&mut dyn Halo> {
        None
    }

    /// What the ranks reduce together within an evaluation.
    fn reduction(&mut self) -> Option<&mut dyn Reduction> {
        None
    }

    /// The sums this rank computed for particles other ranks own (a deformable body cut
    /// between ranks).
    fn reverse_sums(&mut self) -> Option<PartialSums<'_>> {
        None
    }

    /// Records that a whole gather merges into the model one process holds.
    fn merge(&mut self) -> Option<&mut dyn Merge> {
        None
    }

    /// The work that a re-partition balances.
    fn balance(&mut self) -> Option<&mut dyn Balance> {
        None
    }

    /// A post-step hook's decisions for its own particles.
    fn decisions(&mut self) -> Option<&mut dyn Decisions> {
        None
    }
}

/// A split model's force evaluation: stages 5 and 7 of the module documentation.
pub trait Evaluation {
    /// Computes this rank's part from the state and the ghosts' records.
    fn compute(&mut self, state: &State);

    /// Adds the forces (and moments) on this rank's own particles.
    fn apply(&mut self, force: &mut [Vec3], torque: &mut [Vec3]);
}

/// Nodal averages that a deformable body's forces read, each a sum over the blocks that hold
/// the particle (the averaged-pressure tetrahedron's θ̄_a): stage 5, before
/// [`Evaluation::compute`]. The runtime calls, in order, [`Averaging::partial`], the reverse
/// exchange of [`Averaging::partial_sums`], [`Averaging::average`] and the forward exchange
/// of [`Averaging::averages`].
pub trait Averaging {
    /// Computes this rank's blocks' partial sums at `state`.
    fn partial(&mut self, state: &State);

    /// The partial sums for particles other ranks own (laid out as the block sums), which
    /// the reverse exchange sends to the owners; `None` when the body is not cut.
    fn partial_sums(&mut self) -> Option<PartialSums<'_>>;

    /// Averages the particles this rank owns from their complete partial sums.
    fn average(&mut self);

    /// The averages, which the forward exchange copies from each owner to the ranks whose
    /// blocks hold the particle; `None` when the body is not cut.
    fn averages(&mut self) -> Option<NodalValues<'_>>;
}

/// A deformable body's per-particle values that owners send forward to the ranks whose
/// blocks hold the particle ([`Averaging::averages`]), by the slots of its [`SumExchange`].
pub struct NodalValues<'a> {
    /// Per particle of the body (from `first`), its value.
    pub values: &'a mut [Vec3],
    /// The particle of each block slot (the body's [`BodyLayout::nodes`]).
    pub nodes: &'a [u32],
    /// The body's first particle.
    pub first: usize,
    /// The slots exchanged, as the reverse exchange lists them.
    pub plan: &'a mut SumExchange,
}

/// A split model's neighbour lists: stages 1 and 2.
pub trait Lists {
    /// Reads this rank's own particles at `state`; returns the largest distance one of its
    /// own items has moved since the lists were built (infinite before).
    fn moved(&mut self, state: &State) -> f64;

    /// Whether the lists must be rebuilt, given the largest displacement over every rank
    /// (the same answer on every rank).
    fn needs_rebuild(&self, moved: f64, time: f64) -> bool;

    /// Rebuilds the lists near this rank's items, once every item's record is known.
    fn rebuild(&mut self, time: f64);
}

/// A split model's item records, exchanged forward from their owners: stages 2 to 4.
pub trait Halo {
    /// The particle of each item whose record the ranks exchange (contact spheres).
    fn items(&self) -> Vec<usize>;

    /// Values per item record in [`Halo::pack`].
    fn record_values(&self) -> usize;

    /// Appends the records of `items` (this rank's own) to `out`.
    fn pack(&self, items: &[u32], out: &mut Vec<f64>);

    /// Sets the records of `items` from what [`Halo::pack`] wrote on their owners.
    fn unpack(&mut self, items: &[u32], values: &[f64]);

    /// The items of other ranks that this rank's lists read (ascending), when they changed
    /// since the last call; `None` when unchanged.
    fn new_ghosts(&mut self) -> Option<Vec<u32>>;

    /// Reads the motion of the own items that the lists read, before the forward exchange
    /// sends them.
    fn read_partners(&mut self, state: &State);
}

/// What the ranks of a decomposed run reduce together within an evaluation (a time-delayed
/// boundary's contact forces): stage 5.
pub trait Reduction {
    /// Appends this rank's share to `out` and returns true; false when there is nothing to
    /// reduce (the same answer on every rank).
    fn mine(&mut self, out: &mut Vec<f64>) -> bool;

    /// Every rank's [`Reduction::mine`], in rank order.
    fn reduced(&mut self, time: f64, all: &[f64]);
}

/// The records a whole gather ([`crate::world::World::gather`]) merges.
pub trait Merge {
    /// Appends this rank's records (contacts) to `out` and returns true; false when the
    /// model is whole already (the same answer on every rank).
    fn records(&self, out: &mut Vec<f64>) -> bool;

    /// Makes the model whole, as one process holds it after its last evaluation, from every
    /// rank's [`Merge::records`] (`all`, in rank order) and every item's record.
    fn merge(&mut self, all: &[f64]);
}

/// A split model's work, which the decomposition weighs ([`crate::parallel::decomposition`])
/// and a re-partition ([`crate::world::World::repartition`]) balances.
pub trait Balance {
    /// Whether the model has rebuilt what decides its work (DEM contacts: their candidate
    /// lists) since the last call, the same on every rank: a decomposed world may then
    /// re-partition.
    fn rebuilt(&mut self) -> bool;

    /// This rank's work in the model at its last evaluation, in units of one particle's
    /// step (DEM contacts: five per own contact sphere and three per candidate contact).
    fn work(&self) -> f64;

    /// Adds each particle's share of the model's work to `cost` (one entry per particle),
    /// from the whole records (before the decomposition, or after a gather).
    fn add_costs(&self, cost: &mut [f64]);
}

/// A post-step hook's decisions, which every rank acts on after a step.
pub trait Decisions {
    /// Appends what this rank decided (the groups whose anchor it owns that wrap) to `out`.
    fn decide(&self, state: &State, out: &mut Vec<f64>);

    /// Acts on every rank's decisions (`all`, in rank order).
    fn act(&mut self, state: &mut State, all: &[f64]);
}

/// One deformable body's share of the decomposition, for one rank: which of its blocks the
/// rank computes, which of its particles the rank owns, which block sums go where. The
/// decomposition makes it from the body's [`BodyLayout`] and hands it over in
/// [`crate::step::Part::body`].
#[derive(Clone, Debug)]
pub struct BodySplit {
    /// The blocks this rank computes.
    pub mine: Range<usize>,
    /// This rank.
    pub me: u32,
    /// The body's first particle.
    pub first: usize,
    /// Per particle of the body (from `first`), the rank that owns it and sums its force.
    pub owner: Vec<u32>,
    /// The exchange of block sums, for a body cut between ranks.
    pub exchange: Option<SumExchange>,
    /// Per rank, the body's block sums it receives per step.
    pub halo: Vec<usize>,
}

/// The block sums a rank sends to and receives from the others each step (slots of the
/// body's sums, grouped by rank, ascending within a rank: both sides list them alike). A
/// body hands it back in its [`crate::step::PartialSums`]; the runtime runs it.
#[derive(Clone)]
pub struct SumExchange {
    pub(crate) send_slots: Vec<u32>,
    /// Values (three per sum) sent to each rank.
    pub(crate) send_counts: Vec<usize>,
    pub(crate) recv_slots: Vec<u32>,
    /// Values received from each rank.
    pub(crate) recv_counts: Vec<usize>,
    pub(crate) send: Vec<f64>,
    pub(crate) recv: Vec<f64>,
}

impl std::fmt::Debug for SumExchange {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SumExchange")
            .field("send", &self.send_slots.len())
            .field("recv", &self.recv_slots.len())
            .finish()
    }
}

/// What the decomposition reads of a deformable body's blocks, which the body declares
/// ([`crate::step::split::Facets::body`]): block `b` holds the tetrahedra
/// `tet_start[b]..tet_start[b + 1]` and the node slots `node_start[b]..node_start[b + 1]`.
#[derive(Clone, Copy)]
pub struct BodyLayout<'a> {
    /// What one tetrahedron of the body costs to compute, relative to an elastic one.
    pub tet_cost: f64,
    /// Block `b`'s tetrahedra are `tet_start[b]..tet_start[b + 1]`.
    pub tet_start: &'a [u32],
    /// Block `b`'s slots are `node_start[b]..node_start[b + 1]`.
    pub node_start: &'a [u32],
    /// The particle of each slot.
    pub nodes: &'a [u32],
    /// The body's first particle.
    pub first: usize,
    /// Particle `first + i`'s entries are `entries[entry_start[i]..entry_start[i + 1]]`.
    pub entry_start: &'a [u32],
    /// Slots, per particle in ascending block order.
    pub entries: &'a [u32],
}
