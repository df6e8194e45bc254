//! The run loop: steps a [`Simulation`] to `t_end`, sampling probes and writing VTU
//! snapshots at their intervals, and a summary and a plot of the probe displacements
//! (`probes.svg`, beside `probes.csv`) at the end. Every output file is written
//! atomically; a run stopped by an instability still commits the probe rows up to the failure.
//!
//! The loop is an explicit pipeline: step → wrap (periodic cells) → probes → snapshot →
//! progress. A scene with `[granular]` also gets `stones.csv` (the stones' spheres at the end,
//! the sample format `[granular] sample` reads); one with a time-delayed boundary gets
//! `boundary.csv` (time, the measured average boundary force, the left and right ghost
//! scales) at the probe interval, and one with `[[section]]`s `sections.csv` (time, the
//! average contact force across each section plane); one with rigid `[[body]]`s gets
//! `poses.csv` (where each ended, the file `[[body]] pose_from` reads: [`crate::pose_from`]).

use crate::build::{BodyKind, Simulation};
use crate::checkpoint::{
    read_checkpoint, scene_fingerprint, write_checkpoint, CheckpointFileError, CHECKPOINT_FILE,
};
use crate::crack_svg::write_crack_svg;
use crate::granular_build::write_stones_csv;
use crate::output::{write_atomic, write_summary, write_vtu, OutputError, ProbeCsv, VtuGrid};
use crate::plot::{line_plot_svg, Labels, Series};
use crate::pose_from::{poses, write_poses_csv};
use crate::run_record::{check_checkpointable, decode_run, encode_run, RunRecord};
use crate::scene::Integrator;
use qdem_contact::BondedParticles;
use qdem_core::instability::{EnergyGrowth, GROWTH_PER_STEP, GROWTH_STEPS};
use qdem_core::{stable_step, CoreError, Newmark, StaticSteps, Stepper, Vec3, Verlet};
use serde_json::json;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;
use thiserror::Error;

/// Why a run stopped early.
#[derive(Debug, Error)]
pub enum RunError {
    /// An output could not be written.
    #[error(transparent)]
    Output(#[from] OutputError),
    /// The output directory could not be created.
    #[error("cannot create the output directory {path}: {source}")]
    OutputDir {
        /// The directory.
        path: PathBuf,
        /// The io error.
        source: std::io::Error,
    },
    /// The stepper failed (an instability).
    #[error("{scene}: {source}")]
    Core {
        /// The scene file.
        scene: PathBuf,
        /// What went wrong.
        source: CoreError,
    },
    /// The run went unstable.
    #[error(
        "{scene}: the run became unstable at step {step} (t = {time:.6e} s): {detail}. The step \
         was dt = {dt:.4e} s; the stable bound at this state is {bound:.4e} s (set by \
         {limiter}): {advice}",
        scene = scene.display(),
        advice = unstable_advice(dt, bound)
    )]
    Unstable {
        /// The scene file.
        scene: PathBuf,
        /// The step that failed.
        step: u64,
        /// Simulated time after it.
        time: f64,
        /// What went wrong, and where (particle, body, element).
        detail: String,
        /// The step size.
        dt: f64,
        /// The stable bound at this state.
        bound: f64,
        /// The model that sets it.
        limiter: String,
    },
    /// A checkpoint that cannot be resumed from.
    #[error(transparent)]
    Checkpoint(#[from] CheckpointFileError),
    /// The run was stopped on request (Ctrl-C, SIGTERM) after writing a checkpoint.
    #[error(
        "interrupted at t = {time:.6e} s (step {step}); the run is checkpointed in {checkpoint}: \
         continue it with `qdem run SCENE --resume {checkpoint}`",
        checkpoint = checkpoint.display()
    )]
    Interrupted {
        /// Simulated time reached.
        time: f64,
        /// The last step done.
        step: u64,
        /// The checkpoint written.
        checkpoint: PathBuf,
    },
    /// A run that failed after its last good state was checkpointed.
    #[error(
        "{source}\nthe last good state (t = {time:.6e} s) is saved in {checkpoint}",
        checkpoint = checkpoint.display()
    )]
    Failed {
        /// Why the run failed.
        source: Box<RunError>,
        /// The time of the checkpointed state.
        time: f64,
        /// The checkpoint written.
        checkpoint: PathBuf,
    },
}

