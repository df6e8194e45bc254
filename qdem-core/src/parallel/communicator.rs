//! [`Communicator`]: the collectives of a run decomposed over ranks. Only the seam
//! ([`crate::parallel`]) calls them: the [`crate::parallel::ParallelRuntime`] that a
//! [`crate::world::World`] owns runs them around the models' force evaluations, in the same order
//! on every rank; no model calls one.

/// What a decomposed run needs of its message passing: the collectives every rank calls in
/// the same order. `qdem` implements it over MPI (`--features mpi`); a test can implement it
/// over threads.
///
/// Counts are per rank, in rank order; buffers hold the ranks' parts one after the other.
///
/// ```
/// use qdem_core::{parallel::Communicator, continuum::Material, step::Model, step::Scheme, step::State, step::StepRequest, step::StepSettings,
///     continuum::TetBody, Vec3, world::World};
///
/// /// The communicator of a single process: every collective is a copy.
/// struct Alone;
///
/// impl Communicator for Alone {
///     fn rank(&self) -> usize { 0 }
///     fn size(&self) -> usize { 1 }
///     fn all_to_all(&self, send: &[f64], _: &[usize], recv: &mut [f64], _: &[usize]) {
///         recv.copy_from_slice(send);
///     }
///     fn all_gather(&self, mine: &[f64], all: &mut [f64], _: &[usize]) {
///         all.copy_from_slice(mine);
///     }
///     fn min(&self, value: u64) -> u64 { value }
///     fn broadcast(&self, _: usize, _: &mut Vec<u8>) {}
/// }
///
/// let nodes = vec![Vec3::zeros(), Vec3::x(), Vec3::y(), Vec3::z()];
/// let mut state = State::at_rest(nodes);
/// let body = TetBody::new("tet", &state.reference, vec![[0, 1, 2, 3]],
///     Material::elastic(1000.0, 1e6, 0.3)).unwrap();
/// body.lump_mass(&mut state.mass);
/// state.position[3].z += 0.01;
/// let models: Vec<Box<dyn Model>> = vec![Box::new(body)];
/// let request = StepRequest { scheme: Scheme::Verlet, dt: None, safety: 0.5,
///     local_damping: 0.0, adaptive: false, event_solve: Default::default(),
///     implicit_default: None, fit_to: None };
/// let settings = StepSettings::resolve(&request, &state, &models).unwrap();
/// let mut world = World::new(state, models, settings).unwrap();
/// let decomposition = world.decompose(std::sync::Arc::new(Alone)).unwrap();
/// assert_eq!(decomposition.tets, vec![1]);
/// assert_eq!(decomposition.owned, vec![4]);
/// world.initialize().unwrap();
/// world.step().unwrap();
/// assert!(world.state.velocity[3].z < 0.0, "the stretched vertex is pulled back");
/// ```
pub trait Communicator: Send + Sync {
    /// This process's rank, `0..size`.
    fn rank(&self) -> usize;

    /// The number of ranks.
    fn size(&self) -> usize;

    /// Sends `send` (`send_counts[q]` values to rank `q`, in rank order) and receives into
    /// `recv` (`recv_counts[q]` values from rank `q`, in rank order).
    fn all_to_all(
        &self,
        send: &[f64],
        send_counts: &[usize],
        recv: &mut [f64],
        recv_counts: &[usize],
    );

    /// Every rank's `mine` into `all`, in rank order (`counts[q]` values from rank `q`).
    fn all_gather(&self, mine: &[f64], all: &mut [f64], counts: &[usize]);

    /// The smallest of the ranks' `value`s, on every rank.
    fn min(&self, value: u64) -> u64;

    /// Rank `root`'s `bytes`, on every rank (resized to the root's length).
    fn broadcast(&self, root: usize, bytes: &mut Vec<u8>);

    /// Every rank's `value`, in rank order.
    fn all_gather_one(&self, value: f64) -> Vec<f64> {
        let ranks = self.size();
        let mut all = vec![0.0; ranks];
        self.all_gather(&[value], &mut all, &vec![1; ranks]);
        all
    }

    /// Every rank's `mine`, of lengths the ranks do not know beforehand, into `all` in rank
    /// order: two collectives, the lengths and then the values.
    fn all_gather_varying(&self, mine: &[f64], all: &mut Vec<f64>) {
        let counts: Vec<usize> = self
            .all_gather_one(mine.len() as f64)
            .iter()
            .map(|&n| n as usize)
            .collect();
        all.resize(counts.iter().sum(), 0.0);
        self.all_gather(mine, all, &counts);
    }
}

/// The largest of the ranks' `value`s (≥ 0, or infinite), on every rank: exact, since the
/// order of non-negative floats is that of their bits.
pub(crate) fn max_over_ranks(comm: &dyn Communicator, value: f64) -> f64 {
    f64::from_bits(!comm.min(!value.to_bits()))
}
