//! `qdem modes` end to end: its files and table on the paper's cantilever mesh, free and
//! clamped, and its refusals.

mod common;

use common::{workspace, TempDir};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const QDEM: &str = env!("CARGO_BIN_EXE_qdem");

/// A scene of the lc = 0.1 m cantilever mesh, clamped at x = 0 or free, in `dir`.
fn scene(dir: &Path, clamped: bool) -> PathBuf {
    let mesh = workspace().join("fixtures/cantilever/cantilever_lc100.msh");
    let fix = if clamped {
        "[[fix]]\nbody = \"beam\"\ngroup = \"clamp\"\ndofs = \"xyz\"\n"
    } else {
        ""
    };
    let text = format!(
        "[run]\nt_end = 1.0\ndt = \"auto\"\n\n[[material]]\nname = \"concrete\"\ndensity = \
         2350.0\nyoung = 45e9\npoisson = 0.167\nshear_viscosity = 0.0\nbulk_viscosity = \
         0.0\n\n[[body]]\nname = \"beam\"\nmesh = {mesh:?}\nmaterial = \"concrete\"\n\n{fix}"
    );
    let path = dir.join(if clamped { "clamped.toml" } else { "free.toml" });
    std::fs::write(&path, text).unwrap();
    path
}

fn modes(scene: &Path, count: &str, out: &Path) -> Output {
    Command::new(QDEM)
        .args(["modes", scene.to_str().unwrap(), "--count", count, "--out"])
        .arg(out)
        .args(["--threads", "2"])
        .env("CI", "1")
        .output()
        .expect("start the qdem binary")
}

/// The rows of modes.csv as (frequency, kind, direction).
fn rows(csv: &str) -> Vec<(f64, String, String)> {
    csv.lines()
        .skip(1)
        .map(|line| {
            let cells: Vec<&str> = line.split(',').collect();
            assert_eq!(cells.len(), 14, "{line}");
            (cells[1].parse().unwrap(), cells[2].into(), cells[3].into())
        })
        .collect()
}

#[test]
fn free_beam_lists_six_rigid_modes_first_then_its_elastic_modes() {
    let dir = TempDir::new("modes-free");
    let out = modes(&scene(dir.path(), false), "9", &dir.path().join("out"));
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let csv = std::fs::read_to_string(dir.path().join("out/modes.csv")).unwrap();
    assert_eq!(
        String::from_utf8_lossy(&out.stdout),
        csv,
        "the table printed is the file"
    );
    assert!(csv.starts_with(
        "mode,frequency_hz,kind,direction,participation,mass_x,mass_y,mass_z,mass_rx,mass_ry,mass_rz,motion_x,motion_y,motion_z\n"
    ));
    let rows = rows(&csv);
    assert_eq!(rows.len(), 9);
    assert!(rows[..6]
        .iter()
        .all(|(f, kind, _)| *f < 1.0 && kind == "rigid"));
    let mut directions: Vec<&str> = rows[..6].iter().map(|r| r.2.as_str()).collect();
    directions.sort_unstable();
    assert_eq!(directions, ["rx", "ry", "rz", "x", "y", "z"]);
    // The free-free beam's first bending mode: well above the clamped one's 27 Hz.
    assert!(rows[6..]
        .iter()
        .all(|(f, kind, _)| *f > 100.0 && kind == "elastic"));
    assert!(rows.windows(2).skip(5).all(|w| w[0].0 <= w[1].0));
    let pvd = std::fs::read_to_string(dir.path().join("out/modes.pvd")).unwrap();
    for k in 1..=9 {
        let name = format!("vtu/mode_{k:04}.vtu");
        assert!(pvd.contains(&name), "{pvd}");
        assert!(dir.path().join("out").join(name).is_file());
    }
}

#[test]
fn clamped_beam_bends_vertically_first() {
    let dir = TempDir::new("modes-clamped");
    let out = modes(&scene(dir.path(), true), "2", &dir.path().join("out"));
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rows = rows(&String::from_utf8_lossy(&out.stdout));
    // The 0.22 m depth is the smaller: vertical (z) bending is the lowest mode, lateral (y)
    // the next; the coarse linear tets are stiff, so both lie above the converged 26.9 and
    // 30.5 Hz.
    assert_eq!((rows[0].2.as_str(), rows[1].2.as_str()), ("z", "y"));
    assert!(rows[0].0 > 26.874 && rows[1].0 > 30.482);
}

#[test]
fn more_modes_than_free_dofs_is_refused_naming_both_numbers() {
    let dir = TempDir::new("modes-too-many");
    let out = modes(&scene(dir.path(), false), "100000", &dir.path().join("out"));
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    // 352 nodes: 1056 free DOFs.
    assert!(
        stderr.starts_with("error: ") && stderr.contains("100000 modes") && stderr.contains("1056"),
        "{stderr}"
    );
    assert_eq!(stderr.matches("error:").count(), 1, "{stderr}");
}

#[test]
fn zero_modes_is_a_usage_error() {
    let dir = TempDir::new("modes-zero");
    let out = modes(&scene(dir.path(), true), "0", &dir.path().join("out"));
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("--count") && stderr.contains("positive whole number"),
        "{stderr}"
    );
}