/// Where the run is, for a progress display.
#[derive(Clone, Copy, Debug)]
pub struct Progress {
    /// Steps done.
    pub step: u64,
    /// Steps in the whole run.
    pub steps: u64,
    /// Simulated time (s).
    pub time: f64,
    /// Steps per wall-clock second so far.
    pub steps_per_second: f64,
    /// Estimated wall-clock seconds left.
    pub eta_seconds: f64,
}

/// What a finished run reports (also written to `summary.json`).
#[derive(Clone, Debug)]
pub struct RunReport {
    /// The stepper's name.
    pub integrator: String,
    /// Steps taken.
    pub steps: u64,
    /// Step size (s).
    pub dt: f64,
    /// Final simulated time (s).
    pub final_time: f64,
    /// Wall-clock seconds of the stepping loop, outputs included.
    pub wall_seconds: f64,
    /// Tetrahedron-steps per wall-clock second.
    pub tet_steps_per_second: f64,
    /// Rows written to `probes.csv`.
    pub probe_rows: usize,
    /// VTU snapshots written.
    pub vtu_files: usize,
    /// Particle-steps per wall-clock second.
    pub particle_steps_per_second: f64,
    /// Wall-clock seconds of the steps before and after the first broken bond, and the
    /// number of each (bonded scenes; zero otherwise): the t_b, t_u of paper 001 Tables 1–2.
    pub crack_timing: CrackTiming,
}

/// Wall time per step before and after cracking starts.
#[derive(Clone, Copy, Debug, Default)]
pub struct CrackTiming {
    /// Seconds in steps that began with no bond broken.
    pub before_seconds: f64,
    /// Steps that began with no bond broken.
    pub before_steps: u64,
    /// Seconds in steps that began with bonds broken.
    pub after_seconds: f64,
    /// Steps that began with bonds broken.
    pub after_steps: u64,
    /// Time of the first broken bond (s), if any.
    pub first_break: Option<f64>,
    /// When the run stopped early because the bonded body moved beyond its
    /// small-displacement range: (time, particle, displacement).
    pub collapse: Option<(f64, usize, f64)>,
}

impl CrackTiming {
    pub(crate) fn add(&mut self, cracked: bool, seconds: f64) {
        if cracked {
            self.after_seconds += seconds;
            self.after_steps += 1;
        } else {
            self.before_seconds += seconds;
            self.before_steps += 1;
        }
    }
}

/// A bonded run ends early once a particle has moved this many particle spacings: its linear
/// bonds and contacts are meaningless beyond (the body has collapsed or come apart).
const COLLAPSE_SPACINGS: f64 = 0.5;

/// Wall-clock seconds between the in-memory copies of the last good state (on the main
/// cantilever job, probing every 26 steps, a copy at every probe sample cost 16% of the run).
const GOOD_STATE_EVERY: f64 = 1.0;

/// How a run starts and when it stops early.
#[derive(Clone, Copy, Debug, Default)]
pub struct RunOptions<'a> {
    /// A checkpoint to continue from (`qdem run --resume`), written by a run of the same scene
    /// into the same output directory.
    pub resume: Option<&'a Path>,
    /// Set (by a Ctrl-C or SIGTERM handler) to stop the run after the current step, with a
    /// checkpoint.
    pub stop: Option<&'a AtomicBool>,
    /// Stops as on a stop request once this step is done (a batch slot's last step, a test).
    pub stop_after: Option<u64>,
}

/// Runs `sim` to its end time, writing `probes.csv`, `summary.json` and, if asked,
/// `vtu/state_NNNNN.vtu` with `results.pvd` into `out_dir`. `progress` is called about twice
/// a second of wall-clock time.
pub fn run(
    sim: &mut Simulation,
    out_dir: &Path,
    progress: &mut dyn FnMut(&Progress),
) -> Result<RunReport, RunError> {
    run_with(sim, out_dir, RunOptions::default(), progress)
}

