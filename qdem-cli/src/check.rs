//! `qdem check SCENE`: validates a scene and prints its meshes, mass, stable step, checkpoint
//! support, the measured cost of a step with the projected run time, and where a step's time
//! goes, stage by stage of the world's step ([`qdem_core::stages`]).

use crate::command::CliError;
use crate::progress;
use qdem_core::Model as _;
use qdem_io::build::{BodyKind, Simulation};
use qdem_io::runner::RunError;
use qdem_io::scene::Scene;
use std::path::Path;
use std::time::Instant;

/// Loads and builds the scene at `path`, prints what `qdem check` reports, and measures the
/// cost of a step (inside the caller's thread pool).
pub fn check_scene(path: &Path) -> Result<(), CliError> {
    let scene = Scene::load(path)?;
    let mut sim = Simulation::build(scene)?;
    println!("scene {}: valid", path.display());
    for w in &sim.warnings {
        println!("warning: {w}");
    }
    for body in &sim.bodies {
        let s = &body.stats;
        let mass = sim.body_mass(body);
        let kind = match body.kind {
            BodyKind::Rigid { .. } => "rigid",
            BodyKind::Deformable { .. } => "deformable",
        };
        println!(
            "body `{}` ({}, {kind}): {} particles, {} tets, volume {:.6e} m^3, mass {:.6e} kg, edges {:.4e}..{:.4e} m, worst quality {:.3} (tet {})",
            body.name,
            body.mesh.display(),
            s.nodes,
            s.tets,
            s.volume,
            mass,
            s.min_edge,
            s.max_edge,
            s.worst_quality,
            s.worst_tet
        );
    }
    if let Some(b) = sim.bonded() {
        let mass: f64 = sim.world.state.mass.iter().sum();
        println!(
            "bonded body `{}`: {} particles (radius {:.4e} m), {} beam bonds, mass {:.6e} kg; \
             paper 001 Eq. 28 dt_crit {:.4e} s",
            b.name(),
            sim.world.state.len(),
            b.radii()[0],
            b.bonds().len(),
            mass,
            b.initial_critical_step()
        );
    }
    if let Some(contacts) = sim.contacts() {
        println!(
            "contact: {} spheres, {} walls, {} candidate pairs and wall contacts at the start",
            contacts.spheres(),
            contacts.walls(),
            contacts.candidates()
        );
    }
    for p in &sim.probes {
        println!(
            "probe `{}`: particle {} at {:.3e} m from the requested point",
            p.name, p.particle, p.distance
        );
    }
    let (bound, limiter) = &sim.world.settings().stable_dt;
    println!(
        "integrator {}: dt {:.6e} s ({:.3}x the explicit stable bound {bound:.6e} s set by `{limiter}`); {} steps to t_end = {} s",
        sim.scene.run.integrator.name(),
        sim.world.dt(),
        sim.world.dt() / bound,
        sim.steps(),
        sim.scene.run.t_end
    );
    match sim.world.checkpointable() {
        Ok(()) => println!("checkpoints: supported (`checkpoint_every`, Ctrl-C, --resume)"),
        Err(why) => println!("checkpoints: not supported: {why}"),
    }
    let per_step = measure_step_cost(&mut sim, 20)?;
    let total = per_step * sim.steps() as f64;
    // A scene without tetrahedra (spheres, a bonded body) steps particles.
    let rate = match sim.tets() {
        0 => format!(
            "{:.3e} particle-steps/s",
            sim.world.state.len() as f64 / per_step
        ),
        tets => format!("{:.3e} tet-steps/s", tets as f64 / per_step),
    };
    println!(
        "measured {:.3e} s/step on {} threads ({rate}): estimated run time {} (outputs not counted)",
        per_step,
        rayon::current_num_threads(),
        progress::clock(total)
    );
    print_stages(&sim);
    Ok(())
}

/// Where the measured steps' time went, stage by stage ([`qdem_core::stages`]).
fn print_stages(sim: &Simulation) {
    println!(
        "time per step by stage ({} steps):",
        sim.world.stages().steps()
    );
    for stage in sim.world.stage_report() {
        println!(
            "  {:<32} {:.3e} s ({:.1}%)",
            stage.name,
            stage.seconds_per_step,
            100.0 * stage.share
        );
    }
    if let Some(c) = sim.contacts() {
        println!(
            "  contacts after the measured steps: {} candidate pairs and wall candidates, {} touching",
            c.candidates(),
            c.contacts()
        );
    }
}

/// Wall seconds per step of the scene's world, measured over `n` steps from its start; for
/// implicit and static scenes also prints the sparse system's size, non-zeros, Cholesky fill
/// and factorisation time from the stepper's one factorisation (in `initialize`, which is not
/// timed).
fn measure_step_cost(sim: &mut Simulation, n: usize) -> Result<f64, CliError> {
    let scene = sim.scene.path.clone();
    let run_error = |source| RunError::Core {
        scene: scene.clone(),
        source,
    };
    let world = &mut sim.world;
    world.initialize().map_err(run_error)?;
    if let Some(s) = world.stepper().factor_stats() {
        println!(
            "implicit system: {} unknowns, {} non-zeros (lower triangle), factor {} non-zeros (fill {:.1}x); symbolic {:.3e} s, numeric {:.3e} s",
            s.dofs,
            s.nonzeros,
            s.factor_nonzeros,
            s.factor_nonzeros as f64 / s.nonzeros.max(1) as f64,
            s.symbolic_seconds,
            s.numeric_seconds
        );
    }
    let start = Instant::now();
    for _ in 0..n {
        if world.step().map_err(run_error)?.is_some() {
            break;
        }
    }
    Ok(start.elapsed().as_secs_f64() / world.stages().steps().max(1) as f64)
}
