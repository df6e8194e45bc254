//! What the run loop carries from step to step besides the simulation (the next step, the
//! output schedules, the probe rows written, the plot's history, the crack timings), and the
//! encoding of a whole run into a checkpoint body and back ([`crate::checkpoint`]).

use crate::build::Simulation;
use crate::output::PvdIndex;
use crate::runner::CrackTiming;
use qdem_core::checkpoint::same_count;
use qdem_core::{CheckpointError, CoreError, Decoder, Encoder, Stepper};

/// Samples that fall due every `every` seconds (to the nearest step), from `next` on.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Schedule {
    every: f64,
    next: f64,
}

impl Schedule {
    /// Due at t = 0, then every `every` seconds; never if `every` ≤ 0.
    pub(crate) fn new(every: f64) -> Schedule {
        Schedule { every, next: 0.0 }
    }

    /// Due first at t = `every`.
    pub(crate) fn after_start(every: f64) -> Schedule {
        Schedule { every, next: every }
    }

    /// Whether a sample is due at `time`, given the step `dt`; advances past it if so.
    pub(crate) fn due(&mut self, time: f64, dt: f64) -> bool {
        if self.every <= 0.0 || time < self.next - 0.5 * dt {
            return false;
        }
        // An interval far below the step (a checkpoint at every step) skips ahead at once,
        // and one below the rounding of `next` still advances it.
        let horizon = time + 0.5 * dt;
        let behind = (horizon - self.next) / self.every;
        if behind > 64.0 {
            self.next += behind.floor() * self.every;
        }
        while self.next <= horizon {
            self.next = (self.next + self.every).max(self.next.next_up());
        }
        true
    }
}

/// The run loop's own state.
pub(crate) struct RunRecord {
    /// The next step to process (0: the sample at the start).
    pub next_step: u64,
    pub probes: Schedule,
    pub vtu: Schedule,
    pub checkpoints: Schedule,
    pub pvd: PvdIndex,
    /// Rows in `probes.csv`.
    pub probe_rows: u64,
    /// Per probe and component, (time, displacement) for the plot.
    pub history: Vec<Vec<(f64, f64)>>,
    /// The time-delayed boundary's rows for `boundary.csv`.
    pub boundary_rows: Vec<[f64; 4]>,
    /// `sections.csv`'s rows, flat: the time, then each `[[section]]`'s force.
    pub section_rows: Vec<f64>,
    pub timing: CrackTiming,
}

impl RunRecord {
    /// The record of a run of `sim` that has not started.
    pub(crate) fn new(sim: &Simulation) -> RunRecord {
        let (run, output) = (&sim.scene.run, &sim.scene.output);
        RunRecord {
            next_step: 0,
            probes: Schedule::new(run.probe_every.unwrap_or(run.t_end / 1000.0)),
            vtu: Schedule::new(output.vtu_every),
            checkpoints: Schedule::after_start(output.checkpoint_every),
            pvd: PvdIndex::new(),
            probe_rows: 0,
            history: vec![Vec::new(); 3 * sim.probes.len()],
            boundary_rows: Vec::new(),
            section_rows: Vec::new(),
            timing: CrackTiming::default(),
        }
    }

    fn save(&self, out: &mut Encoder) {
        out.tag("run");
        out.u64(self.next_step);
        for s in [&self.probes, &self.vtu, &self.checkpoints] {
            out.f64(s.next);
        }
        out.u64(self.pvd.len() as u64);
        for (time, file) in self.pvd.entries() {
            out.f64(*time);
            out.str(file);
        }
        out.u64(self.probe_rows);
        out.u64(self.history.len() as u64);
        for series in &self.history {
            out.f64s(&series.iter().flat_map(|&(t, u)| [t, u]).collect::<Vec<_>>());
        }
        out.f64s(&self.boundary_rows.concat());
        out.f64s(&self.section_rows);
        let t = &self.timing;
        out.f64(t.before_seconds);
        out.u64(t.before_steps);
        out.f64(t.after_seconds);
        out.u64(t.after_steps);
    }

