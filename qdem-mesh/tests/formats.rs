//! Every format fixture (gmsh and meshio, MSH 2.2 and 4.1, ASCII and binary) reads to the
//! same mesh as gmsh's 4.1 ASCII file.

mod common;

use common::{fixture, rel};
use qdem_mesh::{read_msh, TetMesh};

const BOX_VOLUME: f64 = 0.3 * 0.2 * 0.1;

const FORMATS: [&str; 8] = [
    "box_gmsh22_ascii.msh",
    "box_gmsh22_binary.msh",
    "box_gmsh41_ascii.msh",
    "box_gmsh41_binary.msh",
    "box_meshio22_ascii.msh",
    "box_meshio22_binary.msh",
    "box_meshio41_ascii.msh",
    "box_meshio41_binary.msh",
];

fn read(name: &str) -> TetMesh {
    let (mesh, warnings) =
        read_msh(&fixture(&format!("msh/{name}"))).unwrap_or_else(|e| panic!("{name}: {e}"));
    assert!(warnings.is_empty(), "{name}: {warnings:?}");
    mesh
}

fn summary(m: &TetMesh) -> Vec<(String, u8, usize)> {
    m.groups
        .iter()
        .map(|g| (g.name.clone(), g.dim, g.nodes.len()))
        .collect()
}

#[test]
fn reference_mesh_is_the_box() {
    let m = read("box_gmsh41_ascii.msh");
    assert!(rel(m.volume(), BOX_VOLUME) < 1e-12, "{}", m.volume());
    assert!(m.tets.len() > 100);
    let names: Vec<&str> = m.groups.iter().map(|g| g.name.as_str()).collect();
    assert_eq!(names, ["origin", "left", "right", "body"]);
    assert_eq!(m.group("origin").unwrap().nodes.len(), 1);
    assert_eq!(m.group("body").unwrap().nodes.len(), m.nodes.len());
    let origin = m.group("origin").unwrap().nodes[0];
    assert_eq!(m.nodes[origin as usize], [0.0, 0.0, 0.0]);
    for &n in &m.group("left").unwrap().nodes {
        assert_eq!(m.nodes[n as usize][0], 0.0);
    }
    for &n in &m.group("right").unwrap().nodes {
        assert!((m.nodes[n as usize][0] - 0.3).abs() < 1e-15);
    }
    assert!(m
        .tets
        .iter()
        .enumerate()
        .all(|(t, _)| m.tet_volume(t) > 0.0));
    // The named groups are exactly the nodes on those faces.
    assert_eq!(
        m.group("left").unwrap().nodes,
        m.nodes_in_box([-1.0, -1.0, -1.0], [0.0, 1.0, 1.0])
    );
}

#[test]
fn all_formats_agree() {
    let reference = read("box_gmsh41_ascii.msh");
    for name in FORMATS {
        let m = read(name);
        assert_eq!(m.nodes.len(), reference.nodes.len(), "{name}");
        assert_eq!(m.tets.len(), reference.tets.len(), "{name}");
        assert!(rel(m.volume(), reference.volume()) < 1e-12, "{name}");
        assert!(rel(m.volume(), BOX_VOLUME) < 1e-12, "{name}");
        assert_eq!(summary(&m), summary(&reference), "{name}");
        assert!(
            m.tets
                .iter()
                .enumerate()
                .all(|(t, _)| m.tet_volume(t) > 0.0),
            "{name}"
        );
    }
}

#[test]
fn gmsh_files_agree_node_for_node() {
    // gmsh writes the same nodes and elements in all four of its formats (ASCII coordinates
    // with 16 significant digits, binary ones exact).
    let reference = read("box_gmsh41_ascii.msh");
    for name in &FORMATS[..4] {
        let m = read(name);
        assert_eq!(m.nodes.len(), reference.nodes.len(), "{name}");
        for (p, q) in m.nodes.iter().zip(&reference.nodes) {
            assert!(
                (0..3).all(|d| (p[d] - q[d]).abs() < 1e-15),
                "{name}: {p:?} {q:?}"
            );
        }
        assert_eq!(m.tets, reference.tets, "{name}");
        assert_eq!(m.groups, reference.groups, "{name}");
    }
}

#[test]
fn big_endian_binary_reads_the_same() {
    // Byte-swap a little-endian 2.2 binary file by hand: header marker, nodes and elements.
    let path = fixture("msh/box_gmsh22_binary.msh");
    let bytes = std::fs::read(&path).unwrap();
    let reference = read("box_gmsh22_binary.msh");
    let swapped = swap_msh22(&bytes);
    let (m, _) = qdem_mesh::parse_msh(&swapped, &path).unwrap();
    assert_eq!(m, reference);
}

/// Rewrites a little-endian MSH 2.2 binary file as big-endian.
fn swap_msh22(b: &[u8]) -> Vec<u8> {
    fn find(b: &[u8], from: usize, pat: &[u8]) -> usize {
        from + b[from..].windows(pat.len()).position(|w| w == pat).unwrap()
    }
    fn swap_words(b: &mut [u8], at: usize, sizes: &[usize]) -> usize {
        let mut p = at;
        for &s in sizes {
            b[p..p + s].reverse();
            p += s;
        }
        p
    }
    let mut out = b.to_vec();
    let marker = find(b, 0, b"2.2 1 8\n") + 8;
    out[marker..marker + 4].reverse();
    // Nodes.
    let nodes = find(b, 0, b"$Nodes\n") + 7;
    let eol = find(b, nodes, b"\n");
    let n: usize = std::str::from_utf8(&b[nodes..eol])
        .unwrap()
        .trim()
        .parse()
        .unwrap();
    let mut p = eol + 1;
    for _ in 0..n {
        p = swap_words(&mut out, p, &[4, 8, 8, 8]);
    }
    // Elements.
    let elems = find(b, 0, b"$Elements\n") + 10;
    let eol = find(b, elems, b"\n");
    let n: usize = std::str::from_utf8(&b[elems..eol])
        .unwrap()
        .trim()
        .parse()
        .unwrap();
    let mut p = eol + 1;
    let mut done = 0;
    let int = |b: &[u8], p: usize| i32::from_le_bytes(b[p..p + 4].try_into().unwrap()) as usize;
    while done < n {
        let (ty, follow, ntags) = (int(b, p), int(b, p + 4), int(b, p + 8));
        p = swap_words(&mut out, p, &[4, 4, 4]);
        let nn = qdem_mesh::element_info(ty as i32).unwrap().2;
        for _ in 0..follow * (1 + ntags + nn) {
            p = swap_words(&mut out, p, &[4]);
        }
        done += follow;
    }
    out
}
