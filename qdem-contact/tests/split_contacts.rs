//! Contacts decomposed over ranks ([`qdem_contact::DemContacts`] as a split model: each rank
//! evaluates the contacts that touch the grains it owns and receives its ghosts) give the
//! bits of one process: the state, every contact record, the per-sphere forces and the
//! checkpoint, for 2 and 3 ranks (threads of this process,
//! [`qdem_core::parallel::thread_ranks::on_thread_ranks`]), for grains that rotate as particles or as
//! rigid bodies (owned whole by one rank), in a box and in a cell periodic across the ranks'
//! cut (grains wrapping back into it), with and without a time delay on the periodic
//! boundary; a checkpoint written at 2 ranks resumes at 1 and 3.

mod common;

use common::contacts;
use qdem_contact::{
    ContactLaw, ContactSettings, ContactSphere, DemContacts, LinearSpring, LoadCycle, PeriodicBox,
    PeriodicWrap, PlaneWall, TimeDelayedBoundary, Wall, WallShape, WrapGroup,
};
use qdem_core::parallel::thread_ranks::on_thread_ranks;
use qdem_core::{
    checkpoint::Decoder, checkpoint::Encoder, loads::Gravity, step::Dofs, step::Model,
    step::Scheme, step::State, step::StepRequest, step::StepSettings, world::World, Mat3, Vec3,
};

const R: f64 = 0.005;

/// Steps of each run, and the steps between the gathers that outputs would ask for.
const STEPS: usize = 600;
const GATHER_EVERY: usize = 97;

/// The step after which every run re-partitions (a no-op on one process).
const REPARTITION_AT: u64 = 300;

/// 10 × 6 × 10 rotating grains with jittered radii and velocities above a floor, in a box
/// longer in x than in y: friction spins them, and they cross the ranks' cut as they fall.
/// The grains of a test.
#[derive(Clone, Copy, PartialEq)]
enum Grains {
    /// Particles that rotate, in a box.
    Rotating,
    /// The same in a cell periodic in x instead of walled there: the grains wrap.
    Periodic,
    /// Rigid bodies of one sphere each, in a box.
    Rigid,
    /// The periodic cell with a time delay on its boundary (paper 003 §5).
    Delayed,
}

