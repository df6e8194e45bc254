//! What a finite-element user met (issue 55), as they met it: the stress of an
//! averaged-pressure block in the VTU, the reactions of two fixes that share the clamp's
//! nodes, and a pressure given a volume group or a point.
//!
//! The block is the gmsh box 0.3 × 0.2 × 0.1 m of `fixtures/msh` (groups `left` x = 0,
//! `right` x = 0.3, `origin`, the volume `body`), solved statically.

mod common;

use common::{fixture, test_dir};
use qdem_io::build::{BuildError, Simulation};
use qdem_io::runner::run;
use qdem_io::scene::Scene;
use std::path::Path;

/// Face x = 0.3's area (m²).
const AREA: f64 = 0.2 * 0.1;

/// The box in `dir`, its material `material` (TOML lines), clamped on `left` by `fixes`,
/// loaded by `load` (a `[[load]]`'s keys after `body`).
fn block(dir: &Path, material: &str, fixes: &str, load: &str) -> Scene {
    let mesh = fixture("msh/box_gmsh22_ascii.msh");
    let text = format!(
        "[run]\nt_end = 1.0\ndt = 1.0\nintegrator = \"static\"\nprobe_every = 1.0\n\n\
         [[material]]\nname = \"m\"\ndensity = 1100.0\n{material}\n\n\
         [[body]]\nname = \"block\"\nmesh = {mesh:?}\nmaterial = \"m\"\n\n\
         {fixes}\n\n[[load]]\nbody = \"block\"\n{load}\n\n\
         [output]\nvtu_every = 1.0\n"
    );
    let path = dir.join("block.toml");
    std::fs::write(&path, text).unwrap();
    Scene::load(&path).unwrap()
}

/// The rubber block of item 1 (ν = 0.499, averaged-pressure, clamped on x = 0, pressed by
/// p = 0.1 MPa on x = 0.3): away from the clamp the block is in uniaxial compression, so
/// the 27 elements within 6 cm of the loaded face's centre carry σxx ≈ −p. The
/// formulation's stress gives that to 7% on this coarse mesh (measured −1.051 p to
/// −0.949 p: the clamp's restraint of the lateral bulging reaches the loaded end); Hooke's
/// law on each element's own strain, which the VTU reported before, gave a checkerboard of
/// −3.73 p to +1.37 p.
#[test]
fn averaged_pressure_block_reports_its_pressure_in_the_vtu() {
    let dir = test_dir("fem-findings-rubber");
    let p = 1.0e5;
    let scene = block(
        &dir,
        "young = 5e6\npoisson = 0.499\nformulation = \"averaged-pressure\"",
        "[[fix]]\nbody = \"block\"\ngroup = \"left\"",
        &format!("group = \"right\"\npressure = {p:e}"),
    );
    let mut sim = Simulation::build(scene).unwrap();
    let out = dir.join("out");
    run(&mut sim, &out, &mut |_| {}).unwrap();
    let vtu = std::fs::read_to_string(out.join("vtu/state_00001.vtu")).unwrap();
    let stress = common::vtu_array(&vtu, "stress");
    let state = &sim.world.state;
    let tets = sim.body_tets(&sim.bodies[0]);
    let centre = qdem_core::Vec3::new(0.3, 0.1, 0.05);
    let near: Vec<f64> = tets
        .iter()
        .zip(stress.chunks(6))
        .filter(|(t, _)| {
            let c = t
                .iter()
                .map(|&n| state.reference[n as usize])
                .sum::<qdem_core::Vec3>()
                / 4.0;
            (c - centre).norm() < 0.06
        })
        .map(|(_, s)| s[0] / p)
        .collect();
    assert!(
        near.len() >= 4,
        "{} tetrahedra near the face's centre",
        near.len()
    );
    let (lo, hi) = near
        .iter()
        .fold((f64::MAX, f64::MIN), |(lo, hi), &s| (lo.min(s), hi.max(s)));
    eprintln!(
        "σxx/p near the loaded face's centre: {lo:.3} .. {hi:.3} ({} tets)",
        near.len()
    );
    assert!(
        lo > -1.07 && hi < -0.93,
        "σxx/p {lo:.3} .. {hi:.3}, want −1 ± 0.07"
    );
}

