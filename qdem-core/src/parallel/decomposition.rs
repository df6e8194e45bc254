//! A run decomposed over processes (MPI ranks), bit-identical to one process.
//!
//! Every deformable body's blocks ([`crate::continuum::tet_blocks`]), taken in model order and then
//! block order (their spatial order: recursive bisection), are cut into one contiguous range
//! per rank of about equal work; a body whose blocks all fall on one rank is computed there
//! alone. A particle of a deformable body is **owned** by the rank of the block of its first
//! entry; its **halo** ranks are the others whose blocks hold it. The particles that split
//! models ([`crate::step::split::Facets`]: DEM contacts) move and no deformable body holds are given
//! out in runs of particle order, a rigid body whole to one rank.
//!
//! **The work of an item**, in units of one particle's step (predict and integrate): a
//! tetrahedron `TET_WORK` (1.2) times its body's cost relative to an elastic one, a particle one,
//! and what a split model's items add to the particles they sit on
//! ([`crate::step::split::Balance::add_costs`]: DEM contacts, a contact sphere and its share of
//! each candidate pair), each model's shares times its weight ([`WorkWeights`]: 1, or what its
//! items were measured to cost on the ranks, [`crate::world::World::measured_weights`]). A
//! block weighs its tetrahedra and the particles it owns, so the
//! contact spheres on a deformable body's vertices and their candidates count where they are
//! computed: a bed of deformable stones beside a deformable sleeper is cut through the stones
//! when the contacts make them the heavier part (where weighing the tetrahedra alone left
//! every stone and contact on one rank). A re-partition ([`crate::world::World::repartition`])
//! decomposes again by the work of the lists then built. Each step:
//!
//! 1. each rank predicts the particles it steps (the same arithmetic on the same values
//!    everywhere, so the predicted positions and half-step velocities agree bit for bit);
//! 2. each rank computes the tetrahedra of its blocks only; the block sums of a node owned by
//!    another rank are sent to it ([`Communicator::all_to_all`], only for bodies cut between
//!    ranks), so that the owner adds **every** block sum of its particle in ascending block
//!    order, exactly as one process does (Eq. 11);
//! 3. a split model computes what touches the rank's particles, and the exchange
//!    ([`crate::parallel::ParallelRuntime`]) brings it what it declares it reads of the others (the
//!    contacts' ghosts); the other models (loads, gravity) act on the
//!    rank's particles from the time and the masses, or, when some model reads any particle,
//!    every model is computed whole on every rank from the same state;
//! 4. after the integration, each rank's owned particles' accelerations and velocities (and
//!    spins) go to the ranks that read them (`state_share.rs`); then the failure check
//!    agrees across ranks.
//!
//! What a rank steps and what step 4 sends depend on what the models read:
//! - **halo exchange**, when every model and hook reads only what a rank steps itself or
//!   declares the rest it reads ([`crate::step::Reads::Own`]: gravity, nodal loads;
//!   [`crate::step::Reads::Split`]: deformable bodies, contacts, the periodic wrap) and the stepper can be
//!   restricted (Verlet): a rank predicts its own particles and its halo, integrates its
//!   own, and receives only its halo's motion. The other particles keep the value of the
//!   last whole gather ([`crate::world::World::gather`]), which the outputs, checkpoints and
//!   failure reports ask for before they read the state;
//! - **whole share** otherwise (bonded particles, explicit Newmark): every rank steps every
//!   particle and receives every other rank's owned particles, so that it holds the one
//!   state a single process holds after every step.
//!
//! There is no floating-point reduction across ranks in the state: a value is computed by one
//! rank in the single-process order and copied, so outputs are byte-identical for any number
//! of ranks and threads. (The one sum over ranks is the kinetic energy that the failure check
//! watches in halo mode; see `state_share.rs`.)

use crate::error::CoreError;
use crate::parallel::communicator::Communicator;
use crate::parallel::state_share::{StateHalo, StateShare};
use crate::parallel::work_weights::WorkWeights;
use crate::step::local_particles::{LocalParticles, ParticleRuns};
use crate::step::model::Model;
use crate::step::split::{BodyLayout, BodySplit, Facets, Reads, SumExchange};
use crate::step::state::State;
use crate::Vec3;
use std::sync::Arc;