/// The run of `grains`.
fn world(grains: Grains) -> World {
    let periodic = matches!(grains, Grains::Periodic | Grains::Delayed);
    let mut centers = Vec::new();
    // x slowest: a rank's run of particles is a slab across x, so that in the periodic cell
    // it finds its pairs among the spheres with an image near its slab.
    for i in 0..10 {
        for j in 0..6 {
            for k in 0..10 {
                let jitter = ((i * 7 + j * 13 + k * 29) % 17) as f64 / 17.0 - 0.5;
                centers.push(Vec3::new(
                    (2.2 * i as f64 + 1.2) * R + 0.1 * R * jitter,
                    (2.2 * j as f64 + 1.2) * R - 0.1 * R * jitter,
                    (2.2 * k as f64 + 1.2) * R,
                ));
            }
        }
    }
    let mut state = State::at_rest(centers.clone());
    let mut spheres = Vec::new();
    let mut inertia = Vec::new();
    for i in 0..centers.len() {
        let f = |m: usize| ((i * m) % 101) as f64 / 101.0 - 0.5;
        state.velocity[i] = Vec3::new(f(37), f(53), f(71));
        let radius = R * (0.9 + 0.1 * f(19));
        let mass = 2500.0 * 4.0 / 3.0 * std::f64::consts::PI * radius.powi(3);
        state.mass[i] = mass;
        inertia.push(0.4 * mass * radius * radius);
        if grains == Grains::Rigid {
            let moment = Mat3::identity() * (0.4 * mass * radius * radius);
            state.add_rigid_body("grain", i, &[], moment).unwrap();
        }
        spheres.push(ContactSphere {
            particle: i,
            radius,
            body: i,
            material: 0,
        });
    }
    if grains != Grains::Rigid {
        state.add_spin(inertia, Dofs::NONE);
    }
    let plane = |point: Vec3, normal: Vec3| Wall {
        shape: WallShape::Plane(PlaneWall::new(point, normal, Vec3::zeros())),
        friction: 0.4,
    };
    let (x, y) = (22.0 * R + 0.4 * R, 13.2 * R + 0.4 * R);
    let mut walls = vec![
        plane(Vec3::zeros(), Vec3::z()),
        plane(Vec3::zeros(), Vec3::y()),
        plane(Vec3::new(0.0, y, 0.0), -Vec3::y()),
    ];
    if !periodic {
        walls.push(plane(Vec3::zeros(), Vec3::x()));
        walls.push(plane(Vec3::new(x, 0.0, 0.0), -Vec3::x()));
    }
    let settings = ContactSettings {
        law: ContactLaw::Linear(LinearSpring {
            normal_stiffness: 2e3,
            tangential_stiffness: 1e3,
            damping_ratio: 0.2,
        }),
        friction: 0.5,
        skin: 0.2 * R,
    };
    let mut model = contacts(&state, &spheres, (5e7, 0.25), settings, walls);
    let cell = PeriodicBox::new(Vec3::zeros(), [Some(x), None, None]).unwrap();
    if periodic {
        model = model.with_periodic(cell.clone()).unwrap();
    }
    if grains == Grains::Delayed {
        let cycle = LoadCycle {
            frequency: 20.0,
            phase: 0.0,
            start: 0.0,
        };
        let boundary = TimeDelayedBoundary::new(cycle, 0.5 * std::f64::consts::PI);
        model = model.with_time_delay(0, boundary).unwrap();
    }
    let models: Vec<Box<dyn Model>> = vec![
        Box::new(model),
        Box::new(Gravity::new(Vec3::new(0.0, 0.0, -9.81))),
    ];
    let request = StepRequest {
        scheme: Scheme::Verlet,
        dt: None,
        safety: 0.5,
        local_damping: 0.0,
        adaptive: false,
        event_solve: Default::default(),
        implicit_default: None,
        fit_to: None,
    };
    let settings = StepSettings::resolve(&request, &state, &models).unwrap();
    let mut world = World::new(state, models, settings).unwrap();
    if periodic {
        let groups = (0..centers.len())
            .map(|p| WrapGroup {
                anchor: p,
                particles: vec![p],
            })
            .collect();
        world.add_hook(Box::new(PeriodicWrap::new(cell, groups)));
    }
    world
}

/// What a run leaves, on one rank after its last gather.
struct Outcome {
    /// Positions, velocities and spins (and the rigid bodies' orientations), as bits.
    motion: Vec<u64>,
    /// The sum of the grains' angular speeds (rad/s).
    spin: f64,
    /// The force through the time-delayed boundary at the last evaluation (N), 0 without.
    boundary_force: f64,
    /// Every touching contact: partners and force, as bits.
    touching: Vec<(usize, String, [u64; 3])>,
    /// Every sphere's contact force, as bits.
    sphere_forces: Vec<[u64; 3]>,
    /// The checkpoint's bytes.
    checkpoint: Vec<u8>,
    rebuilds: u64,
}

impl Outcome {
    /// Fails naming the first part and index where `self` differs from `alone`.
    fn assert_same(&self, alone: &Outcome, run: &str) {
        same(&self.motion, &alone.motion, run, "motion");
        same(&self.touching, &alone.touching, run, "touching contacts");
        same(
            &self.sphere_forces,
            &alone.sphere_forces,
            run,
            "sphere forces",
        );
        same(&self.checkpoint, &alone.checkpoint, run, "checkpoint");
        assert_eq!(self.rebuilds, alone.rebuilds, "{run}: rebuilds");
        let force = (
            self.boundary_force.to_bits(),
            alone.boundary_force.to_bits(),
        );
        assert_eq!(force.0, force.1, "{run}: boundary force");
    }
}

