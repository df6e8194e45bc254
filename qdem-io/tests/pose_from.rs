//! `poses.csv` and `[[body]] pose_from` (`qdem_io::pose_from`): a rigid block pushed off
//! centre in zero gravity moves and turns; a second scene with the same design placement and
//! `pose_from` the first run's `poses.csv` must start with every node where the first run
//! left it, and a third, chained on the second after it has turned further, likewise — the
//! pose is measured from the design placement, not from the run's start. A body of another
//! name placed with `pose_body` and `pose_shift` starts as the first run's block moved by the
//! shift.

mod common;

use common::{fixture, test_dir};
use qdem_core::Vec3;
use qdem_io::build::Simulation;
use qdem_io::pose_from::{poses, write_poses_csv};
use qdem_io::scene::Scene;
use std::path::Path;

/// The block of `fixtures/contact/block.msh`, tilted and shifted in its design placement,
/// pushed up on its x > 0 half so that it translates and spins; `body` its name, `pose` the
/// lines that place it (`pose_from` and the rest).
fn scene(dir: &Path, name: &str, body: &str, pose: &str) -> Scene {
    let mesh = fixture("contact/block.msh");
    let text = format!(
        r#"[run]
t_end = 0.02
dt = 1e-4

[[material]]
name = "concrete"
density = 2400.0
young = 30e9
poisson = 0.2

[[body]]
name = "{body}"
mesh = {mesh:?}
material = "concrete"
rigid = true
rotate_deg = [10.0, -25.0, 40.0]
translate = [0.3, -0.2, 0.5]
{pose}
[[load]]
body = "{body}"
box = [[0.3, -1.0, -1.0], [1.0, 1.0, 1.0]]
total_force = [0.0, 20.0, 50.0]

[output]
dir = "out"
"#,
        mesh = mesh.display().to_string()
    );
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    Scene::load(&path).unwrap()
}

/// Builds `scene`, steps it to its `t_end`, writes its poses to `dir/name.csv` and returns the
/// block's node positions at the start and at the end.
fn run(scene: Scene, dir: &Path, name: &str) -> (Vec<Vec3>, Vec<Vec3>) {
    let mut sim = Simulation::build(scene).unwrap();
    let nodes = sim.bodies[0].particles.clone();
    let start = sim.world.state.position[nodes.clone()].to_vec();
    sim.world.initialize().unwrap();
    while sim.world.state.time < sim.scene.run.t_end {
        sim.world.step().unwrap();
    }
    write_poses_csv(&dir.join(format!("{name}.csv")), &poses(&sim)).unwrap();
    (start, sim.world.state.position[nodes].to_vec())
}

/// `pose_from = FILE`.
fn from(file: &Path) -> String {
    format!("pose_from = {:?}\n", file.display().to_string())
}

/// Largest distance between corresponding nodes.
fn gap(a: &[Vec3], b: &[Vec3]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).norm())
        .fold(0.0, f64::max)
}

#[test]
fn a_body_placed_from_poses_starts_where_the_earlier_runs_left_it() {
    let dir = test_dir("pose_from");
    let (design, end_a) = run(scene(&dir, "a", "block", ""), &dir, "a");
    // The block has moved and turned: nodes some millimetres away from the design placement.
    let moved = gap(&design, &end_a);
    assert!(moved > 1e-3, "the block moved only {moved} m");
    let (start_b, end_b) = run(
        scene(&dir, "b", "block", &from(&dir.join("a.csv"))),
        &dir,
        "b",
    );
    let d_b = gap(&start_b, &end_a);
    let (start_c, _) = run(
        scene(&dir, "c", "block", &from(&dir.join("b.csv"))),
        &dir,
        "c",
    );
    let d_c = gap(&start_c, &end_b);
    eprintln!("moved {moved:.3e} m; start of b vs end of a {d_b:.1e} m, c vs b {d_c:.1e} m");
    // Rounding only: the block is 0.1 m across, positions are written with 17 digits.
    assert!(d_b < 1e-12, "b starts {d_b} m from where a ended");
    assert!(d_c < 1e-12, "c starts {d_c} m from where b ended");
}

#[test]
fn a_body_takes_another_bodys_pose_shifted_by_pose_shift() {
    let dir = test_dir("pose_body");
    let (_, end_a) = run(scene(&dir, "a", "block", ""), &dir, "a");
    let shift = Vec3::new(0.0, 0.7, -0.05);
    let place = format!(
        "{}pose_body = \"block\"\npose_shift = [{}, {}, {}]\n",
        from(&dir.join("a.csv")),
        shift.x,
        shift.y,
        shift.z
    );
    let (start, _) = run(scene(&dir, "copy", "copy", &place), &dir, "copy");
    let shifted: Vec<Vec3> = end_a.iter().map(|x| x + shift).collect();
    let d = gap(&start, &shifted);
    eprintln!("copy vs block's end + shift: {d:.1e} m");
    assert!(d < 1e-12, "the copy starts {d} m from the shifted block");
}
