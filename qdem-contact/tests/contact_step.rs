//! The contacts' step from the contacts present (`stable_step.rs`): a bed poured at the
//! default step settles; the settled bed of the oedometer LIGGGHTS steps at 2e-5 s is
//! accepted there and stays stable; a step above what one contact alone allows is refused
//! at the start, or stops the run at the rebuild that finds the contact; and a rigid body of
//! many spheres with a dashpot is bounded by its touching contacts and its own mass, to the
//! exact step of its one mode.

mod common;

use common::{contacts, rigid_spheres, verlet_world};
use qdem_contact::{
    ContactLaw, ContactSettings, ContactSphere, DemContacts, HertzMindlin, LinearSpring, PlaneWall,
    Wall, WallShape,
};
use qdem_core::continuum::stable_step::critical_step;
use qdem_core::error::CoreError;
use qdem_core::loads::Gravity;
use qdem_core::step::{Model, State};
use qdem_core::world::World;
use qdem_core::{Mat3, Vec3};

/// The oedometer's material: E = 50 MPa, ν = 0.25, ρ = 2,500 kg/m³.
const MATERIAL: (f64, f64) = (5e7, 0.25);
const DENSITY: f64 = 2500.0;
/// The box's side (m).
const SIDE: f64 = 0.1;

/// ζ of restitution e: −ln e/√(π² + ln² e).
fn damping_ratio(restitution: f64) -> f64 {
    let l = restitution.ln();
    -l / (std::f64::consts::PI.powi(2) + l * l).sqrt()
}

/// A plane wall through `point` facing `normal`, with friction 0.5.
fn wall(point: Vec3, normal: Vec3) -> Wall {
    Wall {
        shape: WallShape::Plane(PlaneWall::new(point, normal, Vec3::zeros())),
        friction: 0.5,
    }
}

/// A floor and four sides of a square box.
fn box_walls() -> Vec<Wall> {
    vec![
        wall(Vec3::zeros(), Vec3::z()),
        wall(Vec3::zeros(), Vec3::x()),
        wall(Vec3::new(SIDE, 0.0, 0.0), -Vec3::x()),
        wall(Vec3::zeros(), Vec3::y()),
        wall(Vec3::new(0.0, SIDE, 0.0), -Vec3::y()),
    ]
}

/// 320 rotating spheres of diameters 8–12 mm on a loose 8 × 8 × 5 lattice in the box, at
/// rest: the oedometer's grains (μ = 0.5, e = 0.5, Hertz–Mindlin).
fn lattice() -> (State, DemContacts) {
    let spacing = SIDE / 8.0;
    let mut centers = Vec::new();
    let mut radii = Vec::new();
    for k in 0..5 {
        for j in 0..8 {
            for i in 0..8 {
                let n = centers.len();
                let fraction = (n as f64 * 0.618_033_988_749_895).fract();
                radii.push(0.004 + 0.002 * fraction);
                centers.push(Vec3::new(
                    (i as f64 + 0.5) * spacing,
                    (j as f64 + 0.5) * spacing,
                    (k as f64 + 0.5) * spacing,
                ));
            }
        }
    }
    let mut state = State::at_rest(centers);
    let mut spheres = Vec::new();
    for (i, &radius) in radii.iter().enumerate() {
        state.mass[i] = DENSITY * 4.0 / 3.0 * std::f64::consts::PI * radius.powi(3);
        let inertia = Mat3::identity() * (0.4 * state.mass[i] * radius * radius);
        state.add_rigid_body("grain", i, &[], inertia).unwrap();
        spheres.push(ContactSphere {
            particle: i,
            radius,
            body: i,
            material: 0,
        });
    }
    let settings = ContactSettings {
        law: ContactLaw::HertzMindlin(HertzMindlin {
            damping_ratio: damping_ratio(0.5),
        }),
        friction: 0.5,
        skin: 0.001,
    };
    let model = contacts(&state, &spheres, MATERIAL, settings, box_walls());
    (state, model)
}

/// A world of `model` under gravity, stepped at `dt` (automatic when `None`).
fn world(state: State, model: DemContacts, dt: Option<f64>) -> Result<World, CoreError> {
    let models: Vec<Box<dyn Model>> = vec![
        Box::new(model),
        Box::new(Gravity::new(Vec3::new(0.0, 0.0, -9.81))),
    ];
    verlet_world(state, models, dt)
}

/// Steps `world` to `t_end`; the first failure stops it.
fn run_to(world: &mut World, t_end: f64) -> Result<(), CoreError> {
    while world.state.time < t_end {
        world.step()?;
    }
    Ok(())
}

