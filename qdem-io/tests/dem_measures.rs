//! `[[measure]]`: the contact stress, solid fraction, coordination and kinetic energy of the
//! stones in a region, against statics.
//!
//! - A bed of one-sphere grains settled under gravity in a cell periodic in x and y on a floor: in a horizontal
//!   layer of the bed, the contact stress σ_zz (Love–Weber, tension positive) is
//!   −ρ g (1 − n) h, with n the porosity of the column of height h above the layer's middle
//!   (a second measure from there to above the free surface, so that ρ (1 − n) h A is the
//!   mass of the stones whose centres lie above): nothing but the floor carries weight, so the contacts through a horizontal plane carry all of it. Over the whole bed the sum
//!   telescopes exactly: σ_zz V = −g Σ m z; `walls.csv` has the floor carry the weight;
//!   `grading.csv` sieves each grain at its diameter; a `[[section]]` with an `area` has the
//!   stress of the weight above it. The coordination number is a frictional packing's.
//! - A bed of clumps (two and three spheres) settled the same way: the whole-bed identity
//!   with each clump's mass and centre of mass, and the floor carrying the weight.

mod common;

use qdem_io::build::Simulation;
use qdem_io::runner::run;
use qdem_io::scene::Scene;
use std::collections::HashMap;
use std::path::Path;

use common::{
    columns, grain_bed, test_dir, BED_DENSITY as DENSITY, BED_G as G, BED_WIDTH as WIDTH,
};
/// The height of the `[[section]]` through the bed (m).
const SECTION: f64 = 0.045;

/// `measure_NAME.csv` of `out` as columns by name.
fn measure(out: &Path, name: &str) -> HashMap<String, Vec<f64>> {
    columns(&out.join(format!("measure_{name}.csv")))
}

