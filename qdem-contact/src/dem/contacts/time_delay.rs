//! The time-delayed boundary as a part of the contact model (paper 003 Eqs. 6–7): a model
//! of its own beside the force pass, which only reads its ghost scales. At each evaluation
//! the touching pairs through the boundary are reduced over the ranks (`stages.rs`); their
//! average force magnitude, F_Ave_current, is measured before the scaling and sets the ghost
//! scales the sums of that same evaluation apply.

use crate::boundaries::time_delayed_boundary::{GhostScales, TimeDelayedBoundary};
use crate::dem::contact_list::{Contact, ContactList};
use qdem_core::{checkpoint::CheckpointError, checkpoint::Decoder, checkpoint::Encoder, Vec3};

/// A time-delayed periodic boundary along one periodic axis, and its latest state.
pub(super) struct TimeDelay {
    axis: usize,
    boundary: TimeDelayedBoundary,
    scales: GhostScales,
    boundary_force: f64,
}

impl TimeDelay {
    /// The boundary `boundary` across periodic `axis`, its ghosts not scaled yet.
    pub(super) fn new(axis: usize, boundary: TimeDelayedBoundary) -> TimeDelay {
        TimeDelay {
            axis,
            boundary,
            scales: GhostScales::PERIODIC,
            boundary_force: 0.0,
        }
    }

    /// The delay axis and the current ghost scales, what the sums read.
    #[inline]
    pub(super) fn ghosts(&self) -> (usize, GhostScales) {
        (self.axis, self.scales)
    }

    /// The ghost scales (left, right) of the last evaluation and the average magnitude of
    /// the contact forces through the boundary it measured.
    pub(super) fn state(&self) -> (GhostScales, f64) {
        (self.scales, self.boundary_force)
    }

    /// Appends to `out`, one entry of six values each (kind 0, partners, force magnitude,
    /// two zeros), the touching pairs of `pairs` whose second sphere's image crosses the
    /// delay axis, in list order; `through`, where known, lists those pairs' indices
    /// (ascending), so that the others are not read.
    pub(super) fn reduction(
        &self,
        pairs: &ContactList,
        through: Option<&[u32]>,
        out: &mut Vec<f64>,
    ) {
        let records: Box<dyn Iterator<Item = (&Contact, Vec3)>> = match through {
            Some(through) => Box::new(
                through
                    .iter()
                    .map(|&k| (&pairs.items[k as usize], pairs.shift(k as usize))),
            ),
            None => Box::new(pairs.with_shifts()),
        };
        for (c, shift) in records {
            if c.force != Vec3::zeros() && shift[self.axis] != 0.0 {
                out.extend([
                    0.0,
                    c.first as f64,
                    c.second as f64,
                    c.force.norm(),
                    0.0,
                    0.0,
                ]);
            }
        }
    }

    /// Every rank's pairs through the boundary (partners, force magnitude), merged by
    /// partners (a pair two ranks hold taken once): their average force, and the ghost
    /// scales that follow at `time`.
    pub(super) fn reduced(&mut self, time: f64, mut pairs: Vec<(u32, u32, f64)>) {
        pairs.sort_by_key(|&(a, b, _)| (a, b));
        pairs.dedup_by_key(|&mut (a, b, _)| (a, b));
        let mut sum = 0.0;
        for &(_, _, f) in &pairs {
            sum += f;
        }
        let measured = match pairs.len() {
            0 => 0.0,
            n => sum / n as f64,
        };
        self.boundary_force = measured;
        self.scales = self.boundary.update(time, measured);
    }

    /// Saves the scales, the measured force and the boundary's history.
    pub(super) fn save(&self, out: &mut Encoder) {
        out.f64(self.scales.left);
        out.f64(self.scales.right);
        out.f64(self.boundary_force);
        self.boundary.save(out);
    }

    /// Restores what [`TimeDelay::save`] saved.
    pub(super) fn restore(&mut self, input: &mut Decoder<'_>) -> Result<(), CheckpointError> {
        self.scales = GhostScales {
            left: input.f64("the left ghost scale")?,
            right: input.f64("the right ghost scale")?,
        };
        self.boundary_force = input.f64("the boundary force")?;
        self.boundary.restore(input)
    }
}

/// Scales of the forces on the first and second sphere of a pair whose second sphere's image
/// was translated by `shift` along the delay axis: a negative shift means the second sphere
/// sits near the right boundary and its image beyond the left one, so the first sphere feels
/// a left ghost and the second (through the image of the first beyond the right boundary) a
/// right ghost; a positive shift is the mirror case; zero is an ordinary pair.
#[inline]
pub(super) fn pair_scales(shift: f64, scales: &GhostScales) -> (f64, f64) {
    if shift < 0.0 {
        (scales.left, scales.right)
    } else if shift > 0.0 {
        (scales.right, scales.left)
    } else {
        (1.0, 1.0)
    }
}
