//! Speed versus error of the paper 001 §5 benchmark beam (`fixtures/bbm`, docs/bbm.md) before
//! it cracks: the 3 m × 0.5 m bonded concrete beam, pinned, under a line load ramped over
//! 0.25 s, run to a time before its first bond breaks. Each element size is stepped explicitly
//! (central differences, Newmark β = 0, at the paper's 0.2 ∆t_crit of Eq. 28) and implicitly
//! (average-acceleration Newmark, β = ¼, γ = ½) at several ∆t. Error: the largest midspan
//! deflection difference over the run, max_t |u(t) − u_ref(t)| / max_t |u_ref(t)| (the run
//! interpolated linearly at the reference's samples), against the explicit run on the finest
//! element size (the reference of docs/bbm.md's table), and against the explicit run of the
//! same element size (the integrator's share of it).

use super::cpu::timed;
use super::{Size, StudyError};
use crate::cantilever::{fixtures_dir, read_column};
use qdem_io::build::Simulation;
use qdem_io::plot::{line_plot_svg, Labels, Series};
use qdem_io::runner::run as run_scene;
use qdem_io::scene::{Scene, TimeStep};
use std::path::Path;

/// The sweep: element sizes, implicit steps and the simulated time.
#[derive(Clone, Debug)]
pub struct Sweep {
    /// Element sizes (m), coarsest first; the last is the reference's.
    pub sizes: Vec<f64>,
    /// Implicit steps (s), longest first.
    pub dts: Vec<f64>,
    /// Simulated seconds (before the first break).
    pub seconds: f64,
}

impl Sweep {
    /// Quick (the tests): 0.1 and 0.05 m to 0.05 s at ∆t = 5 and 1 ms; full: 0.1, 0.05 and
    /// 0.025 m to 0.2 s (docs/bbm.md's finest run breaks its first bond at 0.232 s) at 5, 2.5
    /// and 1 ms.
    pub fn of(size: Size) -> Sweep {
        match size {
            Size::Quick => Sweep {
                sizes: vec![0.1, 0.05],
                dts: vec![5e-3, 1e-3],
                seconds: 0.05,
            },
            Size::Full => Sweep {
                sizes: vec![0.1, 0.05, 0.025],
                dts: vec![5e-3, 2.5e-3, 1e-3],
                seconds: 0.2,
            },
        }
    }
}

/// One run of the sweep.
#[derive(Clone, Debug)]
pub struct Row {
    /// Element size (m).
    pub size: f64,
    /// `None` for the explicit run, else the implicit step (s).
    pub implicit_dt: Option<f64>,
    /// The step the run took (s).
    pub dt: f64,
    /// Steps.
    pub steps: u64,
    /// CPU seconds.
    pub cpu_seconds: f64,
    /// Midspan deflection history (s, µm).
    pub history: Vec<(f64, f64)>,
}

/// The benchmark beam at element size `size`, explicit (`dt` `None`) or implicit at `dt`, run
/// to `seconds`, probes only.
pub fn scene(size: f64, dt: Option<f64>, seconds: f64) -> Result<Scene, StudyError> {
    let fixture = match dt {
        None => "beam_explicit_0.05.toml",
        Some(_) => "beam_implicit_0.025.toml",
    };
    let mut s = Scene::load(&fixtures_dir().join("bbm").join(fixture))?;
    s.run.t_end = seconds;
    s.output.vtu_every = 0.0;
    if let Some(bonded) = s.bonded.as_mut() {
        bonded.element_size = size;
    }
    if let Some(dt) = dt {
        s.run.dt = TimeStep::Fixed(dt);
    }
    Ok(s)
}

/// Runs the sweep, each run's outputs under `work`.
pub fn run(sweep: &Sweep, work: &Path) -> Result<Vec<Row>, StudyError> {
    let mut rows = Vec::new();
    for &size in &sweep.sizes {
        let kinds = std::iter::once(None).chain(sweep.dts.iter().map(|&dt| Some(dt)));
        for implicit_dt in kinds {
            let name = match implicit_dt {
                None => format!("h{size}_explicit"),
                Some(dt) => format!("h{size}_implicit_{dt:e}"),
            };
            let scene = scene(size, implicit_dt, sweep.seconds)?;
            rows.push(one(scene, size, implicit_dt, &work.join(name))?);
        }
    }
    Ok(rows)
}

fn one(scene: Scene, size: f64, implicit_dt: Option<f64>, out: &Path) -> Result<Row, StudyError> {
    let (report, cpu_seconds) = timed(|| {
        let mut sim = Simulation::build(scene)?;
        Ok(run_scene(&mut sim, out, &mut |_| {})?)
    })?;
    Ok(Row {
        size,
        implicit_dt,
        dt: report.dt,
        steps: report.steps,
        cpu_seconds,
        history: read_column(&out.join("probes.csv"), "midspan.uy")?,
    })
}

