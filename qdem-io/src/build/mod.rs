//! Building a simulation from a scene: meshes read, reordered and placed (`rotate_deg`,
//! `translate`), particles of all bodies laid out one body after another in one [`State`]
//! (then one centre particle per rigid body), and only the models the scene needs: a
//! [`TetBody`] per deformable body (a rigid body gets none: its mass and inertia come from its
//! tetrahedra, [`qdem_core::step::rigid_body`]), contacts only when bodies carry contact spheres
//! (`contact`), [`Gravity`] only for a non-zero gravity, a [`NodalLoad`] per load.
//!
//! # The stage
//!
//! Building is the stage after [validation](crate::scene): it reads a validated [`Scene`] and
//! the references validation resolved ([`Scene::refs`]: each body's material, each fix's, load's
//! and probe's body as indices), so no name is looked up again here. One module per part of a
//! scene, each taking the table it builds and the indices it needs:
//!
//! - this module: the `[[body]]` meshes, fixes, loads and the step request; `area_load`: a
//!   load's pressure or traction on the selected faces, lumped to their nodes;
//! - [`probes`]: the `[[probe]]`s on particles, stones and boxes; `initial_motion`: the
//!   bodies' and stones' initial velocity and angular velocity;
//! - `contact`: contact spheres, the `[contact]` law and the `[[wall]]`s; `overlap_advice`:
//!   the scene keys that fix a start the contact set-up refuses;
//! - [`granular`]: the rigid stones of `[granular]`; [`ballast`]: the deformable stones of
//!   `[ballast]`; `bonded`: a `[bonded]` body (built instead of everything else);
//! - `periodic`: the `[periodic]` cell, its wrap groups and time delay;
//! - `rest_on`: bodies laid on a granular sample; `load_series`: a load's CSV time series;
//! - `start_from`: the state of another scene's checkpoint; `kind_change`: a body rigid there
//!   and deformable here, or the other way round;
//! - [`memory`]: the memory a count needs, refused before allocating beyond the machine;
//!   `step_check`: a time step that cannot advance the run, refused; `absurd_inputs`: valid
//!   inputs that are hardly meant (a tiny dt, a far probe, a soft stone), warned of;
//! - [`BuildError`] (`error`): why a build failed.

mod absurd_inputs;
mod area_load;
pub mod ballast;
mod bonded;
mod contact;
mod error;
pub(crate) mod fix_frames;
pub mod granular;
mod initial_motion;
mod kind_change;
pub(crate) mod load_series;
pub mod locking;
pub mod memory;
mod overlap_advice;
mod periodic;
pub mod pose_from;
pub mod probes;
pub mod refill;
mod rest_on;
mod start_from;
mod step_check;

pub use area_load::load_resultant;
pub use error::BuildError;

use crate::scene::suggest::did_you_mean;
use crate::scene::{Body, EventSolveName, Integrator, Scene, Selection, TimeStep};
use ballast::{place_ballast, BallastInfo};
use contact::ExtraSpheres;
use granular::GranularInfo;
use nalgebra::{Rotation3, UnitQuaternion};
use qdem_contact::BondedParticles;
use qdem_contact::{DemContacts, PeriodicBox, PeriodicWrap};
use qdem_core::step::model::Deformable;
use qdem_core::step::rigid_body::tet_mass_properties;
use qdem_core::{
    continuum::Material, continuum::TetBody, error::CoreError, loads::Gravity, loads::NodalLoad,
    loads::TimeFunction, step::Dofs, step::EventSolve, step::MemberHold, step::Model, step::Scheme,
    step::State, step::StepRequest, step::StepSettings, world::World, Mat3, Vec3,
};
use qdem_mesh::{read_msh, FileIds, MeshError, MeshStats, TetMesh};
use std::ops::Range;
use std::path::{Path, PathBuf};

/// How a body is integrated.
#[derive(Clone, Debug)]
pub enum BodyKind {
    /// A QDEM body: index of its [`TetBody`] in the world's models ([`qdem_core::world::World::models`]).
    Deformable {
        /// The model index.
        model: usize,
    },
    /// A rigid body: its index in `state.rigid`, its centre particle and its tetrahedra (for
    /// output).
    Rigid {
        /// Index into [`State::rigid`].
        body: usize,
        /// Its centre particle.
        center: usize,
        /// Its tetrahedra, as state particle indices.
        tets: Vec<[u32; 4]>,
        /// Orientation its principal frame had in the body's design placement (after
        /// `rotate_deg` and `translate`, before `pose_from`): the pose written to `poses.csv`
        /// is measured from it ([`pose_from`]).
        design_frame: UnitQuaternion<f64>,
    },
    /// The `[ballast]` stones with `rigid = true`: one rigid body per stone, stone `k` being
    /// rigid body `first + k` with centre particle `centers[k]`.
    Stones {
        /// Index into [`State::rigid`] of the first stone.
        first: usize,
        /// Each stone's centre particle.
        centers: Vec<usize>,
        /// The stones' tetrahedra, as state particle indices (for output).
        tets: Vec<[u32; 4]>,
    },
}