/// [`run`], resuming from a checkpoint or stopping on request as `options` say. With
/// `[output] checkpoint_every`, a resume or a stop request, the scene's models and stepper
/// must be checkpointable, which is checked before the first step. At every checkpoint the
/// probe rows so far are published under `probes.csv`; a resumed run keeps the rows the
/// checkpoint has seen and appends. A run that fails leaves its last good state in
/// `checkpoint.qdc` when it can be checkpointed: the state at a probe sample, kept in memory
/// at most once per [`GOOD_STATE_EVERY`] seconds of wall time so that encoding it costs next
/// to nothing however often the probes sample.
pub fn run_with(
    sim: &mut Simulation,
    out_dir: &Path,
    options: RunOptions<'_>,
    progress: &mut dyn FnMut(&Progress),
) -> Result<RunReport, RunError> {
    let dir_error = |path: &Path| {
        let path = path.to_path_buf();
        move |source| RunError::OutputDir { path, source }
    };
    std::fs::create_dir_all(out_dir).map_err(dir_error(out_dir))?;
    let vtu_dir = out_dir.join("vtu");
    if sim.scene.output.writes_vtu() {
        std::fs::create_dir_all(&vtu_dir).map_err(dir_error(&vtu_dir))?;
    }
    crate::output::remove_stale_temporaries(out_dir);
    let names: Vec<String> = sim.probes.iter().map(|p| p.name.clone()).collect();
    let steps = sim.steps();
    let mut stepper = make_stepper(sim).map_err(|source| core_error(sim, source))?;
    let checkpoint_path = out_dir.join(CHECKPOINT_FILE);
    let fingerprint = scene_fingerprint(&sim.scene);
    let can_checkpoint = check_checkpointable(sim, stepper.as_ref());
    if sim.scene.output.checkpoint_every > 0.0 || options.resume.is_some() {
        if let Err(source) = &can_checkpoint {
            return Err(core_error(sim, source.clone().into()));
        }
    }
    let mut record = RunRecord::new(sim);
    let probes_path = out_dir.join("probes.csv");
    let mut csv = match options.resume {
        Some(path) => {
            let body = read_checkpoint(path, Some(&fingerprint))?;
            decode_run(&body, sim, stepper.as_mut(), &mut record)
                .map_err(|source| core_error(sim, source))?;
            ProbeCsv::resume(&probes_path, &names, record.probe_rows as usize)?
        }
        None => ProbeCsv::create(&probes_path, &names)?,
    };
    let first_step = record.next_step;
    let start = Instant::now();
    let mut last_report = start;
    let mut last_good: Option<(f64, Vec<u8>, Instant)> = None;
    let mut energy = EnergyGrowth::new();
    let outcome = (|| -> Result<(), RunError> {
        if options.resume.is_none() {
            stepper
                .initialize(&mut sim.state, &mut sim.models)
                .map_err(|source| core_error(sim, source))?;
        }
        for step in first_step..=steps {
            if step > 0 {
                let cracked = sim.bonded().is_some_and(|b| b.broken() > 0);
                let begin = Instant::now();
                let stepped = stepper.step(&mut sim.state, &mut sim.models);
                check_stability(sim, stepped, step, &mut energy)?;
                record.timing.add(cracked, begin.elapsed().as_secs_f64());
                if let Some((cell, groups)) = &sim.periodic {
                    cell.wrap_bodies(&mut sim.state, groups);
                }
                if let Some((p, u)) = sim.bonded().and_then(|b| {
                    b.beyond_small_displacement(&sim.state, COLLAPSE_SPACINGS * 2.0 * b.radii()[0])
                }) {
                    record.timing.collapse = Some((sim.state.time, p, u));
                }
            }
            let (time, dt) = (sim.state.time, sim.dt);
            let sampled = record.probes.due(time, dt);
            if sampled {
                let samples = probe_samples(sim);
                for (p, sample) in samples.iter().enumerate() {
                    for (axis, u) in sample[0].iter().enumerate() {
                        record.history[3 * p + axis].push((time, *u));
                    }
                }
                csv.row(time, &samples)?;
                record.probe_rows += 1;
                if let Some((scales, force)) = sim.contacts().and_then(|c| c.time_delay_state()) {
                    record
                        .boundary_rows
                        .push([time, force, scales.left, scales.right]);
                }
                record_sections(sim, time, &mut record.section_rows);
            }
            if record.vtu.due(time, dt) {
                let file = format!("vtu/state_{:05}.vtu", record.pvd.len());
                write_snapshot(sim, &out_dir.join(&file))?;
                record.pvd.push(time, file);
                record.pvd.write(&out_dir.join("results.pvd"))?;
            }
            record.next_step = step + 1;
            let stop = options.stop.is_some_and(|s| s.load(Ordering::Relaxed))
                || options.stop_after == Some(step);
            if record.checkpoints.due(time, dt) || stop {
                csv.publish()?;
                let body = encode_run(sim, stepper.as_ref(), &record)
                    .map_err(|source| core_error(sim, source.into()))?;
                write_checkpoint(&checkpoint_path, &fingerprint, &body)?;
            } else if sampled
                && can_checkpoint.is_ok()
                && last_good
                    .as_ref()
                    .is_none_or(|g| g.2.elapsed().as_secs_f64() >= GOOD_STATE_EVERY)
            {
                let body = encode_run(sim, stepper.as_ref(), &record)
                    .map_err(|source| core_error(sim, source.into()))?;
                last_good = Some((time, body, Instant::now()));
            }
            if stop {
                return Err(RunError::Interrupted {
                    time,
                    step,
                    checkpoint: checkpoint_path.clone(),
                });
            }
            if step % 64 == 0 && last_report.elapsed().as_secs_f64() > 0.5 {
                last_report = Instant::now();
                progress(&progress_at(
                    step - first_step,
                    steps - first_step,
                    time,
                    start,
                ));
            }
            if record.timing.collapse.is_some() {
                break;
            }
        }
        Ok(())
    })();
    let wall_seconds = start.elapsed().as_secs_f64();
    let probe_rows = csv.num_rows();
    csv.finish()?;
    let outcome = match (outcome, last_good) {
        (
            Err(source @ (RunError::Core { .. } | RunError::Unstable { .. })),
            Some((time, body, _)),
        ) => {
            write_checkpoint(&checkpoint_path, &fingerprint, &body)?;
            Err(RunError::Failed {
                source: Box::new(source),
                time,
                checkpoint: checkpoint_path.clone(),
            })
        }
        (outcome, _) => outcome,
    };
    let mut timing = record.timing;
    if !names.is_empty() {
        plot_probes(&out_dir.join("probes.svg"), &names, &record.history)?;
    }
    if let Some(model) = sim.bonded() {
        timing.first_break = model.broken_log().first().map(|b| b.0);
        write_crack_svg(&out_dir.join("crack.svg"), model, &sim.state)?;
    }
    if let Some(info) = &sim.granular {
        write_stones_csv(&out_dir.join("stones.csv"), info, &sim.state)?;
    }
    let poses = poses(sim);
    if !poses.is_empty() {
        write_poses_csv(&out_dir.join("poses.csv"), &poses)?;
    }
    if !record.boundary_rows.is_empty() {
        write_boundary_csv(&out_dir.join("boundary.csv"), &record.boundary_rows)?;
    }
    if !record.section_rows.is_empty() {
        write_sections_csv(&out_dir.join("sections.csv"), sim, &record.section_rows)?;
    }
    outcome?;
    let steps = match timing.collapse {
        Some(_) => timing.before_steps + timing.after_steps,
        None => steps,
    };
    let stepped = steps.saturating_sub(first_step.saturating_sub(1)) as f64;
    let tet_steps = (sim.tets() as f64) * stepped;
    let report = RunReport {
        integrator: stepper.name().to_string(),
        steps,
        dt: sim.dt,
        final_time: sim.state.time,
        wall_seconds,
        tet_steps_per_second: tet_steps / wall_seconds.max(1e-9),
        probe_rows,
        vtu_files: record.pvd.len(),
        particle_steps_per_second: sim.state.len() as f64 * stepped / wall_seconds.max(1e-9),
        crack_timing: timing,
    };
    let mut summary = summary_json(sim, &report);
    if options.resume.is_some() {
        summary["resumed_at_step"] = json!(first_step.saturating_sub(1));
    }
    if let Some(model) = sim.bonded() {
        summary["bonded"] = bonded_summary(model, &report, stepper.as_ref());
    }
    if let Some(info) = &sim.granular {
        let spheres = info.radii.len() as f64;
        summary["granular"] = json!({
            "name": info.name,
            "stones": info.len(),
            "spheres": info.radii.len(),
            "sphere_steps_per_second": spheres * stepped / wall_seconds.max(1e-9),
        });
    }
    if let Some(contacts) = sim.contacts() {
        summary["contact"] = json!({
            "spheres": contacts.spheres(),
            "contacts": contacts.contacts(),
            "rebuilds": contacts.rebuilds(),
            "sphere_steps_per_second":
                contacts.spheres() as f64 * stepped / wall_seconds.max(1e-9),
        });
    }
    if let Some((cell, _)) = &sim.periodic {
        summary["periodic"] = json!({
            "length": [cell.length(0), cell.length(1), cell.length(2)],
            "origin": [cell.origin().x, cell.origin().y, cell.origin().z],
            "time_delay": sim.contacts().and_then(|c| c.time_delay_state()).map(|(s, f)| json!({
                "last_left_scale": s.left,
                "last_right_scale": s.right,
                "last_boundary_force": f,
            })),
        });
    }
    write_summary(&out_dir.join("summary.json"), &summary)?;
    Ok(report)
}

