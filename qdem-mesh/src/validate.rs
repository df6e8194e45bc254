//! From the raw, file-id based parse to a checked [`TetMesh`]: node ids resolved,
//! duplicate tetrahedra merged, unused nodes dropped and the rest renumbered (file order kept),
//! negative tetrahedra reoriented, degenerate ones rejected, physical groups turned into
//! node sets; the file's node and element ids and each tetrahedron's physical volume kept
//! ([`FileIds`]).

use std::collections::HashMap;
use std::path::Path;

use crate::error::{MeshError, MeshWarning};
use crate::msh::RawMesh;
use crate::quality::{max_edge, signed_volume6};
use crate::{FileIds, PhysicalGroup, TetMesh};

/// A tetrahedron is degenerate when `|6V| <= DEGENERATE_TOL * (longest edge)^3`.
pub const DEGENERATE_TOL: f64 = 1e-12;

/// The physical groups of a mesh may hold at most this many node entries per mesh node, all
/// groups together (2^20 entries for a mesh of up to 16384 nodes). A node of a real mesh is in a
/// handful of groups (its volume, a boundary surface, a curve, a point); a file whose elements
/// are each in thousands of groups would otherwise make node sets quadratic in its size.
pub const MAX_GROUP_ENTRIES_PER_NODE: usize = 64;

/// The node-entry limit of the physical groups of a small mesh (4 MiB of node indices).
const MIN_GROUP_ENTRY_LIMIT: u64 = 1 << 20;

const NONE: u32 = u32::MAX;

/// File node id to index in the raw node list.
enum IdMap {
    Dense(Vec<u32>),
    Sparse(HashMap<u64, u32>),
}

impl IdMap {
    fn new(ids: &[u64], file: &Path) -> Result<IdMap, MeshError> {
        let dup = |node_id| MeshError::DuplicateNode {
            file: file.to_path_buf(),
            node_id,
        };
        let max = ids.iter().copied().max().unwrap_or(0);
        let dense_limit = (ids.len() as u64).saturating_mul(4).saturating_add(1024);
        if max <= dense_limit {
            let mut map = vec![NONE; max as usize + 1];
            for (k, &id) in ids.iter().enumerate() {
                let slot = &mut map[id as usize];
                if *slot != NONE {
                    return Err(dup(id));
                }
                *slot = k as u32;
            }
            Ok(IdMap::Dense(map))
        } else {
            let mut map = HashMap::with_capacity(ids.len());
            for (k, &id) in ids.iter().enumerate() {
                if map.insert(id, k as u32).is_some() {
                    return Err(dup(id));
                }
            }
            Ok(IdMap::Sparse(map))
        }
    }

    fn get(&self, id: u64) -> Option<u32> {
        match self {
            IdMap::Dense(v) => usize::try_from(id)
                .ok()
                .and_then(|i| v.get(i))
                .copied()
                .filter(|&k| k != NONE),
            IdMap::Sparse(m) => m.get(&id).copied(),
        }
    }
}

