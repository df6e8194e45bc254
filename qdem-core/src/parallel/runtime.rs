//! [`ParallelRuntime`]: the one place where a step meets the ranks. A [`crate::world::World`] owns
//! one: single-process by default, where every call is a plain loop or does nothing, and
//! decomposed after [`crate::world::World::decompose`]. The steppers evaluate forces through it
//! ([`Seam::sum_forces`](crate::step::seam::Seam::sum_forces)) and end each integration with it
//! ([`ParallelRuntime::complete`]); the world runs its gathers, its failure agreement, the
//! post-step hooks and the re-partitions through it. Models never call a collective: a split model declares what it exchanges
//! ([`crate::step::split::Facets`]) and the runtime runs the collectives between its stages, in
//! the same order on every rank.

use crate::error::CoreError;
use crate::parallel::communicator::{max_over_ranks, Communicator};
use crate::parallel::decomposition::{decompose, particle_costs, Decomposed, RankFigures};
use crate::parallel::ghosts::GhostTable;
use crate::parallel::state_share::StateShare;
use crate::parallel::work_weights::WorkWeights;
use crate::step::local_particles::{LocalParticles, ParticleRuns};
use crate::step::model::Model;
use crate::step::post_step::{Halt, PostStep};
use crate::step::seam::{add_model_forces, Seam};
use crate::step::split::{Balance, BodySplit, Facets, Part, Reads};
use crate::step::stages::{Stage, StageTimes};
use crate::step::state::State;
use crate::Vec3;
use std::sync::Arc;

/// The ratio of the busiest rank's work to the mean above which a rebuild of a split
/// model's lists re-partitions ([`crate::world::World::repartition`]).
const REPARTITION_IMBALANCE: f64 = 1.1;

/// Rebuilds between two re-partitions at least: a re-partition gathers the whole state, and
/// an imbalance it cannot mend (one body heavier than a rank's share) must not make every
/// rebuild pay for it.
const REPARTITION_REBUILDS: usize = 8;

/// What a step exchanges between the ranks of a decomposed run; nothing in a run of one
/// process ([`ParallelRuntime::default`]), where [`Seam::sum_forces`](crate::step::seam::Seam::sum_forces) sums the
/// models' forces and the rest does nothing.
///
/// ```
/// use qdem_core::{parallel::ParallelRuntime, loads::Gravity, step::Model, step::State, step::StageTimes, Vec3};
/// use qdem_core::step::seam::Seam;
///
/// let mut state = State::at_rest(vec![Vec3::zeros()]);
/// state.mass[0] = 2.0;
/// let mut models: Vec<Box<dyn Model>> = vec![Box::new(Gravity::new(Vec3::new(0.0, 0.0, -9.81)))];
/// let (mut force, mut torque) = (Vec::new(), Vec::new());
/// let mut exchange = ParallelRuntime::default();
/// exchange.sum_forces(&state, &mut models, &mut force, &mut torque, &mut StageTimes::off());
/// assert_eq!(force[0].z, -19.62);
/// assert!(exchange.decomposition().is_none());
/// ```
#[derive(Default)]
pub struct ParallelRuntime {
    ranks: Option<Ranks>,
}

/// The exchange of a decomposed run.
struct Ranks {
    comm: Arc<dyn Communicator>,
    share: StateShare,
    figures: RankFigures,
    /// The particles this rank steps, when a step shares only the halo (the only run that
    /// re-partitions).
    local: Option<LocalParticles>,
    /// Per model, this rank's tetrahedra's work in the fixed shares (units of one
    /// particle's step).
    tet_work: Vec<f64>,
    /// The weight of each model's items in the cut (the fixed shares until measured).
    weights: WorkWeights,
    /// Per model, the seconds of its evaluations spent in collectives (waiting for the
    /// other ranks included): not the work of its items.
    exchanged: Vec<f64>,
    /// Per model: whether a deformable body (split by its blocks in any mode).
    bodies: Vec<bool>,
    /// Per model, its split state when this rank computes it in part.
    models: Vec<Option<Ghosts>>,
    /// Per hook: whether it is split (decides for its own particles).
    hooks: Vec<bool>,
    /// Re-partitions so far, and rebuilds of a split model's lists since the last one.
    repartitions: usize,
    rebuilds_since: usize,
    mine: Vec<f64>,
    all: Vec<f64>,
}

