//! [`Probes`]: `probes.csv` (each probe's displacement, velocity and acceleration every
//! `probe_every`, streamed) and, at the end, `probes.svg` (the displacements against time).

use super::schedule::{probe_interval, Schedule};
use super::{Recorder, RunFigures, StateRead, StepInfo};
use crate::build::Simulation;
use crate::output::{OutputError, ProbeCsv};
use crate::plot::{line_plot_svg, Labels, Series};
use qdem_core::checkpoint::same_count;
use qdem_core::{CheckpointError, Decoder, Encoder, Vec3};
use std::path::{Path, PathBuf};

/// The probes' record.
pub(crate) struct Probes {
    schedule: Schedule,
    names: Vec<String>,
    csv_path: PathBuf,
    svg_path: PathBuf,
    csv: Option<ProbeCsv>,
    /// Rows in `probes.csv`.
    rows: u64,
    /// Per probe and component, (time, displacement) for the plot.
    history: Vec<Vec<(f64, f64)>>,
}

impl Probes {
    pub(crate) fn new(sim: &Simulation, out_dir: &Path) -> Probes {
        let names: Vec<String> = sim.probes.iter().map(|p| p.name.clone()).collect();
        Probes {
            schedule: Schedule::new(probe_interval(sim)),
            history: vec![Vec::new(); 3 * names.len()],
            names,
            csv_path: out_dir.join("probes.csv"),
            svg_path: out_dir.join("probes.svg"),
            csv: None,
            rows: 0,
        }
    }
}

/// Displacement, velocity and acceleration of every probe's particle.
fn samples(sim: &Simulation) -> Vec<[Vec3; 3]> {
    let s = &sim.world.state;
    sim.probes
        .iter()
        .map(|p| {
            [
                s.displacement(p.particle),
                s.velocity[p.particle],
                s.acceleration[p.particle],
            ]
        })
        .collect()
}

impl Recorder for Probes {
    fn name(&self) -> &'static str {
        "probes"
    }

    fn start(&mut self, resumed: bool) -> Result<(), OutputError> {
        self.csv = Some(match resumed {
            true => ProbeCsv::resume(&self.csv_path, &self.names, self.rows as usize)?,
            false => ProbeCsv::create(&self.csv_path, &self.names)?,
        });
        Ok(())
    }

    fn reads(&self, time: f64, dt: f64) -> StateRead {
        match self.schedule.is_due(time, dt) {
            true => StateRead::Probes,
            false => StateRead::Nothing,
        }
    }

    fn record(&mut self, sim: &Simulation, step: &StepInfo<'_>) -> Result<(), OutputError> {
        let time = sim.world.state.time;
        if !self.schedule.due(time, step.dt) {
            return Ok(());
        }
        let samples = samples(sim);
        for (p, sample) in samples.iter().enumerate() {
            for (axis, u) in sample[0].iter().enumerate() {
                self.history[3 * p + axis].push((time, *u));
            }
        }
        self.csv
            .as_mut()
            .expect("started before recording")
            .row(time, &samples)?;
        self.rows += 1;
        Ok(())
    }

    fn publish(&mut self) -> Result<(), OutputError> {
        self.csv.as_mut().map_or(Ok(()), ProbeCsv::publish)
    }

    fn finish(&mut self, _sim: &Simulation) -> Result<(), OutputError> {
        if let Some(csv) = self.csv.take() {
            csv.finish()?;
        }
        if self.names.is_empty() {
            return Ok(());
        }
        plot(&self.svg_path, &self.names, &self.history)
    }

    fn summarize(&self, _sim: &Simulation, _run: &RunFigures, summary: &mut serde_json::Value) {
        summary["probe_rows"] = self.rows.into();
    }

    fn save(&self, out: &mut Encoder) {
        out.f64(self.schedule.next);
        out.u64(self.rows);
        out.u64(self.history.len() as u64);
        for series in &self.history {
            out.f64s(&series.iter().flat_map(|&(t, u)| [t, u]).collect::<Vec<_>>());
        }
    }

    fn restore(&mut self, input: &mut Decoder<'_>) -> Result<(), CheckpointError> {
        self.schedule.next = input.f64("the probe schedule")?;
        self.rows = input.u64("the probe rows")?;
        let series = input.u64("the probe histories")? as usize;
        same_count("probe histories", self.history.len(), series)?;
        for h in self.history.iter_mut() {
            let flat = input.f64s("a probe history")?;
            *h = flat.chunks_exact(2).map(|p| (p[0], p[1])).collect();
        }
        Ok(())
    }
}

/// Displacement of every probe against time, one curve per component.
fn plot(path: &Path, names: &[String], history: &[Vec<(f64, f64)>]) -> Result<(), OutputError> {
    let labels: Vec<String> = names
        .iter()
        .flat_map(|n| ["ux", "uy", "uz"].map(|c| format!("{n}.{c}")))
        .collect();
    let series: Vec<Series<'_>> = labels
        .iter()
        .zip(history)
        .map(|(label, points)| Series { label, points })
        .collect();
    let labels = Labels {
        title: "probe displacements",
        x: "t (s)",
        y: "displacement (m)",
    };
    line_plot_svg(path, &labels, &series)
}
