//! A `[[body]]` alone with its fixes, as a deformable body whatever its scene kind: its lowest
//! elastic natural frequency (the Lanczos solve of `qdem modes`,
//! [`qdem_core::modal::lanczos::natural_modes`]), whether its fixes hold every rigid motion,
//! its explicit stable step and its Kelvin–Voigt damping at that frequency.
//!
//! The body is taken out of the scene (its particles and tetrahedra alone, nothing touching
//! it) so that a rigid body is asked what it would be if deformable, and so that the solve
//! costs one body's factorisation, not the scene's. A `[ballast]` stone is asked the same way,
//! free ([`of_part`]).

use crate::build::{core_material, BodyInfo, Simulation};
use crate::scene::Material;
use qdem_core::continuum::TetBody;
use qdem_core::modal::lanczos::natural_modes;
use qdem_core::step::{Dofs, Model, State};
use qdem_core::Vec3;
use std::f64::consts::PI;

/// Rigid modes a free body has, plus the elastic one sought.
const MODES: usize = 7;

/// What a body alone tells of itself.
#[derive(Clone, Debug)]
pub(super) struct BodyModes {
    /// Lowest elastic natural frequency with its fixes (Hz).
    pub lowest_hz: f64,
    /// Whether its fixes leave it no rigid motion (a clamped beam): its deformation is then
    /// all the motion it has.
    pub held: bool,
    /// Its explicit stable step as a deformable body (s).
    pub stable_dt: f64,
    /// Its tetrahedra.
    pub tets: usize,
    /// The damping ratio ζ = π f τ of its Kelvin–Voigt viscosity at `lowest_hz`, τ = μ_D/G
    /// the shear relaxation time (a bending mode is a shear deformation).
    pub damping_ratio: f64,
}

/// `body` of `material` alone with the scene's fixes on it; an error in words where the
/// solve is refused (a body with fewer degrees of freedom than [`MODES`]).
pub(super) fn of_body(
    sim: &Simulation,
    body: &BodyInfo,
    material: &Material,
) -> Result<BodyModes, String> {
    let range = body.particles.clone();
    let start = range.start as u32;
    let tets: Vec<[u32; 4]> = sim
        .body_tets(body)
        .iter()
        .map(|t| t.map(|n| n - start))
        .collect();
    let mut fixed = Vec::new();
    for (fix, particles) in sim.scene.fixes.iter().zip(&sim.fix_particles) {
        if fix.body != body.name {
            continue;
        }
        fixed.extend(
            particles
                .iter()
                .filter(|p| range.contains(p))
                .map(|&p| (p - range.start, Dofs::from_mask(fix.dofs))),
        );
    }
    of_part(
        &body.name,
        &sim.world.state.reference[range],
        tets,
        material,
        &fixed,
    )
}

/// The part of a body made of the particles at `reference` and the tetrahedra `tets` (indices
/// into `reference`) of `material`, its particles `fixed` in the given directions: a `[[body]]`
/// or one stone of a `[ballast]`.
pub(super) fn of_part(
    name: &str,
    reference: &[Vec3],
    tets: Vec<[u32; 4]>,
    material: &Material,
    fixed: &[(usize, Dofs)],
) -> Result<BodyModes, String> {
    let count = tets.len();
    let model = TetBody::new(name, reference, tets, core_material(material))
        .map_err(|e| e.to_string())?
        .with_formulation(material.formulation.core());
    let mut state = State::at_rest(reference.to_vec());
    model.lump_mass(&mut state.mass);
    for &(p, dofs) in fixed {
        state.fix(p, dofs);
    }
    let stable_dt = model.stable_dt(&state).unwrap_or(f64::INFINITY);
    let models: Vec<Box<dyn Model>> = vec![Box::new(model)];
    let wanted = MODES.min(state.dofs());
    let modes = natural_modes(&state, &models, wanted).map_err(|e| e.to_string())?;
    let held = !modes.modes.iter().any(|m| m.rigid);
    let lowest_hz = modes
        .modes
        .iter()
        .find(|m| !m.rigid)
        .map(|m| m.frequency_hz)
        .ok_or_else(|| format!("its {wanted} lowest modes are all rigid-body motions"))?;
    Ok(BodyModes {
        lowest_hz,
        held,
        stable_dt,
        tets: count,
        damping_ratio: PI * lowest_hz * relaxation_time(material),
    })
}

/// The shear relaxation time τ = μ_D/G of `material`'s Kelvin–Voigt viscosity (s).
pub(super) fn relaxation_time(material: &Material) -> f64 {
    let shear_modulus = material.young / (2.0 * (1.0 + material.poisson));
    material.shear_viscosity / shear_modulus
}
