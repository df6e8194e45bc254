//! Speed versus error of the box test (paper 003, docs/boxtest.md) against the contact
//! stiffness: the small periodic cell's bed (`fixtures/boxtest/small_deposit_cell_bed.toml`,
//! 110 stones) deposited once at 1 GPa, then the rigid sleeper rested on it and loaded
//! cyclically (40 kN at 3 Hz, between 7.5% and 100%) with the stones' and the sleeper's
//! Young's modulus E, which sets the Hertz–Mindlin contact stiffness
//! (F = 4/3 E* √R* δ^{3/2}) and the step (∆t ∝ E^{-1/2} at a given overlap). Measured: the
//! sleeper's settlement (its displacement at the last cycle's end, the load at its minimum,
//! from the load's start) and its resilient displacement (its rebound from the last peak of
//! the load to the cycle's end, the load back at its minimum), each against the stiffest run (the reference, closest
//! to granite's 50–70 GPa). For a fixed network of Hertz contacts the resilient displacement
//! goes as E^{-2/3}.

use super::cpu::timed;
use super::{Size, StudyError};
use crate::cantilever::{fixtures_dir, read_column};
use qdem_io::build::Simulation;
use qdem_io::plot::{line_plot_svg, Labels, Series};
use qdem_io::runner::run as run_scene;
use qdem_io::scene::Scene;
use std::path::{Path, PathBuf};

/// The load's frequency (Hz) and its start (s).
const FREQUENCY: f64 = 3.0;
const START: f64 = 0.05;

/// The sweep: Young's moduli and cycles.
#[derive(Clone, Debug)]
pub struct Sweep {
    /// Young's moduli of the stones and the sleeper (Pa), increasing; the last is the
    /// reference.
    pub youngs: Vec<f64>,
    /// Load cycles.
    pub cycles: usize,
}

impl Sweep {
    /// Quick: 0.25, 1 and 4 GPa, three cycles; full: 0.25 to 4 GPa by factors of 2, ten
    /// cycles (docs/boxtest.md's stiffness check).
    pub fn of(size: Size) -> Sweep {
        match size {
            Size::Quick => Sweep {
                youngs: vec![0.25e9, 1e9, 4e9],
                cycles: 3,
            },
            Size::Full => Sweep {
                youngs: vec![0.25e9, 0.5e9, 1e9, 2e9, 4e9],
                cycles: 10,
            },
        }
    }
}

/// One run of the sweep.
#[derive(Clone, Debug)]
pub struct Row {
    /// Young's modulus (Pa).
    pub young: f64,
    /// Step (s).
    pub dt: f64,
    /// Steps.
    pub steps: u64,
    /// CPU seconds of the loaded run (the shared deposition not counted).
    pub cpu_seconds: f64,
    /// Settlement at the last cycle's end (mm, downwards positive).
    pub settlement_mm: f64,
    /// Resilient displacement: the rebound from the last cycle's peak load to its end (mm).
    pub resilient_mm: f64,
}

/// Deposits the bed once and loads it at each modulus, the runs' outputs under `work`
/// (made absolute: the loaded scenes name the bed's `stones.csv`).
pub fn run(sweep: &Sweep, work: &Path) -> Result<Vec<Row>, StudyError> {
    std::fs::create_dir_all(work).map_err(|e| problem(work, e.to_string()))?;
    let work = work
        .canonicalize()
        .map_err(|e| problem(work, e.to_string()))?;
    let bed = work.join("bed");
    let mut scene = Scene::load(&boxtest().join("small_deposit_cell_bed.toml"))?;
    scene.output.vtu_every = 0.0;
    let mut sim = Simulation::build(scene)?;
    run_scene(&mut sim, &bed, &mut |_| {})?;
    sweep
        .youngs
        .iter()
        .map(|&young| loaded(young, sweep.cycles, &bed, &work.join(format!("E{young:e}"))))
        .collect()
}

fn boxtest() -> PathBuf {
    fixtures_dir().join("boxtest")
}

fn problem(path: &Path, message: String) -> StudyError {
    StudyError::Probes {
        path: path.to_path_buf(),
        message,
    }
}

/// The loaded cell: the sleeper rested on the bed in `bed`, `cycles` cycles at modulus
/// `young` (the scene of `small_single_periodic.toml` without the crib).
pub fn loaded_scene(young: f64, cycles: usize, bed: &Path) -> Result<Scene, StudyError> {
    let t_end = START + cycles as f64 / FREQUENCY;
    let stones = bed.join("stones.csv");
    let text = format!(
        r#"[run]
t_end = {t_end}
gravity = [0.0, 0.0, -9.81]
probe_every = 0.002

[[material]]
name = "granite"
density = 2600.0
young = {young:e}
poisson = 0.25

[[material]]
name = "concrete"
density = 2400.0
young = {young:e}
poisson = 0.2

[contact]
law = "hertz-mindlin"
friction = 0.6
damping_ratio = 0.0
local_damping = 0.7

[[body]]
name = "sleeper2"
mesh = "sleeper.msh"
material = "concrete"
rigid = true
contact_radius = 0.015
translate = [0.15, 1.05, 0.335]
rest_on = "ballast"

[[fix]]
body = "sleeper2"
box = [[-1.0, -10.0, -1.0], [1.0, 10.0, 1.0]]
dofs = "xy"
rotation = true

[[probe]]
name = "sleeper2"
body = "sleeper2"
point = [0.15, 1.05, 0.335]

[[load]]
body = "sleeper2"
box = [[-1.0, -10.0, -1.0], [1.0, 10.0, 1.0]]
total_force = [0.0, 0.0, -40e3]
cyclic = {{ min = 0.075, max = 1.0, frequency = {FREQUENCY}, phase_deg = 0.0, start = {START} }}

[granular]
name = "ballast"
material = "granite"
sample = "{stones}"
crop = [[0.0, -10.0, 0.0], [0.3, 10.0, 0.25]]

[[wall]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]

[[wall]]
point = [0.0, 0.0, 0.0]
normal = [1.0, 0.0, 0.0]

[[wall]]
point = [0.3, 0.0, 0.0]
normal = [-1.0, 0.0, 0.0]

[periodic]
axes = "y"
length = [0.7]
origin = [0.0, 0.7, 0.0]

[output]
vtu_every = 0.0
"#,
        stones = stones.display(),
    );
    Ok(Scene::parse(
        &text,
        &boxtest().join("speed_vs_error_cell.toml"),
    )?)
}