/// A split model's exchange of item records; none for a model without a halo (a deformable
/// body, which exchanges block sums only).
type Ghosts = Option<GhostTable>;

impl ParallelRuntime {
    fn local(&self) -> Option<&LocalParticles> {
        self.ranks.as_ref().and_then(|r| r.local.as_ref())
    }

    /// How the run is decomposed over processes; `None` for a run of one process.
    pub fn decomposition(&self) -> Option<&RankFigures> {
        self.ranks.as_ref().map(|r| &r.figures)
    }

    /// This process's rank (0 in a run of one process).
    pub fn rank(&self) -> usize {
        self.ranks.as_ref().map_or(0, |r| r.comm.rank())
    }

    /// The smallest of the ranks' `value`s, on every rank (`value` in a run of one process):
    /// a collective, which every rank calls at the same point of the run.
    pub(crate) fn agree_min(&self, value: u64) -> u64 {
        self.ranks.as_ref().map_or(value, |r| r.comm.min(value))
    }

    /// Every rank's `mine` (of one length on every rank), in rank order (`mine` in a run of
    /// one process): a collective, which every rank calls at the same point of the run.
    pub(crate) fn gather_values(&self, mine: &[f64]) -> Vec<f64> {
        let Some(ranks) = &self.ranks else {
            return mine.to_vec();
        };
        let size = ranks.comm.size();
        let mut all = vec![0.0; mine.len() * size];
        ranks
            .comm
            .all_gather(mine, &mut all, &vec![mine.len(); size]);
        all
    }

    /// How many times the free particles were given new owners.
    pub fn repartitions(&self) -> usize {
        self.ranks.as_ref().map_or(0, |r| r.repartitions)
    }

    /// Decomposes the run over `comm`'s ranks (see [`crate::world::World::decompose`]): a halo
    /// exchange when every model and hook reads only what a rank steps itself and
    /// `steps_in_part` (the stepper can step a rank's particles alone), else every rank
    /// steps every particle and receives the others' after every step.
    pub(crate) fn decompose(
        &mut self,
        state: &mut State,
        models: &mut [Box<dyn Model>],
        hooks: &mut [Box<dyn PostStep>],
        comm: Arc<dyn Communicator>,
        steps_in_part: bool,
    ) -> Result<(), CoreError> {
        let halo_allowed = hooks.iter_mut().all(|h| !matches!(h.reads(), Reads::All));
        let weights = WorkWeights::default();
        let cost = particle_costs(state.len(), split_models(models, hooks, &weights));
        let decomposed = decompose(state, models, comm.clone(), halo_allowed, (&cost, &weights))?;
        let mut ranks = Ranks {
            comm,
            share: decomposed.share,
            figures: decomposed.figures,
            local: decomposed.local,
            tet_work: decomposed.tet_work,
            weights,
            exchanged: vec![0.0; models.len()],
            bodies: decomposed.splits.iter().map(Option::is_some).collect(),
            models: (0..models.len()).map(|_| None).collect(),
            hooks: vec![false; hooks.len()],
            repartitions: 0,
            rebuilds_since: 0,
            mine: Vec::new(),
            all: Vec::new(),
        };
        ranks.split_bodies(models, decomposed.splits);
        if ranks.local.is_some() && !steps_in_part {
            ranks.step_whole(&mut [], &mut []);
        }
        if ranks.local.is_some() {
            ranks.split_by_owners(models, hooks);
        }
        self.ranks = Some(ranks);
        Ok(())
    }

