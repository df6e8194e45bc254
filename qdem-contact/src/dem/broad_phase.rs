//! Broad phase: a uniform cell grid with a skin distance (a Verlet list).
//!
//! Spheres are binned into cubic cells of side 2 r_max + skin, keyed by their integer cell
//! coordinates and sorted by key; every occupied cell is then compared with itself and with the
//! neighbour cells of larger key (13 of the 26 on average), so each candidate pair is visited
//! once, in parallel over cells; a neighbour is found in a table over the grid's keys when the
//! grid is not much larger than the spheres, else by a binary search. A pair is kept when the gap between its surfaces is below the
//! skin and its spheres belong to different bodies. The list is sorted by (a, b), a < b, so it
//! does not depend on the number of threads. The contact model rebuilds it only when some
//! sphere has moved more than half the skin since the last build (then no pair outside the list
//! can have come into contact). Cost O(N log N) per build; there is no O(N²) path.
//!
//! Along a periodic axis ([`PeriodicBox`]) the grid spans exactly one period, cells are binned
//! by the wrapped coordinate, neighbour cells wrap around, and distances are minimum images, so
//! spheres near opposite boundaries pair through the boundary. A period of fewer than three
//! cells gets a single cell along that axis (every pair is then compared along it), so no cell
//! pair is ever visited twice.

use crate::boundaries::periodic_boundary::PeriodicBox;
use qdem_core::Vec3;
use rayon::prelude::*;

/// The spheres the broad phase sorts: centres, radii and owning bodies.
pub struct SphereSet<'a> {
    /// Centres (m).
    pub center: &'a [Vec3],
    /// Radii (m).
    pub radius: &'a [f64],
    /// Owning body of each sphere; spheres of one body never pair.
    pub body: &'a [u32],
    /// The periodic axes, if any.
    pub periodic: Option<&'a PeriodicBox>,
}

/// Integer cell coordinates of every sphere and the grid's key function.
struct Grid {
    origin: Vec3,
    inverse_cell: [f64; 3],
    dims: [u64; 3],
    period: [Option<f64>; 3],
}

/// The lower and upper corners of the axis-aligned box around `points` (infinite, inverted
/// corners for none).
pub fn bounds<'a>(points: impl IntoIterator<Item = &'a Vec3>) -> (Vec3, Vec3) {
    points.into_iter().fold(
        (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY)),
        |(lo, hi), x| (lo.inf(x), hi.sup(x)),
    )
}

impl Grid {
    fn new(center: &[Vec3], cell: f64, periodic: Option<&PeriodicBox>) -> Grid {
        let (mut lo, mut hi) = bounds(center);
        let period = [0, 1, 2].map(|k| periodic.and_then(|p| p.length(k)));
        for k in 0..3 {
            if let (Some(l), Some(p)) = (period[k], periodic) {
                lo[k] = p.origin()[k];
                hi[k] = lo[k] + l;
            }
        }
        // Spheres spread over a very large region get larger cells, so that keys fit in u64.
        let mut inverse_cell = 1.0 / cell;
        let cells = |inv: f64| [0, 1, 2].map(|k| ((hi[k] - lo[k]) * inv) as u64 + 1);
        while cells(inverse_cell)
            .iter()
            .map(|&d| d as f64)
            .product::<f64>()
            > 1e18
        {
            inverse_cell *= 0.5;
        }
        let mut dims = cells(inverse_cell);
        let mut inverse = [inverse_cell; 3];
        for k in 0..3 {
            if let Some(l) = period[k] {
                let whole = (l * inverse_cell).floor() as u64;
                dims[k] = if whole >= 3 { whole } else { 1 };
                inverse[k] = dims[k] as f64 / l;
            }
        }
        Grid {
            origin: lo,
            inverse_cell: inverse,
            dims,
            period,
        }
    }

    fn coords(&self, x: &Vec3) -> [u64; 3] {
        [0, 1, 2].map(|k| {
            let mut u = x[k] - self.origin[k];
            if let Some(l) = self.period[k] {
                u = u.rem_euclid(l);
            }
            ((u * self.inverse_cell[k]) as u64).min(self.dims[k] - 1)
        })
    }

    fn key(&self, c: [u64; 3]) -> u64 {
        c[0] + self.dims[0] * (c[1] + self.dims[1] * c[2])
    }

    /// The number of cells (and of keys).
    fn cells(&self) -> u64 {
        self.dims.iter().product()
    }
}

