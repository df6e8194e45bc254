//! `qdem modes` with contacts: a stiff deformable cube resting on a plane wall through the
//! linear springs of its bottom face's contact spheres bounces vertically at
//! f = √(N kn / m) / 2π, the frequency of a rigid mass on N parallel springs.
//!
//! The cube (0.1 m, 1 kg, E = 10 GPa) is about 10⁴ times stiffer than its contact springs
//! (N · kn ≈ 2.5 × 10⁵ N/m against E A / L = 10⁹ N/m), so the rigid-mass answer holds to the
//! ratio of the two, 2.5 × 10⁻⁴ in ω², about 10⁻⁴ in frequency: the tolerance is 10⁻³.

mod common;

use common::{fixture, test_dir};
use qdem_io::build::Simulation;
use qdem_io::modes::compute_and_write;
use qdem_io::scene::Scene;
use std::f64::consts::PI;

const RADIUS: f64 = 0.008;
const OVERLAP: f64 = 0.0002;
const KN: f64 = 1e4;

/// The cube on the wall z = 0, its bottom spheres pressed `OVERLAP` into it; without contact
/// spheres when `touching` is false.
fn scene(dir: &std::path::Path, touching: bool) -> Scene {
    let mesh = fixture("contact/block.msh");
    let (contact, spheres, wall) = match touching {
        true => (
            format!(
                "[contact]\nlaw = \"linear\"\nnormal_stiffness = {KN:e}\n\
                 tangential_stiffness = 5e3\nfriction = 0.5\n"
            ),
            format!("contact_radius = {RADIUS}\n"),
            "[[wall]]\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\n",
        ),
        false => (String::new(), String::new(), ""),
    };
    let text = format!(
        "[run]\nt_end = 0.01\ngravity = [0.0, 0.0, 0.0]\n\n[[material]]\nname = \"stiff\"\n\
         density = 1000.0\nyoung = 1e10\npoisson = 0.25\n\n{contact}\n[[body]]\n\
         name = \"cube\"\nmesh = {mesh:?}\nmaterial = \"stiff\"\n{spheres}translate = [0.0, 0.0, \
         {z}]\n\n{wall}",
        z = 0.05 + RADIUS - OVERLAP
    );
    let path = dir.join("cube.toml");
    std::fs::write(&path, text).unwrap();
    Scene::load(&path).unwrap()
}

#[test]
fn a_stiff_cube_on_its_contact_springs_bounces_at_the_spring_mass_frequency() {
    let dir = test_dir("contact-modes");
    let mut sim = Simulation::build(scene(&dir, true)).unwrap();
    let state = &sim.world.state;
    let mass: f64 = state.mass.iter().sum();
    let bottom = state
        .position
        .iter()
        .filter(|p| (p.z - (RADIUS - OVERLAP)).abs() < 1e-9)
        .count();
    assert!(bottom >= 4, "the cube's bottom face has vertices");
    let report = compute_and_write(&mut sim, 6, &dir.join("modes")).unwrap();
    assert!(
        report.ignored.is_empty(),
        "the contacts give a stiffness: {:?}",
        report.ignored
    );
    let modes = &report.modes.modes;
    assert!(
        modes.iter().all(|m| !m.rigid && m.frequency_hz > 1.0),
        "the springs hold the cube against every rigid motion"
    );
    let vertical = modes
        .iter()
        .find(|m| m.dominant().0 == 2)
        .expect("a vertical mode among the lowest six");
    let expected = (bottom as f64 * KN / mass).sqrt() / (2.0 * PI);
    let error = vertical.frequency_hz / expected - 1.0;
    eprintln!(
        "cube on {bottom} springs: vertical mode {:.6} Hz, sqrt(N kn / m) / 2 pi = {expected:.6} Hz, error {error:.2e}",
        vertical.frequency_hz
    );
    assert!(error.abs() < 1e-3, "error {error:.3e}");
    assert!(vertical.dominant().1 > 0.99, "the cube moves as a whole");
}

#[test]
fn without_contact_spheres_the_cube_is_free() {
    let dir = test_dir("contact-modes-free");
    let mut sim = Simulation::build(scene(&dir, false)).unwrap();
    let report = compute_and_write(&mut sim, 7, &dir.join("modes")).unwrap();
    let rigid = report.modes.modes.iter().filter(|m| m.rigid).count();
    assert_eq!(rigid, 6, "six rigid-body modes of a free cube");
}

#[test]
fn a_free_cube_under_gravity_is_refused_and_on_its_springs_it_is_not() {
    let dir = test_dir("contact-modes-gravity");
    for (touching, refused) in [(false, true), (true, false)] {
        let mut scene = scene(&dir, touching);
        scene.run.gravity = [0.0, 0.0, -9.81];
        let mut sim = Simulation::build(scene).unwrap();
        let result = compute_and_write(&mut sim, 6, &dir.join("modes"));
        match refused {
            true => assert!(result
                .unwrap_err()
                .to_string()
                .contains("gravity pushes it")),
            false => assert!(result.is_ok(), "the springs hold it"),
        }
    }
}
