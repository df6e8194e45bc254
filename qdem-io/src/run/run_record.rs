//! What the run loop carries from step to step besides the world and the recorders (the next
//! step, the checkpoint schedule), and the encoding of a whole run into a checkpoint body and
//! back ([`crate::checkpoint`]).
//!
//! A body is the run record as one block (the next step, the checkpoint schedule, then each
//! recorder's history tagged with its name: [`crate::run::record`]), then the world
//! ([`qdem_core::world::World::save`]: the state, every model, the stepper). The record is a block so
//! that `[run] start_from`, which takes only the state, can skip it whatever outputs the scene
//! that wrote it had.

use crate::build::Simulation;
use crate::run::record::schedule::Schedule;
use crate::run::record::{restore_all, save_all, Recorder};
use qdem_core::{
    checkpoint::CheckpointError, checkpoint::Decoder, checkpoint::Encoder, error::CoreError,
};

/// The run loop's own state.
pub(crate) struct RunRecord {
    /// The next step to process (0: the sample at the start).
    pub next_step: u64,
    /// When the next checkpoint is due.
    pub checkpoints: Schedule,
}

impl RunRecord {
    /// The record of a run of `sim` that has not started.
    pub(crate) fn new(sim: &Simulation) -> RunRecord {
        RunRecord {
            next_step: 0,
            checkpoints: Schedule::after_start(sim.scene.output.checkpoint_every),
        }
    }
}

/// Reads past the run record at the start of a checkpoint body, leaving `input` at the state
/// (for `[run] start_from`, which takes only the state).
pub(crate) fn skip_record(input: &mut Decoder<'_>) -> Result<(), CheckpointError> {
    input.block("the run record").map(|_| ())
}

/// The checkpoint body of a run: the record with the recorders' histories, then the world.
pub(crate) fn encode_run(
    sim: &Simulation,
    run: &RunRecord,
    recorders: &[Box<dyn Recorder>],
) -> Result<Vec<u8>, CheckpointError> {
    let mut record = Encoder::new();
    record.tag("run");
    record.u64(run.next_step);
    record.f64(run.checkpoints.next);
    save_all(recorders, &mut record);
    let mut out = Encoder::new();
    out.block(record.bytes());
    sim.world.save(&mut out)?;
    Ok(out.into_bytes())
}

/// Restores a run encoded by [`encode_run`] into a freshly built `sim`, a fresh record and
/// the recorders registered for it; the world's stepper is resumed rather than initialised.
pub(crate) fn decode_run(
    body: &[u8],
    sim: &mut Simulation,
    run: &mut RunRecord,
    recorders: &mut [Box<dyn Recorder>],
) -> Result<(), CoreError> {
    let mut input = Decoder::new(body);
    let mut record = Decoder::new(input.block("the run record")?);
    record.tag("run")?;
    run.next_step = record.u64("the next step")?;
    run.checkpoints.next = record.f64("the checkpoint schedule")?;
    restore_all(recorders, &mut record)?;
    done(&record, "the run record")?;
    sim.world
        .restore(&mut input, run.next_step.saturating_sub(1))?;
    done(&input, "the last model")?;
    Ok(())
}

/// Restores only the world of a run encoded by [`encode_run`] (a rank of a decomposed run
/// that writes no outputs); returns the next step.
pub(crate) fn decode_world(body: &[u8], sim: &mut Simulation) -> Result<u64, CoreError> {
    let mut input = Decoder::new(body);
    let mut record = Decoder::new(input.block("the run record")?);
    record.tag("run")?;
    let next_step = record.u64("the next step")?;
    sim.world.restore(&mut input, next_step.saturating_sub(1))?;
    done(&input, "the last model")?;
    Ok(next_step)
}

/// Fails if bytes are left after `what`.
fn done(input: &Decoder<'_>, what: &str) -> Result<(), CheckpointError> {
    if input.is_done() {
        return Ok(());
    }
    Err(CheckpointError::Invalid {
        what: "end",
        detail: format!("bytes are left over after {what}"),
    })
}