/// Builds the checked mesh from the raw parse.
pub(crate) fn build(raw: RawMesh, file: &Path) -> Result<(TetMesh, Vec<MeshWarning>), MeshError> {
    let mut warnings = Vec::new();
    for (&type_id, &(count, first_element_id)) in &raw.unknown {
        warnings.push(MeshWarning::IgnoredUnknownElements {
            type_id,
            count,
            first_element_id,
        });
    }
    if raw.tets.is_empty() {
        return Err(MeshError::NoTetrahedra {
            file: file.to_path_buf(),
        });
    }
    if raw.node_ids.len() >= NONE as usize || raw.tets.len() >= NONE as usize {
        return Err(MeshError::Malformed {
            file: file.to_path_buf(),
            location: crate::Location::Byte(0),
            message: "more than 2^32 - 1 nodes or tetrahedra".to_string(),
        });
    }
    let map = IdMap::new(&raw.node_ids, file)?;
    let undefined = |element_id, node_id| MeshError::UndefinedNode {
        file: file.to_path_buf(),
        element_id,
        node_id,
    };

    // Exact duplicates (same id and nodes): keep the first, in the lowest physical volume
    // of them all.
    let mut keep = vec![true; raw.tets.len()];
    let mut volume: Vec<Option<i32>> = raw
        .tets
        .iter()
        .map(|t| lowest_volume(&raw.sources[t.src as usize]))
        .collect();
    let mut dups = 0usize;
    let mut first_dup = None;
    let mut order: Vec<u32> = Vec::new();
    if !raw.tets.windows(2).all(|w| w[0].id < w[1].id) {
        order = (0..raw.tets.len() as u32).collect();
        order.sort_unstable_by_key(|&k| {
            let t = &raw.tets[k as usize];
            (t.id, t.nodes, k)
        });
    }
    let mut kept = order.first().map_or(0, |&k| k as usize);
    for w in order.windows(2) {
        let (a, b) = (&raw.tets[w[0] as usize], &raw.tets[w[1] as usize]);
        if a.id == b.id && a.nodes == b.nodes {
            keep[w[1] as usize] = false;
            volume[kept] = [volume[kept], volume[w[1] as usize]]
                .into_iter()
                .flatten()
                .min();
            dups += 1;
            first_dup.get_or_insert(b.id);
        } else {
            kept = w[1] as usize;
        }
    }
    if let Some(first_element_id) = first_dup {
        warnings.push(MeshWarning::DuplicateTets {
            count: dups,
            first_element_id,
        });
    }

    // Resolve node ids; mark used nodes.
    let mut used = vec![false; raw.node_ids.len()];
    let mut tets_raw: Vec<[u32; 4]> = Vec::with_capacity(raw.tets.len());
    let mut tet_ids: Vec<u64> = Vec::with_capacity(raw.tets.len());
    let mut volumes: Vec<i32> = Vec::with_capacity(raw.tets.len());
    for ((t, _), v) in raw
        .tets
        .iter()
        .zip(&keep)
        .zip(&volume)
        .filter(|((_, &k), _)| k)
    {
        let mut r = [0u32; 4];
        for (slot, &id) in r.iter_mut().zip(&t.nodes) {
            *slot = map.get(id).ok_or_else(|| undefined(t.id, id))?;
            used[*slot as usize] = true;
        }
        tets_raw.push(r);
        tet_ids.push(t.id);
        volumes.push(v.unwrap_or(-1));
    }

    // Renumber in file order.
    let mut new_index = vec![NONE; raw.node_ids.len()];
    let mut nodes = Vec::with_capacity(raw.node_ids.len());
    let mut node_ids = Vec::with_capacity(raw.node_ids.len());
    let mut dropped = 0usize;
    let mut first_dropped = None;
    for (k, &u) in used.iter().enumerate() {
        if u {
            new_index[k] = nodes.len() as u32;
            nodes.push(raw.coords[k]);
            node_ids.push(raw.node_ids[k]);
        } else {
            dropped += 1;
            first_dropped.get_or_insert(raw.node_ids[k]);
        }
    }
    if let Some(first_node_id) = first_dropped {
        warnings.push(MeshWarning::DroppedUnusedNodes {
            count: dropped,
            first_node_id,
        });
    }

    // Orientation and degeneracy.
    let mut tets = Vec::with_capacity(tets_raw.len());
    let mut flipped = 0usize;
    let mut first_flipped = None;
    for (r, &id) in tets_raw.iter().zip(&tet_ids) {
        let mut t = r.map(|k| new_index[k as usize]);
        let p = t.map(|k| nodes[k as usize]);
        let v6 = signed_volume6(&p);
        let h = max_edge(&p);
        let scale = DEGENERATE_TOL * h * h * h;
        let nodes_ids = r.map(|k| raw.node_ids[k as usize]);
        if !v6.is_finite() || !scale.is_finite() {
            return Err(MeshError::OverflowingTet {
                file: file.to_path_buf(),
                element_id: id,
                nodes: nodes_ids,
                coords: Box::new(p),
                span: box_width(&p),
            });
        }
        if v6.abs() <= scale {
            return Err(MeshError::DegenerateTet {
                file: file.to_path_buf(),
                element_id: id,
                nodes: nodes_ids,
                coords: Box::new(p),
                volume6: v6,
            });
        }
        if v6 < 0.0 {
            t.swap(2, 3);
            flipped += 1;
            first_flipped.get_or_insert(id);
        }
        tets.push(t);
    }
    if let Some(first_element_id) = first_flipped {
        warnings.push(MeshWarning::ReorientedTets {
            count: flipped,
            first_element_id,
        });
    }

    let groups = groups(&raw, &map, &new_index, nodes.len(), file, &mut warnings)?;
    Ok((
        TetMesh {
            nodes,
            tets,
            groups,
            file_ids: FileIds {
                nodes: node_ids,
                tets: tet_ids,
                volumes,
            },
        },
        warnings,
    ))
}

/// The lowest tag of the dimension-3 groups among `groups`, if any.
fn lowest_volume(groups: &[(u8, i32)]) -> Option<i32> {
    groups.iter().filter(|g| g.0 == 3).map(|g| g.1).min()
}

