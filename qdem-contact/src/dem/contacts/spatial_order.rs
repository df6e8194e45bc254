//! The spatial order of the contact spheres: at every build of the candidate lists the
//! engine renumbers its spheres by the cell their centre lies in, so that the pair kernel
//! (`pair_kernel.rs`) reads the narrow phase's records and writes the per-sphere sums of
//! neighbours that sit near each other in memory, whatever order the scene gave them in (a
//! poured bed lists its spheres in pour order, at random in space). LAMMPS does the same for
//! its atoms (`atom_modify sort`, every 1,000 steps by default).
//!
//! The key of a sphere is the Morton code (the bits of the three cell coordinates
//! interleaved) of its cell in a grid of the broad phase's cell side, 2 r_max + skin, from
//! the lowest corner of the centres' box; the spheres are sorted by (key, stable id), where
//! the stable id is the sphere's index as the builder gave it. The order is thus a function of
//! the centres at the build alone: one process and every rank of a decomposed run (which
//! holds every sphere's centre at a rebuild) find the same, and a run resumed from a
//! checkpoint finds it again from the saved build positions ([`DemContacts::restore`]).
//!
//! Inside the engine a sphere is its *slot*, its place in this order: the sphere records
//! (`spheres.rs`), the build positions and the candidate lists (`candidates.rs`), a rank's
//! ownership (`split.rs`) and the bodies' surfaces (`tunnelling.rs`) are renumbered
//! together, each pair kept with its lower slot first (a pair whose partners change places
//! keeps its spring as it acts on the new first sphere, −ξ). Everything outside keeps the
//! stable ids: the outputs' queries (`output_queries.rs`), the checkpoint
//! (`persistence.rs`) and the items a decomposed run exchanges (`split.rs`). The state's
//! particles keep their order: the engine reads their motion into its own records once per
//! evaluation and adds each sum to its particle once, while a pair's work reads and writes
//! records twice per candidate.

use super::*;

/// Bits of a cell coordinate in the key: three of them fill 63 bits.
const KEY_BITS: u32 = 21;

/// The engine's numbering of its spheres: the stable id of the sphere in each slot and the
/// slot of each stable id; both empty while they are the same.
#[derive(Clone, Debug, Default)]
pub(super) struct SphereOrder {
    /// Per slot, the stable id of the sphere there.
    id: Vec<u32>,
    /// Per stable id, the sphere's slot.
    slot: Vec<u32>,
}

impl SphereOrder {
    /// The order that puts stable id `id[s]` in slot `s`.
    fn new(id: Vec<u32>) -> SphereOrder {
        if id.iter().enumerate().all(|(s, &i)| s as u32 == i) {
            return SphereOrder::default();
        }
        let mut slot = vec![0; id.len()];
        for (s, &i) in id.iter().enumerate() {
            slot[i as usize] = s as u32;
        }
        SphereOrder { id, slot }
    }

    /// The stable id of the sphere in slot `s`.
    #[inline]
    pub(super) fn id(&self, s: u32) -> u32 {
        self.id.get(s as usize).copied().unwrap_or(s)
    }

    /// The slot of the sphere of stable id `id`.
    #[inline]
    pub(super) fn slot(&self, id: u32) -> u32 {
        self.slot.get(id as usize).copied().unwrap_or(id)
    }
}

/// The stable ids in spatial order: sorted by the Morton key of their centre's cell (side
/// `cell`, from the lowest corner of the centres' box), then by id. `center` is by stable id.
pub(super) fn spatial_order(center: &[Vec3], cell: f64) -> Vec<u32> {
    let finite = || center.iter().filter(|x| x.iter().all(|v| v.is_finite()));
    let low = finite().fold(Vec3::repeat(f64::INFINITY), |l, x| l.inf(x));
    let inverse = 1.0 / cell;
    let most = (1u64 << KEY_BITS) - 1;
    let mut keyed: Vec<(u64, u32)> = center
        .par_iter()
        .enumerate()
        .map(|(id, x)| {
            // A coordinate beyond the grid (or not finite) falls into its last (first) cell.
            let coordinate = |k: usize| (((x[k] - low[k]) * inverse) as u64).min(most);
            (
                morton(coordinate(0), coordinate(1), coordinate(2)),
                id as u32,
            )
        })
        .collect();
    // The (key, id) are distinct: any sort gives the same order.
    keyed.par_sort_unstable();
    keyed.into_iter().map(|(_, id)| id).collect()
}

/// The Morton code of cell (i, j, k): bit b of i at 3b, of j at 3b + 1, of k at 3b + 2.
fn morton(i: u64, j: u64, k: u64) -> u64 {
    spread(i) | (spread(j) << 1) | (spread(k) << 2)
}

