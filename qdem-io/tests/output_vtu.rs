//! VTU writer: exact round trip of a small mesh through a hand-written reader, validation
//! errors, and failure cleanup.

mod common;
use common::*;

use nalgebra::Vector3;
use qdem_io::output::{write_vtu, OutputError, VtuGrid};

fn b64_decode(text: &str) -> Vec<u8> {
    fn val(c: u8) -> u32 {
        match c {
            b'A'..=b'Z' => u32::from(c - b'A'),
            b'a'..=b'z' => u32::from(c - b'a') + 26,
            b'0'..=b'9' => u32::from(c - b'0') + 52,
            b'+' => 62,
            b'/' => 63,
            _ => panic!("invalid base64 character {:?}", c as char),
        }
    }
    let bytes = text.trim().as_bytes();
    assert_eq!(bytes.len() % 4, 0, "base64 length must be a multiple of 4");
    let mut out = Vec::with_capacity(bytes.len() / 4 * 3);
    for group in bytes.chunks(4) {
        let pad = group.iter().filter(|&&c| c == b'=').count();
        assert!(pad <= 2 && group[..4 - pad].iter().all(|&c| c != b'='));
        let mut v = 0u32;
        for &c in &group[..4 - pad] {
            v = (v << 6) | val(c);
        }
        v <<= 6 * pad as u32;
        let three = [(v >> 16) as u8, (v >> 8) as u8, v as u8];
        out.extend_from_slice(&three[..3 - pad]);
    }
    out
}

/// The value of attribute `name` in the start tag `tag`.
fn attr<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let key = format!(" {name}=\"");
    let start = tag.find(&key)? + key.len();
    let len = tag[start..].find('"')?;
    Some(&tag[start..start + len])
}

/// The DataArray named `name`: (its start tag, its decoded payload without the header).
fn data_array<'a>(xml: &'a str, name: &str) -> (&'a str, Vec<u8>) {
    let mut rest = xml;
    while let Some(i) = rest.find("<DataArray ") {
        let tag_end = i + rest[i..].find('>').unwrap();
        let tag = &rest[i..tag_end];
        let body_end = tag_end + rest[tag_end..].find("</DataArray>").unwrap();
        if attr(tag, "Name") == Some(name) {
            assert_eq!(attr(tag, "format"), Some("binary"), "{tag}");
            let raw = b64_decode(&rest[tag_end + 1..body_end]);
            let (header, payload) = raw.split_at(8);
            let n = u64::from_le_bytes(header.try_into().unwrap());
            assert_eq!(n as usize, payload.len(), "byte count header of {name}");
            return (tag, payload.to_vec());
        }
        rest = &rest[body_end..];
    }
    panic!("no DataArray named {name}");
}

fn f64s(bytes: &[u8]) -> Vec<u64> {
    bytes
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()).to_bits())
        .collect()
}

fn i64s(bytes: &[u8]) -> Vec<i64> {
    bytes
        .chunks_exact(8)
        .map(|c| i64::from_le_bytes(c.try_into().unwrap()))
        .collect()
}

fn vec_bits(v: &[Vector3<f64>]) -> Vec<u64> {
    v.iter()
        .flat_map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
        .collect()
}

fn two_tets() -> (Vec<Vector3<f64>>, Vec<[u32; 4]>) {
    let points = vec![
        Vector3::new(0.0, 0.0, 0.0),
        Vector3::new(1.0, 0.0, 0.0),
        Vector3::new(0.0, 1.0, 0.0),
        Vector3::new(0.0, 0.0, 1.0),
        Vector3::new(1.0 / 3.0, 0.7, 1.1),
    ];
    (points, vec![[0, 1, 2, 3], [1, 2, 3, 4]])
}