/// Fails naming the first index where `a` and `b` differ, or their lengths.
fn same<T: PartialEq + std::fmt::Debug>(a: &[T], b: &[T], run: &str, what: &str) {
    assert_eq!(a.len(), b.len(), "{run}: {what}: lengths");
    if let Some(k) = (0..a.len()).find(|&k| a[k] != b[k]) {
        panic!(
            "{run}: {what} differ first at {k}: {:?} vs {:?}",
            a[k], b[k]
        );
    }
}

fn bits(v: &Vec3) -> [u64; 3] {
    [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()]
}

fn outcome(world: &World) -> Outcome {
    let state = &world.state;
    let contacts = world.model::<DemContacts>().unwrap();
    let mut checkpoint = Encoder::new();
    world.save(&mut checkpoint).unwrap();
    Outcome {
        motion: state
            .position
            .iter()
            .chain(&state.velocity)
            .chain(&state.spin.velocity)
            .chain(&state.rigid.angular_velocity)
            .flat_map(bits)
            .chain(state.rigid.orientation.iter().flat_map(|q| {
                q.as_ref()
                    .coords
                    .iter()
                    .map(|c| c.to_bits())
                    .collect::<Vec<_>>()
            }))
            .collect(),
        spin: state
            .spin
            .velocity
            .iter()
            .chain(&state.rigid.angular_velocity)
            .map(|w| w.norm())
            .sum(),
        touching: contacts
            .touching()
            .map(|c| {
                let force = c.normal_force + c.tangential_force;
                (c.first, format!("{:?}", c.second), bits(&force))
            })
            .collect(),
        sphere_forces: contacts
            .sphere_records(state)
            .map(|s| bits(&s.force))
            .collect(),
        checkpoint: checkpoint.into_bytes(),
        rebuilds: contacts.rebuilds(),
        boundary_force: contacts.time_delay_state().map_or(0.0, |(_, f)| f),
    }
}

/// `steps` steps of `world` (gathered every [`GATHER_EVERY`] steps and at the end when
/// decomposed, re-partitioned after step [`REPARTITION_AT`]), and per gather whether this
/// rank's lists were fewer than the whole.
fn steps(world: &mut World, steps: usize) -> Vec<bool> {
    let mut cut = Vec::new();
    for step in 1..=steps {
        world.step().unwrap();
        if world.steps_done() == REPARTITION_AT {
            world.repartition();
        }
        if step % GATHER_EVERY == 0 || step == steps {
            let part = world.model::<DemContacts>().unwrap().candidates();
            world.gather();
            cut.push(part < world.model::<DemContacts>().unwrap().candidates());
        }
    }
    cut
}

/// One process's outcome after [`STEPS`] steps, and its checkpoint after `stop`.
fn one_process(grains: Grains, stop: usize) -> (Outcome, Vec<u8>) {
    let mut world = world(grains);
    world.initialize().unwrap();
    steps(&mut world, stop);
    let saved = outcome(&world).checkpoint;
    steps(&mut world, STEPS - stop);
    (outcome(&world), saved)
}

/// Every rank's outcome over `size` ranks, resumed from `checkpoint` after `stop` steps if
/// given; and whether each rank's lists were cut at every gather.
fn on_ranks(size: usize, grains: Grains, resume: Option<(Vec<u8>, usize)>) -> Vec<(Outcome, bool)> {
    on_thread_ranks(size, move |comm| {
        let mut world = world(grains);
        world.decompose(comm).unwrap();
        let done = match &resume {
            Some((bytes, stop)) => {
                world
                    .restore(&mut Decoder::new(bytes), *stop as u64)
                    .unwrap();
                *stop
            }
            None => {
                world.initialize().unwrap();
                0
            }
        };
        let cut = steps(&mut world, STEPS - done);
        assert!(world.repartitions() > 0 || size == 1, "re-partitioned");
        (outcome(&world), cut.iter().all(|&c| c))
    })
}

