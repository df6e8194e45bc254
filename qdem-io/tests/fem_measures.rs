//! What an FEM user measures (issue 40, part A): a pressure on a face lumped to its nodes,
//! the stress tensor and principal stresses of the tetrahedra's VTU with its `TimeValue`,
//! the reactions of the fixes, and `qdem analyze`'s input load from a pressure `series`.
//!
//! The pressed block: the gmsh box 0.3 × 0.2 × 0.1 m (`fixtures/msh`), its face x = 0.3 under
//! a pressure p, held on its face x = 0 in x only, at the origin in y and z and at
//! (0, 0.2, 0) in z: supports that stop the rigid motions and nothing else, so the linear
//! solution is the uniform uniaxial stress σ = −p eₓ⊗eₓ, which a linear tetrahedral mesh
//! represents exactly. The static solve reaches it to the solver's rounding (the
//! displacements of 10⁻⁵ m are stored beside coordinates of 0.1 m, ~10⁻¹¹ relative), so
//! every tetrahedron's stress is checked to 10⁻⁹ p.

mod common;

use common::{fixture, test_dir};
use qdem_core::loads::NodalLoad;
use qdem_io::analyze::{analyze, AnalyzeOptions};
use qdem_io::build::{load_resultant, Simulation};
use qdem_io::runner::run;
use qdem_io::scene::Scene;
use std::path::Path;

const P: f64 = 1.0e6;
const AREA: f64 = 0.2 * 0.1;

/// The pressed block's scene in `dir` with `load` as its `[[load]]`'s force keys.
fn pressed_block(dir: &Path, load: &str) -> Scene {
    let mesh = fixture("msh/box_gmsh22_ascii.msh");
    let e = 1e-9;
    let text = format!(
        "[run]\nt_end = 1.0\ndt = 1.0\nintegrator = \"static\"\n\n\
         [[material]]\nname = \"concrete\"\ndensity = 2350.0\nyoung = 45e9\npoisson = 0.2\n\n\
         [[body]]\nname = \"block\"\nmesh = {mesh:?}\nmaterial = \"concrete\"\n\n\
         [[fix]]\nbody = \"block\"\ngroup = \"left\"\ndofs = \"x\"\n\n\
         [[fix]]\nbody = \"block\"\ngroup = \"origin\"\ndofs = \"yz\"\n\n\
         [[fix]]\nbody = \"block\"\nbox = [[-{e}, {lo}, -{e}], [{e}, {hi}, {e}]]\ndofs = \"z\"\n\n\
         [[load]]\nbody = \"block\"\ngroup = \"right\"\n{load}\n\n\
         [output]\nvtu_every = 1.0\n",
        lo = 0.2 - e,
        hi = 0.2 + e,
    );
    let path = dir.join("block.toml");
    std::fs::write(&path, text).unwrap();
    Scene::load(&path).unwrap()
}

/// The nodal forces of a pressure sum to p·A along the inward normal, and those of a
/// traction to t·A, to 10⁻¹² (they are sums of A_k/3 over the face's triangles).
#[test]
fn pressure_and_traction_forces_sum_to_load_times_area() {
    let dir = test_dir("fem-pressure-sum");
    let sim = Simulation::build(pressed_block(&dir, &format!("pressure = {P:e}"))).unwrap();
    let total = sim.world.model::<NodalLoad>().unwrap().total();
    assert!((total.x + P * AREA).abs() <= 1e-12 * P * AREA, "{total}");
    assert!(total.y.abs() + total.z.abs() <= 1e-12 * P * AREA, "{total}");

    let sim = Simulation::build(pressed_block(&dir, "traction = [0.0, 3.0e5, -1.0e5]")).unwrap();
    let total = sim.world.model::<NodalLoad>().unwrap().total();
    let want = qdem_core::Vec3::new(0.0, 3.0e5, -1.0e5) * AREA;
    assert!(
        (total - want).norm() <= 1e-12 * want.norm(),
        "{total} vs {want}"
    );
}

/// A pressure or traction `series` load counts in `qdem analyze` as its resultant: the
/// scene-only [`load_resultant`] is p·A along the inward normal (and t·A for a traction) to
/// 10⁻¹², and a probe whose velocity is 3e-6 (m/s)/N times p·A times the series has a
/// mobility of 3e-6 at every frequency, as a `total_force` load of p·A gives (a pressure
/// load used to count as no load at all).
#[test]
fn analyze_sizes_a_pressure_series_by_its_resultant() {
    let dir = test_dir("fem-analyze-pressure");
    let (dt, n) = (1e-4, 3000);
    let factor = |t: f64| 1.0 + (2.0 * std::f64::consts::PI * 37.0 * t).sin();
    let mut series = String::from("time,p\n");
    for i in 0..n {
        let t = i as f64 * dt;
        series.push_str(&format!("{t},{}\n", factor(t)));
    }
    std::fs::write(dir.join("series.csv"), series).unwrap();
    let traction = pressed_block(&dir, "traction = [0.0, 3.0e5, -1.0e5]");
    let want = qdem_core::Vec3::new(0.0, 3.0e5, -1.0e5) * AREA;
    let got = load_resultant(&traction, 0).unwrap();
    assert!(
        (got - want).norm() <= 1e-12 * want.norm(),
        "{got} vs {want}"
    );
    let load = format!("pressure = {P:e}\nseries = {{ file = \"series.csv\", column = \"p\" }}");
    let scene = pressed_block(&dir, &load);
    let got = load_resultant(&scene, 0).unwrap();
    let want = qdem_core::Vec3::new(-P * AREA, 0.0, 0.0);
    assert!((got - want).norm() <= 1e-12 * P * AREA, "{got} vs {want}");
    let mut probes = String::from("time,c.ux,c.uy,c.uz,c.vx,c.vy,c.vz,c.ax,c.ay,c.az\n");
    for i in 0..n {
        let t = i as f64 * dt;
        let vz = 3e-6 * P * AREA * factor(t);
        probes.push_str(&format!("{t},0,0,0,0,0,{vz},0,0,0\n"));
    }
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("probes.csv"), probes).unwrap();
    let a = analyze(&scene, &out, &AnalyzeOptions::default()).unwrap();
    assert!(a.mobility);
    let mobility = std::fs::read_to_string(a.dir.join("mobility.csv")).unwrap();
    let mut rows = 0;
    for line in mobility.lines().skip(1) {
        let m: f64 = line.split(',').nth(1).unwrap().parse().unwrap();
        assert!((m - 3e-6).abs() < 1e-9 * 3e-6, "{line}");
        rows += 1;
    }
    assert!(rows > 100, "{rows} rows");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The pressed block solved statically: every tetrahedron's stress in the VTU is −p eₓ⊗eₓ to
