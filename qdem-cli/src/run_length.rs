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

/// Contact pairs per grain of a settled bed: a coordination of about 6 contacts per grain,
/// each shared by two.
pub const SETTLED_PAIRS_PER_GRAIN: f64 = 3.0;

/// Wall seconds of a touching pair's evaluation on one thread (the narrow phase, the law and
/// the sums): 60 ns a candidate on the 10⁵ grains split over 2 ranks (docs/scaling.md), about
/// one candidate per touching pair in a settled bed.
const PAIR_STEP: f64 = 6e-8;

/// What a step of `sim` costs more once its contacts have grown from those present now to
/// a settled bed's ([`SETTLED_PAIRS_PER_GRAIN`] per body with contact spheres), on `threads`
/// threads: `None` when they are already as many (a step measured before a pour's contacts
/// form is a lower bound of its steps after; issue of `qdem check`'s 9 s for a 49.7 s pour).
#[must_use]
pub fn settled_contacts(sim: &Simulation, threads: usize) -> Option<SettledContacts> {
    let contacts = sim.contacts()?;
    let now = contacts.contacts();
    let settled = (SETTLED_PAIRS_PER_GRAIN * contacts.body_names().len() as f64).round() as usize;
    (settled > now).then(|| SettledContacts {
        now,
        settled,
        extra_step: (settled - now) as f64 * PAIR_STEP / threads.max(1) as f64,
    })
}

/// A scene whose contacts will grow (a pour), and what its step costs more then.
#[derive(Clone, Copy, Debug)]
pub struct SettledContacts {
    /// The contacts touching now.
    pub now: usize,
    /// The contacts of the settled bed.
    pub settled: usize,
    /// The wall seconds a step costs more with them.
    pub extra_step: f64,
}

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
