//! The run loop: steps a [`Simulation`]'s [`qdem_core::world::World`] to `t_end`, hands the state
//! after every step to the outputs' recorders (`record`: probes, VTU/PVD, sections,
//! boundary, crack picture, stones, poses), checkpoints when due or asked to, and writes
//! `summary.json` at the end. Every output file is written atomically; a run stopped by an
//! instability still commits the probe rows up to the failure and its end-of-run files.

use crate::build::Simulation;
use crate::checkpoint::{
    read_checkpoint, scene_fingerprint, write_checkpoint, CheckpointFileError, CHECKPOINT_FILE,
};
use crate::output::{FolderLock, LockError, OutputError};
use crate::run::contact_watch::{ContactWatch, Interpenetration};
use crate::run::fresh_start;
use crate::run::inputs::SceneFingerprint;
use crate::run::load_cause::load_cause;
use crate::run::record::schedule::{probe_interval, Schedule};
use crate::run::record::{self, Recorder, RunFigures, StateRead, StepInfo};
use crate::run::run_record::{decode_run, decode_world, encode_run, RunRecord};
use qdem_core::world::Gather;
use qdem_core::{error::CoreError, step::Halt, world::World};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;
use thiserror::Error;

/// Why a run stopped early.
#[derive(Debug, Error)]
pub enum RunError {
    /// An output could not be written.
    #[error(transparent)]
    Output(#[from] OutputError),
    /// The output directory could not be created.
    #[error("cannot create the output directory {path}: {source}")]
    OutputDir {
        /// The directory.
        path: PathBuf,
        /// The io error.
        source: std::io::Error,
    },
    /// The step failed: an instability the world's failure check found
    /// ([`CoreError::Unstable`], naming the step, the time, where, and the stable bound), or
    /// another error of the core.
    #[error("{scene}: {source}")]
    Core {
        /// The scene file.
        scene: PathBuf,
        /// What went wrong.
        source: CoreError,
    },
    /// The output folder is in use by another run, or its lock cannot be taken.
    #[error(transparent)]
    Lock(#[from] LockError),
    /// The run would write over (or, starting fresh, remove) a file its scene reads: refused
    /// before it removes or writes anything.
    #[error(
        "{scene}: the run would write over (or, starting fresh, remove) {output}, which the \
         scene reads (\"{input}\"): a run must not change its own input; fix: give the run \
         another --out (or [output] dir), or copy the file out of the output folder and name \
         the copy in the scene",
        scene = scene.display(),
        output = output.display(),
        input = input.display()
    )]
    OverwritesInput {
        /// The scene file.
        scene: PathBuf,
        /// The file read, as the scene names it.
        input: PathBuf,
        /// The output it is, in the output folder.
        output: PathBuf,
    },
    /// Two bodies pass through each other: the interpenetration watch stopped the run.
    #[error("{scene}: {source}")]
    Interpenetration {
        /// The scene file.
        scene: PathBuf,
        /// The bodies, the overlap, the speed and the fix.
        source: Box<Interpenetration>,
    },
    /// A checkpoint that cannot be resumed from.
    #[error(transparent)]
    Checkpoint(#[from] CheckpointFileError),
    /// `--stop-after N` on a resume from a checkpoint at or past step N.
    #[error(
        "--stop-after {stop_after} counts steps from the run's start, and the checkpoint is at \
         step {done}, past it, so the run would not stop; fix: give a step after {done}, e.g. \
         --stop-after {} to stop {stop_after} steps from here",
        done + stop_after
    )]
    StopAfterPassed {
        /// The step asked for.
        stop_after: u64,
        /// The checkpoint's last step.
        done: u64,
    },
    /// The run was stopped on request (Ctrl-C, SIGTERM) after writing a checkpoint.
    #[error(
        "interrupted at t = {time:.6e} s (step {step}); the run is checkpointed in {checkpoint}: \
         continue it with `qdem run SCENE --resume {checkpoint}`",
        checkpoint = checkpoint.display()
    )]
    Interrupted {
        /// Simulated time reached.
        time: f64,
        /// The last step done.
        step: u64,
        /// The checkpoint written.
        checkpoint: PathBuf,
    },
    /// A run that failed after its last good state was checkpointed.
    #[error(
        "{source}\nthe last good state (t = {time:.6e} s) is saved in {checkpoint}",
        checkpoint = checkpoint.display()
    )]
    Failed {
        /// Why the run failed.
        source: Box<RunError>,
        /// The time of the checkpointed state.
        time: f64,
        /// The checkpoint written.
        checkpoint: PathBuf,
    },
}

