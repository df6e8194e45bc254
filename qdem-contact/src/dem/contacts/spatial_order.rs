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
//! checkpoint finds it again from the saved build positions (`persistence.rs`).
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
    use crate::{LinearSpring, PlaneWall, WallShape};

    const R: f64 = 0.005;
    /// Spheres per edge of the bed: 4,913 spheres, four runs of the pair kernel.
    const EDGE: usize = 17;
    /// Evaluations of a run, and the time between two.
    const EVALUATIONS: usize = 24;
    const DT: f64 = 5e-4;

    /// The centre and velocity of the sphere at lattice place `l` of the bed: a lattice of
    /// spacing 1.9 R (every neighbour 0.1 R deep), jittered, moving apart and sliding at up to
    /// 0.3 m/s (0.03 R per evaluation: the lists are rebuilt every few evaluations).
    fn place(l: usize) -> (Vec3, Vec3) {
        let (i, j, k) = (l / (EDGE * EDGE), (l / EDGE) % EDGE, l % EDGE);
        let wave = |a: usize, b: usize| ((a * 7 + b * 13 + l * 29) % 23) as f64 / 23.0 - 0.5;
        let x = Vec3::new(i as f64, j as f64, k as f64) * 1.9 * R
            + Vec3::new(wave(i, 1), wave(j, 2), wave(k, 3)) * 0.02 * R
            + Vec3::repeat(R);
        let v = Vec3::new(wave(j, 5), wave(k, 6), wave(i, 7)) * 0.6;
        (x, v)
    }

    /// The bed with sphere (and particle) `s` at lattice place `lattice[s]`, on a floor that
    /// the lowest layer presses into.
    fn bed(lattice: &[usize]) -> (State, DemContacts) {
        let (x, v): (Vec<Vec3>, Vec<Vec3>) = lattice.iter().map(|&l| place(l)).unzip();
        let mut state = State::at_rest(x);
        state.velocity = v;
        state.mass = vec![1e-3; lattice.len()];
        let spheres: Vec<ContactSphere> = (0..lattice.len())
            .map(|s| ContactSphere {
                particle: s,
                radius: R,
                body: s,
                material: 0,
            })
            .collect();
        let floor = Wall {
            shape: WallShape::Plane(PlaneWall::new(
                Vec3::new(0.0, 0.0, 0.1 * R),
                Vec3::z(),
                Vec3::zeros(),
            )),
            friction: 0.5,
        };
        let settings = ContactSettings {
            law: ContactLaw::Linear(LinearSpring {
                normal_stiffness: 1e4,
                tangential_stiffness: 1e4,
                damping_ratio: 0.2,
            }),
            friction: 0.5,
            skin: 0.2 * R,
        };
        let names = (0..lattice.len()).map(|s| s.to_string()).collect();
        let model = DemContacts::new(
            &state,
            &spheres,
            names,
            &[(1e9, 0.25)],
            settings,
            vec![floor],
        );
        (state, model)
    }

    /// Evaluations `evaluations` of the bed moving at its velocities from where `state` has
    /// it (at t = 0): per evaluation, the contact force on each particle.
    fn run(
        state: &mut State,
        model: &mut DemContacts,
        evaluations: std::ops::Range<usize>,
    ) -> Vec<Vec<Vec3>> {
        let start = state.position.clone();
        evaluations
            .map(|e| {
                state.time = e as f64 * DT;
                let time = state.time;
                for ((x, x0), v) in state.position.iter_mut().zip(&start).zip(&state.velocity) {
                    *x = x0 + time * v;
                }
                let mut force = vec![Vec3::zeros(); state.len()];
                model.add_forces(state, &mut force, &mut []);
                force
            })
            .collect()
    }

    /// Lattice places 0..n in a fixed pseudo-random order (a full-period LCG's).
    fn shuffled(n: usize) -> Vec<usize> {
        let mut order: Vec<(u64, usize)> = (0..n)
            .map(|l| {
                (
                    (l as u64)
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407)
                        >> 17,
                    l,
                )
            })
            .collect();
        order.sort_unstable();
        order.into_iter().map(|(_, l)| l).collect()
    }

    /// The forces of a run of the bed listed by `lattice`, by lattice place, and the mean
    /// distance in the engine's slots between the partners of a candidate pair at the end.
    fn forces_by_place(lattice: &[usize]) -> (Vec<Vec<Vec3>>, f64) {
        let (mut state, mut model) = bed(lattice);
        let forces = run(&mut state, &mut model, 0..EVALUATIONS);
        let by_place = forces
            .iter()
            .map(|force| {
                let mut at = vec![Vec3::zeros(); force.len()];
                for (s, &l) in lattice.iter().enumerate() {
                    at[l] = force[s];
                }
                at
            })
            .collect();
        (by_place, mean_span(&model))
    }

    /// The mean |b − a| over the candidate pairs (a, b) in the engine's slots.
    fn mean_span(model: &DemContacts) -> f64 {
        let pairs = &model.candidates.pairs().items;
        let total: u64 = pairs.iter().map(|c| (c.second - c.first) as u64).sum();
        total as f64 / pairs.len() as f64
    }

    #[test]
    fn a_bed_in_lattice_shuffled_reversed_or_sorted_order_gets_the_same_forces_and_the_same_locality(
    ) {
        let n = EDGE * EDGE * EDGE;
        let lattice: Vec<usize> = (0..n).collect();
        let reversed: Vec<usize> = (0..n).rev().collect();
        let places: Vec<Vec3> = (0..n).map(|l| place(l).0).collect();
        let sorted: Vec<usize> = spatial_order(&places, 2.2 * R)
            .into_iter()
            .map(|l| l as usize)
            .collect();
        let (reference, lattice_span) = forces_by_place(&lattice);
        let largest = reference
            .iter()
            .flatten()
            .map(|f| f.norm())
            .fold(0.0, f64::max);
        assert!(largest > 0.1, "the bed is loaded: {largest}");
        for order in [shuffled(n), reversed, sorted] {
            let (forces, span) = forces_by_place(&order);
            eprintln!("mean slot span of a pair: {span} (lattice {lattice_span})");
            // The same contacts, their forces summed in another order: each particle's force
            // (a sum of at most 19 terms) within 1e-12 of the largest, a few thousand ulps.
            for (a, b) in reference.iter().flatten().zip(forces.iter().flatten()) {
                assert!((a - b).norm() <= 1e-12 * largest, "{a:?} vs {b:?}");
            }
            // Neighbours sit as near in the engine's memory as those of the lattice: a
            // random order would put them n/3 ≈ 1,600 slots apart.
            assert!(
                span <= 1.1 * lattice_span,
                "{span} slots against {lattice_span}"
            );
        }
        assert!(lattice_span < 0.05 * n as f64, "{lattice_span}");
    }

    #[test]
    fn a_shuffled_bed_gives_the_same_bits_on_one_and_two_threads() {
        let order = shuffled(EDGE * EDGE * EDGE);
        let on = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| forces_by_place(&order).0)
        };
        let (one, two) = (on(1), on(2));
        let bits = |f: &Vec<Vec<Vec3>>| -> Vec<u64> {
            f.iter()
                .flatten()
                .flat_map(|v| v.iter().map(|x| x.to_bits()))
                .collect()
        };
        assert!(bits(&one) == bits(&two), "1 and 2 threads differ");
    }

    #[test]
    fn a_checkpoint_resumes_the_spatial_order_and_the_forces_bit_for_bit() {
        let order = shuffled(EDGE * EDGE * EDGE);
        let half = EVALUATIONS / 2;
        let (mut state, mut whole) = bed(&order);
        let uninterrupted = run(&mut state, &mut whole, 0..EVALUATIONS);
        let (mut state, mut first) = bed(&order);
        run(&mut state, &mut first, 0..half);
        assert!(!first.order.id.is_empty(), "the engine's order is its own");

        assert!(first.rebuilds() > 2, "{} builds", first.rebuilds());
        let mut out = Encoder::new();
        first.save(&mut out);
        // A new model of the same scene, its spheres in the builder's order until restored.
        let (mut state, mut resumed) = bed(&order);
        resumed.restore(&mut Decoder::new(out.bytes())).unwrap();
        assert_eq!(resumed.order.id, first.order.id);
        let rest = run(&mut state, &mut resumed, half..EVALUATIONS);
        for (a, b) in uninterrupted[half..]
            .iter()
            .flatten()
            .zip(rest.iter().flatten())
        {
            assert_eq!(a.map(f64::to_bits), b.map(f64::to_bits));
        }
        assert!(whole.rebuilds() > first.rebuilds());
        assert_eq!(whole.rebuilds(), resumed.rebuilds());
    }

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
