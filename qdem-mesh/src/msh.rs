//! The gmsh MSH reader: file-level structure (`$MeshFormat`, section dispatch,
//! `$PhysicalNames`) and the raw, file-id based representation that the version-specific
//! parsers ([`crate::msh2`], [`crate::msh4`]) fill and [`crate::validate`] turns into a
//! [`TetMesh`].

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use crate::cursor::{trim, Cursor};
use crate::element_types::{element_info, TET4};
use crate::error::{MeshError, MeshWarning};
use crate::{msh2, msh4, validate, TetMesh};

/// A tetrahedron as in the file.
pub(crate) struct RawTet {
    pub id: u64,
    pub nodes: [u64; 4],
    /// Index into [`RawMesh::sources`]: the physical groups it belongs to.
    pub src: u32,
}

/// A lower-dimensional element that belongs to at least one physical group.
pub(crate) struct RawElem {
    pub id: u64,
    pub src: u32,
    /// Its node ids are `other_nodes[start..start + len]`.
    pub start: usize,
    pub len: usize,
}

/// What the parsers collect: everything still in file ids.
pub(crate) struct RawMesh {
    /// `$PhysicalNames`: (dim, tag, name).
    pub names: Vec<(u8, i32, String)>,
    pub node_ids: Vec<u64>,
    pub coords: Vec<[f64; 3]>,
    pub tets: Vec<RawTet>,
    pub others: Vec<RawElem>,
    pub other_nodes: Vec<u64>,
    /// Interned lists of physical groups `(dim, tag)`; index 0 is the empty list.
    pub sources: Vec<Vec<(u8, i32)>>,
    source_index: HashMap<Vec<(u8, i32)>, u32>,
    /// Cache of one-group sources (MSH 2.2 elements).
    single: HashMap<(u8, i32), u32>,
    /// MSH 4.1 `$Entities`: entity `(dim, tag)` to its source index.
    pub entities: HashMap<(u8, i32), u32>,
    /// Unknown element types skipped: type to (count, first element id).
    pub unknown: BTreeMap<i32, (usize, u64)>,
}

impl RawMesh {
    fn new() -> Self {
        let mut source_index = HashMap::new();
        source_index.insert(Vec::new(), 0);
        RawMesh {
            names: Vec::new(),
            node_ids: Vec::new(),
            coords: Vec::new(),
            tets: Vec::new(),
            others: Vec::new(),
            other_nodes: Vec::new(),
            sources: vec![Vec::new()],
            source_index,
            single: HashMap::new(),
            entities: HashMap::new(),
            unknown: BTreeMap::new(),
        }
    }

    /// The source index of a list of physical groups.
    pub fn intern(&mut self, mut groups: Vec<(u8, i32)>) -> u32 {
        groups.sort_unstable();
        groups.dedup();
        if let Some(&k) = self.source_index.get(&groups) {
            return k;
        }
        let k = self.sources.len() as u32;
        self.sources.push(groups.clone());
        self.source_index.insert(groups, k);
        k
    }

    /// The source index of the single group `(dim, tag)`.
    pub fn single(&mut self, dim: u8, tag: i32) -> u32 {
        if let Some(&k) = self.single.get(&(dim, tag)) {
            return k;
        }
        let k = self.intern(vec![(dim, tag)]);
        self.single.insert((dim, tag), k);
        k
    }

    pub fn note_unknown(&mut self, type_id: i32, element_id: u64) {
        let e = self.unknown.entry(type_id).or_insert((0, element_id));
        e.0 += 1;
    }

    pub fn push_node(&mut self, id: u64, p: [f64; 3]) {
        self.node_ids.push(id);
        self.coords.push(p);
    }

