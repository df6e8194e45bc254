//! [`ParticleRuns`] and [`LocalParticles`]: the particles one rank of a decomposed run steps
//! itself, as sorted runs of indices cut into pieces for the threads.
//!
//! In a run decomposed with a halo exchange ([`crate::parallel::decomposition`]) a rank integrates only
//! the particles whose force it sums (those it owns, and those every rank computes whole) and
//! predicts those plus the ones it receives each step (the halo: the other ranks' particles
//! that its tetrahedra touch). Every other particle keeps the value of the last whole
//! gather until the next one. The update of each particle is the same arithmetic as in a
//! whole pass (velocity Verlet, paper 000 §2.4), so the particles a rank steps agree bit for
//! bit with one process.

use crate::step::stepper::PARTICLE_CHUNK;
use std::ops::Range;

/// Particle indices as sorted, disjoint ranges, each at most 32,768 (`PARTICLE_CHUNK`) long, grouped
/// into batches of consecutive ranges of about that many particles, so that a parallel pass
/// hands a thread one batch at a time however short the ranges are (a rank's particles in a
/// mesh numbered across its cut come in runs of a few dozen).
///
/// ```
/// use qdem_core::step::local_particles::ParticleRuns;
///
/// let runs = ParticleRuns::from_mask(&[true, true, false, true]);
/// assert_eq!(runs.len(), 3);
/// assert_eq!(runs.pieces(), &[0..2, 3..4]);
/// assert!(runs.contains(3) && !runs.contains(2));
/// ```
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ParticleRuns {
    pieces: Vec<Range<usize>>,
    /// Each batch's places in `pieces`.
    batches: Vec<Range<usize>>,
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
        let (mut batches, mut start, mut size) = (Vec::new(), 0, 0);
        for (k, piece) in pieces.iter().enumerate() {
            size += piece.len();
            if size >= PARTICLE_CHUNK || k + 1 == pieces.len() {
                batches.push(start..k + 1);
                (start, size) = (k + 1, 0);
            }
        }
        let count = pieces.iter().map(Range::len).sum();
        ParticleRuns {
            pieces,
            batches,
            count,
        }
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

    /// The ranges of each batch, in order.
    pub(crate) fn batches(&self) -> Vec<&[Range<usize>]> {
        self.batches
            .iter()
            .map(|b| &self.pieces[b.clone()])
            .collect()
    }

    /// `slice`'s entries of each range, batch by batch (for a parallel pass over the
    /// batches, zipped with [`ParticleRuns::batches`]).
    pub(crate) fn split<'a, T>(&self, mut slice: &'a mut [T]) -> Vec<Vec<&'a mut [T]>> {
        let mut at = 0;
        let mut take = |r: &Range<usize>| {
            let (_, rest) = std::mem::take(&mut slice).split_at_mut(r.start - at);
            let (piece, rest) = rest.split_at_mut(r.len());
            slice = rest;
            at = r.end;
            piece
        };
        self.batches()
            .into_iter()
            .map(|batch| batch.iter().map(&mut take).collect())
            .collect()
    }
}

/// What one rank of a decomposed run steps itself
/// ([`crate::parallel::ParallelRuntime::stepped`]).
///
/// ```
/// use qdem_core::step::local_particles::{LocalParticles, ParticleRuns};
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn short_runs_are_batched_in_order_and_split_covers_each_particle_once() {
        // Every third particle of 10⁵: 33,334 runs of one particle.
        let n = 100_000;
        let mask: Vec<bool> = (0..n).map(|i| i % 3 == 0).collect();
        let runs = ParticleRuns::from_mask(&mask);
        let batches = runs.batches();
        assert_eq!(batches.len(), 2, "32,768 particles a batch, then the rest");
        assert_eq!(batches[0].len(), PARTICLE_CHUNK);
        let mut values: Vec<usize> = (0..n).collect();
        let mut seen = Vec::new();
        for (batch, ranges) in runs.split(&mut values).into_iter().zip(runs.batches()) {
            for (piece, r) in batch.into_iter().zip(ranges) {
                assert_eq!(piece.len(), r.len());
                seen.extend(piece.iter().copied());
            }
        }
        assert_eq!(seen, runs.indices().collect::<Vec<_>>());
        assert_eq!(seen.len(), runs.len());
        assert!(seen.iter().all(|&i| mask[i]));
        assert!(runs.contains(99_999) && !runs.contains(99_998));
    }
}