/// The figures of a decomposition, per rank: how the deformable bodies' blocks and the
/// particles fall on the ranks, the same on every rank; what [`crate::world::World::decompose`]
/// returns (see the example of [`Communicator`]).
#[derive(Clone, Debug, PartialEq)]
pub struct RankFigures {
    /// The number of ranks.
    pub ranks: usize,
    /// Per rank, the tetrahedra it computes.
    pub tets: Vec<usize>,
    /// Per rank, the particles it owns (those of deformable bodies; the others are computed
    /// by every rank).
    pub owned: Vec<usize>,
    /// Per rank, the block sums it receives per step from the other ranks (its halo).
    pub halo: Vec<usize>,
    /// Per rank, the particles whose motion it receives per step: its halo's when every
    /// model reads only what a rank steps itself, else every other rank's particles.
    pub received: Vec<usize>,
    /// The bodies cut between ranks (an exchange of block sums each step).
    pub cut_bodies: usize,
    /// Per rank, the work the partition gave it (units of one particle's step, see the module
    /// documentation): its tetrahedra, the particles it owns and their items (in a run that
    /// shares only the halo; a particle every rank steps counts on none).
    pub work: Vec<f64>,
}

/// What one elastic tetrahedron's evaluation costs, in units of one particle's step (its
/// prediction and integration), measured on the paper-size loading step
/// (`fixtures/ballast/full_load.toml`, docs/ballast.md, one thread, a quiet machine): the
/// sleeper's kernel 16 ns and the stones' 18.5 ns a viscoelastic tetrahedron (1.6 elastic
/// ones), against 9 ns a particle for the rest of the step.
pub(crate) const TET_WORK: f64 = 1.2;

/// What [`decompose`] gives.
pub(crate) struct Decomposed {
    /// The exchange that ends each step.
    pub share: StateShare,
    /// The figures of the decomposition.
    pub figures: RankFigures,
    /// In a run that shares only the halo, the particles this rank steps.
    pub local: Option<LocalParticles>,
    /// Per model, its blocks for this rank if it is a deformable body.
    pub splits: Vec<Option<BodySplit>>,
    /// Per model, this rank's tetrahedra's work in the fixed shares ([`TET_WORK`] each,
    /// times its body's cost; not weighed).
    pub tet_work: Vec<f64>,
}

impl SumExchange {
    /// Sends the sums this rank computed for other ranks' particles, and writes those the
    /// others computed for this rank's particles into `sums`: the reverse exchange of
    /// [`crate::parallel::ParallelRuntime`].
    pub(crate) fn run(&mut self, comm: &dyn Communicator, sums: &mut [Vec3]) {
        self.send.clear();
        for &s in &self.send_slots {
            self.send.extend_from_slice(sums[s as usize].as_slice());
        }
        self.recv.resize(3 * self.recv_slots.len(), 0.0);
        comm.all_to_all(
            &self.send,
            &self.send_counts,
            &mut self.recv,
            &self.recv_counts,
        );
        for (&s, v) in self.recv_slots.iter().zip(self.recv.chunks_exact(3)) {
            sums[s as usize] = Vec3::new(v[0], v[1], v[2]);
        }
    }

    /// The forward exchange of per-particle `values` (from `first`) over the slots of the
    /// reverse one: each owner sends the values of its particles whose slots it receives in
    /// [`SumExchange::run`], and writes those it receives into the particles of the slots it
    /// sends there (`nodes`: the particle of each slot); a copy, no arithmetic.
    pub(crate) fn run_forward(
        &mut self,
        comm: &dyn Communicator,
        nodes: &[u32],
        first: usize,
        values: &mut [Vec3],
    ) {
        self.send.clear();
        for &s in &self.recv_slots {
            let value = values[nodes[s as usize] as usize - first];
            self.send.extend_from_slice(value.as_slice());
        }
        self.recv.resize(3 * self.send_slots.len(), 0.0);
        comm.all_to_all(
            &self.send,
            &self.recv_counts,
            &mut self.recv,
            &self.send_counts,
        );
        for (&s, v) in self.send_slots.iter().zip(self.recv.chunks_exact(3)) {
            values[nodes[s as usize] as usize - first] = Vec3::new(v[0], v[1], v[2]);
        }
    }
}

