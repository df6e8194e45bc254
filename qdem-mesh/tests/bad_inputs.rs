//! Each bad-input fixture gives the expected error or warning, and its message names the file
//! and the line or element id. Plus small hand-written inputs for the other error paths.

mod common;

use std::path::Path;

use common::{fixture, rel};
use qdem_mesh::{parse_msh, read_msh, Location, MeshError, MeshWarning};

fn read_err(name: &str) -> (MeshError, String) {
    let path = fixture(&format!("msh/{name}"));
    let err = read_msh(&path).expect_err(name);
    let msg = err.to_string();
    assert!(msg.contains(name), "message does not name the file: {msg}");
    assert!(msg.contains("fix"), "message has no fix: {msg}");
    (err, msg)
}

fn parse_err(text: &str) -> (MeshError, String) {
    let err = parse_msh(text.as_bytes(), Path::new("mem.msh")).expect_err(text);
    let msg = err.to_string();
    assert!(
        msg.contains("mem.msh"),
        "message does not name the file: {msg}"
    );
    assert!(
        msg.contains("fix") || msg.contains("mesh the volume"),
        "message has no fix: {msg}"
    );
    (err, msg)
}

#[test]
fn truncated_file() {
    let (err, msg) = read_err("bad_truncated41.msh");
    let lines = std::fs::read_to_string(fixture("msh/bad_truncated41.msh"))
        .unwrap()
        .lines()
        .count();
    assert!(
        matches!(err, MeshError::Truncated { location: Location::Line(l), .. } if l == lines),
        "{err:?}"
    );
    assert!(
        msg.contains(&format!("bad_truncated41.msh:{lines}")),
        "{msg}"
    );
    assert!(msg.contains("truncated"), "{msg}");
}

#[test]
fn hexahedron_is_rejected() {
    let (err, msg) = read_err("bad_hexahedron.msh");
    assert!(
        matches!(
            err,
            MeshError::UnsupportedElement {
                element_id: 10,
                type_id: 5,
                ..
            }
        ),
        "{err:?}"
    );
    assert!(
        msg.contains("element 10 ") && msg.contains("Hexahedron 8"),
        "{msg}"
    );
    assert!(
        msg.contains("Mesh.ElementOrder = 1") && msg.contains("Recombine3DAll"),
        "{msg}"
    );
}

#[test]
fn second_order_tetrahedra_are_rejected() {
    let (err, msg) = read_err("bad_tet10.msh");
    assert!(
        matches!(
            err,
            MeshError::UnsupportedElement {
                element_id: 18,
                type_id: 11,
                ..
            }
        ),
        "{err:?}"
    );
    assert!(
        msg.contains("element 18 ") && msg.contains("Tetrahedron 10"),
        "{msg}"
    );
}

#[test]
fn inverted_tet_is_reoriented_with_a_warning() {
    let (mesh, warnings) = read_msh(&fixture("msh/bad_inverted22.msh")).unwrap();
    assert_eq!(
        warnings,
        [MeshWarning::ReorientedTets {
            count: 1,
            first_element_id: 46
        }]
    );
    assert!(warnings[0].to_string().contains("element 46"));
    assert!((0..mesh.tets.len()).all(|t| mesh.tet_volume(t) > 0.0));
    assert!(rel(mesh.volume(), 0.3 * 0.2 * 0.1) < 1e-12);
}

#[test]
fn degenerate_tet_is_an_error() {
    let (err, msg) = read_err("bad_degenerate22.msh");
    assert!(
        matches!(
            err,
            MeshError::DegenerateTet {
                element_id: 2,
                nodes: [2, 5, 3, 6],
                ..
            }
        ),
        "{err:?}"
    );
    assert!(
        msg.contains("tetrahedron 2 ") && msg.contains("(0.5, 0.5, 0)"),
        "{msg}"
    );
    assert!(msg.contains("remove duplicate nodes"), "{msg}");
}

#[test]
fn unused_node_is_dropped_with_a_warning() {
    let (mesh, warnings) = read_msh(&fixture("msh/bad_unused_node22.msh")).unwrap();
    assert_eq!(
        warnings,
        [MeshWarning::DroppedUnusedNodes {
            count: 1,
            first_node_id: 127
        }]
    );
    assert!(warnings[0].to_string().contains("node 127"));
    let (reference, _) = read_msh(&fixture("msh/box_gmsh22_ascii.msh")).unwrap();
    assert_eq!(mesh, reference);
}

#[test]
fn undefined_node_is_an_error() {
    let (err, msg) = read_err("bad_undefined_node22.msh");
    assert!(
        matches!(
            err,
            MeshError::UndefinedNode {
                element_id: 46,
                node_id: 999_999,
                ..
            }
        ),
        "{err:?}"
    );
    assert!(
        msg.contains("element 46") && msg.contains("999999"),
        "{msg}"
    );
}

