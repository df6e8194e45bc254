//! Checkpoint and restart (issue 8): a run 0 → T equals, bit for bit, a run 0 → T/2 that is
//! stopped with a checkpoint and resumed to T: the final state (every position, velocity and
//! acceleration, compared by bit pattern) and every output file byte for byte. Checked on a
//! deformable body under a ramped load (Verlet), and on a rigid sleeper dropped onto a
//! generated clump sample in a periodic cell with a time-delayed boundary (contact springs,
//! candidate lists, rigid rotations, the boundary's running estimates), on a bonded beam
//! (explicit and implicit) and on a static solve (its reused factorisation). Also: a checkpoint
//! of another scene, and a scene whose models cannot be checkpointed, are refused up front.

mod common;

use common::{build, fixture, run, short_cantilever, test_dir};
use qdem_io::build::Simulation;
use qdem_io::checkpoint::CHECKPOINT_FILE;
use qdem_io::runner::{RunError, RunOptions};
use std::path::{Path, PathBuf};

/// The short cantilever (5,300 steps), sampled every 1 ms, a VTU every 5 ms.
fn cantilever_scene(dir: &Path) -> PathBuf {
    short_cantilever(
        dir,
        &[
            ("probe_every = 1e-4", "probe_every = 1e-3"),
            ("vtu_every = 0.05", "vtu_every = 0.005"),
        ],
    )
}

/// A rigid sleeper dropped onto 16 falling clumps (about as much rock as the 40 were before the
/// generator scaled each clump to measure its sieve size; seed 2, whose stones press through the
/// boundary on both sides of the checkpoint at t = 0.3 s) in a cell periodic along y, its ghosts
/// scaled by a time-delayed boundary that follows its cyclic load.
fn boxtest_scene(dir: &Path) -> PathBuf {
    let text = format!(
        r#"
[run]
t_end = 0.4
gravity = [0.0, 0.0, -9.81]
probe_every = 0.004

[[material]]
name = "granite"
density = 2600.0
young = 1e9
poisson = 0.25

[[material]]
name = "concrete"
density = 2400.0
young = 1e9
poisson = 0.2

[contact]
law = "hertz-mindlin"
friction = 0.6
damping_ratio = 0.0
local_damping = 0.2

[granular]
name = "ballast"
material = "granite"
region = [[0.0, 0.7, 0.0], [0.3, 1.4, 0.4]]
count = 16
grading = [[0.07, 0.0], [0.09, 0.5], [0.11, 1.0]]
spheres_per_stone = [1, 3]
seed = 2

[[body]]
name = "sleeper"
mesh = "{mesh}"
material = "concrete"
rigid = true
contact_radius = 0.015
translate = [0.15, 1.05, 0.55]

[[fix]]
body = "sleeper"
box = [[-1.0, -10.0, -1.0], [1.0, 10.0, 2.0]]
dofs = "xy"
rotation = true

[[load]]
body = "sleeper"
box = [[-1.0, -10.0, -1.0], [1.0, 10.0, 2.0]]
total_force = [0.0, 0.0, -4e3]
cyclic = {{ min = 0.1, max = 1.0, frequency = 20.0, phase_deg = 0.0, start = 0.0 }}

[[probe]]
name = "sleeper"
body = "sleeper"
point = [0.15, 1.05, 0.55]

[[section]]
name = "face"
axis = "y"
at = 0.7

[[wall]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]

[[wall]]
point = [0.0, 0.0, 0.0]
normal = [1.0, 0.0, 0.0]

[[wall]]
point = [0.3, 0.0, 0.0]
normal = [-1.0, 0.0, 0.0]

[periodic]
axes = "y"
length = [0.7]
origin = [0.0, 0.7, 0.0]

[periodic.time_delay]
body = "sleeper"
lag_deg = 90.0

[output]
vtu_every = 0.1
"#,
        mesh = fixture("boxtest/sleeper.msh").display()
    );
    let path = dir.join("boxtest.toml");
    std::fs::write(&path, text).unwrap();
    path
}

/// Every evolving array of the state, by bit pattern.
fn state_bits(sim: &Simulation) -> Vec<u64> {
    let s = &sim.world.state;
    let vectors = [&s.position, &s.velocity, &s.acceleration, &s.reference];
    let mut bits: Vec<u64> = vectors
        .iter()
        .flat_map(|v| v.iter().flat_map(|x| x.iter().map(|c| c.to_bits())))
        .collect();
    bits.push(s.time.to_bits());
    for w in s.rigid.angular_velocity.iter().chain(&s.spin.angle) {
        bits.extend(w.iter().map(|c| c.to_bits()));
    }
    bits
}

/// The files both runs must have written identically (the summary holds wall times).
fn same_outputs(a: &Path, b: &Path, files: &[&str]) {
    for f in files {
        let (x, y) = (std::fs::read(a.join(f)), std::fs::read(b.join(f)));
        let (x, y) = (x.unwrap(), y.unwrap_or_else(|e| panic!("{f}: {e}")));
        assert!(
            x == y,
            "{f} differs between the uninterrupted and the resumed run"
        );
    }
}

