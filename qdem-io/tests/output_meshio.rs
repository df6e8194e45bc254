//! VTU interoperability: a structured tet grid written by `write_vtu` is read back by
//! meshio (Python) and checked there (`tests/meshio_check.py`).
//!
//! meshio is required: this test fails (never skips) when it is missing.

use std::path::PathBuf;
use std::process::Command;

use nalgebra::{Matrix3, Vector3};
mod common;
use common::test_dir;
use qdem_io::output::{write_vtu, VtuGrid};

/// The linear field u(x) = A x + b; must match `A`, `B` in `tests/meshio_check.py`.
fn displacement_field(x: &Vector3<f64>) -> Vector3<f64> {
    let a = Matrix3::new(
        1.0e-3,
        2.0e-3,
        -5.0e-1,
        0.0,
        -3.0e-3,
        1.0 / 3.0,
        7.0,
        0.0,
        1.0e-6,
    );
    a * x + Vector3::new(0.1, -0.2, 0.25)
}

/// An `n`×`n`×`n` grid of cubes of edge `h`, each split into 6 positively oriented
/// tetrahedra around its main diagonal (Kuhn subdivision).
fn structured_tets(n: usize, h: f64) -> (Vec<Vector3<f64>>, Vec<[u32; 4]>) {
    let m = n + 1;
    let id = |i: usize, j: usize, k: usize| (i + m * (j + m * k)) as u32;
    let mut points = Vec::new();
    for k in 0..m {
        for j in 0..m {
            for i in 0..m {
                points.push(Vector3::new(i as f64, j as f64, k as f64) * h);
            }
        }
    }
    // Axis permutations with their parity.
    let perms = [
        ([0, 1, 2], true),
        ([1, 2, 0], true),
        ([2, 0, 1], true),
        ([0, 2, 1], false),
        ([2, 1, 0], false),
        ([1, 0, 2], false),
    ];
    let mut tets = Vec::new();
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                for (perm, even) in perms {
                    let mut c = [i, j, k];
                    let mut t = [id(i, j, k), 0, 0, 0];
                    for (slot, axis) in perm.into_iter().enumerate() {
                        c[axis] += 1;
                        t[slot + 1] = id(c[0], c[1], c[2]);
                    }
                    if !even {
                        t.swap(1, 2);
                    }
                    tets.push(t);
                }
            }
        }
    }
    (points, tets)
}

#[test]
fn meshio_reads_structured_grid() {
    let python_ok = Command::new("python3")
        .args(["-c", "import meshio"])
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false);
    assert!(python_ok, "meshio is required: pip install meshio");

    let (points, tets) = structured_tets(2, 0.5);
    assert_eq!((points.len(), tets.len()), (27, 48));
    let displacement: Vec<Vector3<f64>> = points.iter().map(displacement_field).collect();
    let velocity = vec![Vector3::new(1.0, 2.0, 3.0); points.len()];
    let cell_index: Vec<f64> = (0..tets.len()).map(|i| i as f64).collect();
    let volumetric_strain = vec![1e-3; tets.len()];
    let grid = VtuGrid {
        points: &points,
        tets: &tets,
        point_vectors: vec![("displacement", &displacement), ("velocity", &velocity)],
        cell_scalars: vec![
            ("cell_index", &cell_index),
            ("volumetric_strain", &volumetric_strain),
        ],
    };
    let dir = test_dir("meshio");
    let file = dir.join("grid.vtu");
    write_vtu(&file, &grid).unwrap();

    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/meshio_check.py");
    let out = Command::new("python3")
        .arg(&script)
        .arg(&file)
        .arg(points.len().to_string())
        .arg(tets.len().to_string())
        .output()
        .expect("run python3");
    assert!(
        out.status.success(),
        "{} failed ({}):\nstdout:\n{}\nstderr:\n{}",
        script.display(),
        out.status,
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
