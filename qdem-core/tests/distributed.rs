//! A run decomposed over ranks gives the bit-identical state of one process, for 2 and 3
//! ranks: here the ranks are threads of this process
//! ([`qdem_core::parallel::thread_ranks::on_thread_ranks`]), so the decomposition itself is tested
//! without MPI.

mod common;

use qdem_core::parallel::thread_ranks::on_thread_ranks;
use qdem_core::{
    parallel::RankFigures, step::Model, step::Scheme, step::State, step::StepEvents,
    step::StepRequest, step::StepSettings, world::Gather, world::World, Vec3,
};

/// An event every time the tip's vertical velocity crosses a multiple of [`BAND`]: a
/// stand-in for a bond reaching its strength, so that an adaptive Newmark step is retaken and
/// finished in sub-steps whose predictions read the velocities of the sub-step before.
struct Tripwire {
    particle: usize,
    /// The band of the last accepted step.
    band: f64,
}

/// Width of the tripwire's velocity bands (m/s).
const BAND: f64 = 2e-3;

impl Tripwire {
    fn band(&self, state: &State) -> f64 {
        (state.velocity[self.particle].z / BAND).floor()
    }
}

impl Model for Tripwire {
    fn name(&self) -> &str {
        "tripwire"
    }

    fn add_forces(&mut self, _: &State, _: &mut [Vec3], _: &mut [Vec3]) {}

    fn events(&mut self) -> Option<&mut dyn StepEvents> {
        Some(self)
    }
}

impl StepEvents for Tripwire {
    /// Halves the step while it crosses a band boundary, down to the stepper's least fraction.
    fn check_step(&mut self, state: &State, _: bool) -> Option<f64> {
        (self.band(state) != self.band).then_some(0.25)
    }

    fn commit_step(&mut self, state: &State) -> bool {
        self.band = self.band(state);
        false
    }
}

/// The viscoelastic cantilever of the determinism test as a world stepped by Verlet, or by
/// adaptive explicit Newmark with a [`Tripwire`] on its tip.
fn beam_world(newmark: bool) -> World {
    let (state, mut models) = common::viscoelastic_beam();
    let scheme = match newmark {
        false => Scheme::Verlet,
        true => {
            let particle = state.len() - 1;
            models.push(Box::new(Tripwire {
                particle,
                band: 0.0,
            }));
            Scheme::Newmark {
                beta: 0.0,
                gamma: 0.5,
            }
        }
    };
    let request = StepRequest {
        scheme,
        dt: None,
        safety: 0.9,
        local_damping: 0.0,
        adaptive: newmark,
        event_solve: Default::default(),
        implicit_default: None,
        fit_to: None,
    };
    let settings = StepSettings::resolve(&request, &state, &models).unwrap();
    World::new(state, models, settings).unwrap()
}

const STEPS: usize = 300;

/// The state after [`STEPS`] steps of one process, and the retakes.
fn one_process(newmark: bool) -> (State, u64) {
    one_process_for(newmark, STEPS)
}

/// [`one_process`] after `steps` steps.
fn one_process_for(newmark: bool, steps: usize) -> (State, u64) {
    let mut world = beam_world(newmark);
    world.initialize().unwrap();
    for _ in 0..steps {
        world.step().unwrap();
    }
    let retakes = world.stepper().report().counts.retakes;
    (world.state, retakes)
}

/// Every rank's state after [`STEPS`] steps over `size` ranks (made whole by a gather at the
/// end, and also every `gather_every` steps if given), and the decomposition; and per rank
/// whether the last gather changed its state.
fn ranks(
    size: usize,
    newmark: bool,
    gather_every: Option<usize>,
) -> (Vec<State>, RankFigures, Vec<bool>) {
    let runs = on_thread_ranks(size, move |comm| {
        let mut world = beam_world(newmark);
        let figures = world.decompose(comm).unwrap();
        world.initialize().unwrap();
        for step in 1..=STEPS {
            world.step().unwrap();
            if gather_every.is_some_and(|n| step % n == 0) {
                world.gather();
            }
        }
        let before = common::motion_bits(&world.state);
        world.gather();
        let gathered = before != common::motion_bits(&world.state);
        (world.state, figures, gathered)
    });
    let figures = runs[0].1.clone();
    let (mut states, mut gathered) = (Vec::new(), Vec::new());
    for (state, _, g) in runs {
        states.push(state);
        gathered.push(g);
    }
    (states, figures, gathered)
}

