//! [`Reactions`]: `reactions.csv`: every `probe_every`, the force and moment each `[[fix]]` of
//! a deformable body carries: R = −Σ f_i over its particles, counting on each particle the
//! directions that fix holds only (its `dofs`, not those another fix holds there), f_i the
//! total (internal and external) force on particle i at the state
//! (the stepper's last evaluation, [`qdem_core::step::stepper::Stepper::forces`]; a static solve's
//! f − K u), and the moment M = Σ (X_i − c) × R_i about the centroid c of the fix's particles
//! in the reference configuration (X_i their reference positions). Columns
//! `fixK_fx, fixK_fy, fixK_fz, fixK_mx, fixK_my, fixK_mz` (N, N·m) for the K-th `[[fix]]`
//! (from 1, in scene order). A fix with a `frame` gives its force in that frame, summed over
//! its particles of each one's components there: `fixK_fr, fixK_ft, fixK_fz` (radial,
//! tangential, axial) for a cylindrical frame, `fixK_f1, fixK_f2, fixK_f3` along e₁, e₂, e₃
//! of a basis; its moment is about the axes. A direction that n fixes hold on one particle
//! (directions parallel, in any frame, count as one) is shared equally,
//! 1/n of its force to each, so the fixes' reactions sum to the supports' total whatever
//! their overlap (over-constrained in no physical sense: a held direction stays at rest
//! whichever fix holds it, so no fix has a better claim to its force). A fix on a rigid
//! body's members holds the body at those points ([`qdem_core::step::rigid_constraints`]):
//! the stepper puts at each held member the force −μ e (μ the least-norm constraint forces
//! of the body's holds), so the same sums give its reaction; the fixes of a body whose
//! rotation `rotation = true` holds (its centre holds it then, not its points) are left out.
//! In a run over MPI ranks the forces are
//! gathered from the particles' owners with the state ([`qdem_core::world::World::gather`]), so the
//! file is the same for any rank count. A wall's force is `walls.csv`'s.
//!
//! With `[output] node_reactions = true`, `node_reactions.csv` gives the same forces per
//! particle, as CalculiX's `*NODE PRINT … RF` does per node: a row per time, fix and particle,
//! `time, fix, gmsh_node_id, particle, x, y, z, fx, fy, fz` (the fix's number, the node's tag
//! in its .msh file or −1, the particle's index in the state and the VTU, its reference
//! position, m, and the force, N, on the axes, also for a fix with a frame); a fix's rows sum
//! to its `reactions.csv` force (for a fix with a frame, each row read in the node's frame).

use super::schedule::{probe_interval, Schedule};
use super::{write_rows, Recorder, StateRead, StepInfo};
use crate::build::fix_frames::{held_vectors, parallel};
use crate::build::{BodyKind, Simulation};
use crate::output::{write_atomic, OutputError};
use crate::scene::FixFrame;
use qdem_core::{
    checkpoint::CheckpointError, checkpoint::Decoder, checkpoint::Encoder, step::Dofs, step::State,
    Mat3, Vec3,
};
use std::path::{Path, PathBuf};