/// What the output needs to know about one body.
#[derive(Clone, Debug)]
pub struct BodyInfo {
    /// Body name.
    pub name: String,
    /// Its particles in the state (a rigid body's members; its centre comes after all bodies).
    pub particles: Range<usize>,
    /// Deformable or rigid.
    pub kind: BodyKind,
    /// Mesh statistics.
    pub stats: MeshStats,
    /// Mesh file.
    pub mesh: PathBuf,
    /// The mesh file's numbering of its particles (in `particles` order) and tetrahedra (in
    /// [`Simulation::body_tets`] order), and their physical volumes; empty for the
    /// `[ballast]` stones, which are drawn from many files.
    pub file_ids: FileIds,
}

/// A probe resolved to a particle.
#[derive(Clone, Debug)]
pub struct ProbePoint {
    /// Probe name.
    pub name: String,
    /// Sampled particle.
    pub particle: usize,
    /// Distance from the requested point to the particle (m).
    pub distance: f64,
}

/// A ready-to-run simulation: the [`World`] that steps, and what the outputs need to know of
/// the scene's bodies and probes.
pub struct Simulation {
    /// The scene it was built from.
    pub scene: Scene,
    /// The state of all bodies, their models (bodies first in scene order, then contacts,
    /// gravity, loads), the stepper and the post-step hooks (periodic wrapping, a bonded
    /// body's collapse watch).
    pub world: World,
    /// Per-body output information.
    pub bodies: Vec<BodyInfo>,
    /// Probes on particles (a body's, a stone's centre) in scene order.
    pub probes: Vec<ProbePoint>,
    /// Probes on boxes over the `[granular]` sample, in scene order.
    pub regions: Vec<probes::RegionProbe>,
    /// Warnings, one line each, naming the file: the meshes', and inputs that are valid but
    /// hardly meant (`absurd_inputs`).
    pub warnings: Vec<String>,
    /// The stones of `[granular]`.
    pub granular: Option<GranularInfo>,
    /// The stones of `[ballast]`.
    pub ballast: Option<BallastInfo>,
    /// The particles each `[[fix]]` selects (state indices, increasing), in scene order: what
    /// `reactions.csv` sums.
    pub fix_particles: Vec<Vec<usize>>,
    /// For each `[[fix]]` with a `frame`, its basis (columns e₁, e₂, e₃ in world axes) at
    /// each of its particles, in `fix_particles`' order; `None` for a fix on the axes.
    pub fix_frames: Vec<Option<Vec<Mat3>>>,
}

/// Each `[[fix]]`'s particles and, for a framed one, its basis at each.
type FixedParticles = (Vec<Vec<usize>>, Vec<Option<Vec<Mat3>>>);

/// A body's mesh as read and placed, with its file and its particles' place in the state.
pub(crate) struct PlacedMesh {
    pub(crate) mesh: TetMesh,
    pub(crate) path: PathBuf,
    pub(crate) particles: Range<usize>,
    /// The rotation `pose_from` gave the mesh from its design placement (identity without).
    pub(crate) rotation: UnitQuaternion<f64>,
}

impl Simulation {
    /// Reads the meshes and builds every model of `scene`: bodies, then gravity (only if
    /// non-zero), then loads; fixes go into the state. Refuses counts that would need more
    /// memory than the machine has before allocating them ([`memory`]), and a time step that
    /// cannot advance the run (`step_check`); warns of inputs that are hardly meant
    /// (`absurd_inputs`).
    pub fn build(scene: Scene) -> Result<Simulation, BuildError> {
        let mut sim = Simulation::build_models(scene)?;
        step_check::check_step(&sim)?;
        let absurd = absurd_inputs::warnings(&sim);
        sim.warnings.extend(absurd);
        Ok(sim)
    }

