//! The blocked, deterministic scatter of the tetrahedron forces onto the particles
//! (paper 000 Eq. 11: each particle's force is the sum over the subdomains that belong to it).
//!
//! The tetrahedra of a body are cut into blocks of at most [`MAX_BLOCK`] tetrahedra, compact
//! in space (recursive coordinate bisection of the reference centroids). A block lists the
//! particles its tetrahedra touch (its *nodes*, ascending) and gives each tetrahedron's four
//! corners as indices into that list, so a block can copy its nodes' positions into a small
//! array, compute its tetrahedra against that array and add their forces into a block-local
//! accumulator that stays in cache. The accumulated sums go to a per-(block, node) buffer laid
//! out like the node lists; a particle's force is then the sum of its entries in that buffer,
//! in ascending block order.
//!
//! Every particle therefore sums its contributions in one fixed order (tetrahedra within a
//! block in ascending order, then the blocks in ascending order), whatever the number of
//! threads: the blocks are fixed by the mesh alone. No atomics and no per-tetrahedron force
//! buffer: what crosses memory per tetrahedron is its reference data and local corners, and
//! per node of a block one position in, one sum out and back.

use crate::continuum::tet_lanes::{self, TetPack, PACK};
use crate::{Mat3, Vec3};

/// The most tetrahedra in one block: its nodes (at most four per tetrahedron) must be
/// addressable by a `u16`, and its position and force arrays (about 60 B per node) should stay
/// in a core's L2 cache.
pub const MAX_BLOCK: usize = 8192;
/// The fewest blocks a body is cut into when it has enough tetrahedra, so that small bodies
/// still spread over the threads.
const MIN_BLOCKS: usize = 16;
/// The smallest block worth a task of its own.
const MIN_BLOCK: usize = 256;

/// How a body's tetrahedra are cut into blocks, for a model of the memory traffic of a step.
///
/// ```
/// use qdem_core::{continuum::Material, continuum::TetBody, Vec3};
///
/// let nodes = vec![Vec3::zeros(), Vec3::x(), Vec3::y(), Vec3::z()];
/// let body = TetBody::new("tet", &nodes, vec![[0, 1, 2, 3]], Material::elastic(1.0, 1.0, 0.25))?;
/// let layout = body.block_layout();
/// assert_eq!((layout.blocks, layout.block_nodes), (1, 4));
/// # Ok::<(), qdem_core::error::CoreError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BlockLayout {
    /// Number of blocks.
    pub blocks: usize,
    /// Sum over the blocks of the particles each touches: the entries of the block sums, at
    /// least the body's particle count (each particle shared by k blocks counts k times).
    pub block_nodes: usize,
}

/// One tetrahedron as the hot loop reads it: the inverse reference edge matrix and the four
/// corners as indices into its block's nodes.
#[derive(Clone, Debug)]
pub(crate) struct HotTet {
    pub dm_inv: Mat3,
    pub local: [u16; 4],
}

/// The blocks of a body: which tetrahedra, in what order, touching which particles.
#[derive(Clone, Debug)]
pub(crate) struct TetBlocks {
    /// Per block, the range of its tetrahedra in `hot` and `order` (`tet_start[b]..[b+1]`).
    pub tet_start: Vec<u32>,
    /// The tetrahedra in block order.
    pub hot: Vec<HotTet>,
    /// The tetrahedra of each block in packs for the lane kernel
    /// ([`crate::continuum::tet_lanes`]): block `b`'s are `pack_start[b]..[b+1]`.
    pub packs: Vec<TetPack>,
    /// Per block, the range of its packs in `packs`.
    pub pack_start: Vec<u32>,
    /// The body's index of each tetrahedron in block order.
    pub order: Vec<u32>,
    /// The block order's index of each tetrahedron of the body (the inverse of `order`).
    pub rank: Vec<u32>,
    /// Per block, the range of its nodes in `nodes` (`node_start[b]..[b+1]`).
    pub node_start: Vec<u32>,
    /// The particles of every block, ascending within a block, blocks one after the other.
    pub nodes: Vec<u32>,
    /// The first particle any tetrahedron uses.
    pub first: usize,
    /// Per particle from `first`, the range of its entries in `entries`.
    pub entry_start: Vec<u32>,
    /// Indices into `nodes` (and the sums laid out like it) of each particle's block entries,
    /// in ascending block order.
    pub entries: Vec<u32>,
}

