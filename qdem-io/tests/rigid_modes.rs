//! `qdem modes` with rigid bodies (their six DOFs): a rigid cube resting on a plane wall
//! through the linear springs of its bottom face's contact spheres.
//!
//! The reference is an independent dense solve of the same 6-DOF problem, written here from
//! first principles: each touching sphere is a spring k = kn n nᵀ + kt (I − n nᵀ) at its
//! contact point (the middle of the overlap), whose motion is u_c + θ × a for the arm a from
//! the cube's centre, so K = Σ Jᵀ k J with J = [I, −[a]×]; M = diag(m, m, m, I, I, I) with the
//! cube's m = ρ s³ and I = m s² / 6. The two solve the same linear problem, so they agree to
//! rounding: the tolerance is 10⁻⁸ in frequency. The vertical mode, nearly decoupled, is
//! checked against √(N kn / m) / 2π as well.

mod common;

use common::{fixture, test_dir};
use nalgebra::{DMatrix, Matrix3, SymmetricEigen, Vector3};
use qdem_io::build::Simulation;
use qdem_io::modes::{compute_and_write, compute_and_write_as, ModesError, Shapes};
use qdem_io::scene::Scene;
use std::f64::consts::PI;

const RADIUS: f64 = 0.008;
const OVERLAP: f64 = 0.0002;
const KN: f64 = 1e4;
const KT: f64 = 5e3;
const SIDE: f64 = 0.1;
const DENSITY: f64 = 1000.0;

/// The rigid cube (0.1 m, 1 kg), with contact spheres pressed `OVERLAP` into the wall z = 0
/// when `touching`, and the further scene text `extra`.
fn scene(dir: &std::path::Path, touching: bool, extra: &str) -> Scene {
    scene_on(dir, touching.then_some(FLOOR), extra)
}

/// The floor z = 0: a point and the normal.
const FLOOR: ([f64; 3], [f64; 3]) = ([0.0; 3], [0.0, 0.0, 1.0]);

/// The cube of [`scene`] with contact spheres and the wall `wall` (point, normal) when given.
fn scene_on(dir: &std::path::Path, wall: Option<([f64; 3], [f64; 3])>, extra: &str) -> Scene {
    let mesh = fixture("contact/block.msh");
    let (contact, spheres, wall) = match wall {
        Some((point, normal)) => (
            format!(
                "[contact]\nlaw = \"linear\"\nnormal_stiffness = {KN:e}\n\
                 tangential_stiffness = {KT:e}\nfriction = 0.5\n"
            ),
            format!("contact_radius = {RADIUS}\n"),
            format!("[[wall]]\npoint = {point:?}\nnormal = {normal:?}\n"),
        ),
        None => (String::new(), String::new(), String::new()),
    };
    let text = format!(
        "[run]\nt_end = 0.01\ndt = 1e-5\ngravity = [0.0, 0.0, 0.0]\n\n[[material]]\nname = \"stiff\"\n\
         density = {DENSITY}\nyoung = 1e10\npoisson = 0.25\n\n{contact}\n[[body]]\n\
         name = \"cube\"\nmesh = {mesh:?}\nmaterial = \"stiff\"\nrigid = true\n{spheres}\
         translate = [0.0, 0.0, {z}]\n\n{wall}\n{extra}",
        z = SIDE / 2.0 + RADIUS - OVERLAP
    );
    let path = dir.join("cube.toml");
    std::fs::write(&path, text).unwrap();
    Scene::load(&path).unwrap()
}

/// The six natural frequencies (Hz, ascending) of the cube on springs of normal `n` at
/// `points` (contact points relative to its centre), by a dense symmetric eigen-solve.
fn dense_frequencies(points: &[Vector3<f64>], n: Vector3<f64>) -> Vec<f64> {
    let k = n * n.transpose() * KN + (Matrix3::identity() - n * n.transpose()) * KT;
    let mut stiffness = DMatrix::<f64>::zeros(6, 6);
    for a in points {
        let mut j = DMatrix::<f64>::zeros(3, 6);
        j.view_mut((0, 0), (3, 3)).copy_from(&Matrix3::identity());
        j.view_mut((0, 3), (3, 3)).copy_from(&(-a.cross_matrix()));
        stiffness += j.transpose() * k * &j;
    }
    cubes_frequencies(stiffness)
}