/// Where the run is, for a progress display.
#[derive(Clone, Copy, Debug)]
pub struct Progress {
    /// Steps done.
    pub step: u64,
    /// Steps in the whole run.
    pub steps: u64,
    /// Simulated time (s).
    pub time: f64,
    /// Steps per wall-clock second so far.
    pub steps_per_second: f64,
    /// Estimated wall-clock seconds left.
    pub eta_seconds: f64,
}

/// What a finished run reports (also written to `summary.json`).
#[derive(Clone, Debug)]
pub struct RunReport {
    /// The stepper's name.
    pub integrator: String,
    /// Steps taken.
    pub steps: u64,
    /// Step size (s).
    pub dt: f64,
    /// Final simulated time (s).
    pub final_time: f64,
    /// Wall-clock seconds of the stepping loop, outputs included.
    pub wall_seconds: f64,
    /// Tetrahedron-steps per wall-clock second.
    pub tet_steps_per_second: f64,
    /// Particle-steps per wall-clock second.
    pub particle_steps_per_second: f64,
    /// Why a post-step hook ended the run before `t_end` (a bonded body that collapsed).
    pub halt: Option<Halt>,
}

/// Wall-clock seconds between the in-memory copies of the last good state (on the main
/// cantilever job, probing every 26 steps, a copy at every probe sample cost 16% of the run).
const GOOD_STATE_EVERY: f64 = 1.0;

/// The steps after which a run decomposed over ranks cuts them again with each model's items
/// weighed by what they were measured to cost over those steps
/// ([`World::measured_weights`]): once, so that a long run pays for one gather, and late
/// enough that the contact lists have been built on every rank.
const MEASURED_STEPS: u64 = 20;

/// How a run starts and when it stops early.
#[derive(Clone, Copy, Default)]
pub struct RunOptions<'a> {
    /// A checkpoint to continue from (`qdem run --resume`), written by a run of the same scene
    /// into the same output directory.
    pub resume: Option<&'a Path>,
    /// Set (by a Ctrl-C or SIGTERM handler) to stop the run after the current step, with a
    /// checkpoint.
    pub stop: Option<&'a AtomicBool>,
    /// Stops as on a stop request once this step is done (a batch slot's last step, a test).
    pub stop_after: Option<u64>,
}

impl std::fmt::Debug for RunOptions<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RunOptions")
            .field("resume", &self.resume)
            .field("stop", &self.stop)
            .field("stop_after", &self.stop_after)
            .finish()
    }
}

impl RunOptions<'_> {
    /// After `step`: whether the run stops (asked to, on any rank of a decomposed run),
    /// having made whole what the ranks read first (`read`: what this rank reads, of the
    /// `probes`' particles for [`StateRead::Probes`]; the whole state at a stop, for its
    /// checkpoint): [`World::agree_on_stop`], one agreement of `world`'s ranks per step in a
    /// decomposed run (rank 0 writes every output, the others only step).
    fn stops_after(&self, world: &mut World, step: u64, read: StateRead, probes: &[usize]) -> bool {
        let asked =
            self.stop.is_some_and(|s| s.load(Ordering::Relaxed)) || self.stop_after == Some(step);
        let wanted = match read {
            StateRead::Nothing => Gather::Nothing,
            StateRead::Probes => Gather::Particles,
            StateRead::Whole => Gather::Whole,
        };
        world.agree_on_stop(asked, wanted, probes)
    }
}

/// Runs `sim` to its end time, writing `probes.csv`, `summary.json` and, if asked,
/// `vtu/state_NNNNN.vtu` with `results.pvd` into `out_dir`. `progress` is called about twice
/// a second of wall-clock time.
pub fn run(
    sim: &mut Simulation,
    out_dir: &Path,
    progress: &mut dyn FnMut(&Progress),
) -> Result<RunReport, RunError> {
    run_with(sim, out_dir, RunOptions::default(), progress)
}

/// The last good state of a run, kept in memory: its time, its checkpoint body and when it
/// was taken.
type GoodState = (f64, Vec<u8>, Instant);

