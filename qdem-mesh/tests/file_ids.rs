//! The file's numbering kept beside a mesh ([`qdem_mesh::FileIds`]): every node keeps its
//! file id and every tetrahedron its element id and physical volume through the reordering
//! and the merge of coincident nodes. Checked against the file itself, parsed here by hand
//! (the MSH 2.2 ASCII box of `fixtures/msh`, whose `body` volume has tag 1).

mod common;

use common::fixture;
use qdem_mesh::{read_msh, TetMesh};
use std::collections::HashMap;

/// A mesh file's nodes (id to coordinates) and tetrahedra (id to node ids).
type MshFile = (HashMap<u64, [f64; 3]>, HashMap<u64, [u64; 4]>);

/// The box's nodes and tetrahedra, from the file.
fn parse_msh22(text: &str) -> MshFile {
    let section = |name: &str| {
        let start = text.find(&format!("${name}\n")).unwrap() + name.len() + 2;
        let end = text.find(&format!("$End{name}")).unwrap();
        text[start..end].lines().skip(1).collect::<Vec<_>>()
    };
    let numbers = |line: &str| -> Vec<f64> {
        line.split_whitespace()
            .map(|w| w.parse().unwrap())
            .collect()
    };
    let nodes = section("Nodes")
        .into_iter()
        .map(|l| {
            let v = numbers(l);
            (v[0] as u64, [v[1], v[2], v[3]])
        })
        .collect();
    let tets = section("Elements")
        .into_iter()
        .map(numbers)
        .filter(|v| v[1] == 4.0)
        .map(|v| {
            let n = v.len();
            (
                v[0] as u64,
                [v[n - 4], v[n - 3], v[n - 2], v[n - 1]].map(|x| x as u64),
            )
        })
        .collect();
    (nodes, tets)
}

/// Every node of `mesh` sits where the file puts its id, and every tetrahedron has the
/// nodes of its element, in the physical volume `body` (tag 1).
fn assert_matches_file(mesh: &TetMesh, file: &MshFile) {
    let ids = &mesh.file_ids;
    assert_eq!(ids.nodes.len(), mesh.nodes.len());
    assert_eq!(ids.tets.len(), mesh.tets.len());
    assert_eq!(ids.volumes, vec![1; mesh.tets.len()]);
    for (p, id) in mesh.nodes.iter().zip(&ids.nodes) {
        assert_eq!(*p, file.0[id], "node {id}");
    }
    for (t, id) in mesh.tets.iter().zip(&ids.tets) {
        let mut got = t.map(|n| ids.nodes[n as usize]);
        let mut want = file.1[id];
        got.sort_unstable();
        want.sort_unstable();
        assert_eq!(got, want, "element {id}");
    }
}

#[test]
fn ids_follow_the_reordering() {
    let path = fixture("msh/box_gmsh22_ascii.msh");
    let file = parse_msh22(&std::fs::read_to_string(&path).unwrap());
    let (mut mesh, _) = read_msh(&path).unwrap();
    assert_eq!(mesh.tets.len(), file.1.len());
    assert_matches_file(&mesh, &file);
    let before = mesh.file_ids.clone();
    mesh.reorder_for_locality();
    // The reordering moved nodes and tetrahedra, so the check below is not the one above.
    assert_ne!(mesh.file_ids.nodes, before.nodes);
    assert_ne!(mesh.file_ids.tets, before.tets);
    assert_matches_file(&mesh, &file);
}

/// The box and its mirror image in its face x = 0.3 (the mirror's ids shifted past the
/// box's): merging the shared face keeps the box's ids there and every other node's own.
#[test]
fn merged_nodes_keep_the_first_ones_id() {
    let path = fixture("msh/box_gmsh22_ascii.msh");
    let (one, _) = read_msh(&path).unwrap();
    let mut two = one.clone();
    let offset = one.nodes.len() as u32;
    two.nodes
        .extend(one.nodes.iter().map(|p| [0.6 - p[0], p[1], p[2]]));
    two.tets
        .extend(one.tets.iter().map(|t| t.map(|n| n + offset)));
    let ids = &mut two.file_ids;
    ids.nodes
        .extend(one.file_ids.nodes.iter().map(|n| n + 1000));
    ids.tets.extend(one.file_ids.tets.iter().map(|n| n + 1000));
    ids.volumes.extend(&one.file_ids.volumes);
    let removed = two.merge_coincident_nodes();
    let face = one.nodes.iter().filter(|p| p[0] == 0.3).count();
    assert_eq!(removed, face);
    assert_eq!(two.file_ids.nodes.len(), two.nodes.len());
    for (p, id) in two.nodes.iter().zip(&two.file_ids.nodes) {
        let own = |id: u64| one.file_ids.nodes.iter().position(|&n| n == id).unwrap();
        let want = match *id > 1000 {
            true => one.nodes[own(id - 1000)],
            false => one.nodes[own(*id)],
        };
        let x = if *id > 1000 { 0.6 - want[0] } else { want[0] };
        assert_eq!(*p, [x, want[1], want[2]], "node {id}");
    }
}
