//! Speed versus error of a sphere packing against its time step: the granular benchmark's
//! lattice of spheres ([`crate::granular::Packing::lattice`]) dropped into its open box under
//! gravity, elastic (Hertz contacts F = 4/3 E* √R* δ^{3/2}, no dashpots, no friction), so
//! that the equations conserve the total energy
//! E = ½ Σ m v² + ½ Σ J ω² + Σ 8/15 E* √R* δ^{5/2} − Σ m g·x, stepped by velocity Verlet at
//! fractions of the Rayleigh time T_R = π r √(ρ/G)/(0.1631ν + 0.8766) (the DEM codes' rule:
//! LIGGGHTS recommends ∆t ≤ 0.2 T_R). Error measures: the energy drift max_t |E(t) − E(0)|
//! over the energy the fall can release, m g Σ (z_i − r) (reference: 0, the equations'
//! invariant), and the mean normal contact force over the second half of the run against the
//! run at the smallest step (the reference: a chaotic packing's forces do not converge
//! pointwise, their mean does).

use super::cpu::timed;
use super::{Size, StudyError};
use crate::granular::{rayleigh_time, Packing, RADIUS};
use qdem_contact::DemContacts;
use qdem_core::solvers::Verlet;
use qdem_core::step::{Model, State, Stepper};
use qdem_io::plot::{line_plot_svg, Labels, Series};
use std::path::Path;

/// The sweep: spheres, simulated seconds and steps as fractions of the Rayleigh time.
#[derive(Clone, Debug)]
pub struct Sweep {
    /// Spheres in the lattice.
    pub spheres: usize,
    /// Simulated seconds of each run.
    pub seconds: f64,
    /// ∆t / T_R of each run, in increasing order.
    pub fractions: Vec<f64>,
}

impl Sweep {
    /// The sweep of a size: 27 spheres for 0.03 s at 0.05, 0.2 and 0.8 T_R (quick, for the
    /// tests), or 1,000 spheres for 0.15 s at 0.025 to 0.8 T_R.
    pub fn of(size: Size) -> Sweep {
        match size {
            Size::Quick => Sweep {
                spheres: 27,
                seconds: 0.03,
                fractions: vec![0.05, 0.2, 0.8],
            },
            Size::Full => Sweep {
                spheres: 1000,
                seconds: 0.15,
                fractions: vec![0.025, 0.05, 0.1, 0.2, 0.4, 0.8],
            },
        }
    }
}

/// One run of the sweep.
#[derive(Clone, Debug)]
pub struct Row {
    /// ∆t / T_R.
    pub fraction: f64,
    /// Step (s).
    pub dt: f64,
    /// ∆t over the contacts' stable bound at the end of the run.
    pub of_bound: f64,
    /// Steps.
    pub steps: u64,
    /// CPU seconds of the run.
    pub cpu_seconds: f64,
    /// max |E(t) − E(0)| over m g Σ (z_i − r) at the start.
    pub drift: f64,
    /// Mean normal force of a touching contact over the run's second half (N).
    pub mean_force: f64,
}

/// Samples of the energy and the forces per run.
const SAMPLES: u64 = 300;

/// Runs the sweep.
pub fn run(sweep: &Sweep) -> Result<Vec<Row>, StudyError> {
    let packing = Packing::lattice(sweep.spheres);
    sweep
        .fractions
        .iter()
        .map(|&fraction| one(&packing, sweep.seconds, fraction))
        .collect()
}

fn one(packing: &Packing, seconds: f64, fraction: f64) -> Result<Row, StudyError> {
    let (mut state, mut models) = packing.build_elastic();
    let dt = fraction * rayleigh_time();
    let steps = (seconds / dt).ceil() as u64;
    let every = (steps / SAMPLES).max(1);
    let fall: f64 = (0..state.len())
        .map(|i| state.mass[i] * 9.81 * (state.position[i].z - RADIUS))
        .sum();
    let ((drift, mean_force), cpu_seconds) = timed(|| {
        let mut stepper = Verlet::new(dt);
        stepper.initialize(&mut state, &mut models)?;
        let start = energy(&state, &models);
        let (mut drift, mut forces) = (0.0f64, Vec::new());
        for step in 1..=steps {
            stepper.step(&mut state, &mut models)?;
            if step % every == 0 {
                drift = drift.max((energy(&state, &models) - start).abs());
                if 2 * step >= steps {
                    forces.push(mean_normal_force(contacts(&models)));
                }
            }
        }
        let mean = forces.iter().sum::<f64>() / forces.len().max(1) as f64;
        Ok((drift / fall, mean))
    })?;
    let bound = qdem_core::step::stepper::stable_step(&state, &models).map_or(f64::NAN, |b| b.0);
    Ok(Row {
        fraction,
        dt,
        of_bound: dt / bound,
        steps,
        cpu_seconds,
        drift,
        mean_force,
    })
}