/// Item 2: an xyz fix and a z-only fix on the same clamp face, the free end under a traction
/// t = (tx, 0, tz). Each fix reports only what it holds: the xyz fix −tx·A in x; the z
/// direction, which both hold, shared half and half; the z-only fix nothing in x or y. The
/// two sum to −t·A (before, the z-only fix reported the xyz fix's −tx·A as its own, and the
/// fixes summed to twice the load). The static solve's rounding and the CSV's nine digits
/// bound the check at 10⁻⁷ of the load.
#[test]
fn two_fixes_sharing_nodes_report_what_each_holds() {
    let dir = test_dir("fem-findings-shared-fix");
    let (tx, tz): (f64, f64) = (-2.5e5, 1.0e5);
    let scene = block(
        &dir,
        "young = 45e9\npoisson = 0.2",
        "[[fix]]\nbody = \"block\"\ngroup = \"left\"\n\n\
         [[fix]]\nbody = \"block\"\ngroup = \"left\"\ndofs = \"z\"",
        &format!("group = \"right\"\ntraction = [{tx:e}, 0.0, {tz:e}]"),
    );
    let mut sim = Simulation::build(scene).unwrap();
    let out = dir.join("out");
    run(&mut sim, &out, &mut |_| {}).unwrap();
    let columns = common::columns(&out.join("reactions.csv"));
    let last = |name: &str| *columns[name].last().unwrap();
    let load = tx.abs().max(tz.abs()) * AREA;
    for (name, want) in [
        ("fix1_fx", -tx * AREA),
        ("fix1_fy", 0.0),
        ("fix1_fz", -tz * AREA / 2.0),
        ("fix2_fx", 0.0),
        ("fix2_fy", 0.0),
        ("fix2_fz", -tz * AREA / 2.0),
    ] {
        let got = last(name);
        assert!(
            (got - want).abs() <= 1e-7 * load,
            "{name} = {got} N, want {want} N"
        );
    }
}

/// Item 5: a pressure given the volume group is refused, naming the group and the whole
/// boundary it would load (it loaded the clamped face too, silently); a pressure on a point
/// group is refused for what it is (a point has no face), not as "selects no particle".
#[test]
fn a_pressure_on_a_volume_or_a_point_is_refused_for_what_it_is() {
    let dir = test_dir("fem-findings-not-a-face");
    let build = |group: &str| {
        let scene = block(
            &dir,
            "young = 45e9\npoisson = 0.2",
            "[[fix]]\nbody = \"block\"\ngroup = \"left\"",
            &format!("group = \"{group}\"\npressure = 1e5"),
        );
        match Simulation::build(scene) {
            Err(e @ BuildError::NotAFace { .. }) => e.to_string(),
            Err(e) => panic!("{group}: another error: {e}"),
            Ok(_) => panic!("{group}: a pressure on it was accepted"),
        }
    };
    let volume = build("body");
    for part in [
        "`body` is a volume group",
        "whole closed boundary",
        "triangles",
        "physical surface",
    ] {
        assert!(volume.contains(part), "no `{part}` in: {volume}");
    }
    let point = build("origin");
    for part in ["1 particle(s)", "no boundary triangle", "total_force"] {
        assert!(point.contains(part), "no `{part}` in: {point}");
    }
    assert!(!point.contains("selects no particle"), "{point}");
}

