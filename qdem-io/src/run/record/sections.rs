//! [`Sections`]: `sections.csv`: every `probe_every`, the time and the average magnitude of
//! the contact forces across each `[[section]]` plane (N), one column per section
//! ([`qdem_contact::DemContacts::section_force`]); 0 in a scene where nothing can touch,
//! which builds no contact model.

use super::schedule::{probe_interval, Schedule};
use super::{Recorder, StateRead, StepInfo};
use crate::build::Simulation;
use crate::output::{write_atomic, OutputError};
use qdem_core::{CheckpointError, Decoder, Encoder};
use std::path::{Path, PathBuf};

/// The sections' record.
pub(crate) struct Sections {
    schedule: Schedule,
    path: PathBuf,
    names: Vec<String>,
    /// Each section's axis (0, 1, 2) and position.
    planes: Vec<(usize, f64)>,
    /// The rows, flat: the time, then each section's force.
    rows: Vec<f64>,
}

impl Sections {
    pub(crate) fn new(sim: &Simulation, out_dir: &Path) -> Sections {
        let sections = &sim.scene.sections;
        Sections {
            schedule: Schedule::new(probe_interval(sim)),
            path: out_dir.join("sections.csv"),
            names: sections.iter().map(|s| s.name.clone()).collect(),
            planes: sections
                .iter()
                .map(|s| ("xyz".find(&s.axis).expect("validated: x, y or z"), s.at))
                .collect(),
            rows: Vec::new(),
        }
    }
}

impl Recorder for Sections {
    fn name(&self) -> &'static str {
        "sections"
    }

    fn reads(&self, time: f64, dt: f64) -> StateRead {
        match self.schedule.is_due(time, dt) {
            true => StateRead::Whole,
            false => StateRead::Nothing,
        }
    }

    fn record(&mut self, sim: &Simulation, step: &StepInfo<'_>) -> Result<(), OutputError> {
        let time = sim.world.state.time;
        if !self.schedule.due(time, step.dt) {
            return Ok(());
        }
        let contacts = sim.contacts();
        self.rows.push(time);
        for &(axis, at) in &self.planes {
            self.rows
                .push(contacts.map_or(0.0, |c| c.section_force(axis, at)));
        }
        Ok(())
    }

    fn finish(&mut self, _sim: &Simulation) -> Result<(), OutputError> {
        if self.rows.is_empty() {
            return Ok(());
        }
        write_atomic(&self.path, |w| {
            writeln!(w, "time,{}", self.names.join(","))?;
            for row in self.rows.chunks_exact(self.names.len() + 1) {
                let cells: Vec<String> = row.iter().map(|v| format!("{v:.9e}")).collect();
                writeln!(w, "{}", cells.join(","))?;
            }
            Ok(())
        })
    }

    fn save(&self, out: &mut Encoder) {
        out.f64(self.schedule.next);
        out.f64s(&self.rows);
    }

    fn restore(&mut self, input: &mut Decoder<'_>) -> Result<(), CheckpointError> {
        self.schedule.next = input.f64("the section schedule")?;
        self.rows = input.f64s("the section rows")?;
        Ok(())
    }
}