    /// A new stepper that cannot step a rank's particles alone: every step shares the whole
    /// state from now on (after a whole gather, and with the split models whole again).
    pub(crate) fn restepped(
        &mut self,
        steps_in_part: bool,
        state: &mut State,
        models: &mut [Box<dyn Model>],
        hooks: &mut [Box<dyn PostStep>],
        torques: &mut [Vec3],
    ) {
        if let Some(ranks) = &mut self.ranks {
            if ranks.local.is_some() && !steps_in_part {
                ranks.gather(state, models, torques);
                ranks.step_whole(models, hooks);
            }
        }
    }

    /// Makes the state and the split models whole on every rank, as one process holds them
    /// (see [`crate::world::World::gather`]); a no-op in a run of one process.
    pub(crate) fn gather(
        &mut self,
        state: &mut State,
        models: &mut [Box<dyn Model>],
        torques: &mut [Vec3],
    ) {
        if let Some(ranks) = &mut self.ranks {
            ranks.gather(state, models, torques);
        }
    }

    /// Makes the stepper's per-particle `forces` whole on every rank (see
    /// [`crate::world::World::gather_forces`]).
    pub(crate) fn gather_forces(&mut self, forces: &mut [Vec3]) {
        if let Some(ranks) = &mut self.ranks {
            ranks.share.gather_vectors(forces);
        }
    }

    /// Makes `particles`' motion whole on every rank (see [`crate::world::World::gather_particles`]).
    pub(crate) fn gather_particles(&mut self, state: &mut State, particles: &[usize]) {
        if let Some(ranks) = &mut self.ranks {
            ranks.share.gather_some(state, particles);
        }
    }

    /// After the stepper's initialisation with outcome `done`: the decomposed state made
    /// whole on every rank, and the ranks agreed on a failure.
    pub(crate) fn initialized(
        &mut self,
        state: &mut State,
        torques: &mut [Vec3],
        done: Result<(), CoreError>,
    ) -> Result<(), CoreError> {
        let Some(ranks) = &mut self.ranks else {
            return done;
        };
        // The waits of the steps only, as the stage clock counts them (the initial
        // evaluation's, with the first build of the lists, are not a step's).
        ranks.exchanged.fill(0.0);
        ranks.share.share(state);
        ranks.share.gather(state, torques);
        match ranks.share.agree(done.err().map(|e| e.to_string())) {
            Some(failure) => Err(CoreError::Decomposition(failure)),
            None => Ok(()),
        }
    }

    /// The failure every rank reports: the one of the lowest rank that found one (`local`
    /// itself in a run of one process).
    pub(crate) fn agree(&self, local: Option<String>) -> Option<String> {
        match &self.ranks {
            Some(ranks) => ranks.share.agree(local),
            None => local,
        }
    }

    /// The kinetic energy of the whole state (J), the same on every rank.
    pub(crate) fn kinetic_energy(&self, state: &State) -> f64 {
        match &self.ranks {
            Some(ranks) => ranks.share.kinetic_energy(state),
            None => state.kinetic_energy(),
        }
    }

    /// Runs post-step hook `i`: a split hook decides for its own particles, and every rank
    /// acts on every rank's decisions.
    pub(crate) fn after_step(
        &mut self,
        i: usize,
        hook: &mut dyn PostStep,
        state: &mut State,
        models: &[Box<dyn Model>],
    ) -> Option<Halt> {
        let Some(ranks) = self.ranks.as_mut().filter(|r| r.hooks[i]) else {
            return hook.after_step(state, models);
        };
        let decisions = match hook.reads() {
            Reads::Split(facets) => facets.decisions(),
            _ => None,
        };
        let decisions = decisions.expect("a split hook decides");
        ranks.mine.clear();
        decisions.decide(state, &mut ranks.mine);
        ranks.comm.all_gather_varying(&ranks.mine, &mut ranks.all);
        decisions.act(state, &ranks.all);
        None
    }

    /// Whether a step ends with [`ParallelRuntime::rebalance`] (a run decomposed with a halo
    /// exchange).
    pub(crate) fn rebalances(&self) -> bool {
        self.ranks.as_ref().is_some_and(|r| r.local.is_some())
    }

