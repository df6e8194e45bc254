//! [`Settlement`]: `settlement.csv` and `settlement.svg`, for a scene with a `cyclic`
//! `[[load]]` and probes on particles: at each cycle's minimum (its start, Φ = −π/2) and its
//! maximum (half a period later) of each cyclic load, every probe's displacement along the
//! load's direction (`total_force` as a unit vector: positive where the load pushes, a
//! sleeper's settlement under a downward load), to the nearest step. One row per load and
//! cycle: `load` (the `[[load]]`'s number, from 1), `cycle` (from 1), `time_min`,
//! `time_max`, then `NAME.at_min` and `NAME.at_max` per probe, then `body` (the `[[body]]`
//! the load acts on); the plot draws them against the cycle number. The displacement at the
//! next cycle's minimum is the permanent settlement after a cycle; the difference between a
//! cycle's maximum and minimum is its resilient (elastic) part.
//!
//! The end of the run: an extremum is taken at the first step within half a step of it, so
//! one at `t_end` (a run of whole cycles) is taken at the last step. A cycle whose minimum
//! was taken but whose maximum falls after the last step still gets its row, after every
//! whole cycle's, with `NaN` for `time_max` and the `at_max` cells: its minimum is the
//! permanent settlement after the cycle before it. A cyclic `pressure` or `traction` load
//! (no `total_force`) gets no rows.

use super::{Recorder, StateRead, StepInfo};
use crate::build::Simulation;
use crate::output::{write_atomic, OutputError};
use crate::plot::{line_plot_svg, Labels, Series};
use qdem_core::{
    checkpoint::CheckpointError, checkpoint::Decoder, checkpoint::Encoder, loads::Cyclic, Vec3,
};
use std::path::{Path, PathBuf};

/// One cyclic load: its number, cycle, direction, and the time of its next extremum.
struct Load {
    /// The `[[load]]`'s number, from 1.
    number: usize,
    /// The `[[body]]` it acts on.
    body: String,
    cycle: Cyclic,
    /// Unit vector along `total_force`.
    direction: Vec3,
    /// Extrema passed: even at a minimum, odd at a maximum.
    passed: u64,
}

impl Load {
    /// The time of extremum `k` (k even: the minimum beginning cycle k/2 + 1).
    fn extremum(&self, k: u64) -> f64 {
        self.cycle.first_cycle_start() + 0.5 * k as f64 / self.cycle.frequency
    }
}

/// The settlement record.
pub(crate) struct Settlement {
    csv: PathBuf,
    svg: PathBuf,
    names: Vec<String>,
    loads: Vec<Load>,
    /// Rows, flat: load, cycle, time at the minimum, time at the maximum, then per probe
    /// the displacement at the minimum and at the maximum.
    rows: Vec<f64>,
    /// The row being filled per load: its minimum's time and displacements (`NaN` at the
    /// maximum); empty when no minimum waits for its maximum.
    pending: Vec<Vec<f64>>,
}

impl Settlement {
    /// The record of `sim`, if it has a cyclic load and probes on particles.
    pub(crate) fn new(sim: &Simulation, out_dir: &Path) -> Option<Settlement> {
        let loads: Vec<Load> = sim
            .scene
            .loads
            .iter()
            .enumerate()
            .filter_map(|(k, l)| {
                let force = Vec3::from(l.total_force);
                let cycle = l.cyclic?.cycle();
                (force.norm() > 0.0).then(|| Load {
                    number: k + 1,
                    body: l.body.clone(),
                    cycle,
                    direction: force.normalize(),
                    passed: 0,
                })
            })
            .collect();
        if loads.is_empty() || sim.probes.is_empty() {
            return None;
        }
        Some(Settlement {
            csv: out_dir.join("settlement.csv"),
            svg: out_dir.join("settlement.svg"),
            names: sim.probes.iter().map(|p| p.name.clone()).collect(),
            pending: vec![Vec::new(); loads.len()],
            loads,
            rows: Vec::new(),
        })
    }

    fn width(&self) -> usize {
        4 + 2 * self.names.len()
    }
}

