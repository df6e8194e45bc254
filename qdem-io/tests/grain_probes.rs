//! Particle-level DEM through the scene format: a `[granular]` sample's initial `velocity` and
//! `angular_velocity`, probes on a stone (by number and nearest a point) and on a box (mean
//! velocity, kinetic energy, count), a rigid `[[body]]`'s `angular_velocity`, and the
//! acceleration a probe on a rigid body's surface vertex reads.
//!
//! - A sphere thrown spinning at a wall slides throughout the contact: Δv_t = μ (1 + e) v_n
//!   and Δω = 5 μ (1 + e) v_n / (2R) (the spin read from the box probe's kinetic energy, the
//!   sphere's mass and inertia the closed forms).
//! - A probe on a rigid body's vertex reads the rigid motion's acceleration: the central
//!   difference of its velocity, row to row, on a block spinning in free flight; the
//!   acceleration integrates to the velocity on the block sliding down the incline at
//!   g (sin θ − μ cos θ) (whose contacts chatter).

mod common;

use common::{fixture, test_dir};
use qdem_io::build::Simulation;
use qdem_io::runner::run;
use qdem_io::scene::Scene;
use std::collections::HashMap;
use std::f64::consts::PI;
use std::path::Path;

const RADIUS: f64 = 0.01;
const DENSITY: f64 = 2500.0;
const FRICTION: f64 = 0.3;

/// `probes.csv` as columns by name.
fn columns(out: &Path) -> HashMap<String, Vec<f64>> {
    let text = std::fs::read_to_string(out.join("probes.csv")).unwrap();
    let mut lines = text.lines();
    let names: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    let mut cols: HashMap<String, Vec<f64>> = names.iter().map(|n| (n.clone(), vec![])).collect();
    for line in lines {
        for (name, value) in names.iter().zip(line.split(',')) {
            cols.get_mut(name).unwrap().push(value.parse().unwrap());
        }
    }
    cols
}

/// Writes `text` as `dir/scene.toml`, runs it into `dir/out` and returns its probe columns.
fn run_scene(dir: &Path, text: &str) -> HashMap<String, Vec<f64>> {
    let path = dir.join("scene.toml");
    std::fs::write(&path, text).unwrap();
    let mut sim = Simulation::build(Scene::load(&path).unwrap()).unwrap();
    let out = dir.join("out");
    run(&mut sim, &out, &mut |_| {}).unwrap();
    columns(&out)
}