    /// Stores an element of a known type; lower-dimensional ones only if `src != 0`.
    pub fn push_element(&mut self, kind: &Kind, id: u64, src: u32, nodes: &[u64]) {
        match kind {
            Kind::Tet => {
                let mut n = [0u64; 4];
                n.copy_from_slice(&nodes[..4]);
                self.tets.push(RawTet { id, nodes: n, src });
            }
            Kind::Lower { .. } if src != 0 => {
                let start = self.other_nodes.len();
                self.other_nodes.extend_from_slice(nodes);
                self.others.push(RawElem {
                    id,
                    src,
                    start,
                    len: nodes.len(),
                });
            }
            _ => {}
        }
    }
}

/// How the reader treats an element type.
pub(crate) enum Kind {
    /// Linear tetrahedron (type 4).
    Tet,
    /// Points, lines, surfaces of any order: node sets for physical groups.
    Lower { dim: u8, nn: usize },
    /// A volume element other than the linear tetrahedron: an error.
    BadVolume { name: &'static str },
    /// Not in the type table.
    Unknown,
}

impl Kind {
    pub fn of(type_id: i32) -> Kind {
        match element_info(type_id) {
            Some(_) if type_id == TET4 => Kind::Tet,
            Some((name, 3, _)) => Kind::BadVolume { name },
            Some((_, dim, nn)) => Kind::Lower { dim, nn },
            None => Kind::Unknown,
        }
    }

    /// Number of nodes, `None` for unknown types.
    pub fn nodes(&self) -> Option<usize> {
        match self {
            Kind::Tet => Some(4),
            Kind::Lower { nn, .. } => Some(*nn),
            _ => None,
        }
    }
}

/// The error for a volume element that is not a linear tetrahedron.
pub(crate) fn unsupported(file: &Path, element_id: u64, type_id: i32, name: &str) -> MeshError {
    MeshError::UnsupportedElement {
        file: file.to_path_buf(),
        element_id,
        type_id,
        type_name: name.to_string(),
    }
}

/// MSH major version.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Version {
    V2,
    V41,
}

/// Reads and validates a gmsh MSH file (2.2 or 4.1, ASCII or binary).
///
/// Returns the mesh (only linear tetrahedra; nodes not used by any tetrahedron dropped;
/// every tetrahedron positively oriented) and the warnings about repairs made.
///
/// # Errors
/// [`MeshError::Io`] if the file cannot be read, otherwise as [`parse_msh`].
pub fn read_msh(path: &Path) -> Result<(TetMesh, Vec<MeshWarning>), MeshError> {
    let bytes = std::fs::read(path).map_err(|source| MeshError::Io {
        file: path.to_path_buf(),
        source,
    })?;
    parse_msh(&bytes, path)
}

/// Parses the bytes of a gmsh MSH file; `file` is used only in messages.
///
/// Never panics, whatever the input: malformed, truncated or hostile data give a
/// [`MeshError`] naming `file` and the line (ASCII) or byte offset (binary) or element id.
///
/// # Errors
/// Every [`MeshError`] variant but `Io` and `MissingGroup`.
pub fn parse_msh(bytes: &[u8], file: &Path) -> Result<(TetMesh, Vec<MeshWarning>), MeshError> {
    let mut c = Cursor::new(bytes, file);
    c.skip_ws();
    match c.line() {
        Some((line, _)) if trim(line) == b"$MeshFormat" => {}
        _ => {
            return Err(MeshError::NotMsh {
                file: file.to_path_buf(),
            })
        }
    }
    let version = mesh_format(&mut c)?;
    let mut raw = RawMesh::new();
    while !c.at_eof_after_ws() {
        let Some((line, start)) = c.line() else { break };
        let header = trim(line);
        let name = match header.strip_prefix(b"$") {
            Some(n)
                if !n.is_empty()
                    && !n.starts_with(b"End")
                    && !n.iter().any(|b| b.is_ascii_whitespace()) =>
            {
                String::from_utf8_lossy(n).into_owned()
            }
            _ => {
                let shown = String::from_utf8_lossy(&header[..header.len().min(40)]).into_owned();
                return Err(c.malformed_at(
                    start,
                    format!("expected a section header like $Nodes, found `{shown}`"),
                ));
            }
        };
        match (name.as_str(), version) {
            ("PhysicalNames", _) => physical_names(&mut c, &mut raw)?,
            ("Entities", Version::V41) => msh4::entities(&mut c, &mut raw)?,
            ("Nodes", Version::V41) => msh4::nodes(&mut c, &mut raw)?,
            ("Elements", Version::V41) => msh4::elements(&mut c, &mut raw)?,
            ("Nodes", Version::V2) => msh2::nodes(&mut c, &mut raw)?,
            ("Elements", Version::V2) => msh2::elements(&mut c, &mut raw)?,
            ("PartitionedEntities", _) => {
                return Err(MeshError::Partitioned {
                    file: file.to_path_buf(),
                    location: c.location_at(start),
                })
            }
            (other, _) => c.skip_section(other)?,
        }
    }
    validate::build(raw, file)
}

