//! [`World`]: a [`State`], its models, its stepper and its post-step hooks, stepped as named,
//! timed stages — exactly what `qdem run` does, for whoever embeds the crates.
//!
//! One [`World::step`] runs, in this order:
//! 1. **predict**, **forces** of each model, **integrate** (and **solve**, **events** for
//!    Newmark-β): the stepper ([`crate::Verlet`], [`crate::Newmark`],
//!    [`crate::StaticSteps`]) marks each stage as it goes;
//! 2. the **failure check**: a non-finite acceleration, a model's
//!    [`Model::failure`] (an inverted tetrahedron) or a kinetic energy growing like an
//!    unstable step's ([`crate::instability::EnergyGrowth`]) stops the run with
//!    [`CoreError::Unstable`], which names the stable bound at that state;
//!    In a run decomposed over processes ([`World::decompose`]), the **share** of each rank's
//!    owned particles comes first, and the ranks agree on the failure;
//! 3. the **post-step hooks** ([`PostStep`]) in the order they were added: periodic wrapping
//!    of bodies, a bonded body's collapse watch; a hook may [`Halt`] the run.
//!
//! Every stage's wall time accumulates in the world's [`StageTimes`], which `qdem check` and
//! `summary.json` report. The step itself is chosen once, by [`StepSettings::resolve`], and
//! the models learn how they are stepped from [`Model::prepare`].

use crate::checkpoint::{CheckpointError, Decoder, Encoder};
use crate::distributed::{decompose, Communicator, Decomposition, Partition};
use crate::error::CoreError;
use crate::instability::{EnergyGrowth, GROWTH_PER_STEP, GROWTH_STEPS};
use crate::local_particles::LocalParticles;
use crate::model::{find_model, Model, ParticleReads, Persistence, SplitModel};
use crate::stages::{Stage, StageShare, StageTimes};
use crate::state::State;
use crate::state_share::StateShare;
use crate::step_settings::{Scheme, StepSettings};
use crate::stepper::{stable_step, Stepper};
use std::sync::Arc;

/// Something a world does after every step, once the step has passed the failure check:
/// periodic wrapping of bodies, a watch that ends the run when a body has failed.
pub trait PostStep: std::any::Any + Send + Sync {
    /// A short name for the stage counters.
    fn name(&self) -> &str;

    /// Acts on the state after a step; returns a [`Halt`] to end the run after this step.
    fn after_step(&mut self, state: &mut State, models: &[Box<dyn Model>]) -> Option<Halt>;

    /// Which particles' motion the hook reads ([`Model::particle_reads`]); the default,
    /// [`ParticleReads::All`], is always right.
    fn particle_reads(&self) -> ParticleReads {
        ParticleReads::All
    }

