//! A granular run (rigid spheres, Hertz–Mindlin with friction and damping, gravity, a floor
//! and side walls) gives bit-identical positions, velocities and spins with 1 and 2 threads.

mod common;

use common::{contacts, rigid_spheres, stepper};
use qdem_contact::{ContactLaw, ContactSettings, HertzMindlin, PlaneWall, Wall, WallShape};
use qdem_core::{loads::Gravity, step::Model, step::State, step::Stepper, Vec3};

const R: f64 = 0.005;

fn run() -> State {
    // 12 × 12 × 40 spheres on a lattice with a deterministic jitter, poured into a box.
    let mut centers = Vec::new();
    for k in 0..40 {
        for j in 0..12 {
            for i in 0..12 {
                let jitter = ((i * 7 + j * 13 + k * 29) % 17) as f64 / 17.0 - 0.5;
                centers.push(Vec3::new(
                    (2.1 * i as f64 + 1.2) * R + 0.1 * R * jitter,
                    (2.1 * j as f64 + 1.2) * R - 0.1 * R * jitter,
                    (2.1 * k as f64 + 1.2) * R,
                ));
            }
        }
    }
    let (mut state, spheres) = rigid_spheres(&centers, R, 2700.0);
    // Random-looking velocities so that contacts form within the run.
    for (i, v) in state.velocity.iter_mut().enumerate() {
        let f = |m: usize| ((i * m) % 101) as f64 / 101.0 - 0.5;
        *v = Vec3::new(f(37), f(53), f(71));
    }
    let side = 2.1 * 12.0 * R + 0.4 * R;
    let plane = |point: Vec3, normal: Vec3| Wall {
        shape: WallShape::Plane(PlaneWall::new(point, normal, Vec3::zeros())),
        friction: 0.4,
    };
    let walls = vec![
        plane(Vec3::zeros(), Vec3::z()),
        plane(Vec3::zeros(), Vec3::x()),
        plane(Vec3::zeros(), Vec3::y()),
        plane(Vec3::new(side, 0.0, 0.0), -Vec3::x()),
        plane(Vec3::new(0.0, side, 0.0), -Vec3::y()),
    ];
    let settings = ContactSettings {
        law: ContactLaw::HertzMindlin(HertzMindlin { damping_ratio: 0.3 }),
        friction: 0.5,
        skin: 0.2 * R,
    };
    let model = contacts(&state, &spheres, (5e7, 0.25), settings, walls);
    let dt = 0.5 * model.stable_dt(&state).unwrap();
    let mut models: Vec<Box<dyn Model>> = vec![
        Box::new(model),
        Box::new(Gravity::new(Vec3::new(0.0, 0.0, -9.81))),
    ];
    let mut s = stepper(dt, &mut state, &mut models);
    for _ in 0..3000 {
        s.step(&mut state, &mut models).unwrap();
    }
    state
}

fn in_pool(threads: usize) -> State {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(run)
}

#[test]
fn one_and_two_threads_give_bit_identical_granular_runs() {
    let (a, b) = (in_pool(1), in_pool(2));
    let spin: f64 = a.rigid.angular_velocity.iter().map(|w| w.norm()).sum();
    assert!(spin > 0.0, "friction must spin the spheres");
    let bits = |s: &State| -> Vec<u64> {
        s.position
            .iter()
            .chain(&s.velocity)
            .chain(&s.rigid.angular_velocity)
            .flat_map(|v| v.iter().map(|c| c.to_bits()).collect::<Vec<_>>())
            .collect()
    };
    assert_eq!(bits(&a), bits(&b));
}