    /// [`Simulation::build`] before its step is checked.
    fn build_models(scene: Scene) -> Result<Simulation, BuildError> {
        if let Some((bonded, material)) = scene.bonded.clone().zip(scene.refs().bonded_material) {
            let material = scene.materials[material].clone();
            return bonded::build_bonded(scene, &bonded, &material);
        }
        let core = |source| BuildError::Core {
            scene: scene.path.clone(),
            source,
        };
        let (mut meshes, mut warnings, mut ballast) = read_meshes(&scene)?;
        warnings.extend(locking::warnings(&scene));
        let (stones, sampled) = match &scene.granular {
            Some(g) => granular::stones(&scene, g)?,
            None => (Vec::new(), 0),
        };
        let periodic_box = match &scene.periodic {
            Some(p) => Some(periodic::periodic_box(&scene, p)?),
            None => None,
        };
        pose_from::pose_bodies(&scene, &mut meshes)?;
        rest_on::rest_bodies(&scene, &mut meshes, &stones, periodic_box.as_ref())?;
        let reference = meshes
            .iter()
            .flat_map(|m| m.mesh.nodes.iter().map(|p| Vec3::from(*p)));
        let mut state = State::at_rest(reference.collect());
        let mut models: Vec<Box<dyn Model>> = Vec::new();
        let bodies = build_bodies(&scene, &meshes, ballast.as_mut(), &mut state, &mut models)
            .map_err(core)?;
        let deformable_ballast = ballast.as_ref().filter(|info| info.centers.is_empty());
        if let Some((b, info)) = scene.ballast.as_ref().zip(deformable_ballast) {
            for stone in &info.stones {
                let (v, w) = (Vec3::from(b.velocity), Vec3::from(b.angular_velocity));
                initial_motion::move_rigidly(&mut state, stone.clone(), v, w);
            }
        }
        let (fix_particles, fix_frames) = apply_fixes(&scene, &meshes, &mut state)?;
        fix_rigid_bodies(&scene, &bodies, &fix_particles, &mut state);
        let mut extra = ExtraSpheres::of_ballast(ballast.as_ref());
        let granular = add_granular(&scene, (&stones, sampled), &mut state, &mut extra)?;
        let periodic = periodic_box.map(|p| {
            let groups =
                periodic::wrap_groups(&state, &bodies, granular.as_ref(), ballast.as_ref());
            (p, groups)
        });
        extra.periodic = periodic.as_ref().map(|p| p.0.clone());
        add_forces(&scene, &meshes, &state, extra, &mut models)?;
        if let Some(file) = &scene.run.start_from {
            let units = kind_change::units(&scene, &meshes, &bodies, ballast.as_ref());
            let p = periodic.as_ref();
            let contacts = models.iter_mut().find_map(|m| {
                let m: &mut dyn std::any::Any = m.as_mut();
                m.downcast_mut::<DemContacts>()
            });
            warnings.extend(start_from::restore_state(
                &scene,
                file,
                &units,
                (&mut state, contacts),
                p,
            )?);
        }
        let (probes, regions) = probes::resolve_probes(&scene, &bodies, granular.as_ref(), &state)?;
        let settings =
            StepSettings::resolve(&step_request(&scene), &state, &models).map_err(core)?;
        let mut world = World::new(state, models, settings).map_err(core)?;
        if let Some((cell, groups)) = periodic {
            world.add_hook(Box::new(PeriodicWrap::new(cell, groups)));
        }
        Ok(Simulation {
            scene,
            world,
            bodies,
            probes,
            regions,
            warnings,
            granular,
            ballast,
            fix_particles,
            fix_frames,
        })
    }

    /// The mesh files' tag of every particle of the state (`gmsh_node_id`), −1 where no file
    /// numbers it: a generated body, the `[ballast]` stones, a rigid body's centre, a
    /// sphere, an id beyond 2⁶³ − 1 (which only a binary file can hold).
    pub fn gmsh_node_ids(&self) -> Vec<i64> {
        let mut nodes = vec![-1; self.world.state.len()];
        for body in &self.bodies {
            let file = &body.file_ids.nodes;
            for (slot, n) in nodes[body.particles.clone()].iter_mut().zip(file) {
                *slot = i64::try_from(*n).unwrap_or(-1);
            }
        }
        nodes
    }

    /// Number of steps to reach `t_end` (the last one may end slightly past it for a fixed dt).
    pub fn steps(&self) -> u64 {
        self.world.settings().steps_to(self.scene.run.t_end)
    }

    /// Number of tetrahedra in all bodies.
    pub fn tets(&self) -> usize {
        self.bodies.iter().map(|b| b.stats.tets).sum()
    }

    /// The deformable body's model as a [`Deformable`] (its [`TetBody`]); `None` for a rigid
    /// one.
    pub fn tet_body(&self, body: &BodyInfo) -> Option<&dyn Deformable> {
        let BodyKind::Deformable { model } = body.kind else {
            return None;
        };
        self.world.models[model].deformable()
    }