    /// The ranks of a run decomposed with a halo exchange, the only one that re-partitions.
    fn halo_ranks(&mut self) -> Option<&mut Ranks> {
        self.ranks.as_mut().filter(|r| r.local.is_some())
    }

    /// After a step: re-partitions when a split model rebuilt its lists and the ranks' work
    /// is out of balance ([`crate::world::World::repartition`]).
    pub(crate) fn rebalance(
        &mut self,
        state: &mut State,
        models: &mut [Box<dyn Model>],
        hooks: &mut [Box<dyn PostStep>],
        torques: &mut [Vec3],
    ) {
        let Some(ranks) = self.halo_ranks() else {
            return;
        };
        let mut rebuilt = false;
        let computed = ranks.local.as_ref().map_or(0, |l| l.computed.len());
        let weights = &ranks.weights;
        let tets = ranks.tet_work.iter().enumerate();
        let mut work = computed as f64 + tets.map(|(m, w)| weights.of(m) * w).sum::<f64>();
        for (weight, balance) in balances(models, hooks, &ranks.models, &ranks.hooks, weights) {
            rebuilt |= balance.rebuilt();
            work += weight * balance.work();
        }
        if !rebuilt {
            return;
        }
        ranks.rebuilds_since += 1;
        if ranks.repartitions > 0 && ranks.rebuilds_since < REPARTITION_REBUILDS {
            return;
        }
        let works = ranks.comm.all_gather_one(work);
        let mean = works.iter().sum::<f64>() / works.len() as f64;
        let busiest = works.iter().cloned().fold(0.0, f64::max);
        if busiest > REPARTITION_IMBALANCE * mean {
            self.repartition(state, models, hooks, torques);
        }
    }

    /// On a rank of a run decomposed with a halo exchange: per model, the work this rank
    /// was given in the fixed shares (its tetrahedra; a split model's items at its last
    /// evaluation, [`Balance::work`]) and the seconds its evaluations spent in collectives,
    /// and the particles it integrates (its own and those every rank computes); `None`
    /// otherwise.
    pub(crate) fn rank_work(
        &mut self,
        models: &mut [Box<dyn Model>],
    ) -> Option<(Vec<f64>, Vec<f64>, usize)> {
        let ranks = self.halo_ranks()?;
        let mut work = ranks.tet_work.clone();
        for (i, model) in models.iter_mut().enumerate() {
            let balance = split_facets(model.as_mut()).and_then(|f| f.balance());
            if let Some(balance) = balance.filter(|_| ranks.models[i].is_some()) {
                work[i] += balance.work();
            }
        }
        let computed = ranks.local.as_ref().map_or(0, |l| l.computed.len());
        Some((work, ranks.exchanged.clone(), computed))
    }

    /// Weighs each model's items by `weights` in the re-partitions from now on (a no-op in
    /// a run of one process).
    pub(crate) fn set_weights(&mut self, weights: WorkWeights) {
        if let Some(ranks) = &mut self.ranks {
            ranks.weights = weights;
        }
    }

    /// The seconds model `model`'s evaluations spent in collectives on this rank (see
    /// [`crate::world::World::waited_seconds`]).
    pub(crate) fn waited_seconds(&self, model: usize) -> f64 {
        let waited = self.ranks.as_ref().and_then(|r| r.exchanged.get(model));
        waited.copied().unwrap_or(0.0)
    }

    /// The weights of the models' items in the cut: their fixed shares (all 1) until set;
    /// `None` in a run of one process.
    pub(crate) fn weights(&self) -> Option<&WorkWeights> {
        self.ranks.as_ref().map(|r| &r.weights)
    }