/// Physical groups as sorted node sets (new indices), sorted by (dim, tag).
///
/// The nodes are gathered per source (list of groups) first, so that an element in many
/// groups is walked once, and the total size of the sets is checked against
/// [`MAX_GROUP_ENTRIES_PER_NODE`] before they are filled: the work and memory stay
/// proportional to the file.
fn groups(
    raw: &RawMesh,
    map: &IdMap,
    new_index: &[u32],
    mesh_nodes: usize,
    file: &Path,
    warnings: &mut Vec<MeshWarning>,
) -> Result<Vec<PhysicalGroup>, MeshError> {
    // Every group named or referenced, in (dim, tag) order.
    let mut keys: Vec<(u8, i32)> = raw.names.iter().map(|&(d, t, _)| (d, t)).collect();
    keys.extend(raw.sources.iter().flatten().copied());
    keys.sort_unstable();
    keys.dedup();
    let slot: HashMap<(u8, i32), usize> = keys.iter().enumerate().map(|(k, &g)| (g, k)).collect();

    // The node set of each source. All tetrahedra, dropped duplicates included (same nodes,
    // maybe other groups).
    let mut per_source: Vec<Vec<u32>> = vec![Vec::new(); raw.sources.len()];
    for t in &raw.tets {
        if raw.sources[t.src as usize].is_empty() {
            continue;
        }
        for &id in &t.nodes {
            // Resolved above: every tetrahedron's nodes exist and are used.
            if let Some(k) = map.get(id) {
                per_source[t.src as usize].push(new_index[k as usize]);
            }
        }
    }
    for e in &raw.others {
        for &id in &raw.other_nodes[e.start..e.start + e.len] {
            let k = map.get(id).ok_or_else(|| MeshError::UndefinedNode {
                file: file.to_path_buf(),
                element_id: e.id,
                node_id: id,
            })?;
            let n = new_index[k as usize];
            if n != NONE {
                per_source[e.src as usize].push(n);
            }
        }
    }
    for set in &mut per_source {
        set.sort_unstable();
        set.dedup();
    }

    // Each group gets the set of every source it is in: bound the total before filling.
    let size = |s: usize| (raw.sources[s].len() as u64).saturating_mul(per_source[s].len() as u64);
    let entries = (0..raw.sources.len()).fold(0u64, |sum, s| sum.saturating_add(size(s)));
    let limit = (MAX_GROUP_ENTRIES_PER_NODE as u64)
        .saturating_mul(mesh_nodes as u64)
        .max(MIN_GROUP_ENTRY_LIMIT);
    if entries > limit {
        let worst = (0..raw.sources.len()).max_by_key(|&s| size(s)).unwrap_or(0);
        let element_id = raw
            .tets
            .iter()
            .map(|t| (t.src, t.id))
            .chain(raw.others.iter().map(|e| (e.src, e.id)))
            .find(|&(src, _)| src as usize == worst)
            .map_or(0, |(_, id)| id);
        return Err(MeshError::TooManyGroupEntries {
            file: file.to_path_buf(),
            entries,
            limit,
            nodes: mesh_nodes,
            element_id,
            groups: raw.sources[worst].len(),
        });
    }
    let mut sets: Vec<Vec<u32>> = vec![Vec::new(); keys.len()];
    for (groups, set) in raw.sources.iter().zip(&per_source) {
        for g in groups {
            sets[slot[g]].extend_from_slice(set);
        }
    }

    // The first name given to a group wins.
    let mut names: HashMap<(u8, i32), &str> = HashMap::with_capacity(raw.names.len());
    for (dim, tag, name) in &raw.names {
        names.entry((*dim, *tag)).or_insert(name.as_str());
    }
    let mut out = Vec::with_capacity(keys.len());
    for ((dim, tag), mut nodes) in keys.into_iter().zip(sets) {
        nodes.sort_unstable();
        nodes.dedup();
        let name = names
            .get(&(dim, tag))
            .map_or_else(|| format!("{dim}:{tag}"), |n| (*n).to_string());
        if nodes.is_empty() {
            warnings.push(MeshWarning::EmptyGroup {
                name: name.clone(),
                dim,
                tag,
            });
        }
        out.push(PhysicalGroup {
            name,
            dim,
            tag,
            nodes,
        });
    }
    Ok(out)
}

/// The widest side of the box around a tetrahedron's corners: finite for any finite corners
/// (its longest edge, a square root of squares, overflows from about 1e154 m on).
fn box_width(p: &[[f64; 3]; 4]) -> f64 {
    (0..3)
        .map(|axis| {
            let (lo, hi) = p
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), c| {
                    (lo.min(c[axis]), hi.max(c[axis]))
                });
            hi - lo
        })
        .fold(0.0, f64::max)
}