/// Stops the run after a failed step (a non-finite acceleration), a step that left a model
/// in an impossible state (an inverted tetrahedron), or runaway kinetic energy, with the
/// diagnosis and the stable step at this state; passes other stepper errors on.
fn check_stability(
    sim: &Simulation,
    stepped: Result<(), CoreError>,
    step: u64,
    energy: &mut EnergyGrowth,
) -> Result<(), RunError> {
    let failure = match stepped {
        Err(CoreError::NonFinite { particle, .. }) => {
            Some(format!("particle {particle} has a non-finite acceleration"))
        }
        Err(source) => return Err(core_error(sim, source)),
        Ok(()) => sim
            .models
            .iter()
            .find_map(|m| m.failure(&sim.state))
            .map(|e| e.to_string()),
    };
    let failure = failure.or_else(|| {
        energy.observe(sim.state.kinetic_energy()).map(|growth| {
            format!(
                "the kinetic energy grew by more than {:.0}% at each of the last {GROWTH_STEPS} \
                 steps (x{growth:.2e} in all), the signature of an unstable step",
                100.0 * (GROWTH_PER_STEP - 1.0)
            )
        })
    });
    let Some(detail) = failure else {
        return Ok(());
    };
    let (bound, limiter) =
        stable_step(&sim.state, &sim.models).unwrap_or((f64::INFINITY, "nothing".to_string()));
    Err(RunError::Unstable {
        scene: sim.scene.path.clone(),
        step,
        time: sim.state.time,
        detail,
        dt: sim.dt,
        bound,
        limiter,
    })
}