/// 10⁻⁹ p, its principal stresses are (0, 0, −p) and its von Mises stress p; the file carries
/// its time.
#[test]
fn pressed_block_has_uniform_stress_in_the_vtu() {
    let dir = test_dir("fem-pressed-block");
    let mut sim = Simulation::build(pressed_block(&dir, &format!("pressure = {P:e}"))).unwrap();
    let out = dir.join("out");
    run(&mut sim, &out, &mut |_| {}).unwrap();
    let vtu = std::fs::read_to_string(out.join("vtu/state_00001.vtu")).unwrap();
    assert!(
        vtu.contains("Name=\"TimeValue\" NumberOfTuples=\"1\" format=\"ascii\">1.0<"),
        "no TimeValue 1.0 in the VTU"
    );
    let tets = sim.tets();
    let stress = common::vtu_array(&vtu, "stress");
    assert_eq!(stress.len(), 6 * tets);
    let want = [-P, 0.0, 0.0, 0.0, 0.0, 0.0];
    let worst = stress
        .chunks(6)
        .flat_map(|s| s.iter().zip(want).map(|(a, b)| (a - b).abs()))
        .fold(0.0, f64::max);
    eprintln!("pressed block: largest stress error {:.2e} p", worst / P);
    assert!(
        worst <= 1e-9 * P,
        "largest stress error {worst:e} Pa of p = {P:e}"
    );
    for (name, want) in [
        ("principal_stress_1", 0.0),
        ("principal_stress_2", 0.0),
        ("principal_stress_3", -P),
        ("von_mises", P),
    ] {
        let values = common::vtu_array(&vtu, name);
        assert_eq!(values.len(), tets);
        let worst = values.iter().map(|v| (v - want).abs()).fold(0.0, f64::max);
        assert!(worst <= 1e-9 * P, "{name}: largest error {worst:e} Pa");
    }
}

/// The paper's cantilever (2.4 × 0.25 × 0.22 m, clamped at x = 0) solved statically under a
/// downward traction of 200 N in all on its tip face x = 2.4: the clamp's reaction in
/// `reactions.csv` is the tip load, +200 N along z, and its moment about the clamp's node
/// centroid c the tip load's arm: M_y = −200 N × 2.4 m, M_x = 200 N × (0.125 − c_y) (the
/// lumped traction acts at the face's centroid, (2.4, 0.125, 0.11)), M_z = 0. Measured to
/// ~10⁻¹² of the load; the CSV's nine digits bound the check at 10⁻⁸.
#[test]
fn cantilever_reaction_is_the_tip_load_and_its_moment() {
    let dir = test_dir("fem-cantilever-reaction");
    let path = common::short_cantilever(
        &dir,
        &[
            ("integrator = \"verlet\"", "integrator = \"static\""),
            ("t_end = 0.02", "t_end = 1.0"),
            ("dt = \"auto\"", "dt = 1.0"),
            ("probe_every = 1e-4", "probe_every = 1.0"),
            ("vtu_every = 0.05", "vtu_every = 0.0"),
            (
                "total_force = [0.0, 0.0, -200.0]",
                "traction = [0.0, 0.0, -3636.363636363636]",
            ),
            (
                "ramp = [[0.0, 0.0], [0.01, 1.0], [2.0, 1.0], [2.0, 0.0]]",
                "",
            ),
        ],
    );
    let mut sim = Simulation::build(Scene::load(&path).unwrap()).unwrap();
    let load = sim.world.model::<NodalLoad>().unwrap().total();
    assert!((load.z + 200.0).abs() < 1e-9, "tip load {load}");
    let clamp = &sim.fix_particles[0];
    let c_y = clamp
        .iter()
        .map(|&i| sim.world.state.reference[i].y)
        .sum::<f64>()
        / clamp.len() as f64;
    let out = dir.join("out");
    run(&mut sim, &out, &mut |_| {}).unwrap();
    let csv = std::fs::read_to_string(out.join("reactions.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next().unwrap(),
        "time,fix1_fx,fix1_fy,fix1_fz,fix1_mx,fix1_my,fix1_mz"
    );
    let last: Vec<f64> = lines
        .last()
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    let want = [1.0, 0.0, 0.0, 200.0, 200.0 * (0.125 - c_y), -480.0, 0.0];
    let error = |k: usize| (last[k] - want[k]).abs();
    eprintln!("cantilever reaction {:?} (want {want:?})", &last);
    for k in 1..4 {
        assert!(
            error(k) <= 1e-8 * 200.0,
            "force {k}: {} vs {}",
            last[k],
            want[k]
        );
    }
    for k in 4..7 {
        assert!(
            error(k) <= 1e-8 * 480.0,
            "moment {k}: {} vs {}",
            last[k],
            want[k]
        );
    }
}