/// [`run`], resuming from a checkpoint or stopping on request as `options` say. With
/// `[output] checkpoint_every`, a resume or a stop request, the scene's models and stepper
/// must be checkpointable, which is checked before the first step. At every checkpoint the
/// probe rows so far are published under `probes.csv`; a resumed run keeps the rows the
/// checkpoint has seen and appends. A run that fails leaves its last good state in
/// `checkpoint.qdc` when it can be checkpointed: the state at a probe sample, kept in memory
/// at most once per `GOOD_STATE_EVERY` seconds of wall time so that encoding it costs next
/// to nothing however often the probes sample.
pub fn run_with(
    sim: &mut Simulation,
    out_dir: &Path,
    options: RunOptions<'_>,
    progress: &mut dyn FnMut(&Progress),
) -> Result<RunReport, RunError> {
    if sim.world.rank() != 0 {
        return follow(sim, options);
    }
    let mut run = Run::open(sim, out_dir, options)?;
    let steps = sim.steps();
    let probes = probe_particles(sim);
    let first_step = run.record.next_step;
    let watch = sim
        .world
        .decomposition()
        .is_none()
        .then(|| ContactWatch::new(sim))
        .flatten();
    let start = Instant::now();
    let mut last_report = start;
    let mut halt = None;
    let outcome = (|| -> Result<(), RunError> {
        if options.resume.is_none() {
            sim.world
                .initialize()
                .map_err(|source| core_error(sim, source))?;
        }
        for step in first_step..=steps {
            let dt = sim.world.dt();
            let mut seconds = None;
            if step > 0 {
                let begin = Instant::now();
                halt = sim.world.step().map_err(|source| core_error(sim, source))?;
                seconds = Some(begin.elapsed().as_secs_f64());
                weigh_measured_cost(&mut sim.world, step - first_step);
                if let Some(watch) = &watch {
                    watch
                        .check(sim, step)
                        .map_err(|source| RunError::Interpenetration {
                            scene: sim.scene.path.clone(),
                            source,
                        })?;
                }
            }
            let info = StepInfo {
                dt,
                seconds,
                halt: halt.as_ref(),
            };
            let keep_good = run.keeps_good_state(sim, dt);
            let read = match keep_good {
                true => StateRead::Whole,
                false => run.reads_state(sim, dt),
            };
            let stop = options.stops_after(&mut sim.world, step, read, &probes);
            run.after_step(sim, step, &info, stop, keep_good)?;
            if step % 64 == 0 && last_report.elapsed().as_secs_f64() > 0.5 {
                last_report = Instant::now();
                let time = sim.world.state.time;
                progress(&progress_at(
                    step - first_step,
                    steps - first_step,
                    time,
                    start,
                ));
            }
            if halt.is_some() {
                break;
            }
        }
        Ok(())
    })();
    if outcome.is_ok() {
        // The other ranks gather too at a run's end, but not after a stop or a failure,
        // which gathered at their step.
        sim.world.gather();
    }
    let wall_seconds = start.elapsed().as_secs_f64();
    run.close(sim, outcome)?;
    let steps = match halt {
        Some(_) => sim.world.steps_done(),
        None => steps,
    };
    let (report, figures) = report(sim, steps, first_step, wall_seconds, halt);
    let resumed_at = options.resume.map(|_| first_step.saturating_sub(1));
    let recorders = &run.recorders;
    record::summary::write(out_dir, sim, &report, &figures, recorders, resumed_at)?;
    Ok(report)
}

/// A run in progress besides its world: the recorders, the run record, and what checkpoints
/// need (the file, the scene's fingerprint, the last good state kept in memory).
struct Run {
    recorders: Vec<Box<dyn Recorder>>,
    record: RunRecord,
    checkpoint_path: PathBuf,
    fingerprint: SceneFingerprint,
    can_checkpoint: bool,
    last_good: Option<GoodState>,
    good_schedule: Schedule,
    /// The output folder's lock, held until the run (its summary included) is done.
    _lock: FolderLock,
}

