//! What a static run leaves for a finite-element user (issue 55, items 3 and 4): the final
//! state's VTU without `vtu_every`, one solve per distinct load level, level times as given,
//! the mesh file's node and element ids and physical volume in the VTU whatever the
//! reordering, and nodal stresses beside the element ones.
//!
//! The pressed block of `fem_measures.rs`: the gmsh box 0.3 × 0.2 × 0.1 m
//! (`fixtures/msh/box_gmsh22_ascii.msh`, 126 nodes, 330 tetrahedra, volume `body` of tag 1),
//! its face x = 0.3 under a pressure p, held against rigid motion only, so the linear solution
//! is the uniform stress σ = −p eₓ⊗eₓ, which linear tetrahedra represent exactly; the static
//! solve reaches it to ~10⁻¹¹ relative (displacements of 10⁻⁵ m beside coordinates of
//! 0.1 m), checked to 10⁻⁹ p.

mod common;

use common::{fixture, test_dir};
use qdem_io::build::Simulation;
use qdem_io::runner::run;
use qdem_io::scene::Scene;
use std::path::Path;

const P: f64 = 1.0e6;

/// The pressed block's scene in `dir` with the further `[run]` lines `run` and the load's
/// time function `ramp` (empty: constant).
fn pressed_block(dir: &Path, run: &str, ramp: &str) -> Scene {
    let mesh = fixture("msh/box_gmsh22_ascii.msh");
    let e = 1e-9;
    let text = format!(
        "[run]\nt_end = 1.0\nintegrator = \"static\"\n{run}\n\n\
         [[material]]\nname = \"concrete\"\ndensity = 2350.0\nyoung = 45e9\npoisson = 0.2\n\n\
         [[body]]\nname = \"block\"\nmesh = {mesh:?}\nmaterial = \"concrete\"\n\n\
         [[fix]]\nbody = \"block\"\ngroup = \"left\"\ndofs = \"x\"\n\n\
         [[fix]]\nbody = \"block\"\ngroup = \"origin\"\ndofs = \"yz\"\n\n\
         [[fix]]\nbody = \"block\"\nbox = [[-{e}, {lo}, -{e}], [{e}, {hi}, {e}]]\ndofs = \"z\"\n\n\
         [[load]]\nbody = \"block\"\ngroup = \"right\"\npressure = {P:e}\n{ramp}\n",
        lo = 0.2 - e,
        hi = 0.2 + e,
    );
    let path = dir.join("block.toml");
    std::fs::write(&path, text).unwrap();
    Scene::load(&path).unwrap()
}

/// Runs `scene` into `dir/out`; returns the simulation, the output folder and its summary.
fn run_block(scene: Scene, dir: &Path) -> (Simulation, std::path::PathBuf, serde_json::Value) {
    let mut sim = Simulation::build(scene).unwrap();
    let out = dir.join("out");
    run(&mut sim, &out, &mut |_| {}).unwrap();
    let summary = std::fs::read_to_string(out.join("summary.json")).unwrap();
    (sim, out, serde_json::from_str(&summary).unwrap())
}

/// The largest difference of six-component tensors from −p eₓ⊗eₓ.
fn worst_from_uniaxial(tensors: &[f64]) -> f64 {
    let want = [-P, 0.0, 0.0, 0.0, 0.0, 0.0];
    tensors
        .chunks(6)
        .flat_map(|s| s.iter().zip(want).map(|(a, b)| (a - b).abs()))
        .fold(0.0, f64::max)
}

/// Without `vtu_every`, a static run writes one VTU, of its final state: at t = 1 s, with the
/// pressed block's stress in it (the state at t = 0 would be stress-free).
#[test]
fn a_static_run_writes_its_final_state_without_vtu_every() {
    let dir = test_dir("static-final-vtu");
    let (_, out, summary) = run_block(pressed_block(&dir, "", ""), &dir);
    let files = common::entries(&out.join("vtu"));
    assert_eq!(files, ["state_00000.vtu"]);
    assert_eq!(summary["vtu_files"], 1);
    let vtu = std::fs::read_to_string(out.join("vtu/state_00000.vtu")).unwrap();
    assert!(
        vtu.contains("Name=\"TimeValue\" NumberOfTuples=\"1\" format=\"ascii\">1.0<"),
        "no TimeValue 1.0 in the VTU"
    );
    let worst = worst_from_uniaxial(&common::vtu_array(&vtu, "stress"));
    assert!(worst <= 1e-9 * P, "largest stress error {worst:e} Pa");
    let pvd = std::fs::read_to_string(out.join("results.pvd")).unwrap();
    assert_eq!(pvd.matches("<DataSet ").count(), 1, "{pvd}");
    assert!(pvd.contains("timestep=\"1\""), "{pvd}");
}

