//! Contact springs carried across `[run] start_from`: a stage that starts from another's
//! checkpoint keeps the tangential springs of the contacts between the same spheres (and
//! walls), whatever the bodies' kinds, so a block held by static friction, or sliding, goes on
//! as the uninterrupted run does; a spring whose sphere the new stage does not have is
//! dropped and counted.
//!
//! The scenes are `fixtures/contact/incline.toml`'s rigid 0.1 m block on a plane inclined at
//! 25°, with friction 0.6 (> tan 25° = 0.466: it lands, slips a little and is held) or 0.3
//! (it slides at a = g (sin 25° − 0.3 cos 25°)).

mod common;

use common::{build, fixture, test_dir};
use qdem_contact::Partner;
use qdem_core::Vec3;
use qdem_io::build::{BodyKind, Simulation};
use qdem_io::runner::{run_with, RunOptions};
use std::path::{Path, PathBuf};

/// The block's placement 1 mm lower along the slope's normal (−0.4226, 0, 0.9063) than the
/// fixture's: its lowest contact spheres just touch the plane.
const TOUCHING: &str = "translate = [-0.0253574, 0.0, 0.0543787]";

/// The incline scene with friction `friction`, run to `t_end` with a checkpoint at its end
/// into `out/<name>`, after the text `edits`.
fn incline(dir: &Path, name: &str, friction: f64, t_end: f64, edits: &[(&str, &str)]) -> PathBuf {
    let text = std::fs::read_to_string(fixture("contact/incline.toml")).unwrap();
    let mesh = format!("mesh = \"{}\"", fixture("contact/block.msh").display());
    let base = [
        ("t_end = 0.4", format!("t_end = {t_end}\ndt = 1e-5")),
        ("friction = 0.3", format!("friction = {friction}")),
        ("mesh = \"block.msh\"", mesh),
        ("dir = \"out/incline\"", format!("dir = \"out/{name}\"")),
        ("vtu_every = 0.05", format!("checkpoint_every = {t_end}")),
        // On the slope rather than 1 mm above it: no bounce, touching from the start.
        (
            "translate = [-0.025780, 0.0, 0.055285]",
            TOUCHING.to_string(),
        ),
    ];
    let text = base
        .iter()
        .map(|(from, to)| (*from, to.as_str()))
        .chain(edits.iter().copied())
        .fold(text, |text, (from, to)| text.replace(from, to));
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

/// The edit that makes a scene start from the checkpoint of the run `out/<name>`.
fn start_from(dir: &Path, name: &str) -> (&'static str, String) {
    let file = dir.join(format!("out/{name}/checkpoint.qdc"));
    (
        "[run]",
        format!("[run]\nstart_from = \"{}\"", file.display()),
    )
}

/// Runs `sim` to its end, writing into `dir/out/<its name>`.
fn run(dir: &Path, sim: &mut Simulation) {
    let out = dir.join(&sim.scene.output.dir);
    run_with(sim, &out, RunOptions::default(), &mut |_| {}).unwrap();
}

/// The block's centre of mass and its velocity (its rigid body's, or its nodes').
fn block_motion(sim: &Simulation) -> (Vec3, Vec3) {
    let s = &sim.world.state;
    match sim.bodies[0].kind {
        BodyKind::Rigid { center, .. } => (s.position[center], s.velocity[center]),
        _ => {
            let nodes = sim.bodies[0].particles.clone();
            let m: f64 = s.mass[nodes.clone()].iter().sum();
            let weigh = |v: &[Vec3]| {
                nodes
                    .clone()
                    .fold(Vec3::zeros(), |a, i| a + s.mass[i] * v[i])
            };
            (weigh(&s.position) / m, weigh(&s.velocity) / m)
        }
    }
}

/// The tangential force of every touching wall contact at the last evaluation, by the
/// particle of its sphere, sorted.
fn wall_friction(sim: &Simulation) -> Vec<(usize, Vec3)> {
    let contacts = sim.contacts().unwrap();
    let particles: Vec<usize> = contacts
        .sphere_records(&sim.world.state)
        .map(|r| r.particle)
        .collect();
    let mut out: Vec<(usize, Vec3)> = contacts
        .touching()
        .filter(|c| matches!(c.second, Partner::Wall(_)))
        .map(|c| (particles[c.first], c.tangential_force))
        .collect();
    out.sort_by_key(|c| c.0);
    out
}

/// Runs the stage `first` to its end, then a stage starting from its checkpoint (`second`,
/// kinds and all), and the uninterrupted scene `whole`; returns the three simulations.
fn staged(dir: &Path, first: &Path, second: &Path, whole: &Path) -> [Simulation; 3] {
    let mut a = build(first);
    run(dir, &mut a);
    let mut b = build(second);
    run(dir, &mut b);
    let mut w = build(whole);
    run(dir, &mut w);
    [a, b, w]
}

#[test]
fn a_rigid_block_held_or_sliding_goes_on_across_start_from_as_the_uninterrupted_run() {
    for (what, friction, t1, t2) in [("held", 0.6, 0.1, 0.05), ("sliding", 0.3, 0.05, 0.05)] {
        let dir = test_dir(&format!("springs-{what}"));
        let from = start_from(&dir, "first");
        let first = incline(&dir, "first", friction, t1, &[]);
        let second = incline(&dir, "second", friction, t2, &[(from.0, &from.1)]);
        let whole = incline(&dir, "whole", friction, t1 + t2, &[]);
        let [a, b, w] = staged(&dir, &first, &second, &whole);
        assert_eq!(a.steps() + b.steps(), w.steps(), "{what}: the same steps");
        assert!(b.warnings.is_empty(), "{what}: {:?}", b.warnings);
        let ((x, v), (x_w, v_w)) = (block_motion(&b), block_motion(&w));
        let (dx, dv) = ((x - x_w).norm(), (v - v_w).norm());
        // What restarting the springs unstretched would do, for scale: the held block slips
        // until its touching springs take its weight's pull down the slope again,
        // m g sin 25° / (n k_t) ~ 1e-7 m (n ~ 10 touching spheres, k_t = 1e7 N/m; 9.5e-8 m
        // measured with the build before this change); the sliding one misses the friction
        // of its first half step, μ g cos 25° dt/2 ~ 1.3e-5 m/s.
        let n = wall_friction(&a).len() as f64;
        let slip = 2.4 * 9.81 * 25f64.to_radians().sin() / (n * 1e7);
        let kick = friction * 9.81 * 25f64.to_radians().cos() * 0.5e-5;
        // Carried, the stages differ from the uninterrupted run only in the round-off of the
        // time (restarted at 0): the springs grow by v (t − t_last), whose last bits differ.
        eprintln!("{what}: |dx| = {dx:.3e} m (slip {slip:.2e}), |dv| = {dv:.3e} m/s");
        assert!(
            dx < 1e-12 && dx < 1e-4 * slip,
            "{what}: the block is {dx} m off"
        );
        assert!(dv < 1e-9 && dv < 1e-4 * kick, "{what}: {dv} m/s off");
        if what == "sliding" {
            let down = Vec3::new(-25f64.to_radians().cos(), 0.0, -25f64.to_radians().sin());
            assert!(v.dot(&down) > 0.05, "{what}: still sliding at {v:?}");
        }
    }
}

#[test]
fn a_rigid_block_turned_deformable_keeps_its_springs_and_their_hold() {
    let dir = test_dir("springs-to-deformable");
    let from = start_from(&dir, "first");
    let first = incline(&dir, "first", 0.6, 0.1, &[]);
    let deformable = [
        (from.0, from.1.as_str()),
        ("rigid = true\n", ""),
        ("dt = 1e-5\n", ""),
    ];
    let second = incline(&dir, "second", 0.6, 0.02, &deformable);
    let mut a = build(&first);
    run(&dir, &mut a);
    let mut b = build(&second);
    assert!(
        b.warnings.iter().any(|w| w.contains("deformable here")),
        "{:?}",
        b.warnings
    );
    b.world.initialize().unwrap();
    // The same springs on the same spheres: the first evaluation of the deformable block
    // (at the checkpoint's positions, no time elapsed) gives each sphere the friction the
    // rigid block's had, up to the round-off of the pose (nodes at c + R s).
    let (before, after) = (wall_friction(&a), wall_friction(&b));
    assert_eq!(
        before.iter().map(|c| c.0).collect::<Vec<_>>(),
        after.iter().map(|c| c.0).collect::<Vec<_>>()
    );
    let total: f64 = before.iter().map(|c| c.1.norm()).sum();
    assert!(
        total > 1.0,
        "the held block leans on its springs: {total} N"
    );
    for ((p, f), (_, g)) in before.iter().zip(&after) {
        assert!(
            (f - g).norm() < 1e-9 * total,
            "sphere on {p}: {f:?} vs {g:?}"
        );
    }
    // They hold the block's weight's pull down the slope, M g sin 25° (M = 2.4 kg), as the
    // rigid block's did.
    let pull = 2.4 * 9.81 * 25f64.to_radians().sin();
    let held: Vec3 = after.iter().map(|c| c.1).sum();
    eprintln!(
        "deformable: friction {:.6} N of the pull {pull:.6} N",
        held.norm()
    );
    assert!(
        (held.norm() / pull - 1.0).abs() < 1e-5,
        "{held:?} vs {pull}"
    );
}

#[test]
fn springs_whose_sphere_is_gone_are_dropped_and_counted() {
    let dir = test_dir("springs-dropped");
    let from = start_from(&dir, "first");
    // A second block beside the first, 0.2 m across the slope.
    let second_block = "[contact]";
    let block2 = "[[body]]\nname = \"block2\"\nmesh = \"MESH\"\nmaterial = \"concrete\"\n\
                  rigid = true\ncontact_radius = 0.01\nrotate_deg = [0.0, -25.0, 0.0]\n\
                  translate = [-0.0253574, 0.2, 0.0543787]\n\n[contact]"
        .replace("MESH", &fixture("contact/block.msh").display().to_string());
    let first = incline(&dir, "first", 0.6, 0.02, &[(second_block, &block2)]);
    let gone = block2.replace("contact_radius = 0.01\n", "");
    let edits = [(from.0, from.1.as_str()), (second_block, gone.as_str())];
    let second = incline(&dir, "second", 0.6, 0.01, &edits);
    let mut a = build(&first);
    run(&dir, &mut a);
    let stretched = wall_friction(&a);
    let block2 = a.bodies[1].particles.clone();
    let on_block2 = stretched.iter().filter(|c| block2.contains(&c.0)).count();
    assert!(on_block2 > 0 && on_block2 < stretched.len());
    let b = build(&second);
    let line = format!(
        "{on_block2} of its {} stretched tangential contact springs dropped",
        stretched.len()
    );
    assert!(
        b.warnings.iter().any(|w| w.contains(&line)),
        "`{line}` in {:?}",
        b.warnings
    );
    let carried = format!("the other {} carried", stretched.len() - on_block2);
    assert!(b.warnings.iter().any(|w| w.contains(&carried)));
}