/// Runs `scene` 0 → T in one go (into `whole/` of the returned directory) and as 0 →
/// `stop_after`, checkpoint, resume → T (into `parts/`).
fn resume_equals_uninterrupted(
    name: &str,
    scene: &Path,
    stop_after: u64,
    files: &[&str],
) -> PathBuf {
    let dir = test_dir(name);
    let (whole, parts) = (dir.join("whole"), dir.join("parts"));
    let mut a = build(scene);
    run(&mut a, &whole, RunOptions::default()).unwrap();

    let mut b = build(scene);
    let stop = RunOptions {
        stop_after: Some(stop_after),
        ..RunOptions::default()
    };
    match run(&mut b, &parts, stop) {
        Err(RunError::Interrupted { step, .. }) => assert_eq!(step, stop_after),
        other => panic!("expected an interrupted run, got {other:?}"),
    }
    let half = b.world.state.time;
    assert!(half > 0.0 && half < a.world.state.time);
    let checkpoint = parts.join(CHECKPOINT_FILE);
    let mut c = build(scene);
    let resume = RunOptions {
        resume: Some(&checkpoint),
        ..RunOptions::default()
    };
    run(&mut c, &parts, resume).unwrap();
    assert!(
        state_bits(&a) == state_bits(&c),
        "{name}: the resumed run's state differs from the uninterrupted run's"
    );
    same_outputs(&whole, &parts, files);
    eprintln!(
        "{name}: stopped at t = {half:.4} s, resumed to {:.4} s: {} state values equal bit \
         for bit, {files:?} equal byte for byte",
        c.world.state.time,
        state_bits(&c).len()
    );
    dir
}

#[test]
fn a_resumed_deformable_run_equals_the_uninterrupted_one() {
    let dir = test_dir("ckpt-cantilever-scene");
    let scene = cantilever_scene(&dir);
    let files = [
        "probes.csv",
        "probes.svg",
        "results.pvd",
        "vtu/state_00002.vtu",
        "vtu/state_00004.vtu",
    ];
    resume_equals_uninterrupted("ckpt-cantilever", &scene, 2_600, &files);
}

#[test]
fn a_resumed_periodic_contact_run_equals_the_uninterrupted_one() {
    let dir = test_dir("ckpt-boxtest-scene");
    let scene = boxtest_scene(&dir);
    let sim = build(&scene);
    let steps = sim.steps();
    let files = [
        "probes.csv",
        "boundary.csv",
        "sections.csv",
        "stones.csv",
        "probes.svg",
        "results.pvd",
        "vtu/walls.vtu",
        "vtu/spheres_00004.vtu",
        "vtu/contacts_00004.vtu",
    ];
    let dir = resume_equals_uninterrupted("ckpt-boxtest", &scene, steps * 3 / 4, &files);
    // The boundary's estimates were live at the checkpoint (t = 0.3 s): ghost scales other
    // than 1 both before and after it.
    let text = std::fs::read_to_string(dir.join("whole/boundary.csv")).unwrap();
    let scaled: Vec<f64> = text
        .lines()
        .skip(1)
        .map(|l| {
            l.split(',')
                .map(|x| x.parse::<f64>().unwrap())
                .collect::<Vec<_>>()
        })
        .filter(|r| r[2] != 1.0 || r[3] != 1.0)
        .map(|r| r[0])
        .collect();
    let stop = 0.75 * 0.4;
    assert!(
        scaled.iter().any(|&t| t < stop) && scaled.iter().any(|&t| t > stop),
        "ghost scales other than 1 at {scaled:?}"
    );
}

#[test]
fn a_checkpoint_of_another_scene_is_refused() {
    let dir = test_dir("ckpt-other-scene");
    let scene = cantilever_scene(&dir);
    let mut sim = build(&scene);
    let stop = RunOptions {
        stop_after: Some(10),
        ..RunOptions::default()
    };
    assert!(matches!(
        run(&mut sim, &dir.join("out"), stop),
        Err(RunError::Interrupted { .. })
    ));
    let edited = std::fs::read_to_string(&scene).unwrap() + "\n# edited\n";
    std::fs::write(&scene, edited).unwrap();
    let checkpoint = dir.join("out").join(CHECKPOINT_FILE);
    let resume = RunOptions {
        resume: Some(&checkpoint),
        ..RunOptions::default()
    };
    let error = run(&mut build(&scene), &dir.join("out"), resume).unwrap_err();
    let message = error.to_string();
    assert!(
        message.contains("another scene file") && message.contains("edited"),
        "{message}"
    );
}

/// The small bonded beam (explicit Newmark, particle rotations), stopped at 1 ms while its
/// bonds are breaking.
fn bonded_scene(dir: &Path, integrator: &str, checkpoint_every: f64) -> PathBuf {
    let text = std::fs::read_to_string(fixture("bbm/small_beam.toml"))
        .unwrap()
        .replace("beta = 0.0", integrator)
        .replace(
            "[output]\n",
            &format!("[output]\ncheckpoint_every = {checkpoint_every:?}\n"),
        );
    let scene = dir.join("beam.toml");
    std::fs::write(&scene, text).unwrap();
    scene
}

