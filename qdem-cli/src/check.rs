//! `qdem check SCENE`: validates a scene and prints its meshes, mass, stable step (of an
//! explicit run), the modelling advice ([`qdem_io::advice`]: each body and stone set rigid or
//! deformable, a body's formulation, the integrator, the contacts' stiffness; `--advice json` prints only
//! that), an estimate of the memory the run keeps, checkpoint support, the measured
//! cost of a step with the projected run time, and where a step's time goes, stage by stage of the world's step
//! ([`qdem_core::step::stages`]). Under `mpirun` (N > 1) the run is decomposed as `qdem run`
//! decomposes it, and rank 0 also prints each rank's tetrahedra, owned particles, halo,
//! contacts and measured stage times, the imbalance and the speed-up they predict; then the
//! ranks are cut again by what each model's items were measured to cost
//! ([`qdem_core::parallel::WorkWeights`]) and the table is printed again over as many steps.

use crate::command::CliError;
use crate::progress;
use crate::run_length;
use qdem_contact::{rayleigh_time, DemContacts};
use qdem_core::{
    parallel::Communicator, parallel::RankFigures, step::Model as _, step::Scheme, step::Stage,
    step::StageTimes,
};
use qdem_io::build::{memory, BodyKind, Simulation};
use qdem_io::runner::RunError;
use qdem_io::scene::Scene;
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

/// Loads and builds the scene at `path`, prints what `qdem check` reports, and measures the
/// cost of a step (inside the caller's thread pool); over `ranks`, decomposed, with the
/// ranks' figures.
pub fn check_scene(path: &Path, ranks: Option<Arc<dyn Communicator>>) -> Result<(), CliError> {
    let scene = Scene::load(path)?;
    let mut sim = progress::while_busy("building the scene", || Simulation::build(scene))?;
    build_contact_lists(&mut sim);
    if let Some(r) = &ranks {
        sim.world
            .decompose(r.clone())
            .map_err(|source| CliError::Decompose {
                scene: path.to_path_buf(),
                source,
            })?;
    }
    let leader = sim.world.rank() == 0;
    if leader {
        print_scene(path, &sim);
        for advice in qdem_io::advice::advise(&sim) {
            println!("{}", advice.line());
        }
    }
    initialize(&mut sim)?;
    let start = Window::start(&sim);
    let mut per_step = measure_steps(&mut sim, STEPS)?;
    if let Some(d) = sim.world.decomposition().cloned() {
        // The decomposition now: a re-partition moves grains and rigid bodies.
        let table = rank_table(&sim, &d, &start, "the fixed shares");
        if leader {
            print!("{table}");
        }
        if let Some(weights) = sim.world.measured_weights() {
            sim.world.repartition_weighted(weights);
            let start = Window::start(&sim);
            per_step = measure_steps(&mut sim, STEPS)?;
            let d = sim.world.decomposition().cloned().expect("decomposed");
            let table = rank_table(&sim, &d, &start, "the measured cost");
            if leader {
                print!("{table}");
            }
        }
        // The whole contact lists for the counts below.
        sim.world.gather();
    }
    if leader {
        print_cost(&sim, per_step);
    }
    Ok(())
}

/// The steps each measurement of `qdem check` takes.
const STEPS: usize = 20;

/// Builds the contact lists at the state the run starts from, where no step has built them
/// yet (a `[run] start_from` stage's), so that the contacts' step is estimated, and its
/// one-contact bound found, from the contacts of that state.
fn build_contact_lists(sim: &mut Simulation) {
    let world = &mut sim.world;
    let contacts = world.models.iter_mut().find_map(|m| {
        let m: &mut dyn std::any::Any = m.as_mut();
        m.downcast_mut::<DemContacts>()
    });
    if let Some(contacts) = contacts {
        contacts.build_lists(&world.state);
    }
}

/// `qdem check --advice json`: builds the scene at `path` and prints its advice as one JSON
/// array, nothing else.
pub fn print_advice_json(path: &Path) -> Result<(), CliError> {
    let scene = Scene::load(path)?;
    let sim = progress::while_busy("building the scene", || Simulation::build(scene))?;
    let json = qdem_io::advice::to_json(&qdem_io::advice::advise(&sim));
    println!("{json:#}");
    Ok(())
}