#[test]
fn two_tet_mesh_round_trips_bit_for_bit() {
    let dir = test_dir("vtu-roundtrip");
    let path = dir.join("mesh.vtu");
    let (points, tets) = two_tets();
    // Awkward values: negative zero, subnormal, tiny, huge, non-terminating, NaN.
    let displacement = vec![
        Vector3::new(-0.0, 5e-324, 1e-300),
        Vector3::new(1.0 / 7.0, -2.5e-7, f64::MAX),
        Vector3::new(0.1, 0.2, 0.3),
        Vector3::new(f64::NAN, f64::INFINITY, -1.0),
        Vector3::new(std::f64::consts::PI, -std::f64::consts::E, 1e16),
    ];
    let velocity: Vec<Vector3<f64>> = (0..5).map(|i| Vector3::repeat(i as f64 * 0.25)).collect();
    let von_mises = vec![1.5e6, -1.0 / 3.0];
    let grid = VtuGrid {
        points: &points,
        tets: &tets,
        point_vectors: vec![("displacement", &displacement), ("velocity", &velocity)],
        cell_scalars: vec![("von_mises", &von_mises)],
    };
    write_vtu(&path, &grid).unwrap();
    assert_eq!(entries(&dir), ["mesh.vtu"], "no temporary file left");

    let xml = std::fs::read_to_string(&path).unwrap();
    assert!(xml.starts_with("<?xml version=\"1.0\"?>\n"));
    let root = &xml[xml.find("<VTKFile").unwrap()..];
    let root = &root[..root.find('>').unwrap()];
    assert_eq!(attr(root, "type"), Some("UnstructuredGrid"));
    assert_eq!(attr(root, "byte_order"), Some("LittleEndian"));
    assert_eq!(attr(root, "header_type"), Some("UInt64"));
    assert!(xml.contains("<Piece NumberOfPoints=\"5\" NumberOfCells=\"2\">"));
    assert!(xml.trim_end().ends_with("</VTKFile>"));

    let (tag, bytes) = data_array(&xml, "Points");
    assert_eq!(attr(tag, "type"), Some("Float64"));
    assert_eq!(attr(tag, "NumberOfComponents"), Some("3"));
    assert_eq!(f64s(&bytes), vec_bits(&points));

    let (tag, bytes) = data_array(&xml, "displacement");
    assert_eq!(attr(tag, "type"), Some("Float64"));
    assert_eq!(attr(tag, "NumberOfComponents"), Some("3"));
    assert_eq!(f64s(&bytes), vec_bits(&displacement));

    let (_, bytes) = data_array(&xml, "velocity");
    assert_eq!(f64s(&bytes), vec_bits(&velocity));

    let (tag, bytes) = data_array(&xml, "von_mises");
    assert_eq!(attr(tag, "type"), Some("Float64"));
    assert_eq!(attr(tag, "NumberOfComponents"), None);
    let want: Vec<u64> = von_mises.iter().map(|v| v.to_bits()).collect();
    assert_eq!(f64s(&bytes), want);

    let (tag, bytes) = data_array(&xml, "connectivity");
    assert_eq!(attr(tag, "type"), Some("Int64"));
    assert_eq!(i64s(&bytes), [0, 1, 2, 3, 1, 2, 3, 4]);
    let (tag, bytes) = data_array(&xml, "offsets");
    assert_eq!(attr(tag, "type"), Some("Int64"));
    assert_eq!(i64s(&bytes), [4, 8]);
    let (tag, bytes) = data_array(&xml, "types");
    assert_eq!(attr(tag, "type"), Some("UInt8"));
    assert_eq!(bytes, [10, 10]);

    // Point and cell data sections precede Points and Cells, each inside its section.
    let pd = xml.find("<PointData").unwrap();
    let cd = xml.find("<CellData").unwrap();
    assert!(pd < xml.find("Name=\"displacement\"").unwrap());
    assert!(xml.find("Name=\"velocity\"").unwrap() < xml.find("</PointData>").unwrap());
    assert!(cd < xml.find("Name=\"von_mises\"").unwrap());
    assert!(xml.find("Name=\"von_mises\"").unwrap() < xml.find("</CellData>").unwrap());

    // Overwriting an existing file works and leaves no temporary file.
    let grid = VtuGrid {
        point_vectors: vec![],
        cell_scalars: vec![],
        ..grid
    };
    write_vtu(&path, &grid).unwrap();
    assert!(!std::fs::read_to_string(&path)
        .unwrap()
        .contains("displacement"));
    assert_eq!(entries(&dir), ["mesh.vtu"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn wrong_lengths_are_rejected_before_writing() {
    let dir = test_dir("vtu-lengths");
    let path = dir.join("bad.vtu");
    let (points, tets) = two_tets();
    let short = vec![Vector3::zeros(); 4];
    let grid = VtuGrid {
        points: &points,
        tets: &tets,
        point_vectors: vec![("displacement", &short)],
        cell_scalars: vec![],
    };
    match write_vtu(&path, &grid) {
        Err(OutputError::Length {
            path: p,
            name,
            expected,
            found,
        }) => {
            assert_eq!(
                (p, name.as_str(), expected, found),
                (path.clone(), "displacement", 5, 4)
            );
        }
        other => panic!("expected a Length error, got {other:?}"),
    }

    let too_many = [1.0, 2.0, 3.0];
    let grid = VtuGrid {
        points: &points,
        tets: &tets,
        point_vectors: vec![],
        cell_scalars: vec![("von_mises", &too_many)],
    };
    let err = write_vtu(&path, &grid).unwrap_err();
    assert!(
        matches!(&err, OutputError::Length { name, expected: 2, found: 3, .. } if name == "von_mises"),
        "{err:?}"
    );
    let msg = err.to_string();
    assert!(
        msg.contains("bad.vtu") && msg.contains("von_mises"),
        "{msg}"
    );

    let bad_tets = [[0, 1, 2, 3], [1, 2, 3, 5]];
    let grid = VtuGrid {
        points: &points,
        tets: &bad_tets,
        point_vectors: vec![],
        cell_scalars: vec![],
    };
    let err = write_vtu(&path, &grid).unwrap_err();
    assert!(
        matches!(
            err,
            OutputError::PointIndex {
                kind: "tetrahedron",
                cell: 1,
                index: 5,
                num_points: 5,
                ..
            }
        ),
        "{err:?}"
    );

    let u = vec![Vector3::zeros(); 5];
    let grid = VtuGrid {
        points: &points,
        tets: &tets,
        point_vectors: vec![("u", &u), ("u", &u)],
        cell_scalars: vec![],
    };
    let err = write_vtu(&path, &grid).unwrap_err();
    assert!(matches!(err, OutputError::InvalidName { .. }), "{err:?}");

    assert!(
        entries(&dir).is_empty(),
        "nothing written: {:?}",
        entries(&dir)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn io_failures_name_the_path_and_leave_no_temp_file() {
    let dir = test_dir("vtu-io");
    let (points, tets) = two_tets();
    let grid = VtuGrid {
        points: &points,
        tets: &tets,
        point_vectors: vec![],
        cell_scalars: vec![],
    };

    // Missing directory: the temporary file cannot be created.
    let path = dir.join("missing").join("out.vtu");
    let err = write_vtu(&path, &grid).unwrap_err();
    assert!(matches!(err, OutputError::Io { .. }), "{err:?}");
    let msg = err.to_string();
    assert!(msg.contains(&path.display().to_string()), "{msg}");
    assert!(msg.contains("VTU file"), "{msg}");
    assert!(entries(&dir).is_empty(), "{:?}", entries(&dir));

    // The target is a non-empty directory: writing succeeds, the rename fails; the
    // temporary file must be removed and the directory untouched.
    let path = dir.join("occupied.vtu");
    std::fs::create_dir(&path).unwrap();
    std::fs::write(path.join("keep"), "x").unwrap();
    let err = write_vtu(&path, &grid).unwrap_err();
    assert!(
        matches!(
            &err,
            OutputError::Io {
                stage: qdem_io::output::IoStage::Rename,
                ..
            }
        ),
        "{err:?}"
    );
    assert!(err.to_string().contains("occupied.vtu"), "{err}");
    assert_eq!(entries(&dir), ["occupied.vtu"]);
    assert_eq!(entries(&path), ["keep"]);
    std::fs::remove_dir_all(&dir).unwrap();
}
