//! `qdem check`'s modelling advice (issue 58), each kind on a scene built to need it and on
//! one built not to: a stiff stone under a slow load (rigid) and a fast one (deformable); a
//! free beam loaded near its first mode (deformable) and far below it (rigid); ν = 0.49
//! (averaged-pressure) and 0.3 (standard); a creep test (implicit) and a stubby block shaken
//! at half its first mode (explicit); a light grain bed on stiff springs (softer) and a heavy
//! body on soft ones (stiffer); a `[ballast]` stone set on soft contacts (rigid) and on Table
//! 1's (deformable); a `[granular]` bed on soft springs (rigid) and on stiff ones
//! (deformable); a slender `[bonded]` beam under a slow load (implicit) and a stubby bonded
//! block (explicit).

mod common;

use common::{fixture, test_dir};
use qdem_io::advice::{advise, Advice, Topic};
use qdem_io::build::Simulation;
use qdem_io::scene::Scene;
use std::f64::consts::PI;

/// The advice of the scene `text` (written to `name.toml` in a fresh directory).
fn advice_of(name: &str, text: &str) -> Vec<Advice> {
    let dir = test_dir(&format!("advice-{name}"));
    let path = dir.join("scene.toml");
    std::fs::write(&path, text).unwrap();
    advise(&Simulation::build(Scene::load(&path).unwrap()).unwrap())
}

/// The advice on `topic` about `subject`.
fn on<'a>(all: &'a [Advice], subject: &str, topic: Topic) -> &'a Advice {
    all.iter()
        .find(|a| a.topic == topic && a.subject == subject)
        .unwrap_or_else(|| panic!("no {topic:?} advice on {subject} in {all:#?}"))
}

/// A granite cube (0.1 m, fixtures/contact/block.msh), free, pushed by 1 kN ramped on over
/// `rise` seconds.
fn stone(rise: f64) -> String {
    format!(
        r#"
[run]
t_end = 1.0
gravity = [0.0, 0.0, 0.0]
[[material]]
name = "granite"
density = 2700.0
young = 5e10
poisson = 0.25
[[body]]
name = "stone"
mesh = "{}"
material = "granite"
[[load]]
body = "stone"
group = "bottom"
total_force = [0.0, 0.0, 1000.0]
ramp = [[0.0, 0.0], [{rise}, 1.0]]
"#,
        fixture("contact/block.msh").display()
    )
}

/// The 2.4 m concrete beam of the cantilever fixture, free (no fix), its tip pushed by a load
/// cycling at `frequency` Hz; `material` lines replace the concrete's.
fn free_beam(cyclic: &str, poisson: f64, fix: bool, run: &str) -> String {
    let fix = match fix {
        true => "[[fix]]\nbody = \"beam\"\ngroup = \"clamp\"\n",
        false => "",
    };
    format!(
        r#"
[run]
t_end = 2.0
gravity = [0.0, 0.0, 0.0]
{run}
[[material]]
name = "concrete"
density = 2350.0
young = 45e9
poisson = {poisson}
[[body]]
name = "beam"
mesh = "{}"
material = "concrete"
{fix}
[[load]]
body = "beam"
group = "tip"
total_force = [0.0, 0.0, -200.0]
{cyclic}
"#,
        fixture("cantilever/cantilever_lc100.msh").display()
    )
}

/// A stone pushed over a second, hundreds of its periods, is advised rigid: its first mode
/// rings at 1/(π f₁ t_r) of the static deflection, far under 1%; pushed over 20 µs, about
/// its period, it stays deformable.
#[test]
fn a_stiff_stone_under_a_slow_load_is_advised_rigid_under_a_fast_one_deformable() {
    let slow = advice_of("slow-stone", &stone(1.0));
    let a = on(&slow, "body `stone`", Topic::Rigidity);
    assert_eq!(
        (a.now.as_str(), a.advised.as_str()),
        ("deformable", "rigid"),
        "{a:#?}"
    );
    let f1 = a.figure("lowest_frequency_hz").unwrap();
    // A 0.1 m granite cube's first free mode: c_s/(2 × 0.1 m) = 2.7 km/s / 0.2 m ≈ 13.6 kHz
    // scale; the coarse mesh is stiffer, within a factor of two.
    assert!((6e3..3e4).contains(&f1), "{f1}");
    let d = a.figure("dynamic_share").unwrap();
    assert!(
        (d - 1.0 / (PI * f1 * 1.0)).abs() < 1e-12 * d.max(1e-30),
        "{d} {f1}"
    );
    let fast = advice_of("fast-stone", &stone(2e-5));
    let a = on(&fast, "body `stone`", Topic::Rigidity);
    assert_eq!(a.advised, "deformable", "{a:#?}");
}