#[test]
fn a_sphere_thrown_spinning_at_a_wall_gets_the_sliding_impulses_and_the_probes_follow_it() {
    let dir = test_dir("grain-probes-throw");
    std::fs::write(
        dir.join("ball.csv"),
        format!("stone,x,y,z,radius\n1,0.0,0.0,{},{RADIUS}\n", RADIUS + 1e-6),
    )
    .unwrap();
    // v = (5, 0, -1) m/s, ω = 40 rad/s about y: the contact point slips at 5 − 0.4 m/s,
    // more than 7/2 μ (1 + e) v_n = 2.1 m/s, so it slides throughout.
    let scene = format!(
        r#"
[run]
t_end = 2e-3
dt = 1e-6
probe_every = 1e-4

[[material]]
name = "glass"
density = {DENSITY}
young = 7e10
poisson = 0.3

[contact]
law = "linear"
normal_stiffness = 1e6
tangential_stiffness = 1e6
friction = {FRICTION}

[granular]
name = "balls"
material = "glass"
sample = "ball.csv"
velocity = [5.0, 0.0, -1.0]
angular_velocity = [0.0, 40.0, 0.0]

[[wall]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]

[[probe]]
name = "ball"
body = "balls"
stone = 1

[[probe]]
name = "near"
body = "balls"
point = [0.1, 0.0, 0.0]

[[probe]]
name = "all"
body = "balls"
box = [[-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]]

[[probe]]
name = "none"
body = "balls"
box = [[5.0, 5.0, 5.0], [6.0, 6.0, 6.0]]
"#
    );
    let c = run_scene(&dir, &scene);
    let mass = 4.0 / 3.0 * PI * RADIUS.powi(3) * DENSITY;
    let inertia = 0.4 * mass * RADIUS * RADIUS;
    // The start: the keys' motion, the box over everything holds the sphere, the other none.
    assert_eq!([c["ball.vx"][0], c["ball.vz"][0]], [5.0, -1.0]);
    assert_eq!(c["all.count"][0], 1.0);
    assert_eq!(c["none.count"][0], 0.0);
    assert!(c["none.vx"][0].is_nan());
    let energy = 0.5 * mass * 26.0 + 0.5 * inertia * 1600.0;
    assert!(
        (c["all.ke"][0] / energy - 1.0).abs() < 1e-14,
        "{} vs {energy}",
        c["all.ke"][0]
    );
    assert_eq!(c["all.vx"][0], 5.0);
    // After the bounce (the last row): the impulse laws, e measured.
    let last = c["time"].len() - 1;
    let (vx, vz) = (c["ball.vx"][last], c["ball.vz"][last]);
    assert_eq!(
        c["near.vx"][last], vx,
        "the stone nearest the point is the ball"
    );
    let e = vz / 1.0;
    assert!(e > 0.99 && e < 1.01, "undamped: e = {e}");
    let impulse = FRICTION * (1.0 + e) * 1.0;
    let dv = 5.0 - vx;
    // The spin as the probe reads it (rad/s): about y only, the start's exactly, and the
    // magnitude the box probe's rotational energy gives.
    assert_eq!(c["ball.wy"][0], 40.0);
    let (wx, wz) = (c["ball.wx"][last], c["ball.wz"][last]);
    assert!(wx.abs() < 1e-9 && wz.abs() < 1e-9, "ω = ({wx}, _, {wz})");
    let omega = c["ball.wy"][last];
    let spin_energy = c["all.ke"][last] - 0.5 * mass * (vx * vx + vz * vz);
    assert!(
        (0.5 * inertia * omega * omega / spin_energy - 1.0).abs() < 1e-9,
        "ω = {omega}, rotational energy {spin_energy}"
    );
    let dw = omega - 40.0;
    // The contact point sits at the middle of the overlap, so the lever arm is R − δ̄/2, δ̄
    // the overlap averaged over the friction impulse: π/4 δ_max, δ_max = v_n √(m/k) for the
    // undamped linear spring (qdem-contact's oblique_impact test).
    let mean_overlap = PI / 4.0 * 1.0 * (mass / 1e6).sqrt();
    let spin = 5.0 * impulse / (2.0 * RADIUS) * (1.0 - mean_overlap / (2.0 * RADIUS));
    eprintln!("thrown sphere: e = {e:.6}, Δv_t = {dv:.6} (law {impulse:.6}), Δω = {dw:.4} (law {spin:.4})");
    assert!(
        (dv / impulse - 1.0).abs() < 1e-6,
        "Δv_t = {dv} vs {impulse}"
    );
    assert!((dw / spin - 1.0).abs() < 2e-4, "Δω = {dw} vs {spin}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Largest |a − (v(t + h) − v(t − h)) / 2h| over the rows and axes of probe `name`, and the
/// largest |a|, from row `from` on.
fn central_difference_gap(c: &HashMap<String, Vec<f64>>, name: &str, from: usize) -> (f64, f64) {
    let t = &c["time"];
    let (mut gap, mut largest) = (0.0f64, 0.0f64);
    for axis in ["x", "y", "z"] {
        let v = &c[&format!("{name}.v{axis}")];
        let a = &c[&format!("{name}.a{axis}")];
        for k in from.max(1)..t.len() - 1 {
            let difference = (v[k + 1] - v[k - 1]) / (t[k + 1] - t[k - 1]);
            gap = gap.max((a[k] - difference).abs());
            largest = largest.max(a[k].abs());
        }
    }
    (gap, largest)
}

/// Largest |v(t) − v(t_from) − ∫ a dt| over the rows and axes of probe `name` (the integral by
/// the trapezoid rule over the rows, which is how Verlet's half kicks add up), and the largest
/// |v(t) − v(t_from)|.
fn integration_gap(c: &HashMap<String, Vec<f64>>, name: &str, from: usize) -> (f64, f64) {
    let t = &c["time"];
    let (mut gap, mut change) = (0.0f64, 0.0f64);
    for axis in ["x", "y", "z"] {
        let v = &c[&format!("{name}.v{axis}")];
        let a = &c[&format!("{name}.a{axis}")];
        let mut integral = 0.0;
        for k in from + 1..t.len() {
            integral += 0.5 * (t[k] - t[k - 1]) * (a[k - 1] + a[k]);
            gap = gap.max((v[k] - v[from] - integral).abs());
            change = change.max((v[k] - v[from]).abs());
        }
    }
    (gap, change)
}

#[test]
fn a_probe_on_a_spinning_rigid_bodys_vertex_reads_the_rigid_acceleration() {
    let dir = test_dir("grain-probes-spin");
    let mesh = fixture("contact/block.msh");
    // The 0.1 m cube in free flight under gravity, spinning at 20 rad/s about a tilted axis:
    // its corner accelerates at g + α × r − |ω|² r⊥, some 14 m/s² of it centripetal.
    let scene = format!(
        r#"
[run]
t_end = 0.05
dt = 2e-5
gravity = [0.0, 0.0, -9.81]
probe_every = 2e-5

[[material]]
name = "concrete"
density = 2400.0
young = 30e9
poisson = 0.2

[[body]]
name = "block"
mesh = "{}"
material = "concrete"
rigid = true
velocity = [1.0, 0.0, 0.0]
angular_velocity = [4.0, -6.0, 18.0]

[[probe]]
name = "corner"
body = "block"
point = [0.05, 0.05, 0.05]

[[probe]]
name = "center"
body = "block"
point = [0.0, 0.0, 0.0]
"#,
        mesh.display()
    );
    let c = run_scene(&dir, &scene);
    // The centre falls freely.
    for az in &c["center.az"] {
        assert!((az + 9.81).abs() < 1e-9, "{az}");
    }
    // At t = 0 the corner's velocity is v + ω × r, r = (0.05, 0.05, 0.05).
    let r = [0.05, 0.05, 0.05];
    let w = [4.0, -6.0, 18.0];
    let vx = 1.0 + w[1] * r[2] - w[2] * r[1];
    assert!(
        (c["corner.vx"][0] - vx).abs() < 1e-12,
        "{}",
        c["corner.vx"][0]
    );
    let (gap, largest) = central_difference_gap(&c, "corner", 1);
    eprintln!(
        "spinning block corner: |a| up to {largest:.4} m/s², central difference within {gap:.2e}"
    );
    assert!(largest > 15.0, "the corner turns: |a| = {largest}");
    assert!(gap < 1e-3 * largest, "{gap} of {largest}");
    // A cube's principal moments are equal: free of torque it spins at a constant ω, which a
    // probe on its vertex and one on its centre read.
    for probe in ["corner", "center"] {
        for (axis, want) in ["wx", "wy", "wz"].iter().zip(w) {
            for got in &c[&format!("{probe}.{axis}")] {
                assert!((got - want).abs() < 1e-12 * 18.0, "{probe}.{axis} = {got}");
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_probe_on_a_sliding_rigid_bodys_vertex_reads_the_rigid_acceleration() {
    let dir = test_dir("grain-probes-slide");
    let text = std::fs::read_to_string(fixture("contact/incline.toml")).unwrap();
    let mesh = format!("mesh = \"{}\"", fixture("contact/block.msh").display());
    // A corner of the block (its design placement is rotated onto the slope: the point is
    // taken where the corner lies) sampled every step, to 0.25 s.
    let scene = text
        .replace("mesh = \"block.msh\"", &mesh)
        .replace("t_end = 0.4", "t_end = 0.25")
        .replace("probe_every = 1e-3", "probe_every = 1e-5\ndt = 1e-5")
        .replace(
            "[output]",
            "[[probe]]\nname = \"corner\"\nbody = \"block\"\npoint = [-0.11, 0.05, 0.08]\n\n[output]",
        )
        .replace("vtu_every = 0.05", "vtu_every = 0.0");
    let c = run_scene(&dir, &scene);
    // After the first 0.05 s, in which the block drops 1 mm onto the plane and settles.
    let settled = c["time"].iter().position(|&t| t >= 0.05).unwrap();
    // The contacts chatter (spheres touch and let go, stick and slip), so the acceleration
    // jumps from step to step: its integral, not its central difference, is the velocity.
    let (gap, change) = integration_gap(&c, "corner", settled);
    eprintln!(
        "sliding block corner: velocity changes by up to {change:.4} m/s, the integral of the \
         acceleration within {gap:.2e}"
    );
    assert!(change > 0.05, "the corner speeds up: {change}");
    assert!(gap < 1e-3 * change, "{gap} of {change}");
    // The slide is the Coulomb one: the centre's mean acceleration down the slope (the
    // corner's differs by the block's rocking, ω × r at the ends over the window).
    let theta = 25f64.to_radians();
    let (down_x, down_z) = (-theta.cos(), -theta.sin());
    let rows = (settled..c["time"].len()).len() as f64;
    let mean = |name: &str| {
        (settled..c["time"].len())
            .map(|k| c[&format!("{name}.ax")][k] * down_x + c[&format!("{name}.az")][k] * down_z)
            .sum::<f64>()
            / rows
    };
    let expected = 9.81 * (theta.sin() - FRICTION * theta.cos());
    let (centre, corner) = (mean("center"), mean("corner"));
    eprintln!("sliding block: mean a = {centre:.5} (corner {corner:.5}) vs {expected:.5}");
    assert!(
        (centre / expected - 1.0).abs() < 0.01,
        "{centre} vs {expected}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
