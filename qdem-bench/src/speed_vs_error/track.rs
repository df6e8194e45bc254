//! Speed versus error of the reduced ballasted track at the paper's stiffness (paper 000 §4,
//! docs/ballast.md, "Forming rigid, loading deformable"): the bed poured and consolidated
//! with rigid stones once (`stiff_deposit_rigid.toml`, `stiff_consolidate_rigid.toml`,
//! cached: [`bed`]), then loaded by the first axle (`stiff_load_from_rigid.toml`, to
//! [`Sweep::window`]) with the stones deformable or rigid and the linear contact at Table 1's
//! stiffness or softer. Measured: the sleeper's rail-seat sensor S2 (vertical) at 0.10 s and
//! at the window's end, and the peaks of its vertical acceleration's linear spectrum,
//! Parzen-smoothed over 20 Hz as paper 000 §4.2 (`qdem_io::linear_spectrum`), in the bands of
//! the sleeper's rigid mode and first three bending modes on the bed; each against the
//! reference variant (deformable stones, Table 1's stiffness).
//!
//! What a softer contact buys, checked on one stone of the bed at rest on the ground
//! ([`stone_at_rest`]):
//! - the step a linear contact allows is that of its oscillator, ∆t = 2/ω with
//!   ω = √(k_n/m): ∆t ∝ k_n^(-1/2), twice as long for k_n/4, unless another bound (a
//!   deformable stone's tetrahedra) is shorter;
//! - a body of weight W at rest on n contacts carries Σ k_n δ_i = W: their mean overlap is
//!   δ̄ = W/(n k_n), four times deeper for k_n/4, whatever the stone's own stiffness.

use super::cpu::timed;
use super::{Size, StudyError};
use crate::cantilever::{fixtures_dir, read_column};
use qdem_core::step::Model as _;
use qdem_io::build::Simulation;
use qdem_io::linear_spectrum::{linear_spectrum, parzen_smooth};
use qdem_io::output::write_atomic;
use qdem_io::plot::{line_plot_svg, Labels, Series};
use qdem_io::runner::run as run_scene;
use qdem_io::scene::Scene;
use std::path::{Path, PathBuf};

/// The forming scenes, in order: the pour, then the stabiliser's pass from its checkpoint.
pub const FORMING: [&str; 2] = ["stiff_deposit_rigid.toml", "stiff_consolidate_rigid.toml"];
/// The loading scene the variants change (deformable stones, Table 1's stiffness).
pub const LOADING: &str = "stiff_load_from_rigid.toml";
/// The time S2 is read at before the window's end (s): mid-way into the first axle's bearing
/// failure (docs/ballast.md: from 0.108 s with deformable stones).
pub const MID: f64 = 0.10;
/// The start of the record the spectra read (s): the first 20 ms, where the bed formed at the
/// softened stiffness springs back at Table 1's, are left out.
pub const SPECTRUM_FROM: f64 = 0.02;
/// The Parzen bandwidth of the spectra (Hz), paper 000 §4.2's.
pub const BANDWIDTH: f64 = 20.0;
/// The bands (Hz) of the sleeper's modes on the bed (docs/ballast.md, "Spectra against the
/// modes on the bed"): the rigid vertical mode (88–95 Hz), the first three bending modes
/// (178, 470 and 955 Hz).
pub const BANDS: [(&str, f64, f64); 4] = [
    ("rigid", 60.0, 130.0),
    ("bending 1", 130.0, 300.0),
    ("bending 2", 300.0, 700.0),
    ("bending 3", 700.0, 1300.0),
];
/// The file that marks a bed as formed to the end, beside its runs.
const FORMED: &str = "formed.txt";
/// The stone of the quick check and how long it rests (s): it is still within 1e-6 of its
/// overlap after 0.9 ms.
const STONE: &str = "stones/coarse/stone_00.msh";
const REST: f64 = 0.002;

/// One loading variant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Variant {
    /// Rigid stones (else deformable).
    pub rigid: bool,
    /// The contact springs (normal and tangential) are Table 1's divided by this.
    pub softening: f64,
}