#[test]
fn a_resumed_cracking_bonded_beam_equals_the_uninterrupted_one() {
    let dir = test_dir("ckpt-bonded-scene");
    let scene = bonded_scene(&dir, "beta = 0.0", 0.0);
    let steps = build(&scene).steps();
    let files = ["probes.csv", "crack.svg", "probes.svg"];
    let dir = resume_equals_uninterrupted("ckpt-bonded", &scene, steps / 2, &files);
    let summary = std::fs::read_to_string(dir.join("parts/summary.json")).unwrap();
    let broken = |text: &str| {
        let v: serde_json::Value = serde_json::from_str(text).unwrap();
        v["bonded"]["broken_bonds"].as_u64().unwrap()
    };
    let whole = std::fs::read_to_string(dir.join("whole/summary.json")).unwrap();
    assert!(broken(&whole) > 0, "bonds break in this run");
    assert_eq!(broken(&summary), broken(&whole));
}

#[test]
fn a_resumed_implicit_bonded_beam_equals_the_uninterrupted_one() {
    let dir = test_dir("ckpt-implicit-scene");
    let scene = bonded_scene(&dir, "beta = 0.25", 0.0);
    let steps = build(&scene).steps();
    let files = ["probes.csv", "crack.svg", "probes.svg"];
    resume_equals_uninterrupted("ckpt-implicit", &scene, steps / 2, &files);
}

/// The implicit beam solved after its breaks by conjugate gradients on the kept factor: the
/// checkpoint keeps the matrices the kept factors were computed from and the assembler's
/// pattern, so the resumed run iterates on the same factors.
#[test]
fn a_resumed_preconditioned_implicit_bonded_beam_equals_the_uninterrupted_one() {
    let dir = test_dir("ckpt-preconditioned-scene");
    let scene = bonded_scene(&dir, "beta = 0.25", 0.0);
    let text = std::fs::read_to_string(&scene)
        .unwrap()
        .replace("[bonded]\n", "[bonded]\nevent_solve = \"preconditioned\"\n");
    std::fs::write(&scene, text).unwrap();
    let steps = build(&scene).steps();
    let files = ["probes.csv", "crack.svg", "probes.svg"];
    let dir = resume_equals_uninterrupted("ckpt-preconditioned", &scene, steps / 2, &files);
    let bonded = |part: &str| {
        let text = std::fs::read_to_string(dir.join(part).join("summary.json")).unwrap();
        let v: serde_json::Value = serde_json::from_str(&text).unwrap();
        v["bonded"].clone()
    };
    let (whole, parts) = (bonded("whole"), bonded("parts"));
    assert!(whole["iterative_solves"].as_u64().unwrap() > 0);
    for key in [
        "broken_bonds",
        "factorizations",
        "iterative_solves",
        "iterations",
    ] {
        assert_eq!(whole[key], parts[key], "{key}");
    }
}

/// The short cantilever solved statically at 20 load levels (dt = 1 ms), a VTU every 5 ms.
fn static_scene(dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(cantilever_scene(dir))
        .unwrap()
        .replace("integrator = \"verlet\"", "integrator = \"static\"")
        .replace("dt = \"auto\"", "dt = 0.001");
    let scene = dir.join("static.toml");
    std::fs::write(&scene, text).unwrap();
    scene
}

#[test]
fn a_resumed_static_run_equals_the_uninterrupted_one() {
    let dir = test_dir("ckpt-static-scene");
    let scene = static_scene(&dir);
    assert_eq!(build(&scene).steps(), 20);
    let files = [
        "probes.csv",
        "probes.svg",
        "results.pvd",
        "vtu/state_00002.vtu",
        "vtu/state_00004.vtu",
    ];
    resume_equals_uninterrupted("ckpt-static", &scene, 10, &files);
}

/// A model without a checkpoint of its history (none of the scene models is one any more).
struct Forgetful;

impl qdem_core::step::Model for Forgetful {
    fn name(&self) -> &str {
        "forgetful"
    }

    fn add_forces(
        &mut self,
        _state: &qdem_core::step::State,
        _force: &mut [qdem_core::Vec3],
        _torque: &mut [qdem_core::Vec3],
    ) {
    }
}

#[test]
fn a_scene_that_cannot_be_checkpointed_is_refused_before_the_first_step() {
    let dir = test_dir("ckpt-unsupported");
    let text = std::fs::read_to_string(cantilever_scene(&dir))
        .unwrap()
        .replace("[output]\n", "[output]\ncheckpoint_every = 0.005\n");
    let scene = dir.join("unsupported.toml");
    std::fs::write(&scene, text).unwrap();
    let mut sim = build(&scene);
    sim.world.models.push(Box::new(Forgetful));
    let error = run(&mut sim, &dir.join("out"), RunOptions::default()).unwrap_err();
    let message = error.to_string();
    assert!(
        message.contains("model `forgetful`") && message.contains("cannot be checkpointed"),
        "{message}"
    );
    assert_eq!(sim.world.state.time, 0.0, "no step may be taken");
}