    /// The tetrahedra of a body, deformable or rigid, as state particle indices.
    pub fn body_tets<'a>(&'a self, body: &'a BodyInfo) -> &'a [[u32; 4]] {
        match &body.kind {
            BodyKind::Rigid { tets, .. } | BodyKind::Stones { tets, .. } => tets,
            BodyKind::Deformable { .. } => self
                .tet_body(body)
                .expect("a deformable body has a TetBody")
                .tets(),
        }
    }

    /// The mass of a body (kg).
    pub fn body_mass(&self, body: &BodyInfo) -> f64 {
        let mass = &self.world.state.mass;
        match body.kind {
            BodyKind::Deformable { .. } => mass[body.particles.clone()].iter().sum(),
            BodyKind::Rigid { center, .. } => mass[center],
            BodyKind::Stones { ref centers, .. } => centers.iter().map(|&c| mass[c]).sum(),
        }
    }

    /// The bonded-particle model of a `[bonded]` scene.
    pub fn bonded(&self) -> Option<&BondedParticles> {
        self.world.model::<BondedParticles>()
    }

    /// The contact model, if the scene has contacts.
    pub fn contacts(&self) -> Option<&DemContacts> {
        self.world.model::<DemContacts>()
    }

    /// The periodic cell of `[periodic]`.
    pub fn periodic(&self) -> Option<&PeriodicBox> {
        self.world.hook::<PeriodicWrap>().map(|w| &w.cell)
    }
}

/// The models that act between and on the bodies, after the bodies': contacts (when something
/// can touch), gravity (when it is not zero), then one [`NodalLoad`] per `[[load]]`.
fn add_forces(
    scene: &Scene,
    meshes: &[PlacedMesh],
    state: &State,
    extra: ExtraSpheres,
    models: &mut Vec<Box<dyn Model>>,
) -> Result<(), BuildError> {
    if let Some(contacts) = contact::build_contacts(scene, meshes, state, extra)? {
        models.push(Box::new(contacts));
    }
    if scene.run.gravity.iter().any(|&g| g != 0.0) {
        models.push(Box::new(Gravity::new(Vec3::from(scene.run.gravity))));
    }
    build_loads(scene, meshes, models)
}

/// The `[granular]` stones appended to `state` as rigid bodies after the mesh bodies and the
/// ballast stones, their spheres and names added to `extra`.
fn add_granular(
    scene: &Scene,
    stones: (&[qdem_contact::samples::clump_sample::Stone], usize),
    state: &mut State,
    extra: &mut ExtraSpheres,
) -> Result<Option<GranularInfo>, BuildError> {
    let Some((g, material)) = scene.granular.as_ref().zip(scene.refs().granular_material) else {
        return Ok(None);
    };
    let (info, spheres) = granular::add_stones(
        &scene.path,
        g,
        stones,
        state,
        scene.bodies.len() + extra.names.len(),
        (material, scene.materials[material].density),
    )?;
    extra.spheres.extend(spheres);
    extra
        .names
        .extend((1..=info.len()).map(|k| format!("{} stone {k}", g.name)));
    Ok(Some(info))
}

/// The placed meshes, mesh warnings and `[ballast]` stones of a scene.
type ReadMeshes = (Vec<PlacedMesh>, Vec<String>, Option<BallastInfo>);

/// Reads (and reorders, unless the body says not to) every body's mesh, laying the bodies'
/// particles out one after another, then the `[ballast]` stones as one more mesh.
fn read_meshes(scene: &Scene) -> Result<ReadMeshes, BuildError> {
    let mut warnings = Vec::new();
    let mut meshes: Vec<PlacedMesh> = Vec::new();
    for body in &scene.bodies {
        let path = scene.mesh_path(body);
        let mut mesh = read_mesh(&path, &mut warnings)?;
        coincident_nodes(&mut mesh, body, &path, &mut warnings);
        if body.reorder {
            mesh.reorder_for_locality();
        }
        place(&mut mesh, body.rotate_deg, body.translate);
        let start = meshes.last().map_or(0, |m| m.particles.end);
        let particles = start..start + mesh.nodes.len();
        meshes.push(PlacedMesh {
            mesh,
            path,
            particles,
            rotation: UnitQuaternion::identity(),
        });
    }
    let mut ballast = None;
    if let Some((b, material)) = scene.ballast.as_ref().zip(scene.refs().ballast_material) {
        let start = meshes.last().map_or(0, |m| m.particles.end);
        let first_body = scene.bodies.len();
        let (placed, info, stone_warnings) = place_ballast(scene, b, start, first_body, material)?;
        meshes.push(placed);
        warnings.extend(stone_warnings);
        ballast = Some(info);
    }
    Ok((meshes, warnings, ballast))
}

