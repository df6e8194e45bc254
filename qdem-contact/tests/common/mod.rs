//! Scenes built directly on the library for the contact tests.
#![allow(dead_code)]

pub mod packing;

use qdem_contact::{ContactSettings, ContactSphere, DemContacts, Wall};
use qdem_core::error::CoreError;
use qdem_core::step::{Scheme, StepRequest, StepSettings};
use qdem_core::world::World;
use qdem_core::{solvers::Verlet, step::Model, step::State, step::Stepper, Mat3, Vec3};

/// A state of rigid spheres: one centre particle per sphere, each its own body.
pub fn rigid_spheres(centers: &[Vec3], radius: f64, density: f64) -> (State, Vec<ContactSphere>) {
    let mut state = State::at_rest(centers.to_vec());
    let mass = density * 4.0 / 3.0 * std::f64::consts::PI * radius.powi(3);
    let mut spheres = Vec::new();
    for i in 0..centers.len() {
        state.mass[i] = mass;
        let inertia = Mat3::identity() * (0.4 * mass * radius * radius);
        state.add_rigid_body("sphere", i, &[], inertia).unwrap();
        spheres.push(ContactSphere {
            particle: i,
            radius,
            body: i,
            material: 0,
        });
    }
    (state, spheres)
}

/// The contact model over `spheres` with one material (E, ν) and the given walls.
pub fn contacts(
    state: &State,
    spheres: &[ContactSphere],
    material: (f64, f64),
    settings: ContactSettings,
    walls: Vec<Wall>,
) -> DemContacts {
    let bodies = spheres.iter().map(|s| s.body).max().map_or(0, |b| b + 1);
    let names = (0..bodies).map(|b| format!("body{b}")).collect();
    DemContacts::new(state, spheres, names, &[material], settings, walls)
}

/// Verlet at `dt`, initialised.
pub fn stepper(dt: f64, state: &mut State, models: &mut [Box<dyn Model>]) -> Verlet {
    let mut s = Verlet::new(dt);
    s.initialize(state, models).unwrap();
    s
}

/// Total energy: kinetic plus every model's potential energy.
pub fn total_energy(state: &State, models: &[Box<dyn Model>]) -> f64 {
    state.kinetic_energy()
        + models
            .iter()
            .map(|m| m.potential_energy(state).unwrap_or(0.0))
            .sum::<f64>()
}

/// A world of `models` over `state`, stepped by Verlet at `dt` (automatic, at 0.9 of the
/// stable step, when `None`), initialised.
pub fn verlet_world(
    state: State,
    models: Vec<Box<dyn Model>>,
    dt: Option<f64>,
) -> Result<World, CoreError> {
    let request = StepRequest {
        scheme: Scheme::Verlet,
        dt,
        safety: 0.9,
        local_damping: 0.0,
        adaptive: false,
        event_solve: Default::default(),
        implicit_default: None,
        fit_to: None,
    };
    let settings = StepSettings::resolve(&request, &state, &models)?;
    let mut world = World::new(state, models, settings)?;
    world.initialize()?;
    Ok(world)
}
