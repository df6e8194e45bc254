//! A body's kind chosen per stage: `[ballast] rigid = true` stones, and a scene that
//! `start_from`s a checkpoint with a body of the other kind (rigid → deformable at its pose,
//! deformable → rigid at its centre of mass and best-fit rotation), keeping momentum and
//! angular momentum; what cannot be carried refused by name.

mod common;

use common::{fixture, test_dir};
use qdem_core::Vec3;
use qdem_io::build::{BodyKind, BuildError, Simulation};
use qdem_io::runner::{run_with, RunOptions};
use qdem_io::scene::Scene;
use std::path::{Path, PathBuf};

/// Six coarse stones apart in a box, no gravity, moving with `motion` (velocity and angular
/// velocity lines); `edits` replace text.
fn stones_scene(dir: &Path, name: &str, edits: &[(&str, &str)]) -> PathBuf {
    let meshes: Vec<String> = (0..4)
        .map(|i| {
            let mesh = fixture(&format!("ballast/stones/coarse/stone_{i:02}.msh"));
            format!("\"{}\"", mesh.display())
        })
        .collect();
    let text = format!(
        r#"
[run]
t_end = 0.0005
probe_every = 0.0005

[[material]]
name = "granite"
density = 2700.0
young = 1.2e9
poisson = 0.2

[contact]
law = "linear"
normal_stiffness = 6.45e7
tangential_stiffness = 2.69e7
friction = 0.577

[ballast]
name = "ballast"
material = "granite"
meshes = [{meshes}]
contact_radius = 0.012
count = 6
region = [[0.0, 0.0, 0.0], [0.5, 0.3, 0.5]]
grading = [[0.05, 0.0], [0.06, 0.5], [0.07, 1.0]]
seed = 3
MOTION

[output]
dir = "out"
checkpoint_every = 0.0005
"#,
        meshes = meshes.join(", ")
    );
    write(dir, name, text, edits)
}

/// The contact fixtures' 0.1 m block, alone, no gravity; `edits` replace text.
fn block_scene(dir: &Path, name: &str, edits: &[(&str, &str)]) -> PathBuf {
    let text = format!(
        r#"
[run]
t_end = 0.0005
dt = 1e-5
probe_every = 0.0005

[[material]]
name = "steel"
density = 7800.0
young = 2.0e8
poisson = 0.3

[[body]]
name = "block"
mesh = "{}"
material = "steel"
MOTION

[output]
dir = "out"
checkpoint_every = 0.0005
"#,
        fixture("contact/block.msh").display()
    );
    write(dir, name, text, edits)
}

