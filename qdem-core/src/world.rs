//! [`World`]: a [`State`], its models, its stepper and its post-step hooks, stepped as named,
//! timed stages — exactly what `qdem run` does, for whoever embeds the crates.
//!
//! One [`World::step`] runs, in this order:
//! 1. **predict**, **forces** of each model, **integrate** (and **solve**, **events** for
//!    Newmark-β): the stepper ([`crate::solvers::Verlet`], [`crate::solvers::Newmark`],
//!    [`crate::solvers::StaticSteps`]) marks each stage as it goes;
//! 2. the **failure check**: a non-finite acceleration, a model's
//!    [`Model::failure`] (an inverted tetrahedron) or a kinetic energy growing like an
//!    unstable step's ([`crate::step::instability::EnergyGrowth`]) stops the run with
//!    [`CoreError::Unstable`], which names the stable bound at that state, and a contact
//!    sphere through a wall or into a body (the contacts' failure) with
//!    [`CoreError::PassThrough`]; in a run decomposed over processes
//!    ([`World::decompose`]) the ranks agree on it;
//! 3. the **post-step hooks** ([`PostStep`]) in the order they were added: periodic wrapping
//!    of bodies, a bonded body's collapse watch; a hook may [`Halt`] the run.
//!
//! In a run decomposed over processes, every collective runs in the world's
//! [`ParallelRuntime`] ([`crate::parallel`]): the steppers evaluate the forces through it and end
//! each integration with it (the **share** of each rank's new motion), the hooks that decide
//! for their own particles share their decisions through it, and a step ends with its
//! re-partition check; in a run of one process each of these is a plain loop or nothing, so
//! a step has one path either way.
//!
//! Every stage's wall time accumulates in the world's [`StageTimes`], which `qdem check` and
//! `summary.json` report. The step itself is chosen once, by [`StepSettings::resolve`], and
//! the models learn how they are stepped from [`Model::prepare`].

use crate::checkpoint::{model_tag, whole_block, CheckpointError, Decoder, Encoder};
use crate::error::CoreError;
use crate::parallel::{Communicator, ParallelRuntime, RankFigures, WorkWeights};
use crate::solvers::stepper_for::stepper_for;
use crate::step::instability::{EnergyGrowth, GROWTH_PER_STEP, GROWTH_STEPS};
use crate::step::model::{find_model, Model, Persistence};
use crate::step::post_step::{Halt, PostStep};
use crate::step::stages::{Stage, StageShare, StageTimes};
use crate::step::state::State;
use crate::step::step_settings::StepSettings;
use crate::step::stepper::{stable_step, Stepper};
use std::sync::Arc;

/// Marks a model's [`CoreError::PassThrough`] in the text the ranks agree on, so that the
/// failure check reports it as itself rather than as an unstable step; it also separates
/// the report's detail from its fix.
const PASS_THROUGH: &str = "\u{1}pass through\u{1}";

/// What a driver reads of the state after a step ([`World::agree_on_stop`]), which a
/// decomposed run makes whole first; each reads more than the ones before it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Gather {
    /// Nothing.
    Nothing,
    /// Some particles (the probes').
    Particles,
    /// The whole state.
    Whole,
}

/// A simulation that steps itself: state, models, stepper, hooks and stage counters.
///
/// ```
/// use qdem_core::{continuum::Material, step::Model, loads::NodalLoad, step::Scheme, step::State, step::StepRequest, step::StepSettings,
///     continuum::TetBody, loads::TimeFunction, Vec3, world::World};
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
///     state.fix(p, qdem_core::step::Dofs::ALL);
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
    /// The parallel runtime: what a step exchanges between ranks, nothing in a run of one
    /// process.
    parallel: ParallelRuntime,
}

