//! `qdem modes`: the natural modes of a scene's deformable and rigid bodies
//! ([`qdem_core::modal::lanczos`]) and their files.
//!
//! - `modes.csv`: one row per mode, `mode,frequency_hz,kind,direction,participation,mass_x,
//!   mass_y,mass_z,mass_rx,mass_ry,mass_rz,motion_x,motion_y,motion_z`: `kind` is `rigid` (a rigid-body mode of a body
//!   with no fixity, or one its fixes leave free, frequency zero to rounding) or `elastic`; `mass_*` are the effective
//!   modal mass fractions along x, y, z and about the axes x, y, z through the mass centre
//!   (each column sums to 1 over all modes); `direction` and `participation` are the largest
//!   of them; `motion_*` the shares of the mode's kinetic energy in x, y and z motion (they
//!   tell apart the elastic modes of a free body, whose effective masses are all zero).
//! - `vtu/mode_NNNN.vtu`: the mode shape as the point vector `mode_shape`, scaled so that its
//!   largest particle displacement is 1 (warp by it with the amplitude you want, in metres),
//!   on the reference positions; indexed by `modes.pvd`, whose "time" is the mode number.
//!
//! All files are written atomically. The contacts touching in the starting state enter as
//! sticking springs (`qdem_contact`'s contact springs); models without a modal stiffness
//! (loads, gravity) add none and are listed in [`ModesReport::ignored`]. A rigid body takes
//! part with its six DOFs (`qdem_core`'s lanczos module); its mesh moves rigidly in the mode
//! shapes.

use crate::build::{BodyKind, Simulation};
use crate::output::{write_atomic, write_vtu, OutputError, PvdIndex, VtuGrid};
use qdem_core::modal::lanczos::{natural_modes, ModalError, Mode, Modes, DIRECTIONS};
use qdem_core::Vec3;
use std::io::Write;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// What `qdem modes` can fail on.
#[derive(Debug, Error)]
pub enum ModesError {
    /// The eigenproblem was refused or did not converge.
    #[error("scene {}: {source}", .scene.display())]
    Modal {
        /// The scene file.
        scene: PathBuf,
        /// Why.
        source: ModalError,
    },
    /// A body free to move rigidly (no fix, nothing touching it) that a load or gravity
    /// pushes: it accelerates, so it has no natural modes about the state.
    #[error(
        "scene {}: body `{body}` has no fix and nothing holds it, but {load} pushes it: it is \
         not in equilibrium, so it has no natural modes about this state; fix it with [[fix]], \
         or remove {load} to get its free-free modes",
        .scene.display()
    )]
    LoadedFreeBody {
        /// The scene file.
        scene: PathBuf,
        /// The body.
        body: String,
        /// What pushes it: `[[load]] #k` or `gravity`.
        load: String,
    },
    /// A bonded body with `supports = "none"`: its lattice is held out of its plane only, so
    /// its rigid motions in the plane are free and it has no elastic modes to report.
    #[error(
        "scene {}: bonded body `{body}` has no supports ([bonded] supports = \"none\"), so \
         {modes} of its rigid-body motions in its plane are free; fix: give it supports = \
         \"simple\" or \"pinned\" (a bonded body takes no [[fix]])",
        .scene.display()
    )]
    UnsupportedBonded {
        /// The scene file.
        scene: PathBuf,
        /// The bonded body.
        body: String,
        /// Its free rigid-body motions.
        modes: usize,
    },
    /// The output directory could not be created.
    #[error("cannot create the output directory {}: {source}", .path.display())]
    CreateDir {
        /// The directory.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// An output file could not be written.
    #[error(transparent)]
    Output(#[from] OutputError),
}

/// The modes and where their files went.
#[derive(Debug)]
pub struct ModesReport {
    /// The modes.
    pub modes: Modes,
    /// Models left out of the stiffness (no linearisation).
    pub ignored: Vec<String>,
    /// Rigid-body modes of a `[ballast]` body's stones that touch nothing in the state along
    /// which a load or gravity does work (a stone in flight above a settled bed falls): kept
    /// in `modes.csv` as rigid, the bed's elastic modes being about the rest's equilibrium.
    /// A single body in that state is refused instead ([`ModesError::LoadedFreeBody`]).
    pub loose_stone_modes: usize,
    /// `modes.csv`.
    pub csv: PathBuf,
    /// `modes.pvd`, unless the shapes were left out ([`Shapes::None`]).
    pub pvd: Option<PathBuf>,
}

/// Whether the mode shapes are written beside `modes.csv`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shapes {
    /// `modes.pvd` and one VTU a mode (the whole mesh each: about 24 MB a mode on a bed of
    /// 3,000 paper stones).
    Vtu,
    /// `modes.csv` only: the hundreds of modes a bed needs before its sleeper's.
    None,
}

