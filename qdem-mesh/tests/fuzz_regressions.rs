//! Regressions from the fuzzing campaign (`docs/fuzzing.md`).
//!
//! The 10-minute libFuzzer runs of `msh_ascii` and `msh_binary` found no crash in inputs of
//! up to 21 KB (the largest seed). Two resource bugs lay beyond that size, in the physical
//! groups; they were found by reviewing the reader for work that grows faster than the file,
//! and confirmed with crafted files (the fuzz targets timed out or ran out of memory on them):
//!
//! 1. each group looked its name up in the whole `$PhysicalNames` list: quadratic in the number
//!    of names (the first test's 300 000 names took 94 s before the fix, in the test profile);
//! 2. each element pushed its nodes once per physical group of its entity before the sets were
//!    deduplicated: the second test's 850 KB file (one entity in 100 000 physical groups,
//!    20 000 tetrahedra on the same 4 nodes) would need over 32 GB; under a 6 GB limit the test
//!    aborted.
//!
//! All three tests take 0.4 s together after the fix. The files are generated here rather than
//! committed (they are large). Speed is not asserted here (no timed tests): a return of the
//! quadratic behaviour shows as a test that takes minutes.

use std::path::Path;

use qdem_mesh::{parse_msh, MeshError, MAX_GROUP_ENTRIES_PER_NODE};

/// A valid MSH 2.2 ASCII file: one tetrahedron (nodes 1-4, in physical volume 1), with
/// `names` extra physical names of surfaces 10, 11, ... that no element uses.
fn many_names_22(names: usize) -> String {
    let mut text = String::from("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n");
    text.push_str(&format!("$PhysicalNames\n{}\n3 1 \"body\"\n", names + 2));
    for k in 0..names {
        text.push_str(&format!("2 {} \"g{k}\"\n", k + 10));
    }
    // A second name for group (3, 1): the first one wins.
    text.push_str("3 1 \"second name\"\n$EndPhysicalNames\n");
    text.push_str("$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n");
    text.push_str("$Elements\n1\n1 4 2 1 1 1 2 3 4\n$EndElements\n");
    text
}

#[test]
fn many_physical_names_are_read_in_linear_time() {
    let names = 300_000;
    let text = many_names_22(names);
    let (mesh, warnings) = parse_msh(text.as_bytes(), Path::new("names.msh")).unwrap();
    assert_eq!(mesh.groups.len(), names + 1);
    let body = mesh.group("body").unwrap();
    assert_eq!(
        (body.dim, body.tag, body.nodes.as_slice()),
        (3, 1, &[0, 1, 2, 3][..])
    );
    assert!(mesh.group("second name").is_none());
    let last = mesh.group(&format!("g{}", names - 1)).unwrap();
    assert_eq!((last.dim, last.tag), (2, (names + 9) as i32));
    assert!(last.nodes.is_empty());
    // Every unused name is reported as an empty group.
    assert_eq!(warnings.len(), names);
}

/// A valid MSH 4.1 ASCII file: one volume entity in physical groups 1..=`groups`, holding
/// `tets` tetrahedra. With `spread`, tetrahedron k has its own 4 nodes (4 · `tets` nodes);
/// otherwise all tetrahedra (distinct ids) share nodes 1-4.
fn entity_in_many_groups_41(groups: usize, tets: usize, spread: bool) -> String {
    let mut text = String::from("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n0 0 0 1\n");
    text.push_str(&format!("1 0 0 0 1 1 1 {groups}"));
    for g in 1..=groups {
        text.push_str(&format!(" {g}"));
    }
    text.push_str(" 0\n$EndEntities\n");
    let corners = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]];
    let nodes = if spread { 4 * tets } else { 4 };
    text.push_str(&format!("$Nodes\n1 {nodes} 1 {nodes}\n3 1 0 {nodes}\n"));
    for id in 1..=nodes {
        text.push_str(&format!("{id}\n"));
    }
    for k in 0..nodes {
        let c = corners[k % 4];
        let shift = 2 * (k / 4);
        text.push_str(&format!("{} {} {}\n", c[0] + shift, c[1], c[2]));
    }
    text.push_str(&format!(
        "$EndNodes\n$Elements\n1 {tets} 1 {tets}\n3 1 4 {tets}\n"
    ));
    for k in 0..tets {
        let first = if spread { 4 * k + 1 } else { 1 };
        text.push_str(&format!(
            "{} {} {} {} {}\n",
            k + 1,
            first,
            first + 1,
            first + 2,
            first + 3
        ));
    }
    text.push_str("$EndElements\n");
    text
}

#[test]
fn an_entity_in_many_groups_is_walked_once() {
    // 100 000 groups × 20 000 tetrahedra: the node sets are 4 nodes each, 400 000 entries.
    let (groups, tets) = (100_000, 20_000);
    let text = entity_in_many_groups_41(groups, tets, false);
    let (mesh, _) = parse_msh(text.as_bytes(), Path::new("groups.msh")).unwrap();
    assert_eq!(mesh.tets.len(), tets);
    assert_eq!(mesh.groups.len(), groups);
    assert!(mesh.groups.iter().all(|g| g.nodes == [0, 1, 2, 3]));
}

#[test]
fn node_sets_beyond_the_limit_are_an_error() {
    // 300 groups on 1000 tetrahedra with their own nodes: 300 × 4000 = 1.2 million entries,
    // above the limit of a 4000-node mesh (max(64 × 4000, 2^20) = 1 048 576).
    let text = entity_in_many_groups_41(300, 1000, true);
    let err = parse_msh(text.as_bytes(), Path::new("groups.msh")).unwrap_err();
    match &err {
        MeshError::TooManyGroupEntries {
            entries,
            limit,
            nodes,
            element_id,
            groups,
            ..
        } => {
            assert_eq!(*entries, 1_200_000);
            assert_eq!(*limit, 1 << 20);
            assert_eq!(*nodes, 4000);
            assert_eq!(*element_id, 1);
            assert_eq!(*groups, 300);
        }
        other => panic!("expected TooManyGroupEntries, got {other:?}"),
    }
    let message = err.to_string();
    assert!(message.starts_with("groups.msh: "), "{message}");
    assert!(
        message.contains("element 1 is in 300 physical groups"),
        "{message}"
    );
    assert!(message.contains("fix: "), "{message}");

    // Under the limit the same layout reads: 200 × 4000 = 800 000 entries.
    let text = entity_in_many_groups_41(200, 1000, true);
    let (mesh, _) = parse_msh(text.as_bytes(), Path::new("groups.msh")).unwrap();
    assert_eq!(mesh.groups.len(), 200);
    assert!(mesh.groups.iter().all(|g| g.nodes.len() == 4000));
    assert_eq!(MAX_GROUP_ENTRIES_PER_NODE, 64);
}