    /// Reads a record written by `save`; `fixed_histories` says that the number of probe
    /// histories must match this record's (false only to read past a record).
    fn restore(
        &mut self,
        input: &mut Decoder<'_>,
        fixed_histories: bool,
    ) -> Result<(), CheckpointError> {
        input.tag("run")?;
        self.next_step = input.u64("the next step")?;
        for s in [&mut self.probes, &mut self.vtu, &mut self.checkpoints] {
            s.next = input.f64("an output schedule")?;
        }
        for _ in 0..input.u64("the VTU count")? {
            let time = input.f64("a VTU time")?;
            self.pvd.push(time, input.str("a VTU file name")?);
        }
        self.probe_rows = input.u64("the probe rows")?;
        let series = input.u64("the probe histories")? as usize;
        if fixed_histories {
            same_count("probe histories", self.history.len(), series)?;
        } else {
            self.history = vec![Vec::new(); series];
        }
        for h in self.history.iter_mut() {
            let flat = input.f64s("a probe history")?;
            *h = flat.chunks_exact(2).map(|p| (p[0], p[1])).collect();
        }
        let rows = input.f64s("the boundary rows")?;
        self.boundary_rows = rows
            .chunks_exact(4)
            .map(|r| [r[0], r[1], r[2], r[3]])
            .collect();
        self.section_rows = input.f64s("the section rows")?;
        let t = &mut self.timing;
        t.before_seconds = input.f64("the crack timing")?;
        t.before_steps = input.u64("the crack timing")?;
        t.after_seconds = input.f64("the crack timing")?;
        t.after_steps = input.u64("the crack timing")?;
        Ok(())
    }
}

/// Reads past the run record at the start of a checkpoint body, leaving `input` at the state
/// (for `[run] start_from`, which takes only the state).
pub(crate) fn skip_record(input: &mut Decoder<'_>) -> Result<(), CheckpointError> {
    let mut record = RunRecord {
        next_step: 0,
        probes: Schedule::new(0.0),
        vtu: Schedule::new(0.0),
        checkpoints: Schedule::new(0.0),
        pvd: PvdIndex::new(),
        probe_rows: 0,
        history: Vec::new(),
        boundary_rows: Vec::new(),
        section_rows: Vec::new(),
        timing: CrackTiming::default(),
    };
    record.restore(input, false)
}

/// Fails, naming the first model or the stepper that cannot be checkpointed.
pub(crate) fn check_checkpointable(
    sim: &Simulation,
    stepper: &dyn Stepper,
) -> Result<(), CheckpointError> {
    if let Some(m) = sim.models.iter().find(|m| !m.checkpointable()) {
        return Err(CheckpointError::Unsupported {
            what: format!("model `{}`", m.name()),
        });
    }
    stepper.save(&mut Encoder::new())
}

/// The checkpoint body of a run: the record, the state, every model, the stepper (whose
/// resumption may refactorise with the models' restored tangents).
pub(crate) fn encode_run(
    sim: &Simulation,
    stepper: &dyn Stepper,
    record: &RunRecord,
) -> Result<Vec<u8>, CheckpointError> {
    let mut out = Encoder::new();
    record.save(&mut out);
    sim.state.save(&mut out);
    for m in &sim.models {
        out.tag(&format!("model {}", m.name()));
        m.save(&mut out);
    }
    stepper.save(&mut out)?;
    Ok(out.into_bytes())
}

/// Restores a run encoded by [`encode_run`] into a freshly built `sim`, its stepper and a
/// fresh record; the stepper is resumed, after the models, rather than initialised.
pub(crate) fn decode_run(
    body: &[u8],
    sim: &mut Simulation,
    stepper: &mut dyn Stepper,
    record: &mut RunRecord,
) -> Result<(), CoreError> {
    let mut input = Decoder::new(body);
    record.restore(&mut input, true)?;
    sim.state.restore(&mut input)?;
    for m in sim.models.iter_mut() {
        input.tag(&format!("model {}", m.name()))?;
        m.restore(&mut input)?;
    }
    stepper.resume(&mut sim.state, &mut sim.models, &mut input)?;
    if !input.is_done() {
        return Err(CheckpointError::Invalid {
            what: "end",
            detail: "bytes are left over after the last model".to_string(),
        }
        .into());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::Schedule;

    #[test]
    fn a_schedule_is_due_once_per_interval_and_at_every_step_when_the_interval_is_tiny() {
        let mut every_tenth = Schedule::new(0.1);
        let due = (0..=100)
            .filter(|&n| every_tenth.due(n as f64 * 0.01, 0.01))
            .count();
        assert_eq!(due, 11);
        let mut tiny = Schedule::after_start(1e-300);
        assert!((1..=1000).all(|n| tiny.due(n as f64 * 1e-3, 1e-3)));
        let mut never = Schedule::new(0.0);
        assert!(!never.due(0.0, 1e-3));
    }
}