#[test]
fn the_contact_stress_of_a_settled_bed_is_its_weight_above() {
    let dir = test_dir("measures-bed");
    let layers = [(0.01, 0.04), (0.025, 0.055), (0.04, 0.07), (0.055, 0.085)];
    let top = 0.3;
    let mut measures = String::new();
    for (k, (lo, hi)) in layers.iter().enumerate() {
        let mid = 0.5 * (lo + hi);
        measures += &format!(
            "[[measure]]\nname = \"layer{k}\"\nbox = [[0.0, 0.0, {lo}], [{WIDTH}, {WIDTH}, {hi}]]\n\
             [[measure]]\nname = \"above{k}\"\nbox = [[0.0, 0.0, {mid}], [{WIDTH}, {WIDTH}, {top}]]\n"
        );
    }
    let area = WIDTH * WIDTH;
    let scene = grain_bed(
        2.0,
        0.01,
        250,
        &format!(
            r#"
{measures}
[[section]]
name = "mid"
axis = "z"
at = {SECTION}
area = {area}

[[measure]]
name = "all"
center = [0.02, 0.02, 0.1]
radius = 1.0
"#
        ),
    );
    let path = dir.join("scene.toml");
    std::fs::write(&path, scene).unwrap();
    let mut sim = Simulation::build(Scene::load(&path).unwrap()).unwrap();
    let out = dir.join("out");
    run(&mut sim, &out, &mut |_| {}).unwrap();
    let all = measure(&out, "all");
    // Settled: the kinetic energy is a ten-millionth of the bed's potential energy scale.
    let (weight, weight_z, above) = stones_weight(&out);
    // sections.csv: the pairs through a plane carry the weight of the stones above it.
    let sections = columns(&out.join("sections.csv"));
    let stress = sections["mid.stress"][sections["mid.stress"].len() - 1];
    let expected = -above / (WIDTH * WIDTH);
    eprintln!("section: {stress:.6} Pa, weight above over the area {expected:.6} Pa");
    assert!(
        (stress / expected - 1.0).abs() < 1e-6,
        "{stress} vs {expected}"
    );
    // grading.csv: one-sphere stones sieve at their diameter, each its sphere's mass, the
    // curve by mass ending at 1.
    let grading = columns(&out.join("grading.csv"));
    for (d, m) in grading["sieve_size"].iter().zip(&grading["mass"]) {
        assert!((0.010..=0.014).contains(d), "sieve size {d}");
        let sphere = DENSITY * std::f64::consts::PI * d.powi(3) / 6.0;
        assert!((m / sphere - 1.0).abs() < 1e-8, "{m} vs {sphere}");
    }
    assert_eq!(grading["mass_passing"].last(), Some(&1.0));
    assert!(grading["sieve_size"].windows(2).all(|w| w[0] <= w[1]));
    // walls.csv: the floor carries the bed's weight (nothing else does).
    let walls = columns(&out.join("walls.csv"));
    let floor = walls["wall1.fz"][walls["wall1.fz"].len() - 1];
    eprintln!("floor: {floor:.9} N, weight {weight:.9} N");
    assert!((floor / -weight - 1.0).abs() < 1e-6, "{floor} vs {weight}");
    let last = all["time"].len() - 1;
    let energy = all["ke_translation"][last] + all["ke_rotation"][last];
    assert!(energy < 1e-7 * weight_z, "not settled: {energy} J");
    // The whole bed (a sphere around it): the contacts through the floor telescope to
    // σ_zz V = −g Σ m z, but for the floor's contact points, half an overlap below it: the
    // bottom spheres' overlaps δ ≈ W / (k n_floor) ≈ 5.7 N / (5e3 N/m · 15) ≈ 8e-5 m shift
    // it by W δ / 2 ≈ 2e-4 N m, 7e-4 of it (measured 8e-4).
    let volume = 4.0 / 3.0 * std::f64::consts::PI;
    let whole = all["szz"][last] * volume;
    eprintln!(
        "whole bed: σzz V = {whole:.6} N m, −g Σ m z = {:.6} N m",
        -weight_z
    );
    assert!(
        (whole / -weight_z - 1.0).abs() < 2e-3,
        "{whole} vs {}",
        -weight_z
    );
    let coordination = all["coordination"][last];
    assert!((3.0..6.0).contains(&coordination), "Z = {coordination}");
    let mut ratios = Vec::new();
    for (k, (lo, hi)) in layers.iter().enumerate() {
        let layer = measure(&out, &format!("layer{k}"));
        let above = measure(&out, &format!("above{k}"));
        let h = top - 0.5 * (lo + hi);
        let szz = layer["szz"][last];
        let porosity = above["porosity"][last];
        let expected = -DENSITY * G * (1.0 - porosity) * h;
        eprintln!(
            "layer {k} (h = {h:.3} m): σzz = {szz:.1} Pa, ρ g (1 − n) h = {expected:.1} Pa \
             (n = {porosity:.4}), ratio {:.4}; layer φ = {:.3}, {} stones",
            szz / expected,
            layer["solid_fraction"][last],
            layer["stones"][last]
        );
        ratios.push(szz / expected);
    }
    // Each layer's σzz is the weight above its mass-midplane up to the offsets of the contact
    // points crossing its two faces (within r_max = 7 mm of them, L = 30 mm apart): ~50
    // contacts a face, force-weighted (a few chains carry most) some 10, scatter the ratio
    // by about r_max/√3/√10 / L ≈ 4% a face, 6% for two: each layer within 15% (2.5σ), their
    // mean (four, half overlapping) within 6%.
    let mean = ratios.iter().sum::<f64>() / ratios.len() as f64;
    eprintln!("ratios {ratios:.4?}, mean {mean:.4}");
    assert!(ratios.iter().all(|r| (r - 1.0).abs() < 0.15), "{ratios:?}");
    assert!((mean - 1.0).abs() < 0.06, "mean ratio {mean}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The settled bed again, of clumps of two and three spheres: a clump's contacts count from
/// its centre of mass (not its spheres' centres), so over the whole bed σ_zz V = −g Σ m z_c
/// still holds (to the floor's half-overlaps, as for one-sphere grains: 2e-3), with m the
/// clump's mass (its spheres' union) and z_c its centre of mass from the run's state (from
/// the spheres' centres instead, each contact force would be weighed at its sphere's height,
/// a few mm off a centre of mass some 12 mm up: tens of percent); the floor carries
/// Σ m g. (A bed of 100 clumps is some 2 cm deep, two grains: too shallow for layers.)
#[test]
fn the_contact_stress_of_a_settled_bed_of_clumps_is_its_weight() {
    const T_END: f64 = 2.0;
    let dir = test_dir("measures-clumps");
    let extra = "[[measure]]\nname = \"all\"\ncenter = [0.02, 0.02, 0.1]\nradius = 1.0\n";
    // Clumps scaled to measure their sieve size are longer than the grains: they are generated
    // in a taller region (the default's 0.25 m holds 71 of them).
    let scene = grain_bed(T_END, 0.01, 100, extra)
        .replace("spheres_per_stone = [1, 1]", "spheres_per_stone = [2, 3]")
        .replace(", 0.25]]\ncount", ", 0.45]]\ncount");
    let path = dir.join("scene.toml");
    std::fs::write(&path, scene).unwrap();
    let mut sim = Simulation::build(Scene::load(&path).unwrap()).unwrap();
    let out = dir.join("out");
    run(&mut sim, &out, &mut |_| {}).unwrap();
    let state = &sim.world.state;
    let info = sim.granular.as_ref().unwrap();
    let spheres: usize = info.stones.iter().map(|(_, m)| m.len()).sum();
    assert!(
        spheres > info.len(),
        "clumps: {spheres} spheres, {} stones",
        info.len()
    );
    let (mut weight, mut weight_z) = (0.0, 0.0);
    for (c, _) in &info.stones {
        weight += state.mass[*c] * G;
        weight_z += state.mass[*c] * G * state.position[*c].z;
    }
    let walls = columns(&out.join("walls.csv"));
    let floor = walls["wall1.fz"][walls["wall1.fz"].len() - 1];
    assert!((floor / -weight - 1.0).abs() < 1e-6, "{floor} vs {weight}");
    let all = measure(&out, "all");
    let last = all["time"].len() - 1;
    let energy = all["ke_translation"][last] + all["ke_rotation"][last];
    assert!(energy < 1e-7 * weight_z, "not settled: {energy} J");
    let whole = all["szz"][last] * 4.0 / 3.0 * std::f64::consts::PI;
    eprintln!(
        "clumps: {} stones, {spheres} spheres, KE/(g Σ m z) {:.1e}; σzz V = {whole:.6} N m, \
         −g Σ m z = {:.6} N m, Z = {:.2}",
        info.len(),
        energy / weight_z,
        -weight_z,
        all["coordination"][last]
    );
    assert!(
        (whole / -weight_z - 1.0).abs() < 2e-3,
        "{whole} vs {}",
        -weight_z
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// g Σ m, g Σ m z, and g Σ m over those above the section, of the stones of `stones.csv`
/// (one-sphere stones, their mass from the radius).
fn stones_weight(out: &Path) -> (f64, f64, f64) {
    let text = std::fs::read_to_string(out.join("stones.csv")).unwrap();
    let (mut weight, mut moment, mut above) = (0.0, 0.0, 0.0);
    for line in text.lines().skip(1) {
        let v: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        let mass = DENSITY * 4.0 / 3.0 * std::f64::consts::PI * v[4].powi(3);
        weight += mass * G;
        moment += mass * G * v[3];
        if v[3] > SECTION {
            above += mass * G;
        }
    }
    (weight, moment, above)
}

/// `probes.csv` of `out` as columns by name.
fn probes(out: &Path) -> HashMap<String, Vec<f64>> {
    columns(&out.join("probes.csv"))
}

/// The rebound ratio −v_out/v_in of a 1 cm sphere thrown at 1 m/s onto a wall under `law`.
fn rebound(dir: &Path, law: &str, restitution: f64) -> f64 {
    let text = format!(
        r#"
[run]
t_end = 2e-3
dt = 2e-7
probe_every = 1e-4

[[material]]
name = "glass"
density = 2500.0
young = 7e10
poisson = 0.3

[contact]
{law}
restitution = {restitution}

[granular]
name = "balls"
material = "glass"
sample = "ball.csv"
velocity = [0.0, 0.0, -1.0]

[[wall]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]

[[probe]]
name = "ball"
body = "balls"
stone = 1
"#
    );
    std::fs::write(
        dir.join("ball.csv"),
        "stone,x,y,z,radius\n1,0,0,0.0101,0.01\n",
    )
    .unwrap();
    let path = dir.join("scene.toml");
    std::fs::write(&path, text).unwrap();
    let mut sim = Simulation::build(Scene::load(&path).unwrap()).unwrap();
    let out = dir.join("out");
    run(&mut sim, &out, &mut |_| {}).unwrap();
    let c = probes(&out);
    c["ball.vz"][c["ball.vz"].len() - 1] / 1.0
}

#[test]
fn a_sphere_rebounds_off_a_wall_with_the_restitution_given() {
    let dir = test_dir("measures-restitution");
    for e in [0.9, 0.5] {
        // Linear: exact, e = exp(−ζπ/√(1 − ζ²)) for the unclipped spring-dashpot, up to the
        // step: the dashpot reads the velocity half a step late, an error of first order,
        // ζ ω dt ≤ 0.22 · 9.8e3/s · 2e-7 s = 4e-4 of e (measured 1.7e-4 and 3.5e-4).
        let linear = "law = \"linear\"\nnormal_stiffness = 1e6\ntangential_stiffness = 1e6";
        let measured = rebound(&dir, linear, e);
        eprintln!("linear: e = {e}, rebound {measured:.6}");
        assert!(
            (measured / e - 1.0).abs() < 1e-3,
            "linear e = {e}: {measured}"
        );
        // Hertz–Mindlin: LIGGGHTS's damping from e (γ ∝ √δ, Tsuji's: e independent of the
        // speed), which rebounds at e too.
        let measured = rebound(&dir, "law = \"hertz-mindlin\"", e);
        eprintln!("hertz-mindlin: e = {e}, rebound {measured:.6}");
        assert!(
            (measured / e - 1.0).abs() < 1e-3,
            "Hertz e = {e}: {measured}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn restitution_beside_a_damping_ratio_or_out_of_range_is_refused() {
    let scene = |contact: &str| {
        format!(
            "[run]\nt_end = 1.0\n[[material]]\nname = \"m\"\ndensity = 1.0\nyoung = 1.0\n\
             poisson = 0.2\n[granular]\nname = \"g\"\nmaterial = \"m\"\nsample = \"s.csv\"\n\
             [contact]\nnormal_stiffness = 1.0\ntangential_stiffness = 1.0\n{contact}\n"
        )
    };
    let path = Path::new("scene.toml");
    let both = Scene::parse(&scene("restitution = 0.5\ndamping_ratio = 0.2"), path);
    let message = both.unwrap_err().to_string();
    assert!(message.contains("both set the dashpots"), "{message}");
    let zero = Scene::parse(&scene("restitution = 0.0"), path);
    let message = zero.unwrap_err().to_string();
    assert!(message.contains("must be in (0, 1]"), "{message}");
    let one = Scene::parse(&scene("restitution = 1.0"), path).unwrap();
    assert_eq!(one.contact.unwrap().damping(), 0.0);
}
