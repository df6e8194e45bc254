//! A floor moving up at constant speed lifts a rigid sphere resting on it: the sphere takes the
//! wall's velocity and rides at the static overlap m g / k below its radius, measured from where
//! the wall is at that time.

mod common;

use common::{contacts, rigid_spheres, stepper};
use qdem_contact::{ContactLaw, ContactSettings, LinearSpring, PlaneWall, Wall, WallShape};
use qdem_core::{loads::Gravity, step::Model, step::Stepper, Vec3};

#[test]
fn a_rising_floor_carries_a_sphere_at_its_speed_and_the_static_overlap() {
    let (radius, k, speed) = (0.01, 1e5, 0.1);
    let (mut state, spheres) = rigid_spheres(&[Vec3::new(0.0, 0.0, radius)], radius, 2700.0);
    let wall = Wall {
        shape: WallShape::Plane(PlaneWall::new(
            Vec3::zeros(),
            Vec3::z(),
            Vec3::new(0.0, 0.0, speed),
        )),
        friction: 0.5,
    };
    let settings = ContactSettings {
        law: ContactLaw::Linear(LinearSpring {
            normal_stiffness: k,
            tangential_stiffness: k,
            damping_ratio: 0.7,
        }),
        friction: 0.5,
        skin: 0.002,
    };
    let model = contacts(&state, &spheres, (1e9, 0.25), settings, vec![wall]);
    let dt = 0.5 * model.stable_dt(&state).unwrap();
    let g = 9.81;
    let mut models: Vec<Box<dyn Model>> = vec![
        Box::new(model),
        Box::new(Gravity::new(Vec3::new(0.0, 0.0, -g))),
    ];
    let mut s = stepper(dt, &mut state, &mut models);
    while state.time < 0.2 {
        s.step(&mut state, &mut models).unwrap();
    }
    let gap = state.position[0].z - speed * state.time;
    let expected = radius - state.mass[0] * g / k;
    eprintln!(
        "rising floor: v = {:.6} m/s, centre {gap:.6e} m above the floor vs {expected:.6e}",
        state.velocity[0].z
    );
    assert!((state.velocity[0].z / speed - 1.0).abs() < 1e-3);
    assert!((gap / expected - 1.0).abs() < 1e-4, "{gap} vs {expected}");
}