/// Finds an occupied cell by its key: in a table over every key of the grid when the grid
/// has not many more cells than spheres (each of a cell's 13 forward neighbours is then one
/// read, where a binary search of a ballast's 10⁵ occupied cells takes 17 dependent ones),
/// else by a binary search of the sorted keys. Either finds the same cell, so the pairs do
/// not depend on which.
enum CellLookup<'a> {
    /// Per key, the occupied cell's index, or `u32::MAX`.
    Table(Vec<u32>),
    /// The occupied cells' keys, ascending.
    Search(&'a [u64]),
}

impl<'a> CellLookup<'a> {
    /// The most cells per sphere (plus a fixed allowance) for which a table is made.
    const CELLS_PER_SPHERE: u64 = 4;
    const CELLS_ALLOWED: u64 = 1 << 20;

    /// The lookup of the occupied cells of keys `keys` (ascending) in a grid of `cells`
    /// cells holding `spheres` spheres.
    fn new(keys: &'a [u64], cells: u64, spheres: usize) -> CellLookup<'a> {
        if cells > Self::CELLS_PER_SPHERE * spheres as u64 + Self::CELLS_ALLOWED {
            return CellLookup::Search(keys);
        }
        let mut table = vec![u32::MAX; cells as usize];
        for (c, &key) in keys.iter().enumerate() {
            table[key as usize] = c as u32;
        }
        CellLookup::Table(table)
    }

    /// The index of the occupied cell of key `key`, if it is occupied.
    #[inline]
    fn find(&self, key: u64) -> Option<usize> {
        match self {
            CellLookup::Table(table) => match table[key as usize] {
                u32::MAX => None,
                c => Some(c as usize),
            },
            CellLookup::Search(keys) => keys.binary_search(&key).ok(),
        }
    }
}

/// All pairs (a, b), a < b, of spheres of different bodies whose surfaces are less than `skin`
/// apart, sorted.
pub fn find_pairs(spheres: &SphereSet, skin: f64) -> Vec<(u32, u32)> {
    let n = spheres.center.len();
    if n < 2 {
        return Vec::new();
    }
    let r_max = spheres.radius.iter().cloned().fold(0.0, f64::max);
    let grid = Grid::new(spheres.center, 2.0 * r_max + skin, spheres.periodic);
    let mut keyed: Vec<(u64, u32)> = spheres
        .center
        .par_iter()
        .enumerate()
        .map(|(i, x)| (grid.key(grid.coords(x)), i as u32))
        .collect();
    keyed.par_sort_unstable();
    let mut cell_start: Vec<usize> = (0..n)
        .filter(|&i| i == 0 || keyed[i].0 != keyed[i - 1].0)
        .collect();
    let cell_keys: Vec<u64> = cell_start.iter().map(|&s| keyed[s].0).collect();
    cell_start.push(n);
    let members = |c: usize| &keyed[cell_start[c]..cell_start[c + 1]];
    let lookup = CellLookup::new(&cell_keys, grid.cells(), n);
    let mut pairs: Vec<(u32, u32)> = (0..cell_keys.len())
        .into_par_iter()
        .with_min_len(64)
        .fold(Vec::new, |mut out, c| {
            let here = members(c);
            let first = spheres.center[here[0].1 as usize];
            let base = grid.coords(&first);
            for (k, &(_, i)) in here.iter().enumerate() {
                for &(_, j) in &here[k + 1..] {
                    push_if_near(spheres, skin, i, j, &mut out);
                }
            }
            for neighbour in forward_neighbours(&grid, base) {
                if let Some(d) = lookup.find(neighbour) {
                    for &(_, i) in here {
                        for &(_, j) in members(d) {
                            push_if_near(spheres, skin, i, j, &mut out);
                        }
                    }
                }
            }
            out
        })
        .reduce(Vec::new, |mut a, mut b| {
            a.append(&mut b);
            a
        });
    pairs.par_sort_unstable();
    pairs
}

/// Keys of the neighbour cells of `c` with a larger key than `c`'s own (wrapping around
/// periodic axes).
fn forward_neighbours(grid: &Grid, c: [u64; 3]) -> impl Iterator<Item = u64> + '_ {
    let own = grid.key(c);
    (0..27).filter_map(move |m| {
        let offset = [m % 3, (m / 3) % 3, m / 9].map(|o| o as i64 - 1);
        let mut cell = [0u64; 3];
        for k in 0..3 {
            let dims = grid.dims[k] as i64;
            let mut v = c[k] as i64 + offset[k];
            if grid.period[k].is_some() && dims >= 3 {
                v = v.rem_euclid(dims);
            }
            if v < 0 || v >= dims {
                return None;
            }
            cell[k] = v as u64;
        }
        let key = grid.key(cell);
        (key > own).then_some(key)
    })
}