/// Each rank's state after `steps` Verlet steps over `size` ranks, ended by `finish` (a
/// collective every rank calls).
fn ranks_ending(size: usize, steps: usize, finish: fn(&mut World)) -> Vec<State> {
    on_thread_ranks(size, move |comm| {
        let mut world = beam_world(false);
        world.decompose(comm).unwrap();
        world.initialize().unwrap();
        for _ in 0..steps {
            world.step().unwrap();
        }
        finish(&mut world);
        world.state
    })
}

/// The particles a probe gather asks for (the beam has 61 x 7 x 7 = 2,989): the last and one
/// in the middle, the last twice (two probes on one particle).
const PROBED: [usize; 3] = [2988, 1500, 2988];

/// A probe sample gathers only the probes' particles: on every rank they then hold one
/// process's bits, which the ranks that do not own them have received.
#[test]
fn a_probe_gather_gives_every_rank_the_probed_particles_of_one_process() {
    let (reference, _) = one_process_for(false, 150);
    assert_eq!(reference.len(), 2989);
    let states = ranks_ending(3, 150, |world| world.gather_particles(&PROBED));
    for (rank, state) in states.iter().enumerate() {
        for p in PROBED {
            let bits = |s: &State| {
                [s.position[p], s.velocity[p], s.acceleration[p]].map(|v| v.map(f64::to_bits))
            };
            assert_eq!(bits(state), bits(&reference), "rank {rank}, particle {p}");
        }
    }
    let whole = |s: &State| common::motion_bits(s) == common::motion_bits(&reference);
    assert!(
        !states.iter().all(whole),
        "only the probed particles were gathered"
    );
}

/// After 150 steps over three ranks, each rank's answer to [`World::agree_on_stop`] when
/// only rank 2 is asked to stop (`stop`) and only rank 1 reads the probes, with its state.
fn agreements(stop: bool) -> Vec<(bool, State)> {
    on_thread_ranks(3, move |comm| {
        let mut world = beam_world(false);
        world.decompose(comm).unwrap();
        world.initialize().unwrap();
        for _ in 0..150 {
            world.step().unwrap();
        }
        let asked = stop && world.rank() == 2;
        let wanted = match world.rank() {
            1 => Gather::Particles,
            _ => Gather::Nothing,
        };
        let stops = world.agree_on_stop(asked, wanted, &PROBED);
        (stops, world.state)
    })
}

/// A stop asked for on one rank stops every rank, each holding the whole state of one
/// process (the checkpoint rank 0 writes at a stop reads it), whatever the others read.
#[test]
fn a_stop_asked_on_one_rank_stops_every_rank_with_the_whole_state() {
    let (reference, _) = one_process_for(false, 150);
    let runs = agreements(true);
    assert!(runs.iter().all(|(stops, _)| *stops), "every rank stops");
    let states: Vec<State> = runs.into_iter().map(|(_, s)| s).collect();
    assert_all_equal(&states, &reference);
}

/// Without a stop the ranks gather the most any of them reads: the probes' particles that
/// rank 1 reads, on every rank, and not the whole state.
#[test]
fn the_ranks_agree_to_gather_what_any_rank_reads() {
    let (reference, _) = one_process_for(false, 150);
    let runs = agreements(false);
    assert!(runs.iter().all(|(stops, _)| !*stops), "no rank stops");
    for (rank, (_, state)) in runs.iter().enumerate() {
        for p in PROBED {
            let bits = |s: &State| [s.position[p], s.velocity[p]].map(|v| v.map(f64::to_bits));
            assert_eq!(bits(state), bits(&reference), "rank {rank}, particle {p}");
        }
    }
    let whole = |s: &State| common::motion_bits(s) == common::motion_bits(&reference);
    assert!(
        !runs.iter().all(|(_, s)| whole(s)),
        "only the probes were gathered"
    );
}

/// Every rank's state has the bits of one process's.
fn assert_all_equal(states: &[State], reference: &State) {
    for (rank, state) in states.iter().enumerate() {
        assert!(
            common::motion_bits(state) == common::motion_bits(reference),
            "rank {rank} of {} differs from one process",
            states.len()
        );
    }
}