/// This rank's [`BodySplit`] of a body whose block `b` is computed by rank `block_rank[b]`.
pub(crate) fn split_body(
    layout: BodyLayout<'_>,
    block_rank: &[u32],
    comm: &Arc<dyn Communicator>,
) -> BodySplit {
    let me = comm.rank() as u32;
    let ranks = comm.size();
    let first_mine = block_rank.iter().position(|&r| r == me);
    let mine = match first_mine {
        Some(a) => a..a + block_rank[a..].iter().take_while(|&&r| r == me).count(),
        None => 0..0,
    };
    let block_of_slot = slot_blocks(layout.node_start);
    let owner: Vec<u32> = (0..layout.entry_start.len() - 1)
        .map(|i| {
            block_rank
                [block_of_slot[layout.entries[layout.entry_start[i] as usize] as usize] as usize]
        })
        .collect();
    let mut halo = vec![0; ranks];
    for (s, &node) in layout.nodes.iter().enumerate() {
        let (from, to) = (
            block_rank[block_of_slot[s] as usize],
            owner[node as usize - layout.first],
        );
        halo[to as usize] += usize::from(from != to);
    }
    let cut = block_rank.iter().any(|&r| r != block_rank[0]);
    let exchange = cut.then(|| {
        let (mut send, mut recv) = (vec![Vec::new(); ranks], vec![Vec::new(); ranks]);
        for (s, &node) in layout.nodes.iter().enumerate() {
            let from = block_rank[block_of_slot[s] as usize];
            let to = owner[node as usize - layout.first];
            if from == me && to != me {
                send[to as usize].push(s as u32);
            } else if to == me && from != me {
                recv[from as usize].push(s as u32);
            }
        }
        SumExchange {
            send_counts: send.iter().map(|v| 3 * v.len()).collect(),
            send_slots: send.concat(),
            recv_counts: recv.iter().map(|v| 3 * v.len()).collect(),
            recv_slots: recv.concat(),
            send: Vec::new(),
            recv: Vec::new(),
        }
    });
    BodySplit {
        mine,
        me,
        first: layout.first,
        owner,
        exchange,
        halo,
    }
}

/// The block of every slot.
fn slot_blocks(node_start: &[u32]) -> Vec<u32> {
    let mut block = Vec::with_capacity(*node_start.last().unwrap_or(&0) as usize);
    for (b, w) in node_start.windows(2).enumerate() {
        block.extend(std::iter::repeat_n(b as u32, (w[1] - w[0]) as usize));
    }
    block
}

/// Cuts the blocks of every deformable body (`bodies`: per body, the work of each block;
/// model order, then block order) into `ranks` contiguous ranges of about equal work; per
/// body, the rank of each block.
fn assign_blocks(bodies: &[Vec<f64>], ranks: usize) -> Vec<Vec<u32>> {
    let total: f64 = bodies.iter().flatten().sum();
    let mut done = 0.0;
    bodies
        .iter()
        .map(|blocks| {
            blocks
                .iter()
                .map(|&work| {
                    let middle = done + 0.5 * work;
                    done += work;
                    ((middle / total * ranks as f64) as usize).min(ranks - 1) as u32
                })
                .collect()
        })
        .collect()
}

/// The work of each of a body's blocks, in block order: its tetrahedra ([`TET_WORK`] each,
/// times the body's cost and its `weight`) and the `cost` of the particles it owns (those
/// whose first entry is in it).
fn block_work(layout: &BodyLayout<'_>, weight: f64, cost: &[f64]) -> Vec<f64> {
    let mut work: Vec<f64> = block_tets(layout)
        .into_iter()
        .map(|tets| weight * TET_WORK * layout.tet_cost * tets as f64)
        .collect();
    let block_of_slot = slot_blocks(layout.node_start);
    for (i, first) in layout.entry_start[..layout.entry_start.len() - 1]
        .iter()
        .enumerate()
    {
        let block = block_of_slot[layout.entries[*first as usize] as usize];
        work[block as usize] += cost[layout.first + i];
    }
    work
}

/// Each particle's work (see the module documentation): one for its step, plus what the
/// split models and hooks (`split`: each with its weight, models first) add for the items on
/// it, from their whole records, times their weight.
pub(crate) fn particle_costs<'a>(
    len: usize,
    split: impl Iterator<Item = (f64, &'a mut dyn Facets)>,
) -> Vec<f64> {
    let mut cost = vec![1.0; len];
    let mut items = vec![0.0; len];
    for (weight, facets) in split {
        if let Some(balance) = facets.balance() {
            items.fill(0.0);
            balance.add_costs(&mut items);
            for (c, w) in cost.iter_mut().zip(&items) {
                *c += weight * w;
            }
        }
    }
    cost
}