/// The natural frequencies (Hz, ascending) of cubes whose six DOFs each (translation, then
/// rotation) have the stiffness `stiffness`: M = diag(m, m, m, I, I, I) per cube, with the
/// cube's m = ρ s³ and I = m s² / 6.
fn cubes_frequencies(stiffness: DMatrix<f64>) -> Vec<f64> {
    let mass = DENSITY * SIDE.powi(3);
    let inertia = mass * SIDE * SIDE / 6.0;
    let n = stiffness.nrows();
    let scale = DMatrix::from_fn(n, n, |r, c| match (r == c, r % 6 < 3) {
        (false, _) => 0.0,
        (true, true) => 1.0 / mass.sqrt(),
        (true, false) => 1.0 / inertia.sqrt(),
    });
    let eigen = SymmetricEigen::new(&scale * stiffness * &scale);
    let mut f: Vec<f64> = eigen
        .eigenvalues
        .iter()
        .map(|w2| w2.max(0.0).sqrt() / (2.0 * PI))
        .collect();
    f.sort_by(f64::total_cmp);
    f
}

#[test]
fn a_rigid_cube_on_its_contact_springs_matches_the_dense_six_dof_solve() {
    let dir = test_dir("rigid-modes");
    let mut sim = Simulation::build(scene(&dir, true, "")).unwrap();
    let state = sim.world.state.clone();
    let centre = state.position[state.rigid.center[0]];
    let bottom = RADIUS - OVERLAP;
    // The contact points: the bottom spheres' centres, lowered to the middle of the overlap.
    let points: Vec<Vector3<f64>> = state
        .position
        .iter()
        .filter(|p| (p.z - bottom).abs() < 1e-9)
        .map(|p| p - Vector3::z() * (RADIUS - OVERLAP / 2.0) - centre)
        .collect();
    assert!(points.len() >= 4, "the cube's bottom face has vertices");
    let report = compute_and_write(&mut sim, 6, &dir.join("modes")).unwrap();
    let modes = &report.modes.modes;
    assert_eq!(
        report.modes.dofs, 6,
        "the body's six DOFs, the members eliminated"
    );
    assert_eq!(report.modes.mechanisms, 0);
    let expected = dense_frequencies(&points, Vector3::z());
    for (mode, f) in modes.iter().zip(&expected) {
        let error = mode.frequency_hz / f - 1.0;
        eprintln!(
            "rigid cube: {:.9} Hz, dense {f:.9} Hz, error {error:.1e}",
            mode.frequency_hz
        );
        assert!(!mode.rigid && error.abs() < 1e-8, "error {error:.3e}");
    }
    let vertical = modes
        .iter()
        .find(|m| m.dominant().0 == 2)
        .expect("a vertical mode");
    // The mesh's bottom face is not exactly symmetric (its inner vertices are unstructured),
    // so heave couples with rocking at the 10⁻⁷ level of mass fraction (measured: 5 × 10⁻⁷);
    // the closed form holds to that coupling, well inside 10⁻⁵.
    let bounce = (points.len() as f64 * KN / (DENSITY * SIDE.powi(3))).sqrt() / (2.0 * PI);
    let error = vertical.frequency_hz / bounce - 1.0;
    assert!(
        error.abs() < 1e-5,
        "heave {:.9} Hz against {bounce:.9} Hz",
        vertical.frequency_hz
    );
    assert!(vertical.dominant().1 > 1.0 - 1e-5 && vertical.motion[2] > 1.0 - 1e-5);
    // Each direction's effective masses over the six modes (all the DOFs) sum to 1.
    for d in 0..6 {
        let total: f64 = modes.iter().map(|m| m.participation[d]).sum();
        assert!((total - 1.0).abs() < 1e-9, "direction {d}: {total}");
    }
    // Every mode moves the members rigidly with the centre: no pair of particles of the cube
    // changes its distance, (u_i − u_j)·(x_i − x_j) = 0 to rounding.
    for mode in modes {
        let scale = mode.shape.iter().map(|u| u.norm()).fold(0.0, f64::max) * SIDE;
        for (i, (xi, ui)) in state
            .position
            .iter()
            .zip(&mode.shape)
            .enumerate()
            .step_by(7)
        {
            for (xj, uj) in state.position.iter().zip(&mode.shape).skip(i + 1) {
                assert!(((ui - uj).dot(&(xi - xj))).abs() < 1e-12 * scale);
            }
        }
    }
}