impl TetBlocks {
    /// Cuts `tets` (with the inverse reference edge matrices `dm_inv`) into blocks, by their
    /// centroids in `reference`.
    pub fn new(reference: &[Vec3], tets: &[[u32; 4]], dm_inv: &[Mat3]) -> TetBlocks {
        let (order, tet_start) = cut(reference, tets);
        let mut rank = vec![0u32; tets.len()];
        for (k, &e) in order.iter().enumerate() {
            rank[e as usize] = k as u32;
        }
        let (node_start, nodes, hot) = block_nodes(tets, dm_inv, &order, &tet_start);
        let (first, entry_start, entries) = entry_lists(&nodes);
        // Sized once, so that the whole array is allocated (and advised huge pages) before
        // it is written, instead of growing by doublings whose older parts keep small pages.
        let total = tet_start
            .windows(2)
            .map(|r| (r[1] - r[0]).div_ceil(PACK as u32));
        let mut packs = Vec::with_capacity(total.sum::<u32>() as usize);
        let mut pack_start = vec![0u32];
        for range in tet_start.windows(2) {
            packs.extend(tet_lanes::packs(&hot[range[0] as usize..range[1] as usize]));
            pack_start.push(packs.len() as u32);
        }
        TetBlocks {
            tet_start,
            hot,
            packs,
            pack_start,
            order,
            rank,
            node_start,
            nodes,
            first,
            entry_start,
            entries,
        }
    }

    /// Number of blocks.
    pub fn len(&self) -> usize {
        self.tet_start.len() - 1
    }

    /// The number of blocks and of block nodes.
    pub fn layout(&self) -> BlockLayout {
        BlockLayout {
            blocks: self.len(),
            block_nodes: self.nodes.len(),
        }
    }

    /// The inverse reference edge matrix of the body's tetrahedron `e`.
    pub fn dm_inv(&self, e: usize) -> &Mat3 {
        &self.hot[self.rank[e] as usize].dm_inv
    }
}

/// The renumbering of the particles that puts each block's nodes together, in the order the
/// blocks read them: `new_of_old[i]` is particle `i`'s new index. The blocks are the ones
/// [`TetBlocks::new`] cuts (they depend on the reference centroids and the tetrahedron order
/// alone, so a body built on the renumbered particles has the same blocks); walking the blocks
/// in order and each block's tetrahedra in order, a particle gets the next index the first
/// time a corner names it. A particle interior to a block is then numbered with that block's
/// other particles, in the order of its first use, and a particle shared by several blocks
/// with the first of them; particles no tetrahedron names keep their relative order after all
/// others.
///
/// Each particle's force sums the same terms in the same order either way (tetrahedra within a
/// block in ascending order, then the blocks in ascending order), so a body on the renumbered
/// particles computes the same forces bit for bit, permuted.
///
/// ```
/// use qdem_core::{continuum::tet_blocks::block_node_order, Vec3};
///
/// let nodes = vec![Vec3::z(), Vec3::zeros(), Vec3::x(), Vec3::y(), Vec3::new(5.0, 5.0, 5.0)];
/// // One tetrahedron naming particles 1, 2, 3, 0; particle 4 is used by none.
/// assert_eq!(block_node_order(&nodes, &[[1, 2, 3, 0]]), vec![3, 0, 1, 2, 4]);
/// ```
pub fn block_node_order(reference: &[Vec3], tets: &[[u32; 4]]) -> Vec<u32> {
    let (order, _) = cut(reference, tets);
    let mut new_of_old = vec![u32::MAX; reference.len()];
    let mut next = 0u32;
    let corners = order.iter().flat_map(|&e| tets[e as usize]);
    let unused = 0..reference.len() as u32;
    for n in corners.chain(unused) {
        let slot = &mut new_of_old[n as usize];
        if *slot == u32::MAX {
            *slot = next;
            next += 1;
        }
    }
    new_of_old
}

/// The blocks of `tets`: the tetrahedra in block order, ascending within each block, and
/// each block's start in that order (with the end appended).
fn cut(reference: &[Vec3], tets: &[[u32; 4]]) -> (Vec<u32>, Vec<u32>) {
    let size = block_size(tets.len());
    let centroid: Vec<Vec3> = tets
        .iter()
        .map(|t| t.iter().map(|&n| reference[n as usize]).sum::<Vec3>() / 4.0)
        .collect();
    let mut order: Vec<u32> = (0..tets.len() as u32).collect();
    let mut tet_start = vec![0u32];
    bisect(&mut order, &centroid, size, &mut tet_start);
    for b in 0..tet_start.len() - 1 {
        order[tet_start[b] as usize..tet_start[b + 1] as usize].sort_unstable();
    }
    (order, tet_start)
}

/// Tetrahedra per block for a body of `tets`: at most [`MAX_BLOCK`], and small enough for
/// [`MIN_BLOCKS`] blocks, but not below [`MIN_BLOCK`].
fn block_size(tets: usize) -> usize {
    tets.div_ceil(MIN_BLOCKS).clamp(MIN_BLOCK, MAX_BLOCK)
}