/// What to do about an instability, given the step and its bound.
fn unstable_advice(dt: &f64, bound: &f64) -> String {
    if dt > bound {
        format!("the step is above the bound: use dt = \"auto\" or dt <= {bound:.4e} s")
    } else {
        "the step is within the bound, so the cause is physical: a load or a contact \
         stiffness too large for the mesh there (reduce it or refine the mesh), or a contact \
         pushing a vertex through its body (finer contact spheres)"
            .to_string()
    }
}

/// The time-delayed boundary's record: time, F_Ave_current, left and right ghost scales.
fn write_boundary_csv(path: &Path, rows: &[[f64; 4]]) -> Result<(), OutputError> {
    write_atomic(path, |w| {
        writeln!(w, "time,boundary_force,left_scale,right_scale")?;
        for r in rows {
            writeln!(w, "{:.9e},{:.9e},{:.9e},{:.9e}", r[0], r[1], r[2], r[3])?;
        }
        Ok(())
    })
}

/// Appends a row of `sections.csv`: the time and each `[[section]]`'s average contact force
/// (0 in a scene where nothing can touch, which builds no contact model).
fn record_sections(sim: &Simulation, time: f64, rows: &mut Vec<f64>) {
    if sim.scene.sections.is_empty() {
        return;
    }
    let contacts = sim.contacts();
    rows.push(time);
    for s in &sim.scene.sections {
        let axis = "xyz".find(&s.axis).expect("validated: x, y or z");
        rows.push(contacts.map_or(0.0, |c| c.section_force(axis, s.at)));
    }
}

