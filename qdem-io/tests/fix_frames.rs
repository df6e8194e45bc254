//! `[[fix]]` with `frame` as a scene gives it: the reactions of a framed fix sharing nodes with
//! an axis fix, each reported in its own frame, and the nodes a frame cannot hold refused at
//! build (a node on a cylindrical frame's axis; two fixes holding one node in oblique
//! directions).
//!
//! The block is the gmsh box 0.3 × 0.2 × 0.1 m of `fixtures/msh` (groups `left` x = 0,
//! `right` x = 0.3), solved statically, as in `fem_findings.rs`.

mod common;

use common::{fixture, test_dir};
use qdem_io::build::{BuildError, Simulation};
use qdem_io::runner::run;
use qdem_io::scene::Scene;
use std::path::Path;

/// Face x = 0.3's area (m²).
const AREA: f64 = 0.2 * 0.1;

/// The box in `dir`, clamped on `left` by `fixes`, under the traction (tx, 0, tz) on `right`.
fn block(dir: &Path, fixes: &str, (tx, tz): (f64, f64)) -> Scene {
    let mesh = fixture("msh/box_gmsh22_ascii.msh");
    let text = format!(
        "[run]\nt_end = 1.0\ndt = 1.0\nintegrator = \"static\"\nprobe_every = 1.0\n\n\
         [[material]]\nname = \"m\"\ndensity = 2400.0\nyoung = 45e9\npoisson = 0.2\n\n\
         [[body]]\nname = \"block\"\nmesh = {mesh:?}\nmaterial = \"m\"\n\n\
         {fixes}\n\n[[load]]\nbody = \"block\"\ngroup = \"right\"\n\
         traction = [{tx:e}, 0.0, {tz:e}]\n"
    );
    let path = dir.join("block.toml");
    std::fs::write(&path, text).unwrap();
    Scene::load(&path).unwrap()
}

/// An xyz fix and a fix in the basis e₁ = y, e₂ = −x, e₃ = z holding "12" (x and y again, in
/// its own names) on the clamp face; the free end under t = (tx, 0, tz). A direction both
/// hold is shared half and half, each fix giving its half in its own frame: the xyz fix
/// −tx·A/2 in x and all of −tz·A in z; the framed one e₂·(−t·A)/2 = tx·A/2 in `f2`, nothing
/// in `f1` (y carries no load) or `f3` (it does not hold z). The fixes' reactions read on
/// the axes sum to −t·A; the static solve's rounding and the CSV's nine digits bound the
/// check at 10⁻⁷ of the load.
#[test]
fn a_framed_fix_sharing_nodes_reports_its_share_in_its_frame() {
    let dir = test_dir("fix-frames-shared");
    let (tx, tz): (f64, f64) = (-2.5e5, 1.0e5);
    let scene = block(
        &dir,
        "[[fix]]\nbody = \"block\"\ngroup = \"left\"\n\n\
         [[fix]]\nbody = \"block\"\ngroup = \"left\"\n\
         frame = [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]\ndofs = \"12\"",
        (tx, tz),
    );
    let mut sim = Simulation::build(scene).unwrap();
    let out = dir.join("out");
    run(&mut sim, &out, &mut |_| {}).unwrap();
    let columns = common::columns(&out.join("reactions.csv"));
    let last = |name: &str| {
        *columns
            .get(name)
            .unwrap_or_else(|| panic!("no column {name}"))
            .last()
            .unwrap()
    };
    let load = tx.abs().max(tz.abs()) * AREA;
    for (name, want) in [
        ("fix1_fx", -tx * AREA / 2.0),
        ("fix1_fy", 0.0),
        ("fix1_fz", -tz * AREA),
        ("fix2_f1", 0.0),
        ("fix2_f2", tx * AREA / 2.0),
        ("fix2_f3", 0.0),
    ] {
        let got = last(name);
        assert!(
            (got - want).abs() <= 1e-7 * load,
            "{name} = {got} N, want {want} N"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The build's message for the scene in `dir` with `fixes`.
fn refused(dir: &Path, fixes: &str) -> String {
    match Simulation::build(block(dir, fixes, (1e5, 0.0))) {
        Err(e @ BuildError::FixFrame { .. }) => e.to_string(),
        Err(other) => panic!("refused for another reason: {other}"),
        Ok(_) => panic!("built"),
    }
}

/// A cylindrical frame about the z axis cannot hold the clamp face's nodes on that axis
/// (x = y = 0: no radial direction); two fixes holding a node in directions at 30° cannot
/// split its force. Both are refused naming the fixes, the node and the fix.
#[test]
fn nodes_a_frame_cannot_hold_are_refused() {
    let dir = test_dir("fix-frames-refused");
    let msg = refused(
        &dir,
        "[[fix]]\nbody = \"block\"\ngroup = \"left\"\nframe = \"cylindrical\"\n\
         axis = [0.0, 0.0, 1.0]\ndofs = \"t\"",
    );
    assert!(
        msg.contains("[[fix]] #1") && msg.contains("lies on the axis"),
        "{msg}"
    );
    assert!(msg.contains("leave the axis's nodes out"), "{msg}");
    let (s, c) = 30f64.to_radians().sin_cos();
    let msg = refused(
        &dir,
        &format!(
            "[[fix]]\nbody = \"block\"\ngroup = \"left\"\ndofs = \"x\"\n\n\
             [[fix]]\nbody = \"block\"\ngroup = \"left\"\n\
             frame = [[{c:?}, {s:?}, 0.0], [{:?}, {c:?}, 0.0], [0.0, 0.0, 1.0]]\ndofs = \"13\"",
            -s
        ),
    );
    assert!(
        msg.contains("[[fix]] #1 and [[fix]] #2") && msg.contains("30.0000°"),
        "{msg}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
