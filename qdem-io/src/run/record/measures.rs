//! [`Measures`]: per `[[measure]]`, `measure_NAME.csv` (every `every`: the contact stress
//! tensor, solid fraction, porosity, coordination number and kinetic energy of the stones in
//! its region, [`crate::post::contact_stress`]) and, at the end, `measure_NAME.svg` (the
//! normal stresses against time) and `measure_NAME_energy.svg` (the kinetic energy: when
//! has a pour settled). A region with `follow_wall` is translated by that wall's
//! displacement at each row ([`qdem_contact::DemContacts::wall_displacement`], the same on
//! every rank of a decomposed run).

use super::schedule::{probe_interval, Schedule};
use super::{Recorder, StateRead, StepInfo};
use crate::build::Simulation;
use crate::output::{write_atomic, OutputError};
use crate::plot::{line_plot_svg, Labels, Series};
use crate::post::contact_stress::{measure, Measurement, Stones};
use crate::scene::MeasureRegion;
use qdem_core::checkpoint::same_count;
use qdem_core::{checkpoint::CheckpointError, checkpoint::Decoder, checkpoint::Encoder};
use std::path::{Path, PathBuf};

/// The columns of `measure_NAME.csv` after `time`.
const COLUMNS: [&str; 14] = [
    "sxx",
    "syy",
    "szz",
    "syz",
    "sxz",
    "sxy",
    "mean_stress",
    "solid_fraction",
    "porosity",
    "coordination",
    "stones",
    "contacts",
    "ke_translation",
    "ke_rotation",
];

/// One `[[measure]]`'s record.
struct One {
    name: String,
    region: MeasureRegion,
    /// The wall the region moves with (from 0).
    follow: Option<usize>,
    schedule: Schedule,
    /// The rows, flat: the time, then [`COLUMNS`].
    rows: Vec<f64>,
}

/// Every `[[measure]]`'s record.
pub(crate) struct Measures {
    out_dir: PathBuf,
    stones: Option<Stones>,
    measures: Vec<One>,
}

impl Measures {
    pub(crate) fn new(sim: &Simulation, out_dir: &Path) -> Measures {
        let scene = &sim.scene;
        let density = scene
            .refs()
            .granular_material
            .map(|m| scene.materials[m].density);
        let stones = sim
            .granular
            .as_ref()
            .zip(density)
            .map(|(g, rho)| Stones::new(&g.stones, &sim.world.state.mass, rho));
        let measures = scene
            .measures
            .iter()
            .map(|m| One {
                name: m.name.clone(),
                region: m.shape(),
                follow: m.follow_wall.map(|k| k - 1),
                schedule: Schedule::new(m.every.unwrap_or_else(|| probe_interval(sim))),
                rows: Vec::new(),
            })
            .collect();
        Measures {
            out_dir: out_dir.to_path_buf(),
            stones,
            measures,
        }
    }
}

/// A measurement as the row's cells after the time, in [`COLUMNS`] order.
fn cells(m: &Measurement) -> [f64; 14] {
    let s = &m.stress;
    [
        s[(0, 0)],
        s[(1, 1)],
        s[(2, 2)],
        s[(1, 2)],
        s[(0, 2)],
        s[(0, 1)],
        s.trace() / 3.0,
        m.solid_fraction,
        1.0 - m.solid_fraction,
        m.coordination,
        m.stones as f64,
        m.contacts as f64,
        m.translation_energy,
        m.rotation_energy,
    ]
}

impl Recorder for Measures {
    fn name(&self) -> &'static str {
        "measures"
    }

    fn reads(&self, time: f64, dt: f64) -> StateRead {
        StateRead::whole_if(self.measures.iter().any(|m| m.schedule.is_due(time, dt)))
    }

    fn record(&mut self, sim: &Simulation, step: &StepInfo<'_>) -> Result<(), OutputError> {
        let state = &sim.world.state;
        let (Some(stones), Some(contacts)) = (&self.stones, sim.contacts()) else {
            return Ok(());
        };
        for m in &mut self.measures {
            if m.schedule.due(state.time, step.dt) {
                let region = match m.follow {
                    Some(w) => m
                        .region
                        .shifted(contacts.wall_displacement(w, state.time).into()),
                    None => m.region,
                };
                m.rows.push(state.time);
                m.rows
                    .extend(cells(&measure(&region, stones, contacts, state)));
            }
        }
        Ok(())
    }

    fn finish(&mut self, _sim: &Simulation) -> Result<(), OutputError> {
        for m in &self.measures {
            if m.rows.is_empty() {
                continue;
            }
            let path = self.out_dir.join(format!("measure_{}.csv", m.name));
            write_atomic(&path, |w| {
                writeln!(w, "time,{}", COLUMNS.join(","))?;
                for row in m.rows.chunks_exact(COLUMNS.len() + 1) {
                    let cells: Vec<String> = row.iter().map(|v| format!("{v:.9e}")).collect();
                    writeln!(w, "{}", cells.join(","))?;
                }
                Ok(())
            })?;
            plot(&self.out_dir, m)?;
        }
        Ok(())
    }

    fn save(&self, out: &mut Encoder) {
        out.u64(self.measures.len() as u64);
        for m in &self.measures {
            out.f64(m.schedule.next);
            out.f64s(&m.rows);
        }
    }

    fn restore(&mut self, input: &mut Decoder<'_>) -> Result<(), CheckpointError> {
        let count = input.u64("the measures")? as usize;
        same_count("measures", self.measures.len(), count)?;
        for m in &mut self.measures {
            m.schedule.next = input.f64("a measure schedule")?;
            m.rows = input.f64s("a measure's rows")?;
        }
        Ok(())
    }
}

/// The column `k` of [`COLUMNS`] of `m`'s rows against time.
fn series(m: &One, k: usize) -> Vec<(f64, f64)> {
    m.rows
        .chunks_exact(COLUMNS.len() + 1)
        .map(|row| (row[0], row[k + 1]))
        .collect()
}

/// `measure_NAME.svg` (σxx, σyy, σzz) and `measure_NAME_energy.svg` (kinetic energy).
fn plot(dir: &Path, m: &One) -> Result<(), OutputError> {
    let stresses: Vec<Vec<(f64, f64)>> = (0..3).map(|k| series(m, k)).collect();
    let names = ["σxx", "σyy", "σzz"];
    let curves: Vec<Series<'_>> = names
        .iter()
        .zip(&stresses)
        .map(|(label, points)| Series { label, points })
        .collect();
    let title = format!("contact stress in {} (tension positive)", m.name);
    let labels = Labels {
        title: &title,
        x: "t (s)",
        y: "stress (Pa)",
    };
    line_plot_svg(
        &dir.join(format!("measure_{}.svg", m.name)),
        &labels,
        &curves,
    )?;
    let energy: Vec<Vec<(f64, f64)>> = (12..14).map(|k| series(m, k)).collect();
    let names = ["translation", "rotation"];
    let curves: Vec<Series<'_>> = names
        .iter()
        .zip(&energy)
        .map(|(label, points)| Series { label, points })
        .collect();
    let title = format!("kinetic energy in {}", m.name);
    let labels = Labels {
        title: &title,
        x: "t (s)",
        y: "kinetic energy (J)",
    };
    line_plot_svg(
        &dir.join(format!("measure_{}_energy.svg", m.name)),
        &labels,
        &curves,
    )
}
