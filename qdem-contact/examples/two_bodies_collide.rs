//! Two deformable QDEM cubes, with contact spheres at their surface vertices, collide
//! off-centre and rebound. The contact forces come in opposite pairs, so the total momentum
//! must stay what it was to round-off; without friction and contact damping the total energy
//! (kinetic, elastic and contact) must stay within half a percent (the explicit step's error
//! during the impact), and the bodies must come apart with at most the approach speed. The
//! example prints the centre-of-mass velocities before and after and exits non-zero if a check
//! fails.
//!
//! Run with `cargo run --release -p qdem-contact --example two_bodies_collide`.

use std::process::ExitCode;

use qdem_contact::{ContactLaw, ContactSettings, ContactSphere, DemContacts, LinearSpring};
use qdem_core::{
    continuum::Material, continuum::TetBody, solvers::Verlet, step::Model, step::State,
    step::Stepper, Vec3,
};
use qdem_mesh::structured_box;

/// Cube edge (m) and contact sphere radius (m).
const EDGE: f64 = 0.1;
const RADIUS: f64 = 0.008;

/// Kinetic energy plus every conservative model's potential energy (J).
fn total_energy(state: &State, models: &[Box<dyn Model>]) -> f64 {
    state.kinetic_energy()
        + models
            .iter()
            .map(|m| m.potential_energy(state).unwrap_or(0.0))
            .sum::<f64>()
}

/// Mass-weighted mean velocity of particles `range` (m/s).
fn centre_velocity(state: &State, range: std::ops::Range<usize>) -> Vec3 {
    let mass: f64 = state.mass[range.clone()].iter().sum();
    range
        .map(|i| state.mass[i] * state.velocity[i])
        .sum::<Vec3>()
        / mass
}

fn main() -> ExitCode {
    // Two copies of one 3 × 3 × 3-cell cube, the second shifted along x so that their
    // spheres are 0.1 mm apart, and sideways so that the impact is off-centre.
    let mesh = structured_box([0.0; 3], [EDGE; 3], [3, 3, 3]).unwrap();
    let n = mesh.nodes.len();
    let offset = Vec3::new(EDGE + 2.0 * RADIUS + 1e-4, 0.3 * EDGE, 0.1 * EDGE);
    let reference: Vec<Vec3> = mesh
        .nodes
        .iter()
        .map(|p| Vec3::from(*p))
        .chain(mesh.nodes.iter().map(|p| Vec3::from(*p) + offset))
        .collect();
    let material = Material::elastic(1000.0, 1e8, 0.3);
    let mut state = State::at_rest(reference.clone());
    let shifted: Vec<[u32; 4]> = mesh.tets.iter().map(|t| t.map(|i| i + n as u32)).collect();
    let a = TetBody::new("a", &reference, mesh.tets.clone(), material.clone()).expect("mesh");
    let b = TetBody::new("b", &reference, shifted, material).expect("mesh");
    a.lump_mass(&mut state.mass);
    b.lump_mass(&mut state.mass);
    for i in 0..n {
        state.velocity[i] = Vec3::new(2.0, 0.0, 0.0);
        state.velocity[i + n] = Vec3::new(-0.5, 0.1, 0.0);
    }

    // A contact sphere on every surface vertex; spheres of one body never touch each other.
    let surface = mesh.surface_nodes();
    let spheres: Vec<ContactSphere> = (0..2)
        .flat_map(|body| {
            surface.iter().map(move |&p| ContactSphere {
                particle: p as usize + body * n,
                radius: RADIUS,
                body,
                material: 0,
            })
        })
        .collect();
    let settings = ContactSettings {
        law: ContactLaw::Linear(LinearSpring {
            normal_stiffness: 2e5,
            tangential_stiffness: 1e5,
            damping_ratio: 0.0,
        }),
        friction: 0.0,
        skin: 0.002,
    };
    let contact = DemContacts::new(
        &state,
        &spheres,
        vec!["a".into(), "b".into()],
        &[(1e8, 0.3)],
        settings,
        vec![],
    );
    let mut models: Vec<Box<dyn Model>> = vec![Box::new(a), Box::new(b), Box::new(contact)];

    // Half the smallest stable step of the bodies and the contacts.
    let dt = 0.5
        * models
            .iter()
            .filter_map(|m| m.stable_dt(&state))
            .fold(f64::INFINITY, f64::min);
    let mut verlet = Verlet::new(dt);
    verlet
        .initialize(&mut state, &mut models)
        .expect("a valid start");
    let (va0, vb0) = (
        centre_velocity(&state, 0..n),
        centre_velocity(&state, n..2 * n),
    );
    let (p0, e0) = (state.momentum(), total_energy(&state, &models));
    let (mut drift_p, mut drift_e, mut most) = (0.0f64, 0.0f64, 0);
    while state.time < 0.03 {
        verlet.step(&mut state, &mut models).expect("a stable step");
        drift_p = drift_p.max((state.momentum() - p0).norm() / p0.norm());
        drift_e = drift_e.max((total_energy(&state, &models) / e0 - 1.0).abs());
        // Models are `Any`: the contact model's counters are reached by downcasting.
        let contact: &dyn std::any::Any = models[2].as_ref();
        let contact = contact.downcast_ref::<DemContacts>().expect("model 2");
        most = most.max(contact.contacts());
    }
    let (va, vb) = (
        centre_velocity(&state, 0..n),
        centre_velocity(&state, n..2 * n),
    );
    let (approach, separation) = ((va0 - vb0).x, (vb - va).x);
    let restitution = separation / approach;
    let fmt = |v: Vec3| format!("({:+.4}, {:+.4}, {:+.4})", v.x, v.y, v.z);
    println!(
        "{} particles, {} contact spheres, dt {dt:.3e} s, at most {most} contacts at once",
        state.len(),
        spheres.len()
    );
    println!("before: a {} m/s, b {} m/s", fmt(va0), fmt(vb0));
    println!("after:  a {} m/s, b {} m/s", fmt(va), fmt(vb));
    println!(
        "rebound: approach {approach:.4} m/s, separation {separation:.4} m/s along x \
         (restitution {restitution:.3}: the off-centre impact also deflects and spins the bodies \
         and sets them ringing)"
    );
    println!("largest drift over the run: momentum {drift_p:.2e} (relative), energy {drift_e:.2e}");
    let mut ok = true;
    let mut check = |pass: bool, what: String| {
        if !pass {
            eprintln!("failed: {what}");
            ok = false;
        }
    };
    check(most >= 4, format!("the bodies touch at {most} spheres"));
    // Every pair force is applied to both spheres with opposite signs: round-off only.
    check(drift_p < 1e-10, format!("momentum drift {drift_p:e}"));
    check(drift_e < 5e-3, format!("energy drift {drift_e:e}"));
    check(
        separation > 0.0 && restitution <= 1.0 + 1e-6,
        format!("restitution {restitution}: the bodies must part, no faster than they met"),
    );
    if ok {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}
