//! [`PeriodicWrap`]: the post-step hook of a periodic cell (paper 003 §2): after every step,
//! each body whose anchor has left the cell moves back into it whole, by whole periods
//! ([`PeriodicBox::wrap_bodies`]).
//!
//! In a run decomposed with a halo exchange ([`qdem_core::parallel`]) a rank holds only
//! its own particles' and its halo's positions, so the rank that owns a group's anchor
//! decides whether the group wraps, from the position one process would read
//! ([`Decisions::decide`]); the world's parallel runtime shares the decisions after every
//! step and each rank moves every particle of a wrapping group (position and reference) by
//! the same period ([`Decisions::act`]), so all ranks agree with one process.

use crate::boundaries::periodic_boundary::{PeriodicBox, WrapGroup};
use qdem_core::step::split::{Decisions, Facets, Ownership, Part, Reads};
use qdem_core::{step::Halt, step::Model, step::PostStep, step::State, Vec3};

/// Wraps groups of particles (whole bodies) back into a periodic cell after every step.
///
/// ```
/// use qdem_contact::{PeriodicBox, PeriodicWrap, WrapGroup};
/// use qdem_core::{step::PostStep, step::State, Vec3};
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
    /// Per particle, the rank that owns it, and this rank, in a decomposed run.
    split: Option<Part>,
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
        self.cell.wrap_bodies(state, &self.groups);
        None
    }

    /// A rank decides for the anchors it owns once split.
    fn reads(&mut self) -> Reads<'_> {
        Reads::Split(self)
    }
}

impl Ownership for PeriodicWrap {
    fn split(&mut self, part: Option<Part>) {
        self.split = part;
    }
}

/// A hook: it decides, and computes no forces.
impl Facets for PeriodicWrap {
    fn decisions(&mut self) -> Option<&mut dyn Decisions> {
        Some(self)
    }
}

impl Decisions for PeriodicWrap {
    /// The groups whose anchor this rank owns (rank 0 for an anchor every rank computes)
    /// and that wrap: group index, then the shift.
    fn decide(&self, state: &State, out: &mut Vec<f64>) {
        let Some(part) = &self.split else {
            return;
        };
        let decides = |p: usize| match part.owner[p] {
            u32::MAX => part.rank == 0,
            r => r == part.rank,
        };
        for (g, group) in self.groups.iter().enumerate() {
            if !decides(group.anchor) {
                continue;
            }
            let shift = self.cell.shift_into(&state.position[group.anchor]);
            if shift != Vec3::zeros() {
                out.extend([g as f64, shift.x, shift.y, shift.z]);
            }
        }
    }

    /// Moves every particle of each wrapping group, every rank's decisions in rank order.
    fn act(&mut self, state: &mut State, all: &[f64]) {
        for w in all.chunks_exact(4) {
            let shift = Vec3::new(w[1], w[2], w[3]);
            for &p in &self.groups[w[0] as usize].particles {
                state.position[p] += shift;
                state.reference[p] += shift;
            }
        }
    }
}
