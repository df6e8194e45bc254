//! [`Crack`]: a bonded body's record (paper 001): the wall time of the steps before and after
//! the first broken bond (the t_b, t_u of Tables 1–2), the bonded figures of `summary.json`,
//! and at the end `crack.svg`, the crack pattern ([`crate::crack_svg`]).

use super::{Recorder, RunFigures, StepInfo};
use crate::build::Simulation;
use crate::crack_svg::write_crack_svg;
use crate::output::OutputError;
use qdem_core::{
    checkpoint::CheckpointError, checkpoint::Decoder, checkpoint::Encoder, step::Halt,
    step::StepCounts,
};
use serde_json::json;
use std::path::{Path, PathBuf};

/// Wall time per step before and after cracking starts, and the collapse that ended the run.
#[derive(Clone, Debug, Default)]
pub(crate) struct Crack {
    path: PathBuf,
    /// Seconds in steps that began with no bond broken.
    before_seconds: f64,
    /// Steps that began with no bond broken.
    before_steps: u64,
    /// Seconds in steps that began with bonds broken.
    after_seconds: f64,
    /// Steps that began with bonds broken.
    after_steps: u64,
    /// Whether a bond was broken at the last record (so before the next step).
    cracked: bool,
    /// Why the collapse watch ended the run.
    collapse: Option<Halt>,
    /// The stepper's counts at the start of the step in which the first bond broke (until
    /// then, at the start of the last step).
    at_crack: StepCounts,
}

impl Crack {
    pub(crate) fn new(out_dir: &Path) -> Crack {
        Crack {
            path: out_dir.join("crack.svg"),
            ..Crack::default()
        }
    }
}

impl Recorder for Crack {
    fn name(&self) -> &'static str {
        "crack"
    }

    fn record(&mut self, sim: &Simulation, step: &StepInfo<'_>) -> Result<(), OutputError> {
        if let Some(seconds) = step.seconds {
            if self.cracked {
                self.after_seconds += seconds;
                self.after_steps += 1;
            } else {
                self.before_seconds += seconds;
                self.before_steps += 1;
            }
        }
        if let Some(halt) = step.halt {
            self.collapse = Some(halt.clone());
        }
        self.cracked = sim.bonded().is_some_and(|b| b.broken() > 0);
        if !self.cracked {
            self.at_crack = sim.world.stepper().report().counts;
        }
        Ok(())
    }

    fn finish(&mut self, sim: &Simulation) -> Result<(), OutputError> {
        let model = sim.bonded().expect("registered for a bonded scene");
        write_crack_svg(&self.path, model, &sim.world.state)
    }

    fn summarize(&self, sim: &Simulation, run: &RunFigures, summary: &mut serde_json::Value) {
        let model = sim.bonded().expect("registered for a bonded scene");
        let per = |s: f64, n: u64| if n > 0 { s / n as f64 } else { 0.0 };
        let report = sim.world.stepper().report();
        let (counts, factor) = (report.counts, report.factor.as_ref());
        summary["bonded"] = json!({
            "bonds": model.bonds().len(),
            "broken_bonds": model.broken(),
            "first_break_time": model.broken_log().first().map(|b| b.0),
            "touching_pairs": model.touching(),
            "critical_step_eq28": model.initial_critical_step(),
            "stopped_at_collapse": self.collapse.as_ref().map(|h| json!({
                "time": h.time, "particle": h.particle, "displacement": h.value,
            })),
            "step_before_crack_seconds": per(self.before_seconds, self.before_steps),
            "step_after_crack_seconds": per(self.after_seconds, self.after_steps),
            "steps_before_crack": self.before_steps,
            "steps_after_crack": self.after_steps,
            "retakes": counts.retakes,
            "substeps": counts.substeps,
            "event_steps": counts.event_steps,
            "factorizations": counts.factorizations,
            "redos": counts.redos,
            "solves": counts.solves,
            "iterative_solves": counts.iterative_solves,
            "iterations": counts.iterations,
            "crack_phase_per_step": crack_phase(counts, self.at_crack, self.after_steps + 1),
            "factor_dofs": factor.map(|f| f.dofs),
            "factor_nonzeros": factor.map(|f| f.factor_nonzeros),
            "particle_steps_per_second": run.rate(sim.world.state.len()),
        });
    }

    fn save(&self, out: &mut Encoder) {
        out.f64(self.before_seconds);
        out.u64(self.before_steps);
        out.f64(self.after_seconds);
        out.u64(self.after_steps);
        out.bool(self.cracked);
        self.at_crack
            .to_array()
            .into_iter()
            .for_each(|n| out.u64(n));
    }

    fn restore(&mut self, input: &mut Decoder<'_>) -> Result<(), CheckpointError> {
        self.before_seconds = input.f64("the crack timing")?;
        self.before_steps = input.u64("the crack timing")?;
        self.after_seconds = input.f64("the crack timing")?;
        self.after_steps = input.u64("the crack timing")?;
        self.cracked = input.bool("the crack flag")?;
        let mut n = [0; StepCounts::LEN];
        for x in &mut n {
            *x = input.u64("the counts at the first break")?;
        }
        self.at_crack = StepCounts::from_array(n);
        Ok(())
    }
}

/// The stepper's work per nominal step of the crack phase (from the step in which the first
/// bond broke, `steps` steps): counts `now` less those at its start.
fn crack_phase(now: StepCounts, start: StepCounts, steps: u64) -> serde_json::Value {
    let per = |a: u64, b: u64| (a - b) as f64 / steps as f64;
    json!({
        "steps": steps,
        "retakes": per(now.retakes, start.retakes),
        "substeps": per(now.substeps, start.substeps),
        "redos": per(now.redos, start.redos),
        "solves": per(now.solves, start.solves),
        "factorizations": per(now.factorizations, start.factorizations),
        "iterative_solves": per(now.iterative_solves, start.iterative_solves),
        "iterations": per(now.iterations, start.iterations),
    })
}