/// What the scene is: bodies, contacts, probes, the step, checkpoint support.
fn print_scene(path: &Path, sim: &Simulation) {
    println!("scene {}: valid", path.display());
    for w in &sim.warnings {
        println!("warning: {w}");
    }
    for body in &sim.bodies {
        let s = &body.stats;
        let mass = sim.body_mass(body);
        let kind = match body.kind {
            BodyKind::Rigid { .. } => "rigid",
            BodyKind::Stones { .. } => "rigid stones",
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
    println!("{}", integrator_line(sim));
    if !sim.world.settings().is_implicit() {
        print_step_limits(sim);
    }
    print_memory(sim);
    match sim.world.checkpointable() {
        Ok(()) => println!("checkpoints: supported (`checkpoint_every`, Ctrl-C, --resume)"),
        Err(why) => println!("checkpoints: not supported: {why}"),
    }
}

/// The integrator and its step: an explicit step against the stable bound it was chosen
/// under; an implicit step, or a static run's load levels, without it (no stable bound
/// applies to them).
fn integrator_line(sim: &Simulation) -> String {
    let settings = sim.world.settings();
    let (dt, steps, t_end) = (sim.world.dt(), sim.steps(), sim.scene.run.t_end);
    let name = sim.scene.run.integrator.name();
    match settings.request.scheme {
        Scheme::Static => format!(
            "integrator static: load levels every {dt:.6e} s, {steps} steps to t_end = {t_end} \
             s, one solve per distinct load level"
        ),
        scheme if scheme.is_implicit() => format!(
            "integrator {name}: dt {dt:.6e} s (implicit); {steps} steps to t_end = {t_end} s"
        ),
        _ => {
            let (bound, limiter) = &settings.stable_dt;
            format!(
                "integrator {name}: dt {dt:.6e} s ({:.3}x the explicit stable bound {bound:.6e} s \
                 set by `{limiter}`); {steps} steps to t_end = {t_end} s",
                dt / bound
            )
        }
    }
}

/// Per body, its kind and the explicit step its own model allows (a deformable body's
/// tetrahedra; a rigid body has none: its contacts act on its whole mass, in the contacts'
/// bound), then the contacts' bound: what limits this stage's step.
fn print_step_limits(sim: &Simulation) {
    let state = &sim.world.state;
    for body in &sim.bodies {
        let limit = match &body.kind {
            BodyKind::Deformable { model } => match sim.world.models[*model].stable_dt(state) {
                Some(dt) => format!("deformable, its tetrahedra bound the step at {dt:.4e} s"),
                None => "deformable, no bound of its own".to_string(),
            },
            BodyKind::Rigid { .. } => {
                "rigid, no bound of its own: its contacts act on its whole mass".to_string()
            }
            BodyKind::Stones { centers, .. } => format!(
                "{} rigid stones, no bound of their own: their contacts act on whole stones",
                centers.len()
            ),
        };
        println!("step limit of body `{}`: {limit}", body.name);
    }
    if let Some(contacts) = sim.contacts() {
        print_contact_step(sim, contacts);
    }
}

/// The contacts' step estimated from the contacts present, the step one contact alone cannot
/// be stepped above, and beside them Rayleigh's time of the smallest sphere and 20% of it,
/// the step LIGGGHTS's and EDEM's users usually take.
fn print_contact_step(sim: &Simulation, contacts: &DemContacts) {
    let state = &sim.world.state;
    if let Some(dt) = contacts.stable_dt(state) {
        let alone = contacts.unstable_above(state).map_or(String::new(), |u| {
            format!("; a step above {u:.4e} s, which one of them alone cannot take, is refused")
        });
        println!(
            "step limit of the contacts: {dt:.4e} s, estimated from the {} contacts present \
             (a larger dt is warned of, and the run stops if a contact comes to need a \
             shorter one){alone}",
            contacts.touching_at(state.time)
        );
    }
    let materials = &sim.scene.materials;
    let rayleigh = contacts
        .radii_and_materials()
        .filter_map(|(r, m)| materials.get(m).map(|m| (r, m)))
        .map(|(r, m)| rayleigh_time(r, m.density, m.young, m.poisson))
        .fold(f64::INFINITY, f64::min);
    if rayleigh.is_finite() {
        println!(
            "Rayleigh time of the smallest sphere: {rayleigh:.4e} s; 20% of it, the step \
             LIGGGHTS's and EDEM's users usually take: {:.4e} s",
            0.2 * rayleigh
        );
    }
}

/// The memory the run will keep, estimated from its particles and tetrahedra as the build
/// estimated it before allocating them ([`memory`]), against the machine's.
fn print_memory(sim: &Simulation) {
    let (particles, tets) = (sim.world.state.len(), sim.tets());
    let need = memory::estimate(particles as f64, tets as f64);
    let machine = memory::machine_memory().map_or("unknown".to_string(), memory::human);
    println!(
        "memory: about {} for {particles} particles and {tets} tets (the machine has {machine})",
        memory::human(need)
    );
}

/// The measured cost of a step, the projected run time and the stages.
fn print_cost(sim: &Simulation, per_step: f64) {
    let total = per_step * sim.steps() as f64;
    // A scene without tetrahedra (spheres, a bonded body) steps particles.
    let rate = match sim.tets() {
        0 => format!(
            "{:.3e} particle-steps/s",
            sim.world.state.len() as f64 / per_step
        ),
        tets => format!("{:.3e} tet-steps/s", tets as f64 / per_step),
    };
    let threads = rayon::current_num_threads();
    let settling = run_length::settled_contacts(sim, threads);
    let least = if settling.is_some() { "at least " } else { "" };
    println!(
        "measured {per_step:.3e} s/step on {threads} threads ({rate}): estimated run time \
         {least}{} (outputs not counted)",
        progress::clock(total)
    );
    if let Some(s) = settling {
        println!(
            "the step was measured with {} contacts; as a bed settles to about {} (6 per \
             grain) its steps cost more: about {} in all",
            s.now,
            s.settled,
            progress::clock((per_step + s.extra_step) * sim.steps() as f64)
        );
    }
    print_stages(sim);
}

/// The stage clock and the seconds spent in collectives at the start of a window of
/// measured steps.
struct Window {
    stages: StageTimes,
    waited: Vec<f64>,
}

impl Window {
    /// The window that starts now.
    fn start(sim: &Simulation) -> Window {
        let world = &sim.world;
        Window {
            stages: world.stages().clone(),
            waited: (0..world.models.len())
                .map(|i| world.waited_seconds(i))
                .collect(),
        }
    }

    /// The steps taken since the window started.
    fn steps(&self, sim: &Simulation) -> f64 {
        (sim.world.stages().steps() - self.stages.steps()).max(1) as f64
    }

    /// Seconds per step of `stage` since the window started.
    fn per_step(&self, sim: &Simulation, stage: Stage) -> f64 {
        (sim.world.stages().seconds(stage) - self.stages.seconds(stage)) / self.steps(sim)
    }

    /// Seconds per step of model `model`'s forces since the window started, less those
    /// spent in collectives (waiting for the other ranks): the work this rank was given.
    fn busy(&self, sim: &Simulation, model: usize) -> f64 {
        let waited = sim.world.waited_seconds(model) - self.waited[model];
        (self.per_step(sim, Stage::Forces(model)) - waited / self.steps(sim)).max(0.0)
    }
}

/// Each rank's share of a decomposed step cut by `weighed` (the work of what), gathered to
/// every rank (a collective: every rank calls it), over the steps since `window` started:
/// tetrahedra, owned particles, halo (block sums received per step), particles whose motion
/// it receives per step, the candidate contacts it evaluates, the contact spheres of other
/// ranks it receives (ghosts) and those it owns, the work the partition gave it (in particle
/// steps), its step, and the seconds per step of its tetrahedra (the deformable bodies'
/// forces), its contacts and its particles' prediction and integration, without the waits
/// in collectives, and of its share of the state; the imbalance of the kernel (the slowest
/// rank's kernel time over the mean), and the speed-up over one process that these times
/// predict (their sum over all ranks, what one process would compute, over the busiest
/// rank's: no exchange counted).
fn rank_table(sim: &Simulation, d: &RankFigures, window: &Window, weighed: &str) -> String {
    let world = &sim.world;
    let kinds = |deformable: bool| {
        let models = world.models.iter().enumerate();
        models
            .filter(move |(_, m)| m.deformable().is_some() == deformable)
            .map(|(i, _)| i)
    };
    let kernel: f64 = kinds(true).map(|i| window.busy(sim, i)).sum();
    let contact: f64 = kinds(false)
        .filter(|&i| {
            let model: &dyn std::any::Any = world.models[i].as_ref();
            model.is::<DemContacts>()
        })
        .map(|i| window.busy(sim, i))
        .sum();
    let particles = window.per_step(sim, Stage::Predict) + window.per_step(sim, Stage::Integrate);
    let share = window.per_step(sim, Stage::Share);
    let steps = window.steps(sim);
    let forces: f64 = (0..world.models.len())
        .map(|i| window.per_step(sim, Stage::Forces(i)))
        .sum();
    let step = forces + particles + share;
    // The spheres this rank owns, the contacts it evaluates and the ghosts it receives
    // (split contacts).
    let (spheres, contacts, ghosts) = sim
        .contacts()
        .map_or((0, 0, 0), |c| (c.own_spheres(), c.candidates(), c.ghosts()));
    let mine = [
        step,
        kernel,
        contact,
        particles,
        share,
        contacts as f64,
        ghosts as f64,
        spheres as f64,
    ];
    let all = world.rank_rows(&mine);
    let mut table = format!(
        "decomposed over {} ranks, cut by {weighed} ({} bodies cut between ranks), {steps} steps:\n  rank  tets      owned     halo      received  contacts  ghosts    spheres   work      step (s)   tets (s)   contacts (s) particles (s) share (s)\n",
        d.ranks, d.cut_bodies
    );
    for (r, row) in all.chunks_exact(8).enumerate() {
        table += &format!(
            "  {r:<5} {:<9} {:<9} {:<9} {:<9} {:<9} {:<9} {:<9} {:<9.0} {:.3e}  {:.3e}  {:.3e}    {:.3e}     {:.3e}\n",
            d.tets[r],
            d.owned[r],
            d.halo[r],
            d.received[r],
            row[5],
            row[6],
            row[7],
            d.work[r],
            row[0],
            row[1],
            row[2],
            row[3],
            row[4]
        );
    }
    if let Some(weights) = world.work_weights().filter(|w| !w.models.is_empty()) {
        let named = world.models.iter().zip(&weights.models);
        let named: Vec<String> = named
            .filter(|(_, &w)| w != 1.0)
            .map(|(m, w)| format!("`{}` {w:.3}", m.name()))
            .collect();
        table += &format!(
            "  weights of the items' fixed shares, measured: {}\n",
            named.join(", ")
        );
    }
    if world.repartitions() > 0 {
        table += &format!(
            "  re-partitioned {} times so far (by the work of the lists then built)\n",
            world.repartitions()
        );
    }
    let column = |k: usize| all.chunks_exact(8).map(|row| row[k]).collect::<Vec<_>>();
    match d.tets.iter().sum::<usize>() {
        0 => {
            let contacts = imbalance(&column(5));
            table += &format!("  contact imbalance (most candidates / mean): {contacts:.3}\n");
        }
        _ => {
            let kernel = imbalance(&column(1));
            table += &format!("  kernel imbalance (slowest / mean): {kernel:.3}\n");
        }
    }
    let busy: Vec<f64> = all
        .chunks_exact(8)
        .map(|row| row[1] + row[2] + row[3])
        .collect();
    let slowest = busy.iter().cloned().fold(0.0, f64::max);
    table += &format!(
        "  predicted speed-up over one process: {:.2}x (the ranks' tets, contacts and \
         particles summed over the busiest rank's, no exchange counted)\n",
        busy.iter().sum::<f64>() / slowest.max(f64::MIN_POSITIVE)
    );
    table
}

/// The largest of `values` over their mean.
fn imbalance(values: &[f64]) -> f64 {
    let mean = values.iter().sum::<f64>() / values.len() as f64;
    let largest = values.iter().cloned().fold(0.0, f64::max);
    largest / mean.max(f64::MIN_POSITIVE)
}

/// Where the measured steps' time went, stage by stage ([`qdem_core::step::stages`]).
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

/// Initialises the scene's world for its first step; for implicit and static scenes also
/// prints the sparse system's size, non-zeros, Cholesky fill and factorisation time from the
/// stepper's one factorisation (in `initialize`, which is not timed).
fn initialize(sim: &mut Simulation) -> Result<(), CliError> {
    let scene = sim.scene.path.clone();
    let world = &mut sim.world;
    world
        .initialize()
        .map_err(|source| RunError::Core { scene, source })?;
    if let Some(s) = world.stepper().report().factor {
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
    Ok(())
}

/// Wall seconds per step of the scene's world over `n` more steps (fewer if it ends).
fn measure_steps(sim: &mut Simulation, n: usize) -> Result<f64, CliError> {
    let scene = sim.scene.path.clone();
    let world = &mut sim.world;
    let (before, start) = (world.stages().steps(), Instant::now());
    for _ in 0..n {
        let step = world.step().map_err(|source| RunError::Core {
            scene: scene.clone(),
            source,
        })?;
        if step.is_some() {
            break;
        }
    }
    let taken = (world.stages().steps() - before).max(1);
    Ok(start.elapsed().as_secs_f64() / taken as f64)
}
