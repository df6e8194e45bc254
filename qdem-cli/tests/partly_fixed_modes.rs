//! `qdem modes` of a body fixed in some directions that keeps rigid-body motions (issue 43):
//! the paper's cantilever held only in z on its two end faces (simply supported) keeps its
//! in-plane motions (x, y translations and the rotation about z), which come out as rigid modes; under gravity (which does no work along them) it is accepted, and
//! under a load along x (which does) it is refused.

mod common;

use common::{workspace, TempDir};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn scene(dir: &Path, extra: &str) -> PathBuf {
    let mesh = workspace().join("fixtures/cantilever/cantilever_lc100.msh");
    let text = format!(
        "[run]\nt_end = 1.0\ndt = \"auto\"\n{extra}\n[[material]]\nname = \"concrete\"\ndensity \
         = 2350.0\nyoung = 45e9\npoisson = 0.167\n\n[[body]]\nname = \"beam\"\nmesh = \
         {mesh:?}\nmaterial = \"concrete\"\n\n[[fix]]\nbody = \"beam\"\ngroup = \
         \"clamp\"\ndofs = \"z\"\n\n[[fix]]\nbody = \"beam\"\ngroup = \"tip\"\ndofs = \"z\"\n"
    );
    let path = dir.join("held_in_z.toml");
    std::fs::write(&path, text).unwrap();
    path
}

fn modes(scene: &Path, out: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_qdem"))
        .args(["modes", scene.to_str().unwrap(), "--count", "5", "--out"])
        .arg(out)
        .args(["--threads", "2"])
        .env("CI", "1")
        .output()
        .expect("start the qdem binary")
}

#[test]
fn a_body_held_in_z_has_its_three_in_plane_rigid_modes_and_is_refused_only_when_pushed_along_them()
{
    let dir = TempDir::new("partly-fixed");
    let out = dir.path().join("modes");
    let held = scene(dir.path(), "gravity = [0.0, 0.0, -9.81]\n");
    let run = modes(&held, &out);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    let table = std::fs::read_to_string(out.join("modes.csv")).unwrap();
    let kinds: Vec<&str> = table
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(2).unwrap())
        .collect();
    assert_eq!(
        kinds,
        ["rigid", "rigid", "rigid", "elastic", "elastic"],
        "{table}"
    );
    for line in table.lines().skip(1).take(3) {
        let f: f64 = line.split(',').nth(1).unwrap().parse().unwrap();
        assert!(f < 1.0, "a rigid mode at {f} Hz");
    }
    let pushed = dir.path().join("pushed.toml");
    let text = std::fs::read_to_string(&held).unwrap()
        + "\n[[load]]\nbody = \"beam\"\ngroup = \"tip\"\ntotal_force = [100.0, 0.0, 0.0]\n";
    std::fs::write(&pushed, text).unwrap();
    let run = modes(&pushed, &dir.path().join("pushed"));
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success());
    assert!(stderr.contains("[[load]] #1"), "{stderr}");
}