/// One process's run against 2 and 3 ranks'.
fn same_on_ranks(grains: Grains) -> Outcome {
    let (alone, _) = one_process(grains, STEPS);
    assert!(alone.spin > 0.0, "friction spins the grains");
    assert!(
        alone.touching.len() > 50,
        "{} touching",
        alone.touching.len()
    );
    assert!(
        alone.rebuilds > 3,
        "the lists are rebuilt as the grains fall"
    );
    for size in [2, 3] {
        for (rank, (outcome, cut)) in on_ranks(size, grains, None).into_iter().enumerate() {
            assert!(cut, "{size} ranks: rank {rank} evaluates only its part");
            outcome.assert_same(&alone, &format!("{size} ranks: rank {rank}"));
        }
    }
    alone
}

#[test]
fn split_contacts_give_one_processs_bits_on_two_and_three_ranks() {
    same_on_ranks(Grains::Rotating);
}

/// The ranks measure the force through the boundary over all their pairs, as one process.
#[test]
fn split_contacts_with_a_time_delayed_boundary_give_one_processs_bits_on_two_and_three_ranks() {
    let alone = same_on_ranks(Grains::Delayed);
    assert!(
        alone.boundary_force > 0.0,
        "grains touch through the boundary"
    );
}

#[test]
fn split_contacts_of_rigid_grains_give_one_processs_bits_on_two_and_three_ranks() {
    same_on_ranks(Grains::Rigid);
}

#[test]
fn split_contacts_in_a_periodic_cell_give_one_processs_bits_on_two_and_three_ranks() {
    let alone = same_on_ranks(Grains::Periodic);
    let x: Vec<f64> = alone.motion[..1800]
        .chunks(3)
        .map(|p| f64::from_bits(p[0]))
        .collect();
    let period = 22.4 * R;
    assert!(
        x.iter().all(|&x| (0.0..period).contains(&x)),
        "every grain is wrapped into the cell"
    );
    let through = alone
        .touching
        .iter()
        .filter(|(first, second, _)| {
            let b = second.trim_start_matches("Sphere(").trim_end_matches(')');
            b.parse::<usize>()
                .is_ok_and(|b| (x[*first] - x[b]).abs() > 0.5 * period)
        })
        .count();
    assert!(
        through > 0,
        "some grains touch through the periodic boundary"
    );
}

/// A checkpoint of `grains` written at 2 ranks after 250 steps is one process's, and
/// resumes at 1 and 3 ranks to one process's end.
fn resumes_on_other_ranks(grains: Grains) {
    let stop = 250;
    let (alone, saved_alone) = one_process(grains, stop);
    let saved = on_thread_ranks(2, move |comm| {
        let mut world = world(grains);
        world.decompose(comm).unwrap();
        world.initialize().unwrap();
        steps(&mut world, stop);
        outcome(&world).checkpoint
    });
    same(&saved[0], &saved_alone, "2 ranks", "checkpoint");
    for size in [1, 3] {
        let resumed = on_ranks(size, grains, Some((saved[0].clone(), stop)));
        for (rank, (outcome, _)) in resumed.into_iter().enumerate() {
            outcome.assert_same(&alone, &format!("resumed on {size} ranks: rank {rank}"));
        }
    }
}

#[test]
fn a_checkpoint_of_split_contacts_at_two_ranks_resumes_at_one_and_three() {
    resumes_on_other_ranks(Grains::Rotating);
}

/// The rigid bodies' rotation and the stepper's torques on them come from their owners.
#[test]
fn a_checkpoint_of_split_rigid_grains_at_two_ranks_resumes_at_one_and_three() {
    resumes_on_other_ranks(Grains::Rigid);
}
