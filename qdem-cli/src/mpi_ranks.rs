//! MPI (Open MPI through rsmpi) for `mpirun -np N qdem run SCENE`: the collectives a
//! decomposed run needs ([`qdem_core::parallel::Communicator`]) over `MPI_COMM_WORLD`. Built only with
//! `--features mpi`.

use mpi::collective::{CommunicatorCollectives, Root, SystemOperation};
use mpi::datatype::{Partition, PartitionMut};
use mpi::environment::Universe;
use mpi::topology::{Communicator as _, SimpleCommunicator};
use mpi::Threading;
use qdem_core::parallel::Communicator;

/// The processes of an `mpirun`, as a [`Communicator`].
///
/// ```no_run
/// use qdem_core::parallel::Communicator;
///
/// // Started by `mpirun -np 2`: two ranks; started alone: `None`.
/// if let Some((_universe, ranks)) = qdem_cli::mpi_ranks::start() {
///     println!("rank {} of {}", ranks.rank(), ranks.size());
/// }
/// ```
pub struct MpiRanks {
    world: SimpleCommunicator,
}

// SAFETY: MPI is initialised with `Threading::Serialized`, which allows calls from any thread
// as long as no two are made at once. A decomposed run makes its MPI calls only from the
// thread that steps its `World` (a model's forces, the share after a step, the stop
// agreement), one after the other; rayon's workers never touch the communicator.
unsafe impl Send for MpiRanks {}
unsafe impl Sync for MpiRanks {}

/// Starts MPI. `Some` when the process was started by `mpirun` with more than one rank: the
/// universe (MPI ends when it is dropped) and the ranks; `None` for a single process.
pub fn start() -> Option<(Universe, MpiRanks)> {
    let (universe, _) = mpi::initialize_with_threading(Threading::Serialized)?;
    let world = universe.world();
    if world.size() < 2 {
        return None;
    }
    Some((universe, MpiRanks { world }))
}

impl MpiRanks {
    /// Ends every rank's process at once (a rank that failed alone, on an output error).
    pub fn abort(&self, code: i32) -> ! {
        self.world.abort(code)
    }
}

/// MPI counts and displacements of a partition given as counts per rank.
fn partition(counts: &[usize]) -> (Vec<i32>, Vec<i32>) {
    let counts: Vec<i32> = counts.iter().map(|&c| c as i32).collect();
    let displs = counts
        .iter()
        .scan(0, |at, &c| {
            let here = *at;
            *at += c;
            Some(here)
        })
        .collect();
    (counts, displs)
}

impl Communicator for MpiRanks {
    fn rank(&self) -> usize {
        self.world.rank() as usize
    }

    fn size(&self) -> usize {
        self.world.size() as usize
    }

    fn all_to_all(
        &self,
        send: &[f64],
        send_counts: &[usize],
        recv: &mut [f64],
        recv_counts: &[usize],
    ) {
        let (sc, sd) = partition(send_counts);
        let (rc, rd) = partition(recv_counts);
        let send = Partition::new(send, &sc[..], &sd[..]);
        let mut recv = PartitionMut::new(recv, &rc[..], &rd[..]);
        self.world.all_to_all_varcount_into(&send, &mut recv);
    }

    fn all_gather(&self, mine: &[f64], all: &mut [f64], counts: &[usize]) {
        let (c, d) = partition(counts);
        let mut all = PartitionMut::new(all, &c[..], &d[..]);
        self.world.all_gather_varcount_into(mine, &mut all);
    }

    fn min(&self, value: u64) -> u64 {
        let mut least = 0u64;
        self.world
            .all_reduce_into(&value, &mut least, SystemOperation::min());
        least
    }

    fn broadcast(&self, root: usize, bytes: &mut Vec<u8>) {
        let root = self.world.process_at_rank(root as i32);
        let mut len = bytes.len() as u64;
        root.broadcast_into(&mut len);
        bytes.resize(len as usize, 0);
        root.broadcast_into(&mut bytes[..]);
    }
}
