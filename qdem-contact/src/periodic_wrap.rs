//! [`PeriodicWrap`]: the post-step hook of a periodic cell (paper 003 §2): after every step,
//! each body whose anchor has left the cell moves back into it whole, by whole periods
//! ([`PeriodicBox::wrap_bodies`]).
//!
//! In a run decomposed with a halo exchange ([`qdem_core::distributed`]) a rank holds only
//! its own particles' and its halo's positions, so the rank that owns a group's anchor
//! decides whether the group wraps, from the position one process would read; the ranks
//! share their decisions after every step and each moves every particle of a wrapping
//! group (position and reference) by the same period, so all ranks agree with one process.

use crate::periodic_boundary::{PeriodicBox, WrapGroup};
use qdem_core::{
    Communicator, Halt, Model, Ownership, ParticleReads, PostStep, SplitModel, State, Vec3,
};

/// Wraps groups of particles (whole bodies) back into a periodic cell after every step.
///
/// ```
/// use qdem_contact::{PeriodicBox, PeriodicWrap, WrapGroup};
/// use qdem_core::{PostStep, State, Vec3};
///
/// // A cell periodic in x over [0, 1): a two-particle body whose anchor left it at x = 1.2.
/// let cell = PeriodicBox::new(Vec3::zeros(), [Some(1.0), None, None]).unwrap();
/// let group = WrapGroup { anchor: 0, particles: vec![0, 1] };
/// let mut wrap = PeriodicWrap::new(cell, vec![group]);
/// let mut state = State::at_rest(vec![Vec3::new(1.2, 0.0, 0.0), Vec3::new(0.9, 0.0, 0.0)]);
/// wrap.after_step(&mut state, &[]);
/// assert!((state.position[0].x - 0.2).abs() < 1e-12);
/// assert!((state.position[1].x + 0.1).abs() < 1e-12, "the body moves whole");
/// ```
#[derive(Clone)]
pub struct PeriodicWrap {
    /// The cell.
    pub cell: PeriodicBox,
    /// The groups that wrap together.
    pub groups: Vec<WrapGroup>,
    /// Per particle, the rank that owns it, and the ranks, in a decomposed run.
    split: Option<Ownership>,
}

impl PeriodicWrap {
    /// Wraps `groups` back into `cell`.
    pub fn new(cell: PeriodicBox, groups: Vec<WrapGroup>) -> PeriodicWrap {
        PeriodicWrap {
            cell,
            groups,
            split: None,
        }
    }

    /// The groups whose anchor this rank owns (rank 0 for an anchor every rank computes)
    /// and that wrap, with their shifts, shared with every rank in rank order: group index,
    /// then the shift.
    fn shared_wraps(
        &self,
        state: &State,
        owner: &[u32],
        comm: &dyn Communicator,
    ) -> Vec<(usize, Vec3)> {
        let me = comm.rank() as u32;
        let decides = |p: usize| match owner[p] {
            u32::MAX => me == 0,
            r => r == me,
        };
        let mut mine = Vec::new();
        for (g, group) in self.groups.iter().enumerate() {
            if !decides(group.anchor) {
                continue;
            }
            let shift = self.cell.shift_into(&state.position[group.anchor]);
            if shift != Vec3::zeros() {
                mine.extend([g as f64, shift.x, shift.y, shift.z]);
            }
        }
        let mut all = Vec::new();
        comm.all_gather_varying(&mine, &mut all);
        all.chunks_exact(4)
            .map(|w| (w[0] as usize, Vec3::new(w[1], w[2], w[3])))
            .collect()
    }
}

impl std::fmt::Debug for PeriodicWrap {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PeriodicWrap")
            .field("cell", &self.cell)
            .field("groups", &self.groups)
            .field("split", &self.split.is_some())
            .finish()
    }
}

impl PostStep for PeriodicWrap {
    fn name(&self) -> &str {
        "periodic wrap"
    }

    fn after_step(&mut self, state: &mut State, _models: &[Box<dyn Model>]) -> Option<Halt> {
        let Some((owner, comm)) = &self.split else {
            self.cell.wrap_bodies(state, &self.groups);
            return None;
        };
        for (g, shift) in self.shared_wraps(state, owner, comm.as_ref()) {
            for &p in &self.groups[g].particles {
                state.position[p] += shift;
                state.reference[p] += shift;
            }
        }
        None
    }

    /// A rank reads only the anchors it owns once split.
    fn particle_reads(&self) -> ParticleReads {
        ParticleReads::Local
    }

    fn split_model(&mut self) -> Option<&mut dyn SplitModel> {
        Some(self)
    }
}

impl SplitModel for PeriodicWrap {
    /// None: the groups are bodies' particles, which other models place.
    fn free_particles(&self) -> Vec<usize> {
        Vec::new()
    }

    fn split(&mut self, split: Option<Ownership>) {
        self.split = split;
    }

    /// Nothing to gather: every rank moved every wrapping group.
    fn gather(&mut self) {}
}
