//! [`Snapshots`]: every `vtu_every`, and a static run's final state, `vtu/state_NNNNN.vtu` of
//! all bodies (reference points with displacement, velocity, the nodal stress
//! ([`nodal_stress`](super::nodal_stress)) and the mesh file's node id per particle; von
//! Mises stress, volumetric strain, the stress tensor, the principal stresses, the mesh
//! file's element id and physical volume per tetrahedron; rigid bodies' tetrahedra at zero
//! stress; −1 for an id no mesh file gives), each file carrying its time as `TimeValue` field
//! data and, beside it as further parts of the same
//! time in `results.pvd`, what else the scene has: the contact spheres
//! ([`spheres_vtu`](super::spheres_vtu)) and their touching contacts
//! ([`contacts_vtu`](super::contacts_vtu)), the walls ([`walls_vtu`](super::walls_vtu): one
//! file for walls that stay, one per time for walls that move), a bonded body's discs and
//! bonds ([`bonds_vtu`](super::bonds_vtu)). `results.pvd`, the ParaView time index, is
//! rewritten after each time (the run creates `vtu/`); the bodies stay part 0.
//!
//! A checkpoint keeps the times and body files only: the other parts' files follow from the
//! scene and the time's number.

use super::bonds_vtu::write_bonds;
use super::contacts_vtu::write_contacts;
use super::nodal_stress::nodal_stress;
use super::schedule::Schedule;
use super::spheres_vtu::write_spheres;
use super::tet_stress::StressFields;
use super::walls_vtu::{walls_move, write_walls};
use super::{Recorder, RunFigures, StateRead, StepInfo};
use crate::build::Simulation;
use crate::output::{write_vtu_mesh_at, OutputError, PvdIndex, VtuCells, VtuField, VtuMesh};
use crate::scene::{Integrator, Scene};
use qdem_core::{checkpoint::CheckpointError, checkpoint::Decoder, checkpoint::Encoder, Vec3};
use std::path::{Path, PathBuf};

/// A part of every time of the series besides the bodies.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Part {
    /// The contact spheres.
    Spheres,
    /// The touching contacts.
    Contacts,
    /// The walls, written once (`false`) or at every time (`true`, walls that move).
    Walls { moving: bool },
    /// A bonded body's discs and bonds.
    Bonds,
}

impl Part {
    /// The file of this part at time number `k`.
    fn file(self, k: usize) -> String {
        match self {
            Part::Spheres => format!("vtu/spheres_{k:05}.vtu"),
            Part::Contacts => format!("vtu/contacts_{k:05}.vtu"),
            Part::Walls { moving: false } => "vtu/walls.vtu".to_string(),
            Part::Walls { moving: true } => format!("vtu/walls_{k:05}.vtu"),
            Part::Bonds => format!("vtu/bonds_{k:05}.vtu"),
        }
    }

    /// Writes this part of `sim`'s current state to `path`.
    fn write(self, sim: &Simulation, path: &Path) -> Result<(), OutputError> {
        let state = &sim.world.state;
        let contacts = || {
            sim.contacts()
                .expect("registered for a scene with contacts")
        };
        match self {
            Part::Spheres => write_spheres(contacts(), state, path),
            Part::Contacts => write_contacts(contacts(), state.time, path),
            Part::Walls { moving } => write_walls(contacts().wall_list(), state, path, moving),
            Part::Bonds => write_bonds(
                sim.bonded().expect("registered for a bonded scene"),
                state,
                path,
            ),
        }
    }
}

/// The VTU series.
pub(crate) struct Snapshots {
    schedule: Schedule,
    /// A static run's end: its final state is written whatever the schedule.
    end: Option<f64>,
    out_dir: PathBuf,
    /// `(time, body file)` of every time written, what a checkpoint keeps.
    times: Vec<(f64, String)>,
    /// The parts besides the bodies, in part order (part 1, 2, …).
    parts: Vec<Part>,
    pvd: PvdIndex,
    /// Whether the file of the walls that stay is written (by this run, or by the run it
    /// resumes).
    walls_written: bool,
}

