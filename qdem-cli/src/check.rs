//! `qdem check SCENE`: validates a scene and prints its meshes, mass, stable step, checkpoint
//! support, the measured cost of a step with the projected run time, and where a step's time
//! goes by model.

use crate::command::CliError;
use crate::progress;
use qdem_core::Model as _;
use qdem_io::build::{BodyKind, Simulation};
use qdem_io::runner::{checkpoint_support, make_stepper, RunError};
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
        let mass: f64 = sim.state.mass.iter().sum();
        println!(
            "bonded body `{}`: {} particles (radius {:.4e} m), {} beam bonds, mass {:.6e} kg; \
             paper 001 Eq. 28 dt_crit {:.4e} s",
            b.name(),
            sim.state.len(),
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
    let (bound, limiter) = &sim.stable_dt;
    println!(
        "integrator {}: dt {:.6e} s ({:.3}x the explicit stable bound {bound:.6e} s set by `{limiter}`); {} steps to t_end = {} s",
        sim.scene.run.integrator.name(),
        sim.dt,
        sim.dt / bound,
        sim.steps(),
        sim.scene.run.t_end
    );
    match checkpoint_support(&sim) {
        Ok(()) => println!("checkpoints: supported (`checkpoint_every`, Ctrl-C, --resume)"),
        Err(why) => println!("checkpoints: not supported: {why}"),
    }
    let (per_step, stepped) = measure_step_cost(&mut sim, 20)?;
    let total = per_step * sim.steps() as f64;
    println!(
        "measured {:.3e} s/step on {} threads ({:.3e} tet-steps/s): estimated run time {} (outputs not counted)",
        per_step,
        rayon::current_num_threads(),
        sim.tets() as f64 / per_step,
        progress::clock(total)
    );
    print_force_split(&mut sim, &stepped, per_step, 10);
    Ok(())
}

/// Where a step's time goes: each model's force evaluation timed over `n` calls on the state
/// the cost measurement left, as a share of the measured step; models under 1% are summed.
fn print_force_split(sim: &mut Simulation, state: &qdem_core::State, per_step: f64, n: usize) {
    let mut force = vec![qdem_core::Vec3::zeros(); state.len()];
    let mut torque = vec![qdem_core::Vec3::zeros(); state.rigid.len() + state.spin.len()];
    let mut rest = 0.0;
    let mut forces = 0.0;
    println!("time per step by model (force evaluation, {n} calls each):");
    for model in sim.models.iter_mut() {
        let start = Instant::now();
        for _ in 0..n {
            model.add_forces(state, &mut force, &mut torque);
        }
        let seconds = start.elapsed().as_secs_f64() / n as f64;
        forces += seconds;
        if seconds < 0.01 * per_step {
            rest += seconds;
            continue;
        }
        println!(
            "  {:<24} {seconds:.3e} s ({:.1}%)",
            model.name(),
            100.0 * seconds / per_step
        );
    }
    println!(
        "  {:<24} {rest:.3e} s ({:.1}%)",
        "other models",
        100.0 * rest / per_step
    );
    let integrate = (per_step - forces).max(0.0);
    println!(
        "  {:<24} {integrate:.3e} s ({:.1}%)",
        "integration and checks",
        100.0 * integrate / per_step
    );
    if let Some(c) = sim.contacts() {
        println!(
            "  contacts after the measured steps: {} candidate pairs and wall candidates, {} touching",
            c.candidates(),
            c.contacts()
        );
    }
}

/// Wall seconds per step of the scene's own stepper, measured over `n` steps on a copy of the
/// state; for implicit and static scenes also prints the sparse system's size, non-zeros,
/// Cholesky fill and factorisation time from the stepper's one factorisation (in
/// `initialize`, which is not timed).
fn measure_step_cost(sim: &mut Simulation, n: usize) -> Result<(f64, qdem_core::State), CliError> {
    let run_error = |source| RunError::Core {
        scene: sim.scene.path.clone(),
        source,
    };
    let mut state = sim.state.clone();
    let mut stepper = make_stepper(sim).map_err(run_error)?;
    stepper
        .initialize(&mut state, &mut sim.models)
        .map_err(run_error)?;
    if let Some(s) = stepper.factor_stats() {
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
        stepper
            .step(&mut state, &mut sim.models)
            .map_err(run_error)?;
    }
    Ok((start.elapsed().as_secs_f64() / n as f64, state))
}