/// The body of `$MeshFormat` (after its header line), through `$EndMeshFormat`.
fn mesh_format(c: &mut Cursor) -> Result<Version, MeshError> {
    c.skip_ws();
    let Some((line, start)) = c.line() else {
        return Err(c.truncated("$MeshFormat"));
    };
    let text = String::from_utf8_lossy(&line[..line.len().min(60)]).into_owned();
    let unsupported = || MeshError::UnsupportedVersion {
        file: c.file().to_path_buf(),
        location: c.location_at(start),
        version: text.trim().to_string(),
    };
    let fields: Vec<&[u8]> = crate::cursor::split_ws(line).collect();
    if fields.len() < 3 {
        return Err(unsupported());
    }
    let parse = |t: &[u8]| {
        std::str::from_utf8(t)
            .ok()
            .and_then(|s| s.parse::<f64>().ok())
    };
    let version = match parse(fields[0]) {
        Some(v) if (2.0..3.0).contains(&v) => Version::V2,
        Some(_) if fields[0] == b"4.1" => Version::V41,
        _ => return Err(unsupported()),
    };
    let binary = match fields[1] {
        b"0" => false,
        b"1" => true,
        _ => return Err(unsupported()),
    };
    let data_size = crate::cursor::parse_int(fields[2]);
    if binary {
        c.size_t = match (version, data_size) {
            (Version::V2, Some(8)) => 8,
            (Version::V41, Some(n @ (4 | 8))) => n as usize,
            _ => return Err(unsupported()),
        };
        c.binary = true;
        let at = c.pos();
        let marker = c.bytes(4, "the endianness marker of $MeshFormat")?;
        c.big_endian = match marker {
            [1, 0, 0, 0] => false,
            [0, 0, 0, 1] => true,
            _ => {
                return Err(c.malformed_at(
                    at,
                    format!(
                        "the binary endianness marker should be the int 1, found bytes {marker:?}"
                    ),
                ))
            }
        };
    }
    c.expect_end("MeshFormat")?;
    Ok(version)
}

/// `$PhysicalNames` (always ASCII): count, then `dim tag "name"` lines.
fn physical_names(c: &mut Cursor, raw: &mut RawMesh) -> Result<(), MeshError> {
    let n = c.count("the number of physical names", 6)?;
    for _ in 0..n {
        let start = c.pos();
        let dim = c.int32("the dimension of a physical name")?;
        let dim = u8::try_from(dim).ok().filter(|d| *d <= 3).ok_or_else(|| {
            c.malformed_at(
                start,
                format!("physical group dimension {dim} is not 0, 1, 2 or 3"),
            )
        })?;
        let tag = c.int32("the tag of a physical name")?;
        let Some((rest, _)) = c.line() else {
            return Err(c.truncated("a physical name"));
        };
        let rest = trim(rest);
        let name = rest
            .strip_prefix(b"\"")
            .and_then(|r| r.strip_suffix(b"\""))
            .unwrap_or(rest);
        raw.names
            .push((dim, tag, String::from_utf8_lossy(name).into_owned()));
    }
    c.expect_end("PhysicalNames")
}