/// Reads the mesh at `path`, adding its warnings, each naming the file, to `warnings`.
pub(crate) fn read_mesh(path: &Path, warnings: &mut Vec<String>) -> Result<TetMesh, MeshError> {
    let (mesh, mesh_warnings) = read_msh(path)?;
    warnings.extend(
        mesh_warnings
            .iter()
            .map(|w| format!("{}: {w}", path.display())),
    );
    Ok(mesh)
}

/// Merges the coincident nodes of a body's mesh with `merge_nodes = true`; without it, warns
/// of them, naming the count and where the first is.
fn coincident_nodes(mesh: &mut TetMesh, body: &Body, path: &Path, warnings: &mut Vec<String>) {
    if body.merge_nodes {
        mesh.merge_coincident_nodes();
        return;
    }
    if let Some(c) = mesh.coincident_nodes() {
        let [x, y, z] = c.at;
        warnings.push(format!(
            "{}: body `{}`: {} nodes coincide with another node (within {:.1e} m), the first \
             (node {}, with node {}) at ({x}, {y}, {z}) m: no tetrahedron joins them, so the \
             body is in pieces there; fix: merge_nodes = true on the body, or merge them in \
             the mesher (gmsh: Coherence)",
            path.display(),
            body.name,
            c.count,
            c.tolerance,
            c.first.0 + 1,
            c.first.1 + 1
        ));
    }
}

/// Rotates the nodes about their centroid by `degrees` about x, then y, then z, then
/// translates them.
fn place(mesh: &mut TetMesh, degrees: [f64; 3], shift: [f64; 3]) {
    if degrees == [0.0; 3] && shift == [0.0; 3] {
        return;
    }
    let [rx, ry, rz] = degrees.map(f64::to_radians);
    let rotation = Rotation3::from_axis_angle(&Vec3::z_axis(), rz)
        * Rotation3::from_axis_angle(&Vec3::y_axis(), ry)
        * Rotation3::from_axis_angle(&Vec3::x_axis(), rx);
    let centroid = mesh
        .nodes
        .iter()
        .fold(Vec3::zeros(), |c, p| c + Vec3::from(*p))
        / mesh.nodes.len() as f64;
    for p in &mut mesh.nodes {
        let x = centroid + rotation * (Vec3::from(*p) - centroid) + Vec3::from(shift);
        *p = x.into();
    }
}

/// One [`TetBody`] per deformable body, its lumped mass added to the state; one rigid body
/// (a new centre particle at its centre of mass) per rigid body, then the `[ballast]` stones
/// (one body, or a rigid body per stone). Sets initial velocities and angular velocities
/// (`initial_motion`) of the bodies and of rigid stones.
fn build_bodies(
    scene: &Scene,
    meshes: &[PlacedMesh],
    ballast_info: Option<&mut BallastInfo>,
    state: &mut State,
    models: &mut Vec<Box<dyn Model>>,
) -> Result<Vec<BodyInfo>, CoreError> {
    let mut bodies = Vec::new();
    let materials = &scene.refs().body_materials;
    for ((body, placed), &material) in scene.bodies.iter().zip(meshes).zip(materials) {
        let material = &scene.materials[material];
        let tets = offset_tets(&placed.mesh, placed.particles.start);
        let velocity = Vec3::from(body.velocity);
        let omega = Vec3::from(body.angular_velocity);
        let kind = if body.rigid {
            let (mass, center, inertia) =
                tet_mass_properties(&state.reference, &tets, material.density);
            let c = state.push_particle(center, velocity, mass);
            let members: Vec<usize> = placed.particles.clone().collect();
            let index = state.add_rigid_body(&body.name, c, &members, inertia)?;
            state.rigid.set_angular_velocity(index, omega);
            BodyKind::Rigid {
                body: index,
                center: c,
                tets,
                design_frame: placed.rotation.inverse() * state.rigid.orientation[index],
            }
        } else {
            let core = core_material(material);
            let tet_body = TetBody::new(&body.name, &state.reference, tets, core)?
                .with_formulation(material.formulation.core());
            tet_body.lump_mass(&mut state.mass);
            models.push(Box::new(tet_body));
            BodyKind::Deformable {
                model: models.len() - 1,
            }
        };
        match kind {
            BodyKind::Rigid { .. } | BodyKind::Stones { .. } => {
                state.velocity[placed.particles.clone()].fill(velocity)
            }
            BodyKind::Deformable { .. } => {
                initial_motion::move_rigidly(state, placed.particles.clone(), velocity, omega)
            }
        }
        bodies.push(BodyInfo {
            name: body.name.clone(),
            particles: placed.particles.clone(),
            kind,
            stats: placed.mesh.stats(),
            mesh: placed.path.clone(),
            file_ids: placed.mesh.file_ids.clone(),
        });
    }
    let ballast = scene.ballast.as_ref().zip(scene.refs().ballast_material);
    if let (Some((b, material)), Some(placed), Some(info)) =
        (ballast, meshes.get(scene.bodies.len()), ballast_info)
    {
        let material = &scene.materials[material];
        bodies.push(if b.rigid {
            rigid_ballast_body(b, material.density, placed, info, state)?
        } else {
            ballast_body(b, material, placed, state, models)?
        });
    }
    if scene
        .bodies
        .iter()
        .any(|b| b.rigid && b.angular_velocity != [0.0; 3])
    {
        qdem_core::step::rigid_body::place_members(state);
    }
    Ok(bodies)
}