impl Variant {
    /// The variant in words.
    pub fn label(&self) -> String {
        let kind = if self.rigid { "rigid" } else { "deformable" };
        match self.softening == 1.0 {
            true => format!("{kind} stones, Table 1's k_n"),
            false => format!("{kind} stones, k_n / {}", self.softening),
        }
    }
}

/// The sweep.
#[derive(Clone, Debug)]
pub struct Sweep {
    /// The loading variants, the reference first; none at the quick size.
    pub variants: Vec<Variant>,
    /// The loading's length (s).
    pub window: f64,
    /// The softenings of the stone at rest (1 = Table 1's stiffness), for both stone kinds.
    pub softenings: Vec<f64>,
}

impl Sweep {
    /// Quick: the stone at rest only (a debug build runs it in seconds). Full: also the four
    /// loadings of the first axle (0.15 s): stones deformable (the reference) or rigid, at
    /// Table 1's stiffness and at a quarter of it.
    pub fn of(size: Size) -> Sweep {
        let variants = match size {
            Size::Quick => Vec::new(),
            Size::Full => [(false, 1.0), (false, 4.0), (true, 1.0), (true, 4.0)]
                .into_iter()
                .map(|(rigid, softening)| Variant { rigid, softening })
                .collect(),
        };
        Sweep {
            variants,
            window: 0.15,
            softenings: vec![1.0, 4.0],
        }
    }
}

/// One loading run.
#[derive(Clone, Debug)]
pub struct Row {
    /// The variant.
    pub variant: Variant,
    /// Step (s).
    pub dt: f64,
    /// Steps.
    pub steps: u64,
    /// CPU seconds of the loading (the shared forming not counted).
    pub cpu_seconds: f64,
    /// S2's vertical displacement at [`MID`] from the loading's start (mm, up positive).
    pub s2_mid_mm: f64,
    /// S2's vertical displacement at the window's end (mm).
    pub s2_end_mm: f64,
    /// The largest peak of S2's smoothed spectrum in each of [`BANDS`] (Hz), if any.
    pub peaks: [Option<f64>; 4],
}

/// One stone at rest on the ground.
#[derive(Clone, Debug)]
pub struct StoneRow {
    /// Rigid stone (else deformable).
    pub rigid: bool,
    /// Normal contact stiffness (N/m).
    pub normal_stiffness: f64,
    /// The run's step (s).
    pub dt: f64,
    /// What bounds the run's step.
    pub limiter: String,
    /// The step the contacts touching at the end allow (s).
    pub contact_dt: f64,
    /// Contacts touching the ground at the end.
    pub touching: usize,
    /// Their mean overlap (m).
    pub mean_overlap: f64,
    /// The stone's weight (N).
    pub weight: f64,
}

fn ballast() -> PathBuf {
    fixtures_dir().join("ballast")
}

fn problem(path: &Path, message: String) -> StudyError {
    StudyError::Probes {
        path: path.to_path_buf(),
        message,
    }
}

/// Reads and parses `file` of the ballast fixtures without checking the files it names (the
/// checkpoint it starts from is replaced by the caller's).
fn scene(file: &str) -> Result<(Scene, String), StudyError> {
    let path = ballast().join(file);
    let text = std::fs::read_to_string(&path).map_err(|e| problem(&path, e.to_string()))?;
    Ok((Scene::parse(&text, &path)?, text))
}

