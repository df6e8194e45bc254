//! A stiff block (a rigid cube with contact spheres at its eight corners) on a plane wall
//! inclined at θ under gravity: it sticks when tan θ < μ and otherwise slides down with
//! a = g (sin θ − μ cos θ).

mod common;

use common::{contacts, stepper};
use qdem_contact::{
    ContactLaw, ContactSettings, ContactSphere, LinearSpring, PlaneWall, Wall, WallShape,
};
use qdem_core::{loads::Gravity, step::Model, step::State, step::Stepper, Mat3, Vec3};

const G: f64 = 9.81;
const MU: f64 = 0.3;
const HALF: f64 = 0.05;
const RADIUS: f64 = 0.01;

/// Slides the block for `t_end` after a settling time; returns (mean acceleration down the
/// slope over the slide, displacement down the slope at the end).
fn slide(theta_deg: f64, t_end: f64) -> (f64, f64) {
    let theta = theta_deg.to_radians();
    let normal = Vec3::new(-theta.sin(), 0.0, theta.cos());
    let uphill = Vec3::new(theta.cos(), 0.0, theta.sin());
    let side = Vec3::y();
    let center = (HALF + RADIUS) * normal;
    let mut points = vec![center];
    for corner in 0..8 {
        let sign = |bit: usize| if corner & bit != 0 { 1.0 } else { -1.0 };
        points.push(center + HALF * (sign(1) * uphill + sign(2) * side + sign(4) * normal));
    }
    let mut state = State::at_rest(points);
    let mass = 2500.0 * (2.0 * HALF).powi(3);
    state.mass[0] = mass;
    let inertia = Mat3::identity() * (mass * (2.0 * HALF).powi(2) / 6.0);
    let members: Vec<usize> = (1..9).collect();
    state.add_rigid_body("block", 0, &members, inertia).unwrap();
    let spheres: Vec<ContactSphere> = members
        .iter()
        .map(|&p| ContactSphere {
            particle: p,
            radius: RADIUS,
            body: 0,
            material: 0,
        })
        .collect();
    let wall = Wall {
        shape: WallShape::Plane(PlaneWall::new(Vec3::zeros(), normal, Vec3::zeros())),
        friction: MU,
    };
    let k = 1e7;
    let settings = ContactSettings {
        law: ContactLaw::Linear(LinearSpring {
            normal_stiffness: k,
            tangential_stiffness: k,
            damping_ratio: 0.5,
        }),
        friction: MU,
        skin: 0.002,
    };
    let model = contacts(&state, &spheres, (1e9, 0.25), settings, vec![wall]);
    let dt = 0.2 * model.stable_dt(&state).unwrap();
    let mut models: Vec<Box<dyn Model>> = vec![
        Box::new(model),
        Box::new(Gravity::new(Vec3::new(0.0, 0.0, -G))),
    ];
    let mut s = stepper(dt, &mut state, &mut models);
    let down = |st: &State| -(st.position[0] - center).dot(&uphill);
    let speed = |st: &State| -st.velocity[0].dot(&uphill);
    let settle = 0.05;
    while state.time < settle {
        s.step(&mut state, &mut models).unwrap();
    }
    let (t0, v0) = (state.time, speed(&state));
    while state.time < settle + t_end {
        s.step(&mut state, &mut models).unwrap();
    }
    ((speed(&state) - v0) / (state.time - t0), down(&state))
}

#[test]
fn slides_with_the_coulomb_acceleration_when_steeper_than_friction() {
    for theta in [25.0f64, 40.0] {
        let (a, _) = slide(theta, 0.3);
        let t = theta.to_radians();
        let expected = G * (t.sin() - MU * t.cos());
        eprintln!("θ = {theta}°: a = {a:.5} m/s² vs {expected:.5}");
        assert!(
            (a / expected - 1.0).abs() < 0.01,
            "θ = {theta}: a = {a} vs {expected}"
        );
    }
}

#[test]
fn sticks_when_flatter_than_friction() {
    let (a, moved) = slide(15.0, 0.3);
    eprintln!("θ = 15°: a = {a:.3e} m/s², moved {moved:.3e} m");
    // Sliding freely for 0.35 s would move it metres; elastic creep of the springs is tiny.
    assert!(moved.abs() < 1e-4, "moved {moved} m");
    assert!(a.abs() < 1e-3, "a = {a}");
}
