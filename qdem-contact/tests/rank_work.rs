//! A deformable "sleeper" without contact spheres beside a bed of deformable stones with
//! spheres on every surface vertex, the paper-size loading step in small
//! (`fixtures/ballast/full_load.toml`): the sleeper has more tetrahedra than the stones, so a
//! partition that weighs the tetrahedra alone gives one rank part of the sleeper and the other
//! the rest of it with every stone, sphere and candidate contact. Weighed by the work of each
//! item (tetrahedra, particles, contact spheres, candidate pairs), two ranks (threads of this
//! process) cut the stones and their contacts between them, a re-partition in the middle of
//! the run cuts the bodies' blocks anew by the lists then built, and the run keeps one
//! process's bits (the motion, the touching contacts and the checkpoint). Weighed by what the
//! items were measured to cost (`WorkWeights`), every rank gets the same weights, the cut
//! follows the weights it is given, and the run keeps one process's bits whatever the cut.

mod common;

use common::contacts;
use qdem_contact::{
    ContactLaw, ContactSettings, ContactSphere, DemContacts, LinearSpring, PlaneWall, Wall,
    WallShape,
};
use qdem_core::parallel::thread_ranks::on_thread_ranks;
use qdem_core::parallel::WorkWeights;
use qdem_core::{
    checkpoint::Encoder, continuum::Material, continuum::TetBody, loads::Gravity, step::Model,
    step::Scheme, step::State, step::StepRequest, step::StepSettings, world::World, Vec3,
};
use qdem_mesh::structured_box;

/// A stone's edge and its spheres' radius (m).
const EDGE: f64 = 0.02;
const RADIUS: f64 = 0.003;
/// Stones per side of the bed.
const SIDE: usize = 6;
const STEPS: usize = 120;
/// How far each outer sphere reaches into a wall, half what facing spheres overlap (m).
const SQUEEZE: f64 = 0.0002;

/// The sleeper (15 × 5 × 4 cells, 1,800 tetrahedra, above the bed, touching nothing) and
/// 36 stones of 2 × 2 × 2 cells (1,728 tetrahedra) on a floor in a box, each pressed into
/// its neighbours and the walls.
fn world() -> World {
    let sleeper = structured_box([0.0, 0.0, 0.2], [0.2, 0.06, 0.25], [15, 5, 4]).unwrap();
    let stone = structured_box([0.0; 3], [EDGE; 3], [2, 2, 2]).unwrap();
    let surface = stone.surface_nodes();
    let mut reference: Vec<Vec3> = sleeper.nodes.iter().map(|p| Vec3::from(*p)).collect();
    let mut stone_tets = Vec::new();
    let mut spheres = Vec::new();
    // Closer than two radii: neighbouring stones' facing spheres overlap.
    let pitch = EDGE + 2.0 * RADIUS - 2.0 * SQUEEZE;
    for i in 0..SIDE {
        for j in 0..SIDE {
            let first = reference.len() as u32;
            let corner = Vec3::new(pitch * i as f64, pitch * j as f64, RADIUS - SQUEEZE);
            reference.extend(stone.nodes.iter().map(|p| Vec3::from(*p) + corner));
            stone_tets.extend(stone.tets.iter().map(|t| t.map(|n| n + first)));
            spheres.extend(surface.iter().map(|&n| ContactSphere {
                particle: (first + n) as usize,
                radius: RADIUS,
                body: i * SIDE + j,
                material: 0,
            }));
        }
    }
    let material = Material::elastic(2500.0, 1e7, 0.25);
    let sleeper = TetBody::new("sleeper", &reference, sleeper.tets, material.clone()).unwrap();
    let stones = TetBody::new("stones", &reference, stone_tets, material).unwrap();
    let mut state = State::at_rest(reference);
    sleeper.lump_mass(&mut state.mass);
    stones.lump_mass(&mut state.mass);
    for (p, v) in state.velocity.iter_mut().enumerate() {
        *v = Vec3::new(0.0, 0.0, -0.2 - 0.01 * (p % 7) as f64);
    }
    let settings = ContactSettings {
        law: ContactLaw::Linear(LinearSpring {
            normal_stiffness: 2e4,
            tangential_stiffness: 1e4,
            damping_ratio: 0.1,
        }),
        friction: 0.5,
        skin: 0.001,
    };
    let wall = |point: Vec3, normal: Vec3| Wall {
        shape: WallShape::Plane(PlaneWall::new(point, normal, Vec3::zeros())),
        friction: 0.5,
    };
    let (low, high) = (
        SQUEEZE - RADIUS,
        pitch * (SIDE - 1) as f64 + EDGE + RADIUS - SQUEEZE,
    );
    let walls = vec![
        wall(Vec3::zeros(), Vec3::z()),
        wall(Vec3::repeat(low), Vec3::x()),
        wall(Vec3::repeat(low), Vec3::y()),
        wall(Vec3::repeat(high), -Vec3::x()),
        wall(Vec3::repeat(high), -Vec3::y()),
    ];
    let contact = contacts(&state, &spheres, (1e7, 0.25), settings, walls);
    let models: Vec<Box<dyn Model>> = vec![
        Box::new(sleeper),
        Box::new(stones),
        Box::new(contact),
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
    World::new(state, models, settings).unwrap()
}

/// Positions and velocities as bits.
fn motion(state: &State) -> Vec<u64> {
    state
        .position
        .iter()
        .chain(&state.velocity)
        .flat_map(|v| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()])
        .collect()
}