fn write(dir: &Path, name: &str, text: String, edits: &[(&str, &str)]) -> PathBuf {
    let text = edits
        .iter()
        .fold(text, |text, (from, to)| text.replace(from, to));
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

fn build(path: &Path) -> Result<Simulation, BuildError> {
    Simulation::build(Scene::load(path).unwrap())
}

/// Runs `scene` to its end in `dir/out` (writing its checkpoint there) and returns it.
fn run(dir: &Path, scene: &Path) -> Simulation {
    let mut sim = build(scene).unwrap();
    run_with(
        &mut sim,
        &dir.join("out"),
        RunOptions::default(),
        &mut |_| {},
    )
    .unwrap();
    sim
}

/// The `[run] start_from` line of a scene that starts where the run in `dir/out` ended.
fn start_from(dir: &Path) -> String {
    let file = dir.join("out/checkpoint.qdc");
    format!("start_from = \"{}\"\n\n[[material]]", file.display())
}

/// Momentum and angular momentum about the origin of each rigid body or stone of `sim`'s
/// bodies, or of each deformable body's (stone's) nodes, in body (stone) order.
fn momenta(sim: &Simulation) -> Vec<(Vec3, Vec3)> {
    let s = &sim.world.state;
    let rigid = |b: usize, c: usize| {
        let p = s.mass[c] * s.velocity[c];
        (p, s.position[c].cross(&p) + s.rigid.angular_momentum[b])
    };
    let nodes = |r: std::ops::Range<usize>| {
        r.fold((Vec3::zeros(), Vec3::zeros()), |(p, l), i| {
            let pi = s.mass[i] * s.velocity[i];
            (p + pi, l + s.position[i].cross(&pi))
        })
    };
    let mut out = Vec::new();
    for body in &sim.bodies {
        match &body.kind {
            BodyKind::Rigid { body, center, .. } => out.push(rigid(*body, *center)),
            BodyKind::Stones { first, centers, .. } => out.extend(
                centers
                    .iter()
                    .enumerate()
                    .map(|(k, &c)| rigid(first + k, c)),
            ),
            BodyKind::Deformable { .. } => match &sim.ballast {
                Some(info) if info.name == body.name => {
                    out.extend(info.stones.iter().map(|r| nodes(r.clone())))
                }
                _ => out.push(nodes(body.particles.clone())),
            },
        }
    }
    out
}

/// The largest difference of two lists of momenta, relative to the largest of each kind.
fn relative_difference(a: &[(Vec3, Vec3)], b: &[(Vec3, Vec3)]) -> (f64, f64) {
    assert_eq!(a.len(), b.len());
    let scale = |f: fn(&(Vec3, Vec3)) -> Vec3| a.iter().map(|m| f(m).norm()).fold(0.0, f64::max);
    let (sp, sl) = (scale(|m| m.0), scale(|m| m.1));
    a.iter().zip(b).fold((0.0f64, 0.0f64), |(dp, dl), (x, y)| {
        (
            dp.max((x.0 - y.0).norm() / sp),
            dl.max((x.1 - y.1).norm() / sl),
        )
    })
}

/// The strain energy of every deformable body of `sim` (J).
fn strain_energy(sim: &Simulation) -> f64 {
    sim.bodies
        .iter()
        .filter_map(|b| sim.tet_body(b))
        .map(|t| t.potential_energy(&sim.world.state).unwrap())
        .sum()
}

#[test]
fn rigid_stones_have_their_tetrahedra_mass_and_carry_the_spheres() {
    let dir = test_dir("kind-rigid-stones");
    let at_rest = [("MOTION", "")];
    let deformable = build(&stones_scene(&dir, "d.toml", &at_rest)).unwrap();
    let rigid = [("MOTION", "rigid = true")];
    let sim = build(&stones_scene(&dir, "r.toml", &rigid)).unwrap();
    let info = sim.ballast.as_ref().unwrap();
    assert_eq!(info.centers.len(), 6);
    assert_eq!(sim.world.state.rigid.len(), 6);
    // The same stones: each rigid stone's mass is its lumped nodes' in the deformable build
    // (both the tetrahedra's volume times the density), its centre their centre of mass.
    let s = &deformable.world.state;
    for (k, nodes) in info.stones.iter().enumerate() {
        let m: f64 = s.mass[nodes.clone()].iter().sum();
        let c = nodes
            .clone()
            .fold(Vec3::zeros(), |a, i| a + s.mass[i] * s.position[i])
            / m;
        let centre = info.centers[k];
        assert!((sim.world.state.mass[centre] - m).abs() < 1e-12 * m);
        assert!((sim.world.state.position[centre] - c).norm() < 1e-14);
        assert!(sim.world.state.mass[nodes.clone()]
            .iter()
            .all(|&m| m == 0.0));
    }
    assert_eq!(sim.contacts().unwrap().spheres(), info.spheres.len());
    assert!(
        sim.world.models.iter().all(|m| m.name() != "ballast"),
        "no kernel"
    );
}

#[test]
fn a_rigid_stone_turned_deformable_at_rest_stays_at_rest_unstressed() {
    let dir = test_dir("kind-at-rest");
    run(
        &dir,
        &stones_scene(&dir, "r.toml", &[("MOTION", "rigid = true")]),
    );
    let from = start_from(&dir);
    let edits = [("[[material]]", from.as_str()), ("MOTION", "")];
    let mut sim = build(&stones_scene(&dir, "d.toml", &edits)).unwrap();
    assert!(
        sim.warnings.iter().any(|w| w.contains("deformable here")),
        "{:?}",
        sim.warnings
    );
    let s = &sim.world.state;
    let info = sim.ballast.as_ref().unwrap();
    let nodes = info.stones[0].start..info.stones.last().unwrap().end;
    // The pose of a stone at rest is its build's: the nodes are the reference up to the
    // round-off of x = c + R Rᵀ (X − c) (a few ulps of 0.5 m coordinates).
    for i in nodes.clone() {
        assert!((s.position[i] - s.reference[i]).norm() < 1e-15, "node {i}");
        assert_eq!(s.velocity[i], Vec3::zeros());
    }
    let stone_energy = 2.0e-3; // ½ m v² of a 0.3 kg stone at 0.1 m/s, for scale
    assert!(
        strain_energy(&sim) < 1e-20 * stone_energy,
        "{}",
        strain_energy(&sim)
    );
    sim.world.initialize().unwrap();
    for _ in 0..200 {
        sim.world.step().unwrap();
    }
    let s = &sim.world.state;
    // Round-off only: the pose leaves ~1e-17 m in 0.01 m edges, a strain of ~1e-15 and a
    // stress of E 1e-15 ~ 1e-6 Pa; on a node's ~1e-4 m² and ~3e-4 kg that is ~3e-7 m/s²,
    // ~1e-10 m/s over the 200 steps' time (dt ~ 1e-6 s).
    let elapsed = 200.0 * sim.world.dt();
    let fastest = nodes.map(|i| s.velocity[i].norm()).fold(0.0, f64::max);
    assert!(
        fastest < 3e-7 * elapsed * 2.0,
        "a stone at rest moves at {fastest} m/s after {elapsed} s"
    );
}

#[test]
fn moving_rigid_bodies_become_deformable_with_their_momentum_and_angular_momentum() {
    let motion = "velocity = [0.3, -0.2, -1.0]\nangular_velocity = [5.0, -3.0, 7.0]";
    for (what, scene) in [
        (
            "stones",
            stones_scene as fn(&Path, &str, &[(&str, &str)]) -> PathBuf,
        ),
        ("block", block_scene),
    ] {
        let dir = test_dir(&format!("kind-to-deformable-{what}"));
        let rigid_motion = format!("{motion}\nrigid = true");
        let rigid = run(&dir, &scene(&dir, "r.toml", &[("MOTION", &rigid_motion)]));
        let from = start_from(&dir);
        let edits = [("[[material]]", from.as_str()), ("MOTION", motion)];
        let sim = build(&scene(&dir, "d.toml", &edits)).unwrap();
        let (dp, dl) = relative_difference(&momenta(&rigid), &momenta(&sim));
        assert!(
            dp < 1e-12 && dl < 1e-12,
            "{what}: momentum {dp:e}, angular {dl:e}"
        );
        // Unstressed: the nodes are at a rigid motion of the reference.
        let kinetic = sim.world.state.kinetic_energy();
        assert!(
            strain_energy(&sim) < 1e-20 * kinetic,
            "{what}: {}",
            strain_energy(&sim)
        );
    }
}

#[test]
fn deformable_bodies_become_rigid_with_their_momentum_and_the_strain_energy_reported() {
    let motion = "velocity = [0.3, -0.2, -1.0]\nangular_velocity = [5.0, -3.0, 7.0]";
    for (what, scene) in [
        (
            "stones",
            stones_scene as fn(&Path, &str, &[(&str, &str)]) -> PathBuf,
        ),
        ("block", block_scene),
    ] {
        let dir = test_dir(&format!("kind-to-rigid-{what}"));
        let deformable = run(&dir, &scene(&dir, "d.toml", &[("MOTION", motion)]));
        let strain = strain_energy(&deformable);
        assert!(strain > 0.0, "{what}: spinning stretches the body");
        let from = start_from(&dir);
        let rigid_motion = format!("{motion}\nrigid = true");
        let edits = [("[[material]]", from.as_str()), ("MOTION", &rigid_motion)];
        let sim = build(&scene(&dir, "r.toml", &edits)).unwrap();
        let (dp, dl) = relative_difference(&momenta(&deformable), &momenta(&sim));
        assert!(
            dp < 1e-12 && dl < 1e-12,
            "{what}: momentum {dp:e}, angular {dl:e}"
        );
        let reported = format!("strain energy {strain:.4e} J");
        assert!(
            sim.warnings.iter().any(|w| w.contains(&reported)),
            "{what}: {reported} in {:?}",
            sim.warnings
        );
        // The best-fit pose: every node where the deformable one was, up to its strain.
        let (a, b) = (&deformable.world.state, &sim.world.state);
        let off = (0..a.len()).map(|i| (a.position[i] - b.position[i]).norm());
        let off = off.fold(0.0, f64::max);
        assert!(off < 1e-6, "{what}: a node {off} m off the deformed one");
    }
}

#[test]
fn a_changed_mesh_or_stone_count_is_refused_by_name() {
    let dir = test_dir("kind-refused");
    run(
        &dir,
        &stones_scene(&dir, "r.toml", &[("MOTION", "rigid = true")]),
    );
    let from = start_from(&dir);
    let cases = [
        ("count = 6", "count = 5", "[ballast] `ballast` stone 1"),
        ("stone_00.msh", "stone_07.msh", "[ballast] `ballast` stone"),
    ];
    for (old, new, name) in cases {
        let edits = [("[[material]]", from.as_str()), ("MOTION", ""), (old, new)];
        match build(&stones_scene(&dir, "d.toml", &edits)) {
            Err(e @ BuildError::StartFrom { .. }) => {
                let message = e.to_string();
                assert!(message.contains(name), "{new}: {message}");
                assert!(message.contains("only `rigid`"), "{message}");
            }
            Err(e) => panic!("{new}: expected a start_from error, got {e}"),
            Ok(_) => panic!("{new}: a checkpoint of other stones was accepted"),
        }
    }
    let block = block_scene(
        &dir,
        "b.toml",
        &[("[[material]]", from.as_str()), ("MOTION", "")],
    );
    let message = build(&block).err().unwrap().to_string();
    assert!(message.contains("body `block`"), "{message}");
}