/// The `[ballast]` stones as one [`TetBody`] of `material` in its formulation, their lumped
/// mass added to the state, with their initial velocity.
fn ballast_body(
    b: &crate::scene::Ballast,
    material: &crate::scene::Material,
    placed: &PlacedMesh,
    state: &mut State,
    models: &mut Vec<Box<dyn Model>>,
) -> Result<BodyInfo, CoreError> {
    let tets = offset_tets(&placed.mesh, placed.particles.start);
    let stones = TetBody::new(&b.name, &state.reference, tets, core_material(material))?
        .with_formulation(material.formulation.core());
    stones.lump_mass(&mut state.mass);
    models.push(Box::new(stones));
    for i in placed.particles.clone() {
        state.velocity[i] = Vec3::from(b.velocity);
    }
    Ok(BodyInfo {
        name: b.name.clone(),
        particles: placed.particles.clone(),
        kind: BodyKind::Deformable {
            model: models.len() - 1,
        },
        stats: placed.mesh.stats(),
        mesh: placed.path.clone(),
        file_ids: placed.mesh.file_ids.clone(),
    })
}

/// The `[ballast]` stones with `rigid = true`, one rigid body each
/// ([`ballast::rigid_stones`]), with their initial velocity and angular velocity.
fn rigid_ballast_body(
    b: &crate::scene::Ballast,
    density: f64,
    placed: &PlacedMesh,
    info: &mut BallastInfo,
    state: &mut State,
) -> Result<BodyInfo, CoreError> {
    let tets = offset_tets(&placed.mesh, placed.particles.start);
    let motion = (Vec3::from(b.velocity), Vec3::from(b.angular_velocity));
    let first = ballast::rigid_stones(info, &tets, density, motion, state)?;
    Ok(BodyInfo {
        name: b.name.clone(),
        particles: placed.particles.clone(),
        kind: BodyKind::Stones {
            first,
            centers: info.centers.clone(),
            tets,
        },
        stats: placed.mesh.stats(),
        mesh: placed.path.clone(),
        file_ids: placed.mesh.file_ids.clone(),
    })
}

/// The `[[fix]]`es on rigid bodies' members (a rigid `[[body]]`, the `[ballast]`'s rigid
/// stones): a body with `rotation = true` on one of its fixes only moves along, its rotation
/// held and its centre fixed in every direction a member is held in; any other is held at its
/// members in their directions ([`State::hold_members`]: free to turn about them, or held
/// whole where they leave it no motion), each stone at its own members. `fixed` holds each
/// fix's particles.
fn fix_rigid_bodies(scene: &Scene, bodies: &[BodyInfo], fixed: &[Vec<usize>], state: &mut State) {
    let on = &scene.refs().fix_bodies;
    let mut holds = Vec::new();
    for (k, body) in bodies.iter().enumerate() {
        if matches!(body.kind, BodyKind::Deformable { .. }) {
            continue;
        }
        let fixes = || {
            scene
                .fixes
                .iter()
                .zip(on)
                .enumerate()
                .filter(move |(_, (_, &b))| b == k)
        };
        if let BodyKind::Rigid { body: b, .. } = body.kind {
            if fixes().any(|(_, (f, _))| f.rotation) {
                state.rigid.spin_fixed[b] = true;
                state.rigid.set_angular_velocity(b, Vec3::zeros());
            }
        }
        for (i, (fix, _)) in fixes() {
            let dofs = Dofs::from_mask(fix.dofs);
            holds.extend(fixed[i].iter().map(|&particle| MemberHold {
                particle,
                dofs,
                fix: i + 1,
            }));
        }
    }
    state.hold_members(&holds);
}

