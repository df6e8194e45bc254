//! A nearly incompressible material on linear tetrahedra (issue 43): `qdem check` and
//! `qdem run` warn of the locking and say what to use instead; with
//! `formulation = "averaged-pressure"` the scene runs, is told only of its bulk-wave step,
//! and its modes are computed.

mod common;

use common::{workspace, TempDir};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The lc = 0.1 m cantilever of a rubber-like material of Poisson's ratio 0.4999, clamped,
/// in `formulation` (`None`: the key left out).
fn scene(dir: &Path, formulation: Option<&str>) -> PathBuf {
    let mesh = workspace().join("fixtures/cantilever/cantilever_lc100.msh");
    let formulation = formulation.map_or(String::new(), |f| format!("formulation = {f:?}\n"));
    let text = format!(
        "[run]\nt_end = 2e-6\ndt = \"auto\"\n\n[[material]]\nname = \"rubber\"\ndensity = \
         1100.0\nyoung = 5e6\npoisson = 0.4999\n{formulation}\n[[body]]\nname = \"pad\"\nmesh \
         = {mesh:?}\nmaterial = \"rubber\"\n\n[[fix]]\nbody = \"pad\"\ngroup = \"clamp\"\ndofs \
         = \"xyz\"\n\n[output]\ndir = \"out\"\n"
    );
    let path = dir.join("pad.toml");
    std::fs::write(&path, text).unwrap();
    path
}

fn qdem(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_qdem"))
        .args(args)
        .args(["--threads", "2"])
        .env("CI", "1")
        .output()
        .expect("start the qdem binary")
}

/// Stdout and stderr of a command that must succeed.
fn success(args: &[&str]) -> (String, String) {
    let out = qdem(args);
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    );
    assert!(
        out.status.success(),
        "qdem {args:?} failed:\n{stderr}\n{stdout}"
    );
    (stdout, stderr)
}

#[test]
fn check_and_run_warn_of_locking_and_name_the_averaged_pressure_option() {
    let dir = TempDir::new("locking");
    let scene = scene(dir.path(), None);
    let path = scene.to_str().unwrap();
    let (stdout, _) = success(&["check", path]);
    let warning = stdout
        .lines()
        .find(|l| l.starts_with("warning: body `pad`"))
        .unwrap_or_else(|| panic!("no locking warning in:\n{stdout}"));
    for part in [
        "LOCK",
        "0.10x beam theory",
        "formulation = \"averaged-pressure\"",
        "bulk (dilatational) wave",
    ] {
        assert!(warning.contains(part), "`{part}` missing from: {warning}");
    }
    let out = dir.path().join("out");
    let (_, stderr) = success(&["run", path, "--out", out.to_str().unwrap()]);
    assert!(stderr.contains("LOCK"), "qdem run does not warn:\n{stderr}");
}

#[test]
fn an_averaged_pressure_material_runs_and_has_modes_with_only_its_step_noted() {
    let dir = TempDir::new("averaged");
    let scene = scene(dir.path(), Some("averaged-pressure"));
    let path = scene.to_str().unwrap();
    let (stdout, _) = success(&["check", path]);
    assert!(!stdout.contains("LOCK"), "{stdout}");
    assert!(stdout.contains("locking-free"), "{stdout}");
    assert!(stdout.contains("bulk (dilatational) wave"), "{stdout}");
    let out = dir.path().join("out");
    success(&["run", path, "--out", out.to_str().unwrap()]);
    let modes = dir.path().join("modes");
    success(&[
        "modes",
        path,
        "--count",
        "3",
        "--out",
        modes.to_str().unwrap(),
    ]);
    assert!(modes.join("modes.csv").is_file());
}

/// A static solve takes no explicit step (issue 55): for an averaged-pressure body neither
/// `qdem check` nor `qdem run` speaks of one, nor of the stable bound, and the run line
/// names its load levels.
#[test]
fn a_static_run_is_told_nothing_of_an_explicit_step() {
    let dir = TempDir::new("static-averaged");
    let scene = scene(dir.path(), Some("averaged-pressure"));
    let text = std::fs::read_to_string(&scene).unwrap().replace(
        "t_end = 2e-6\ndt = \"auto\"",
        "t_end = 1.0\nintegrator = \"static\"",
    );
    std::fs::write(&scene, text).unwrap();
    let path = scene.to_str().unwrap();
    let out = dir.path().join("out");
    let (check, _) = success(&["check", path]);
    let (_, run) = success(&["run", path, "--out", out.to_str().unwrap()]);
    for said in [&check, &run] {
        for word in ["explicit", "stable bound", "wave"] {
            assert!(!said.contains(word), "`{word}` in:\n{said}");
        }
    }
    assert!(run.contains("load levels every"), "{run}");
}

#[test]
fn an_unknown_formulation_is_refused_with_the_names_it_takes() {
    let dir = TempDir::new("formulation");
    let scene = scene(dir.path(), Some("b-bar"));
    let out = qdem(&["check", scene.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        stderr.contains("standard") && stderr.contains("averaged-pressure"),
        "{stderr}"
    );
}