impl Snapshots {
    pub(crate) fn new(sim: &Simulation, out_dir: &Path) -> Snapshots {
        let mut parts = Vec::new();
        if let Some(contacts) = sim.contacts().filter(|c| c.spheres() > 0) {
            parts.extend([Part::Spheres, Part::Contacts]);
            if contacts.walls() > 0 {
                let moving = walls_move(contacts.wall_list()) || contacts.has_servo();
                parts.push(Part::Walls { moving });
            }
        }
        if sim.bonded().is_some() {
            parts.push(Part::Bonds);
        }
        Snapshots {
            schedule: Schedule::new(sim.scene.output.vtu_every),
            end: (sim.scene.run.integrator == Integrator::Static).then_some(sim.scene.run.t_end),
            out_dir: out_dir.to_path_buf(),
            times: Vec::new(),
            parts,
            pvd: PvdIndex::new(),
            walls_written: false,
        }
    }

    /// Adds time number `times.len()` at `time` with its body file to the index.
    fn index(&mut self, time: f64, file: String) {
        let k = self.times.len();
        self.pvd.push_part(time, 0, file.clone());
        for (part, p) in (1..).zip(&self.parts) {
            self.pvd.push_part(time, part, p.file(k));
        }
        self.times.push((time, file));
    }

    /// Whether a file is due at `time` (step `dt`): on the schedule, or a static run's final
    /// state (its last level, the first within 10⁻⁹ dt of the end or past it, as
    /// [`qdem_core::step::StepSettings::steps_to`] counts) that the schedule did not write.
    fn is_due(&self, time: f64, dt: f64) -> bool {
        let last = self.times.last().map(|t| t.0);
        let at_end = |end: f64| time >= end - 1e-9 * dt;
        let fin = self.end.is_some_and(at_end) && last != Some(time);
        self.schedule.is_due(time, dt) || fin
    }
}

/// Whether `scene`'s run writes `vtu/state_NNNNN.vtu`: with `vtu_every`, or static.
pub(crate) fn writes_vtu(scene: &Scene) -> bool {
    scene.output.writes_vtu() || scene.run.integrator == Integrator::Static
}

impl Recorder for Snapshots {
    fn name(&self) -> &'static str {
        "snapshots"
    }

    fn reads(&self, time: f64, dt: f64) -> StateRead {
        StateRead::whole_if(self.is_due(time, dt))
    }

    fn record(&mut self, sim: &Simulation, step: &StepInfo<'_>) -> Result<(), OutputError> {
        let time = sim.world.state.time;
        let due = self.is_due(time, step.dt);
        self.schedule.due(time, step.dt);
        if !due {
            return Ok(());
        }
        let k = self.times.len();
        let file = format!("vtu/state_{k:05}.vtu");
        write_snapshot(sim, &self.out_dir.join(&file))?;
        for part in self.parts.clone() {
            if part == (Part::Walls { moving: false }) {
                if self.walls_written {
                    continue;
                }
                self.walls_written = true;
            }
            part.write(sim, &self.out_dir.join(part.file(k)))?;
        }
        self.index(time, file);
        self.pvd.write(&self.out_dir.join("results.pvd"))
    }

    fn summarize(&self, _sim: &Simulation, _run: &RunFigures, summary: &mut serde_json::Value) {
        summary["vtu_files"] = self.times.len().into();
    }

    fn save(&self, out: &mut Encoder) {
        out.f64(self.schedule.next);
        out.u64(self.times.len() as u64);
        for (time, file) in &self.times {
            out.f64(*time);
            out.str(file);
        }
    }

    fn restore(&mut self, input: &mut Decoder<'_>) -> Result<(), CheckpointError> {
        self.schedule.next = input.f64("the VTU schedule")?;
        for _ in 0..input.u64("the VTU count")? {
            let time = input.f64("a VTU time")?;
            let file = input.str("a VTU file name")?;
            self.index(time, file);
        }
        // The run resumed wrote the walls that stay with its first time.
        self.walls_written = !self.times.is_empty();
        Ok(())
    }
}

