//! What an output reads of the contact model ([`DemContacts::touching`],
//! [`DemContacts::sphere_records`]) on a compressed, spinning packing of rigid spheres,
//! periodic along x with a time-delayed boundary (whose ghost scales the sums carry), touching
//! a floor:
//! - the touching contacts' forces, summed per sphere with their ghost scales, are the contact
//!   force the model applied to each sphere, to round-off;
//! - each force splits into a part along the contact normal and a part across it, and each
//!   segment joins the first centre to the touched image (or the floor) along the normal.

mod common;

use common::{contacts, rigid_spheres, stepper};
use qdem_contact::{
    ContactLaw, ContactSettings, DemContacts, HertzMindlin, LoadCycle, Partner, PeriodicBox,
    PlaneWall, TimeDelayedBoundary, Wall, WallShape,
};
use qdem_core::{Model, Stepper, Vec3};

const R: f64 = 0.005;
const ROW: usize = 8;
const SPACING: f64 = 1.96 * R;

#[test]
fn touching_contacts_sum_per_sphere_to_the_applied_contact_force() {
    let mut centers = Vec::new();
    for k in 0..2 {
        for j in 0..2 {
            for i in 0..ROW {
                let jitter = ((i * 7 + j * 13 + k * 29) % 17) as f64 / 17.0 - 0.5;
                centers.push(Vec3::new(
                    (i as f64 + 0.5) * SPACING + 0.02 * R * jitter,
                    1.98 * R * j as f64,
                    0.99 * R + 1.97 * R * k as f64 + 0.01 * R * jitter,
                ));
            }
        }
    }
    let (mut state, spheres) = rigid_spheres(&centers, R, 2700.0);
    for (i, v) in state.velocity.iter_mut().enumerate() {
        let f = |m: usize| ((i * m) % 101) as f64 / 101.0 - 0.5;
        *v = 0.02 * Vec3::new(f(37), f(53), f(71));
    }
    let settings = ContactSettings {
        law: ContactLaw::HertzMindlin(HertzMindlin { damping_ratio: 0.1 }),
        friction: 0.5,
        skin: 0.2 * R,
    };
    let floor = Wall {
        shape: WallShape::Plane(PlaneWall::new(Vec3::zeros(), Vec3::z(), Vec3::zeros())),
        friction: 0.3,
    };
    let periodic =
        PeriodicBox::new(Vec3::zeros(), [Some(ROW as f64 * SPACING), None, None]).unwrap();
    let cycle = LoadCycle {
        frequency: 100.0,
        phase: 0.0,
        start: 0.0,
    };
    let model = contacts(&state, &spheres, (5e7, 0.25), settings, vec![floor])
        .with_periodic(periodic)
        .unwrap()
        .with_time_delay(
            0,
            TimeDelayedBoundary::new(cycle, 0.5 * std::f64::consts::PI),
        )
        .unwrap();
    let dt = 0.5 * model.stable_dt(&state).unwrap();
    let mut models: Vec<Box<dyn Model>> = vec![Box::new(model)];
    let mut s = stepper(dt, &mut state, &mut models);
    for _ in 0..30 {
        s.step(&mut state, &mut models).unwrap();
    }
    let any: &dyn std::any::Any = models[0].as_ref();
    let contacts = any.downcast_ref::<DemContacts>().unwrap();

    let touching: Vec<_> = contacts.touching().collect();
    assert_eq!(touching.len(), contacts.contacts());
    let walls = touching
        .iter()
        .filter(|c| matches!(c.second, Partner::Wall(_)));
    assert!(walls.count() > 0, "bottom spheres touch the floor");
    let period = ROW as f64 * SPACING;
    assert!(
        touching.iter().any(|c| c.to.x < 0.0 || c.to.x >= period),
        "some pair touches through the delayed boundary, at an image outside the cell"
    );
    let mut sum = vec![Vec3::zeros(); contacts.spheres()];
    let mut largest = 0.0f64;
    for c in &touching {
        let f = c.force();
        largest = largest.max(f.norm());
        sum[c.first] += c.scales.0 * f;
        if let Partner::Sphere(b) = c.second {
            sum[b] -= c.scales.1 * f;
            // The segment joins the centres of the touching images: shorter than 2R.
            let gap = c.to - c.from;
            assert!(gap.norm() < 2.0 * R && gap.norm() > 1.8 * R, "{gap:?}");
            assert!((gap.normalize() - c.normal).norm() < 1e-12);
        } else {
            // The floor's nearest point lies straight below the centre, on z = 0.
            assert!(c.to.z.abs() < 1e-15 && (c.to.xy() - c.from.xy()).norm() < 1e-15);
        }
        assert!(c.normal_force.cross(&c.normal).norm() <= 1e-12 * f.norm());
        assert!(c.tangential_force.dot(&c.normal).abs() <= 1e-12 * f.norm());
    }
    assert!(largest > 0.0);
    let records: Vec<_> = contacts.sphere_records(&state).collect();
    assert_eq!(records.len(), contacts.spheres());
    for (s, record) in records.iter().enumerate() {
        // The same contributions as the gather's, in another order: round-off of a few
        // ulps of the largest force at most.
        let off = (sum[s] - record.force).norm();
        assert!(off <= 1e-12 * largest, "sphere {s}: {off:e} N off");
        assert_eq!(record.center, state.position[record.particle]);
        assert!(record.spin.is_some(), "a rigid sphere turns");
    }
}