fn loaded(young: f64, cycles: usize, bed: &Path, out: &Path) -> Result<Row, StudyError> {
    let scene = loaded_scene(young, cycles, bed)?;
    let (report, cpu_seconds) = timed(|| {
        let mut sim = Simulation::build(scene)?;
        Ok(run_scene(&mut sim, out, &mut |_| {})?)
    })?;
    // (s, µm) of the sleeper's vertical displacement.
    let uz = read_column(&out.join("probes.csv"), "sleeper2.uz")?;
    let at = |t: f64| {
        uz.iter()
            .min_by(|a, b| (a.0 - t).abs().total_cmp(&(b.0 - t).abs()))
            .map_or(f64::NAN, |p| p.1)
    };
    let end = START + cycles as f64 / FREQUENCY;
    let peak = end - 0.5 / FREQUENCY;
    Ok(Row {
        young,
        dt: report.dt,
        steps: report.steps,
        cpu_seconds,
        settlement_mm: (at(START) - at(end)) * 1e-3,
        resilient_mm: (at(end) - at(peak)) * 1e-3,
    })
}

/// The family's section of the page, and its figure `speed_vs_error_boxtest.svg` in
/// `figures`.
pub fn section(
    sweep: &Sweep,
    rows: &[Row],
    machine: &str,
    figures: &Path,
) -> Result<String, StudyError> {
    let reference = rows
        .last()
        .ok_or_else(|| problem(figures, "the box test sweep ran nothing".into()))?;
    let error = |v: f64, r: f64| 100.0 * (v / r - 1.0);
    let mut table = String::new();
    for r in rows {
        table += &format!(
            "| {:.2} | {:.3e} | {} | {:.1} | {:.2} | {:+.1}% | {:.3} | {:+.1}% |\n",
            r.young * 1e-9,
            r.dt,
            r.steps,
            r.cpu_seconds,
            r.settlement_mm,
            error(r.settlement_mm, reference.settlement_mm),
            r.resilient_mm,
            error(r.resilient_mm, reference.resilient_mm),
        );
    }
    let settlement: Vec<(f64, f64)> = rows
        .iter()
        .map(|r| (r.cpu_seconds.max(0.01).log10(), r.settlement_mm))
        .collect();
    let resilient: Vec<(f64, f64)> = rows
        .iter()
        .map(|r| (r.cpu_seconds.max(0.01).log10(), r.resilient_mm))
        .collect();
    line_plot_svg(
        &figures.join("speed_vs_error_boxtest.svg"),
        &Labels {
            title: "box test: sleeper displacement against CPU time (E = 0.25 to 4 GPa)",
            x: "log10(CPU seconds)",
            y: "mm",
        },
        &[
            Series {
                label: "settlement after the last cycle",
                points: &settlement,
            },
            Series {
                label: "resilient displacement (rebound), last cycle",
                points: &resilient,
            },
        ],
    )?;
    Ok(format!(
        "## The box test: contact stiffness against settlement\n\n\
         The small periodic cell of [boxtest.md](boxtest.md) (`fixtures/boxtest/small_*`): its \
         bed of 110 stones deposited once at E = 1 GPa, then the rigid sleeper rested on it (no \
         crib) and loaded for {cycles} cycle(s) of 40 kN at 3 Hz with the stones' and the \
         sleeper's E set as below (Hertz–Mindlin: the contact stiffness goes as E, the step as \
         E^(-1/2)). Settlement = the sleeper's displacement at the last cycle's end from the \
         load's start; resilient = its rebound from the last peak load to the cycle's end \
         (E^(-2/3) for a fixed Hertz network). Reference: the stiffest run ({e_ref} GPa). One sample: docs/boxtest.md's \
         five samples spread by ±5 mm after 10 cycles. CPU seconds are the loaded run's (the \
         shared deposition not counted). {machine}.\n\n\
         | E (GPa) | ∆t (s) | steps | CPU s | settlement (mm) | vs {e_ref} GPa | resilient (mm) | vs {e_ref} GPa |\n\
         | --- | --- | --- | --- | --- | --- | --- | --- |\n{table}\n\
         ![box test: sleeper displacement against CPU time](figures/speed_vs_error_boxtest.svg)\n",
        cycles = sweep.cycles,
        e_ref = reference.young * 1e-9,
    ))
}