/// The free beam shaken at 0.9 of its first (free-free) mode answers 4.3x its static
/// deflection on top: deformable; shaken at 1% of it, a rigid beam misses 1e-4: rigid.
#[test]
fn a_free_beam_near_its_first_mode_is_advised_deformable_far_below_it_rigid() {
    let probe = advice_of("beam-probe", &free_beam("", 0.167, false, ""));
    let f1 = on(&probe, "body `beam`", Topic::Rigidity)
        .figure("lowest_frequency_hz")
        .unwrap();
    let cyclic = |f: f64| format!("cyclic = {{ min = -1.0, max = 1.0, frequency = {f} }}");
    let near = advice_of("beam-near", &free_beam(&cyclic(0.9 * f1), 0.167, false, ""));
    let a = on(&near, "body `beam`", Topic::Rigidity);
    assert_eq!(a.advised, "deformable", "{a:#?}");
    // r = 0.9: 2 (1/(1 − 0.81) − 1) for the oscillating part w = 2 of a ±1 cycle.
    let d = a.figure("dynamic_share").unwrap();
    assert!((d - 2.0 * (1.0 / 0.19 - 1.0)).abs() < 1e-9, "{d}");
    let far = advice_of("beam-far", &free_beam(&cyclic(0.01 * f1), 0.167, false, ""));
    let a = on(&far, "body `beam`", Topic::Rigidity);
    assert_eq!(a.advised, "rigid", "{a:#?}");
    // Held at its clamp it has no rigid motion: its deformation is the answer.
    let held = advice_of("beam-held", &free_beam(&cyclic(0.01 * f1), 0.167, true, ""));
    assert_eq!(
        on(&held, "body `beam`", Topic::Rigidity).advised,
        "deformable"
    );
}

/// ν = 0.49 locks the standard tetrahedron; ν = 0.3 does not, and it costs less.
#[test]
fn a_nearly_incompressible_body_is_advised_averaged_pressure_a_compressible_one_standard() {
    let ramp = "ramp = [[0.0, 0.0], [1.0, 1.0]]";
    let soft = advice_of(
        "nu049",
        &free_beam(ramp, 0.49, true, "integrator = \"static\""),
    );
    let a = on(&soft, "body `beam`", Topic::Formulation);
    assert_eq!(
        (a.now.as_str(), a.advised.as_str()),
        ("standard", "averaged-pressure")
    );
    assert!(a.figure("predicted_error").unwrap() > 0.1, "{a:#?}");
    let firm = advice_of(
        "nu03",
        &free_beam(ramp, 0.3, true, "integrator = \"static\""),
    );
    assert_eq!(
        on(&firm, "body `beam`", Topic::Formulation).advised,
        "standard"
    );
}

/// The creep test of paper 000 §3.2 (E = 0.5 MPa, τ = 0.1 s, a step load held 0.5 s) is
/// overdamped in its first mode: quasi-static and viscous, so newmark at τ/20; an elastic
/// block shaken at half its first mode needs inertia, and its explicit step is near what
/// Newmark needs for 0.1% in period: verlet.
#[test]
fn a_creep_test_is_advised_implicit_a_shaken_stubby_block_explicit() {
    let creep = format!(
        r#"
[run]
t_end = 1.0
dt = 1e-3
integrator = "newmark"
gravity = [0.0, 0.0, 0.0]
[[material]]
name = "gel"
density = 2350.0
young = 5e5
poisson = 0.0
shear_viscosity = 3.75e4
[[body]]
name = "bar"
mesh = "{}"
material = "gel"
[[fix]]
body = "bar"
group = "bottom"
[[load]]
body = "bar"
box = [[-1.0, -1.0, 0.049], [1.0, 1.0, 1.0]]
total_force = [0.0, 0.0, -10.0]
ramp = [[0.0, 1.0], [0.5, 1.0], [0.5, 0.0]]
"#,
        fixture("contact/block.msh").display()
    );
    let creep = creep.replace("dt = 1e-3\nintegrator = \"newmark\"\n", "");
    let all = advice_of("creep", &creep);
    let a = on(&all, "run", Topic::Integrator);
    assert_eq!(
        (a.now.as_str(), a.advised.as_str()),
        ("verlet", "newmark"),
        "{a:#?}"
    );
    // τ = μ_D/G = 3.75e4/2.5e5 = 0.15 s; the step τ/20.
    assert!(
        (a.figure("advised_dt").unwrap() - 0.15 / 20.0).abs() < 1e-12,
        "{a:#?}"
    );
    let shaken = creep
        .replace("young = 5e5", "young = 5e10")
        .replace("shear_viscosity = 3.75e4", "")
        .replace(
            "ramp = [[0.0, 1.0], [0.5, 1.0], [0.5, 0.0]]",
            "cyclic = { min = -1.0, max = 1.0, frequency = FREQ }",
        );
    let probe = advice_of("shaken-probe", &shaken.replace("FREQ", "1.0"));
    let f1 = on(&probe, "run", Topic::Integrator)
        .figure("lowest_frequency_hz")
        .unwrap();
    let all = advice_of("shaken", &shaken.replace("FREQ", &format!("{}", 0.5 * f1)));
    let a = on(&all, "run", Topic::Integrator);
    assert_eq!(a.advised, "verlet", "{a:#?}");
}