/// The sections' record: time, then the average magnitude of the contact forces across each
/// `[[section]]` plane (N), one column per section named after it.
fn write_sections_csv(path: &Path, sim: &Simulation, rows: &[f64]) -> Result<(), OutputError> {
    let names: Vec<&str> = sim.scene.sections.iter().map(|s| s.name.as_str()).collect();
    write_atomic(path, |w| {
        writeln!(w, "time,{}", names.join(","))?;
        for row in rows.chunks_exact(names.len() + 1) {
            let cells: Vec<String> = row.iter().map(|v| format!("{v:.9e}")).collect();
            writeln!(w, "{}", cells.join(","))?;
        }
        Ok(())
    })
}

/// Displacement of every probe against time, one curve per component.
fn plot_probes(
    path: &Path,
    names: &[String],
    history: &[Vec<(f64, f64)>],
) -> Result<(), OutputError> {
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

/// Whether runs of `sim` can be checkpointed and resumed, or the model or stepper that
/// cannot.
pub fn checkpoint_support(sim: &Simulation) -> Result<(), CoreError> {
    let stepper = make_stepper(sim)?;
    Ok(check_checkpointable(sim, stepper.as_ref())?)
}

/// The scene's stepper with the simulation's step.
pub fn make_stepper(sim: &Simulation) -> Result<Box<dyn Stepper>, CoreError> {
    let run = &sim.scene.run;
    Ok(match run.integrator {
        Integrator::Verlet => {
            let damping = sim.scene.contact.as_ref().map_or(0.0, |c| c.local_damping);
            Box::new(Verlet::new(sim.dt).with_local_damping(damping))
        }
        Integrator::Newmark => {
            let adaptive = sim.scene.bonded.as_ref().is_some_and(|b| b.adaptive);
            Box::new(Newmark::new(run.beta, run.gamma, sim.dt)?.with_adaptive(adaptive))
        }
        Integrator::Static => Box::new(StaticSteps::new(sim.dt)),
    })
}

fn core_error(sim: &Simulation, source: CoreError) -> RunError {
    RunError::Core {
        scene: sim.scene.path.clone(),
        source,
    }
}

fn progress_at(step: u64, steps: u64, time: f64, start: Instant) -> Progress {
    let elapsed = start.elapsed().as_secs_f64();
    let rate = step as f64 / elapsed.max(1e-9);
    Progress {
        step,
        steps,
        time,
        steps_per_second: rate,
        eta_seconds: (steps - step) as f64 / rate.max(1e-9),
    }
}

fn probe_samples(sim: &Simulation) -> Vec<[Vec3; 3]> {
    let s = &sim.state;
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

/// One VTU of all bodies: reference points with displacement and velocity per particle, von
/// Mises stress and volumetric strain per tetrahedron.
fn write_snapshot(sim: &Simulation, path: &Path) -> Result<(), OutputError> {
    let s = &sim.state;
    let displacement: Vec<Vec3> = (0..s.len()).map(|i| s.displacement(i)).collect();
    let mut tets = Vec::new();
    let (mut von_mises, mut volumetric) = (Vec::new(), Vec::new());
    for body in &sim.bodies {
        match (&body.kind, sim.tet_body(body)) {
            (_, Some(tet_body)) => {
                tets.extend_from_slice(tet_body.tets());
                let (vm, vol) = tet_body.tet_fields(s);
                von_mises.extend(vm);
                volumetric.extend(vol);
            }
            (BodyKind::Rigid { tets: rigid, .. }, None) => {
                tets.extend_from_slice(rigid);
                von_mises.extend(std::iter::repeat_n(0.0, rigid.len()));
                volumetric.extend(std::iter::repeat_n(0.0, rigid.len()));
            }
            (BodyKind::Deformable { .. }, None) => unreachable!("a deformable body has a TetBody"),
        }
    }
    let grid = VtuGrid {
        points: &s.reference,
        tets: &tets,
        point_vectors: vec![("displacement", &displacement), ("velocity", &s.velocity)],
        cell_scalars: vec![
            ("von_mises", &von_mises),
            ("volumetric_strain", &volumetric),
        ],
    };
    write_vtu(path, &grid)
}

/// The bonded body's figures: bonds, breaks, the paper's step bound and Table 1–2 timings.
fn bonded_summary(
    model: &BondedParticles,
    report: &RunReport,
    stepper: &dyn Stepper,
) -> serde_json::Value {
    let t = &report.crack_timing;
    let per = |s: f64, n: u64| if n > 0 { s / n as f64 } else { 0.0 };
    let counts = stepper.counts();
    let factor = stepper.factor_stats();
    json!({
        "bonds": model.bonds().len(),
        "broken_bonds": model.broken(),
        "first_break_time": t.first_break,
        "touching_pairs": model.touching(),
        "critical_step_eq28": model.initial_critical_step(),
        "stopped_at_collapse": t.collapse.map(|(time, particle, u)| json!({
            "time": time, "particle": particle, "displacement": u,
        })),
        "step_before_crack_seconds": per(t.before_seconds, t.before_steps),
        "step_after_crack_seconds": per(t.after_seconds, t.after_steps),
        "steps_before_crack": t.before_steps,
        "steps_after_crack": t.after_steps,
        "retakes": counts.retakes,
        "substeps": counts.substeps,
        "event_steps": counts.event_steps,
        "factorizations": counts.factorizations,
        "factor_dofs": factor.map(|f| f.dofs),
        "factor_nonzeros": factor.map(|f| f.factor_nonzeros),
        "particle_steps_per_second": report.particle_steps_per_second,
    })
}

fn summary_json(sim: &Simulation, report: &RunReport) -> serde_json::Value {
    json!({
        "scene": sim.scene.path.display().to_string(),
        "integrator": report.integrator,
        "steps": report.steps,
        "dt": report.dt,
        "stable_dt": sim.stable_dt.0,
        "dt_limited_by": sim.stable_dt.1,
        "t_end": sim.scene.run.t_end,
        "final_time": report.final_time,
        "wall_seconds": report.wall_seconds,
        "particles": sim.state.len(),
        "tets": sim.tets(),
        "tet_steps_per_second": report.tet_steps_per_second,
        "threads": rayon::current_num_threads(),
        "probe_rows": report.probe_rows,
        "vtu_files": report.vtu_files,
        "kinetic_energy": sim.state.kinetic_energy(),
        "bodies": sim.bodies.iter().map(|b| json!({
            "name": b.name,
            "mesh": b.mesh.display().to_string(),
            "particles": b.particles.len(),
            "tets": b.stats.tets,
        })).collect::<Vec<_>>(),
        "probes": sim.probes.iter().map(|p| json!({
            "name": p.name,
            "particle": p.particle,
            "distance": p.distance,
        })).collect::<Vec<_>>(),
    })
}