/// The lattice poured at the default step and settled for 0.4 s: the state, and the step.
fn settled_bed() -> (State, f64) {
    let (state, model) = lattice();
    let mut pour = world(state, model, None).expect("the default step is accepted");
    let dt = pour.dt();
    run_to(&mut pour, 0.4).expect("the pour stays stable at the default step");
    (pour.state.clone(), dt)
}

/// The contacts of `state` (the lattice's spheres at other positions), their lists built as
/// a run's build does.
fn model_at(state: &State) -> DemContacts {
    let (_, mut model) = lattice();
    model.check_initial_overlaps(state, 1.0).unwrap();
    model
}

#[test]
fn a_pour_settles_at_the_default_step_and_the_settled_bed_runs_at_liggghts_step() {
    let (bed, pour_dt) = settled_bed();
    let kinetic = bed.kinetic_energy();
    let weight: f64 = bed.mass.iter().map(|m| m * 9.81).sum();
    eprintln!("pour: dt = {pour_dt:.3e} s, kinetic energy after 0.4 s {kinetic:.3e} J");
    // Settled: the grains' kinetic energy is below that of their weight falling 1 µm.
    assert!(kinetic < weight * 1e-6, "{kinetic} J");
    // The fixed worst case refused anything above 8.3e-6 s; LIGGGHTS steps this bed at
    // 2e-5 s (13% of the smallest grain's Rayleigh time, 1.53e-4 s).
    let model = model_at(&bed);
    let estimate = model.stable_dt(&bed).unwrap();
    let unstable = model.unstable_above(&bed).unwrap();
    eprintln!(
        "settled bed: estimate {estimate:.3e} s, one contact alone unstable above {unstable:.3e} s"
    );
    assert!(estimate > 8.3e-6 && unstable > 2e-5);
    let mut at_liggghts = world(bed, model, Some(2e-5)).expect("2e-5 s is accepted");
    let before = at_liggghts.state.kinetic_energy();
    run_to(&mut at_liggghts, 0.45).expect("the bed stays stable at 2e-5 s");
    let after = at_liggghts.state.kinetic_energy();
    eprintln!("at 2e-5 s: kinetic energy {before:.3e} J -> {after:.3e} J");
    // Stable: the kinetic energy does not grow beyond the settling bed's.
    assert!(after <= before.max(weight * 1e-7), "{before} -> {after}");
}

/// A sphere of radius 5 mm falling at `speed` onto a floor (Hertz, the oedometer's material).
fn falling_sphere(speed: f64) -> (State, DemContacts) {
    let r = 0.005;
    let (mut state, spheres) = rigid_spheres(&[Vec3::new(0.0, 0.0, r + 1e-4)], r, DENSITY);
    state.velocity[0] = Vec3::new(0.0, 0.0, -speed);
    let settings = ContactSettings {
        law: ContactLaw::HertzMindlin(HertzMindlin { damping_ratio: 0.0 }),
        friction: 0.5,
        skin: 2e-5,
    };
    let floor = wall(Vec3::zeros(), Vec3::z());
    let model = contacts(&state, &spheres, MATERIAL, settings, vec![floor]);
    (state, model)
}

#[test]
fn a_step_one_contact_cannot_take_is_refused_or_stops_the_run_naming_the_contact() {
    // At 20 m/s the impact's largest overlap is (15 m v²/(16 E* √r))^{2/5} = 0.37 mm, where
    // the contact alone needs 2/√(S_n/m) with S_n = 2E*√(r δ): about 2.9e-5 s. The sphere
    // starts apart, so a step of 1e-4 s is accepted, and the rebuild that finds it deep in
    // the floor stops the run.
    let (state, mut model) = falling_sphere(20.0);
    model.check_initial_overlaps(&state, 0.1).unwrap();
    let mut w = world(state, model, Some(2e-4)).expect("no contact touches at the start");
    let error = run_to(&mut w, 0.01).expect_err("the contact needs a shorter step");
    let text = error.to_string();
    eprintln!("{text}");
    assert!(text.contains("sphere 0 of `body0` and a wall"), "{text}");
    let needed: f64 = text
        .split("needs dt <= ")
        .nth(1)
        .and_then(|t| t.split(' ').next())
        .and_then(|t| t.parse().ok())
        .unwrap();
    assert!(needed < 2e-4 && needed > 1e-5, "{needed}");
    // Overlapping at the start by 0.2 mm: 2/√(S_n/m) is known then, and a step above it
    // refused, one below it accepted.
    let (mut state, mut model) = falling_sphere(0.0);
    state.position[0].z = 0.005 - 2e-4;
    model.check_initial_overlaps(&state, 0.1).unwrap();
    let e_star = MATERIAL.0 / (1.0 - MATERIAL.1 * MATERIAL.1);
    let stiffness = 2.0 * e_star * (0.005f64 * 2e-4).sqrt();
    let alone = 2.0 / (stiffness / state.mass[0]).sqrt();
    let got = model.unstable_above(&state).unwrap();
    assert!((got / alone - 1.0).abs() < 1e-12, "{got} vs {alone}");
    let refused = world(state.clone(), model, Some(1.01 * alone));
    assert!(matches!(refused, Err(CoreError::StepTooLarge { .. })));
}

