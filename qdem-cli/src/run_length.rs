//! How long a run will take at the least, modelled before it starts, so that a run of days
//! (a step 10⁶ times too small from a stiffness of 10³⁰, a sliver) is not started by mistake:
//! `qdem run` refuses one that would take more than [`LONGEST_UNASKED`] unless given `--yes`.
//!
//! The model is a lower bound of a step's wall time: its tetrahedra and contact spheres at the
//! fastest rates measured per thread (docs/BENCHMARKS.md: 4.2 × 10⁷ tet-steps/s on one thread,
//! 1.07 × 10⁷ contact-sphere-steps/s on two), taken four times faster for a faster machine,
//! shared over the threads (no more than the cores) and the ranks, and never below
//! [`STEP_FLOOR`]. A run refused is therefore longer than the figure given; `qdem check`
//! measures a step of the scene itself.

use qdem_io::build::Simulation;
use std::path::PathBuf;

/// The modelled wall time above which `qdem run` asks for `--yes`: one day.
pub const LONGEST_UNASKED: f64 = 86_400.0;

/// Wall seconds of a tetrahedron-step on one thread, at the least.
const TET_STEP: f64 = 6e-9;

/// Wall seconds of a contact-sphere-step on one thread, at the least.
const SPHERE_STEP: f64 = 4e-8;

/// Wall seconds of a step, at the least, however small its scene.
const STEP_FLOOR: f64 = 1e-7;

/// A run modelled to take more than [`LONGEST_UNASKED`].
#[derive(Debug, thiserror::Error)]
#[error(
    "{scene}: the run is {steps} steps (dt = {dt:.4e} s to t_end = {t_end} s; the stable bound \
     {bound:.4e} s is set by `{limiter}`): at least {days:.1} days of wall time on {threads} \
     threads (at least {step:.1e} s a step for its {tets} tets and {spheres} contact spheres), \
     more than the day a run starts without asking; fix: shorten it (a shorter t_end; a larger \
     step: what bounds it, a stiffness, a small or flat element, is named above and by `qdem \
     check`, which also measures a step), or give --yes to start it anyway",
    scene = scene.display(),
    days = seconds / 86_400.0
)]
pub struct TooLong {
    /// The scene file.
    pub scene: PathBuf,
    /// The run's steps.
    pub steps: u64,
    /// Its step (s).
    pub dt: f64,
    /// Its end time (s).
    pub t_end: f64,
    /// The explicit stable bound (s).
    pub bound: f64,
    /// What sets the bound.
    pub limiter: String,
    /// The threads (and ranks) the run shares.
    pub threads: usize,
    /// Its tetrahedra.
    pub tets: usize,
    /// Its contact spheres.
    pub spheres: usize,
    /// The modelled wall seconds of a step.
    pub step: f64,
    /// The modelled wall seconds of the run.
    pub seconds: f64,
}

/// The least wall seconds a step of `sim` takes on `threads` threads of `cores` cores, over
/// `ranks` processes (see the module docs).
#[must_use]
pub fn step_seconds(sim: &Simulation, threads: usize, cores: usize, ranks: usize) -> f64 {
    let spheres = sim.contacts().map_or(0, |c| c.spheres());
    let work = sim.tets() as f64 * TET_STEP + spheres as f64 * SPHERE_STEP;
    let share = (threads.min(cores).max(1) * ranks.max(1)) as f64;
    (work / share).max(STEP_FLOOR)
}

/// Refuses a run of `sim` from its start modelled to take more than [`LONGEST_UNASKED`] on
/// `threads` threads of `cores` cores over `ranks` processes.
///
/// # Errors
/// [`TooLong`] with the figures and the fix.
pub fn refuse_long(
    sim: &Simulation,
    threads: usize,
    cores: usize,
    ranks: usize,
) -> Result<(), Box<TooLong>> {
    let steps = sim.steps();
    let step = step_seconds(sim, threads, cores, ranks);
    let seconds = step * steps as f64;
    if seconds <= LONGEST_UNASKED {
        return Ok(());
    }
    let (bound, limiter) = sim.world.settings().stable_dt.clone();
    Err(Box::new(TooLong {
        scene: sim.scene.path.clone(),
        steps,
        dt: sim.world.dt(),
        t_end: sim.scene.run.t_end,
        bound,
        limiter,
        threads: threads * ranks.max(1),
        tets: sim.tets(),
        spheres: sim.contacts().map_or(0, |c| c.spheres()),
        step,
        seconds,
    }))
}
