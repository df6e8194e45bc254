//! [`Walls`]: `walls.csv`: every `probe_every`, each `[[wall]]`'s total contact force (N, the
//! force the spheres exert on it: the reaction a support measures), read from the touching
//! contacts of the last evaluation ([`qdem_contact::DemContacts::touching`]), its
//! displacement from its place at t = 0 (m: a servo wall's as its servo moved it) and its
//! position (m, [`qdem_contact::DemContacts::wall_position`]: a plane's point, a mesh's
//! bounding-box centre), columns `wallK.fx, fy, fz, ux, uy, uz, x, y, z` for the K-th
//! `[[wall]]` (from 1, in scene order).

use super::schedule::{probe_interval, Schedule};
use super::{write_rows, Recorder, StateRead, StepInfo};
use crate::build::Simulation;
use crate::output::OutputError;
use qdem_contact::{DemContacts, Partner};
use qdem_core::{checkpoint::CheckpointError, checkpoint::Decoder, checkpoint::Encoder, Vec3};
use std::path::{Path, PathBuf};

/// The walls' record.
pub(crate) struct Walls {
    schedule: Schedule,
    path: PathBuf,
    walls: usize,
    /// The rows, flat: the time, then per wall its force, displacement and position.
    rows: Vec<f64>,
}

impl Walls {
    pub(crate) fn new(sim: &Simulation, out_dir: &Path) -> Walls {
        Walls {
            schedule: Schedule::new(probe_interval(sim)),
            path: out_dir.join("walls.csv"),
            walls: sim.contacts().map_or(0, DemContacts::walls),
            rows: Vec::new(),
        }
    }
}

/// The total force the touching spheres exert on each wall of `contacts` (N).
pub(crate) fn wall_forces(contacts: &DemContacts) -> Vec<Vec3> {
    let mut forces = vec![Vec3::zeros(); contacts.walls()];
    for c in contacts.touching() {
        if let Partner::Wall(w) = c.second {
            forces[w] -= c.force();
        }
    }
    forces
}

impl Recorder for Walls {
    fn name(&self) -> &'static str {
        "walls"
    }

    fn reads(&self, time: f64, dt: f64) -> StateRead {
        StateRead::whole_if(self.schedule.is_due(time, dt))
    }

    fn record(&mut self, sim: &Simulation, step: &StepInfo<'_>) -> Result<(), OutputError> {
        let time = sim.world.state.time;
        let Some(contacts) = sim.contacts() else {
            return Ok(());
        };
        if !self.schedule.due(time, step.dt) {
            return Ok(());
        }
        self.rows.push(time);
        for (w, force) in wall_forces(contacts).iter().enumerate() {
            let moved = contacts.wall_displacement(w, time);
            let at = contacts.wall_position(w, time);
            self.rows
                .extend(force.iter().chain(moved.iter()).chain(at.iter()));
        }
        Ok(())
    }

    fn finish(&mut self, _sim: &Simulation) -> Result<(), OutputError> {
        let mut header = vec!["time".to_string()];
        for k in 1..=self.walls {
            let columns = ["fx", "fy", "fz", "ux", "uy", "uz", "x", "y", "z"];
            header.extend(columns.map(|c| format!("wall{k}.{c}")));
        }
        write_rows(&self.path, &header, &self.rows)
    }

    fn save(&self, out: &mut Encoder) {
        out.f64(self.schedule.next);
        out.f64s(&self.rows);
    }

    fn restore(&mut self, input: &mut Decoder<'_>) -> Result<(), CheckpointError> {
        self.schedule.next = input.f64("the wall schedule")?;
        self.rows = input.f64s("the wall rows")?;
        Ok(())
    }
}
