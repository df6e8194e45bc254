//! MSH 2.x (2.0–2.2) `$Nodes` and `$Elements`, ASCII and binary.
//!
//! ASCII elements are `id type ntags tag... node...` lines; the first tag is the physical
//! group (0 for none). Binary element data are blocks with an `int` header
//! `type, count, ntags` followed by `count` elements of `1 + ntags + nodes` ints.

use crate::cursor::{split_ws, Cursor};
use crate::error::MeshError;
use crate::msh::{unsupported, Kind, RawMesh};

/// Bytes of one binary 2.2 node: int id and three doubles.
const BIN_NODE: usize = 4 + 3 * 8;

/// The body of `$Nodes` through `$EndNodes`.
pub(crate) fn nodes(c: &mut Cursor, raw: &mut RawMesh) -> Result<(), MeshError> {
    if c.binary {
        let n = c.count("the number of nodes", BIN_NODE)?;
        c.skip_line_rest();
        c.check_count(n, BIN_NODE, "the nodes")?;
        raw.node_ids.reserve(n);
        raw.coords.reserve(n);
        for _ in 0..n {
            let id = c.bin_u32("a node id")?;
            let x = c.bin_f64("a node coordinate")?;
            let y = c.bin_f64("a node coordinate")?;
            let z = c.bin_f64("a node coordinate")?;
            raw.push_node(id, [x, y, z]);
        }
    } else {
        let n = c.count("the number of nodes", 8)?;
        raw.node_ids.reserve(n);
        raw.coords.reserve(n);
        for _ in 0..n {
            let id = c.id("a node id")?;
            let x = c.float("a node coordinate")?;
            let y = c.float("a node coordinate")?;
            let z = c.float("a node coordinate")?;
            raw.push_node(id, [x, y, z]);
        }
    }
    c.expect_end("Nodes")
}

/// The body of `$Elements` through `$EndElements`.
pub(crate) fn elements(c: &mut Cursor, raw: &mut RawMesh) -> Result<(), MeshError> {
    if c.binary {
        elements_binary(c, raw)?;
    } else {
        elements_ascii(c, raw)?;
    }
    c.expect_end("Elements")
}

fn source(raw: &mut RawMesh, dim: u8, phys: i32) -> u32 {
    if phys == 0 {
        0
    } else {
        raw.single(dim, phys)
    }
}

fn elements_ascii(c: &mut Cursor, raw: &mut RawMesh) -> Result<(), MeshError> {
    let n = c.count("the number of elements", 8)?;
    let mut nodes: Vec<u64> = Vec::new();
    for _ in 0..n {
        let (line, start) = c.data_line("an element")?;
        let mut toks = split_ws(line);
        let mut next = |what: &str| {
            toks.next()
                .ok_or_else(|| c.malformed_at(start, format!("element line ends before {what}")))
        };
        let id_tok = next("its id")?;
        let type_tok = next("its type")?;
        let ntags_tok = next("its number of tags")?;
        let id = c.id_in(id_tok, start, "an element id")?;
        let type_id = c.i32_in(type_tok, start, "an element type")?;
        let ntags = c.id_in(ntags_tok, start, "a number of element tags")?;
        let mut phys = 0;
        let mut rest = split_ws(line).skip(3);
        for k in 0..ntags {
            let Some(t) = rest.next() else {
                return Err(c.malformed_at(
                    start,
                    format!("element {id} has fewer than the {ntags} tags it announces"),
                ));
            };
            let v = c.i32_in(t, start, "an element tag")?;
            if k == 0 {
                phys = v;
            }
        }
        let kind = Kind::of(type_id);
        let (dim, nn) = match kind {
            Kind::BadVolume { name } => return Err(unsupported(c.file(), id, type_id, name)),
            Kind::Unknown => {
                raw.note_unknown(type_id, id);
                continue;
            }
            Kind::Tet => (3, 4),
            Kind::Lower { dim, nn } => (dim, nn),
        };
        nodes.clear();
        for t in rest {
            nodes.push(c.id_in(t, start, "an element node id")?);
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
        let src = source(raw, dim, phys);
        raw.push_element(&kind, id, src, &nodes);
    }
    Ok(())
}

fn elements_binary(c: &mut Cursor, raw: &mut RawMesh) -> Result<(), MeshError> {
    let n = c.count("the number of elements", 8)?;
    c.skip_line_rest();
    c.check_count(n, 8, "the elements")?;
    let mut done = 0usize;
    let mut nodes: Vec<u64> = Vec::new();
    while done < n {
        let header = c.pos();
        let type_id = c.bin_i32("an element block header")?;
        let follow = c.bin_u32("an element block header")?;
        let ntags = c.bin_u32("an element block header")?;
        let follow = usize::try_from(follow).unwrap_or(usize::MAX);
        if follow > n - done {
            return Err(c.malformed_at(
                header,
                format!(
                    "an element block of {follow} elements exceeds the {} elements left",
                    n - done
                ),
            ));
        }
        let kind = Kind::of(type_id);
        let nn = match kind {
            Kind::BadVolume { name } => {
                let id = if follow > 0 {
                    c.bin_u32("an element id")?
                } else {
                    0
                };
                return Err(unsupported(c.file(), id, type_id, name));
            }
            Kind::Unknown => {
                return Err(MeshError::UnknownElementType {
                    file: c.file().to_path_buf(),
                    location: c.location_at(header),
                    type_id,
                })
            }
            _ => kind.nodes().unwrap_or(0),
        };
        let dim = if let Kind::Lower { dim, .. } = kind {
            dim
        } else {
            3
        };
        let per = usize::try_from(ntags)
            .ok()
            .and_then(|t| t.checked_add(1 + nn))
            .and_then(|k| k.checked_mul(4))
            .unwrap_or(usize::MAX);
        c.check_count(follow, per, "an element block")?;
        for _ in 0..follow {
            let id = c.bin_u32("an element id")?;
            let mut phys = 0;
            for k in 0..ntags {
                let v = c.bin_i32("an element tag")?;
                if k == 0 {
                    phys = v;
                }
            }
            nodes.clear();
            for _ in 0..nn {
                nodes.push(c.bin_u32("an element node id")?);
            }
            let src = source(raw, dim, phys);
            raw.push_element(&kind, id, src, &nodes);
        }
        done += follow;
    }
    Ok(())
}