#[test]
fn a_free_rigid_cube_reports_its_six_rigid_modes() {
    let dir = test_dir("rigid-modes-free");
    let mut sim = Simulation::build(scene(&dir, false, "")).unwrap();
    let report = compute_and_write(&mut sim, 6, &dir.join("modes")).unwrap();
    let modes = &report.modes.modes;
    assert_eq!(modes.len(), 6);
    assert!(modes.iter().all(|m| m.rigid && m.frequency_hz < 1.0));
    for d in 0..6 {
        let total: f64 = modes.iter().map(|m| m.participation[d]).sum();
        assert!((total - 1.0).abs() < 1e-12, "direction {d}: {total}");
    }
}

/// Held in z with its rotation (a fix on its members without `rotation = true` holds it at
/// those points instead, which the analysis refuses by the fix: `rigid_holds.rs`), the cube
/// keeps its two translations across z free, and nothing touches it.
#[test]
fn a_rigid_cube_fixed_in_part_and_touching_nothing_is_refused() {
    let dir = test_dir("rigid-modes-partly");
    let fix =
        "[[fix]]\nbody = \"cube\"\nbox = [[-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]]\ndofs = \"z\"\n\
               rotation = true\n";
    let mut sim = Simulation::build(scene(&dir, false, fix)).unwrap();
    let error = compute_and_write(&mut sim, 2, &dir.join("modes")).unwrap_err();
    let ModesError::Modal { .. } = &error else {
        panic!("not a modal error: {error}");
    };
    let message = error.to_string();
    assert!(
        message.contains("body `cube`") && message.contains("2 of its 6 rigid-body modes"),
        "{message}"
    );
}

/// On a floor tilted so that one corner's sphere alone touches, the cube keeps its three
/// rotations about that contact point unresisted: they are found as mechanisms and left out,
/// and the three others match the dense solve.
#[test]
fn a_rigid_cube_on_one_contact_keeps_three_unresisted_rotations() {
    let dir = test_dir("rigid-modes-corner");
    let n = Vector3::new(1.0, 1.0, 20.0).normalize();
    let corner = Vector3::new(-SIDE / 2.0, -SIDE / 2.0, RADIUS - OVERLAP);
    let point = corner - (RADIUS - OVERLAP) * n;
    let wall = Some((point.into(), n.into()));
    let mut sim = Simulation::build(scene_on(&dir, wall, "")).unwrap();
    let centre = sim.world.state.position[sim.world.state.rigid.center[0]];
    let contact = corner - (RADIUS - OVERLAP / 2.0) * n - centre;
    let report = compute_and_write(&mut sim, 3, &dir.join("modes")).unwrap();
    assert_eq!(
        report.modes.mechanisms, 3,
        "the rotations about the contact point"
    );
    let expected = dense_frequencies(&[contact], n);
    assert!(
        expected[2] < 1e-6 * expected[3],
        "the dense solve has three zeros too"
    );
    for (mode, f) in report.modes.modes.iter().zip(&expected[3..]) {
        let error = mode.frequency_hz / f - 1.0;
        assert!(
            error.abs() < 1e-8,
            "{} Hz against {f} Hz",
            mode.frequency_hz
        );
    }
    let more = compute_and_write(&mut sim, 4, &dir.join("modes")).unwrap_err();
    assert!(more.to_string().contains("at most 3"), "{more}");
}

