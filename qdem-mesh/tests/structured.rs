//! `structured_box`, surface extraction, reordering and statistics.

use qdem_mesh::{structured_box, GridError, TetMesh};

fn tri_area_vector(m: &TetMesh, t: &[u32; 3]) -> [f64; 3] {
    let [a, b, c] = t.map(|k| m.nodes[k as usize]);
    let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    [
        0.5 * (u[1] * v[2] - u[2] * v[1]),
        0.5 * (u[2] * v[0] - u[0] * v[2]),
        0.5 * (u[0] * v[1] - u[1] * v[0]),
    ]
}

#[test]
fn box_counts_volume_orientation_and_surface() {
    let (min, max) = ([0.1, -0.2, 0.3], [0.4, 0.3, 0.5]);
    for cells in [[1, 1, 1], [3, 2, 4], [5, 1, 2]] {
        let m = structured_box(min, max, cells).unwrap();
        let [nx, ny, nz] = cells;
        let (lx, ly, lz) = (max[0] - min[0], max[1] - min[1], max[2] - min[2]);
        assert_eq!(m.tets.len(), 6 * nx * ny * nz);
        assert_eq!(m.nodes.len(), (nx + 1) * (ny + 1) * (nz + 1));
        let vol = lx * ly * lz;
        assert!((m.volume() - vol).abs() <= 1e-12 * vol);
        assert!((0..m.tets.len()).all(|t| m.tet_volume(t) > 0.0));
        let tris = m.surface_triangles();
        assert_eq!(tris.len(), 2 * 2 * (nx * ny + ny * nz + nx * nz));
        let area: f64 = tris
            .iter()
            .map(|t| {
                let a = tri_area_vector(&m, t);
                (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
            })
            .sum();
        let box_area = 2.0 * (lx * ly + ly * lz + lx * lz);
        assert!((area - box_area).abs() <= 1e-12 * box_area);
        // Outward orientation: the divergence theorem gives back the volume,
        // V = (1/3) sum over faces of x_centroid · n A.
        let div: f64 = tris
            .iter()
            .map(|t| {
                let a = tri_area_vector(&m, t);
                let c: Vec<f64> = (0..3)
                    .map(|d| t.iter().map(|&k| m.nodes[k as usize][d]).sum::<f64>() / 3.0)
                    .collect();
                (c[0] * a[0] + c[1] * a[1] + c[2] * a[2]) / 3.0
            })
            .sum();
        assert!((div - vol).abs() <= 1e-12 * vol, "{div} {vol}");
        // Groups: the nodes on each face.
        assert_eq!(m.group("xmin").unwrap().nodes.len(), (ny + 1) * (nz + 1));
        assert_eq!(m.group("zmax").unwrap().nodes.len(), (nx + 1) * (ny + 1));
        for &k in &m.group("xmax").unwrap().nodes {
            assert_eq!(m.nodes[k as usize][0], max[0]);
        }
        assert_eq!(
            m.group("ymin").unwrap().nodes,
            m.nodes_in_box([-9.0; 3], [9.0, min[1], 9.0])
        );
        let mut surf = m.surface_nodes();
        let mut all: Vec<u32> = m.groups.iter().flat_map(|g| g.nodes.clone()).collect();
        all.sort_unstable();
        all.dedup();
        surf.sort_unstable();
        assert_eq!(surf, all);
    }
}

#[test]
fn kuhn_split_is_conforming() {
    // Every interior face is shared by exactly two tetrahedra: the surface is only the box's.
    let m = structured_box([0.0; 3], [1.0; 3], [3, 3, 3]).unwrap();
    assert_eq!(m.surface_triangles().len(), 2 * 2 * 27);
}

/// Deterministically shuffles the node numbering.
fn shuffle(m: &mut TetMesh, seed: u64) {
    let n = m.nodes.len();
    let mut perm: Vec<u32> = (0..n as u32).collect();
    let mut s = seed;
    for i in (1..n).rev() {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let j = ((s >> 33) % (i as u64 + 1)) as usize;
        perm.swap(i, j);
    }
    m.renumber_nodes(&perm);
}

#[test]
fn reorder_keeps_geometry_and_reduces_bandwidth() {
    let mut m = structured_box([0.0; 3], [2.0, 1.0, 0.5], [12, 6, 3]).unwrap();
    shuffle(&mut m, 7);
    let before = m.clone();
    let bw0 = m.bandwidth();
    m.reorder_for_locality();
    let bw1 = m.bandwidth();
    assert!(bw1 * 4 < bw0, "bandwidth {bw0} -> {bw1}");
    assert!((m.volume() - before.volume()).abs() < 1e-12);
    assert!((0..m.tets.len()).all(|t| m.tet_volume(t) > 0.0));
    for (g0, g1) in before.groups.iter().zip(&m.groups) {
        assert_eq!(g0.name, g1.name);
        let pts = |mesh: &TetMesh, g: &qdem_mesh::PhysicalGroup| {
            let mut p: Vec<[u64; 3]> = g
                .nodes
                .iter()
                .map(|&k| mesh.nodes[k as usize].map(f64::to_bits))
                .collect();
            p.sort_unstable();
            p
        };
        assert_eq!(pts(&before, g0), pts(&m, g1));
        assert!(g1.nodes.windows(2).all(|w| w[0] < w[1]));
    }
    // The same set of tetrahedra (as point sets).
    let tet_set = |mesh: &TetMesh| {
        let mut s: Vec<[[u64; 3]; 4]> = mesh
            .tets
            .iter()
            .map(|t| {
                let mut p = t.map(|k| mesh.nodes[k as usize].map(f64::to_bits));
                p.sort_unstable();
                p
            })
            .collect();
        s.sort_unstable();
        s
    };
    assert_eq!(tet_set(&before), tet_set(&m));
    // Tetrahedra sorted by their smallest node.
    let mins: Vec<u32> = m.tets.iter().map(|t| *t.iter().min().unwrap()).collect();
    assert!(mins.windows(2).all(|w| w[0] <= w[1]));
    // Surfaces survive too.
    assert_eq!(
        m.surface_triangles().len(),
        before.surface_triangles().len()
    );
}

#[test]
fn stats_on_a_regular_mesh() {
    let m = structured_box([0.0; 3], [1.0; 3], [4, 4, 4]).unwrap();
    let s = m.stats();
    assert_eq!(s.nodes, 125);
    assert_eq!(s.tets, 384);
    assert!((s.volume - 1.0).abs() < 1e-12);
    assert!(s.worst_quality > 0.0 && s.worst_quality <= 1.0);
    assert!(s.min_edge > 0.0 && s.min_edge <= s.max_edge);
    assert!((s.min_edge - 0.25).abs() < 1e-12);
    assert!((s.max_edge - 0.25 * 3f64.sqrt()).abs() < 1e-12);
    // All Kuhn tetrahedra are congruent.
    let q = qdem_mesh::radius_ratio(&m.tet_points(0));
    assert!((s.worst_quality - q).abs() < 1e-12);
    assert!(s.worst_tet < s.tets);
    let empty = TetMesh::default().stats();
    assert_eq!(
        (empty.tets, empty.min_edge, empty.worst_quality),
        (0, 0.0, 0.0)
    );
}

#[test]
fn a_box_that_cannot_be_built_is_a_typed_error_not_a_panic() {
    // 10^12 tetrahedra (`qdem bench --tets 1000000000000`) once panicked "too many nodes".
    let n = 5503;
    assert_eq!(
        structured_box([0.0; 3], [1.0; 3], [n; 3]).unwrap_err(),
        GridError::TooManyNodes {
            cells: [n; 3],
            nodes: (n as u128 + 1).pow(3)
        }
    );
    // Counts whose node count overflows 64 bits are counted exactly, not wrapped.
    let huge = [usize::MAX; 3];
    assert!(matches!(
        structured_box([0.0; 3], [1.0; 3], huge),
        Err(GridError::TooManyNodes { .. })
    ));
    // Just over: 1626^3 = 4,298,942,376 nodes against 2^32 - 1 ids.
    assert!(matches!(
        structured_box([0.0; 3], [1.0; 3], [1625; 3]),
        Err(GridError::TooManyNodes { .. })
    ));
    assert_eq!(
        structured_box([0.0; 3], [1.0; 3], [2, 0, 2]).unwrap_err(),
        GridError::NoCells { cells: [2, 0, 2] }
    );
    let flat = structured_box([0.0; 3], [1.0, 0.0, 1.0], [1; 3]).unwrap_err();
    assert!(flat.to_string().contains("min < max"), "{flat}");
    let nan = structured_box([0.0; 3], [1.0, f64::NAN, 1.0], [1; 3]);
    assert!(matches!(nan, Err(GridError::Empty { .. })));
}
