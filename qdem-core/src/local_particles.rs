//! [`ParticleRuns`] and [`LocalParticles`]: the particles one rank of a decomposed run steps
//! itself, as sorted runs of indices cut into pieces for the threads.
//!
//! In a run decomposed with a halo exchange ([`crate::distributed`]) a rank integrates only
//! the particles whose force it sums (those it owns, and those every rank computes whole) and
//! predicts those plus the ones it receives each step (the halo: the other ranks' particles
//! that its tetrahedra touch). Every other particle keeps the value of the last whole
//! gather until the next one. The update of each particle is the same arithmetic as in a
//! whole pass (velocity Verlet, paper 000 §2.4), so the particles a rank steps agree bit for
//! bit with one process.

use crate::stepper::PARTICLE_CHUNK;
use std::ops::Range;

/// Particle indices as sorted, disjoint ranges, each at most [`PARTICLE_CHUNK`] long, so that
/// a parallel pass hands one range to a thread at a time.
///
/// ```
/// use qdem_core::local_particles::ParticleRuns;
///
/// let runs = ParticleRuns::from_mask(&[true, true, false, true]);
/// assert_eq!(runs.len(), 3);
/// assert_eq!(runs.pieces(), &[0..2, 3..4]);
/// assert!(runs.contains(3) && !runs.contains(2));
/// ```
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ParticleRuns {
    pieces: Vec<Range<usize>>,
    count: usize,
}

impl ParticleRuns {
    /// The particles `i` with `mask[i]`.
    pub fn from_mask(mask: &[bool]) -> ParticleRuns {
        let mut pieces: Vec<Range<usize>> = Vec::new();
        for (i, _) in mask.iter().enumerate().filter(|(_, &m)| m) {
            match pieces.last_mut() {
                Some(last) if last.end == i && last.len() < PARTICLE_CHUNK => last.end += 1,
                _ => pieces.push(i..i + 1),
            }
        }
        let count = pieces.iter().map(Range::len).sum();
        ParticleRuns { pieces, count }
    }

    /// The number of particles.
    pub fn len(&self) -> usize {
        self.count
    }

    /// Whether there is no particle.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// The ranges, ascending.
    pub fn pieces(&self) -> &[Range<usize>] {
        &self.pieces
    }

    /// Whether particle `i` is among them.
    pub fn contains(&self, i: usize) -> bool {
        let at = self.pieces.partition_point(|r| r.end <= i);
        self.pieces.get(at).is_some_and(|r| r.contains(&i))
    }

    /// Every particle index, ascending.
    pub fn indices(&self) -> impl Iterator<Item = usize> + '_ {
        self.pieces.iter().flat_map(Range::clone)
    }

    /// `slice`'s entries of each range, in order (for a parallel pass over them).
    pub(crate) fn split<'a, T>(&self, mut slice: &'a mut [T]) -> Vec<&'a mut [T]> {
        let mut out = Vec::with_capacity(self.pieces.len());
        let mut at = 0;
        for r in &self.pieces {
            let (_, rest) = std::mem::take(&mut slice).split_at_mut(r.start - at);
            let (piece, rest) = rest.split_at_mut(r.len());
            out.push(piece);
            slice = rest;
            at = r.end;
        }
        out
    }
}

/// What one rank of a decomposed run steps itself ([`crate::Stepper::restrict`]).
///
/// ```
/// use qdem_core::local_particles::{LocalParticles, ParticleRuns};
///
/// // Particles 0 and 1 are this rank's, particle 2 is its halo, particle 3 another rank's.
/// let local = LocalParticles {
///     computed: ParticleRuns::from_mask(&[true, true, false, false]),
///     stepped: ParticleRuns::from_mask(&[true, true, true, false]),
/// };
/// assert!(local.stepped.contains(2) && !local.computed.contains(2));
/// ```
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct LocalParticles {
    /// The particles whose force this rank sums and which it integrates: those it owns and
    /// those every rank computes whole.
    pub computed: ParticleRuns,
    /// The particles it predicts: `computed` and the halo whose motion it receives after
    /// each step.
    pub stepped: ParticleRuns,
}