const HEAD22: &str = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n";
const NODES22: &str = "$Nodes\n5\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 9 9 9\n$EndNodes\n";

#[test]
fn unparseable_number_names_the_line() {
    let text = format!("{HEAD22}$Nodes\n2\n1 0 0 0\n2 1 zero 0\n$EndNodes\n");
    let (err, msg) = parse_err(&text);
    assert!(
        matches!(
            err,
            MeshError::BadNumber {
                location: Location::Line(7),
                ..
            }
        ),
        "{err:?}"
    );
    assert!(msg.contains("mem.msh:7") && msg.contains("`zero`"), "{msg}");
}

#[test]
fn missing_end_marker_is_truncation() {
    let text = format!("{HEAD22}{NODES22}$Elements\n1\n1 4 2 1 1 1 2 3 4\n");
    let (err, msg) = parse_err(&text);
    assert!(matches!(err, MeshError::Truncated { .. }), "{err:?}");
    assert!(
        msg.contains("truncated") && msg.contains("$EndElements"),
        "{msg}"
    );
}

#[test]
fn a_small_valid_22_file_with_extras() {
    // An unnamed physical surface, an element of unknown type (ignored with a warning), an
    // unknown section (skipped), a group whose only node is not in a tetrahedron.
    let text = format!(
        "{HEAD22}$Comments\nanything $Nodes\n$EndComments\n{NODES22}$Elements\n4\n\
         1 4 2 1 1 1 2 3 4\n2 2 2 7 3 1 2 3\n3 999 2 0 0 1 2\n4 15 2 8 4 5\n$EndElements\n"
    );
    let (mesh, warnings) = parse_msh(text.as_bytes(), Path::new("mem.msh")).unwrap();
    assert_eq!(mesh.nodes.len(), 4);
    assert_eq!(mesh.tets, [[0, 1, 2, 3]]);
    let names: Vec<&str> = mesh.groups.iter().map(|g| g.name.as_str()).collect();
    assert_eq!(names, ["0:8", "2:7", "3:1"]);
    assert_eq!(mesh.group("2:7").unwrap().nodes, [0, 1, 2]);
    assert!(warnings.contains(&MeshWarning::IgnoredUnknownElements {
        type_id: 999,
        count: 1,
        first_element_id: 3
    }));
    assert!(warnings.contains(&MeshWarning::DroppedUnusedNodes {
        count: 1,
        first_node_id: 5
    }));
    assert!(warnings.contains(&MeshWarning::EmptyGroup {
        name: "0:8".into(),
        dim: 0,
        tag: 8
    }));
}

#[test]
fn duplicate_tets_from_two_physical_volumes_are_merged() {
    let text = format!(
        "{HEAD22}$PhysicalNames\n2\n3 1 \"a b\"\n3 2 \"c\"\n$EndPhysicalNames\n{NODES22}$Elements\n2\n\
         1 4 2 1 1 1 2 4 3\n1 4 2 2 1 1 2 4 3\n$EndElements\n"
    );
    let (mesh, warnings) = parse_msh(text.as_bytes(), Path::new("mem.msh")).unwrap();
    assert_eq!(mesh.tets, [[0, 1, 2, 3]]);
    assert_eq!(mesh.group("a b").unwrap().nodes, [0, 1, 2, 3]);
    assert_eq!(mesh.group("c").unwrap().nodes, [0, 1, 2, 3]);
    assert!(warnings.contains(&MeshWarning::DuplicateTets {
        count: 1,
        first_element_id: 1
    }));
    assert!(warnings.contains(&MeshWarning::ReorientedTets {
        count: 1,
        first_element_id: 1
    }));
    let missing = mesh
        .require_group("clamp", Path::new("mem.msh"))
        .unwrap_err()
        .to_string();
    assert!(
        missing.contains("\"clamp\"") && missing.contains("\"a b\", \"c\""),
        "{missing}"
    );
}

