//! The compressed, spinning, frictional packing of rigid spheres periodic along x that the
//! periodic-boundary and contact-view tests step.

use super::{contacts, rigid_spheres, stepper};
use qdem_contact::{
    ContactLaw, ContactSettings, ContactSphere, DemContacts, HertzMindlin, PeriodicBox, Wall,
};
use qdem_core::{step::Model, step::State, step::Stepper, Vec3};

/// Sphere radius (m).
pub const R: f64 = 0.005;
/// Spheres along the periodic axis, and their spacing (below 2R: every neighbour pair
/// overlaps, the last and the first through the boundary).
pub const ROW: usize = 10;
pub const SPACING: f64 = 1.96 * R;
/// The period along x (m).
pub const PERIOD: f64 = ROW as f64 * SPACING;

/// 10 × 3 × 3 spheres, rows along x compressed across the boundary, with deterministic
/// velocities; every coordinate x shifted by `shift`.
pub fn packing(shift: f64) -> (State, Vec<ContactSphere>) {
    let mut centers = Vec::new();
    for k in 0..3 {
        for j in 0..3 {
            for i in 0..ROW {
                let jitter = ((i * 7 + j * 13 + k * 29) % 17) as f64 / 17.0 - 0.5;
                centers.push(Vec3::new(
                    (i as f64 + 0.5) * SPACING + 0.02 * R * jitter + shift,
                    2.2 * R * j as f64 + 0.05 * R * jitter,
                    2.2 * R * k as f64,
                ));
            }
        }
    }
    let (mut state, spheres) = rigid_spheres(&centers, R, 2700.0);
    for (i, v) in state.velocity.iter_mut().enumerate() {
        let f = |m: usize| ((i * m) % 101) as f64 / 101.0 - 0.5;
        *v = 0.02 * Vec3::new(f(37), f(53), f(71));
    }
    (state, spheres)
}

/// The packing's contacts (Hertz–Mindlin, ζ = 0.1, μ = 0.5), periodic along x, with `walls`.
pub fn model(state: &State, spheres: &[ContactSphere], walls: Vec<Wall>) -> DemContacts {
    let settings = ContactSettings {
        law: ContactLaw::HertzMindlin(HertzMindlin { damping_ratio: 0.1 }),
        friction: 0.5,
        skin: 0.2 * R,
    };
    let periodic = PeriodicBox::new(Vec3::zeros(), [Some(PERIOD), None, None]).unwrap();
    contacts(state, spheres, (5e7, 0.25), settings, walls)
        .with_periodic(periodic)
        .unwrap()
}

/// Steps `model` on `state` `steps` times at a fixed step; returns the state.
pub fn run(mut state: State, model: DemContacts, steps: usize) -> (State, Vec<Box<dyn Model>>) {
    let dt = 0.5 * model.stable_dt(&state).unwrap();
    let mut models: Vec<Box<dyn Model>> = vec![Box::new(model)];
    let mut s = stepper(dt, &mut state, &mut models);
    for _ in 0..steps {
        s.step(&mut state, &mut models).unwrap();
    }
    (state, models)
}
