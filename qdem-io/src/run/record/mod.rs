//! Outputs as recorders: each output file of a run is one [`Recorder`], registered by
//! [`register`] for what the scene has, and the run loop only steps the world, hands every
//! recorder the state after each step, and checkpoints.
//!
//! | recorder | file | when |
//! | --- | --- | --- |
//! | [`probes::Probes`] | `probes.csv`, `probes.svg` | every `probe_every` |
//! | [`boundary::Boundary`] | `boundary.csv` (time-delayed boundary) | every `probe_every` |
//! | [`sections::Sections`] | `sections.csv` (`[[section]]`s) | every `probe_every` |
//! | [`reactions::Reactions`] | `reactions.csv` (`[[fix]]`es of deformable bodies) | every `probe_every` |
//! | [`settlement::Settlement`] | `settlement.csv`, `settlement.svg` (a `cyclic` load and probes) | at each cycle's minimum and maximum |
//! | [`walls::Walls`] | `walls.csv` (`[[wall]]`s: force, displacement) | every `probe_every` |
//! | [`measures::Measures`] | `measure_NAME.csv`, `measure_NAME.svg`, `measure_NAME_energy.svg` (`[[measure]]`s) | every `every` |
//! | [`snapshots::Snapshots`] | `vtu/state_NNNNN.vtu`, `results.pvd`; `vtu/spheres_NNNNN.vtu`, `vtu/contacts_NNNNN.vtu`, `vtu/walls.vtu` (contacts), `vtu/bonds_NNNNN.vtu` (`[bonded]`) | every `vtu_every` (never if 0), and a static run's final state |
//! | [`crack::Crack`] | `crack.svg`, the bonded timings | every step; the picture at the end |
//! | [`grading::Grading`] | `grading.csv`, `grading.svg` (`[granular]`: sieve curve by mass) | at the start |
//! | [`stones::Stones`] | `stones.csv` (`[granular]`) | at the end |
//! | [`poses::Poses`] | `poses.csv` (rigid bodies) | at the end |
//!
//! `summary.json` ([`summary`]) is put together at the end of a finished run from the run's
//! figures and each recorder's part. A recorder's history (rows so far, schedules, the plot's
//! points) goes into the checkpoint in registration order, so a resumed run appends to its
//! files as if it had never stopped.

pub(crate) mod bonds_vtu;
pub(crate) mod boundary;
pub(crate) mod contacts_vtu;
pub(crate) mod crack;
pub(crate) mod grading;
pub(crate) mod measures;
pub(crate) mod nodal_stress;
pub(crate) mod poses;
pub(crate) mod probes;
pub(crate) mod reactions;
pub(crate) mod schedule;
pub(crate) mod sections;
pub(crate) mod settlement;
pub(crate) mod snapshots;
pub(crate) mod spheres_vtu;
pub(crate) mod stones;
pub(crate) mod summary;
pub(crate) mod tet_stress;
pub(crate) mod walls;
pub(crate) mod walls_vtu;

use crate::build::Simulation;
use crate::output::{write_atomic, OutputError};
use qdem_core::{
    checkpoint::CheckpointError, checkpoint::Decoder, checkpoint::Encoder, step::Halt,
};
use std::path::Path;

/// What a recorder learns of the step just taken.
#[derive(Clone, Copy, Debug)]
pub(crate) struct StepInfo<'a> {
    /// The step (s).
    pub dt: f64,
    /// Wall seconds the step took; `None` for the sample at the start of the run.
    pub seconds: Option<f64>,
    /// Why a post-step hook ended the run at this step, if one did.
    pub halt: Option<&'a Halt>,
}

/// What a recorder reads of the particles' motion after a step ([`Recorder::reads`]); in a
/// decomposed run the ranks gather that much first.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) enum StateRead {
    /// Nothing.
    Nothing,
    /// The probes' particles.
    Probes,
    /// The whole state.
    Whole,
}

impl StateRead {
    /// The whole state when a sample is `due`, else nothing: the read of a recorder that
    /// samples the whole state on a schedule.
    pub(crate) fn whole_if(due: bool) -> StateRead {
        match due {
            true => StateRead::Whole,
            false => StateRead::Nothing,
        }
    }
}

/// What a finished run did, for the rates in `summary.json`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RunFigures {
    /// Steps taken by this process (a resumed run counts from its checkpoint).
    pub steps_taken: f64,
    /// Wall-clock seconds of the stepping loop, outputs included.
    pub wall_seconds: f64,
}

impl RunFigures {
    /// `count` things stepped `steps_taken` times, per wall-clock second.
    pub(crate) fn rate(&self, count: usize) -> f64 {
        count as f64 * self.steps_taken / self.wall_seconds.max(1e-9)
    }
}

/// One output of a run.
pub(crate) trait Recorder {
    /// A short name, the recorder's tag in checkpoints.
    fn name(&self) -> &'static str;