/// Recursive coordinate bisection: splits `ids` at the median of the centroids along their
/// widest axis until each part has at most `size` tetrahedra, appending each part's end to
/// `starts` in order. Ties are broken by index, so the cut depends on the mesh alone.
fn bisect(ids: &mut [u32], centroid: &[Vec3], size: usize, starts: &mut Vec<u32>) {
    if ids.len() <= size {
        let end = starts.last().copied().unwrap_or(0) + ids.len() as u32;
        starts.push(end);
        return;
    }
    let axis = widest_axis(ids, centroid);
    let key = |&e: &u32| (centroid[e as usize][axis], e);
    let mid = ids.len() / 2;
    ids.select_nth_unstable_by(mid, |a, b| {
        let (ka, kb) = (key(a), key(b));
        ka.0.total_cmp(&kb.0).then(ka.1.cmp(&kb.1))
    });
    let (left, right) = ids.split_at_mut(mid);
    bisect(left, centroid, size, starts);
    bisect(right, centroid, size, starts);
}

/// The axis along which the centroids of `ids` spread the most.
fn widest_axis(ids: &[u32], centroid: &[Vec3]) -> usize {
    let mut lo = Vec3::repeat(f64::INFINITY);
    let mut hi = Vec3::repeat(f64::NEG_INFINITY);
    for &e in ids {
        lo = lo.inf(&centroid[e as usize]);
        hi = hi.sup(&centroid[e as usize]);
    }
    (hi - lo).imax()
}

/// Each block's sorted node list and its tetrahedra's local corners.
fn block_nodes(
    tets: &[[u32; 4]],
    dm_inv: &[Mat3],
    order: &[u32],
    tet_start: &[u32],
) -> (Vec<u32>, Vec<u32>, Vec<HotTet>) {
    let mut node_start = vec![0u32];
    let mut nodes = Vec::new();
    let mut hot = Vec::with_capacity(order.len());
    for range in tet_start.windows(2) {
        let block = &order[range[0] as usize..range[1] as usize];
        let mut own: Vec<u32> = block.iter().flat_map(|&e| tets[e as usize]).collect();
        own.sort_unstable();
        own.dedup();
        for &e in block {
            let local = tets[e as usize].map(|n| own.binary_search(&n).expect("own node") as u16);
            hot.push(HotTet {
                dm_inv: dm_inv[e as usize],
                local,
            });
        }
        nodes.extend_from_slice(&own);
        node_start.push(nodes.len() as u32);
    }
    (node_start, nodes, hot)
}