/// The default step is t_end/100, so a constant load has 101 levels (t = 0 included) of the
/// same loads: one solve. A ramp to full load at 0.5 s, then held, has 51 distinct levels
/// (0, 0.01, …, 0.5 s) and 50 that repeat the last: 51 solves. The answer is the same
/// either way (−p eₓ⊗eₓ), and the last level is at t_end = 1 s exactly, not at the sum of
/// a hundred steps of 0.01 s (1.0000000000000007).
#[test]
fn a_static_run_solves_once_per_distinct_load_level_at_times_as_given() {
    let dir = test_dir("static-levels");
    for (ramp, solves) in [("", 1), ("ramp = [[0.0, 0.0], [0.5, 1.0], [1.0, 1.0]]", 51)] {
        let (_, out, summary) = run_block(pressed_block(&dir, "", ramp), &dir);
        assert_eq!(summary["steps"], 100, "{ramp}");
        assert_eq!(summary["solves"], solves, "{ramp}");
        assert_eq!(summary["final_time"].as_f64(), Some(1.0), "{ramp}");
        let vtu = std::fs::read_to_string(out.join("vtu/state_00000.vtu")).unwrap();
        let worst = worst_from_uniaxial(&common::vtu_array(&vtu, "stress"));
        assert!(
            worst <= 1e-9 * P,
            "{ramp}: largest stress error {worst:e} Pa"
        );
    }
}

/// The VTU's `gmsh_node_id` of every point is the file's node at the same coordinates, its
/// `gmsh_element_id` of every cell the file's element of the same nodes, and its
/// `physical_group` the volume `body` (tag 1), although the body was reordered (the ids
/// are not in file order).
#[test]
fn gmsh_ids_in_the_vtu_are_the_msh_files_after_reordering() {
    let dir = test_dir("static-gmsh-ids");
    let (sim, out, _) = run_block(pressed_block(&dir, "", ""), &dir);
    let (file_nodes, file_tets) =
        common::parse_msh22(&std::fs::read_to_string(fixture("msh/box_gmsh22_ascii.msh")).unwrap());
    let vtu = std::fs::read_to_string(out.join("vtu/state_00000.vtu")).unwrap();
    let points = common::vtu_array(&vtu, "Points");
    let node_ids = common::vtu_integers(&vtu, "gmsh_node_id");
    assert_eq!(node_ids.len(), sim.world.state.len());
    assert_eq!(node_ids.len(), file_nodes.len());
    let in_file_order: Vec<i64> = (1..=node_ids.len() as i64).collect();
    assert_ne!(node_ids, in_file_order, "the body was not reordered");
    for (p, id) in points.chunks(3).zip(&node_ids) {
        assert_eq!(p, file_nodes[id], "node {id}");
    }
    let connectivity = common::vtu_integers(&vtu, "connectivity");
    let element_ids = common::vtu_integers(&vtu, "gmsh_element_id");
    assert_eq!(element_ids.len(), file_tets.len());
    for (cell, id) in connectivity.chunks(4).zip(&element_ids) {
        let mut got: Vec<i64> = cell.iter().map(|&k| node_ids[k as usize]).collect();
        let mut want = file_tets[id].to_vec();
        got.sort_unstable();
        want.sort_unstable();
        assert_eq!(got, want, "element {id}");
    }
    assert_eq!(
        common::vtu_integers(&vtu, "physical_group"),
        vec![1; element_ids.len()]
    );
}

/// Under the uniform stress every node's volume-weighted average of the stresses around it
/// is the element stress: −p eₓ⊗eₓ to the same 10⁻⁹ p, and within the spread of the element
/// values of each component (an average of them) to rounding.
#[test]
fn nodal_stress_of_a_uniform_stress_is_the_element_stress() {
    let dir = test_dir("static-nodal-stress");
    let (sim, out, _) = run_block(pressed_block(&dir, "", ""), &dir);
    let vtu = std::fs::read_to_string(out.join("vtu/state_00000.vtu")).unwrap();
    let nodal = common::vtu_array(&vtu, "nodal_stress");
    let element = common::vtu_array(&vtu, "stress");
    assert_eq!(nodal.len(), 6 * sim.world.state.len());
    let worst = worst_from_uniaxial(&nodal);
    eprintln!("nodal stress: largest error {:.2e} p", worst / P);
    assert!(worst <= 1e-9 * P, "largest nodal stress error {worst:e} Pa");
    for c in 0..6 {
        let values = element.iter().skip(c).step_by(6);
        let lo = values.clone().fold(f64::INFINITY, |a, &b| a.min(b));
        let hi = values.fold(f64::NEG_INFINITY, |a, &b| a.max(b));
        let slack = 1e-15 * P;
        for n in nodal.iter().skip(c).step_by(6) {
            assert!(
                *n >= lo - slack && *n <= hi + slack,
                "component {c}: {n} not in [{lo}, {hi}]"
            );
        }
    }
}
