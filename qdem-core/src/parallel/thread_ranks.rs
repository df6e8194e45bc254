//! [`ThreadRank`]: the ranks of a decomposed run as threads of one process, passing messages
//! through shared memory, so that a decomposition can be tested (and embedded) without MPI.
//!
//! Every collective posts each rank's parts, waits at a barrier for all ranks, and copies
//! what was posted for it; values travel unchanged, so a run over thread ranks gives the
//! bits a run over MPI ranks gives.

use crate::parallel::communicator::Communicator;
use std::sync::{Arc, Barrier, Mutex};

/// The ranks' mailboxes: what each rank posted for each rank.
struct Hub {
    size: usize,
    barrier: Barrier,
    posts: Mutex<Vec<Vec<Vec<f64>>>>,
    words: Mutex<Vec<u64>>,
}

/// One rank of a set of thread ranks ([`on_thread_ranks`]).
pub struct ThreadRank {
    rank: usize,
    hub: Arc<Hub>,
}

/// `job`'s results on each of `size` thread ranks, in rank order; each thread gets its own
/// rank of one set.
///
/// ```
/// use qdem_core::parallel::thread_ranks::on_thread_ranks;
/// use qdem_core::parallel::Communicator;
///
/// let ranks = on_thread_ranks(3, |comm| {
///     let mut all = vec![0.0; 3];
///     comm.all_gather(&[comm.rank() as f64], &mut all, &[1, 1, 1]);
///     (all, comm.min(10 + comm.rank() as u64))
/// });
/// assert!(ranks.iter().all(|(all, min)| *all == [0.0, 1.0, 2.0] && *min == 10));
/// ```
pub fn on_thread_ranks<T: Send + 'static>(
    size: usize,
    job: impl Fn(Arc<ThreadRank>) -> T + Send + Sync + Clone + 'static,
) -> Vec<T> {
    let hub = Arc::new(Hub {
        size,
        barrier: Barrier::new(size),
        posts: Mutex::new(vec![Vec::new(); size]),
        words: Mutex::new(vec![0; size]),
    });
    let runs: Vec<_> = (0..size)
        .map(|rank| {
            let (hub, job) = (hub.clone(), job.clone());
            std::thread::spawn(move || job(Arc::new(ThreadRank { rank, hub })))
        })
        .collect();
    runs.into_iter()
        .map(|r| r.join().expect("a thread rank panicked"))
        .collect()
}

impl ThreadRank {
    /// Posts `parts[q]` for every rank `q`, then returns what every rank posted for this one.
    fn post(&self, parts: Vec<Vec<f64>>) -> Vec<Vec<f64>> {
        self.hub.posts.lock().expect("no rank panicked")[self.rank] = parts;
        self.hub.barrier.wait();
        let got = {
            let posts = self.hub.posts.lock().expect("no rank panicked");
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
        self.hub.words.lock().expect("no rank panicked")[self.rank] = value;
        self.hub.barrier.wait();
        let least = *self
            .hub
            .words
            .lock()
            .expect("no rank panicked")
            .iter()
            .min()
            .expect("one rank at least");
        self.hub.barrier.wait();
        least
    }

    fn broadcast(&self, root: usize, bytes: &mut Vec<u8>) {
        let mine: Vec<f64> = bytes.iter().map(|&b| f64::from(b)).collect();
        let got = self.post(vec![mine; self.hub.size]);
        *bytes = got[root].iter().map(|&b| b as u8).collect();
    }
}