/// A rigid body of 8 × 5 spheres of radius 5 mm in the x–z plane, its rotation held, its
/// lowest row of 8 resting `overlap` into a floor; linear springs k with restitution 0.5.
fn slab(k: f64, overlap: f64) -> (State, DemContacts, f64) {
    let r = 0.005;
    let mut points = vec![Vec3::zeros()];
    for layer in 0..5 {
        for i in 0..8 {
            points.push(Vec3::new(
                2.0 * r * i as f64,
                0.0,
                r - overlap + 2.0 * r * layer as f64,
            ));
        }
    }
    let center = points[1..].iter().sum::<Vec3>() / 40.0;
    points[0] = center;
    let mut state = State::at_rest(points);
    let mass = 40.0 * DENSITY * 4.0 / 3.0 * std::f64::consts::PI * r.powi(3);
    state.mass[0] = mass;
    let members: Vec<usize> = (1..=40).collect();
    state
        .add_rigid_body("slab", 0, &members, Mat3::identity() * mass * 1e-3)
        .unwrap();
    state.rigid.spin_fixed[0] = true;
    let spheres: Vec<ContactSphere> = members
        .iter()
        .map(|&p| ContactSphere {
            particle: p,
            radius: r,
            body: 0,
            material: 0,
        })
        .collect();
    let settings = ContactSettings {
        law: ContactLaw::Linear(LinearSpring {
            normal_stiffness: k,
            tangential_stiffness: 0.5 * k,
            damping_ratio: damping_ratio(0.5),
        }),
        friction: 0.5,
        skin: 0.001,
    };
    let floor = wall(Vec3::zeros(), Vec3::z());
    let mut model = contacts(&state, &spheres, MATERIAL, settings, vec![floor]);
    model.check_initial_overlaps(&state, 0.1).unwrap();
    (state, model, mass)
}

#[test]
fn a_rigid_body_of_many_spheres_with_a_dashpot_is_bounded_by_its_touching_contacts() {
    // The slab's one mode on its 8 floor contacts: ω² = 8k/M, γ = 8c/M with the law's
    // dashpot c = 2ζ√(k M) (the reduced mass against a wall is the body's): central
    // differences are stable up to 2/(√(ω² + γ²/4) + γ/2). The fixed worst case counted
    // all 40 spheres, each twice (Gershgorin): a step 3.3 times shorter here, and for a
    // sleeper of hundreds of spheres with a lever arm, nanoseconds.
    let k = 1e5;
    let (state, model, mass) = slab(k, 1e-5);
    let zeta = damping_ratio(0.5);
    let c = 2.0 * zeta * (k * mass).sqrt();
    let exact = critical_step(8.0 * k / mass, 8.0 * c / mass);
    let estimate = model.stable_dt(&state).unwrap();
    eprintln!("slab: estimate {estimate:.6e} s, exact {exact:.6e} s");
    assert!(
        (estimate / exact - 1.0).abs() < 1e-12,
        "{estimate} vs {exact}"
    );
    // The slab, let go 10 µm into the floor, only loses energy when stepped below that step;
    // stepped above the undamped limit 2/√(8k/M) the step feeds it energy, many times what
    // it had (its contacts being one-sided, it is thrown off the floor rather than
    // diverging).
    let energy = |w: &World| {
        w.state.kinetic_energy()
            + w.models
                .iter()
                .filter_map(|m| m.potential_energy(&w.state))
                .sum::<f64>()
    };
    let (state, model, _) = slab(k, 1e-5);
    let mut below = world(state, model, Some(0.95 * exact)).unwrap();
    let start = energy(&below);
    run_to(&mut below, 0.05).expect("stable below the exact step");
    eprintln!(
        "0.95 of it: energy {start:.6e} J -> {:.6e} J",
        energy(&below)
    );
    assert!(energy(&below) < start);
    let undamped = 2.0 / (8.0 * k / mass).sqrt();
    let (state, model, _) = slab(k, 1e-5);
    let mut above = world(state, model, Some(1.2 * undamped)).unwrap();
    let start = energy(&above);
    let stopped = run_to(&mut above, 0.05).is_err();
    eprintln!(
        "1.2 of 2/omega: energy {start:.6e} J -> {:.6e} J",
        energy(&above)
    );
    assert!(stopped || energy(&above) - start > 10.0 * 8.0 * 0.5 * k * 1e-10);
}