/// Two rigid cubes stacked on the floor, the upper resting on the lower through the pairs of
/// their facing spheres: the twelve frequencies match the dense solve, whose pair springs
/// join the two bodies' contact points (arms from each centre to the middle of the overlap).
#[test]
fn two_stacked_rigid_cubes_match_the_dense_twelve_dof_solve() {
    let dir = test_dir("rigid-modes-stack");
    let z0 = SIDE / 2.0 + RADIUS - OVERLAP;
    // The pairs overlap by half the wall contacts' overlap: a build refuses an initial overlap
    // between bodies beyond 5% of the reduced radius.
    let pair_overlap = OVERLAP / 2.0;
    let z1 = z0 + SIDE + 2.0 * RADIUS - pair_overlap;
    let mesh = fixture("contact/block.msh");
    let body = |name: &str, z: f64| {
        format!(
            "[[body]]\nname = \"{name}\"\nmesh = {mesh:?}\nmaterial = \"stiff\"\nrigid = true\n\
             contact_radius = {RADIUS}\ntranslate = [0.0, 0.0, {z}]\n\n"
        )
    };
    let text = format!(
        "[run]\nt_end = 0.01\ngravity = [0.0, 0.0, 0.0]\n\n[[material]]\nname = \"stiff\"\n\
         density = {DENSITY}\nyoung = 1e10\npoisson = 0.25\n\n[contact]\nlaw = \"linear\"\n\
         normal_stiffness = {KN:e}\ntangential_stiffness = {KT:e}\nfriction = 0.5\n\n{}{}\
         [[wall]]\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\n",
        body("lower", z0),
        body("upper", z1)
    );
    let path = dir.join("stack.toml");
    std::fs::write(&path, text).unwrap();
    let mut sim = Simulation::build(Scene::load(&path).unwrap()).unwrap();
    let state = sim.world.state.clone();
    let rigid = &state.rigid;
    let centre = |b: usize| state.position[rigid.center[b]];
    let face = |b: usize, z: f64| -> Vec<Vector3<f64>> {
        rigid
            .members(b)
            .iter()
            .map(|&m| state.position[m])
            .filter(|p| (p.z - z).abs() < 1e-9)
            .collect()
    };
    // J of a point at arm a of body b among the 12 DOFs: u = u_c + θ × a.
    let jacobian = |b: usize, arm: Vector3<f64>| {
        let mut j = DMatrix::<f64>::zeros(3, 12);
        j.view_mut((0, 6 * b), (3, 3))
            .copy_from(&Matrix3::identity());
        j.view_mut((0, 6 * b + 3), (3, 3))
            .copy_from(&(-arm.cross_matrix()));
        j
    };
    let n = Vector3::z();
    let k = n * n.transpose() * KN + (Matrix3::identity() - n * n.transpose()) * KT;
    let mut stiffness = DMatrix::<f64>::zeros(12, 12);
    let lever = RADIUS - OVERLAP / 2.0;
    for p in face(0, RADIUS - OVERLAP) {
        let j = jacobian(0, p - lever * n - centre(0));
        stiffness += j.transpose() * k * &j;
    }
    let (upper, lower) = (face(1, z1 - SIDE / 2.0), face(0, z0 + SIDE / 2.0));
    let mut pairs = 0;
    for q in &upper {
        for p in lower.iter().filter(|p| (p.xy() - q.xy()).norm() < 1e-9) {
            let contact = p + (RADIUS - pair_overlap / 2.0) * n;
            let j = jacobian(1, contact - centre(1)) - jacobian(0, contact - centre(0));
            stiffness += j.transpose() * k * &j;
            pairs += 1;
        }
    }
    assert!(pairs >= 4, "the cubes touch through their facing spheres");
    let expected = cubes_frequencies(stiffness);
    let report = compute_and_write(&mut sim, 12, &dir.join("modes")).unwrap();
    assert_eq!(report.modes.modes.len(), 12);
    for (mode, f) in report.modes.modes.iter().zip(&expected) {
        let error = mode.frequency_hz / f - 1.0;
        assert!(
            error.abs() < 1e-8,
            "{} Hz against {f} Hz",
            mode.frequency_hz
        );
    }
}