/// Item 5: a point group for a fix and for a `total_force` load is accepted and acts on its
/// one particle.
#[test]
fn a_point_group_holds_and_loads_its_particle() {
    let dir = test_dir("fem-findings-point");
    let scene = block(
        &dir,
        "young = 45e9\npoisson = 0.2",
        "[[fix]]\nbody = \"block\"\ngroup = \"left\"\n\n\
         [[fix]]\nbody = \"block\"\ngroup = \"origin\"\ndofs = \"y\"",
        "group = \"origin\"\ntotal_force = [0.0, 0.0, 5.0]",
    );
    let sim = Simulation::build(scene).unwrap();
    assert_eq!(sim.fix_particles[1].len(), 1);
    let load = sim
        .world
        .model::<qdem_core::loads::NodalLoad>()
        .unwrap()
        .total();
    assert!((load.z - 5.0).abs() < 1e-12, "{load}");
}

/// Item 6: per-node reactions on request. `node_reactions.csv` of the two fixes sharing the
/// clamp's nodes: each fix's rows sum to its `reactions.csv` force (to the nine printed
/// digits), and each row's `gmsh_node_id` is the .msh file's node at the row's reference
/// position (the nodes are reordered in the state, so the id is what maps a row back).
#[test]
fn node_reactions_sum_to_the_fix_and_name_the_gmsh_nodes() {
    let dir = test_dir("fem-findings-node-reactions");
    let scene_text = |dir: &Path| {
        let scene = block(
            dir,
            "young = 45e9\npoisson = 0.2",
            "[[fix]]\nbody = \"block\"\ngroup = \"left\"\n\n\
             [[fix]]\nbody = \"block\"\ngroup = \"left\"\ndofs = \"z\"",
            "group = \"right\"\ntraction = [-2.5e5, 0.0, 1.0e5]",
        );
        let path = scene.path.clone();
        let text = std::fs::read_to_string(&path).unwrap();
        std::fs::write(
            &path,
            text.replace("[output]\n", "[output]\nnode_reactions = true\n"),
        )
        .unwrap();
        Scene::load(&path).unwrap()
    };
    let mut sim = Simulation::build(scene_text(&dir)).unwrap();
    let out = dir.join("out");
    run(&mut sim, &out, &mut |_| {}).unwrap();
    let totals = common::columns(&out.join("reactions.csv"));
    let text = std::fs::read_to_string(out.join("node_reactions.csv")).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "time,fix,gmsh_node_id,particle,x,y,z,fx,fy,fz"
    );
    let msh_text = std::fs::read_to_string(fixture("msh/box_gmsh22_ascii.msh")).unwrap();
    let (msh, _) = common::parse_msh22(&msh_text);
    let mut sums = [[0.0f64; 3]; 2];
    let mut rows = 0;
    let last_time = text
        .lines()
        .last()
        .unwrap()
        .split(',')
        .next()
        .unwrap()
        .to_string();
    for line in lines {
        let v: Vec<&str> = line.split(',').collect();
        if v[0] != last_time {
            continue;
        }
        let fix: usize = v[1].parse().unwrap();
        let id: i64 = v[2].parse().unwrap();
        let x: Vec<f64> = v[4..7].iter().map(|s| s.parse().unwrap()).collect();
        let at = msh[&id];
        assert!(
            (0..3).all(|k| (at[k] - x[k]).abs() < 1e-9),
            "node {id} at {at:?}, row at {x:?}"
        );
        for k in 0..3 {
            sums[fix - 1][k] += v[7 + k].parse::<f64>().unwrap();
        }
        rows += 1;
    }
    let left = sim.fix_particles[0].len();
    assert_eq!(
        rows,
        2 * left,
        "one row per fix and particle at the last time"
    );
    for (fix, sum) in sums.iter().enumerate() {
        for (k, c) in ["fx", "fy", "fz"].iter().enumerate() {
            let want = *totals[&format!("fix{}_{c}", fix + 1)].last().unwrap();
            assert!(
                (sum[k] - want).abs() <= 1e-7 * 2.5e5 * AREA,
                "fix {} {c}: {} vs {want}",
                fix + 1,
                sum[k]
            );
        }
    }
}