/// The bytes of `world`'s checkpoint (the contacts' springs among them).
fn checkpoint(world: &World) -> Vec<u8> {
    let mut out = Encoder::new();
    world.save(&mut out).unwrap();
    out.into_bytes()
}

/// What a rank holds after [`STEPS`] steps: its tetrahedra, spheres and candidates before
/// the whole gather, the partition's work per rank, the re-partitions, and the gathered
/// motion and touching contacts.
struct RankRun {
    tets: usize,
    spheres: usize,
    candidates: usize,
    work: Vec<f64>,
    repartitions: usize,
    motion: Vec<u64>,
    checkpoint: Vec<u8>,
    touching: usize,
}

#[test]
fn two_ranks_cut_the_stones_and_their_contacts_by_their_work_and_keep_one_processs_bits() {
    let mut alone = world();
    alone.initialize().unwrap();
    for _ in 0..STEPS {
        alone.step().unwrap();
    }
    let whole = alone.model::<DemContacts>().unwrap();
    let (spheres, candidates, touching) =
        (whole.own_spheres(), whole.candidates(), whole.contacts());
    eprintln!(
        "alone: {spheres} spheres, {candidates} candidates, {touching} touching, t = {}",
        alone.state.time
    );
    assert!(touching > 100, "the stones press on each other: {touching}");
    let runs = on_thread_ranks(2, |comm| {
        let mut world = world();
        world.decompose(comm).unwrap();
        world.initialize().unwrap();
        for step in 1..=STEPS {
            world.step().unwrap();
            if step == STEPS / 2 {
                // Decomposes again by the lists now: the bodies' blocks are cut anew.
                world.repartition();
            }
        }
        let figures = world.decomposition().unwrap().clone();
        let rank = world.rank();
        let contacts = world.model::<DemContacts>().unwrap();
        let (own, evaluated) = (contacts.own_spheres(), contacts.candidates());
        world.gather();
        RankRun {
            tets: figures.tets[rank],
            spheres: own,
            candidates: evaluated,
            work: figures.work,
            repartitions: world.repartitions(),
            motion: motion(&world.state),
            checkpoint: checkpoint(&world),
            touching: world.model::<DemContacts>().unwrap().contacts(),
        }
    });
    for (rank, run) in runs.iter().enumerate() {
        eprintln!(
            "rank {rank}: {} tets, {} spheres, {} candidates, work {:?}",
            run.tets, run.spheres, run.candidates, run.work
        );
        assert!(run.motion == motion(&alone.state), "rank {rank}: motion");
        assert!(
            run.checkpoint == checkpoint(&alone),
            "rank {rank}: checkpoint"
        );
        assert_eq!(run.touching, touching, "rank {rank}: touching contacts");
        assert!(run.repartitions >= 1, "re-partitioned");
        // Both ranks compute stones: each owns at least a fifth of the spheres and
        // evaluates at least a fifth of the candidates (a pair across the cut counts on
        // both ranks).
        assert!(
            5 * run.spheres >= spheres,
            "rank {rank}: {} spheres of {spheres}",
            run.spheres
        );
        assert!(
            5 * run.candidates >= candidates,
            "rank {rank}: {} candidates of {candidates}",
            run.candidates
        );
    }
    assert_eq!(
        runs[0].spheres + runs[1].spheres,
        spheres,
        "each sphere owned once"
    );
    // The cut falls between blocks of up to 256 tetrahedra: the ranks' work (in particle
    // steps) within 15% of their mean.
    let work = &runs[0].work;
    let mean = work.iter().sum::<f64>() / 2.0;
    assert!(
        work.iter().all(|w| (w - mean).abs() <= 0.15 * mean),
        "work per rank {work:?}"
    );
}

