//! Contact through the scene format: `rigid`, `rotate_deg`, `translate`, `velocity`,
//! `[contact]` and `[[wall]]` (plane and mesh) build the models the analytical answers need.
//!
//! - `fixtures/contact/incline.toml`: a rigid block rotated onto a plane inclined at 25°
//!   slides with a = g (sin θ − μ cos θ).
//! - The same block given a velocity on the triangulated floor `ramp.msh` decelerates at μ g
//!   until it stops after v₀²/(2 μ g).
//! - Without the plane nothing can touch: no contact model is built, and a `[[section]]`
//!   records zero force.

use qdem_core::Vec3;
use qdem_io::build::{BodyKind, Simulation};
use qdem_io::scene::{Scene, Section, Wall};
use std::path::{Path, PathBuf};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../fixtures/contact")
        .join(name)
}

/// Runs `scene` to `t_end`, returning the velocity of the first body's centre every `every`
/// seconds.
fn centre_velocities(scene: Scene, t_end: f64, every: f64) -> Vec<(f64, Vec3)> {
    let mut sim = Simulation::build(scene).expect("the scene builds");
    let BodyKind::Rigid { center, .. } = sim.bodies[0].kind else {
        panic!("the block is rigid");
    };
    sim.world.initialize().unwrap();
    let mut out = vec![(0.0, sim.world.state.velocity[center])];
    while sim.world.state.time < t_end {
        sim.world.step().unwrap();
        if sim.world.state.time >= out.len() as f64 * every {
            out.push((sim.world.state.time, sim.world.state.velocity[center]));
        }
    }
    out
}

#[test]
fn a_rigid_block_slides_down_the_inclined_plane_at_the_coulomb_rate() {
    let scene = Scene::load(&fixture("incline.toml")).unwrap();
    let history = centre_velocities(scene, 0.25, 0.05);
    let theta = 25f64.to_radians();
    let down = Vec3::new(-theta.cos(), 0.0, -theta.sin());
    let (t0, v0) = history[1];
    let (t1, v1) = *history.last().unwrap();
    let a = (v1 - v0).dot(&down) / (t1 - t0);
    let expected = 9.81 * (theta.sin() - 0.3 * theta.cos());
    eprintln!("incline scene: a = {a:.6} m/s² vs {expected:.6}");
    assert!((a / expected - 1.0).abs() < 0.01, "a = {a} vs {expected}");
}

#[test]
fn a_block_sliding_on_a_mesh_wall_decelerates_at_mu_g() {
    let mut scene = Scene::load(&fixture("incline.toml")).unwrap();
    let body = &mut scene.bodies[0];
    body.rotate_deg = [0.0; 3];
    // Resting on the floor: the centroid is 5.8 µm above the block's middle.
    body.translate = [0.0, 0.0, 0.06 + 1e-5];
    body.velocity = [0.5, 0.0, 0.0];
    scene.walls = vec![Wall {
        point: None,
        normal: None,
        mesh: Some("ramp.msh".into()),
        friction: Some(0.4),
        velocity: [0.0; 3],
        servo: None,
        start: Default::default(),
    }];
    let history = centre_velocities(scene, 0.1, 0.02);
    let (t0, v0) = history[1];
    let (t1, v1) = history[4];
    let a = (v1.x - v0.x) / (t1 - t0);
    let expected = -0.4 * 9.81;
    eprintln!(
        "mesh wall: a = {a:.6} m/s² vs {expected:.6} (v from {:.4} to {:.4})",
        v0.x, v1.x
    );
    assert!(v1.x > 0.0, "still sliding over the measured window");
    assert!((a / expected - 1.0).abs() < 0.01, "a = {a} vs {expected}");
}

#[test]
fn a_lone_body_without_walls_gets_no_contact_model() {
    let mut scene = Scene::load(&fixture("incline.toml")).unwrap();
    let with_wall = Simulation::build(scene.clone()).unwrap();
    assert!(with_wall.contacts().is_some());
    scene.walls.clear();
    // Nothing bounds the step of a lone rigid body: the scene must give one.
    scene.run.dt = qdem_io::scene::TimeStep::Fixed(1e-4);
    scene.run.t_end = 2e-3;
    scene.sections.push(Section {
        name: "mid".into(),
        axis: "x".into(),
        at: 0.0,
        area: None,
    });
    let mut alone = Simulation::build(scene).unwrap();
    assert!(
        alone.contacts().is_none(),
        "one body and no wall: nothing can touch"
    );
    // A section there measures no contact force: sections.csv holds zeros.
    let out = std::env::temp_dir().join(format!("qdem-lone-section-{}", std::process::id()));
    qdem_io::runner::run(&mut alone, &out, &mut |_| {}).unwrap();
    let text = std::fs::read_to_string(out.join("sections.csv")).unwrap();
    let rows: Vec<&str> = text.lines().collect();
    assert_eq!(rows[0], "time,mid");
    assert!(rows.len() > 2, "{text}");
    for row in &rows[1..] {
        assert_eq!(row.split(',').nth(1), Some("0.000000000e0"), "{text}");
    }
}