/// max_t |u(t) − u_ref(t)| / max_t |u_ref(t)|, `run` interpolated at `reference`'s times
/// (those within `run`'s span).
///
/// ```
/// use qdem_bench::speed_vs_error::bbm::deviation;
/// let reference = [(0.0, 0.0), (1.0, -2.0), (2.0, -4.0)];
/// let run = [(0.0, 0.0), (2.0, -3.0)];
/// assert!((deviation(&run, &reference) - 0.25).abs() < 1e-12);
/// ```
pub fn deviation(run: &[(f64, f64)], reference: &[(f64, f64)]) -> f64 {
    let peak = reference.iter().map(|r| r.1.abs()).fold(0.0, f64::max);
    let worst = reference
        .iter()
        .filter_map(|&(t, u)| interpolate(run, t).map(|v| (v - u).abs()))
        .fold(0.0, f64::max);
    worst / peak
}

fn interpolate(series: &[(f64, f64)], t: f64) -> Option<f64> {
    let i = series.partition_point(|p| p.0 < t);
    match (i.checked_sub(1).and_then(|j| series.get(j)), series.get(i)) {
        (_, Some(b)) if b.0 == t => Some(b.1),
        (Some(a), Some(b)) => Some(a.1 + (b.1 - a.1) * (t - a.0) / (b.0 - a.0)),
        _ => None,
    }
}

/// The explicit run of element size `size`.
fn explicit(rows: &[Row], size: f64) -> Option<&Row> {
    rows.iter()
        .find(|r| r.size == size && r.implicit_dt.is_none())
}

/// Each run's deviation from the finest explicit run and from the explicit run of its own
/// element size, in `rows`' order.
pub fn deviations(rows: &[Row]) -> Vec<(f64, f64)> {
    let finest = rows.iter().map(|r| r.size).fold(f64::INFINITY, f64::min);
    let reference = explicit(rows, finest);
    rows.iter()
        .map(|r| {
            let against =
                |e: Option<&Row>| e.map_or(f64::NAN, |e| deviation(&r.history, &e.history));
            (against(reference), against(explicit(rows, r.size)))
        })
        .collect()
}

/// The family's section of the page, and its figure `speed_vs_error_bbm.svg` in `figures`.
pub fn section(rows: &[Row], machine: &str, figures: &Path) -> Result<String, StudyError> {
    let errors = deviations(rows);
    let finest = rows.iter().map(|r| r.size).fold(f64::INFINITY, f64::min);
    let mut table = String::new();
    for (r, (to_finest, to_own)) in rows.iter().zip(&errors) {
        let kind = match r.implicit_dt {
            None => "explicit".to_string(),
            Some(_) => "implicit".to_string(),
        };
        let peak = r.history.iter().map(|p| p.1.abs()).fold(0.0, f64::max);
        table += &format!(
            "| {} | {kind} | {:.3e} | {} | {:.2} | {:.2} | {:.3e} | {:.3e} |\n",
            r.size, r.dt, r.steps, r.cpu_seconds, peak, to_finest, to_own,
        );
    }
    let mut series: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    for (r, (to_finest, _)) in rows.iter().zip(&errors) {
        let label = match r.implicit_dt {
            None => "explicit, 0.2 dt_crit".to_string(),
            Some(dt) => format!("implicit Newmark, dt = {dt:e} s"),
        };
        let point = (r.cpu_seconds.max(0.01).log10(), to_finest.max(1e-6).log10());
        match series.iter_mut().find(|(l, _)| *l == label) {
            Some((_, points)) => points.push(point),
            None => series.push((label, vec![point])),
        }
    }
    let series: Vec<Series<'_>> = series
        .iter()
        .map(|(label, points)| Series { label, points })
        .collect();
    line_plot_svg(
        &figures.join("speed_vs_error_bbm.svg"),
        &Labels {
            title: "BBM beam: speed versus error (each curve: coarse to fine element size)",
            x: "log10(CPU seconds)",
            y: "log10(deviation from the finest explicit run)",
        },
        &series,
    )?;
    let seconds = rows
        .iter()
        .filter_map(|r| r.history.last().map(|p| p.0))
        .fold(0.0, f64::max);
    Ok(format!(
        "## The BBM beam: element size, ∆t, explicit or implicit\n\n\
         Paper 001 §5's beam (`fixtures/bbm`, [bbm.md](bbm.md)): 3 m × 0.5 m, pinned, 230 kN/m \
         ramped over 0.25 s, run to {seconds:.3} s, before its first bond breaks. Explicit at \
         0.2 ∆t_crit (Eq. 28) and implicit Newmark (β = ¼, γ = ½) at each element size. \
         Deviation = max |u(t) − u_ref(t)| / max |u_ref| of the midspan deflection, against \
         the explicit run at {finest} m (the finest) and against the explicit run of the same \
         element size (the integrator's own error). {machine}.\n\n\
         | element (m) | integrator | ∆t (s) | steps | CPU s | peak deflection (µm) | vs finest explicit | vs explicit, same size |\n\
         | --- | --- | --- | --- | --- | --- | --- | --- |\n{table}\n\
         ![BBM beam: deviation against CPU time](figures/speed_vs_error_bbm.svg)\n",
    ))
}