    /// Decomposes the run again by the work of its items now (see
    /// [`crate::world::World::repartition`]); a no-op unless the run shares only the halo.
    pub(crate) fn repartition(
        &mut self,
        state: &mut State,
        models: &mut [Box<dyn Model>],
        hooks: &mut [Box<dyn PostStep>],
        torques: &mut [Vec3],
    ) {
        let Some(ranks) = self.halo_ranks() else {
            return;
        };
        ranks.gather(state, models, torques);
        let weights = &ranks.weights;
        let cost = particle_costs(state.len(), split_models(models, hooks, weights));
        let decomposed = decompose(state, models, ranks.comm.clone(), true, (&cost, weights))
            .expect("the bodies decomposed once decompose again");
        let Decomposed {
            share,
            figures,
            local,
            splits,
            tet_work,
        } = decomposed;
        ranks.share = share;
        ranks.figures = figures;
        ranks.local = local;
        ranks.tet_work = tet_work;
        ranks.split_bodies(models, splits);
        ranks.split_by_owners(models, hooks);
        ranks.repartitions += 1;
        ranks.rebuilds_since = 0;
    }
}

/// The runtime is a stepper's seam: in a run of one process it evaluates every model whole;
/// on a rank of a decomposed run each split model stage by stage, with the ranks' exchanges in
/// between.
impl Seam for ParallelRuntime {
    /// Every model's forces in model order, a split model's through its facets on a rank of
    /// a decomposed run, each marked as its own stage; then the forces on members of rigid
    /// bodies moved onto their bodies.
    fn add_forces(
        &mut self,
        state: &State,
        models: &mut [Box<dyn Model>],
        force: &mut [Vec3],
        torque: &mut [Vec3],
        stages: &mut StageTimes,
    ) {
        let mut ranks = self.ranks.as_mut();
        add_model_forces(
            state,
            models,
            force,
            torque,
            stages,
            |i, model, f, t| match ranks.as_mut().filter(|r| r.models[i].is_some()) {
                Some(ranks) => {
                    let facets = split_facets(model).expect("a split model");
                    ranks.evaluate(i, facets, state, f, t);
                }
                None => model.add_forces(state, f, t),
            },
        );
    }

    /// In a run decomposed with a halo exchange, the particles a stepper predicts (its own and
    /// its halo); `None`: every particle.
    fn stepped(&self) -> Option<&ParticleRuns> {
        self.local().map(|l| &l.stepped)
    }

    /// In a run decomposed with a halo exchange, the particles a stepper integrates (those
    /// whose forces this rank sums); `None`: every particle.
    fn computed(&self) -> Option<&ParticleRuns> {
        self.local().map(|l| &l.computed)
    }

    /// Ends an integration whose outcome is `outcome`: in a decomposed run, copies each
    /// rank's owned particles' new motion to the ranks that read it (marked as the share
    /// stage), and with `agree` (a stepper that reads the outcome before the step ends: the
    /// sub-steps of an adaptive step) makes every rank go on with the same outcome: its own
    /// when no rank failed or it failed itself, the failure of the lowest failing rank
    /// otherwise. A run of one process goes on with `outcome`.
    fn complete(
        &mut self,
        state: &mut State,
        stages: &mut StageTimes,
        outcome: Result<(), CoreError>,
        agree: bool,
    ) -> Result<(), CoreError> {
        let Some(ranks) = &mut self.ranks else {
            return outcome;
        };
        ranks.share.share(state);
        stages.mark(Stage::Share);
        if !agree {
            return outcome;
        }
        let local = outcome.as_ref().err().map(|e| e.to_string());
        match (ranks.share.agree(local), outcome) {
            (None, _) => Ok(()),
            (Some(_), Err(own)) => Err(own),
            (Some(failure), Ok(())) => Err(CoreError::Decomposition(failure)),
        }
    }
}

impl Ranks {
    /// Hands each deformable body its blocks for this rank (`splits`, per model).
    fn split_bodies(&mut self, models: &mut [Box<dyn Model>], splits: Vec<Option<BodySplit>>) {
        let me = self.comm.rank() as u32;
        for ((model, body), slot) in models.iter_mut().zip(splits).zip(&mut self.models) {
            if let Some(body) = body {
                let facets = split_facets(model.as_mut()).expect("a deformable body splits");
                facets.split(Some(Part {
                    owner: Arc::from([]),
                    rank: me,
                    body: Some(body),
                }));
                *slot = Some(None);
            }
        }
    }