#[test]
fn other_errors() {
    let (e, _) = parse_err("hello\n");
    assert!(matches!(e, MeshError::NotMsh { .. }), "{e:?}");
    let (e, _) = parse_err("$MeshFormat\n3.0 0 8\n$EndMeshFormat\n");
    assert!(matches!(e, MeshError::UnsupportedVersion { .. }), "{e:?}");
    let (e, _) = parse_err("$MeshFormat\n4.0 0 8\n$EndMeshFormat\n");
    assert!(matches!(e, MeshError::UnsupportedVersion { .. }), "{e:?}");
    let (e, msg) = parse_err(
        "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PartitionedEntities\n1\n$EndPartitionedEntities\n",
    );
    assert!(matches!(e, MeshError::Partitioned { .. }), "{e:?}");
    assert!(msg.contains("re-save without partitions"), "{msg}");
    let (e, msg) = parse_err(&format!("{HEAD22}{NODES22}"));
    assert!(matches!(e, MeshError::NoTetrahedra { .. }), "{e:?}");
    assert!(
        msg.contains("no tetrahedra (type 4) in mem.msh") && msg.contains("gmsh -3"),
        "{msg}"
    );
    let (e, _) = parse_err(&format!("{HEAD22}$Nodes\n2\n1 0 0 0\n1 1 0 0\n$EndNodes\n$Elements\n1\n1 4 0 1 1 1 1\n$EndElements\n"));
    assert!(
        matches!(e, MeshError::DuplicateNode { node_id: 1, .. }),
        "{e:?}"
    );
    // Hostile counts: never allocate, report truncation.
    let (e, _) = parse_err(&format!("{HEAD22}$Nodes\n99999999999999\n$EndNodes\n"));
    assert!(matches!(e, MeshError::Truncated { .. }), "{e:?}");
    let (e, _) = parse_err(&format!("{HEAD22}$Nodes\n-3\n$EndNodes\n"));
    assert!(matches!(e, MeshError::BadNumber { .. }), "{e:?}");
    let (e, _) = parse_err(&format!("{HEAD22}$Nodes\n1\n1 0 0 nan\n$EndNodes\n"));
    assert!(matches!(e, MeshError::BadNumber { .. }), "{e:?}");
    // Count smaller than the data.
    let (e, _) = parse_err(&format!("{HEAD22}$Nodes\n1\n1 0 0 0\n2 0 0 0\n$EndNodes\n"));
    assert!(
        matches!(
            e,
            MeshError::Malformed {
                location: Location::Line(7),
                ..
            }
        ),
        "{e:?}"
    );
}

#[test]
fn binary_errors_report_byte_offsets() {
    let mut bytes = b"$MeshFormat\n2.2 1 8\n".to_vec();
    bytes.extend_from_slice(&1i32.to_le_bytes());
    bytes.extend_from_slice(b"\n$EndMeshFormat\n$Nodes\n3\n");
    bytes.extend_from_slice(&1i32.to_le_bytes());
    let e = parse_msh(&bytes, Path::new("b.msh")).unwrap_err();
    assert!(
        matches!(
            e,
            MeshError::Truncated {
                location: Location::Byte(_),
                ..
            }
        ),
        "{e:?}"
    );
    assert!(e.to_string().contains("b.msh: byte offset"), "{e}");
    // Bad endianness marker.
    let mut bytes = b"$MeshFormat\n2.2 1 8\n".to_vec();
    bytes.extend_from_slice(&7i32.to_le_bytes());
    bytes.extend_from_slice(b"\n$EndMeshFormat\n");
    let e = parse_msh(&bytes, Path::new("b.msh")).unwrap_err();
    assert!(
        matches!(
            e,
            MeshError::Malformed {
                location: Location::Byte(20),
                ..
            }
        ),
        "{e:?}"
    );
}

/// A unit tetrahedron scaled by 3.5e300 (coordinates in a wrong unit): its volume overflows.
/// The message names the overflow and the unit, not duplicate nodes, and prints each
/// coordinate in a few characters (the full digits of 3.5e300 are 301 characters each).
#[test]
fn a_tetrahedron_whose_volume_overflows_is_named_as_such_in_a_short_message() {
    let s = 3.5e300;
    let text = format!(
        "{HEAD22}$Nodes\n4\n1 0 0 0\n2 {s} 0 0\n3 0 {s} 0\n4 0 0 {s}\n$EndNodes\n\
         $Elements\n1\n1 4 2 1 1 1 2 3 4\n$EndElements\n"
    );
    let (err, msg) = parse_err(&text);
    assert!(
        matches!(
            err,
            MeshError::OverflowingTet {
                element_id: 1,
                nodes: [1, 2, 3, 4],
                ..
            }
        ),
        "{err:?}"
    );
    assert!(
        msg.contains("overflows")
            && msg.contains("(3.5e300, 0, 0)")
            && msg.contains("is 3.500e300 m across")
            && msg.contains("fix: check the mesh's unit and scale"),
        "{msg}"
    );
    assert!(!msg.contains("duplicate"), "{msg}");
    assert!(msg.len() < 600, "{} characters:\n{msg}", msg.len());
}

/// A degenerate tetrahedron far from the origin prints its corners in exponent form.
#[test]
fn a_degenerate_tetrahedron_far_away_prints_short_coordinates() {
    let text = format!(
        "{HEAD22}$Nodes\n4\n1 1e30 0 0\n2 1e30 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n\
         $Elements\n1\n1 4 2 1 1 1 2 3 4\n$EndElements\n"
    );
    let (_, msg) = parse_err(&text);
    assert!(
        msg.contains("(1e30, 0, 0)") && msg.contains("degenerate"),
        "{msg}"
    );
    assert!(msg.len() < 600, "{} characters:\n{msg}", msg.len());
}
