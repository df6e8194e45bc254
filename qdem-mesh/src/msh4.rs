//! MSH 4.1 `$Entities`, `$Nodes` and `$Elements`, ASCII and binary.
//!
//! Elements come in blocks per geometric entity `(dim, tag)`; `$Entities` gives each entity
//! its physical tags. In binary files counts and tags are `size_t` of the header's data size,
//! entity fields are `int`, coordinates `double`.

use crate::cursor::{split_ws, Cursor};
use crate::error::MeshError;
use crate::msh::{unsupported, Kind, RawMesh};

fn count(
    c: &mut Cursor,
    what: &str,
    min_ascii: usize,
    min_binary: usize,
) -> Result<usize, MeshError> {
    if c.binary {
        c.bin_count(what, min_binary)
    } else {
        c.count(what, min_ascii)
    }
}

fn int(c: &mut Cursor, what: &str) -> Result<i32, MeshError> {
    if c.binary {
        c.bin_i32(what)
    } else {
        c.int32(what)
    }
}

fn float(c: &mut Cursor, what: &str) -> Result<f64, MeshError> {
    if c.binary {
        c.bin_f64(what)
    } else {
        c.float(what)
    }
}

fn size(c: &mut Cursor, what: &str) -> Result<u64, MeshError> {
    if c.binary {
        c.bin_size(what)
    } else {
        c.id(what)
    }
}

fn dim_of(c: &Cursor, at: usize, dim: i32) -> Result<u8, MeshError> {
    u8::try_from(dim)
        .ok()
        .filter(|d| *d <= 3)
        .ok_or_else(|| c.malformed_at(at, format!("entity dimension {dim} is not 0, 1, 2 or 3")))
}

/// The body of `$Entities` through `$EndEntities`.
pub(crate) fn entities(c: &mut Cursor, raw: &mut RawMesh) -> Result<(), MeshError> {
    let mut per_dim = [0usize; 4];
    for n in per_dim.iter_mut() {
        *n = count(c, "the number of entities", 2, 4)?;
    }
    let mut phys = Vec::new();
    for (dim, &n) in per_dim.iter().enumerate() {
        let dim = dim as u8;
        // A point: tag, 3 doubles, a count; anything else: tag, 6 doubles, 2 counts.
        let min_binary = if dim == 0 {
            4 + 24 + c.size_t
        } else {
            4 + 48 + 2 * c.size_t
        };
        c.check_count(n, if c.binary { min_binary } else { 10 }, "the entities")?;
        for _ in 0..n {
            let tag = int(c, "an entity tag")?;
            for _ in 0..if dim == 0 { 3 } else { 6 } {
                float(c, "an entity coordinate")?;
            }
            let np = count(c, "a number of physical tags", 2, 4)?;
            phys.clear();
            for _ in 0..np {
                let p = int(c, "a physical tag")?;
                phys.push((dim, p));
            }
            if dim > 0 {
                let nb = count(c, "a number of bounding entities", 2, 4)?;
                for _ in 0..nb {
                    int(c, "a bounding entity tag")?;
                }
            }
            let src = raw.intern(phys.clone());
            raw.entities.insert((dim, tag), src);
        }
    }
    c.expect_end("Entities")
}

/// The body of `$Nodes` through `$EndNodes`.
pub(crate) fn nodes(c: &mut Cursor, raw: &mut RawMesh) -> Result<(), MeshError> {
    let sz = c.size_t;
    let blocks = count(c, "the number of node blocks", 8, 12 + sz)?;
    let total = count(c, "the number of nodes", 8, sz + 24)?;
    size(c, "the smallest node tag")?;
    size(c, "the largest node tag")?;
    raw.node_ids.reserve(total);
    raw.coords.reserve(total);
    let mut tags: Vec<u64> = Vec::new();
    for _ in 0..blocks {
        let at = c.pos();
        let dim = int(c, "a node block's entity dimension")?;
        let dim = dim_of(c, at, dim)?;
        int(c, "a node block's entity tag")?;
        let parametric = int(c, "a node block's parametric flag")?;
        let extra = if parametric != 0 { usize::from(dim) } else { 0 };
        let n = count(c, "the number of nodes in a block", 8, sz + 8 * (3 + extra))?;
        tags.clear();
        for _ in 0..n {
            tags.push(size(c, "a node tag")?);
        }
        for &id in &tags {
            let x = float(c, "a node coordinate")?;
            let y = float(c, "a node coordinate")?;
            let z = float(c, "a node coordinate")?;
            for _ in 0..extra {
                float(c, "a parametric node coordinate")?;
            }
            raw.push_node(id, [x, y, z]);
        }
    }
    c.expect_end("Nodes")
}

/// The body of `$Elements` through `$EndElements`.
pub(crate) fn elements(c: &mut Cursor, raw: &mut RawMesh) -> Result<(), MeshError> {
    let sz = c.size_t;
    let blocks = count(c, "the number of element blocks", 8, 12 + sz)?;
    count(c, "the number of elements", 4, 2 * sz)?;
    size(c, "the smallest element tag")?;
    size(c, "the largest element tag")?;
    let mut nodes: Vec<u64> = Vec::new();
    for _ in 0..blocks {
        let header = c.pos();
        let dim = int(c, "an element block's entity dimension")?;
        let dim = dim_of(c, header, dim)?;
        let tag = int(c, "an element block's entity tag")?;
        let type_id = int(c, "an element block's element type")?;
        let kind = Kind::of(type_id);
        let per_binary = kind.nodes().map_or(sz, |nn| (nn + 1).saturating_mul(sz));
        let n = count(c, "the number of elements in a block", 4, per_binary)?;
        let src = raw.entities.get(&(dim, tag)).copied().unwrap_or(0);
        let nn = match kind {
            Kind::BadVolume { name } => {
                let id = if n > 0 { size(c, "an element tag")? } else { 0 };
                return Err(unsupported(c.file(), id, type_id, name));
            }
            Kind::Unknown if c.binary => {
                return Err(MeshError::UnknownElementType {
                    file: c.file().to_path_buf(),
                    location: c.location_at(header),
                    type_id,
                });
            }
            Kind::Unknown => {
                for _ in 0..n {
                    let (line, start) = c.data_line("an element")?;
                    let tok = split_ws(line).next().unwrap_or(b"");
                    let id = c.id_in(tok, start, "an element tag")?;
                    if dim == 3 {
                        return Err(unsupported(
                            c.file(),
                            id,
                            type_id,
                            &format!("element of unknown type {type_id}"),
                        ));
                    }
                    raw.note_unknown(type_id, id);
                }
                continue;
            }
            _ => kind.nodes().unwrap_or(0),
        };
        for _ in 0..n {
            nodes.clear();
            let id = if c.binary {
                let id = c.bin_size("an element tag")?;
                for _ in 0..nn {
                    nodes.push(c.bin_size("an element node tag")?);
                }
                id
            } else {
                let (line, start) = c.data_line("an element")?;
                let mut toks = split_ws(line);
                let id = c.id_in(toks.next().unwrap_or(b""), start, "an element tag")?;
                for t in toks {
                    nodes.push(c.id_in(t, start, "an element node tag")?);
                }
                if nodes.len() != nn {
                    return Err(c.malformed_at(
                        start,
                        format!(
                            "element {id} of type {type_id} has {} nodes, expected {nn}",
                            nodes.len()
                        ),
                    ));
                }
                id
            };
            raw.push_element(&kind, id, src, &nodes);
        }
    }
    c.expect_end("Elements")
}
