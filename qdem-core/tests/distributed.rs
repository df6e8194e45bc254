//! A run decomposed over ranks gives the bit-identical state of one process, for 2 and 3
//! ranks: here the ranks are threads of this process, passing messages through shared
//! memory ([`Communicator`] over a barrier), so the decomposition itself is tested without MPI.

mod common;

use qdem_core::{Communicator, Decomposition, Scheme, State, StepRequest, StepSettings, World};
use std::sync::{Arc, Barrier, Mutex};

/// The ranks' mailboxes: what each rank posted for each rank.
struct Hub {
    size: usize,
    barrier: Barrier,
    posts: Mutex<Vec<Vec<Vec<f64>>>>,
}

/// One rank of a [`Hub`].
struct ThreadRank {
    rank: usize,
    hub: Arc<Hub>,
}

impl ThreadRank {
    /// Posts `parts[q]` for every rank `q`, then returns what every rank posted for this one.
    fn post(&self, parts: Vec<Vec<f64>>) -> Vec<Vec<f64>> {
        self.hub.posts.lock().unwrap()[self.rank] = parts;
        self.hub.barrier.wait();
        let got = {
            let posts = self.hub.posts.lock().unwrap();
            posts.iter().map(|p| p[self.rank].clone()).collect()
        };
        self.hub.barrier.wait();
        got
    }
}

impl Communicator for ThreadRank {
    fn rank(&self) -> usize {
        self.rank
    }

    fn size(&self) -> usize {
        self.hub.size
    }

    fn all_to_all(
        &self,
        send: &[f64],
        send_counts: &[usize],
        recv: &mut [f64],
        recv_counts: &[usize],
    ) {
        let mut parts = Vec::new();
        let mut at = 0;
        for &n in send_counts {
            parts.push(send[at..at + n].to_vec());
            at += n;
        }
        let got = self.post(parts);
        let mut at = 0;
        for (part, &n) in got.iter().zip(recv_counts) {
            assert_eq!(part.len(), n, "rank {} expected {n} values", self.rank);
            recv[at..at + n].copy_from_slice(part);
            at += n;
        }
    }

    fn all_gather(&self, mine: &[f64], all: &mut [f64], counts: &[usize]) {
        let got = self.post(vec![mine.to_vec(); self.hub.size]);
        let flat = got.concat();
        assert_eq!(flat.len(), counts.iter().sum::<usize>());
        all.copy_from_slice(&flat);
    }

    fn min(&self, value: u64) -> u64 {
        let got = self.post(vec![vec![value as f64]; self.hub.size]);
        got.iter().map(|v| v[0] as u64).min().unwrap()
    }

    fn broadcast(&self, root: usize, bytes: &mut Vec<u8>) {
        let mine: Vec<f64> = bytes.iter().map(|&b| f64::from(b)).collect();
        let got = self.post(vec![mine; self.hub.size]);
        *bytes = got[root].iter().map(|&b| b as u8).collect();
    }
}

/// The viscoelastic cantilever of the determinism test as a world stepped by Verlet.
fn beam_world() -> World {
    let (state, models) = common::viscoelastic_beam();
    let request = StepRequest {
        scheme: Scheme::Verlet,
        dt: None,
        safety: 0.9,
        local_damping: 0.0,
        adaptive: false,
        event_solve: Default::default(),
        implicit_default: None,
        fit_to: None,
    };
    let settings = StepSettings::resolve(&request, &state, &models).unwrap();
    World::new(state, models, settings).unwrap()
}

const STEPS: usize = 300;

/// The state after [`STEPS`] steps of one process.
fn one_process() -> State {
    let mut world = beam_world();
    world.initialize().unwrap();
    for _ in 0..STEPS {
        world.step().unwrap();
    }
    world.state
}

/// Every rank's state after [`STEPS`] steps over `size` ranks, and the decomposition.
fn ranks(size: usize) -> (Vec<State>, Decomposition) {
    let hub = Arc::new(Hub {
        size,
        barrier: Barrier::new(size),
        posts: Mutex::new(vec![Vec::new(); size]),
    });
    let runs: Vec<_> = (0..size)
        .map(|rank| {
            let hub = hub.clone();
            std::thread::spawn(move || {
                let mut world = beam_world();
                let comm = Arc::new(ThreadRank { rank, hub });
                let figures = world.decompose(comm).unwrap();
                world.initialize().unwrap();
                for _ in 0..STEPS {
                    world.step().unwrap();
                }
                (world.state, figures)
            })
        })
        .collect();
    let mut states = Vec::new();
    let mut figures = None;
    for run in runs {
        let (state, f) = run.join().unwrap();
        states.push(state);
        figures.get_or_insert(f);
    }
    (states, figures.unwrap())
}

#[test]
fn two_and_three_ranks_hold_the_bit_identical_state_of_one_process() {
    let reference = one_process();
    assert!(reference.displacement(reference.len() - 1).norm() > 0.0);
    for size in [2, 3] {
        let (states, figures) = ranks(size);
        for (rank, state) in states.iter().enumerate() {
            assert!(
                common::motion_bits(state) == common::motion_bits(&reference),
                "rank {rank} of {size} differs from one process"
            );
        }
        let tets: usize = figures.tets.iter().sum();
        assert_eq!(tets, 60 * 6 * 6 * 6, "every tetrahedron is computed once");
        assert_eq!(figures.owned.iter().sum::<usize>(), reference.len());
        assert!(figures.tets.iter().all(|&t| t > 0), "{figures:?}");
        assert_eq!(figures.cut_bodies, 1);
    }
}