/// Computes the `count` lowest modes of `sim`'s deformable bodies about its starting state
/// (the reference configuration, or the state of `[run] start_from`), with the contacts
/// touching there as springs, and writes `modes.csv`, `modes.pvd` and `vtu/mode_NNNN.vtu`
/// into `dir`.
pub fn compute_and_write(
    sim: &mut Simulation,
    count: usize,
    dir: &Path,
) -> Result<ModesReport, ModesError> {
    compute_and_write_as(sim, count, dir, Shapes::Vtu)
}

/// [`compute_and_write`], with the mode shapes written or left out as `shapes` says.
pub fn compute_and_write_as(
    sim: &mut Simulation,
    count: usize,
    dir: &Path,
    shapes: Shapes,
) -> Result<ModesReport, ModesError> {
    let push = evaluate_once(sim);
    let world = &sim.world;
    let modes =
        natural_modes(&world.state, &world.models, count).map_err(|source| refused(sim, source))?;
    let loose_stone_modes = refuse_loaded_free_bodies(sim, &modes, &push)?;
    std::fs::create_dir_all(dir).map_err(|source| ModesError::CreateDir {
        path: dir.to_path_buf(),
        source,
    })?;
    let csv = dir.join("modes.csv");
    write_atomic(&csv, |w| write_table(w, &modes))?;
    let pvd = match shapes {
        Shapes::Vtu => Some(write_shapes(sim, &modes, dir)?),
        Shapes::None => None,
    };
    Ok(ModesReport {
        ignored: modes.ignored.clone(),
        loose_stone_modes,
        modes,
        csv,
        pvd,
    })
}

/// Each mode's shape as `vtu/mode_NNNN.vtu`, indexed by `modes.pvd`; returns its path.
fn write_shapes(sim: &Simulation, modes: &Modes, dir: &Path) -> Result<PathBuf, ModesError> {
    let world = &sim.world;
    let vtu_dir = dir.join("vtu");
    std::fs::create_dir_all(&vtu_dir).map_err(|source| ModesError::CreateDir {
        path: vtu_dir.clone(),
        source,
    })?;
    let pvd = dir.join("modes.pvd");
    let tets: Vec<[u32; 4]> = sim
        .bodies
        .iter()
        .flat_map(|b| sim.body_tets(b))
        .copied()
        .collect();
    let mut index = PvdIndex::new();
    for (k, mode) in modes.modes.iter().enumerate() {
        let name = format!("vtu/mode_{:04}.vtu", k + 1);
        let largest = mode.shape.iter().map(|u| u.norm()).fold(0.0, f64::max);
        let shape: Vec<Vec3> = mode
            .shape
            .iter()
            .map(|u| u / largest.max(f64::MIN_POSITIVE))
            .collect();
        let grid = VtuGrid {
            points: &world.state.position,
            tets: &tets,
            point_vectors: vec![("mode_shape", &shape)],
            cell_scalars: vec![],
        };
        write_vtu(&dir.join(&name), &grid)?;
        index.push((k + 1) as f64, name);
    }
    index.write(&pvd)?;
    Ok(pvd)
}

/// The modal analysis's refusal as the scene's: a bonded body free in its plane is told
/// to take `[bonded] supports` (the lattice is held out of its plane, and takes no
/// `[[fix]]`); any other refusal names its body or fix by the scene's names.
fn refused(sim: &Simulation, error: ModalError) -> ModesError {
    let scene = sim.scene.path.clone();
    if let (ModalError::PartlyConstrained { body, modes }, Some(bonded)) =
        (&error, &sim.scene.bonded)
    {
        if *body == bonded.name {
            return ModesError::UnsupportedBonded {
                scene,
                body: body.clone(),
                modes: *modes,
            };
        }
    }
    ModesError::Modal {
        scene,
        source: named(sim, error),
    }
}