#[inline]
fn push_if_near(spheres: &SphereSet, skin: f64, i: u32, j: u32, out: &mut Vec<(u32, u32)>) {
    let (iu, ju) = (i as usize, j as usize);
    if spheres.body[iu] == spheres.body[ju] {
        return;
    }
    let reach = spheres.radius[iu] + spheres.radius[ju] + skin;
    let mut d = spheres.center[ju] - spheres.center[iu];
    if let Some(p) = spheres.periodic {
        d = p.minimum_image(d);
    }
    if d.norm_squared() < reach * reach {
        out.push((i.min(j), i.max(j)));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn brute_force(spheres: &SphereSet, skin: f64) -> Vec<(u32, u32)> {
        let n = spheres.center.len() as u32;
        let mut out = Vec::new();
        for i in 0..n {
            for j in i + 1..n {
                push_if_near(spheres, skin, i, j, &mut out);
            }
        }
        out
    }

    #[test]
    fn the_table_and_the_search_find_the_same_cells() {
        let keys: Vec<u64> = (0..500u64)
            .map(|k| k * k % 7919)
            .collect::<std::collections::BTreeSet<_>>()
            .into_iter()
            .collect();
        let table = CellLookup::new(&keys, 7919, 100);
        let search = CellLookup::Search(&keys);
        assert!(matches!(table, CellLookup::Table(_)));
        for key in 0..7919 {
            assert_eq!(table.find(key), search.find(key), "key {key}");
        }
        assert!(matches!(
            CellLookup::new(&keys, 1 << 40, 100),
            CellLookup::Search(_)
        ));
    }

    #[test]
    fn a_sparse_grid_searches_and_finds_the_brute_force_pairs() {
        // Clusters 100 km apart: far more cells than spheres, so no table.
        let mut center = Vec::new();
        for k in 0..3 {
            for i in 0..20 {
                let t = i as f64;
                center.push(Vec3::new(
                    1e5 * k as f64 + 0.01 * t,
                    0.013 * (t * 0.7).sin(),
                    0.0,
                ));
            }
        }
        let radius = vec![0.006; center.len()];
        let body: Vec<u32> = (0..center.len() as u32).map(|i| i / 3).collect();
        let set = SphereSet {
            center: &center,
            radius: &radius,
            body: &body,
            periodic: None,
        };
        let grid = Grid::new(&center, 0.013, None);
        assert!(grid.cells() > 4 * 60 + (1 << 20));
        let pairs = find_pairs(&set, 0.001);
        assert!(!pairs.is_empty());
        assert_eq!(pairs, brute_force(&set, 0.001));
    }

    proptest! {
        #[test]
        fn the_grid_finds_exactly_the_brute_force_pairs(
            points in proptest::collection::vec((0.0..1.0f64, 0.0..1.0f64, 0.0..0.3f64, 0.01..0.08f64, 0u32..40), 2..300),
            skin in 0.0..0.05f64,
        ) {
            let center: Vec<Vec3> = points.iter().map(|p| Vec3::new(p.0, p.1, p.2)).collect();
            let radius: Vec<f64> = points.iter().map(|p| p.3).collect();
            let body: Vec<u32> = points.iter().map(|p| p.4).collect();
            let set = SphereSet { center: &center, radius: &radius, body: &body, periodic: None };
            prop_assert_eq!(find_pairs(&set, skin), brute_force(&set, skin));
        }

        #[test]
        fn the_periodic_grid_finds_exactly_the_brute_force_minimum_image_pairs(
            points in proptest::collection::vec((-0.2..1.3f64, 0.0..1.0f64, 0.0..0.3f64, 0.01..0.05f64, 0u32..40), 2..300),
            skin in 0.0..0.05f64,
            period in 0.25..1.0f64,
            periodic_y in proptest::bool::ANY,
        ) {
            // Spheres partly outside the cell [0, period) along x (as bodies that have not
            // wrapped yet are); periods from below three cells (one column) to many.
            let center: Vec<Vec3> = points.iter().map(|p| Vec3::new(p.0, p.1, p.2)).collect();
            let radius: Vec<f64> = points.iter().map(|p| p.3).collect();
            let body: Vec<u32> = points.iter().map(|p| p.4).collect();
            let y = periodic_y.then_some(1.0);
            let periodic = PeriodicBox::new(Vec3::zeros(), [Some(period), y, None]).unwrap();
            let set = SphereSet { center: &center, radius: &radius, body: &body, periodic: Some(&periodic) };
            prop_assert_eq!(find_pairs(&set, skin), brute_force(&set, skin));
        }
    }
}