/// One fix's particles, the share of each held direction's force it carries, and the point
/// its moment is taken about.
struct FixGroup {
    /// The fix's number in the scene (from 1).
    number: usize,
    particles: Vec<usize>,
    /// Per particle, the share of each direction's force this fix carries: 1/n for a
    /// direction it holds with n − 1 other fixes, 0 for one it does not hold.
    shares: Vec<Vec3>,
    /// For a fix with a frame, its basis at each particle (columns in world axes).
    frames: Option<Vec<Mat3>>,
    /// The names of its force columns' directions (`fx`, `fr`, `f1`, …).
    columns: [&'static str; 3],
    /// The centroid of the particles' reference positions.
    centroid: Vec3,
}

/// The reactions' record.
pub(crate) struct Reactions {
    schedule: Schedule,
    path: PathBuf,
    groups: Vec<FixGroup>,
    /// The rows, flat: the time, then six numbers per group.
    rows: Vec<f64>,
    /// With `[output] node_reactions`: `node_reactions.csv` and its forces, flat: per time the
    /// time, then three per particle of each group in turn.
    nodes: Option<NodeRows>,
}

/// `node_reactions.csv`'s file, the gmsh node id of every particle, and the forces recorded.
struct NodeRows {
    path: PathBuf,
    ids: Vec<i64>,
    forces: Vec<f64>,
}

impl Reactions {
    /// The record of `sim`'s fixes on deformable bodies and of those holding rigid bodies at
    /// points; `None` when there is none.
    pub(crate) fn new(sim: &Simulation, out_dir: &Path) -> Option<Reactions> {
        let state = &sim.world.state;
        let scene = &sim.scene;
        let held: Vec<Held<'_>> = sim
            .fix_particles
            .iter()
            .zip(&scene.refs().fix_bodies)
            .zip(scene.fixes.iter().zip(&sim.fix_frames))
            .enumerate()
            .filter(|(k, ((_, &b), _))| {
                let deformable = matches!(sim.bodies[b].kind, BodyKind::Deformable { .. });
                deformable || state.rigid.holds.holds_fix(k + 1)
            })
            .map(|(k, ((particles, _), (fix, frames)))| Held {
                number: k + 1,
                particles,
                dofs: Dofs::from_mask(fix.dofs),
                frames: frames.as_ref(),
                columns: columns(&fix.frame),
            })
            .collect();
        let directions = held_per_particle(state.len(), &held);
        let groups: Vec<FixGroup> = held
            .into_iter()
            .map(|h| FixGroup {
                number: h.number,
                particles: h.particles.clone(),
                shares: h
                    .particles
                    .iter()
                    .enumerate()
                    .map(|(n, &i)| {
                        let basis = h.frames.map(|f| &f[n]);
                        let held = &directions[i];
                        Vec3::from_fn(|k, _| share(basis, h.dofs, k, held))
                    })
                    .collect(),
                frames: h.frames.cloned(),
                columns: h.columns,
                centroid: h
                    .particles
                    .iter()
                    .map(|&i| state.reference[i])
                    .sum::<Vec3>()
                    / h.particles.len() as f64,
            })
            .collect();
        (!groups.is_empty()).then(|| Reactions {
            schedule: Schedule::new(probe_interval(sim)),
            path: out_dir.join("reactions.csv"),
            groups,
            rows: Vec::new(),
            nodes: scene.output.node_reactions.then(|| NodeRows {
                path: out_dir.join("node_reactions.csv"),
                ids: sim.gmsh_node_ids(),
                forces: Vec::new(),
            }),
        })
    }