    /// The hook's part in a run decomposed with a halo exchange, for a hook that reads only
    /// what a rank owns and shares what it decides ([`Model::split_model`]); `None` (the
    /// default) otherwise.
    fn split_model(&mut self) -> Option<&mut dyn SplitModel> {
        None
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

/// A simulation that steps itself: state, models, stepper, hooks and stage counters.
///
/// ```
/// use qdem_core::{Material, Model, NodalLoad, Scheme, State, StepRequest, StepSettings,
///     TetBody, TimeFunction, Vec3, World};
///
/// // One tetrahedron with three corners held, pulled at the fourth.
/// let nodes = vec![Vec3::zeros(), Vec3::x(), Vec3::y(), Vec3::z()];
/// let mut state = State::at_rest(nodes);
/// let material = Material { density: 1000.0, young: 1e6, poisson: 0.3,
///     shear_viscosity: 0.0, bulk_viscosity: 0.0 };
/// let body = TetBody::new("cube corner", &state.reference, vec![[0, 1, 2, 3]], material)
///     .unwrap();
/// body.lump_mass(&mut state.mass);
/// for p in 0..3 {
///     state.fix(p, qdem_core::Dofs::ALL);
/// }
/// let pull = NodalLoad::new("pull", vec![3], Vec3::new(0.0, 0.0, 10.0),
///     TimeFunction::constant(1.0));
/// let models: Vec<Box<dyn Model>> = vec![Box::new(body), Box::new(pull)];
/// let request = StepRequest { scheme: Scheme::Verlet, dt: None, safety: 0.5,
///     local_damping: 0.0, adaptive: false, event_solve: Default::default(),
///     implicit_default: None, fit_to: None };
/// let settings = StepSettings::resolve(&request, &state, &models).unwrap();
/// let mut world = World::new(state, models, settings).unwrap();
/// world.initialize().unwrap();
/// for _ in 0..100 {
///     world.step().unwrap();
/// }
/// assert!(world.state.displacement(3).z > 0.0);
/// assert_eq!(world.stages().steps(), 100);
/// ```
pub struct World {
    /// The degrees of freedom of every particle and rigid body.
    pub state: State,
    /// The force models, in the order their forces are summed. Give them to [`World::new`]:
    /// one pushed here later is not told how it is stepped ([`Model::prepare`]) and has no
    /// stage counter of its own.
    pub models: Vec<Box<dyn Model>>,
    stepper: Box<dyn Stepper>,
    hooks: Vec<Box<dyn PostStep>>,
    settings: StepSettings,
    stages: StageTimes,
    energy: EnergyGrowth,
    steps_done: u64,
    share: Option<(StateShare, Decomposition)>,
    /// The particles this rank steps, when a step shares only the halo.
    local: Option<Arc<LocalParticles>>,
    /// What a re-partition keeps, when a step shares only the halo.
    partition: Option<Partition>,
    /// Re-partitions so far, and rebuilds of a split model's lists since the last one.
    repartitions: usize,
    rebuilds_since: usize,
}

/// The ratio of the busiest rank's work to the mean above which a rebuild of a split
/// model's lists re-partitions the free particles ([`World::repartition`]).
const REPARTITION_IMBALANCE: f64 = 1.1;

/// Rebuilds between two re-partitions at least: a re-partition gathers the whole state, and
/// an imbalance it cannot mend (one body heavier than a rank's share) must not make every
/// rebuild pay for it.
const REPARTITION_REBUILDS: usize = 8;

impl World {
    /// A world stepping `state` under `models` as `settings` say; tells every model how it is
    /// stepped ([`Model::prepare`]). Call [`World::initialize`] (or [`World::restore`])
    /// before the first step.
    pub fn new(
        state: State,
        mut models: Vec<Box<dyn Model>>,
        settings: StepSettings,
    ) -> Result<World, CoreError> {
        let stepper = settings.stepper()?;
        prepare(&mut models, &settings);
        let stages = StageTimes::new(models.len(), 0);
        Ok(World {
            state,
            models,
            stepper,
            hooks: Vec::new(),
            settings,
            stages,
            energy: EnergyGrowth::new(),
            steps_done: 0,
            share: None,
            local: None,
            partition: None,
            repartitions: 0,
            rebuilds_since: 0,
        })
    }

    /// Steps with `settings` from now on: a new stepper (call [`World::initialize`] before
    /// the next step), the models told again. No bound is checked: a step chosen here is the
    /// caller's responsibility (the failure check still catches an unstable one).
    pub fn set_settings(&mut self, settings: StepSettings) -> Result<(), CoreError> {
        self.stepper = settings.stepper()?;
        prepare(&mut self.models, &settings);
        self.settings = settings;
        self.restrict_stepper();
        Ok(())
    }

    /// In halo mode, has the stepper step only this rank's particles, or, if it cannot, makes
    /// every step share the whole state (after a whole gather: the stale particles are
    /// brought up to date first).
    fn restrict_stepper(&mut self) {
        let (Some(local), Some((share, figures))) = (&self.local, &mut self.share) else {
            return;
        };
        if !self.stepper.restrict(local.clone()) {
            share.gather(&mut self.state, self.stepper.rigid_torques());
            for part in split_parts(&mut self.models, &mut self.hooks) {
                part.gather();
                part.split(None);
            }
            share.share_whole_every_step(figures);
            self.local = None;
            self.partition = None;
        }
    }

    /// Adds a post-step hook, run after the hooks added before it; the stage counters start
    /// again (add hooks before stepping).
    pub fn add_hook(&mut self, hook: Box<dyn PostStep>) {
        self.hooks.push(hook);
        self.stages = StageTimes::new(self.models.len(), self.hooks.len());
    }

    /// The stepping the world was built with.
    pub fn settings(&self) -> &StepSettings {
        &self.settings
    }

    /// The step (s).
    pub fn dt(&self) -> f64 {
        self.settings.dt
    }

    /// The stepper, for its name, counts and factorisation statistics.
    pub fn stepper(&self) -> &dyn Stepper {
        self.stepper.as_ref()
    }

    /// The stage counters of the steps taken since the world was made.
    pub fn stages(&self) -> &StageTimes {
        &self.stages
    }

    /// The stage counters as named shares of the step.
    pub fn stage_report(&self) -> Vec<StageShare> {
        let models: Vec<&str> = self.models.iter().map(|m| m.name()).collect();
        let hooks: Vec<&str> = self.hooks.iter().map(|h| h.name()).collect();
        self.stages.report(&models, &hooks)
    }

    /// Steps taken (counting those before a checkpoint the world was restored from).
    pub fn steps_done(&self) -> u64 {
        self.steps_done
    }

    /// The first model of type `M`, if any.
    pub fn model<M: Model>(&self) -> Option<&M> {
        find_model(&self.models)
    }

    /// The first post-step hook of type `H`, if any.
    pub fn hook<H: PostStep>(&self) -> Option<&H> {
        self.hooks.iter().find_map(|h| {
            let h: &dyn std::any::Any = h.as_ref();
            h.downcast_ref::<H>()
        })
    }

    /// Decomposes the run over `comm`'s ranks ([`crate::distributed`]): from now on this
    /// process computes its share of the deformable bodies and every step ends with the
    /// exchange of the particles each rank owns (after each sub-step of an adaptive explicit
    /// Newmark step too). When every model and hook reads only what a rank steps itself
    /// ([`ParticleReads::Local`]) and the stepper can be restricted (Verlet), a rank steps
    /// only its own particles and its halo, and receives only its halo, and a split model
    /// ([`crate::SplitModel`], DEM contacts) computes only what touches its particles: call
    /// [`World::gather`] before reading the whole state. Otherwise every rank holds the state
    /// one process would after every step. Call it on every rank, before
    /// [`World::initialize`] or [`World::restore`]. Only explicit runs (Verlet, explicit
    /// Newmark) can be decomposed.
    pub fn decompose(&mut self, comm: Arc<dyn Communicator>) -> Result<Decomposition, CoreError> {
        if self.settings.scheme.is_implicit() {
            return Err(CoreError::Decomposition(format!(
                "only explicit runs (Verlet, explicit Newmark) can be decomposed, and this one is \
                 stepped by {}; run it as one process (without mpirun)",
                self.stepper.name()
            )));
        }
        let halo_allowed = self
            .hooks
            .iter()
            .all(|h| h.particle_reads() == ParticleReads::Local);
        let (share, figures, halo) =
            decompose(&self.state, &mut self.models, comm.clone(), halo_allowed)?;
        self.share = Some((share, figures));
        let (local, partition) = halo.unzip();
        self.local = local.map(Arc::new);
        self.partition = partition;
        self.restrict_stepper();
        if self.local.is_some() {
            self.split_by_owners(comm);
        }
        Ok(self.decomposition().expect("decomposed").clone())
    }

    /// Splits the models and hooks that a rank computes in part by the share's owners.
    fn split_by_owners(&mut self, comm: Arc<dyn Communicator>) {
        let (share, _) = self.share.as_ref().expect("decomposed");
        let owner: Arc<[u32]> = share.owner().into();
        for part in split_parts(&mut self.models, &mut self.hooks) {
            part.split(Some((owner.clone(), comm.clone())));
        }
    }

    /// Gives the particles no deformable body holds (grains, rigid bodies) new owners, in
    /// runs of particle order of about equal measured work (each particle's step, and its
    /// share of the split models' work, [`SplitModel::add_costs`]): a collective, which
    /// every rank calls after the same step, in a run decomposed with a halo exchange (a
    /// no-op otherwise). The state and the split models are gathered first and split again
    /// by the new owners, so the run goes on bit for bit as before. A step calls it at a
    /// rebuild of a split model's lists when the busiest rank has more than 1.1 times the
    /// mean work (at most once every 8 rebuilds).
    pub fn repartition(&mut self) {
        if self.partition.is_none() {
            return;
        }
        self.gather();
        let mut cost = vec![1.0; self.state.len()];
        for part in split_parts(&mut self.models, &mut self.hooks) {
            part.add_costs(&mut cost);
        }
        let partition = self.partition.as_ref().expect("checked above");
        let (share, owned, local) = partition.assign(&self.state, &mut self.models, Some(&cost));
        let comm = partition.comm.clone();
        let (_, mut figures) = self.share.take().expect("decomposed");
        figures.owned = owned;
        self.share = Some((share, figures));
        self.local = Some(Arc::new(local));
        self.restrict_stepper();
        self.split_by_owners(comm);
        self.repartitions += 1;
        self.rebuilds_since = 0;
    }

    /// How many times [`World::repartition`] has run.
    pub fn repartitions(&self) -> usize {
        self.repartitions
    }

    /// After a step: re-partitions when a split model rebuilt its lists and the ranks' work
    /// is out of balance ([`World::repartition`]).
    fn rebalance(&mut self) {
        let Some(partition) = &self.partition else {
            return;
        };
        let mut rebuilt = false;
        let mut work = self.local.as_ref().map_or(0, |l| l.computed.len()) as f64;
        for part in split_parts(&mut self.models, &mut self.hooks) {
            rebuilt |= part.rebuilt();
            work += part.work();
        }
        if !rebuilt {
            return;
        }
        self.rebuilds_since += 1;
        if self.repartitions > 0 && self.rebuilds_since < REPARTITION_REBUILDS {
            return;
        }
        let works = partition.comm.all_gather_one(work);
        let mean = works.iter().sum::<f64>() / works.len() as f64;
        let busiest = works.iter().cloned().fold(0.0, f64::max);
        if busiest > REPARTITION_IMBALANCE * mean {
            self.repartition();
        }
    }

    /// Makes the state whole on every rank of a decomposed run, as one process holds it: a
    /// collective, which every rank calls after the same step. Needed before reading any
    /// particle's motion when a step shares only the halo ([`World::decompose`]); a no-op
    /// otherwise (and in a run of one process).
    pub fn gather(&mut self) {
        if let Some((share, _)) = &mut self.share {
            share.gather(&mut self.state, self.stepper.rigid_torques());
        }
        if self.local.is_some() {
            for part in split_parts(&mut self.models, &mut self.hooks) {
                part.gather();
            }
        }
    }

    /// [`World::gather`] of `particles` only (the probes' particles): every rank calls it
    /// after the same step with the same list, and then holds their position, velocity and
    /// acceleration as one process would.
    pub fn gather_particles(&mut self, particles: &[usize]) {
        if let Some((share, _)) = &mut self.share {
            share.gather_some(&mut self.state, particles);
        }
    }

    /// How the run is decomposed over processes; `None` for a run of one process.
    pub fn decomposition(&self) -> Option<&Decomposition> {
        self.share.as_ref().map(|(_, d)| d)
    }

    /// Makes the accelerations consistent with the forces at the start (and factorises, for
    /// an implicit scheme).
    pub fn initialize(&mut self) -> Result<(), CoreError> {
        let done = self.stepper.initialize(&mut self.state, &mut self.models);
        let Some((share, _)) = &mut self.share else {
            return done;
        };
        share.share(&mut self.state);
        share.gather(&mut self.state, self.stepper.rigid_torques());
        match share.agree(done.err().map(|e| e.to_string())) {
            Some(failure) => Err(CoreError::Decomposition(failure)),
            None => Ok(()),
        }
    }

    /// Advances one step through every stage; `Ok(Some(halt))` when a hook ends the run.
    pub fn step(&mut self) -> Result<Option<Halt>, CoreError> {
        self.stages.begin_step();
        let (state, models, stages) = (&mut self.state, &mut self.models, &mut self.stages);
        let stepped = match &mut self.share {
            None => self.stepper.step_timed(state, models, stages),
            Some((share, _)) => {
                // Verlet integrates once per step: [`World::check`] agrees on its outcome, and
                // a second agreement per step would cost 2% on small bodies (measured).
                let substeps = self.settings.scheme != Scheme::Verlet;
                let mut complete = |state: &mut State, stages: &mut StageTimes, advanced| {
                    share.share(state);
                    stages.mark(Stage::Share);
                    match substeps {
                        true => agreed(share, advanced),
                        false => advanced,
                    }
                };
                self.stepper
                    .step_completed(state, models, stages, &mut complete)
            }
        };
        self.steps_done += 1;
        let checked = self.check(stepped);
        self.stages.mark(Stage::Check);
        checked?;
        let mut halt = None;
        for (i, hook) in self.hooks.iter_mut().enumerate() {
            if let Some(h) = hook.after_step(&mut self.state, &self.models) {
                halt.get_or_insert(h);
            }
            self.stages.mark(Stage::Hook(i));
        }
        if self.partition.is_some() {
            self.rebalance();
            self.stages.mark(Stage::Share);
        }
        Ok(halt)
    }

    /// The failure check after a step: a non-finite acceleration, a model's failure or
    /// runaway kinetic energy becomes [`CoreError::Unstable`]; other stepper errors pass (in
    /// a decomposed run they too become the failure every rank agrees on).
    fn check(&mut self, stepped: Result<(), CoreError>) -> Result<(), CoreError> {
        let local = match stepped {
            Err(CoreError::NonFinite { particle, .. }) => {
                Some(format!("particle {particle} has a non-finite acceleration"))
            }
            Err(source) if self.share.is_none() => return Err(source),
            Err(source) => Some(source.to_string()),
            Ok(()) => self
                .models
                .iter()
                .find_map(|m| m.failure(&self.state))
                .map(|e| e.to_string()),
        };
        let failure = match &self.share {
            Some((share, _)) => share.agree(local),
            None => local,
        };
        let kinetic = match &self.share {
            Some((share, _)) => share.kinetic_energy(&self.state),
            None => self.state.kinetic_energy(),
        };
        let failure = failure.or_else(|| {
            self.energy.observe(kinetic).map(|growth| {
                format!(
                    "the kinetic energy grew by more than {:.0}% at each of the last \
                         {GROWTH_STEPS} steps (x{growth:.2e} in all), the signature of an \
                         unstable step",
                    100.0 * (GROWTH_PER_STEP - 1.0)
                )
            })
        });
        let Some(detail) = failure else {
            return Ok(());
        };
        self.gather();
        let (bound, limiter) = stable_step(&self.state, &self.models)
            .unwrap_or((f64::INFINITY, "nothing".to_string()));
        Err(CoreError::Unstable {
            step: self.steps_done,
            time: self.state.time,
            detail,
            dt: self.settings.dt,
            bound,
            limiter,
        })
    }

    /// Whether the world can be checkpointed, or the first model or the stepper that cannot.
    pub fn checkpointable(&self) -> Result<(), CheckpointError> {
        let unsupported = self
            .models
            .iter()
            .find(|m| matches!(m.persistence(), Persistence::Unsupported));
        if let Some(m) = unsupported {
            return Err(CheckpointError::Unsupported {
                what: format!("model `{}`", m.name()),
            });
        }
        self.stepper.save(&mut Encoder::new())
    }

    /// Writes the state, every model's history and the stepper's into a checkpoint.
    pub fn save(&self, out: &mut Encoder) -> Result<(), CheckpointError> {
        self.state.save(out);
        for m in &self.models {
            out.tag(&format!("model {}", m.name()));
            if let Persistence::Saved(history) = m.persistence() {
                history.save(out);
            }
        }
        self.stepper.save(out)
    }

    /// Instead of [`World::initialize`]: reads back what [`World::save`] wrote, into a world
    /// built from the same scene, `steps_done` steps into the run; the stepper resumes after
    /// the models (it may refactorise with their restored tangents).
    pub fn restore(&mut self, input: &mut Decoder<'_>, steps_done: u64) -> Result<(), CoreError> {
        self.state.restore(input)?;
        for m in self.models.iter_mut() {
            input.tag(&format!("model {}", m.name()))?;
            if let Some(history) = m.persistent_mut() {
                history.restore(input)?;
            }
        }
        self.stepper
            .resume(&mut self.state, &mut self.models, input)?;
        self.steps_done = steps_done;
        Ok(())
    }
}

/// The split facets of the models and hooks ([`SplitModel`]), models first.
fn split_parts<'a>(
    models: &'a mut [Box<dyn Model>],
    hooks: &'a mut [Box<dyn PostStep>],
) -> impl Iterator<Item = &'a mut dyn SplitModel> {
    let models = models.iter_mut().filter_map(|m| m.split_model());
    models.chain(hooks.iter_mut().filter_map(|h| h.split_model()))
}

/// Tells every model how it is stepped.
fn prepare(models: &mut [Box<dyn Model>], settings: &StepSettings) {
    let stepping = settings.stepping();
    for model in models.iter_mut() {
        model.prepare(&stepping);
    }
}

/// The outcome every rank of a decomposed run goes on with after an integration: its own, when
/// no rank failed or it failed itself; the failure of the lowest failing rank otherwise.
fn agreed(share: &StateShare, advanced: Result<(), CoreError>) -> Result<(), CoreError> {
    let local = advanced.as_ref().err().map(|e| e.to_string());
    match (share.agree(local), advanced) {
        (None, _) => Ok(()),
        (Some(_), Err(own)) => Err(own),
        (Some(failure), Ok(())) => Err(CoreError::Decomposition(failure)),
    }
}