impl Run {
    /// Prepares `out_dir` (its folders and lock, no temporary files of killed runs, and for a
    /// fresh run no outputs of an earlier one: `fresh_start`), refuses a run that would write
    /// over a file its scene reads and one that must checkpoint but cannot, registers the recorders and, resuming, restores the world
    /// and the recorders from the checkpoint; then opens the recorders' files.
    fn open(
        sim: &mut Simulation,
        out_dir: &Path,
        options: RunOptions<'_>,
    ) -> Result<Run, RunError> {
        create_dir(out_dir)?;
        let lock = FolderLock::acquire(out_dir)?;
        let fingerprint = scene_fingerprint(&sim.scene);
        let inputs: Vec<(PathBuf, PathBuf)> = crate::inputs::input_files(&sim.scene)
            .into_iter()
            .map(|named| {
                let resolved = fingerprint.resolve(&named);
                (named, resolved)
            })
            .collect();
        if let Some((input, output)) = fresh_start::overwritten_input(out_dir, &inputs) {
            return Err(RunError::OverwritesInput {
                scene: sim.scene.path.clone(),
                input,
                output,
            });
        }
        if options.resume.is_none() {
            fresh_start::remove_earlier_outputs(out_dir);
        }
        if record::snapshots::writes_vtu(&sim.scene) {
            create_dir(&out_dir.join("vtu"))?;
        }
        crate::output::remove_stale_temporaries(out_dir);
        let can_checkpoint = sim.world.checkpointable();
        if sim.scene.output.checkpoint_every > 0.0 || options.resume.is_some() {
            if let Err(source) = &can_checkpoint {
                return Err(core_error(sim, source.clone().into()));
            }
        }
        let mut run = Run {
            recorders: record::register(sim, out_dir),
            record: RunRecord::new(sim),
            checkpoint_path: out_dir.join(CHECKPOINT_FILE),
            fingerprint,
            can_checkpoint: can_checkpoint.is_ok(),
            last_good: None,
            good_schedule: Schedule::new(probe_interval(sim)),
            _lock: lock,
        };
        if let Some(path) = options.resume {
            let body = read_checkpoint(path, Some(&run.fingerprint))?;
            decode_run(&body, sim, &mut run.record, &mut run.recorders)
                .map_err(|source| core_error(sim, source))?;
            let done = run.record.next_step.saturating_sub(1);
            if let Some(stop_after) = options.stop_after.filter(|&n| n <= done) {
                return Err(RunError::StopAfterPassed { stop_after, done });
            }
        }
        for r in run.recorders.iter_mut() {
            r.start(options.resume.is_some())?;
        }
        Ok(run)
    }

    /// What the recorders and a checkpoint read of the state after this step (at `dt`).
    fn reads_state(&self, sim: &Simulation, dt: f64) -> StateRead {
        let time = sim.world.state.time;
        let recorded = self.recorders.iter().map(|r| r.reads(time, dt)).max();
        match self.record.checkpoints.is_due(time, dt) {
            true => StateRead::Whole,
            false => recorded.unwrap_or(StateRead::Nothing),
        }
    }

    /// Whether the last good state is kept in memory after this step (at `dt`): at a probe
    /// interval, at most once per `GOOD_STATE_EVERY` seconds of wall time.
    fn keeps_good_state(&self, sim: &Simulation, dt: f64) -> bool {
        self.can_checkpoint
            && self.good_schedule.is_due(sim.world.state.time, dt)
            && self
                .last_good
                .as_ref()
                .is_none_or(|g| g.2.elapsed().as_secs_f64() >= GOOD_STATE_EVERY)
    }

    /// After the sample at the start (step 0) and after every step, with the state whole
    /// where the ranks agreed: the recorders record, then a checkpoint when due or at a
    /// `stop` (which ends the run with [`RunError::Interrupted`]), else, with `keep_good`,
    /// the last good state in memory.
    fn after_step(
        &mut self,
        sim: &Simulation,
        step: u64,
        info: &StepInfo<'_>,
        stop: bool,
        keep_good: bool,
    ) -> Result<(), RunError> {
        for r in self.recorders.iter_mut() {
            r.record(sim, info)?;
        }
        let time = sim.world.state.time;
        self.good_schedule.due(time, info.dt);
        self.record.next_step = step + 1;
        if self.record.checkpoints.due(time, info.dt) || stop {
            for r in self.recorders.iter_mut() {
                r.publish()?;
            }
            let body = encode(sim, &self.record, &self.recorders)?;
            write_checkpoint(&self.checkpoint_path, &self.fingerprint, &body)?;
        } else if keep_good {
            let body = encode(sim, &self.record, &self.recorders)?;
            self.last_good = Some((time, body, Instant::now()));
        }
        match stop {
            true => Err(RunError::Interrupted {
                time,
                step,
                checkpoint: self.checkpoint_path.clone(),
            }),
            false => Ok(()),
        }
    }

    /// Ends the run, finished or failed: the recorders write their end-of-run files, and a
    /// run that failed leaves its last good state in the checkpoint.
    fn close(&mut self, sim: &Simulation, outcome: Result<(), RunError>) -> Result<(), RunError> {
        for r in self.recorders.iter_mut() {
            r.finish(sim)?;
        }
        match (outcome, self.last_good.take()) {
            (
                Err(source @ (RunError::Core { .. } | RunError::Interpenetration { .. })),
                Some((time, body, _)),
            ) => {
                write_checkpoint(&self.checkpoint_path, &self.fingerprint, &body)?;
                Err(RunError::Failed {
                    source: Box::new(source),
                    time,
                    checkpoint: self.checkpoint_path.clone(),
                })
            }
            (outcome, _) => outcome,
        }
    }
}

