//! Tetrahedron geometry (signed volume, edge lengths, radius-ratio quality) and whole-mesh
//! statistics ([`MeshStats`]).

use crate::TetMesh;

/// Summary numbers of a mesh, from [`TetMesh::stats`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshStats {
    /// Number of nodes.
    pub nodes: usize,
    /// Number of tetrahedra.
    pub tets: usize,
    /// Total (signed) volume.
    pub volume: f64,
    /// Shortest tetrahedron edge (0 for an empty mesh).
    pub min_edge: f64,
    /// Longest tetrahedron edge (0 for an empty mesh).
    pub max_edge: f64,
    /// Smallest radius ratio `3 r / R` over the tetrahedra, in `(0, 1]`, 1 for a regular
    /// tetrahedron (0 for an empty or degenerate mesh).
    pub worst_quality: f64,
    /// Index of the tetrahedron with the smallest radius ratio (0 for an empty mesh).
    pub worst_tet: usize,
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// The 6 edges of a tetrahedron as pairs of local vertex indices.
pub const TET_EDGES: [(usize, usize); 6] = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];

/// Six times the signed volume: `det[p1 - p0, p2 - p0, p3 - p0]`, positive for a positively
/// oriented tetrahedron.
pub fn signed_volume6(p: &[[f64; 3]; 4]) -> f64 {
    dot(sub(p[1], p[0]), cross(sub(p[2], p[0]), sub(p[3], p[0])))
}

/// The longest edge length of a tetrahedron.
pub fn max_edge(p: &[[f64; 3]; 4]) -> f64 {
    TET_EDGES
        .iter()
        .map(|&(a, b)| norm(sub(p[a], p[b])))
        .fold(0.0, f64::max)
}

/// Radius ratio `3 r / R` of a tetrahedron (inradius r, circumradius R): 1 for the regular
/// tetrahedron, towards 0 for slivers and needles, 0 for degenerate ones. Orientation-free.
pub fn radius_ratio(p: &[[f64; 3]; 4]) -> f64 {
    let v6 = signed_volume6(p).abs();
    if v6 == 0.0 || !v6.is_finite() {
        return 0.0;
    }
    // Inradius: r = 3V / (sum of face areas).
    let faces = [(1, 2, 3), (0, 2, 3), (0, 1, 3), (0, 1, 2)];
    let area: f64 = faces
        .iter()
        .map(|&(a, b, c)| 0.5 * norm(cross(sub(p[b], p[a]), sub(p[c], p[a]))))
        .sum();
    let r = 0.5 * v6 / area;
    // Circumradius from the products of opposite edges:
    // 24 V R = sqrt((aA + bB + cC)(aA + bB - cC)(aA - bB + cC)(-aA + bB + cC)).
    let l = |i: usize, j: usize| norm(sub(p[i], p[j]));
    let a = l(0, 1) * l(2, 3);
    let b = l(0, 2) * l(1, 3);
    let c = l(0, 3) * l(1, 2);
    let prod = (a + b + c) * (a + b - c) * (a - b + c) * (-a + b + c);
    let big_r = prod.max(0.0).sqrt() / (4.0 * v6);
    if big_r <= 0.0 {
        return 0.0;
    }
    (3.0 * r / big_r).min(1.0)
}

impl TetMesh {
    /// The corner coordinates of tetrahedron `t`.
    ///
    /// # Panics
    /// If `t` or one of its node indices is out of range.
    pub fn tet_points(&self, t: usize) -> [[f64; 3]; 4] {
        self.tets[t].map(|n| self.nodes[n as usize])
    }

    /// Signed volume of tetrahedron `t` (positive for a positively oriented one).
    ///
    /// # Panics
    /// If `t` or one of its node indices is out of range.
    pub fn tet_volume(&self, t: usize) -> f64 {
        signed_volume6(&self.tet_points(t)) / 6.0
    }

    /// Total signed volume of the mesh.
    pub fn volume(&self) -> f64 {
        (0..self.tets.len()).map(|t| self.tet_volume(t)).sum()
    }

    /// Node and element counts, volume, edge-length range and worst radius ratio.
    pub fn stats(&self) -> MeshStats {
        let mut s = MeshStats {
            nodes: self.nodes.len(),
            tets: self.tets.len(),
            volume: 0.0,
            min_edge: f64::INFINITY,
            max_edge: 0.0,
            worst_quality: f64::INFINITY,
            worst_tet: 0,
        };
        for t in 0..self.tets.len() {
            let p = self.tet_points(t);
            s.volume += signed_volume6(&p) / 6.0;
            for &(a, b) in &TET_EDGES {
                let e = norm(sub(p[a], p[b]));
                s.min_edge = s.min_edge.min(e);
                s.max_edge = s.max_edge.max(e);
            }
            let q = radius_ratio(&p);
            if q < s.worst_quality {
                s.worst_quality = q;
                s.worst_tet = t;
            }
        }
        if self.tets.is_empty() {
            s.min_edge = 0.0;
            s.worst_quality = 0.0;
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regular_tet_has_quality_one() {
        let p = [
            [1.0, 1.0, 1.0],
            [1.0, -1.0, -1.0],
            [-1.0, 1.0, -1.0],
            [-1.0, -1.0, 1.0],
        ];
        assert!((radius_ratio(&p) - 1.0).abs() < 1e-12);
        let v = signed_volume6(&p) / 6.0;
        assert!((v.abs() - 8.0 / 3.0).abs() < 1e-12);
    }

    #[test]
    fn corner_tet() {
        let p = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ];
        assert_eq!(signed_volume6(&p), 1.0);
        let q = radius_ratio(&p);
        // r = 1/(3+sqrt 3), R = sqrt(3)/2.
        let expect = 3.0 / (3.0 + 3f64.sqrt()) / (3f64.sqrt() / 2.0);
        assert!((q - expect).abs() < 1e-12, "{q} {expect}");
        let flat = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
        ];
        assert_eq!(radius_ratio(&flat), 0.0);
    }
}
