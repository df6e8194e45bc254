//! Coincident nodes: two nodes at the same place (within [`COINCIDENT_TOL`] of the mesh's
//! size) that tetrahedra do not share. A mesh made of separately meshed volumes whose
//! interface nodes were not merged (gmsh without `Coherence`) has them: the tetrahedra on
//! either side are then not connected and the body falls apart there, with no error.
//! [`TetMesh::coincident_nodes`] finds them (sort along x, then compare within the
//! tolerance: O(n log n) for a mesh without near-duplicates);
//! [`TetMesh::merge_coincident_nodes`] merges each onto the first of its kind.

use crate::TetMesh;

/// Two nodes closer than this fraction of the mesh's bounding-box diagonal coincide.
pub const COINCIDENT_TOL: f64 = 1e-9;

/// The coincident nodes of a mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct CoincidentNodes {
    /// How many nodes coincide with an earlier node (the nodes a merge removes).
    pub count: usize,
    /// The first such node (0-based index) and the earlier node it coincides with.
    pub first: (u32, u32),
    /// Where the first one is (m).
    pub at: [f64; 3],
    /// The distance below which nodes coincide for this mesh (m).
    pub tolerance: f64,
}

impl TetMesh {
    /// For every node, the earliest node it coincides with (itself when none), and the
    /// tolerance used.
    fn representatives(&self) -> (Vec<u32>, f64) {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in &self.nodes {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let diagonal = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
        let tol = COINCIDENT_TOL * diagonal;
        let mut order: Vec<u32> = (0..self.nodes.len() as u32).collect();
        order.sort_by(|&a, &b| {
            let (pa, pb) = (self.nodes[a as usize], self.nodes[b as usize]);
            pa[0].total_cmp(&pb[0]).then(a.cmp(&b))
        });
        let mut first: Vec<u32> = (0..self.nodes.len() as u32).collect();
        for (i, &a) in order.iter().enumerate() {
            let pa = self.nodes[a as usize];
            for &b in &order[i + 1..] {
                let pb = self.nodes[b as usize];
                if pb[0] - pa[0] > tol {
                    break;
                }
                let d2: f64 = (0..3).map(|k| (pb[k] - pa[k]).powi(2)).sum();
                if d2 <= tol * tol {
                    let (ra, rb) = (root(&mut first, a), root(&mut first, b));
                    first[ra.max(rb) as usize] = ra.min(rb);
                }
            }
        }
        for n in 0..first.len() as u32 {
            first[n as usize] = root(&mut first, n);
        }
        (first, tol)
    }

    /// The nodes that coincide with an earlier one, or `None` when no two nodes do.
    #[must_use]
    pub fn coincident_nodes(&self) -> Option<CoincidentNodes> {
        let (first, tolerance) = self.representatives();
        let mut duplicates = (0..first.len() as u32).filter(|&n| first[n as usize] != n);
        let one = duplicates.next()?;
        Some(CoincidentNodes {
            count: 1 + duplicates.count(),
            first: (one, first[one as usize]),
            at: self.nodes[one as usize],
            tolerance,
        })
    }

    /// Merges every node onto the earliest node it coincides with: the tetrahedra and
    /// physical groups then use that node, and the others are removed (the rest keep their
    /// order and their file ids). Returns how many nodes were removed.
    pub fn merge_coincident_nodes(&mut self) -> usize {
        let (first, _) = self.representatives();
        let mut new_of_old = vec![0u32; first.len()];
        let mut kept = Vec::with_capacity(first.len());
        for (old, &root) in first.iter().enumerate() {
            if root as usize == old {
                new_of_old[old] = kept.len() as u32;
                kept.push(self.nodes[old]);
            } else {
                new_of_old[old] = new_of_old[root as usize];
            }
        }
        let removed = self.nodes.len() - kept.len();
        self.nodes = kept;
        let ids = &self.file_ids.nodes;
        if !ids.is_empty() {
            let roots = (0..first.len()).filter(|&n| first[n] as usize == n);
            self.file_ids.nodes = roots.map(|n| ids[n]).collect();
        }
        for tet in &mut self.tets {
            *tet = tet.map(|n| new_of_old[n as usize]);
        }
        for group in &mut self.groups {
            for n in &mut group.nodes {
                *n = new_of_old[*n as usize];
            }
            group.nodes.sort_unstable();
            group.nodes.dedup();
        }
        removed
    }
}

/// The root of `n` in the union-find `parent` (the smallest node of its set), compressing
/// the path.
fn root(parent: &mut [u32], n: u32) -> u32 {
    let mut r = n;
    while parent[r as usize] != r {
        r = parent[r as usize];
    }
    let mut m = n;
    while parent[m as usize] != r {
        let next = parent[m as usize];
        parent[m as usize] = r;
        m = next;
    }
    r
}

#[cfg(test)]
mod tests {
    use crate::structured_box;

    #[test]
    fn a_mesh_without_duplicates_has_no_coincident_nodes() {
        let mesh = structured_box([0.0; 3], [1.0, 0.5, 0.5], [4, 2, 2]).unwrap();
        assert_eq!(mesh.coincident_nodes(), None);
        let mut merged = mesh.clone();
        assert_eq!(merged.merge_coincident_nodes(), 0);
        assert_eq!(merged, mesh);
    }

    #[test]
    fn two_boxes_side_by_side_share_their_face_once_merged() {
        let left = structured_box([0.0; 3], [1.0, 1.0, 1.0], [1, 1, 1]).unwrap();
        let mut mesh = left.clone();
        let offset = mesh.nodes.len() as u32;
        mesh.nodes
            .extend(left.nodes.iter().map(|p| [p[0] + 1.0, p[1], p[2]]));
        mesh.tets
            .extend(left.tets.iter().map(|t| t.map(|n| n + offset)));
        let found = mesh
            .coincident_nodes()
            .expect("the shared face's four nodes");
        assert_eq!(found.count, 4);
        assert_eq!(found.at[0], 1.0);
        assert_eq!(mesh.merge_coincident_nodes(), 4);
        assert_eq!(mesh.nodes.len(), 12);
        assert_eq!(mesh.coincident_nodes(), None);
        // Every face node of x = 1 is now used by tetrahedra of both boxes.
        let at_face: Vec<u32> = (0..12)
            .filter(|&n| mesh.nodes[n as usize][0] == 1.0)
            .collect();
        for n in at_face {
            let users = mesh.tets.iter().filter(|t| t.contains(&n));
            let sides = users
                .map(|t| t.iter().map(|&m| mesh.nodes[m as usize][0]).sum::<f64>() > 4.0)
                .collect::<Vec<bool>>();
            assert!(sides.contains(&true) && sides.contains(&false));
        }
    }
}
