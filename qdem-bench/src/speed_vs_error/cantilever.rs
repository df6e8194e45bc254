//! Speed versus error of the cantilever's dynamic response (paper 000 §3.1: ramp to 200 N over
//! 1 s, hold, release at 2 s, run to 3 s): on each mesh, explicit Verlet at the automatic step
//! and implicit Newmark (average acceleration, paper 001) at several ∆t. Each run's steady tip
//! deflection and first frequency are compared with the finest-mesh explicit run, with
//! CalculiX C3D10 and with Eqs. 12–13, against its CPU seconds; its section of
//! `speed-vs-error.md` has two SVG plots.

use super::cpu::timed;
use crate::cantilever::{
    cantilever, cantilever_scene, newmark_variant, StudyError, CALCULIX_F1_HZ, CALCULIX_TIP_UZ_UM,
    EQ12_TIP_UZ_UM, EQ13_F1_HZ,
};
use qdem_io::plot::{line_plot_svg, Labels, Series};
use qdem_io::scene::Scene;
use std::path::Path;

/// One run of the study.
#[derive(Clone, Debug)]
pub struct StudyRow {
    /// Mesh size label ("100" = lc 0.100 m).
    pub mesh: String,
    /// Tetrahedra.
    pub tets: usize,
    /// "verlet" or "newmark".
    pub integrator: &'static str,
    /// Step (s).
    pub dt: f64,
    /// Steps.
    pub steps: u64,
    /// CPU seconds of the run (all threads).
    pub cpu_seconds: f64,
    /// Steady tip deflection (µm).
    pub tip_uz_um: f64,
    /// First bending frequency (Hz).
    pub f1_hz: f64,
}

/// Runs every mesh with explicit Verlet and with implicit Newmark at each of `newmark_dts`,
/// writing the runs' outputs under `work`.
pub fn run_study(
    meshes: &[&str],
    newmark_dts: &[f64],
    work: &Path,
) -> Result<Vec<StudyRow>, StudyError> {
    let mut rows = Vec::new();
    for &mesh in meshes {
        let scene = cantilever_scene(mesh);
        let mut explicit = Scene::load(&scene)?;
        explicit.output.vtu_every = 0.0;
        rows.push(row(
            mesh,
            "verlet",
            explicit,
            &work.join(format!("lc{mesh}_verlet")),
        )?);
        for &dt in newmark_dts {
            let dir = work.join(format!("lc{mesh}_newmark_{dt:e}"));
            rows.push(row(mesh, "newmark", newmark_variant(&scene, dt)?, &dir)?);
        }
    }
    Ok(rows)
}

fn row(
    mesh: &str,
    integrator: &'static str,
    scene: Scene,
    out: &Path,
) -> Result<StudyRow, StudyError> {
    let (r, cpu_seconds) = timed(|| cantilever(scene, out))?;
    Ok(StudyRow {
        mesh: mesh.to_string(),
        tets: r.tets,
        integrator,
        dt: r.dt,
        steps: r.steps,
        cpu_seconds,
        tip_uz_um: r.tip_uz_um,
        f1_hz: r.f1_hz,
    })
}

fn error(value: f64, reference: f64) -> f64 {
    100.0 * (value / reference - 1.0).abs()
}