impl World {
    /// A world stepping `state` under `models` as `settings` say; tells every model how it is
    /// stepped ([`Model::prepare`]). Call [`World::initialize`] (or [`World::restore`])
    /// before the first step.
    pub fn new(
        state: State,
        mut models: Vec<Box<dyn Model>>,
        settings: StepSettings,
    ) -> Result<World, CoreError> {
        let stepper = stepper_for(&settings)?;
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
            parallel: ParallelRuntime::default(),
        })
    }

    /// Steps with `settings` from now on: a new stepper (call [`World::initialize`] before
    /// the next step), the models told again. No bound is checked: a step chosen here is the
    /// caller's responsibility (the failure check still catches an unstable one).
    pub fn set_settings(&mut self, settings: StepSettings) -> Result<(), CoreError> {
        self.stepper = stepper_for(&settings)?;
        prepare(&mut self.models, &settings);
        self.settings = settings;
        let steps_in_part = self.stepper.steps_in_part();
        let torques = self.stepper.rigid_torques_mut();
        let (state, models, hooks) = (&mut self.state, &mut self.models, &mut self.hooks);
        self.parallel
            .restepped(steps_in_part, state, models, hooks, torques);
        Ok(())
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

    /// Decomposes the run over `comm`'s ranks ([`crate::parallel`]): from now on this
    /// process computes its share of the deformable bodies and every step ends with the
    /// exchange of the particles each rank owns (after each sub-step of an adaptive explicit
    /// Newmark step too). When every model and hook reads only what a rank steps itself
    /// ([`Reads::Own`] or [`Reads::Split`]) and the stepper can step in part (Verlet), a rank
    /// steps only its own particles and its halo, and receives only its halo, and a split
    /// model ([`crate::step::split::Facets`], DEM contacts) computes only what touches its particles:
    /// call [`World::gather`] before reading the whole state. Otherwise every rank holds the
    /// state one process would after every step. Call it on every rank, before
    /// [`World::initialize`] or [`World::restore`]. Only explicit runs (Verlet, explicit
    /// Newmark) can be decomposed.
    pub fn decompose(&mut self, comm: Arc<dyn Communicator>) -> Result<RankFigures, CoreError> {
        if self.settings.is_implicit() {
            return Err(CoreError::Decomposition(format!(
                "only explicit runs (Verlet, explicit Newmark) can be decomposed, and this one is \
                 stepped by {}; run it as one process (without mpirun)",
                self.stepper.name()
            )));
        }
        if let Some((particle, _, _)) = self.state.frames.iter().next() {
            return Err(CoreError::Decomposition(format!(
                "particle {particle} is held in a local frame (a [[fix]] with `frame`), which \
                 a run over ranks does not support yet; run it as one process (without mpirun), \
                 or hold it on the x, y, z axes"
            )));
        }
        let steps_in_part = self.stepper.steps_in_part();
        let (state, models, hooks) = (&mut self.state, &mut self.models, &mut self.hooks);
        self.parallel
            .decompose(state, models, hooks, comm, steps_in_part)?;
        Ok(self.decomposition().expect("decomposed").clone())
    }

    /// Decomposes the run again by the work of its items now: the deformable bodies' blocks
    /// and the particles no deformable body holds (grains, rigid bodies, in runs of particle
    /// order) cut into ranges of about equal work, each tetrahedron, each particle's step and
    /// its share of the split models' work ([`crate::step::split::Balance::add_costs`]: the
    /// contact spheres and their candidates) counted ([`crate::parallel::decomposition`]): a
    /// collective, which every rank calls after the same step, in a run decomposed with a
    /// halo exchange (a no-op otherwise). The state and the split models are gathered first
    /// and split again by the new owners, so the run goes on bit for bit as before. A step
    /// calls it at a rebuild of a split model's lists when the busiest rank has more than 1.1
    /// times the mean work (at most once every 8 rebuilds).
    pub fn repartition(&mut self) {
        let torques = self.stepper.rigid_torques_mut();
        let (state, models, hooks) = (&mut self.state, &mut self.models, &mut self.hooks);
        self.parallel.repartition(state, models, hooks, torques);
    }

    /// How many times [`World::repartition`] has run.
    pub fn repartitions(&self) -> usize {
        self.parallel.repartitions()
    }

    /// The weight of each model's items in the cut, from what they were measured to cost
    /// on the ranks over the steps taken ([`WorkWeights`]): per model its force stage's
    /// seconds less those spent in collectives, against its work in the fixed shares, both
    /// summed over the ranks, per particle step of the prediction and integration. A
    /// collective, which every rank calls after the same step; the same weights on every
    /// rank. `None` unless the run is decomposed with a halo exchange (the only one that
    /// re-partitions). The work of a split model is its items' at its last evaluation,
    /// taken for every step measured.
    pub fn measured_weights(&mut self) -> Option<WorkWeights> {
        let (work, exchanged, computed) = self.parallel.rank_work(&mut self.models)?;
        let steps = self.stages.steps() as f64;
        let mut mine = Vec::with_capacity(2 * work.len() + 2);
        for (i, (w, waited)) in work.iter().zip(&exchanged).enumerate() {
            mine.push((self.stages.seconds(Stage::Forces(i)) - waited).max(0.0));
            mine.push(w * steps);
        }
        let particles = self.stages.seconds(Stage::Predict) + self.stages.seconds(Stage::Integrate);
        mine.extend([particles, computed as f64 * steps]);
        let all = self.parallel.gather_values(&mine);
        Some(WorkWeights::from_measured(&all, work.len()))
    }

    /// Re-partitions ([`World::repartition`]) with each model's items weighed by `weights`
    /// (the same on every rank: [`World::measured_weights`]'s), which the later
    /// re-partitions keep: a collective, which every rank calls after the same step. The cut
    /// is a function of the weights and the items alone, and the run goes on bit for bit as
    /// before whatever the cut.
    pub fn repartition_weighted(&mut self, weights: WorkWeights) {
        self.parallel.set_weights(weights);
        self.repartition();
    }

    /// The seconds model `model`'s evaluations on this rank have spent in collectives so far
    /// (waiting for the other ranks included), which [`World::measured_weights`] leaves out of
    /// its items' cost; 0 in a run of one process.
    pub fn waited_seconds(&self, model: usize) -> f64 {
        self.parallel.waited_seconds(model)
    }

    /// The weights of the models' items in the cut ([`World::repartition_weighted`]): all 1,
    /// the fixed shares, until set; `None` in a run of one process.
    pub fn work_weights(&self) -> Option<&WorkWeights> {
        self.parallel.weights()
    }

    /// Makes the state whole on every rank of a decomposed run, as one process holds it (and
    /// the stepper's forces, [`World::gather_forces`]): a collective, which every rank calls
    /// after the same step. Needed before reading any
    /// particle's motion when a step shares only the halo ([`World::decompose`]); a no-op
    /// otherwise (and in a run of one process).
    pub fn gather(&mut self) {
        let torques = self.stepper.rigid_torques_mut();
        let (state, models) = (&mut self.state, &mut self.models);
        self.parallel.gather(state, models, torques);
        self.gather_forces();
    }

    /// Makes the stepper's force buffer ([`Stepper::forces`]) whole on every rank of a
    /// decomposed run, each particle's from its owner (a reaction sums fixed particles'
    /// forces, which only their owners hold whole); every rank calls it after the same step.
    pub fn gather_forces(&mut self) {
        self.parallel.gather_forces(self.stepper.forces_mut());
    }

    /// [`World::gather`] of `particles` only (the probes' particles): every rank calls it
    /// after the same step with the same list, and then holds their position, velocity and
    /// acceleration as one process would.
    pub fn gather_particles(&mut self, particles: &[usize]) {
        self.parallel.gather_particles(&mut self.state, particles);
    }

    /// How the run is decomposed over processes; `None` for a run of one process.
    pub fn decomposition(&self) -> Option<&RankFigures> {
        self.parallel.decomposition()
    }

    /// This process's rank in a decomposed run (0 in a run of one process).
    pub fn rank(&self) -> usize {
        self.parallel.rank()
    }

    /// After a step of a driver of the run, on every rank after the same step: whether the
    /// run stops (`stop`: this rank was asked to), having made whole what the ranks read
    /// (`wanted`: what this rank reads; `particles`: those [`Gather::Particles`] makes whole,
    /// the same on every rank). In a decomposed run the ranks agree in one collective: the
    /// run stops when any rank was asked to, and every rank gathers the most that any rank
    /// reads, the whole state at a stop (for its checkpoint). A run of one process stops
    /// when asked to and has nothing to gather.
    pub fn agree_on_stop(&mut self, stop: bool, wanted: Gather, particles: &[usize]) -> bool {
        if self.decomposition().is_none() {
            return stop;
        }
        // The smallest wins: 0 stop (and the whole state), 1 the whole state, 2 the
        // particles, 3 nothing.
        let mine = match (stop, wanted) {
            (true, _) => 0,
            (false, Gather::Whole) => 1,
            (false, Gather::Particles) => 2,
            (false, Gather::Nothing) => 3,
        };
        let agreed = self.parallel.agree_min(mine);
        match agreed {
            0 | 1 => self.gather(),
            2 => self.gather_particles(particles),
            _ => {}
        }
        agreed == 0
    }

    /// Every rank's `row` of figures (of one length on every rank), in rank order, on every
    /// rank: a report's table of the ranks (`row` itself in a run of one process). A
    /// collective, which every rank calls after the same step.
    pub fn rank_rows(&self, row: &[f64]) -> Vec<f64> {
        self.parallel.gather_values(row)
    }

    /// Makes the accelerations consistent with the forces at the start (and factorises, for
    /// an implicit scheme).
    pub fn initialize(&mut self) -> Result<(), CoreError> {
        let (state, models) = (&mut self.state, &mut self.models);
        let done = self
            .stepper
            .initialize_in(state, models, &mut self.parallel);
        let torques = self.stepper.rigid_torques_mut();
        self.parallel.initialized(&mut self.state, torques, done)
    }

    /// Advances one step through every stage; `Ok(Some(halt))` when a hook ends the run.
    pub fn step(&mut self) -> Result<Option<Halt>, CoreError> {
        self.stages.begin_step();
        let (state, models, stages) = (&mut self.state, &mut self.models, &mut self.stages);
        let stepped = self
            .stepper
            .step_timed(state, models, stages, &mut self.parallel);
        self.steps_done += 1;
        let checked = self.check(stepped);
        self.stages.mark(Stage::Check);
        checked?;
        let mut halt = None;
        for (i, hook) in self.hooks.iter_mut().enumerate() {
            let (state, models) = (&mut self.state, &self.models[..]);
            if let Some(h) = self.parallel.after_step(i, hook.as_mut(), state, models) {
                halt.get_or_insert(h);
            }
            self.stages.mark(Stage::Hook(i));
        }
        if self.parallel.rebalances() {
            let torques = self.stepper.rigid_torques_mut();
            let (state, models, hooks) = (&mut self.state, &mut self.models, &mut self.hooks);
            self.parallel.rebalance(state, models, hooks, torques);
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
            Err(source) if self.decomposition().is_none() => return Err(source),
            Err(source) => Some(source.to_string()),
            Ok(()) => self
                .models
                .iter()
                .find_map(|m| m.failure(&self.state))
                .map(|e| match e {
                    CoreError::PassThrough { detail, fix, .. } => {
                        format!("{PASS_THROUGH}{detail}{PASS_THROUGH}{fix}")
                    }
                    e => e.to_string(),
                }),
        };
        let failure = self.parallel.agree(local);
        let kinetic = self.parallel.kinetic_energy(&self.state);
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
        if let Some(report) = detail.strip_prefix(PASS_THROUGH) {
            let (what, fix) = report.split_once(PASS_THROUGH).unwrap_or((report, ""));
            return Err(CoreError::PassThrough {
                step: self.steps_done,
                time: self.state.time,
                dt: self.settings.dt,
                detail: what.to_string(),
                fix: fix.to_string(),
            });
        }
        let (bound, limiter) = stable_step(&self.state, &self.models)
            .unwrap_or((f64::INFINITY, "nothing".to_string()));
        Err(CoreError::Unstable {
            step: self.steps_done,
            time: self.state.time,
            detail,
            dt: self.settings.dt,
            bound,
            limiter: limiter.into_boxed_str(),
            cause: None,
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

    /// Writes the state, every model's history (each a block of its own, empty for a model
    /// without history, so that a reader may skip it: [`crate::checkpoint::model_histories`])
    /// and the stepper's into a checkpoint.
    pub fn save(&self, out: &mut Encoder) -> Result<(), CheckpointError> {
        self.state.save(out);
        for m in &self.models {
            out.tag(&model_tag(m.name()));
            let mut history = Encoder::new();
            if let Persistence::Saved(saved) = m.persistence() {
                saved.save(&mut history);
            }
            out.block(history.bytes());
        }
        self.stepper.save(out)
    }

    /// Instead of [`World::initialize`]: reads back what [`World::save`] wrote, into a world
    /// built from the same scene, `steps_done` steps into the run; the stepper resumes after
    /// the models (it may refactorise with their restored tangents).
    pub fn restore(&mut self, input: &mut Decoder<'_>, steps_done: u64) -> Result<(), CoreError> {
        self.state.restore(input)?;
        for m in self.models.iter_mut() {
            input.tag(&model_tag(m.name()))?;
            let mut block = Decoder::new(input.block("a model's history")?);
            if let Some(history) = m.persistent_mut() {
                history.restore(&mut block)?;
            }
            whole_block(m.name(), &block)?;
        }
        self.stepper
            .resume(&mut self.state, &mut self.models, input)?;
        self.steps_done = steps_done;
        Ok(())
    }
}

/// Tells every model how it is stepped.
fn prepare(models: &mut [Box<dyn Model>], settings: &StepSettings) {
    for model in models.iter_mut() {
        model.prepare(settings);
    }
}
