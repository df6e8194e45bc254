//! Errors and warnings of mesh import.
//!
//! Every [`MeshError`] names the file it comes from, the line (ASCII files) or byte offset
//! (binary files) or element id where one exists, and ends with a sentence that tells the user
//! how to fix the input. [`MeshWarning`]s describe repairs the reader made on its own.

use std::fmt;
use std::path::{Path, PathBuf};

/// Where in a file something was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Location {
    /// A 1-based line number (ASCII files).
    Line(usize),
    /// A 0-based byte offset (binary files).
    Byte(usize),
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Location::Line(n) => write!(f, "line {n}"),
            Location::Byte(n) => write!(f, "byte offset {n}"),
        }
    }
}

/// `file:line` for lines, `file: byte offset N` for bytes.
fn at(file: &Path, location: &Location) -> String {
    match location {
        Location::Line(n) => format!("{}:{n}", file.display()),
        Location::Byte(n) => format!("{}: byte offset {n}", file.display()),
    }
}

/// The corners of a tetrahedron, each coordinate in at most 24 characters (see
/// [`fmt_coordinate`]).
fn fmt_points(coords: &[[f64; 3]; 4]) -> String {
    let parts: Vec<String> = coords
        .iter()
        .map(|p| p.map(fmt_coordinate).join(", "))
        .map(|p| format!("({p})"))
        .collect();
    parts.join(", ")
}

