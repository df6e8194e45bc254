//! Tetrahedral meshes for QDEM: gmsh MSH import, physical groups as node sets, quality,
//! surface extraction, node reordering and structured generators.
//!
//! # Reading gmsh files
//! [`read_msh`] / [`parse_msh`] read MSH 2.2 and 4.1, ASCII and binary (either endianness;
//! 4.1 binary with 4- or 8-byte `size_t`). Only linear tetrahedra (type 4) are volume
//! elements; any other volume element is an error that says how to re-mesh. Points, lines and
//! surface elements (any order) only give node sets to physical groups: a [`PhysicalGroup`]
//! holds the union of the nodes of its elements, of any dimension, as sorted indices into
//! [`TetMesh::nodes`]. The reader then
//! - drops nodes used by no tetrahedron and renumbers the rest in file order (warning),
//! - reorients negative tetrahedra by swapping their last two nodes (warning),
//! - rejects degenerate tetrahedra (`|6V| <= 1e-12 · (longest edge)³`),
//! - keeps exact duplicate tetrahedra once (MSH 2.2 repeats an element per physical group),
//! - keeps the file's node and element tags and each tetrahedron's physical volume
//!   ([`FileIds`]), which follow the renumberings.
//!
//! Nodes at the same place that no tetrahedron shares (separately meshed volumes) are found
//! by [`TetMesh::coincident_nodes`] and merged on request by
//! [`TetMesh::merge_coincident_nodes`].
//!
//! The reader never panics: counts are checked against the bytes left before anything is
//! allocated, the physical groups' node sets are bounded ([`MAX_GROUP_ENTRIES_PER_NODE`]), so
//! work and memory grow about linearly with the file's size (see `docs/fuzzing.md`), and every
//! error names the file and the line (ASCII) or byte offset (binary) or element id, and ends
//! with a fix.
//!
//! ```no_run
//! use std::path::Path;
//! let file = Path::new("fixtures/cantilever/cantilever_lc100.msh");
//! let (mut mesh, warnings) = qdem_mesh::read_msh(file)?;
//! for w in &warnings {
//!     eprintln!("warning: {w}");
//! }
//! let clamp = mesh.require_group("clamp", file)?;
//! println!("{} clamped nodes; {:?}", clamp.nodes.len(), mesh.stats());
//! mesh.reorder_for_locality();
//! # Ok::<(), qdem_mesh::MeshError>(())
//! ```
//!
//! # Design notes
//! The reader works in two stages: version-specific parsers (`msh2` for 2.x, `msh4` for
//! 4.1) fill a raw, file-id based record over a bounds-checked cursor, and one
//! validation stage resolves ids, checks geometry and builds node sets; so every format goes
//! through the same checks. No third-party MSH crate is used: the one available reads 4.1 only.

#![warn(missing_docs)]

mod coincident;
mod cursor;
mod element_types;
mod error;
mod generate;
mod msh;
mod msh2;
mod msh4;
mod quality;
mod reorder;
mod surface;
mod validate;

use std::path::Path;

pub use coincident::{CoincidentNodes, COINCIDENT_TOL};
pub use element_types::element_info;
pub use error::{Location, MeshError, MeshWarning};
pub use generate::{structured_box, GridError};
pub use msh::{parse_msh, read_msh};
pub use quality::{max_edge, radius_ratio, signed_volume6, MeshStats, TET_EDGES};
pub use reorder::NodeGraph;
pub use surface::TET_FACES_OUTWARD;
pub use validate::{DEGENERATE_TOL, MAX_GROUP_ENTRIES_PER_NODE};

/// A linear tetrahedral mesh with physical groups as node sets.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TetMesh {
    /// Node coordinates.
    pub nodes: Vec<[f64; 3]>,
    /// Tetrahedra as 0-based node indices, every one positively oriented
    /// (`det[x1 - x0, x2 - x0, x3 - x0] > 0`).
    pub tets: Vec<[u32; 4]>,
    /// Physical groups of any dimension, as node sets, sorted by (dimension, tag).
    pub groups: Vec<PhysicalGroup>,
    /// The file's numbering of the nodes and tetrahedra, which follows every renumbering;
    /// empty for a mesh no file numbers.
    pub file_ids: FileIds,
}

/// The numbering of a mesh's nodes and tetrahedra in the file it was read from, and the
/// physical volume of each tetrahedron: kept in step with [`TetMesh::nodes`] and
/// [`TetMesh::tets`] by every renumbering ([`TetMesh::renumber_nodes`],
/// [`TetMesh::reorder_for_locality`], [`TetMesh::merge_coincident_nodes`]), so that results
/// can be mapped back to the file. Each list is either empty (a mesh no file numbers: a
/// generated one) or holds one entry per node or tetrahedron.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct FileIds {
    /// The file's node tag of each node.
    pub nodes: Vec<u64>,
    /// The file's element tag of each tetrahedron.
    pub tets: Vec<u64>,
    /// The physical volume of each tetrahedron: the lowest tag of the dimension-3 physical
    /// groups its element is in (over every record of a repeated element), −1 for none.
    pub volumes: Vec<i32>,
}

/// A gmsh physical group reduced to the set of mesh nodes of its elements.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct PhysicalGroup {
    /// The name from `$PhysicalNames`, or `"<dim>:<tag>"` if unnamed.
    pub name: String,
    /// The dimension: 0 points, 1 curves, 2 surfaces, 3 volumes.
    pub dim: u8,
    /// The physical tag.
    pub tag: i32,
    /// Node indices into [`TetMesh::nodes`]: sorted, unique, 0-based.
    pub nodes: Vec<u32>,
}

impl TetMesh {
    /// The first group named `name` (lowest dimension, then tag), if any.
    pub fn group(&self, name: &str) -> Option<&PhysicalGroup> {
        self.groups.iter().find(|g| g.name == name)
    }

    /// The group named `name`, or [`MeshError::MissingGroup`] listing the available names;
    /// `file` is the mesh's source, for the message.
    ///
    /// # Errors
    /// [`MeshError::MissingGroup`] if no group has that name.
    pub fn require_group(&self, name: &str, file: &Path) -> Result<&PhysicalGroup, MeshError> {
        self.group(name).ok_or_else(|| MeshError::MissingGroup {
            file: file.to_path_buf(),
            name: name.to_string(),
            available: self.groups.iter().map(|g| g.name.clone()).collect(),
        })
    }

    /// The nodes inside the closed box `[min, max]`, in increasing order.
    pub fn nodes_in_box(&self, min: [f64; 3], max: [f64; 3]) -> Vec<u32> {
        self.nodes
            .iter()
            .enumerate()
            .filter(|(_, p)| (0..3).all(|d| p[d] >= min[d] && p[d] <= max[d]))
            .map(|(k, _)| k as u32)
            .collect()
    }

    /// The node closest to `p` (the lowest index among equals); `None` for a mesh without
    /// nodes.
    pub fn nearest_node(&self, p: [f64; 3]) -> Option<u32> {
        let d2 = |q: &[f64; 3]| (0..3).map(|d| (q[d] - p[d]) * (q[d] - p[d])).sum::<f64>();
        self.nodes
            .iter()
            .enumerate()
            .min_by(|a, b| d2(a.1).total_cmp(&d2(b.1)))
            .map(|(k, _)| k as u32)
    }
}