/// A refusal of a rigid body by its index, given the body's scene name instead.
fn named(sim: &Simulation, error: ModalError) -> ModalError {
    if let ModalError::HeldAtPoints { fix, .. } = error {
        let body = format!("body `{}`", sim.scene.fixes[fix - 1].body);
        return ModalError::HeldAtPoints { body, fix };
    }
    let ModalError::PartlyConstrainedRigid { body, modes } = error else {
        return error;
    };
    let name = sim.bodies.iter().find_map(|b| match b.kind {
        BodyKind::Rigid { body: r, .. } if r == body => Some(b.name.clone()),
        _ => None,
    });
    match name {
        Some(body) => ModalError::PartlyConstrained { body, modes },
        None => ModalError::PartlyConstrainedRigid { body, modes },
    }
}

/// Refuses a body that moves in a rigid-body mode (no fix, nothing touching it) and that a
/// `[[load]]` or gravity pushes: the modes are about an equilibrium it is not in. The stones
/// of a `[ballast]` body are many bodies: one touching nothing (in flight above the bed) is
/// not refused, its pushed modes are counted and returned.
///
/// A body fixed in some directions keeps only the rigid motions its fixes leave free (a plate
/// on its edges, free in its plane): it is refused only when the loads do work along one of
/// them (a vertical load on that plate does none, the supports take it).
fn refuse_loaded_free_bodies(
    sim: &Simulation,
    modes: &Modes,
    push: &[Vec3],
) -> Result<usize, ModesError> {
    let rigid: Vec<_> = modes.modes.iter().filter(|m| m.rigid).collect();
    let gravity = sim.scene.run.gravity != [0.0; 3];
    let ballast = sim.scene.ballast.as_ref().map(|b| b.name.as_str());
    let mut loose_stone_modes = 0;
    for body in &sim.bodies {
        // The work of the pushes along a mode over all particles (a rigid body's centre
        // carries its translation and its weight).
        let moves = |m: &&&Mode| {
            let moved = body.particles.clone().any(|p| m.shape[p] != Vec3::zeros());
            let (mut work, mut force, mut motion) = (0.0, 0.0, 0.0);
            for (f, u) in push.iter().zip(&m.shape) {
                work += f.dot(u);
                force += f.norm_squared();
                motion += u.norm_squared();
            }
            moved && work.abs() > 1e-9 * (force * motion).sqrt()
        };
        let pushed = rigid.iter().filter(moves).count();
        if pushed == 0 {
            continue;
        }
        let load = match sim.scene.loads.iter().position(|l| l.body == body.name) {
            Some(k) => format!("[[load]] #{}", k + 1),
            None if gravity => "gravity".to_string(),
            None => continue,
        };
        if Some(body.name.as_str()) == ballast {
            loose_stone_modes += pushed;
            continue;
        }
        return Err(ModesError::LoadedFreeBody {
            scene: sim.scene.path.clone(),
            body: body.name.clone(),
            load,
        });
    }
    Ok(loose_stone_modes)
}

/// Every model's forces once at the starting state, so that the contacts know which of them
/// touch there; returns the forces of all but the deformable bodies (loads, gravity, contacts)
/// per particle, what pushes a body along a rigid-body mode.
fn evaluate_once(sim: &mut Simulation) -> Vec<Vec3> {
    let world = &mut sim.world;
    let state = &world.state;
    let mut push = vec![Vec3::zeros(); state.len()];
    let mut internal = vec![Vec3::zeros(); state.len()];
    let mut torque = vec![Vec3::zeros(); state.rigid.len() + state.spin.len()];
    for model in world.models.iter_mut() {
        let body = model.deformable().is_some();
        let force = if body { &mut internal } else { &mut push };
        model.add_forces(state, force, &mut torque);
    }
    push
}

/// The header of `modes.csv`.
pub const MODES_HEADER: &str = "mode,frequency_hz,kind,direction,participation,mass_x,mass_y,\
                                mass_z,mass_rx,mass_ry,mass_rz,motion_x,motion_y,motion_z";

/// Writes the modes' table as `modes.csv` holds it.
pub fn write_table(w: &mut dyn Write, modes: &Modes) -> std::io::Result<()> {
    writeln!(w, "{MODES_HEADER}")?;
    for (k, mode) in modes.modes.iter().enumerate() {
        let (direction, share) = mode.dominant();
        let kind = if mode.rigid { "rigid" } else { "elastic" };
        write!(
            w,
            "{},{:.9e},{kind},{},{:.6}",
            k + 1,
            mode.frequency_hz,
            DIRECTIONS[direction],
            share
        )?;
        for p in mode.participation.iter().chain(&mode.motion) {
            write!(w, ",{p:.6}")?;
        }
        writeln!(w)?;
    }
    Ok(())
}