/// A `[ballast]` stone touching nothing (in flight above a bed) under gravity is not refused:
/// the stones are many bodies, and one in the air leaves the bed's modes as they are. Its
/// six rigid-body modes are kept as rigid, the one gravity does work along (its fall) is
/// counted; the cube resting on its springs keeps the frequencies it has alone, to rounding.
#[test]
fn a_ballast_stone_in_flight_is_counted_and_leaves_the_bed_modes_alone() {
    let dir = test_dir("rigid-modes-stone-in-flight");
    let stone = fixture("ballast/stones/coarse/stone_00.msh");
    let ballast = format!(
        "[ballast]\nname = \"ballast\"\nmaterial = \"stiff\"\nmeshes = [{stone:?}]\n\
         contact_radius = 0.01\ncount = 1\nregion = [[-0.5, -0.5, 1.0], [0.5, 0.5, 1.5]]\n\
         seed = 1\nrigid = true\n"
    );
    let mut alone = scene(&dir, true, "");
    alone.run.gravity = [0.0, 0.0, -9.81];
    let mut sim = Simulation::build(alone).unwrap();
    let cube = compute_and_write(&mut sim, 6, &dir.join("alone")).unwrap();
    assert_eq!(cube.loose_stone_modes, 0);
    let mut with_stone = scene(&dir, true, &ballast);
    with_stone.run.gravity = [0.0, 0.0, -9.81];
    let mut sim = Simulation::build(with_stone).unwrap();
    let report = compute_and_write(&mut sim, 12, &dir.join("with-stone")).unwrap();
    assert_eq!(
        report.loose_stone_modes, 1,
        "gravity works along the stone's fall only"
    );
    let (rigid, elastic): (Vec<_>, Vec<_>) = report.modes.modes.iter().partition(|m| m.rigid);
    assert_eq!(rigid.len(), 6);
    for (mode, alone) in elastic.iter().zip(&cube.modes.modes) {
        let error = mode.frequency_hz / alone.frequency_hz - 1.0;
        assert!(
            error.abs() < 1e-8,
            "{} Hz against {} Hz",
            mode.frequency_hz,
            alone.frequency_hz
        );
    }
}

/// Without the shapes (`qdem modes --no-shapes`) the same modes.csv is written, byte for
/// byte, and no mesh: neither modes.pvd nor vtu/.
#[test]
fn modes_without_shapes_write_the_same_table_and_no_mesh() {
    let dir = test_dir("rigid-modes-no-shapes");
    let mut sim = Simulation::build(scene(&dir, true, "")).unwrap();
    let with = compute_and_write(&mut sim, 6, &dir.join("with")).unwrap();
    let mut sim = Simulation::build(scene(&dir, true, "")).unwrap();
    let without = compute_and_write_as(&mut sim, 6, &dir.join("without"), Shapes::None).unwrap();
    assert!(with.pvd.is_some() && without.pvd.is_none());
    assert_eq!(
        std::fs::read(&with.csv).unwrap(),
        std::fs::read(&without.csv).unwrap()
    );
    assert!(!dir.join("without/vtu").exists() && !dir.join("without/modes.pvd").exists());
}

