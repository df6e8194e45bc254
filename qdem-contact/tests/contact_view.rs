//! What an output reads of the contact model ([`DemContacts::touching`],
//! [`DemContacts::sphere_records`]) on the periodic tests' compressed, spinning packing of rigid
//! spheres, periodic along x with a time-delayed boundary (whose ghost scales the sums carry), touching
//! a floor:
//! - the touching contacts' forces, summed per sphere with their ghost scales, are the contact
//!   force the model applied to each sphere, to round-off;
//! - each force splits into a part along the contact normal and a part across it, and each
//!   segment joins the first centre to the touched image (or the floor) along the normal.

mod common;

use common::packing::{model, packing, run, PERIOD, R};
use qdem_contact::{
    DemContacts, LoadCycle, Partner, PlaneWall, TimeDelayedBoundary, Wall, WallShape,
};
use qdem_core::Vec3;

#[test]
fn touching_contacts_sum_per_sphere_to_the_applied_contact_force() {
    let (state, spheres) = packing(0.0);
    // A floor 1% of a radius into the bottom layer (z = 0).
    let floor = Wall {
        shape: WallShape::Plane(PlaneWall::new(
            Vec3::new(0.0, 0.0, -0.99 * R),
            Vec3::z(),
            Vec3::zeros(),
        )),
        friction: 0.3,
    };
    let cycle = LoadCycle {
        frequency: 100.0,
        phase: 0.0,
        start: 0.0,
    };
    let lag = 0.5 * std::f64::consts::PI;
    let contacts = model(&state, &spheres, vec![floor])
        .with_time_delay(0, TimeDelayedBoundary::new(cycle, lag))
        .unwrap();
    let (state, models) = run(state, contacts, 10);
    let any: &dyn std::any::Any = models[0].as_ref();
    let contacts = any.downcast_ref::<DemContacts>().unwrap();

    let touching: Vec<_> = contacts.touching().collect();
    assert_eq!(touching.len(), contacts.contacts());
    let walls = touching
        .iter()
        .filter(|c| matches!(c.second, Partner::Wall(_)));
    assert!(walls.count() > 0, "bottom spheres touch the floor");
    assert!(
        touching.iter().any(|c| c.to.x < 0.0 || c.to.x >= PERIOD),
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
            // The floor's nearest point lies straight below the centre, on the floor.
            assert!((c.to.z + 0.99 * R).abs() < 1e-15 && (c.to.xy() - c.from.xy()).norm() < 1e-15);
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