#[test]
fn two_and_three_ranks_hold_the_bit_identical_state_of_one_process() {
    let (reference, _) = one_process(false);
    assert!(reference.displacement(reference.len() - 1).norm() > 0.0);
    for size in [2, 3] {
        let (states, figures, _) = ranks(size, false, None);
        assert_all_equal(&states, &reference);
        let tets: usize = figures.tets.iter().sum();
        assert_eq!(tets, 60 * 6 * 6 * 6, "every tetrahedron is computed once");
        assert_eq!(figures.owned.iter().sum::<usize>(), reference.len());
        assert!(figures.tets.iter().all(|&t| t > 0), "{figures:?}");
        assert_eq!(figures.cut_bodies, 1);
        // The beam's models read only what a rank steps: a rank receives its halo, a few
        // cross-sections of the beam (7 x 7 nodes each), not the other ranks' particles.
        for (received, owned) in figures.received.iter().zip(&figures.owned) {
            assert!(*received <= 2 * 49, "{figures:?}");
            assert!(*received < reference.len() - owned, "{figures:?}");
        }
        assert!(figures.received.iter().sum::<usize>() > 0, "{figures:?}");
    }
}

/// Whole gathers in the middle of a halo-exchanged run (the outputs' and checkpoints') leave
/// the stepping as it was; a rank's state differs from one process's before the last gather,
/// which shows that the halo exchange, not a whole share, kept it going.
#[test]
fn gathers_between_halo_exchanged_steps_change_no_bit() {
    let (reference, _) = one_process(false);
    let (states, _, gathered) = ranks(2, false, Some(37));
    assert_all_equal(&states, &reference);
    assert_eq!(
        gathered,
        [true, true],
        "each rank held only its part before the gather"
    );
}

/// Adaptive explicit Newmark with retaken steps: each sub-step predicts from the one before,
/// so the ranks make their state whole after every sub-step, not only at the step's end. The
/// test fails if they do not (the tip's band crossings then differ between the ranks).
#[test]
fn adaptive_explicit_newmark_over_ranks_retakes_the_steps_one_process_retakes() {
    let (reference, retakes) = one_process(true);
    eprintln!("{retakes} retakes in {STEPS} steps");
    assert!(
        retakes >= 5,
        "the tripwire makes sub-steps: {retakes} retakes"
    );
    for size in [2, 3] {
        let (states, figures, gathered) = ranks(size, true, None);
        assert!(
            gathered.iter().all(|g| !g),
            "Newmark shares the whole state every step"
        );
        assert_all_equal(&states, &reference);
        // Newmark steps every particle: each rank receives every other rank's particles.
        for (received, owned) in figures.received.iter().zip(&figures.owned) {
            assert_eq!(*received, reference.len() - owned, "{figures:?}");
        }
    }
}

/// The cantilever of [`beam_world`] (Verlet) stepped at 2.5 times its stable bound, until it
/// fails (at most 2,000 steps): the failure's report.
fn unstable_run(world: &mut World) -> String {
    world.initialize().unwrap();
    for _ in 0..2000 {
        if let Err(e) = world.step() {
            return e.to_string();
        }
    }
    panic!("the run at 2.5 times the stable step did not fail");
}

/// [`beam_world`] with its step raised to 2.5 times the stable bound.
fn unstable_world() -> World {
    let mut world = beam_world(false);
    let mut settings = world.settings().clone();
    settings.dt *= 2.5;
    world.set_settings(settings).unwrap();
    world
}

/// An unstable run stops alike on one process and on every rank of a halo-exchanged run: at
/// the same step, with the same report, whichever rank computes the tetrahedron that turns
/// inside out (the ranks agree on its report and gather the whole state before it names the
/// stable bound at that state).
#[test]
fn an_unstable_halo_exchanged_run_fails_as_one_process_does() {
    let alone = unstable_run(&mut unstable_world());
    assert!(alone.contains("turned inside out"), "{alone}");
    for size in [2, 3] {
        let runs = on_thread_ranks(size, |comm| {
            let mut world = unstable_world();
            world.decompose(comm).unwrap();
            unstable_run(&mut world)
        });
        for (rank, report) in runs.iter().enumerate() {
            assert_eq!(report, &alone, "rank {rank} of {size}");
        }
    }
}
