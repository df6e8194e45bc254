//! Structured generators for tests and benchmarks.

use crate::{FileIds, PhysicalGroup, TetMesh};

/// The six Kuhn (Freudenthal) tetrahedra of the unit cube: each is the path
/// `000 → +e_a → +e_b → +e_c = 111` for a permutation `(a, b, c)` of the axes, listed with
/// the permutation's parity (`true` = even, positively oriented as a path).
const KUHN: [([usize; 3], bool); 6] = [
    ([0, 1, 2], true),
    ([1, 2, 0], true),
    ([2, 0, 1], true),
    ([0, 2, 1], false),
    ([2, 1, 0], false),
    ([1, 0, 2], false),
];

/// Why [`structured_box`] cannot build a box.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum GridError {
    /// A cell count is zero.
    #[error("a structured box needs at least one cell along every axis, got {cells:?}")]
    NoCells {
        /// The cell counts asked for.
        cells: [usize; 3],
    },
    /// `min[d] >= max[d]` (or a bound that is not a number) on some axis.
    #[error("a structured box needs min < max along every axis, got min {min:?}, max {max:?}")]
    Empty {
        /// The lower corner.
        min: [f64; 3],
        /// The upper corner.
        max: [f64; 3],
    },
    /// More nodes than a mesh's `u32` node ids can number.
    #[error(
        "a structured box of {cells:?} cells has {nodes} nodes, more than the {} a mesh can \
         number (32-bit node ids); fix: fewer cells",
        u32::MAX
    )]
    TooManyNodes {
        /// The cell counts asked for.
        cells: [usize; 3],
        /// Its node count `(nx + 1)(ny + 1)(nz + 1)` (at most `u128::MAX`).
        nodes: u128,
    },
}

/// A box `[min, max]` of `cells[0] × cells[1] × cells[2]` hexahedral cells, each split into 6
/// tetrahedra (Kuhn/Freudenthal, the same split in every cell, so the mesh is conforming).
///
/// Nodes are numbered `i + (nx + 1) * (j + (ny + 1) * k)`; the boundary nodes on the six
/// faces are the dimension-2 groups `"xmin"`, `"xmax"`, `"ymin"`, `"ymax"`, `"zmin"`,
/// `"zmax"` (tags 1 to 6). Coordinates on the faces are exactly `min` and `max`. Every
/// tetrahedron is positively oriented. No file numbers it: its [`FileIds`] are empty.
///
/// # Errors
/// [`GridError`] if a cell count is zero, or `min[d] >= max[d]` on some axis, or the node
/// count does not fit in `u32` (checked before anything is allocated).
///
/// ```
/// let m = qdem_mesh::structured_box([0.0; 3], [1.0, 2.0, 3.0], [2, 2, 2])?;
/// assert_eq!(m.tets.len(), 6 * 8);
/// assert!((m.volume() - 6.0).abs() < 1e-12);
/// # Ok::<(), qdem_mesh::GridError>(())
/// ```
pub fn structured_box(
    min: [f64; 3],
    max: [f64; 3],
    cells: [usize; 3],
) -> Result<TetMesh, GridError> {
    if cells.contains(&0) {
        return Err(GridError::NoCells { cells });
    }
    if !(0..3).all(|d| min[d] < max[d]) {
        return Err(GridError::Empty { min, max });
    }
    let nodes = cells
        .iter()
        .fold(1u128, |n, &c| n.saturating_mul(c as u128 + 1));
    if nodes > u32::MAX as u128 {
        return Err(GridError::TooManyNodes { cells, nodes });
    }
    let [nx, ny, nz] = cells;
    let total = nodes as usize;
    let coord = |d: usize, i: usize| {
        if i == cells[d] {
            max[d]
        } else {
            min[d] + (max[d] - min[d]) * (i as f64 / cells[d] as f64)
        }
    };
    let id = |i: usize, j: usize, k: usize| (i + (nx + 1) * (j + (ny + 1) * k)) as u32;
    let mut nodes = Vec::with_capacity(total);
    for k in 0..=nz {
        for j in 0..=ny {
            for i in 0..=nx {
                nodes.push([coord(0, i), coord(1, j), coord(2, k)]);
            }
        }
    }
    let mut tets = Vec::with_capacity(6 * nx * ny * nz);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                for (perm, even) in &KUHN {
                    let mut p = [i, j, k];
                    let mut t = [id(i, j, k), 0, 0, 0];
                    for (s, &axis) in perm.iter().enumerate() {
                        p[axis] += 1;
                        t[s + 1] = id(p[0], p[1], p[2]);
                    }
                    if !even {
                        t.swap(2, 3);
                    }
                    tets.push(t);
                }
            }
        }
    }
    let names = ["xmin", "xmax", "ymin", "ymax", "zmin", "zmax"];
    let groups = names
        .iter()
        .enumerate()
        .map(|(g, name)| {
            let (axis, at_max) = (g / 2, g % 2 == 1);
            let mut set = Vec::new();
            for k in 0..=nz {
                for j in 0..=ny {
                    for i in 0..=nx {
                        let c = [i, j, k][axis];
                        if (at_max && c == cells[axis]) || (!at_max && c == 0) {
                            set.push(id(i, j, k));
                        }
                    }
                }
            }
            PhysicalGroup {
                name: (*name).to_string(),
                dim: 2,
                tag: g as i32 + 1,
                nodes: set,
            }
        })
        .collect();
    Ok(TetMesh {
        nodes,
        tets,
        groups,
        file_ids: FileIds::default(),
    })
}