/// A coordinate as written in meshes (`0.5`) when it is of an everyday size, else in
/// exponent form (`3.5e300`): `Display` writes every digit of a large number, 300 of them
/// for 1e300.
fn fmt_coordinate(x: f64) -> String {
    if x == 0.0 || (1e-4..1e6).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

fn fmt_names(names: &[String]) -> String {
    if names.is_empty() {
        "none".to_string()
    } else {
        names
            .iter()
            .map(|n| format!("\"{n}\""))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// Everything that can go wrong when reading a gmsh MSH file or querying a mesh.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum MeshError {
    /// The file could not be read from disk.
    #[error("cannot read {}: {source}; fix: check the path and its permissions", .file.display())]
    Io {
        /// The file.
        file: PathBuf,
        /// The operating-system error.
        #[source]
        source: std::io::Error,
    },

    /// The file ends in the middle of a section (or a count promises more than the file holds).
    #[error(
        "{}: unexpected end of data while reading {what}: the file looks truncated; \
         fix: re-export the mesh from gmsh (and check that the copy is complete)",
        at(.file, .location)
    )]
    Truncated {
        /// The file.
        file: PathBuf,
        /// Where the data ran out.
        location: Location,
        /// What the reader was reading.
        what: String,
    },

    /// A number could not be parsed (or is not finite, or is out of range).
    #[error(
        "{}: cannot read {what} from `{token}`; fix: the file is corrupt or not written by \
         gmsh: re-export it from gmsh",
        at(.file, .location)
    )]
    BadNumber {
        /// The file.
        file: PathBuf,
        /// Where the token starts.
        location: Location,
        /// What the number should have been.
        what: String,
        /// The offending text (shortened).
        token: String,
    },

    /// Structure that does not follow the MSH format.
    #[error(
        "{}: {message}; fix: re-export the mesh from gmsh as MSH 4.1 or 2.2",
        at(.file, .location)
    )]
    Malformed {
        /// The file.
        file: PathBuf,
        /// Where the problem is.
        location: Location,
        /// What is wrong.
        message: String,
    },

    /// The file does not start with `$MeshFormat`.
    #[error(
        "{} is not a gmsh MSH file (it does not start with $MeshFormat); fix: export the mesh \
         from gmsh in MSH format (.msh)",
        .file.display()
    )]
    NotMsh {
        /// The file.
        file: PathBuf,
    },

    /// An MSH version other than 2.x or 4.1, or a binary data size that is not supported.
    #[error(
        "{}: unsupported MSH format `{version}`; fix: re-save as MSH 4.1 or 2.2 \
         (gmsh option Mesh.MshFileVersion = 4.1, or `gmsh -format msh41`)",
        at(.file, .location)
    )]
    UnsupportedVersion {
        /// The file.
        file: PathBuf,
        /// Where the version is.
        location: Location,
        /// The `$MeshFormat` line as found.
        version: String,
    },

    /// The file holds a partitioned mesh.
    #[error(
        "{}: partitioned meshes are not supported; fix: re-save without partitions \
         (Mesh.PartitionSplitMeshFiles = 0 and no Mesh.NbPartitions, or gmsh `-part 0`)",
        at(.file, .location)
    )]
    Partitioned {
        /// The file.
        file: PathBuf,
        /// Where the `$PartitionedEntities` section starts.
        location: Location,
    },

    /// A volume element that is not a linear tetrahedron.
    #[error(
        "{}: element {element_id} is a {type_name} (gmsh type {type_id}), but only linear \
         tetrahedra (type 4) are supported as volume elements; fix: re-mesh with only \
         first-order tetrahedra: Mesh.ElementOrder = 1, and no Recombine3DAll (nor \
         transfinite/recombined volumes)",
        .file.display()
    )]
    UnsupportedElement {
        /// The file.
        file: PathBuf,
        /// The element's id (tag) in the file.
        element_id: u64,
        /// The gmsh element type number.
        type_id: i32,
        /// The gmsh name of the type, e.g. `Hexahedron 8`.
        type_name: String,
    },

    /// An element type this reader does not know, in a binary file (so its size is unknown).
    #[error(
        "{}: unknown gmsh element type {type_id}; fix: re-mesh with linear tetrahedra and \
         ordinary points, lines, triangles or quadrangles for the physical groups",
        at(.file, .location)
    )]
    UnknownElementType {
        /// The file.
        file: PathBuf,
        /// Where the element block starts.
        location: Location,
        /// The type number found.
        type_id: i32,
    },

    /// An element refers to a node id that the `$Nodes` section does not define.
    #[error(
        "{}: element {element_id} refers to node {node_id}, which is not defined in $Nodes; \
         fix: re-export the complete mesh from gmsh (with all nodes)",
        .file.display()
    )]
    UndefinedNode {
        /// The file.
        file: PathBuf,
        /// The element's id.
        element_id: u64,
        /// The missing node id.
        node_id: u64,
    },

    /// A node id is defined twice.
    #[error(
        "{}: node {node_id} is defined twice in $Nodes; fix: re-export the mesh from gmsh \
         (Mesh.SaveAll = 0, no hand-merged node lists)",
        .file.display()
    )]
    DuplicateNode {
        /// The file.
        file: PathBuf,
        /// The duplicated node id.
        node_id: u64,
    },

    /// A tetrahedron with (numerically) zero volume.
    #[error(
        "{}: tetrahedron {element_id} (nodes {nodes:?}) is degenerate (6V = {volume6:e}), its \
         corners are {}; fix: remove duplicate nodes (gmsh Coherence Mesh) and re-mesh",
        .file.display(),
        fmt_points(.coords)
    )]
    DegenerateTet {
        /// The file.
        file: PathBuf,
        /// The element's id.
        element_id: u64,
        /// Its node ids as in the file.
        nodes: [u64; 4],
        /// Its corner coordinates (boxed to keep the error small).
        coords: Box<[[f64; 3]; 4]>,
        /// Six times its signed volume.
        volume6: f64,
    },

    /// A tetrahedron so large that its volume is not a finite number: coordinates far beyond
    /// any physical size, in the wrong unit or scaled wrongly.
    #[error(
        "{}: tetrahedron {element_id} (nodes {nodes:?}) is {span:.3e} m across, its corners are {}: \
         its volume overflows the largest number a double holds (1.8e308), so the mesh's \
         coordinates are not those of any physical object; fix: check the mesh's unit and \
         scale (qdem reads metres: export the mesh in metres, or check gmsh's \
         Mesh.ScalingFactor)",
        .file.display(),
        fmt_points(.coords)
    )]
    OverflowingTet {
        /// The file.
        file: PathBuf,
        /// The element's id.
        element_id: u64,
        /// Its node ids as in the file.
        nodes: [u64; 4],
        /// Its corner coordinates (boxed to keep the error small).
        coords: Box<[[f64; 3]; 4]>,
        /// The widest side of the box around its corners (m).
        span: f64,
    },

    /// The physical groups would hold more node entries than
    /// [`crate::MAX_GROUP_ENTRIES_PER_NODE`] per mesh node: elements that are in very many
    /// physical groups (corrupt or hostile physical tags).
    #[error(
        "{}: the physical groups would hold up to {entries} node entries, more than the \
         {limit} accepted for a mesh of {nodes} nodes (element {element_id} is in {groups} \
         physical groups); fix: give each element (each entity in $Entities) only the physical \
         groups it belongs to, and re-export the mesh from gmsh",
        .file.display()
    )]
    TooManyGroupEntries {
        /// The file.
        file: PathBuf,
        /// The total size of the node sets before duplicates between sets are merged (an upper
        /// bound).
        entries: u64,
        /// The limit: [`crate::MAX_GROUP_ENTRIES_PER_NODE`] times the number of nodes, and at
        /// least 2^20.
        limit: u64,
        /// The number of mesh nodes (those used by a tetrahedron).
        nodes: usize,
        /// An element of the list of physical groups that contributes most.
        element_id: u64,
        /// The number of physical groups that element is in.
        groups: usize,
    },

    /// The file holds no linear tetrahedra.
    #[error(
        "no tetrahedra (type 4) in {}: mesh the volume (gmsh -3), and if Mesh.SaveAll = 0 put \
         the volume in a Physical Volume",
        .file.display()
    )]
    NoTetrahedra {
        /// The file.
        file: PathBuf,
    },

    /// A physical group that the caller needs is not in the mesh.
    #[error(
        "{}: no physical group named \"{name}\" (available: {}); fix: add `Physical \
         Surface(\"{name}\") = {{...}};` (or Volume/Curve/Point) to the .geo and re-mesh, or use \
         one of the available names",
        .file.display(),
        fmt_names(.available)
    )]
    MissingGroup {
        /// The file the mesh came from.
        file: PathBuf,
        /// The requested name.
        name: String,
        /// The names that exist.
        available: Vec<String>,
    },
}

