//! `summary.json` of a finished run: the version of the outputs' layout
//! ([`crate::output::OUTPUT_FORMAT`]), the run's figures (steps, step, stable bound, wall time,
//! rates, the stage counters of [`qdem_core::world::World`], a static run's linear solves), the
//! bodies and probes, the contact set and the periodic cell, then each recorder's part
//! ([`super::Recorder::summarize`]).

use super::{Recorder, RunFigures};
use crate::build::Simulation;
use crate::output::{write_summary, OutputError, OUTPUT_FORMAT};
use crate::runner::RunReport;
use qdem_core::step::Scheme;
use serde_json::json;
use std::path::Path;

/// Writes `summary.json` of `sim`'s finished run into `out_dir`; `resumed_at` is the step a
/// resumed run continued from.
pub(crate) fn write(
    out_dir: &Path,
    sim: &Simulation,
    report: &RunReport,
    run: &RunFigures,
    recorders: &[Box<dyn Recorder>],
    resumed_at: Option<u64>,
) -> Result<(), OutputError> {
    let mut summary = base(sim, report);
    if let Some(step) = resumed_at {
        summary["resumed_at_step"] = json!(step);
    }
    if sim.world.settings().request.scheme == Scheme::Static {
        summary["solves"] = json!(sim.world.stepper().report().counts.solves);
    }
    if let Some(contacts) = sim.contacts() {
        summary["contact"] = json!({
            "spheres": contacts.spheres(),
            "contacts": contacts.contacts(),
            "rebuilds": contacts.rebuilds(),
            "sphere_steps_per_second": run.rate(contacts.spheres()),
        });
    }
    if let Some(cell) = sim.periodic() {
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
    for r in recorders {
        r.summarize(sim, run, &mut summary);
    }
    write_summary(&out_dir.join("summary.json"), &summary)
}

/// The figures every run has.
fn base(sim: &Simulation, report: &RunReport) -> serde_json::Value {
    let world = &sim.world;
    let settings = world.settings();
    json!({
        "output_format": OUTPUT_FORMAT,
        "scene": sim.scene.path.display().to_string(),
        "integrator": report.integrator,
        "steps": report.steps,
        "dt": report.dt,
        "stable_dt": settings.stable_dt.0,
        "dt_limited_by": settings.stable_dt.1,
        "t_end": sim.scene.run.t_end,
        "final_time": report.final_time,
        "wall_seconds": report.wall_seconds,
        "particles": world.state.len(),
        "tets": sim.tets(),
        "tet_steps_per_second": report.tet_steps_per_second,
        "threads": rayon::current_num_threads(),
        "ranks": world.decomposition().map_or(1, |d| d.ranks),
        "kinetic_energy": world.state.kinetic_energy(),
        "stages": world.stage_report().iter().map(|s| json!({
            "stage": s.name,
            "seconds_per_step": s.seconds_per_step,
            "share": s.share,
        })).collect::<Vec<_>>(),
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
