//! What a refused start tells the user to change: an initial overlap of `[granular]` stones
//! names the keys of `[granular]` and `[contact] overlap_tolerance` (never a `[[body]]`'s
//! `translate` or `contact_radius`, which a stone does not have), and raising
//! `overlap_tolerance` as advised lets the scene build.

mod common;

use common::test_dir;
use qdem_io::build::Simulation;
use qdem_io::scene::Scene;

/// Two glass stones of radius 10 mm whose centres are 18 mm apart (an overlap of 2 mm, 40%
/// of their reduced radius), over a floor at `floor` (m), with `contact` extra `[contact]` keys.
fn stones(dir: &std::path::Path, floor: f64, contact: &str) -> Result<Simulation, String> {
    std::fs::write(
        dir.join("stones.csv"),
        "stone,x,y,z,radius\n1,0.0,0.0,0.05,0.01\n2,0.018,0.0,0.05,0.01\n",
    )
    .unwrap();
    let scene = format!(
        r#"
[run]
t_end = 1e-3
dt = 1e-5

[[material]]
name = "glass"
density = 2500.0
young = 7e10
poisson = 0.3

[contact]
law = "linear"
normal_stiffness = 1e6
tangential_stiffness = 1e6
{contact}

[granular]
name = "bed"
material = "glass"
sample = "stones.csv"

[[wall]]
point = [0.0, 0.0, {floor}]
normal = [0.0, 0.0, 1.0]
"#
    );
    let path = dir.join("scene.toml");
    std::fs::write(&path, scene).unwrap();
    Simulation::build(Scene::load(&path).unwrap()).map_err(|e| e.to_string())
}

#[test]
fn overlapping_granular_stones_are_told_their_own_keys_and_the_tolerance_that_accepts_them() {
    let dir = test_dir("start-refusals-overlap");
    let message = stones(&dir, 0.0, "").err().expect("refused");
    eprintln!("{message}");
    assert!(
        message.contains("bodies `bed stone 1` and `bed stone 2` overlap"),
        "{message}"
    );
    assert!(
        message.contains("[granular] `sample` (the stones' rows) or `crop`"),
        "{message}"
    );
    assert!(
        message.contains("[contact] `overlap_tolerance` (now 0.05)"),
        "{message}"
    );
    assert!(
        !message.contains("translate") && !message.contains("contact_radius"),
        "{message}"
    );
    // The advice holds: 40% of the reduced radius is accepted with a tolerance of 0.5.
    assert!(stones(&dir, 0.0, "overlap_tolerance = 0.5").is_ok());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_stone_in_a_wall_is_told_the_walls_point_and_its_samples_keys() {
    let dir = test_dir("start-refusals-wall");
    // The floor 4 mm under the stones' centres: 6 mm into each, more than half the radius.
    let message = stones(&dir, 0.046, "overlap_tolerance = 0.5")
        .err()
        .expect("refused");
    eprintln!("{message}");
    assert!(message.contains("penetrates wall 1"), "{message}");
    assert!(
        message.contains("[granular] `sample` (the stones' rows) or `crop`; [[wall]] `point`"),
        "{message}"
    );
    assert!(
        message.contains("`overlap_tolerance` (now 0.5)"),
        "{message}"
    );
    assert!(
        !message.contains("translate") && !message.contains("contact_radius"),
        "{message}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