    /// Opens the recorder's files: new ones, or (`resumed`) the ones of the run it continues,
    /// after [`Recorder::restore`].
    fn start(&mut self, resumed: bool) -> Result<(), OutputError> {
        let _ = resumed;
        Ok(())
    }

    /// What [`Recorder::record`] reads of the particles' motion at `time` (a sample is due),
    /// so that a decomposed run gathers it first ([`qdem_core::world::World::gather`]). The default:
    /// nothing.
    fn reads(&self, time: f64, dt: f64) -> StateRead {
        let _ = (time, dt);
        StateRead::Nothing
    }

    /// Records what is due at the simulation's time: once at the start, then after every
    /// step. The default records nothing (an output written at the end).
    fn record(&mut self, sim: &Simulation, step: &StepInfo<'_>) -> Result<(), OutputError> {
        let _ = (sim, step);
        Ok(())
    }

    /// At a checkpoint: makes the rows recorded so far visible under the file's name.
    fn publish(&mut self) -> Result<(), OutputError> {
        Ok(())
    }

    /// At the end of the run, finished or failed: writes the end-of-run files.
    fn finish(&mut self, sim: &Simulation) -> Result<(), OutputError> {
        let _ = sim;
        Ok(())
    }

    /// Adds the recorder's figures to `summary.json`.
    fn summarize(&self, sim: &Simulation, run: &RunFigures, summary: &mut serde_json::Value) {
        let _ = (sim, run, summary);
    }

    /// Writes what the recorder carries from step to step into a checkpoint.
    fn save(&self, out: &mut Encoder) {
        let _ = out;
    }

    /// Reads back what [`Recorder::save`] wrote.
    fn restore(&mut self, input: &mut Decoder<'_>) -> Result<(), CheckpointError> {
        let _ = input;
        Ok(())
    }
}

/// The recorders of `sim`'s outputs in `out_dir`, in the order they record and checkpoint.
pub(crate) fn register(sim: &Simulation, out_dir: &Path) -> Vec<Box<dyn Recorder>> {
    let mut recorders: Vec<Box<dyn Recorder>> = vec![Box::new(probes::Probes::new(sim, out_dir))];
    if sim
        .contacts()
        .is_some_and(|c| c.time_delay_state().is_some())
    {
        recorders.push(Box::new(boundary::Boundary::new(sim, out_dir)));
    }
    if !sim.scene.sections.is_empty() {
        recorders.push(Box::new(sections::Sections::new(sim, out_dir)));
    }
    if let Some(reactions) = reactions::Reactions::new(sim, out_dir) {
        recorders.push(Box::new(reactions));
    }
    if let Some(settlement) = settlement::Settlement::new(sim, out_dir) {
        recorders.push(Box::new(settlement));
    }
    if sim.contacts().is_some_and(|c| c.walls() > 0) {
        recorders.push(Box::new(walls::Walls::new(sim, out_dir)));
    }
    if !sim.scene.measures.is_empty() {
        recorders.push(Box::new(measures::Measures::new(sim, out_dir)));
    }
    recorders.push(Box::new(snapshots::Snapshots::new(sim, out_dir)));
    if sim.bonded().is_some() {
        recorders.push(Box::new(crack::Crack::new(out_dir)));
    }
    if sim.granular.is_some() {
        recorders.push(Box::new(stones::Stones::new(out_dir)));
    }
    if let Some(grading) = grading::Grading::new(sim, out_dir) {
        recorders.push(Box::new(grading));
    }
    if sim
        .bodies
        .iter()
        .any(|b| matches!(b.kind, crate::build::BodyKind::Rigid { .. }))
    {
        recorders.push(Box::new(poses::Poses::new(out_dir)));
    }
    recorders
}

/// Every recorder's history, each tagged with its name.
pub(crate) fn save_all(recorders: &[Box<dyn Recorder>], out: &mut Encoder) {
    for r in recorders {
        out.tag(r.name());
        r.save(out);
    }
}

/// Reads back what [`save_all`] wrote, into the same recorders.
pub(crate) fn restore_all(
    recorders: &mut [Box<dyn Recorder>],
    input: &mut Decoder<'_>,
) -> Result<(), CheckpointError> {
    for r in recorders.iter_mut() {
        input.tag(r.name())?;
        r.restore(input)?;
    }
    Ok(())
}

/// Writes `rows` (flat, `header.len()` values a row) under `header` to `path` as CSV, each
/// value to ten significant digits: the time-series files of the sections, walls and fixes.
/// Writes nothing when there is no row.
pub(crate) fn write_rows(path: &Path, header: &[String], rows: &[f64]) -> Result<(), OutputError> {
    if rows.is_empty() {
        return Ok(());
    }
    write_atomic(path, |w| {
        writeln!(w, "{}", header.join(","))?;
        for row in rows.chunks_exact(header.len()) {
            let cells: Vec<String> = row.iter().map(|v| format!("{v:.9e}")).collect();
            writeln!(w, "{}", cells.join(","))?;
        }
        Ok(())
    })
}