/// The blocks a deformable body declares ([`crate::step::split::Facets::body`]); `None` for
/// the other models.
fn body_of(model: &mut dyn Model) -> Option<BodyLayout<'_>> {
    match model.reads() {
        Reads::Split(facets) => {
            let facets: &dyn crate::step::split::Facets = facets;
            facets.body()
        }
        _ => None,
    }
}

/// The tetrahedra of each of a body's blocks, in block order.
fn block_tets(layout: &BodyLayout<'_>) -> Vec<usize> {
    layout
        .tet_start
        .windows(2)
        .map(|w| (w[1] - w[0]) as usize)
        .collect()
}

/// Decomposes `models`' deformable bodies over `comm`'s ranks by the work of their items
/// (`cost`: per particle, [`particle_costs`]; a body's tetrahedra times its model's weight in
/// `weights`): per model, the blocks of a deformable body
/// this rank computes and the particles it owns, and the exchange that ends each step, the
/// decomposition's figures and, when every model reads only what a rank steps itself and
/// `halo_allowed` (no hook reads more), the particles this rank steps, with the free
/// particles given out by `cost` too.
pub(crate) fn decompose(
    state: &State,
    models: &mut [Box<dyn Model>],
    comm: Arc<dyn Communicator>,
    halo_allowed: bool,
    (cost, weights): (&[f64], &WorkWeights),
) -> Result<Decomposed, CoreError> {
    let ranks = comm.size();
    let halo = halo_allowed && models.iter_mut().all(|m| !matches!(m.reads(), Reads::All));
    // Without a halo exchange every rank steps every particle and computes every split
    // model whole: only the tetrahedra are shared out.
    let unit = vec![0.0; cost.len()];
    let cost = if halo { cost } else { &unit[..] };
    let bodies: Vec<Vec<f64>> = models
        .iter_mut()
        .enumerate()
        .filter_map(|(i, m)| body_of(m.as_mut()).map(|layout| (weights.of(i), layout)))
        .map(|(weight, layout)| block_work(&layout, weight, cost))
        .collect();
    let block_ranks = assign_blocks(&bodies, ranks);
    let mut figures = RankFigures {
        ranks,
        tets: vec![0; ranks],
        owned: vec![0; ranks],
        halo: vec![0; ranks],
        received: vec![0; ranks],
        cut_bodies: 0,
        work: vec![0.0; ranks],
    };
    let mut owner = vec![u32::MAX; state.len()];
    let mut needs = Vec::new();
    let mut tet_work = vec![0.0; models.len()];
    let mut splits = Vec::with_capacity(models.len());
    let mut blocks = bodies.iter().zip(block_ranks);
    for (m, model) in models.iter_mut().enumerate() {
        let Some(layout) = body_of(model.as_mut()) else {
            splits.push(None);
            continue;
        };
        let (work, block_rank) = blocks.next().expect("one block assignment per body");
        for ((tets, &r), w) in block_tets(&layout).into_iter().zip(&block_rank).zip(work) {
            figures.tets[r as usize] += tets;
            figures.work[r as usize] += w;
            if r as usize == comm.rank() {
                tet_work[m] += TET_WORK * layout.tet_cost * tets as f64;
            }
        }
        figures.cut_bodies += usize::from(block_rank.iter().any(|&r| r != block_rank[0]));
        let split = split_body(layout, &block_rank, &comm);
        for (i, &r) in split.owner.iter().enumerate() {
            let p = split.first + i;
            if owner[p] != u32::MAX {
                return Err(CoreError::Decomposition(format!(
                    "particle {p} belongs to two deformable bodies"
                )));
            }
            owner[p] = r;
            figures.owned[r as usize] += 1;
        }
        for (total, n) in figures.halo.iter_mut().zip(&split.halo) {
            *total += n;
        }
        if halo {
            needs.extend(halo_of(layout, &block_rank, &split.owner));
        }
        splits.push(Some(split));
    }
    if !halo {
        let mut share = StateShare::new(&owner, state, None, comm);
        share.share_whole_every_step(&mut figures);
        return Ok(Decomposed {
            share,
            figures,
            local: None,
            splits,
            tet_work,
        });
    }
    needs.sort_unstable();
    needs.dedup();
    for &(q, _) in &needs {
        figures.received[q as usize] += 1;
    }
    own_in_runs(state, models, &mut owner, &mut figures, cost);
    let me = comm.rank() as u32;
    let (exchange, local) = halo_exchange(&owner, &needs, me, ranks);
    let share = StateShare::new(&owner, state, Some(exchange), comm);
    Ok(Decomposed {
        share,
        figures,
        local: Some(local),
        splits,
        tet_work,
    })
}