/// Kinetic energy plus every model's potential energy (J).
fn energy(state: &State, models: &[Box<dyn Model>]) -> f64 {
    state.kinetic_energy()
        + models
            .iter()
            .filter_map(|m| m.potential_energy(state))
            .sum::<f64>()
}

/// The packing's contact model, which its builder puts first.
fn contacts(models: &[Box<dyn Model>]) -> &DemContacts {
    let model: &dyn std::any::Any = models[0].as_ref();
    model.downcast_ref::<DemContacts>().expect("contacts first")
}

/// Mean |normal force| over the touching contacts (0 when none touch).
fn mean_normal_force(contacts: &DemContacts) -> f64 {
    let (sum, count) = contacts.touching().fold((0.0, 0usize), |(s, n), c| {
        (s + c.normal_force.norm(), n + 1)
    });
    sum / count.max(1) as f64
}

/// The family's section of the page, and its figure `speed_vs_error_packing.svg` in
/// `figures`.
pub fn section(
    sweep: &Sweep,
    rows: &[Row],
    machine: &str,
    figures: &Path,
) -> Result<String, StudyError> {
    let reference = rows.first().ok_or_else(|| StudyError::Probes {
        path: figures.to_path_buf(),
        message: "the packing sweep ran no step".into(),
    })?;
    let force_error = |r: &Row| 100.0 * (r.mean_force / reference.mean_force - 1.0).abs();
    let mut table = String::new();
    for r in rows {
        table += &format!(
            "| {} | {:.3e} | {:.2} | {} | {:.2} | {:.3e} | {:.4e} | {:.2}% |\n",
            r.fraction,
            r.dt,
            r.of_bound,
            r.steps,
            r.cpu_seconds,
            r.drift,
            r.mean_force,
            force_error(r),
        );
    }
    let drift: Vec<(f64, f64)> = rows
        .iter()
        .map(|r| (r.cpu_seconds.max(0.01).log10(), r.drift.max(1e-16).log10()))
        .collect();
    line_plot_svg(
        &figures.join("speed_vs_error_packing.svg"),
        &Labels {
            title: "packing: energy drift against CPU time (each point a step fraction of T_R)",
            x: "log10(CPU seconds)",
            y: "log10(energy drift / fall energy)",
        },
        &[Series {
            label: "velocity Verlet, elastic Hertz contacts",
            points: &drift,
        }],
    )?;
    Ok(format!(
        "## A packing: the time step against energy drift and contact force\n\n\
         {spheres} spheres of the granular benchmark (r = 5 mm, E = 50 MPa, ν = 0.25, \
         ρ = 2700 kg/m³) on its loose lattice, dropped into the open box for {seconds} s under \
         gravity, elastic (no dashpots, no friction) so that the energy is an invariant; \
         velocity Verlet at fractions of the Rayleigh time T_R = {tr:.3e} s. Drift = \
         max |E(t) − E(0)| over the energy the fall releases (m g Σ (z − r)), sampled \
         {SAMPLES} times a run; the mean contact force (normal, per touching contact, over the \
         second half) against the run at {fine} T_R. `∆t / bound` is the step over qdem's \
         stable bound for the contacts at the run's end. {machine}.\n\n\
         | ∆t / T_R | ∆t (s) | ∆t / bound | steps | CPU s | energy drift | mean contact force (N) | vs {fine} T_R |\n\
         | --- | --- | --- | --- | --- | --- | --- | --- |\n{table}\n\
         ![packing: energy drift against CPU time](figures/speed_vs_error_packing.svg)\n",
        spheres = sweep.spheres,
        seconds = sweep.seconds,
        tr = rayleigh_time(),
        fine = reference.fraction,
    ))
}
