//! [`Boundary`]: `boundary.csv` of a time-delayed periodic boundary (paper 003 Eqs. 2–7):
//! every `probe_every`, the time, the measured average boundary force F_Ave and the left and
//! right ghost scales.

use super::schedule::{probe_interval, Schedule};
use super::{Recorder, StateRead, StepInfo};
use crate::build::Simulation;
use crate::output::{write_atomic, OutputError};
use qdem_core::{checkpoint::CheckpointError, checkpoint::Decoder, checkpoint::Encoder};
use std::path::{Path, PathBuf};

/// The time-delayed boundary's record.
pub(crate) struct Boundary {
    schedule: Schedule,
    path: PathBuf,
    rows: Vec<[f64; 4]>,
}

impl Boundary {
    pub(crate) fn new(sim: &Simulation, out_dir: &Path) -> Boundary {
        Boundary {
            schedule: Schedule::new(probe_interval(sim)),
            path: out_dir.join("boundary.csv"),
            rows: Vec::new(),
        }
    }
}

impl Recorder for Boundary {
    fn name(&self) -> &'static str {
        "boundary"
    }

    fn reads(&self, time: f64, dt: f64) -> StateRead {
        StateRead::whole_if(self.schedule.is_due(time, dt))
    }

    fn record(&mut self, sim: &Simulation, step: &StepInfo<'_>) -> Result<(), OutputError> {
        let time = sim.world.state.time;
        if !self.schedule.due(time, step.dt) {
            return Ok(());
        }
        if let Some((scales, force)) = sim.contacts().and_then(|c| c.time_delay_state()) {
            self.rows.push([time, force, scales.left, scales.right]);
        }
        Ok(())
    }

    fn finish(&mut self, _sim: &Simulation) -> Result<(), OutputError> {
        if self.rows.is_empty() {
            return Ok(());
        }
        write_atomic(&self.path, |w| {
            writeln!(w, "time,boundary_force,left_scale,right_scale")?;
            for r in &self.rows {
                writeln!(w, "{:.9e},{:.9e},{:.9e},{:.9e}", r[0], r[1], r[2], r[3])?;
            }
            Ok(())
        })
    }

    fn save(&self, out: &mut Encoder) {
        out.f64(self.schedule.next);
        out.f64s(&self.rows.concat());
    }

    fn restore(&mut self, input: &mut Decoder<'_>) -> Result<(), CheckpointError> {
        self.schedule.next = input.f64("the boundary schedule")?;
        let rows = input.f64s("the boundary rows")?;
        self.rows = rows
            .chunks_exact(4)
            .map(|r| [r[0], r[1], r[2], r[3]])
            .collect();
        Ok(())
    }
}
