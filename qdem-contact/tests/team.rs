//! A bed of one-sphere grains (rotating particles, Hertz–Mindlin with friction and damping,
//! gravity, a floor and side walls) stepped on a persistent team of two threads
//! (`qdem_core::step::team`): the same bits as one rayon thread and as two, and one step in
//! four phases of the team (the drift, the contacts' read of the centres, the pair kernel,
//! the kick) that cost at most one wake-up, where rayon started three regions, each of
//! which may wake its sleeping worker.

mod common;

use common::stepper;
use qdem_contact::{
    ContactLaw, ContactSettings, ContactSphere, DemContacts, HertzMindlin, PlaneWall, Wall,
    WallShape,
};
use qdem_core::step::model::find_model;
use qdem_core::step::team::{self, RegionCounts, Team, Waits};
use qdem_core::{loads::Gravity, step::Model, step::State, step::Stepper, Vec3};
use std::time::Duration;

const R: f64 = 0.005;
/// Spheres along each side: 10,648 in all, the benchmarks' 10⁴, where rayon's sweeps cut
/// two tasks of 4,096 particles or more and the kernel six runs.
const SIDE: usize = 22;
const STEPS: usize = 150;

/// The bed, jittered on a lattice a little looser than touching, with velocities that
/// bring neighbours into contact within the run.
fn bed() -> (State, Vec<Box<dyn Model>>) {
    let pitch = 2.02 * R;
    let mut centers = Vec::new();
    for k in 0..SIDE {
        for j in 0..SIDE {
            for i in 0..SIDE {
                let jitter = ((i * 7 + j * 13 + k * 29) % 17) as f64 / 17.0 - 0.5;
                centers.push(Vec3::new(
                    (i as f64 + 0.5) * pitch + 0.05 * R * jitter,
                    (j as f64 + 0.5) * pitch - 0.05 * R * jitter,
                    (k as f64 + 0.5) * pitch,
                ));
            }
        }
    }
    let mut state = State::at_rest(centers.clone());
    let mass = 2700.0 * 4.0 / 3.0 * std::f64::consts::PI * R.powi(3);
    for i in 0..centers.len() {
        state.mass[i] = mass;
        state.let_turn(i, 0.4 * mass * R * R);
        let f = |m: usize| ((i * m) % 101) as f64 / 101.0 - 0.5;
        state.velocity[i] = Vec3::new(f(37), f(53), f(71));
    }
    let spheres: Vec<ContactSphere> = (0..centers.len())
        .map(|i| ContactSphere {
            particle: i,
            radius: R,
            body: i,
            material: 0,
        })
        .collect();
    let width = SIDE as f64 * pitch;
    let plane = |point: Vec3, normal: Vec3| Wall {
        shape: WallShape::Plane(PlaneWall::new(point, normal, Vec3::zeros())),
        friction: 0.4,
    };
    let walls = vec![
        plane(Vec3::zeros(), Vec3::z()),
        plane(Vec3::zeros(), Vec3::x()),
        plane(Vec3::zeros(), Vec3::y()),
        plane(Vec3::new(width, 0.0, 0.0), -Vec3::x()),
        plane(Vec3::new(0.0, width, 0.0), -Vec3::y()),
    ];
    let settings = ContactSettings {
        law: ContactLaw::HertzMindlin(HertzMindlin { damping_ratio: 0.3 }),
        friction: 0.5,
        skin: 0.1 * R,
    };
    let names = vec!["grain".to_string(); centers.len()];
    let contacts = DemContacts::new(&state, &spheres, names, &[(5e7, 0.25)], settings, walls);
    let models: Vec<Box<dyn Model>> = vec![
        Box::new(contacts),
        Box::new(Gravity::new(Vec3::new(0.0, 0.0, -9.81))),
    ];
    (state, models)
}

/// What a run leaves: the state, the contacts touching at its end, its rebuilds, and the
/// regions its steps started.
struct Run {
    state: State,
    touching: usize,
    rebuilds: u64,
    regions: RegionCounts,
}

/// [`bed`] stepped [`STEPS`] times on a rayon pool of `threads`, on a team of two installed
/// on the stepping thread when `waits` is given.
fn run(threads: usize, waits: Option<Waits>) -> Run {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a pool");
    pool.install(|| {
        let team = waits.map(|w| Team::with_waits(2, w));
        let go = || {
            let (mut state, mut models) = bed();
            let dt = 0.5 * models[0].stable_dt(&state).expect("a contact step");
            let mut s = stepper(dt, &mut state, &mut models);
            let before = team::counts();
            for _ in 0..STEPS {
                s.step(&mut state, &mut models).expect("a stable step");
            }
            let after = team::counts();
            let regions = RegionCounts {
                regions: after.regions - before.regions,
                phases: after.phases - before.phases,
                wakeups: after.wakeups - before.wakeups,
                holds: after.holds - before.holds,
            };
            let contacts = find_model::<DemContacts>(&models).expect("the contacts");
            Run {
                touching: contacts.contacts(),
                rebuilds: contacts.rebuilds(),
                state,
                regions,
            }
        };
        match &team {
            Some(team) => team.install(go),
            None => go(),
        }
    })
}

fn bits(s: &State) -> Vec<u64> {
    s.position
        .iter()
        .chain(&s.velocity)
        .chain(&s.spin.velocity)
        .chain(&s.spin.angle)
        .flat_map(|v| v.iter().map(|c| c.to_bits()).collect::<Vec<_>>())
        .collect()
}

#[test]
fn a_team_of_two_gives_the_bits_of_one_thread_and_of_rayon() {
    let one = run(1, None);
    // The run is a real test of the sums: many touching contacts, rebuilt lists, spin.
    assert!(one.touching > 2000, "{} touching", one.touching);
    assert!(one.rebuilds > 1, "{} rebuilds", one.rebuilds);
    assert!(one.state.spin.velocity.iter().any(|w| w.norm() > 0.0));
    let two = run(2, None);
    let team = run(2, Some(Waits::default()));
    assert_eq!(bits(&one.state), bits(&two.state), "rayon, 2 threads");
    assert_eq!(bits(&one.state), bits(&team.state), "a team of 2");
    assert_eq!(one.touching, team.touching);
}

#[test]
fn a_step_on_a_team_is_four_phases_and_at_most_one_wake_up() {
    // Rayon: the drift, the pair kernel and the kick are regions of two tasks or more (the
    // read of 10⁴ centres stays on the caller below 2 × 16,384 spheres), each a possible
    // wake-up of the sleeping worker.
    let rayon = run(2, None);
    let steps = STEPS as u64;
    assert_eq!(rayon.regions.regions, 3 * steps, "{:?}", rayon.regions);
    assert_eq!(rayon.regions.phases, 0);
    // A team whose worker parks as soon as a step ends and never inside one: every region
    // is a phase of the team, four a step, and a step wakes the worker once at most (its
    // first phase, or none when the worker had not parked yet); a worker that parked
    // between the phases of a step would make it up to four.
    let waits = Waits {
        spin: Duration::ZERO,
        patience: Duration::from_secs(3600),
    };
    let team = run(2, Some(waits));
    assert_eq!(team.regions.phases, 4 * steps, "{:?}", team.regions);
    assert_eq!(team.regions.regions, team.regions.phases);
    assert_eq!(team.regions.holds, steps);
    assert!(team.regions.wakeups <= steps, "{:?}", team.regions);
}
