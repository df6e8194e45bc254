//! [`Probes`]: `probes.csv` (each probe's displacement, velocity, acceleration and angular
//! velocity, then each box probe's mean velocity, kinetic energy and count of stones, every
//! `probe_every`, streamed) and, at the end, `probes.svg` (the displacements against time).
//!
//! The angular velocity ω (rad/s, world frame) is the rigid body's for a probe on a rigid
//! body's member or centre (a clump stone, a rigid `[[body]]`), the particle's own for a
//! particle that rotates (a one-sphere stone, a bonded particle), and NaN for a particle
//! without rotation (a deformable body's node: its material turns, the node carries none).
//!
//! A probe on a rigid body's member (a surface vertex, a clump's sphere) reads the rigid
//! motion's acceleration a_c + α × r + ω × (ω × r) ([`qdem_core::step::RigidBodies::point_acceleration`]):
//! a member carries no acceleration of its own. Reading it, or a box probe, needs the rigid
//! bodies' motion and every stone, so a decomposed run gathers its whole state for such a
//! sample instead of the probes' particles.

use super::schedule::{probe_interval, Schedule};
use super::{Recorder, RunFigures, StateRead, StepInfo};
use crate::build::probes::region_sample;
use crate::build::Simulation;
use crate::output::{OutputError, ProbeCsv, ProbeSample};
use crate::plot::{line_plot_svg, Labels, Series};
use qdem_core::checkpoint::same_count;
use qdem_core::step::State;
use qdem_core::{checkpoint::CheckpointError, checkpoint::Decoder, checkpoint::Encoder, Vec3};
use std::path::{Path, PathBuf};

/// The probes' record.
pub(crate) struct Probes {
    schedule: Schedule,
    names: Vec<String>,
    /// The box probes' names.
    regions: Vec<String>,
    /// Where each probe's angular velocity comes from.
    spins: Vec<Spin>,
    /// Whether a sample needs the whole state (module docs).
    whole: bool,
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
        let state = &sim.world.state;
        let spins: Vec<Spin> = sim
            .probes
            .iter()
            .map(|p| Spin::of(state, p.particle))
            .collect();
        let on_body = spins.iter().any(|s| matches!(s, Spin::Body(_)));
        Probes {
            schedule: Schedule::new(probe_interval(sim)),
            history: vec![Vec::new(); 3 * names.len()],
            names,
            regions: sim.regions.iter().map(|r| r.name.clone()).collect(),
            spins,
            whole: on_body || !sim.regions.is_empty(),
            csv_path: out_dir.join("probes.csv"),
            svg_path: out_dir.join("probes.svg"),
            csv: None,
            rows: 0,
        }
    }
}

/// Where a probe's angular velocity comes from (module docs).
#[derive(Clone, Copy, Debug)]
enum Spin {
    /// The rigid body's, of which the particle is the centre or a member.
    Body(usize),
    /// The particle's own rotational degrees of freedom.
    Particle,
    /// None: the particle does not rotate (NaN).
    None,
}

impl Spin {
    /// The source of particle `p`'s angular velocity in `state`.
    fn of(state: &State, p: usize) -> Spin {
        let rigid = &state.rigid;
        let body = rigid
            .body_of_member(p)
            .or_else(|| rigid.center.iter().position(|&c| c == p));
        match body {
            Some(b) => Spin::Body(b),
            None if state.spin.inertia.get(p).is_some_and(|&j| j > 0.0) => Spin::Particle,
            None => Spin::None,
        }
    }

    /// The angular velocity (rad/s) it reads of particle `p` in `state`.
    fn read(self, state: &State, p: usize) -> Vec3 {
        match self {
            Spin::Body(b) => state.rigid.angular_velocity[b],
            Spin::Particle => state.spin.velocity[p],
            Spin::None => Vec3::repeat(f64::NAN),
        }
    }
}

/// Displacement, velocity, acceleration and angular velocity of every probe's particle.
fn samples(sim: &Simulation, spins: &[Spin]) -> Vec<ProbeSample> {
    let s = &sim.world.state;
    sim.probes
        .iter()
        .zip(spins)
        .map(|(p, spin)| {
            [
                s.displacement(p.particle),
                s.velocity[p.particle],
                acceleration(sim, p.particle),
                spin.read(s, p.particle),
            ]
        })
        .collect()
}

/// The acceleration of particle `p`: its own, or a rigid body's member's from the body's motion.
fn acceleration(sim: &Simulation, p: usize) -> Vec3 {
    let s = &sim.world.state;
    let Some(b) = s.rigid.body_of_member(p) else {
        return s.acceleration[p];
    };
    let torque = sim.world.stepper().rigid_torques();
    let torque = torque.get(b).copied().unwrap_or_else(Vec3::zeros);
    let c = s.rigid.center[b];
    let arm = s.position[p] - s.position[c];
    s.rigid
        .point_acceleration(b, torque, s.acceleration[c], arm)
}

/// Every box probe's five values ([`region_sample`]).
fn region_samples(sim: &Simulation) -> Vec<[f64; 5]> {
    let Some(info) = &sim.granular else {
        return Vec::new();
    };
    sim.regions
        .iter()
        .map(|r| region_sample(r, info, &sim.world.state))
        .collect()
}

impl Recorder for Probes {
    fn name(&self) -> &'static str {
        "probes"
    }

    fn start(&mut self, resumed: bool) -> Result<(), OutputError> {
        let (path, names, regions) = (&self.csv_path, &self.names, &self.regions);
        self.csv = Some(match resumed {
            true => ProbeCsv::resume_with_regions(path, names, regions, self.rows as usize)?,
            false => ProbeCsv::with_regions(path, names, regions)?,
        });
        Ok(())
    }

    fn reads(&self, time: f64, dt: f64) -> StateRead {
        match (self.schedule.is_due(time, dt), self.whole) {
            (true, false) => StateRead::Probes,
            (true, true) => StateRead::Whole,
            (false, _) => StateRead::Nothing,
        }
    }

    fn record(&mut self, sim: &Simulation, step: &StepInfo<'_>) -> Result<(), OutputError> {
        let time = sim.world.state.time;
        if !self.schedule.due(time, step.dt) {
            return Ok(());
        }
        let samples = samples(sim, &self.spins);
        for (p, sample) in samples.iter().enumerate() {
            for (axis, u) in sample[0].iter().enumerate() {
                self.history[3 * p + axis].push((time, *u));
            }
        }
        self.csv
            .as_mut()
            .expect("started before recording")
            .row_with_regions(time, &samples, &region_samples(sim))?;
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