/// The low 21 bits of `v`, bit b moved to bit 3b.
fn spread(v: u64) -> u64 {
    let mut v = v & 0x1f_ffff;
    v = (v | (v << 32)) & 0x001f_0000_0000_ffff;
    v = (v | (v << 16)) & 0x001f_0000_ff00_00ff;
    v = (v | (v << 8)) & 0x100f_00f0_0f00_f00f;
    v = (v | (v << 4)) & 0x10c3_0c30_c30c_30c3;
    (v | (v << 2)) & 0x1249_2492_4924_9249
}

impl DemContacts {
    /// Before a build of the lists, every centre current: the spheres renumbered in the
    /// spatial order of their centres.
    pub(super) fn sort_spheres(&mut self) {
        let center = self.spheres.center();
        let by_id: Vec<Vec3> = (0..center.len() as u32)
            .map(|id| center[self.order.slot(id) as usize])
            .collect();
        self.sort_spheres_at(&by_id);
    }

    /// The spheres renumbered in the spatial order of the centres `by_id` (by stable id), in
    /// cells of the broad phase's side, 2 r_max + skin.
    pub(super) fn sort_spheres_at(&mut self, by_id: &[Vec3]) {
        let cell =
            2.0 * self.spheres.radius().iter().cloned().fold(0.0, f64::max) + self.settings.skin;
        self.reorder(spatial_order(by_id, cell));
    }

    /// Every sphere's particle, by stable id.
    pub(super) fn stable_particles(&self) -> Vec<u32> {
        let particle = self.spheres.particle();
        (0..particle.len())
            .map(|id| particle[self.slot_of(id)])
            .collect()
    }

    /// Puts the sphere of stable id `id[s]` in slot `s`: the sphere records, the build
    /// positions, the candidate lists, a rank's ownership and the bodies' surfaces move
    /// together (the partners and the kernel's plan follow at the build, or by the caller).
    pub(super) fn reorder(&mut self, id: Vec<u32>) {
        let order = SphereOrder::new(id);
        let n = self.spheres.len() as u32;
        // The slot each sphere comes from, and the one it goes to.
        let from: Vec<u32> = (0..n).map(|s| self.order.slot(order.id(s))).collect();
        if from.iter().enumerate().all(|(s, &f)| s as u32 == f) {
            self.order = order;
            return;
        }
        let mut to = vec![0; from.len()];
        for (s, &f) in from.iter().enumerate() {
            to[f as usize] = s as u32;
        }
        self.spheres.permute(&from);
        self.candidates.renumber(&from, &to);
        self.passage.renumber(&to);
        if let Some(part) = &mut self.split {
            part.renumber(&from);
        }
        self.order = order;
    }

    /// The stable id of the sphere in slot `s`.
    #[inline]
    pub(super) fn id_of(&self, s: usize) -> usize {
        self.order.id(s as u32) as usize
    }

    /// The slot of the sphere of stable id `id`.
    #[inline]
    pub(super) fn slot_of(&self, id: usize) -> usize {
        self.order.slot(id as u32) as usize
    }
}

/// `values` permuted: slot `s` takes what was in slot `from[s]`.
pub(super) fn permuted<T: Copy>(values: &[T], from: &[u32]) -> Vec<T> {
    from.iter().map(|&f| values[f as usize]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_morton_code_interleaves_the_bits_of_the_three_coordinates() {
        assert_eq!(morton(1, 0, 0), 0b001);
        assert_eq!(morton(0, 1, 0), 0b010);
        assert_eq!(morton(0, 0, 1), 0b100);
        assert_eq!(morton(3, 0, 0), 0b001_001);
        let most = (1 << KEY_BITS) - 1;
        assert_eq!(morton(most, most, most), (1u64 << 63) - 1);
        assert_eq!(morton(1 << 20, 0, 0), 1 << 60);
    }

    #[test]
    fn the_order_follows_the_cells_then_the_ids_whatever_the_input_order() {
        // Eight spheres of a 2 × 2 × 2 block of unit cells, two per cell in the first, given
        // in reverse order: the first cell's two by id, then the Morton order of the cells.
        let mut center: Vec<Vec3> = (0..8)
            .map(|c| Vec3::new((c & 1) as f64, ((c >> 1) & 1) as f64, (c >> 2) as f64))
            .map(|x| x.add_scalar(0.5))
            .rev()
            .collect();
        center.push(Vec3::repeat(0.25));
        let order = spatial_order(&center, 1.0);
        assert_eq!(order, vec![7, 8, 6, 5, 4, 3, 2, 1, 0]);
    }
}
