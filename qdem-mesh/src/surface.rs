//! Boundary extraction: faces that belong to exactly one tetrahedron.

use crate::TetMesh;

/// The faces of a positively oriented tetrahedron `[0, 1, 2, 3]`, each ordered so that its
/// right-hand normal points out of the tetrahedron.
pub const TET_FACES_OUTWARD: [[usize; 3]; 4] = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];

impl TetMesh {
    /// The boundary triangles (faces of exactly one tetrahedron), oriented with the
    /// right-hand normal pointing out of the mesh (given positively oriented tetrahedra).
    /// Sorted by their sorted node triple, so the result is deterministic.
    pub fn surface_triangles(&self) -> Vec<[u32; 3]> {
        let mut faces: Vec<([u32; 3], [u32; 3])> = Vec::with_capacity(self.tets.len() * 4);
        for t in &self.tets {
            for f in &TET_FACES_OUTWARD {
                let tri = [t[f[0]], t[f[1]], t[f[2]]];
                let mut key = tri;
                key.sort_unstable();
                faces.push((key, tri));
            }
        }
        faces.sort_unstable_by_key(|f| f.0);
        let mut out = Vec::new();
        let mut i = 0;
        while i < faces.len() {
            let mut j = i + 1;
            while j < faces.len() && faces[j].0 == faces[i].0 {
                j += 1;
            }
            if j - i == 1 {
                out.push(faces[i].1);
            }
            i = j;
        }
        out
    }

    /// The nodes on the boundary (of any boundary triangle), sorted and unique.
    pub fn surface_nodes(&self) -> Vec<u32> {
        let mut n: Vec<u32> = self.surface_triangles().into_iter().flatten().collect();
        n.sort_unstable();
        n.dedup();
        n
    }
}