/// Gives owners to the particles that split models move and no deformable body holds
/// ([`crate::step::split::Ownership::free_particles`], `owner` `u32::MAX`): runs of particle
/// order of about equal `cost`, a rigid body (its centre and members) whole to one rank.
/// The builders place grains layer by layer, so a run is a slab of the packing (its ghosts
/// are one layer at each cut) and a rank streams contiguous memory when it steps its
/// grains; counts them and their work in `figures`.
fn own_in_runs(
    state: &State,
    models: &mut [Box<dyn Model>],
    owner: &mut [u32],
    figures: &mut RankFigures,
    cost: &[f64],
) {
    let mut free: Vec<usize> = models
        .iter_mut()
        .filter_map(|m| match m.reads() {
            Reads::Split(part) => Some(part.free_particles()),
            _ => None,
        })
        .flatten()
        .filter(|&p| owner[p] == u32::MAX)
        .collect();
    free.sort_unstable();
    free.dedup();
    let rigid = &state.rigid;
    let mut body_of_center = vec![None; state.len()];
    for (b, &c) in rigid.center.iter().enumerate() {
        body_of_center[c] = Some(b);
    }
    let mut placed = vec![false; rigid.len()];
    let mut units: Vec<Vec<usize>> = Vec::new();
    for &p in &free {
        match rigid.body_of_member(p).or(body_of_center[p]) {
            Some(b) if !placed[b] => {
                placed[b] = true;
                units.push(
                    [rigid.center[b]]
                        .into_iter()
                        .chain(rigid.members(b).iter().copied())
                        .collect(),
                );
            }
            Some(_) => {}
            None => units.push(vec![p]),
        }
    }
    let weight = |unit: &[usize]| unit.iter().map(|&p| cost[p]).sum::<f64>();
    let ranks = figures.ranks;
    let total: f64 = units.iter().map(|u| weight(u)).sum();
    let mut before = 0.0;
    for unit in &units {
        let w = weight(unit);
        let r = (((before + 0.5 * w) / total * ranks as f64) as usize).min(ranks - 1);
        for &p in unit {
            owner[p] = r as u32;
        }
        figures.owned[r] += unit.len();
        figures.work[r] += w;
        before += w;
    }
}

/// The (rank, particle) pairs of a body's halo: the nodes of each rank's blocks that another
/// rank owns (`owner`: per particle of the body, from its first).
fn halo_of<'a>(
    layout: BodyLayout<'a>,
    block_rank: &'a [u32],
    owner: &'a [u32],
) -> impl Iterator<Item = (u32, u32)> + 'a {
    layout
        .node_start
        .windows(2)
        .zip(block_rank)
        .flat_map(move |(w, &q)| {
            let nodes = &layout.nodes[w[0] as usize..w[1] as usize];
            nodes
                .iter()
                .filter(move |&&n| owner[n as usize - layout.first] != q)
                .map(move |&n| (q, n))
        })
}

/// This rank's halo exchange and local particles, from every rank's halo `needs` ((rank,
/// particle), sorted) and the particles' owners (`u32::MAX`: computed by all).
fn halo_exchange(
    owner: &[u32],
    needs: &[(u32, u32)],
    me: u32,
    ranks: usize,
) -> (StateHalo, LocalParticles) {
    let (mut send, mut recv) = (vec![Vec::new(); ranks], vec![Vec::new(); ranks]);
    let mut stepped: Vec<bool> = owner.iter().map(|&r| r == me || r == u32::MAX).collect();
    let computed = ParticleRuns::from_mask(&stepped);
    for &(q, p) in needs {
        let from = owner[p as usize];
        if q == me {
            recv[from as usize].push(p);
            stepped[p as usize] = true;
        } else if from == me {
            send[q as usize].push(p);
        }
    }
    let counted: Vec<bool> = owner
        .iter()
        .map(|&r| r == me || (me == 0 && r == u32::MAX))
        .collect();
    let halo = StateHalo {
        send_counts: send.iter().map(Vec::len).collect(),
        send: send.concat(),
        recv_counts: recv.iter().map(Vec::len).collect(),
        recv: recv.concat(),
        counted: ParticleRuns::from_mask(&counted),
    };
    let local = LocalParticles {
        computed,
        stepped: ParticleRuns::from_mask(&stepped),
    };
    (halo, local)
}