/// 64-bit FNV-1a, folded over `bytes` from `hash`.
fn fnv1a(hash: u64, bytes: &[u8]) -> u64 {
    bytes.iter().fold(hash, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// The key of the formed bed: 64-bit FNV-1a over each forming scene's text and the contents
/// of every file it names (meshes of bodies, stones and walls, load series). A change to any
/// of them gives another key, hence a new bed; a change to the code alone does not.
pub fn forming_key() -> Result<u64, StudyError> {
    let mut hash = 0xcbf2_9ce4_8422_2325;
    for file in FORMING {
        let (scene, text) = scene(file)?;
        hash = fnv1a(hash, text.as_bytes());
        let mut named: Vec<PathBuf> = scene.bodies.iter().map(|b| b.mesh.clone()).collect();
        named.extend(scene.ballast.iter().flat_map(|b| b.meshes.iter().cloned()));
        named.extend(scene.walls.iter().filter_map(|w| w.mesh.clone()));
        named.extend(
            scene
                .loads
                .iter()
                .filter_map(|l| l.series.as_ref().map(|s| s.file.clone())),
        );
        for path in named.iter().map(|p| scene.resolve(p)) {
            let bytes = std::fs::read(&path).map_err(|e| problem(&path, e.to_string()))?;
            hash = fnv1a(hash, &bytes);
        }
    }
    Ok(hash)
}

/// The consolidated bed's checkpoint, formed under `work/bed-KEY` ([`forming_key`]) by the
/// two [`FORMING`] scenes unless a run of them there finished before (its `formed.txt`
/// written last, so that an interrupted forming is run again).
pub fn bed(work: &Path) -> Result<PathBuf, StudyError> {
    let dir = work.join(format!("bed-{:016x}", forming_key()?));
    let mut start: Option<PathBuf> = None;
    for file in FORMING {
        let out = dir.join(file.trim_end_matches(".toml"));
        if !dir.join(FORMED).is_file() {
            let (mut scene, _) = scene(file)?;
            scene.output.vtu_every = 0.0;
            if let Some(start) = &start {
                scene.run.start_from = Some(start.clone());
            }
            let mut sim = Simulation::build(scene.validated()?)?;
            run_scene(&mut sim, &out, &mut |_| {})?;
        }
        start = Some(out.join("checkpoint.qdc"));
    }
    let formed = dir.join(FORMED);
    if !formed.is_file() {
        let note = format!("{} formed by {}\n", dir.display(), FORMING.join(", "));
        write_atomic(&formed, |w| w.write_all(note.as_bytes()))?;
    }
    start.ok_or_else(|| problem(&dir, "no forming scene".into()))
}

/// The stone at rest, then, at full size, the bed formed (or found) under `work` and loaded
/// in each variant, the runs' outputs under `work` (made absolute).
pub fn run(sweep: &Sweep, work: &Path) -> Result<(Vec<StoneRow>, Vec<Row>), StudyError> {
    std::fs::create_dir_all(work).map_err(|e| problem(work, e.to_string()))?;
    let work = work
        .canonicalize()
        .map_err(|e| problem(work, e.to_string()))?;
    let mut stones = Vec::new();
    for rigid in [false, true] {
        for &softening in &sweep.softenings {
            let out = work.join(format!("stone-{}-{softening}", kind(rigid)));
            stones.push(stone_at_rest(rigid, softening, &out)?);
        }
    }
    if sweep.variants.is_empty() {
        return Ok((stones, Vec::new()));
    }
    let bed = bed(&work)?;
    let rows = sweep
        .variants
        .iter()
        .map(|v| {
            let out = work.join(format!("load-{}-{}", kind(v.rigid), v.softening));
            loaded(*v, sweep.window, &bed, &out)
        })
        .collect::<Result<_, _>>()?;
    Ok((stones, rows))
}

fn kind(rigid: bool) -> &'static str {
    if rigid {
        "rigid"
    } else {
        "deformable"
    }
}

/// Table 1's normal and tangential contact stiffness, from the loading scene.
fn table_1() -> Result<(f64, f64), StudyError> {
    let (scene, _) = scene(LOADING)?;
    let contact = scene.contact.as_ref();
    let k = |v: Option<f64>| v.ok_or_else(|| problem(&scene.path, "no linear stiffness".into()));
    Ok((
        k(contact.and_then(|c| c.normal_stiffness))?,
        k(contact.and_then(|c| c.tangential_stiffness))?,
    ))
}

/// The loading scene of `variant` over `window` s from the checkpoint `bed`.
pub fn loading_scene(variant: Variant, window: f64, bed: &Path) -> Result<Scene, StudyError> {
    let (mut scene, _) = scene(LOADING)?;
    scene.run.t_end = window;
    scene.run.start_from = Some(bed.to_path_buf());
    scene.output.vtu_every = 0.0;
    if let Some(ballast) = scene.ballast.as_mut() {
        ballast.rigid = variant.rigid;
    }
    if let Some(contact) = scene.contact.as_mut() {
        contact.normal_stiffness = contact.normal_stiffness.map(|k| k / variant.softening);
        contact.tangential_stiffness = contact.tangential_stiffness.map(|k| k / variant.softening);
    }
    Ok(scene.validated()?)
}

fn loaded(variant: Variant, window: f64, bed: &Path, out: &Path) -> Result<Row, StudyError> {
    let scene = loading_scene(variant, window, bed)?;
    let (report, cpu_seconds) = timed(|| {
        let mut sim = Simulation::build(scene)?;
        Ok(run_scene(&mut sim, out, &mut |_| {})?)
    })?;
    let probes = out.join("probes.csv");
    // (s, µm) of S2's vertical displacement, (s, µm/s²) of its acceleration.
    let uz = read_column(&probes, "S2.uz")?;
    let az = read_column(&probes, "S2.az")?;
    // The probe's displacement is from the mesh, the bed's forming included: S2 is read from
    // the loading's start.
    let at = |t: f64| {
        uz.iter()
            .min_by(|a, b| (a.0 - t).abs().total_cmp(&(b.0 - t).abs()))
            .map_or(f64::NAN, |p| p.1 * 1e-3)
    };
    let settlement = |t: f64| at(t) - at(0.0);
    Ok(Row {
        variant,
        dt: report.dt,
        steps: report.steps,
        cpu_seconds,
        s2_mid_mm: settlement(MID),
        s2_end_mm: settlement(window),
        peaks: band_peaks(&az, SPECTRUM_FROM, window),
    })
}

/// The frequency of the largest local maximum of the smoothed linear spectrum of `record`
/// (t, value) over [from, to] in each of [`BANDS`], if the band holds one.
pub fn band_peaks(record: &[(f64, f64)], from: f64, to: f64) -> [Option<f64>; 4] {
    let window: Vec<&(f64, f64)> = record
        .iter()
        .filter(|(t, _)| *t >= from - 1e-9 && *t <= to + 1e-9)
        .collect();
    let samples: Vec<f64> = window.iter().map(|p| p.1).collect();
    let dt = match window.as_slice() {
        [a, b, ..] => b.0 - a.0,
        _ => return [None; 4],
    };
    let spectrum = parzen_smooth(&linear_spectrum(&samples, dt), BANDWIDTH);
    BANDS.map(|(_, lo, hi)| {
        spectrum
            .windows(3)
            .filter(|w| w[1].1 > w[0].1 && w[1].1 >= w[2].1 && (lo..hi).contains(&w[1].0))
            .max_by(|a, b| a[1].1.total_cmp(&b[1].1))
            .map(|w| w[1].0)
    })
}

/// The scene of one stone of the bed (`stone_00`, Table 1's granite) resting on the ground
/// with its flat face down, its lowest contact spheres just touching, the contact springs
/// Table 1's divided by `softening`.
pub fn stone_scene(rigid: bool, softening: f64) -> Result<Scene, StudyError> {
    let (kn, kt) = table_1()?;
    let (kn, kt) = (kn / softening, kt / softening);
    // The stone's flat face is at z = -0.016935 m in its mesh; the spheres' radius 0.015 m.
    let text = format!(
        r#"[run]
t_end = {REST}
gravity = [0.0, 0.0, -9.81]
probe_every = 1e-4

[[material]]
name = "granite"
density = 2700.0
young = 3e+10
poisson = 0.2
shear_viscosity = 1e+04

[contact]
law = "linear"
normal_stiffness = {kn:e}
tangential_stiffness = {kt:e}
friction = 0.577
local_damping = 0.5

[[body]]
name = "stone"
mesh = "{STONE}"
material = "granite"
contact_radius = 0.015
rigid = {rigid}
translate = [0.0, 0.0, 0.03193499850869184]

[[wall]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
"#
    );
    Ok(Scene::parse(
        &text,
        &ballast().join("speed_vs_error_stone.toml"),
    )?)
}

/// One stone at rest on the ground ([`stone_scene`]) for 2 ms, its outputs in `out`: its
/// step, the contacts' own step bound and their mean overlap at the end.
pub fn stone_at_rest(rigid: bool, softening: f64, out: &Path) -> Result<StoneRow, StudyError> {
    let scene = stone_scene(rigid, softening)?;
    let normal_stiffness = scene
        .contact
        .as_ref()
        .and_then(|c| c.normal_stiffness)
        .unwrap_or(f64::NAN);
    let gravity = nalgebra::Vector3::from(scene.run.gravity).norm();
    let mut sim = Simulation::build(scene)?;
    let report = run_scene(&mut sim, out, &mut |_| {})?;
    let state = &sim.world.state;
    let contacts = sim
        .contacts()
        .ok_or_else(|| problem(out, "the stone has no contacts".into()))?;
    let radius = contacts
        .smallest_radius()
        .ok_or_else(|| problem(out, "the stone has no contact sphere".into()))?;
    // The ground is z = 0: a sphere centred below its radius overlaps it (a rigid stone's
    // centre of mass, 3 cm up, is not among them).
    let overlaps: Vec<f64> = state
        .position
        .iter()
        .map(|p| radius - p.z)
        .filter(|d| *d > 0.0)
        .collect();
    Ok(StoneRow {
        rigid,
        normal_stiffness,
        dt: report.dt,
        limiter: sim.world.settings().stable_dt.1.clone(),
        contact_dt: contacts.stable_dt(state).unwrap_or(f64::NAN),
        touching: overlaps.len(),
        mean_overlap: overlaps.iter().sum::<f64>() / overlaps.len().max(1) as f64,
        weight: stone_mass(&sim) * gravity,
    })
}

/// The stone's mass: the sum of its particles' lumped masses (a rigid stone's sits on its
/// centre of mass, its spheres massless).
fn stone_mass(sim: &Simulation) -> f64 {
    sim.world.state.mass.iter().sum()
}

/// The family's section of the page, and its figure `speed_vs_error_track.svg` in `figures`.
pub fn section(
    sweep: &Sweep,
    stones: &[StoneRow],
    rows: &[Row],
    machine: &str,
    figures: &Path,
) -> Result<String, StudyError> {
    let stone_table: String = stones.iter().map(stone_line).collect();
    let mut text = format!(
        "## The reduced track: stone kind and contact stiffness\n\n\
         What a softer contact buys, on one stone of the bed (`stone_00`, Table 1's granite) at \
         rest on the ground for 2 ms: a linear contact's step goes as k_n^(-1/2) (its \
         oscillator's 2/ω, ω = √(k_n/m)) and the mean overlap of n contacts carrying the \
         weight W is W/(n k_n).\n\n\
         | stones | k_n (N/m) | contacts' step (s) | run's step (s), set by | touching | mean overlap (m) | W/(n k_n) (m) |\n\
         | --- | --- | --- | --- | --- | --- | --- |\n{stone_table}\n"
    );
    if rows.is_empty() {
        text += &format!("(Quick size: the loadings were not run.) {machine}.\n");
        return Ok(text);
    }
    let reference = &rows[0];
    let table: String = rows.iter().map(|r| row_line(r, reference)).collect();
    write_figure(rows, figures)?;
    let bands: Vec<String> = BANDS
        .iter()
        .map(|(name, lo, hi)| format!("{name} {lo:.0}–{hi:.0} Hz"))
        .collect();
    text += &format!(
        "The stiff reduced track ([ballast.md](ballast.md#forming-rigid-loading-deformable)): \
         its bed poured and consolidated with rigid stones once (`{deposit}`, `{consolidate}`; \
         cached under the study's work folder in `track/bed-KEY`, KEY a 64-bit FNV-1a hash of \
         both scenes' text and of every mesh and series file they name, so that a changed \
         scene forms a new bed), then loaded by the first axle for {window} s \
         (`{LOADING}` with `t_end = {window}`) in each variant. S2 = the sleeper's rail-seat \
         sensor, vertical, from the loading's start (mm, up positive); peaks = the largest \
         local maximum of S2's vertical acceleration's linear spectrum from {SPECTRUM_FROM} s \
         to the end, Parzen-smoothed over {BANDWIDTH} Hz, in each band ({bands}; '—' where the \
         band holds none). Reference: the first row (deformable stones, Table 1's stiffness, \
         the coarse sleeper). CPU seconds are the loading's (the shared forming not counted). \
         {machine}.\n\n\
         | variant | ∆t (s) | steps | CPU s | S2 at {MID} s (mm) | vs ref (mm) | S2 at {window} s (mm) | vs ref (mm) | peaks (Hz) | vs ref (Hz) |\n\
         | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n{table}\n\
         ![reduced track: S2 against CPU time](figures/speed_vs_error_track.svg)\n",
        deposit = FORMING[0],
        consolidate = FORMING[1],
        window = sweep.window,
        bands = bands.join(", "),
    );
    Ok(text)
}

fn stone_line(s: &StoneRow) -> String {
    format!(
        "| {} | {:.3e} | {:.3e} | {:.3e}, {} | {} | {:.3e} | {:.3e} |\n",
        kind(s.rigid),
        s.normal_stiffness,
        s.contact_dt,
        s.dt,
        s.limiter,
        s.touching,
        s.mean_overlap,
        s.weight / (s.touching as f64 * s.normal_stiffness),
    )
}

fn peaks_text(peaks: &[Option<f64>; 4]) -> String {
    let each: Vec<String> = peaks
        .iter()
        .map(|p| p.map_or("—".into(), |f| format!("{f:.0}")))
        .collect();
    each.join(" / ")
}

fn row_line(r: &Row, reference: &Row) -> String {
    let shifts: Vec<String> = r
        .peaks
        .iter()
        .zip(&reference.peaks)
        .map(|(p, q)| match (p, q) {
            (Some(p), Some(q)) => format!("{:+.0}", p - q),
            _ => "—".into(),
        })
        .collect();
    format!(
        "| {} | {:.3e} | {} | {:.1} | {:.2} | {:+.2} | {:.2} | {:+.2} | {} | {} |\n",
        r.variant.label(),
        r.dt,
        r.steps,
        r.cpu_seconds,
        r.s2_mid_mm,
        r.s2_mid_mm - reference.s2_mid_mm,
        r.s2_end_mm,
        r.s2_end_mm - reference.s2_end_mm,
        peaks_text(&r.peaks),
        shifts.join(" / "),
    )
}

fn write_figure(rows: &[Row], figures: &Path) -> Result<(), StudyError> {
    let mut sorted: Vec<&Row> = rows.iter().collect();
    sorted.sort_by(|a, b| a.cpu_seconds.total_cmp(&b.cpu_seconds));
    let point = |r: &&Row, v: f64| (r.cpu_seconds.max(0.01).log10(), v);
    let end: Vec<(f64, f64)> = sorted.iter().map(|r| point(r, r.s2_end_mm)).collect();
    let mid: Vec<(f64, f64)> = sorted.iter().map(|r| point(r, r.s2_mid_mm)).collect();
    line_plot_svg(
        &figures.join("speed_vs_error_track.svg"),
        &Labels {
            title: "reduced track, first axle: S2 against CPU time (stone kind, contact stiffness)",
            x: "log10(CPU seconds)",
            y: "mm",
        },
        &[
            Series {
                label: "S2 at the window's end",
                points: &end,
            },
            Series {
                label: "S2 at 0.10 s",
                points: &mid,
            },
        ],
    )?;
    Ok(())
}