/// The sleeper's model (the first) weighed eight times its fixed share: its tetrahedra then
/// outweigh the stones with their contact spheres and candidates, which outweigh them at the
/// fixed shares (rank 0 then computes the sleeper and some stones).
const SLEEPER_WEIGHT: f64 = 8.0;

#[test]
fn weighed_by_measured_cost_every_rank_cuts_alike_and_keeps_one_processs_bits() {
    let mut alone = world();
    alone.initialize().unwrap();
    for _ in 0..STEPS {
        alone.step().unwrap();
    }
    let sleeper_tets = 1800;
    let runs = on_thread_ranks(2, |comm| {
        let mut world = world();
        world.decompose(comm).unwrap();
        world.initialize().unwrap();
        let mut measured = None;
        for step in 1..=STEPS {
            world.step().unwrap();
            if step == STEPS / 2 {
                measured = world.measured_weights();
                // Weights given, whatever was measured: the sleeper's tetrahedra eight times
                // their share.
                let mut weights = WorkWeights {
                    models: vec![1.0; world.models.len()],
                };
                weights.models[0] = SLEEPER_WEIGHT;
                world.repartition_weighted(weights);
            }
        }
        let figures = world.decomposition().unwrap().clone();
        let rank = world.rank();
        world.gather();
        (
            measured.expect("a run decomposed with a halo measures"),
            figures.tets[rank],
            figures.work,
            motion(&world.state),
            checkpoint(&world),
        )
    });
    let weights = &runs[0].0;
    eprintln!("measured weights {weights:?}");
    for (rank, (measured, tets, work, bits, saved)) in runs.iter().enumerate() {
        // The weights are computed from every rank's gathered timings in rank order: the
        // same bits on every rank, so every rank cuts alike.
        let same = measured.models.iter().zip(&weights.models);
        assert!(
            measured.models.len() == 4 && same.clone().all(|(a, b)| a.to_bits() == b.to_bits()),
            "rank {rank} measured {measured:?}, rank 0 {weights:?}"
        );
        assert!(
            measured.models.iter().all(|w| (0.1..=10.0).contains(w)),
            "rank {rank}: {measured:?}"
        );
        assert!(*bits == motion(&alone.state), "rank {rank}: motion");
        assert!(*saved == checkpoint(&alone), "rank {rank}: checkpoint");
        // The sleeper's tetrahedra at eight times their share outweigh the stones with their
        // contacts: rank 0 computes part of the sleeper only, rank 1 the rest and every
        // stone; the weighed work within 15% of the mean (blocks of up to 256 tets).
        if rank == 0 {
            assert!(*tets < sleeper_tets, "rank 0 computes {tets} tets");
        }
        let mean = work.iter().sum::<f64>() / 2.0;
        assert!(
            work.iter().all(|w| (w - mean).abs() <= 0.15 * mean),
            "rank {rank}: work per rank {work:?}"
        );
    }
}