/// Fixes the selected directions of the selected particles of every `[[fix]]`, on the axes
/// or in its frame (`fix_frames`); returns each fix's particles and, for a fix with a frame,
/// the basis at each of them.
fn apply_fixes(
    scene: &Scene,
    meshes: &[PlacedMesh],
    state: &mut State,
) -> Result<FixedParticles, BuildError> {
    let on = &scene.refs().fix_bodies;
    let mut fixed = Vec::with_capacity(scene.fixes.len());
    let mut frames = Vec::with_capacity(scene.fixes.len());
    // Per particle, each held direction (world axes) with its fix's number.
    let mut held = vec![Vec::new(); state.len()];
    for (i, (fix, &body)) in scene.fixes.iter().zip(on).enumerate() {
        let placed = &meshes[body];
        let what = format!("[[fix]] #{}", i + 1);
        let selected = select(scene, placed, &fix.selection, &what, &fix.body)?;
        let particles: Vec<usize> = selected
            .iter()
            .map(|&n| placed.particles.start + n as usize)
            .collect();
        let dofs = Dofs::from_mask(fix.dofs);
        let mut bases = Vec::new();
        for &p in &particles {
            let basis = fix_frames::basis_at(&scene.path, fix, &what, p, state.reference[p])?;
            match basis {
                None => state.fix(p, dofs),
                Some(r) => {
                    state
                        .fix_in_frame(p, r, dofs)
                        .map_err(|e| BuildError::FixFrame {
                            scene: scene.path.clone(),
                            message: format!("{what}: {e}"),
                        })?;
                    bases.push(r);
                }
            }
            held[p].extend(fix_frames::held_vectors(basis.as_ref(), dofs).map(|e| (i + 1, e)));
        }
        fixed.push(particles);
        frames.push((!fix.frame.is_axes()).then_some(bases));
    }
    fix_frames::check_aligned(&scene.path, &held)?;
    Ok((fixed, frames))
}

/// A [`NodalLoad`] per `[[load]]`: its total force shared by the selected particles, or its
/// pressure or traction lumped to them ([`area_load`]).
fn build_loads(
    scene: &Scene,
    meshes: &[PlacedMesh],
    models: &mut Vec<Box<dyn Model>>,
) -> Result<(), BuildError> {
    let on = &scene.refs().load_bodies;
    for (i, (load, &body)) in scene.loads.iter().zip(on).enumerate() {
        let placed = &meshes[body];
        let what = format!("[[load]] #{}", i + 1);
        let selected = select(scene, placed, &load.selection, &what, &load.body)?;
        let start = placed.particles.start;
        let particles = selected
            .iter()
            .map(|&n| (start + n as usize) as u32)
            .collect();
        let ramp = match (&load.cyclic, &load.series) {
            (Some(c), _) => TimeFunction::cyclic(c.cycle()),
            (None, Some(series)) => TimeFunction::new(load_series::read_series(
                &scene.resolve(&series.file),
                &series.column,
            )?),
            (None, None) => load.ramp.time_function(),
        }
        .map_err(|source| BuildError::Core {
            scene: scene.path.clone(),
            source,
        })?;
        let model = match load.area {
            None => NodalLoad::new(&what, particles, Vec3::from(load.total_force), ramp),
            Some(area) => {
                let forces = area_load::lumped_forces(
                    scene,
                    placed,
                    &selected,
                    (&load.selection, area),
                    (&what, &load.body),
                )?;
                let forces = forces.into_iter().map(|(n, f)| (n + start as u32, f));
                NodalLoad::per_particle(&what, forces.collect(), ramp)
            }
        };
        models.push(Box::new(model));
    }
    Ok(())
}

/// The stepping `[run]` and `[contact]` ask for: the integrator, `dt` (or automatic: the
/// stable bound times `dt_safety` for an explicit scheme, the load-level interval `probe_every`
/// or t_end/100 for an implicit or static one, shrunk so that a whole number of steps reaches
/// t_end) and `[contact] local_damping`; [`StepSettings::resolve`] applies the rule.
pub(crate) fn step_request(scene: &Scene) -> StepRequest {
    let run = &scene.run;
    StepRequest {
        scheme: scheme(scene),
        dt: match run.dt {
            TimeStep::Auto => None,
            TimeStep::Fixed(dt) => Some(dt),
        },
        safety: run.dt_safety,
        local_damping: scene.contact.as_ref().map_or(0.0, |c| c.local_damping),
        adaptive: scene.bonded.as_ref().is_some_and(|b| b.adaptive),
        event_solve: match scene.bonded.as_ref().map(|b| b.event_solve) {
            Some(EventSolveName::Preconditioned) => EventSolve::Preconditioned,
            _ => EventSolve::Refactorize,
        },
        implicit_default: Some(run.probe_every.unwrap_or(run.t_end / 100.0)),
        fit_to: Some(run.t_end),
    }
}

