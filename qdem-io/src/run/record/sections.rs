//! [`Sections`]: `sections.csv`: every `probe_every`, the time and the average magnitude of
//! the contact forces across each `[[section]]` plane (N), one column per section
//! ([`qdem_contact::DemContacts::section_force`]); 0 in a scene where nothing can touch,
//! which builds no contact model. A section with an `area` also has `NAME.stress`, the
//! normal stress through the plane (Pa, tension positive): the axis component of the forces
//! the touching pairs whose centres lie on either side (a periodic cell's plane repeating
//! every period) put on the partner below the plane, over the area ([`normal_stress`]).

use super::schedule::{probe_interval, Schedule};
use super::{write_rows, Recorder, StateRead, StepInfo};
use crate::build::Simulation;
use crate::output::OutputError;
use qdem_contact::{DemContacts, Partner};
use qdem_core::{checkpoint::CheckpointError, checkpoint::Decoder, checkpoint::Encoder};
use std::path::{Path, PathBuf};

/// The sections' record.
pub(crate) struct Sections {
    schedule: Schedule,
    path: PathBuf,
    names: Vec<String>,
    /// Each section's axis (0, 1, 2), position and area, if it has one.
    planes: Vec<(usize, f64, Option<f64>)>,
    /// The rows, flat: the time, then each section's force.
    rows: Vec<f64>,
}

impl Sections {
    pub(crate) fn new(sim: &Simulation, out_dir: &Path) -> Sections {
        let sections = &sim.scene.sections;
        Sections {
            schedule: Schedule::new(probe_interval(sim)),
            path: out_dir.join("sections.csv"),
            names: sections
                .iter()
                .flat_map(|s| {
                    let stress = s.area.map(|_| format!("{}.stress", s.name));
                    std::iter::once(s.name.clone()).chain(stress)
                })
                .collect(),
            planes: sections
                .iter()
                .map(|s| {
                    let axis = "xyz".find(&s.axis).expect("validated: x, y or z");
                    (axis, s.at, s.area)
                })
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
        StateRead::whole_if(self.schedule.is_due(time, dt))
    }

    fn record(&mut self, sim: &Simulation, step: &StepInfo<'_>) -> Result<(), OutputError> {
        let time = sim.world.state.time;
        if !self.schedule.due(time, step.dt) {
            return Ok(());
        }
        let contacts = sim.contacts();
        self.rows.push(time);
        let period = |axis| sim.periodic().and_then(|p| p.length(axis));
        for &(axis, at, area) in &self.planes {
            self.rows
                .push(contacts.map_or(0.0, |c| c.section_force(axis, at)));
            if let Some(area) = area {
                let force = contacts.map_or(0.0, |c| normal_force(c, axis, at, period(axis)));
                self.rows.push(force / area);
            }
        }
        Ok(())
    }

    fn finish(&mut self, _sim: &Simulation) -> Result<(), OutputError> {
        let header: Vec<String> = ["time".to_string()]
            .into_iter()
            .chain(self.names.iter().cloned())
            .collect();
        write_rows(&self.path, &header, &self.rows)
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

/// The axis component of the forces the touching sphere pairs of `contacts` that cross the
/// plane x[axis] = `at` (their centres, the second at the image it touches, on either side;
/// with a `period`, of the plane or a copy whole periods away) put on their partner below it
/// (N): negative when the two sides press on each other.
fn normal_force(contacts: &DemContacts, axis: usize, at: f64, period: Option<f64>) -> f64 {
    let mut sum = 0.0;
    for c in contacts.touching() {
        if !matches!(c.second, Partner::Sphere(_)) {
            continue;
        }
        let (a, b) = (c.from[axis] - at, c.to[axis] - at);
        // Whether the pair crosses the plane (or the copy just below the first centre and
        // the one above it), and whether the second centre lies above.
        let (crosses, second_above) = match period {
            Some(l) => {
                let below = (a / l).floor() * l;
                (b < below || b >= below + l, b >= below + l)
            }
            None => ((a < 0.0) != (b < 0.0), b >= 0.0),
        };
        if crosses {
            sum += match second_above {
                true => c.force()[axis] * c.scales.0,
                false => -c.force()[axis] * c.scales.1,
            };
        }
    }
    sum
}