/// The cantilever's section of the page, its plots written into `figures`; the reference of
/// "finest mesh" is the explicit run on the mesh with the most tetrahedra.
pub fn section(rows: &[StudyRow], machine: &str, figures: &Path) -> Result<String, StudyError> {
    let finest = rows
        .iter()
        .filter(|r| r.integrator == "verlet")
        .max_by_key(|r| r.tets)
        .cloned()
        .ok_or_else(|| StudyError::Probes {
            path: figures.to_path_buf(),
            message: "no explicit run".into(),
        })?;
    let mut table = String::new();
    for r in rows {
        table += &format!(
            "| {} | {} | {} | {:.3e} | {} | {:.1} | {:.4} | {:.3}% | {:.2}% | {:.2}% | {:.3} | {:.3}% | {:.2}% | {:.2}% |\n",
            r.mesh, r.tets, r.integrator, r.dt, r.steps, r.cpu_seconds, r.tip_uz_um,
            error(r.tip_uz_um, finest.tip_uz_um), error(r.tip_uz_um, CALCULIX_TIP_UZ_UM), error(r.tip_uz_um, EQ12_TIP_UZ_UM),
            r.f1_hz, error(r.f1_hz, finest.f1_hz), error(r.f1_hz, CALCULIX_F1_HZ), error(r.f1_hz, EQ13_F1_HZ),
        );
    }
    plot(
        rows,
        &figures.join("speed_vs_error_tip.svg"),
        "tip deflection error against CalculiX (%)",
        |r| error(r.tip_uz_um, CALCULIX_TIP_UZ_UM),
    )?;
    plot(
        rows,
        &figures.join("speed_vs_error_f1.svg"),
        "f1 error against the finest-mesh explicit run (%)",
        |r| error(r.f1_hz, finest.f1_hz),
    )?;
    Ok(format!(
        "## The cantilever: mesh and integrator\n\n\
         The paper's cantilever (§3.1): 200 N ramped over 1 s, held, released at 2 s, run to 3 s. \
         On each fixture mesh, explicit Verlet at 0.9 × the stable bound and implicit Newmark \
         (β = ¼, γ = ½, paper 001) at several ∆t. Tip deflection = mean over 1–2 s; f₁ = FFT of \
         the free vibration after release. References: the finest-mesh explicit run ({} tets: \
         {:.4} µm, {:.3} Hz), CalculiX C3D10 ({CALCULIX_TIP_UZ_UM} µm, {CALCULIX_F1_HZ} Hz) and \
         Eqs. 12–13 ({EQ12_TIP_UZ_UM} µm, {EQ13_F1_HZ} Hz). {machine}; CPU seconds include \
         writing the probe CSV.\n\n\
         | mesh lc | tets | integrator | ∆t (s) | steps | CPU s | tip uz (µm) | vs finest | vs CalculiX | vs Eq. 12 | f₁ (Hz) | vs finest | vs CalculiX | vs Eq. 13 |\n\
         | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n{table}\n\
         ![tip error against CPU time](figures/speed_vs_error_tip.svg)\n\
         ![frequency error against CPU time](figures/speed_vs_error_f1.svg)\n",
        finest.tets, finest.tip_uz_um, finest.f1_hz,
    ))
}

/// One series per integrator and step: `measure` against log₁₀ of the CPU seconds.
fn plot(
    rows: &[StudyRow],
    path: &Path,
    y: &str,
    measure: impl Fn(&StudyRow) -> f64,
) -> Result<(), StudyError> {
    let mut keys: Vec<(&'static str, f64)> = Vec::new();
    for r in rows {
        let key = (
            r.integrator,
            if r.integrator == "verlet" { 0.0 } else { r.dt },
        );
        if !keys.contains(&key) {
            keys.push(key);
        }
    }
    let labels: Vec<String> = keys
        .iter()
        .map(|(i, dt)| {
            if *i == "verlet" {
                "explicit Verlet, auto dt".to_string()
            } else {
                format!("implicit Newmark, dt = {dt:e} s")
            }
        })
        .collect();
    let points: Vec<Vec<(f64, f64)>> = keys
        .iter()
        .map(|(i, dt)| {
            rows.iter()
                .filter(|r| r.integrator == *i && (*i == "verlet" || r.dt == *dt))
                .map(|r| (r.cpu_seconds.max(0.01).log10(), measure(r)))
                .collect()
        })
        .collect();
    let series: Vec<Series<'_>> = labels
        .iter()
        .zip(&points)
        .map(|(label, points)| Series { label, points })
        .collect();
    let labels = Labels {
        title: "cantilever: speed versus error (each curve: lc 0.10, 0.07, 0.05)",
        x: "log10(CPU seconds)",
        y,
    };
    Ok(line_plot_svg(path, &labels, &series)?)
}