/// Glass grains of 9–11 mm in a box under gravity on linear springs of stiffness `k`.
fn grain_bed(k: f64) -> String {
    format!(
        r#"
[run]
t_end = 0.01
gravity = [0.0, 0.0, -9.81]
[[material]]
name = "glass"
density = 2500.0
young = 5e7
poisson = 0.25
[contact]
law = "linear"
normal_stiffness = {k}
tangential_stiffness = {}
friction = 0.5
[granular]
name = "grains"
material = "glass"
region = [[0.0, 0.0, 0.0], [0.2, 0.2, 0.3]]
count = 2000
grading = [[0.009, 0.0], [0.011, 1.0]]
spheres_per_stone = [1, 1]
seed = 1
[[wall]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
"#,
        k / 2.0
    )
}

/// On 1e4 N/m springs the bed's deepest contact overlaps a fraction of a percent of the
/// radius while the contacts set the step: a softer spring, to 1%, steps longer by the
/// square root of the softening; on 1e2 N/m it overlaps a quarter of the radius: stiffer.
#[test]
fn a_light_bed_on_stiff_springs_is_advised_softer_on_soft_ones_stiffer() {
    let all = advice_of("stiff-springs", &grain_bed(1e4));
    let a = on(&all, "contacts", Topic::ContactStiffness);
    let overlap = a.figure("overlap_over_radius").unwrap();
    let (force, radius) = (
        a.figure("reference_force").unwrap(),
        a.figure("radius").unwrap(),
    );
    assert!((overlap - force / 1e4 / radius).abs() < 1e-12, "{a:#?}");
    assert!(overlap < 0.005, "{a:#?}");
    let s = a.figure("softening").unwrap();
    assert!((overlap * s - 0.01).abs() < 1e-9, "{a:#?}");
    assert_eq!(a.advised, format!("normal_stiffness = {:.4e}", 1e4 / s));
    let all = advice_of("soft-springs", &grain_bed(1e2));
    let a = on(&all, "contacts", Topic::ContactStiffness);
    assert!(a.figure("overlap_over_radius").unwrap() > 0.05, "{a:#?}");
    assert!(a.figure("softening").unwrap() < 1.0, "{a:#?}");
}

/// Four coarse ballast stones (two shapes, 5 cm) of granite with shear viscosity `viscosity`,
/// falling onto a floor on linear springs of stiffness `k`.
fn stone_set(k: f64, viscosity: f64) -> String {
    format!(
        r#"
[run]
t_end = 0.01
gravity = [0.0, 0.0, -9.81]
[[material]]
name = "granite"
density = 2700.0
young = 3e10
poisson = 0.2
shear_viscosity = {viscosity}
[contact]
law = "linear"
normal_stiffness = {k}
tangential_stiffness = {}
friction = 0.5
[ballast]
name = "ballast"
material = "granite"
meshes = ["{}", "{}"]
contact_radius = 0.012
count = 4
region = [[0.0, 0.0, 0.0], [0.4, 0.4, 0.6]]
seed = 1
[[wall]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
"#,
        k / 2.0,
        fixture("ballast/stones/coarse/stone_00.msh").display(),
        fixture("ballast/stones/coarse/stone_01.msh").display()
    )
}

/// A stone set is judged by its most excited shape. On 1e5 N/m springs a 5 cm granite stone's
/// contact lasts about 4 ms, hundreds of its first periods: rigid, stepping longer than the
/// deformable stones' vertex contacts and tetrahedra allow; ten times stiffer, the share grows
/// as √10 (the contact time goes as 1/√k); on Table 1's 1.61e9 N/m the contact lasts about
/// the stone's own period: deformable. Viscous stones made rigid lose their damping, and the
/// advice gives the contacts dashpots of that damping ratio, which shorten the rigid step.
#[test]
fn a_stone_set_on_soft_contacts_is_advised_rigid_on_stiff_ones_deformable() {
    let all = advice_of("stones-soft", &stone_set(1e5, 0.0));
    let soft = on(&all, "[ballast] `ballast`", Topic::Rigidity);
    assert_eq!(
        (soft.now.as_str(), soft.advised.as_str()),
        ("deformable", "rigid"),
        "{soft:#?}"
    );
    assert_eq!(soft.figure("shapes"), Some(2.0), "{soft:#?}");
    let f1 = soft.figure("lowest_frequency_hz").unwrap();
    // A free 5 cm granite stone: a sphere of 2.5 cm radius rings at 2.5 c_s/(2π a) = 34 kHz
    // (c_s = 2.15 km/s); an elongated coarse stone lower, within a factor of three.
    assert!((1e4..6e4).contains(&f1), "{f1}");
    let (deformable, rigid) = (
        soft.figure("deformable_dt").unwrap(),
        soft.figure("rigid_dt").unwrap(),
    );
    assert!(rigid > 2.0 * deformable, "{soft:#?}");
    assert_eq!(soft.figure("rigid_speed_up"), Some(rigid / deformable));
    let d = soft.figure("dynamic_share").unwrap();
    let all = advice_of("stones-firmer", &stone_set(1e6, 0.0));
    let firmer = on(&all, "[ballast] `ballast`", Topic::Rigidity);
    let ratio = firmer.figure("dynamic_share").unwrap() / d;
    assert!((ratio - 10f64.sqrt()).abs() < 1e-9, "{ratio}");
    let all = advice_of("stones-stiff", &stone_set(1.61e9, 0.0));
    let stiff = on(&all, "[ballast] `ballast`", Topic::Rigidity);
    assert_eq!(stiff.advised, "deformable", "{stiff:#?}");
    assert!(stiff.figure("dynamic_share").unwrap() >= 0.1, "{stiff:#?}");
    let all = advice_of("stones-viscous", &stone_set(1e5, 1e4));
    let viscous = on(&all, "[ballast] `ballast`", Topic::Rigidity);
    let zeta = viscous.figure("kelvin_voigt_damping_ratio").unwrap();
    // ζ = π f₁ μ_D/G, G = 3e10/2.4.
    let f1 = viscous.figure("lowest_frequency_hz").unwrap();
    assert!(
        (zeta - PI * f1 * 1e4 / 1.25e10).abs() < 1e-12,
        "{viscous:#?}"
    );
    let z = (zeta * 100.0).ceil() / 100.0;
    assert!(z > 0.01, "{viscous:#?}");
    assert_eq!(
        viscous.advised,
        format!("rigid, [contact] damping_ratio = {z}"),
        "{viscous:#?}"
    );
    let damped = viscous.figure("rigid_advised_dt").unwrap();
    assert!(damped < viscous.figure("rigid_dt").unwrap(), "{viscous:#?}");
}

/// Glass grains are rigid spheres: the heaviest, taken as a sphere of its mass, has the 9–11 mm
/// grading's radius, and its first free mode (Lamb's torsional one, 2.5011 c_s/(2π a), about
/// 6.5 kHz here) is struck by contacts lasting π√(m/k): on 1e4 N/m, 1.3 ms, a share of 0.075,
/// rigid; on 1e6 N/m ten times that, deformable.
#[test]
fn a_grain_bed_on_soft_springs_stays_rigid_on_stiff_ones_is_advised_deformable() {
    let all = advice_of("grains-soft", &grain_bed(1e4));
    let soft = on(&all, "[granular] `grains`", Topic::Rigidity);
    assert_eq!(soft.advised, "rigid", "{soft:#?}");
    let a = soft.figure("radius").unwrap();
    assert!((0.0045..=0.0055 * (1.0 + 1e-9)).contains(&a), "{soft:#?}");
    let f1 = soft.figure("lowest_frequency_hz").unwrap();
    let m = 2500.0 * 4.0 / 3.0 * PI * a.powi(3);
    let d = 2.0 / (PI * f1 * PI * (m / 1e4f64).sqrt());
    let share = soft.figure("dynamic_share").unwrap();
    assert!((share / d - 1.0).abs() < 1e-9, "{share} against {d}");
    assert!((0.01..0.1).contains(&share), "{soft:#?}");
    let all = advice_of("grains-stiff", &grain_bed(1e6));
    let stiff = on(&all, "[granular] `grains`", Topic::Rigidity);
    assert_eq!(
        (stiff.now.as_str(), stiff.advised.as_str()),
        ("rigid", "deformable"),
        "{stiff:#?}"
    );
}

/// A granite cube (27 kg) on a floor of linear springs, pushed down by a `[[load]]` of
/// `total_force` 1 N scaled by `factor` (a ramp or series to 2000).
fn pushed_block(factor: &str) -> String {
    format!(
        r#"
[run]
t_end = 0.1
gravity = [0.0, 0.0, -9.81]
[[material]]
name = "granite"
density = 2700.0
young = 5e10
poisson = 0.25
[contact]
law = "linear"
normal_stiffness = 1e7
tangential_stiffness = 5e6
friction = 0.5
[[body]]
name = "block"
mesh = "{}"
material = "granite"
contact_radius = 0.01
translate = [0.0, 0.0, 0.0601]
[[wall]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
[[load]]
body = "block"
box = [[-1.0, -1.0, 0.109], [1.0, 1.0, 1.0]]
total_force = [0.0, 0.0, -1.0]
{factor}
"#,
        fixture("contact/block.msh").display()
    )
}

/// The force a `[[load]]` puts on one contact is its `total_force` times its time factor's
/// peak: 2000 N, not the 1 N of `total_force` alone (nor the block's 265 N weight), for a ramp
/// and for a series (whose fastest change, 2000 over 10 ms, is its segment).
#[test]
fn a_loads_force_on_the_contacts_is_its_total_force_times_its_peak_factor() {
    let ramp = advice_of(
        "pushed-ramp",
        &pushed_block("ramp = [[0.0, 0.0], [0.05, 2000.0]]"),
    );
    let dir = test_dir("advice-pushed-series-csv");
    let csv = dir.join("push.csv");
    std::fs::write(&csv, "time,f\n0,0\n0.04,0\n0.05,2000\n0.1,2000\n").unwrap();
    let series = advice_of(
        "pushed-series",
        &pushed_block(&format!(
            "series = {{ file = \"{}\", column = \"f\" }}",
            csv.display()
        )),
    );
    for all in [&ramp, &series] {
        let a = on(all, "contacts", Topic::ContactStiffness);
        assert_eq!(a.figure("reference_force"), Some(2000.0), "{a:#?}");
        let overlap = 2000.0 / 1e7 / a.figure("radius").unwrap();
        assert!((a.figure("overlap_over_radius").unwrap() - overlap).abs() < 1e-15);
    }
}

/// A body advised rigid is told the run's step with it rigid, that of the scene built with
/// `rigid = true` (its contacts then act on its whole mass), not the bound its contacts set
/// on its vertex particles now: the granite cube pushed over 50 ms, hundreds of its periods.
#[test]
fn a_body_advised_rigid_is_told_the_step_of_the_scene_with_it_rigid() {
    let text = pushed_block("ramp = [[0.0, 0.0], [0.05, 2000.0]]");
    let all = advice_of("pushed-slow", &text);
    let a = on(&all, "body `block`", Topic::Rigidity);
    assert_eq!(a.advised, "rigid", "{a:#?}");
    let rigid = text.replace(
        "material = \"granite\"\ncontact_radius",
        "material = \"granite\"\nrigid = true\ncontact_radius",
    );
    assert_ne!(rigid, text);
    let dir = test_dir("advice-pushed-rigid");
    std::fs::write(dir.join("scene.toml"), rigid).unwrap();
    let sim = common::build(&dir.join("scene.toml"));
    let step = sim.world.settings().stable_dt.0;
    assert_eq!(a.figure("rigid_dt"), Some(step), "{a:#?}");
    assert!(step > a.figure("deformable_dt").unwrap(), "{a:#?}");
}

/// A concrete `[bonded]` beam (paper 001's material) of `size` at spacing `h`, simply
/// supported, its top load ramped on over `ramp` seconds, run explicitly at 0.2 ∆t_crit.
fn bonded_beam(size: [f64; 2], h: f64, ramp: f64) -> String {
    format!(
        r#"
[run]
t_end = 0.5
integrator = "newmark"
beta = 0.0
gamma = 0.5
[[material]]
name = "concrete"
density = 2400.0
young = 30e9
poisson = 0.25
[bonded]
name = "beam"
material = "concrete"
size = [{}, {}]
element_size = {h}
strength_mean = 6e6
damping_ratio = 0.05
critical_fraction = 0.2
supports = "simple"
top_load = 1e4
load_ramp = {ramp}
"#,
        size[0], size[1]
    )
}

/// How far the lattice's first frequency may lie from Timoshenko's beam's: f ∝ √E, the
/// lattice's E is within 1.7% of the continuum's (docs/bbm.md), and its rows of particles give
/// the depth and the span to a fraction of a spacing (1.3% measured at 0.02 m).
const TOL_F1: f64 = 0.03;

/// A slender bonded beam (1 m × 0.1 m) under a load ramped over 0.5 s: its first mode is
/// Timoshenko's simply supported one, and implicit Newmark at the step that keeps its period
/// within 0.1% takes far fewer steps than the explicit run: implicit, with that step.
#[test]
fn a_slender_bonded_beam_under_a_slow_load_is_advised_implicit_at_its_first_modes_step() {
    let all = advice_of("bonded-slender", &bonded_beam([1.0, 0.1], 0.02, 0.5));
    let a = on(&all, "bonded body `beam`", Topic::Integrator);
    assert_eq!(
        (a.now.as_str(), a.advised.as_str()),
        ("explicit", "implicit"),
        "{a:#?}"
    );
    let f1 = a.figure("lowest_frequency_hz").unwrap();
    // Euler–Bernoulli ω = (π/L)² √(E h²/12ρ) = 1007 rad/s (160.3 Hz); Timoshenko's shear
    // (κ = 5/6, E/κG = 3) lowers it by 1/√(1 + (πh/L)²(1 + 3)/12) to 157.7 Hz.
    let euler = PI * (30e9 * 0.1f64.powi(2) / (12.0 * 2400.0)).sqrt() / 2.0;
    let timoshenko = euler / (1.0 + (PI * 0.1f64).powi(2) * 4.0 / 12.0).sqrt();
    assert!(
        (f1 / timoshenko - 1.0).abs() < TOL_F1,
        "{f1} against {timoshenko}"
    );
    let dt = a.figure("advised_dt").unwrap();
    assert!(
        (dt * 2.0 * PI * f1 - 0.012f64.sqrt()).abs() < 1e-12,
        "{a:#?}"
    );
    assert!(a.figure("predicted_speed_up").unwrap() > 1.0, "{a:#?}");
    // A load ramped over 0.5 s rings the 158 Hz mode by 1/(π f₁ 0.5 s).
    let d = a.figure("dynamic_share").unwrap();
    assert!((d - 1.0 / (PI * f1 * 0.5)).abs() < 1e-12, "{d}");
}

/// A stubby bonded block (0.2 m square at 0.05 m spacing, a few particles a side): its first
/// mode is near the lattice's highest, so the step that keeps that mode accurate is hardly
/// longer than the explicit one, and an implicit step costs several explicit ones: explicit.
/// The same block free gets no advice, in words.
#[test]
fn a_stubby_bonded_block_is_advised_explicit() {
    let all = advice_of("bonded-stubby", &bonded_beam([0.2, 0.2], 0.05, 0.0));
    let a = on(&all, "bonded body `beam`", Topic::Integrator);
    assert_eq!(
        (a.now.as_str(), a.advised.as_str()),
        ("explicit", "explicit"),
        "{a:#?}"
    );
    let ratio = a.figure("advised_dt").unwrap() / a.figure("explicit_dt").unwrap();
    assert!(ratio < qdem_io::advice::IMPLICIT_BBM_STEP_COST, "{a:#?}");
    // Applied at once, the load rings the mode by its whole static deflection.
    assert_eq!(a.figure("dynamic_share"), Some(1.0), "{a:#?}");
    // Free, it is told why it gets no advice (its rotation is no elastic mode).
    let text = bonded_beam([0.2, 0.2], 0.05, 0.0).replace("\"simple\"", "\"none\"");
    let free = advice_of("bonded-free", &text);
    let a = on(&free, "bonded body `beam`", Topic::Integrator);
    assert!(!a.changes() && a.reasoning.contains("free"), "{a:#?}");
}
