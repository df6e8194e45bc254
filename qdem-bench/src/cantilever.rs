//! The paper's cantilever (paper 000 §3.1, Eqs. 12–13) as a measurable run: a scene run through
//! the normal run loop, its tip record read back from `probes.csv`, the steady deflection (mean
//! over 1–2 s) and the first bending frequency (FFT of the free vibration after release at 2 s).
//! Used by `qdem verify --full` and by the speed-versus-error study.

use qdem_io::build::{BuildError, Simulation};
use qdem_io::output::OutputError;
use qdem_io::runner::{run, RunError};
use qdem_io::scene::{Integrator, Scene, SceneError, TimeStep};
use qdem_io::spectrum::{amplitude_spectrum, dominant_frequency};
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Tip deflection of the converged 3D answer, CalculiX C3D10 (µm; shared/references).
pub const CALCULIX_TIP_UZ_UM: f64 = -92.651;
/// First vertical bending frequency, CalculiX C3D10 (Hz).
pub const CALCULIX_F1_HZ: f64 = 26.874;
/// Euler–Bernoulli tip deflection, Eq. 12 (µm).
pub const EQ12_TIP_UZ_UM: f64 = -92.322;
/// First bending frequency of Eq. 13 as the paper states it (Hz).
pub const EQ13_F1_HZ: f64 = 27.01;

/// Why a study run failed.
#[derive(Debug, Error)]
pub enum StudyError {
    /// The scene did not load.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// The scene could not be built.
    #[error(transparent)]
    Build(#[from] BuildError),
    /// The run failed.
    #[error(transparent)]
    Run(#[from] RunError),
    /// A run stepped by the library directly failed.
    #[error(transparent)]
    Core(#[from] qdem_core::error::CoreError),
    /// An output (a plot, a report) could not be written.
    #[error(transparent)]
    Output(#[from] OutputError),
    /// The probe record could not be read.
    #[error("{path}: {message}")]
    Probes {
        /// The CSV.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
}

/// What a cantilever run gives.
pub struct CantileverRun {
    /// Tetrahedra of the mesh.
    pub tets: usize,
    /// Steps taken.
    pub steps: u64,
    /// Step size (s).
    pub dt: f64,
    /// Steady tip deflection, mean over 1–2 s (µm).
    pub tip_uz_um: f64,
    /// First bending frequency from the FFT of the free vibration after 2 s (Hz).
    pub f1_hz: f64,
    /// Wall seconds of the run.
    pub wall_seconds: f64,
    /// Amplitude spectrum of the free vibration (Hz, µm).
    pub spectrum: Vec<(f64, f64)>,
}

/// Directory of the shipped fixtures.
pub fn fixtures_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join("fixtures")
}

/// The shipped cantilever scene of mesh size `lc` ("100", "070" or "050").
pub fn cantilever_scene(lc: &str) -> PathBuf {
    fixtures_dir()
        .join("cantilever")
        .join(format!("cantilever_lc{lc}.toml"))
}

/// The scene stepped by implicit average-acceleration Newmark at step `dt`, without VTU.
pub fn newmark_variant(scene: &Path, dt: f64) -> Result<Scene, StudyError> {
    let mut s = Scene::load(scene)?;
    s.run.integrator = Integrator::Newmark;
    s.run.beta = 0.25;
    s.run.gamma = 0.5;
    s.run.dt = TimeStep::Fixed(dt);
    s.output.vtu_every = 0.0;
    Ok(s)
}

/// Runs a cantilever scene through the normal run loop into `out` and reads its tip record
/// back from `probes.csv`.
pub fn cantilever(scene: Scene, out: &Path) -> Result<CantileverRun, StudyError> {
    let mut sim = Simulation::build(scene)?;
    let tets = sim.tets();
    let report = run(&mut sim, out, &mut |_| {})?;
    let csv = out.join("probes.csv");
    let rows = read_column(&csv, "tip.uz")?;
    let steady: Vec<f64> = rows
        .iter()
        .filter(|r| r.0 >= 1.0 && r.0 <= 2.0)
        .map(|r| r.1)
        .collect();
    let free: Vec<&(f64, f64)> = rows.iter().filter(|r| r.0 > 2.0).collect();
    // The sample spacing of the record itself: a step longer than probe_every samples each step.
    let spacing = match (free.first(), free.last()) {
        (Some(a), Some(b)) if free.len() > 1 => (b.0 - a.0) / (free.len() - 1) as f64,
        _ => f64::NAN,
    };
    let free: Vec<f64> = free.iter().map(|r| r.1).collect();
    Ok(CantileverRun {
        tets,
        steps: report.steps,
        dt: report.dt,
        tip_uz_um: steady.iter().sum::<f64>() / steady.len().max(1) as f64,
        f1_hz: dominant_frequency(&free, spacing).unwrap_or(f64::NAN),
        wall_seconds: report.wall_seconds,
        spectrum: amplitude_spectrum(&free, spacing),
    })
}

/// (t, value in µm) of one column of a probe CSV.
pub(crate) fn read_column(csv: &Path, name: &str) -> Result<Vec<(f64, f64)>, StudyError> {
    let problem = |message: String| StudyError::Probes {
        path: csv.to_path_buf(),
        message,
    };
    let text = std::fs::read_to_string(csv).map_err(|e| problem(e.to_string()))?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
    let column = header
        .iter()
        .position(|h| *h == name)
        .ok_or_else(|| problem(format!("no {name} column")))?;
    Ok(lines
        .map(|l| {
            let f: Vec<f64> = l
                .split(',')
                .map(|v| v.parse().unwrap_or(f64::NAN))
                .collect();
            (f[0], f.get(column).copied().unwrap_or(f64::NAN) * 1e6)
        })
        .collect())
}