/// A body that nothing fixes or holds but a load or gravity pushes is not in equilibrium:
/// refused, naming the body and what pushes it, and no file is written.
#[test]
fn a_free_body_under_a_load_or_gravity_is_refused() {
    let dir = test_dir("rigid-modes-loaded");
    let load = "[[load]]\nbody = \"cube\"\nbox = [[-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]]\n\
                total_force = [0.0, 0.0, -10.0]\n";
    let mut sim = Simulation::build(scene(&dir, false, load)).unwrap();
    let error = compute_and_write(&mut sim, 6, &dir.join("loaded")).unwrap_err();
    assert!(
        matches!(error, ModesError::LoadedFreeBody { .. }),
        "{error}"
    );
    let message = error.to_string();
    assert!(
        message.contains("`cube`") && message.contains("[[load]] #1"),
        "{message}"
    );
    assert!(!dir.join("loaded").exists(), "nothing written");
    let mut falling = scene(&dir, false, "");
    falling.run.gravity = [0.0, 0.0, -9.81];
    let mut sim = Simulation::build(falling).unwrap();
    let error = compute_and_write(&mut sim, 6, &dir.join("falling")).unwrap_err();
    assert!(error.to_string().contains("gravity pushes it"), "{error}");
}

/// A bonded beam without supports (its lattice held out of its plane only) is refused, and
/// told to take `[bonded] supports`, not `[[fix]]`, which a bonded scene does not take.
#[test]
fn a_bonded_beam_without_supports_is_told_to_take_supports() {
    let dir = test_dir("rigid-modes-free-bonded");
    let path = dir.join("beam.toml");
    let text = "[run]\nt_end = 0.1\nintegrator = \"newmark\"\nbeta = 0.0\ngamma = 0.5\n\
                gravity = [0.0, -9.81, 0.0]\n\
                [[material]]\nname = \"concrete\"\ndensity = 2400.0\nyoung = 30e9\n\
                poisson = 0.25\n\
                [bonded]\nname = \"beam\"\nmaterial = \"concrete\"\nsize = [0.4, 0.1]\n\
                element_size = 0.05\nstrength_mean = 6e6\nsupports = \"none\"\n";
    std::fs::write(&path, text).unwrap();
    let mut sim = Simulation::build(Scene::load(&path).unwrap()).unwrap();
    let error = compute_and_write(&mut sim, 6, &dir.join("modes")).unwrap_err();
    let message = error.to_string();
    assert!(
        matches!(error, ModesError::UnsupportedBonded { .. }),
        "{message}"
    );
    assert!(message.contains("supports = \"simple\""), "{message}");
}

/// The same cube made deformable (E = 10 GPa, about 10⁴ times stiffer than its springs, see
/// `contact_modes.rs`) heaves at the rigid cube's frequency to the stiffness ratio: the two
/// representations agree within 10⁻³. (Its vertex spheres do not turn, so its rocking modes
/// take the tangential springs at the spheres' centres and differ: only heave is compared.)
#[test]
fn the_rigid_cube_heaves_as_the_stiff_deformable_one() {
    let dir = test_dir("rigid-modes-versus-deformable");
    let heave = |scene: Scene| {
        let mut sim = Simulation::build(scene).unwrap();
        let report = compute_and_write(&mut sim, 6, &dir.join("modes")).unwrap();
        let mode = report.modes.modes.into_iter().find(|m| m.dominant().0 == 2);
        mode.expect("a heave mode").frequency_hz
    };
    let rigid = heave(scene(&dir, true, ""));
    let mut deformable = scene(&dir, true, "");
    deformable.bodies[0].rigid = false;
    deformable.run.dt = Default::default();
    let deformable = heave(deformable);
    let error = deformable / rigid - 1.0;
    eprintln!("heave: rigid {rigid:.6} Hz, deformable {deformable:.6} Hz, error {error:.1e}");
    assert!(
        error.abs() < 1e-3,
        "deformable {deformable} Hz, rigid {rigid} Hz"
    );
}