    /// Writes `node_reactions.csv` (atomically) from the recorded rows.
    fn write_nodes(&self, state: &State) -> Result<(), OutputError> {
        let Some(nodes) = &self.nodes else {
            return Ok(());
        };
        let per_time = 1 + 3 * self.groups.iter().map(|g| g.particles.len()).sum::<usize>();
        if nodes.forces.is_empty() {
            return Ok(());
        }
        write_atomic(&nodes.path, |w| {
            writeln!(w, "time,fix,gmsh_node_id,particle,x,y,z,fx,fy,fz")?;
            for row in nodes.forces.chunks_exact(per_time) {
                let mut forces = row[1..].chunks_exact(3);
                for group in &self.groups {
                    for &i in &group.particles {
                        let f = forces.next().expect("three per particle");
                        let x = state.reference[i];
                        writeln!(
                            w,
                            "{:.9e},{},{},{i},{:.9e},{:.9e},{:.9e},{:.9e},{:.9e},{:.9e}",
                            row[0], group.number, nodes.ids[i], x.x, x.y, x.z, f[0], f[1], f[2]
                        )?;
                    }
                }
            }
            Ok(())
        })
    }
}

/// One `[[fix]]` of a deformable body as the record reads it.
struct Held<'a> {
    number: usize,
    particles: &'a Vec<usize>,
    dofs: Dofs,
    frames: Option<&'a Vec<Mat3>>,
    columns: [&'static str; 3],
}

/// The names of a fix's force columns in its frame.
fn columns(frame: &FixFrame) -> [&'static str; 3] {
    match frame {
        FixFrame::Axes => ["fx", "fy", "fz"],
        FixFrame::Cylindrical { .. } => ["fr", "ft", "fz"],
        FixFrame::Basis(_) => ["f1", "f2", "f3"],
    }
}

/// The force a fix carries at one particle of total force `force`: −f in the directions it
/// holds, times its `share` of each; with a `basis`, in its directions (and on the axes).
/// Returns the components in the fix's frame and the force on the axes.
fn particle_reaction(force: Vec3, share: &Vec3, basis: Option<&Mat3>) -> (Vec3, Vec3) {
    let Some(r) = basis else {
        let f = Vec3::from_fn(|k, _| {
            if share[k] > 0.0 {
                -force[k] * share[k]
            } else {
                0.0
            }
        });
        return (f, f);
    };
    let local = Vec3::from_fn(|k, _| {
        if share[k] > 0.0 {
            -r.column(k).dot(&force) * share[k]
        } else {
            0.0
        }
    });
    (local, r * local)
}

/// Per particle of a state of `particles`, every direction (world axes) that one of the
/// fixes `held` holds there.
fn held_per_particle(particles: usize, held: &[Held<'_>]) -> Vec<Vec<Vec3>> {
    let mut directions = vec![Vec::new(); particles];
    for h in held {
        for (n, &i) in h.particles.iter().enumerate() {
            let basis = h.frames.map(|f| &f[n]);
            directions[i].extend(held_vectors(basis, h.dofs));
        }
    }
    directions
}

/// The share of direction `k`'s force of a fix holding `dofs` in `basis` (`None`: the
/// axes), at a particle where the fixes hold `held`: 1/n where n of them are parallel to it.
fn share(basis: Option<&Mat3>, dofs: Dofs, k: usize, held: &[Vec3]) -> f64 {
    if !dofs.contains(k) {
        return 0.0;
    }
    let e = match basis {
        Some(r) => r.column(k).into_owned(),
        None => Vec3::ith(k, 1.0),
    };
    let holders = held.iter().filter(|h| parallel(h, &e)).count() as u32;
    1.0 / f64::from(holders)
}

/// The force and moment `group` carries, from the particles' total forces `force` (zero
/// before any evaluation, when `force` is empty); each particle's force also to `per_node`
/// when `node_reactions.csv` is written.
fn reaction(
    state: &State,
    force: &[Vec3],
    group: &FixGroup,
    mut per_node: Option<&mut Vec<f64>>,
) -> (Vec3, Vec3) {
    let evaluated = force.len() == state.len();
    let mut total = (Vec3::zeros(), Vec3::zeros());
    for (n, (&i, share)) in group.particles.iter().zip(&group.shares).enumerate() {
        let basis = group.frames.as_ref().map(|f| &f[n]);
        let (local, r) = match evaluated {
            true => particle_reaction(force[i], share, basis),
            false => (Vec3::zeros(), Vec3::zeros()),
        };
        total.0 += local;
        total.1 += (state.reference[i] - group.centroid).cross(&r);
        if let Some(rows) = per_node.as_deref_mut() {
            rows.extend(r.iter());
        }
    }
    total
}

impl Recorder for Reactions {
    fn name(&self) -> &'static str {
        "reactions"
    }

    fn reads(&self, time: f64, dt: f64) -> StateRead {
        StateRead::whole_if(self.schedule.is_due(time, dt))
    }

    fn record(&mut self, sim: &Simulation, step: &StepInfo<'_>) -> Result<(), OutputError> {
        let state = &sim.world.state;
        if !self.schedule.due(state.time, step.dt) {
            return Ok(());
        }
        let force = sim.world.stepper().forces();
        self.rows.push(state.time);
        let mut per_node = self.nodes.as_mut().map(|nodes| &mut nodes.forces);
        if let Some(rows) = per_node.as_deref_mut() {
            rows.push(state.time);
        }
        for group in &self.groups {
            let (f, m) = reaction(state, force, group, per_node.as_deref_mut());
            self.rows.extend(f.iter().chain(m.iter()));
        }
        Ok(())
    }

    fn finish(&mut self, sim: &Simulation) -> Result<(), OutputError> {
        let mut header = vec!["time".to_string()];
        for g in &self.groups {
            let k = g.number;
            let [a, b, c] = g.columns;
            header.extend([a, b, c, "mx", "my", "mz"].map(|c| format!("fix{k}_{c}")));
        }
        write_rows(&self.path, &header, &self.rows)?;
        self.write_nodes(&sim.world.state)
    }

    fn save(&self, out: &mut Encoder) {
        out.f64(self.schedule.next);
        out.f64s(&self.rows);
        if let Some(nodes) = &self.nodes {
            out.f64s(&nodes.forces);
        }
    }

    fn restore(&mut self, input: &mut Decoder<'_>) -> Result<(), CheckpointError> {
        self.schedule.next = input.f64("the reactions schedule")?;
        self.rows = input.f64s("the reaction rows")?;
        if let Some(nodes) = &mut self.nodes {
            nodes.forces = input.f64s("the node reaction rows")?;
        }
        Ok(())
    }
}