    /// One force evaluation of split model `i` (its `facets`), its stages with the
    /// collectives in between ([`crate::step::split`]).
    fn evaluate(
        &mut self,
        i: usize,
        facets: &mut dyn Facets,
        state: &State,
        force: &mut [Vec3],
        torque: &mut [Vec3],
    ) {
        let comm = self.comm.as_ref();
        let ghosts = self.models[i].as_mut().expect("a split model");
        let mut waited = 0.0;
        let rebuild = facets.lists().is_some_and(|lists| {
            let moved = timed(&mut waited, || max_over_ranks(comm, lists.moved(state)));
            lists.needs_rebuild(moved, state.time)
        });
        if rebuild {
            let table = ghosts
                .as_mut()
                .expect("a split model with lists has a ghost table");
            let halo = facets.halo().expect("a split model with lists has a halo");
            timed(&mut waited, || table.borders(comm, halo));
            facets.lists().expect("checked above").rebuild(state.time);
        }
        if let Some(halo) = facets.halo() {
            let table = ghosts
                .as_mut()
                .expect("a split model with a halo has a ghost table");
            if let Some(wanted) = halo.new_ghosts() {
                timed(&mut waited, || table.set_ghosts(comm, &wanted));
            }
            halo.read_partners(state);
            timed(&mut waited, || table.forward(comm, halo));
        }
        if let Some(averaging) = facets.averaging() {
            averaging.partial(state);
            if let Some(sums) = averaging.partial_sums() {
                timed(&mut waited, || sums.plan.run(comm, sums.sums));
            }
            averaging.average();
            if let Some(nodal) = averaging.averages() {
                timed(&mut waited, || {
                    nodal
                        .plan
                        .run_forward(comm, nodal.nodes, nodal.first, nodal.values)
                });
            }
        }
        let evaluation = facets.evaluation().expect("a split model evaluates");
        evaluation.compute(state);
        if let Some(reduction) = facets.reduction() {
            self.mine.clear();
            if reduction.mine(&mut self.mine) {
                let (mine, all) = (&self.mine, &mut self.all);
                timed(&mut waited, || comm.all_gather_varying(mine, all));
                reduction.reduced(state.time, &self.all);
            }
        }
        if let Some(sums) = facets.reverse_sums() {
            timed(&mut waited, || sums.plan.run(comm, sums.sums));
        }
        let evaluation = facets.evaluation().expect("a split model evaluates");
        evaluation.apply(force, torque);
        self.exchanged[i] += waited;
    }

    /// Splits the models and hooks that a rank computes in part by the share's owners (the
    /// deformable bodies keep their blocks).
    fn split_by_owners(&mut self, models: &mut [Box<dyn Model>], hooks: &mut [Box<dyn PostStep>]) {
        let owner: Arc<[u32]> = self.share.owner().into();
        let (me, size) = (self.comm.rank(), self.comm.size());
        let part = || {
            Some(Part {
                owner: owner.clone(),
                rank: me as u32,
                body: None,
            })
        };
        for (i, model) in models.iter_mut().enumerate() {
            if self.bodies[i] {
                continue;
            }
            let Reads::Split(facets) = model.reads() else {
                continue;
            };
            // A table even without items: every rank runs the same exchanges whatever it
            // holds (an empty contact set still takes part in the max and the forward).
            let table = facets.halo().map(|halo| {
                let item_owner = halo.items().iter().map(|&p| owner[p]).collect();
                GhostTable::new(item_owner, me, size)
            });
            facets.split(part());
            self.models[i] = Some(table);
        }
        for (i, hook) in hooks.iter_mut().enumerate() {
            if let Reads::Split(facets) = hook.reads() {
                facets.split(part());
                self.hooks[i] = true;
            }
        }
    }