impl Recorder for Settlement {
    fn name(&self) -> &'static str {
        "settlement"
    }

    fn reads(&self, time: f64, dt: f64) -> StateRead {
        let due = |l: &Load| time >= l.extremum(l.passed) - 0.5 * dt;
        StateRead::whole_if(self.loads.iter().any(due))
    }

    fn record(&mut self, sim: &Simulation, step: &StepInfo<'_>) -> Result<(), OutputError> {
        let s = &sim.world.state;
        let width = self.width();
        for (l, pending) in self.loads.iter_mut().zip(&mut self.pending) {
            while s.time >= l.extremum(l.passed) - 0.5 * step.dt {
                let along = sim
                    .probes
                    .iter()
                    .map(|p| s.displacement(p.particle).dot(&l.direction));
                if l.passed % 2 == 0 {
                    let cycle = (l.passed / 2 + 1) as f64;
                    *pending = vec![l.number as f64, cycle, s.time, f64::NAN];
                    pending.extend(along.flat_map(|u| [u, f64::NAN]));
                } else {
                    pending[3] = s.time;
                    for (k, u) in along.enumerate() {
                        pending[5 + 2 * k] = u;
                    }
                    debug_assert_eq!(pending.len(), width);
                    self.rows.append(pending);
                }
                l.passed += 1;
            }
        }
        Ok(())
    }

    fn finish(&mut self, _sim: &Simulation) -> Result<(), OutputError> {
        let rows = self.all_rows();
        if rows.is_empty() {
            return Ok(());
        }
        let width = self.width();
        write_atomic(&self.csv, |w| {
            let mut header: Vec<String> = ["load", "cycle", "time_min", "time_max"]
                .map(String::from)
                .to_vec();
            for n in &self.names {
                header.extend([format!("{n}.at_min"), format!("{n}.at_max")]);
            }
            header.push("body".to_string());
            writeln!(w, "{}", header.join(","))?;
            for row in rows.chunks_exact(width) {
                let mut cells = vec![format!("{}", row[0]), format!("{}", row[1])];
                cells.extend(row[2..].iter().map(|v| format!("{v:.9e}")));
                cells.push(self.body_of(row[0]).to_string());
                writeln!(w, "{}", cells.join(","))?;
            }
            Ok(())
        })?;
        self.plot(&rows)
    }

    fn save(&self, out: &mut Encoder) {
        for (l, pending) in self.loads.iter().zip(&self.pending) {
            out.u64(l.passed);
            out.f64s(pending);
        }
        out.f64s(&self.rows);
    }

    fn restore(&mut self, input: &mut Decoder<'_>) -> Result<(), CheckpointError> {
        for (l, pending) in self.loads.iter_mut().zip(&mut self.pending) {
            l.passed = input.u64("the extrema a cyclic load passed")?;
            *pending = input.f64s("a cycle's minimum")?;
        }
        self.rows = input.f64s("the settlement rows")?;
        Ok(())
    }
}

impl Settlement {
    /// The rows of the whole cycles, then per load the cycle whose minimum waits for its
    /// maximum, if any (its maximum `NaN`).
    fn all_rows(&self) -> Vec<f64> {
        let mut rows = self.rows.clone();
        for pending in &self.pending {
            rows.extend_from_slice(pending);
        }
        rows
    }

    /// The body of the load numbered `number` (a row's first cell).
    fn body_of(&self, number: f64) -> &str {
        let load = self.loads.iter().find(|l| l.number as f64 == number);
        load.map_or("", |l| l.body.as_str())
    }

    /// Each probe's displacement at the minima and at the maxima against the cycle number,
    /// per cyclic load.
    fn plot(&self, rows: &[f64]) -> Result<(), OutputError> {
        let width = self.width();
        let mut labels = Vec::new();
        let mut curves: Vec<Vec<(f64, f64)>> = Vec::new();
        for l in &self.loads {
            for (k, name) in self.names.iter().enumerate() {
                for (column, at) in [(4 + 2 * k, "min"), (5 + 2 * k, "max")] {
                    labels.push(format!("{name} at load {} {at}", l.number));
                    curves.push(
                        rows.chunks_exact(width)
                            .filter(|row| row[0] == l.number as f64 && row[column].is_finite())
                            .map(|row| (row[1], row[column]))
                            .collect(),
                    );
                }
            }
        }
        let series: Vec<Series<'_>> = labels
            .iter()
            .zip(&curves)
            .map(|(label, points)| Series { label, points })
            .collect();
        let labels = Labels {
            title: "displacement along the load at each cycle's extrema",
            x: "cycle",
            y: "displacement (m)",
        };
        line_plot_svg(&self.svg, &labels, &series)
    }
}