/// Per particle (from the smallest used), its entries in the block node lists, in ascending
/// block order (the order in which the lists are laid out).
fn entry_lists(nodes: &[u32]) -> (usize, Vec<u32>, Vec<u32>) {
    let first = nodes.iter().min().copied().unwrap_or(0) as usize;
    let last = nodes.iter().max().copied().unwrap_or(0) as usize;
    let mut start = vec![0u32; last - first + 2];
    for &n in nodes {
        start[n as usize - first + 1] += 1;
    }
    for i in 1..start.len() {
        start[i] += start[i - 1];
    }
    let mut fill = start.clone();
    let mut entries = vec![0u32; nodes.len()];
    for (k, &n) in nodes.iter().enumerate() {
        let slot = &mut fill[n as usize - first];
        entries[*slot as usize] = k as u32;
        *slot += 1;
    }
    (first, start, entries)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A row of `n` unit cubes along x, each cut into 6 tetrahedra (Kuhn), with its nodes.
    fn bar(n: usize) -> (Vec<Vec3>, Vec<[u32; 4]>) {
        let node = |i: usize, j: usize, k: usize| (4 * i + 2 * j + k) as u32;
        let mut x = Vec::new();
        for i in 0..=n {
            for j in 0..2 {
                for k in 0..2 {
                    x.push(Vec3::new(i as f64, j as f64, k as f64));
                }
            }
        }
        let mut tets = Vec::new();
        for i in 0..n {
            let c = |d: [usize; 3]| node(i + d[0], d[1], d[2]);
            let paths = [
                [[1, 0, 0], [1, 1, 0]],
                [[1, 0, 0], [1, 0, 1]],
                [[0, 1, 0], [1, 1, 0]],
                [[0, 1, 0], [0, 1, 1]],
                [[0, 0, 1], [1, 0, 1]],
                [[0, 0, 1], [0, 1, 1]],
            ];
            for p in paths {
                tets.push([c([0, 0, 0]), c(p[0]), c(p[1]), c([1, 1, 1])]);
            }
        }
        (x, tets)
    }

    #[test]
    fn every_tetrahedron_lands_in_one_block_and_every_corner_maps_back() {
        let (x, tets) = bar(2000);
        let dm_inv = vec![Mat3::identity(); tets.len()];
        let blocks = TetBlocks::new(&x, &tets, &dm_inv);
        assert!(blocks.len() >= MIN_BLOCKS);
        let mut seen = vec![false; tets.len()];
        for b in 0..blocks.len() {
            let nodes =
                &blocks.nodes[blocks.node_start[b] as usize..blocks.node_start[b + 1] as usize];
            assert!(nodes.windows(2).all(|w| w[0] < w[1]), "nodes ascending");
            for k in blocks.tet_start[b] as usize..blocks.tet_start[b + 1] as usize {
                let e = blocks.order[k] as usize;
                assert!(!seen[e]);
                seen[e] = true;
                assert_eq!(blocks.rank[e] as usize, k);
                assert_eq!(blocks.hot[k].local.map(|l| nodes[l as usize]), tets[e]);
            }
        }
        assert!(seen.iter().all(|&s| s));
    }

    /// `tets` with node `i` renamed `new_of_old[i]`, and the nodes moved with them.
    fn renumbered(x: &[Vec3], tets: &[[u32; 4]], new_of_old: &[u32]) -> (Vec<Vec3>, Vec<[u32; 4]>) {
        let mut moved = vec![Vec3::zeros(); x.len()];
        for (old, &new) in new_of_old.iter().enumerate() {
            moved[new as usize] = x[old];
        }
        let tets = tets
            .iter()
            .map(|t| t.map(|n| new_of_old[n as usize]))
            .collect();
        (moved, tets)
    }

    #[test]
    fn block_numbering_gives_each_block_its_new_nodes_as_one_run_in_first_use_order() {
        // The bar's nodes scattered first (i -> 7919 i mod n, a permutation as 7919 is prime
        // and does not divide n), so that the order below is the numbering's doing.
        let (x, tets) = bar(3000);
        let n = x.len() as u64;
        let scatter: Vec<u32> = (0..n).map(|i| (i * 7919 % n) as u32).collect();
        let (x, tets) = renumbered(&x, &tets, &scatter);
        let dm_inv = vec![Mat3::identity(); tets.len()];
        let before = TetBlocks::new(&x, &tets, &dm_inv);
        let new_of_old = block_node_order(&x, &tets);
        let (x, tets) = renumbered(&x, &tets, &new_of_old);
        let after = TetBlocks::new(&x, &tets, &dm_inv);
        // The same blocks, the same tetrahedra in the same order.
        assert_eq!(
            (&after.tet_start, &after.order),
            (&before.tet_start, &before.order)
        );
        let mut next = 0u32;
        for b in 0..after.len() {
            let range = after.tet_start[b] as usize..after.tet_start[b + 1] as usize;
            let mut first_use = Vec::new();
            for &e in &after.order[range] {
                for n in tets[e as usize] {
                    if n >= next && !first_use.contains(&n) {
                        first_use.push(n);
                    }
                }
            }
            // The particles no earlier block read are next, next + 1, ... in first-use order.
            let run: Vec<u32> = (next..next + first_use.len() as u32).collect();
            assert_eq!(first_use, run, "block {b}");
            next += run.len() as u32;
        }
        assert_eq!(next as usize, x.len());
    }

    #[test]
    fn the_packs_are_allocated_once_at_their_final_size() {
        // Every block's tetrahedra in packs of PACK, the last padded; the array sized once
        // (a grown one would have room to spare, and its older parts no huge pages). 4,230
        // tetrahedra cut into blocks of 264 and 265, 33 and 34 packs: no doubling ends there.
        let (x, tets) = bar(705);
        let blocks = TetBlocks::new(&x, &tets, &vec![Mat3::identity(); tets.len()]);
        for b in 0..blocks.len() {
            let count = (blocks.tet_start[b + 1] - blocks.tet_start[b]) as usize;
            let packs = (blocks.pack_start[b + 1] - blocks.pack_start[b]) as usize;
            assert_eq!(packs, count.div_ceil(PACK), "block {b}");
        }
        assert_eq!(
            blocks.packs.len(),
            *blocks.pack_start.last().unwrap() as usize
        );
        assert_eq!(blocks.packs.capacity(), blocks.packs.len());
    }

    #[test]
    fn each_particle_lists_its_block_entries_in_block_order() {
        let (x, tets) = bar(700);
        let blocks = TetBlocks::new(&x, &tets, &vec![Mat3::identity(); tets.len()]);
        for i in 0..x.len() {
            let range = blocks.entry_start[i] as usize..blocks.entry_start[i + 1] as usize;
            let entries = &blocks.entries[range];
            assert!(!entries.is_empty() && entries.windows(2).all(|w| w[0] < w[1]));
            assert!(entries
                .iter()
                .all(|&k| blocks.nodes[k as usize] as usize == i));
        }
        // A bar cut across its length: interior nodes belong to one block, each cut plane's
        // nodes to two, so the entries exceed the particles by a few cut planes.
        let extra = blocks.entries.len() - x.len();
        assert!(extra <= 4 * 2 * (blocks.len() - 1), "{extra}");
    }
}