    /// Every step shares the whole state from now on, the split models (but the deformable
    /// bodies) whole again.
    fn step_whole(&mut self, models: &mut [Box<dyn Model>], hooks: &mut [Box<dyn PostStep>]) {
        for (i, model) in models.iter_mut().enumerate() {
            if self.models[i].is_some() && !self.bodies[i] {
                if let Reads::Split(facets) = model.reads() {
                    facets.split(None);
                }
                self.models[i] = None;
            }
        }
        for (i, hook) in hooks.iter_mut().enumerate() {
            if self.hooks[i] {
                if let Reads::Split(facets) = hook.reads() {
                    facets.split(None);
                }
                self.hooks[i] = false;
            }
        }
        self.share.share_whole_every_step(&mut self.figures);
        self.local = None;
    }

    /// The whole state on every rank, and every split model merged.
    fn gather(&mut self, state: &mut State, models: &mut [Box<dyn Model>], torques: &mut [Vec3]) {
        self.share.gather(state, torques);
        if self.local.is_none() {
            return;
        }
        let comm = self.comm.as_ref();
        for (i, model) in models.iter_mut().enumerate() {
            let Some(Some(table)) = self.models[i].as_mut() else {
                continue;
            };
            let Reads::Split(facets) = model.reads() else {
                continue;
            };
            self.mine.clear();
            let mine = &mut self.mine;
            if facets.merge().is_some_and(|merge| merge.records(mine)) {
                comm.all_gather_varying(&self.mine, &mut self.all);
                table.borders(comm, facets.halo().expect("a merged model has a halo"));
                facets.merge().expect("checked above").merge(&self.all);
            }
        }
    }
}

/// The facets of a split model.
fn split_facets(model: &mut dyn Model) -> Option<&mut dyn Facets> {
    match model.reads() {
        Reads::Split(facets) => Some(facets),
        _ => None,
    }
}

/// Runs `f`, adding its wall seconds to `waited`.
fn timed<R>(waited: &mut f64, f: impl FnOnce() -> R) -> R {
    let start = std::time::Instant::now();
    let result = f();
    *waited += start.elapsed().as_secs_f64();
    result
}

/// The balance facets of the models and hooks that are split, models first, each with its
/// weight in `weights` (a hook's: 1).
fn balances<'a>(
    models: &'a mut [Box<dyn Model>],
    hooks: &'a mut [Box<dyn PostStep>],
    split_models: &'a [Option<Ghosts>],
    split_hooks: &'a [bool],
    weights: &'a WorkWeights,
) -> impl Iterator<Item = (f64, &'a mut dyn Balance)> {
    let models = models
        .iter_mut()
        .zip(split_models)
        .enumerate()
        .filter(|(_, (_, s))| s.is_some())
        .filter_map(|(i, (m, _))| split_facets(m.as_mut()).map(|f| (weights.of(i), f)));
    let hooks = hooks
        .iter_mut()
        .zip(split_hooks)
        .filter(|(_, &s)| s)
        .filter_map(|(h, _)| match h.reads() {
            Reads::Split(facets) => Some((1.0, facets)),
            _ => None,
        });
    models
        .chain(hooks)
        .filter_map(|(w, facets)| facets.balance().map(|b| (w, b)))
}

/// The facets of every split model and hook, models first, whether or not this rank computes
/// it in part yet, each with its weight in `weights` (a hook's: 1).
fn split_models<'a>(
    models: &'a mut [Box<dyn Model>],
    hooks: &'a mut [Box<dyn PostStep>],
    weights: &'a WorkWeights,
) -> impl Iterator<Item = (f64, &'a mut dyn Facets)> {
    let models = models
        .iter_mut()
        .enumerate()
        .filter_map(|(i, m)| split_facets(m.as_mut()).map(|f| (weights.of(i), f)));
    let hooks = hooks.iter_mut().filter_map(|h| match h.reads() {
        Reads::Split(facets) => Some((1.0, facets)),
        _ => None,
    });
    models.chain(hooks)
}