/// A repair the reader made, or input it ignored. Display-able for users.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum MeshWarning {
    /// Tetrahedra with negative volume whose node order was fixed (two nodes swapped).
    ReorientedTets {
        /// How many.
        count: usize,
        /// The file id of the first one.
        first_element_id: u64,
    },
    /// Nodes that no tetrahedron uses, removed (the rest renumbered).
    DroppedUnusedNodes {
        /// How many.
        count: usize,
        /// The file id of the first one.
        first_node_id: u64,
    },
    /// Elements of a type this reader does not know, skipped (ASCII files only).
    IgnoredUnknownElements {
        /// The gmsh type number.
        type_id: i32,
        /// How many.
        count: usize,
        /// The file id of the first one.
        first_element_id: u64,
    },
    /// Tetrahedra listed more than once with the same id and nodes (MSH 2.2 writes an element
    /// once per physical group it belongs to); kept once.
    DuplicateTets {
        /// How many extra copies were dropped.
        count: usize,
        /// The file id of the first one.
        first_element_id: u64,
    },
    /// A physical group with no node in any tetrahedron (its nodes were all dropped, or it
    /// has no elements).
    EmptyGroup {
        /// The group's name.
        name: String,
        /// Its dimension.
        dim: u8,
        /// Its physical tag.
        tag: i32,
    },
}

impl fmt::Display for MeshWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MeshWarning::ReorientedTets {
                count,
                first_element_id,
            } => write!(
                f,
                "{count} tetrahedra had negative volume and were reoriented (two nodes swapped), \
                 the first is element {first_element_id}"
            ),
            MeshWarning::DroppedUnusedNodes {
                count,
                first_node_id,
            } => write!(
                f,
                "{count} nodes are not used by any tetrahedron and were dropped (nodes \
                 renumbered), the first is node {first_node_id}"
            ),
            MeshWarning::IgnoredUnknownElements {
                type_id,
                count,
                first_element_id,
            } => write!(
                f,
                "{count} elements of unknown gmsh type {type_id} were ignored, the first is \
                 element {first_element_id}"
            ),
            MeshWarning::DuplicateTets {
                count,
                first_element_id,
            } => write!(
                f,
                "{count} duplicate tetrahedra (same id and nodes) were kept once, the first is \
                 element {first_element_id}"
            ),
            MeshWarning::EmptyGroup { name, dim, tag } => write!(
                f,
                "physical group \"{name}\" (dimension {dim}, tag {tag}) has no node in any \
                 tetrahedron; it is empty"
            ),
        }
    }
}