/// After the [`MEASURED_STEPS`]th step this process took (`taken`), a run decomposed with a
/// halo exchange cuts its ranks again by the measured cost of each model's items (a
/// collective, at the same step on every rank; the outputs do not depend on the cut).
fn weigh_measured_cost(world: &mut World, taken: u64) {
    if taken != MEASURED_STEPS {
        return;
    }
    if let Some(weights) = world.measured_weights() {
        world.repartition_weighted(weights);
    }
}

/// A rank other than 0 of a decomposed run: the same steps, the same stop agreements, no
/// outputs (rank 0 writes them from the same state).
fn follow(sim: &mut Simulation, options: RunOptions<'_>) -> Result<RunReport, RunError> {
    let start = Instant::now();
    let first_step = match options.resume {
        Some(path) => {
            let body = read_checkpoint(path, Some(&scene_fingerprint(&sim.scene)))?;
            decode_world(&body, sim).map_err(|source| core_error(sim, source))?
        }
        None => {
            let initialized = sim.world.initialize();
            initialized.map_err(|source| core_error(sim, source))?;
            0
        }
    };
    let steps = sim.steps();
    let probes = probe_particles(sim);
    let mut halt = None;
    let mut stopped = false;
    for step in first_step..=steps {
        if step > 0 {
            halt = sim.world.step().map_err(|source| core_error(sim, source))?;
            weigh_measured_cost(&mut sim.world, step - first_step);
        }
        stopped = options.stops_after(&mut sim.world, step, StateRead::Nothing, &probes);
        if stopped || halt.is_some() {
            break;
        }
    }
    if !stopped {
        sim.world.gather();
    }
    let wall_seconds = start.elapsed().as_secs_f64();
    let steps = sim.world.steps_done();
    Ok(report(sim, steps, first_step, wall_seconds, halt).0)
}

/// The report of a run that ended after `steps` steps, having started at `first_step`, and
/// its figures.
fn report(
    sim: &Simulation,
    steps: u64,
    first_step: u64,
    wall_seconds: f64,
    halt: Option<Halt>,
) -> (RunReport, RunFigures) {
    let figures = RunFigures {
        steps_taken: steps.saturating_sub(first_step.saturating_sub(1)) as f64,
        wall_seconds,
    };
    let report = RunReport {
        integrator: sim.world.stepper().name().to_string(),
        steps,
        dt: sim.world.dt(),
        final_time: sim.world.state.time,
        wall_seconds,
        tet_steps_per_second: figures.rate(sim.tets()),
        particle_steps_per_second: figures.rate(sim.world.state.len()),
        halt,
    };
    (report, figures)
}

/// The probes' particles, which a decomposed run gathers for a probe sample.
fn probe_particles(sim: &Simulation) -> Vec<usize> {
    sim.probes.iter().map(|p| p.particle).collect()
}

/// Creates an output directory.
fn create_dir(path: &Path) -> Result<(), RunError> {
    std::fs::create_dir_all(path).map_err(|source| RunError::OutputDir {
        path: path.to_path_buf(),
        source,
    })
}

/// The checkpoint body of the run so far.
fn encode(
    sim: &Simulation,
    run: &RunRecord,
    recorders: &[Box<dyn Recorder>],
) -> Result<Vec<u8>, RunError> {
    encode_run(sim, run, recorders).map_err(|source| core_error(sim, source.into()))
}

/// A core error of `sim`'s run (an instability found by the world's failure check among
/// them: [`CoreError::Unstable`], whose cause is the load when a load no step resolves
/// caused it: [`load_cause`]; a [`CoreError::PassThrough`] then names that cause in place of
/// its fixes), naming the scene.
fn core_error(sim: &Simulation, mut source: CoreError) -> RunError {
    match &mut source {
        CoreError::Unstable { cause, .. } => *cause = load_cause(sim).map(Box::new),
        CoreError::PassThrough { fix, .. } => {
            if let Some(cause) = load_cause(sim) {
                *fix = cause;
            }
        }
        _ => {}
    }
    RunError::Core {
        scene: sim.scene.path.clone(),
        source,
    }
}

fn progress_at(step: u64, steps: u64, time: f64, start: Instant) -> Progress {
    let elapsed = start.elapsed().as_secs_f64();
    let rate = step as f64 / elapsed.max(1e-9);
    Progress {
        step,
        steps,
        time,
        steps_per_second: rate,
        eta_seconds: (steps - step) as f64 / rate.max(1e-9),
    }
}
