//! Two deformable QDEM boxes with contact spheres at their surface vertices collide off-centre:
//! total momentum is conserved to round-off (every contact force has its opposite), and without
//! friction and damping the total energy (kinetic + elastic + contact) is conserved through the
//! impact within 0.5%.

mod common;

use common::{stepper, total_energy};
use qdem_contact::{ContactLaw, ContactSettings, ContactSphere, DemContacts, LinearSpring};
use qdem_core::{
    continuum::Material, continuum::TetBody, step::Model, step::State, step::Stepper, Vec3,
};
use qdem_mesh::structured_box;

const EDGE: f64 = 0.1;
const RADIUS: f64 = 0.008;

/// Runs the collision; returns (momentum drift / |p₀|, energy drift / E₀ maximum over the run,
/// largest contact count seen).
fn collide(friction: f64) -> (f64, f64, usize) {
    let mesh = structured_box([0.0; 3], [EDGE; 3], [3, 3, 3]).unwrap();
    let surface = mesh.surface_nodes();
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
    let a = TetBody::new("a", &reference, mesh.tets.clone(), material.clone()).unwrap();
    let b = TetBody::new("b", &reference, shifted, material).unwrap();
    a.lump_mass(&mut state.mass);
    b.lump_mass(&mut state.mass);
    for i in 0..n {
        state.velocity[i] = Vec3::new(2.0, 0.0, 0.0);
        state.velocity[i + n] = Vec3::new(-0.5, 0.1, 0.0);
    }
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
        friction,
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
    let dt = 0.5
        * models
            .iter()
            .filter_map(|m| m.stable_dt(&state))
            .fold(f64::INFINITY, f64::min);
    let mut s = stepper(dt, &mut state, &mut models);
    let (p0, e0) = (state.momentum(), total_energy(&state, &models));
    let (mut drift_p, mut drift_e, mut most) = (0.0f64, 0.0f64, 0);
    while state.time < 0.03 {
        s.step(&mut state, &mut models).unwrap();
        drift_p = drift_p.max((state.momentum() - p0).norm() / p0.norm());
        drift_e = drift_e.max((total_energy(&state, &models) / e0 - 1.0).abs());
        let contact: &dyn std::any::Any = models[2].as_ref();
        let contact = contact.downcast_ref::<DemContacts>().unwrap();
        most = most.max(contact.contacts());
    }
    (drift_p, drift_e, most)
}

#[test]
fn frictionless_elastic_collision_conserves_momentum_and_energy() {
    let (drift_p, drift_e, most) = collide(0.0);
    eprintln!(
        "frictionless: momentum drift {drift_p:.2e}, energy drift {drift_e:.2e}, {most} contacts"
    );
    assert!(
        most >= 4,
        "the bodies must touch at several spheres ({most})"
    );
    assert!(drift_p < 1e-10, "momentum drift {drift_p:e}");
    assert!(drift_e < 5e-3, "energy drift {drift_e:e}");
}

#[test]
fn frictional_collision_conserves_momentum() {
    let (drift_p, _, most) = collide(0.5);
    eprintln!("friction 0.5: momentum drift {drift_p:.2e}, {most} contacts");
    assert!(most >= 4);
    assert!(drift_p < 1e-10, "momentum drift {drift_p:e}");
}