/// One VTU of all bodies at the state's time (its `TimeValue`): the particles' displacement,
/// velocity, nodal stress and mesh node id, the tetrahedra's stress tensor, principal
/// stresses, von Mises stress, volumetric strain ([`tet_stress`](super::tet_stress)), mesh
/// element id and physical volume. A static run's stress is the small-strain one of its
/// linear solve ([`qdem_core::continuum::TetBody::small_strain_stresses`]).
fn write_snapshot(sim: &Simulation, path: &Path) -> Result<(), OutputError> {
    let s = &sim.world.state;
    let displacement: Vec<Vec3> = (0..s.len()).map(|i| s.displacement(i)).collect();
    let ids = MeshIds::of(sim);
    let mut tets = Vec::new();
    let mut stress = StressFields::default();
    let mut volumetric = Vec::new();
    for body in &sim.bodies {
        let body_tets = sim.body_tets(body);
        tets.extend_from_slice(body_tets);
        match sim.tet_body(body) {
            Some(tet_body) => {
                let (mut sigma, vol) = tet_body.tet_fields(s);
                if sim.scene.run.integrator == Integrator::Static {
                    sigma = tet_body.small_strain_stresses(s);
                }
                sigma.iter().for_each(|t| stress.push(t));
                volumetric.extend(vol);
            }
            None => {
                stress.push_zeros(body_tets.len());
                volumetric.extend(std::iter::repeat_n(0.0, body_tets.len()));
            }
        }
    }
    let [p1, p2, p3] = &stress.principal;
    let nodal = nodal_stress(&s.reference, &tets, &stress.stress);
    let mesh = VtuMesh {
        points: &s.reference,
        cells: VtuCells::Tets(&tets),
        point_data: vec![
            ("displacement", VtuField::Vectors(&displacement)),
            ("velocity", VtuField::Vectors(&s.velocity)),
            ("nodal_stress", VtuField::SymTensors(&nodal)),
            ("gmsh_node_id", VtuField::Integers(&ids.nodes)),
        ],
        cell_data: vec![
            ("von_mises", VtuField::Scalars(&stress.von_mises)),
            ("volumetric_strain", VtuField::Scalars(&volumetric)),
            ("stress", VtuField::SymTensors(&stress.stress)),
            ("principal_stress_1", VtuField::Scalars(p1)),
            ("principal_stress_2", VtuField::Scalars(p2)),
            ("principal_stress_3", VtuField::Scalars(p3)),
            ("gmsh_element_id", VtuField::Integers(&ids.tets)),
            ("physical_group", VtuField::Integers(&ids.volumes)),
        ],
    };
    write_vtu_mesh_at(path, &mesh, Some(s.time))
}

/// The mesh files' numbering of every particle and tetrahedron of the state, in the VTU's
/// order, −1 where no file numbers it (a generated body, the `[ballast]` stones, a rigid
/// body's centre, a sphere; an id beyond 2⁶³ − 1, which only a binary file can hold).
struct MeshIds {
    /// `gmsh_node_id` per particle.
    nodes: Vec<i64>,
    /// `gmsh_element_id` per tetrahedron.
    tets: Vec<i64>,
    /// `physical_group` per tetrahedron (−1 also for an element in no physical volume).
    volumes: Vec<i64>,
}

impl MeshIds {
    /// The ids of `sim`'s bodies, their tetrahedra in body order.
    fn of(sim: &Simulation) -> MeshIds {
        let id = |n: &u64| i64::try_from(*n).unwrap_or(-1);
        let nodes = sim.gmsh_node_ids();
        let (mut tets, mut volumes) = (Vec::new(), Vec::new());
        for body in &sim.bodies {
            let file = &body.file_ids;
            let count = sim.body_tets(body).len();
            match file.tets.len() == count {
                true => {
                    tets.extend(file.tets.iter().map(id));
                    volumes.extend(file.volumes.iter().map(|&v| i64::from(v)));
                }
                false => {
                    tets.extend(std::iter::repeat_n(-1, count));
                    volumes.extend(std::iter::repeat_n(-1, count));
                }
            }
        }
        MeshIds {
            nodes,
            tets,
            volumes,
        }
    }
}