/// A warning for `[bonded] event_solve = "preconditioned"` in a run that is not implicit,
/// where it does nothing.
pub(crate) fn ineffective_event_solve(scene: &Scene) -> Option<String> {
    let preconditioned = scene
        .bonded
        .as_ref()
        .is_some_and(|b| b.event_solve == EventSolveName::Preconditioned);
    let implicit = matches!(scheme(scene), Scheme::Newmark { beta, .. } if beta > 0.0);
    (preconditioned && !implicit).then(|| {
        format!(
            "{}: [bonded] event_solve = \"preconditioned\" has no effect in this {} run: it \
             applies to implicit Newmark steps (beta > 0) only",
            scene.path.display(),
            scene.run.integrator.name()
        )
    })
}

/// The scene's integrator as a scheme.
fn scheme(scene: &Scene) -> Scheme {
    let run = &scene.run;
    match run.integrator {
        Integrator::Verlet => Scheme::Verlet,
        Integrator::Newmark => Scheme::Newmark {
            beta: run.beta,
            gamma: run.gamma,
        },
        Integrator::Static => Scheme::Static,
    }
}

pub(crate) fn core_material(m: &crate::scene::Material) -> Material {
    Material {
        density: m.density,
        young: m.young,
        poisson: m.poisson,
        shear_viscosity: m.shear_viscosity,
        bulk_viscosity: m.bulk_viscosity,
    }
}

fn offset_tets(mesh: &TetMesh, offset: usize) -> Vec<[u32; 4]> {
    let offset = offset as u32;
    mesh.tets.iter().map(|t| t.map(|n| n + offset)).collect()
}

/// Mesh-local particle indices of a selection; an empty selection is an error.
fn select(
    scene: &Scene,
    placed: &PlacedMesh,
    selection: &Selection,
    what: &str,
    body: &str,
) -> Result<Vec<u32>, BuildError> {
    let (mesh, path) = (&placed.mesh, &placed.path);
    let nodes = match selection {
        Selection::Group(name) => match mesh.group(name) {
            Some(group) => group.nodes.clone(),
            None => return Err(missing_group(scene, mesh, path, name, what, body)),
        },
        Selection::Box([min, max]) => mesh.nodes_in_box(*min, *max),
    };
    if nodes.is_empty() {
        let fix = match selection {
            Selection::Group(_) => "the physical group has no mesh node; check the .geo",
            Selection::Box(_) => "enlarge the box (its bounds are inclusive) or check its units",
        };
        return Err(BuildError::EmptySelection {
            scene: scene.path.clone(),
            what: what.to_string(),
            body: body.to_string(),
            fix,
        });
    }
    Ok(nodes)
}

fn missing_group(
    scene: &Scene,
    mesh: &TetMesh,
    path: &std::path::Path,
    name: &str,
    what: &str,
    body: &str,
) -> BuildError {
    let names: Vec<&str> = mesh.groups.iter().map(|g| g.name.as_str()).collect();
    let hint = did_you_mean(name, names.iter().copied())
        .map_or(String::new(), |s| format!("; did you mean `{s}`?"));
    let available: Vec<String> = names.iter().map(|n| format!("`{n}`")).collect();
    BuildError::MissingGroup {
        scene: scene.path.clone(),
        what: format!("{what} on body `{body}`"),
        mesh: path.display().to_string(),
        group: name.to_string(),
        candidates: format!("{hint} (available: {})", available.join(", ")),
    }
}

/// The candidate particle nearest to `point` (a rigid body's candidates include its centre).
/// The probe `name` at the particle of `candidates` nearest to `point`.
pub(crate) fn nearest_particle_in(
    state: &State,
    candidates: impl Iterator<Item = usize>,
    point: Vec3,
    name: &str,
) -> ProbePoint {
    nearest_particle(state, candidates, point, name)
}

pub(crate) fn nearest_particle(
    state: &State,
    candidates: impl Iterator<Item = usize>,
    point: Vec3,
    name: &str,
) -> ProbePoint {
    let (particle, distance) = candidates
        .map(|i| (i, (state.position[i] - point).norm()))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .expect("a body has particles");
    ProbePoint {
        name: name.to_string(),
        particle,
        distance,
    }
}
