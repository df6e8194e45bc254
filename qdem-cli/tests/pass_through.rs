//! Bodies that went through a wall or another body without a word (issue 56): a block
//! dropped through the 5 cm slab of `fixtures/contact/ramp.msh`, two blocks and stones
//! going through the gaps between a block's contact spheres, and a stone placed inside a
//! block. Each is now
//! stopped, or refused before the first step, with the sphere, what it went into, its speed
//! and the fix; stones too large for the gaps rest on the block to the end of their run.

mod common;
use common::{variant, workspace, TempDir};
use std::ffi::OsStr;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// `qdem run SCENE --out OUT` from the workspace root.
fn run(scene: &Path, out: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_qdem"))
        .args([
            OsStr::new("run"),
            scene.as_os_str(),
            OsStr::new("--out"),
            out.as_os_str(),
        ])
        .current_dir(workspace())
        .env("CI", "1")
        .output()
        .expect("start the qdem binary")
}

/// The stderr of a run that must have failed with one clean error (status 1, no panic)
/// holding each of `needles`.
fn refused(out: &Output, needles: &[&str]) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(1), "expected a refusal:\n{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    for needle in needles {
        assert!(stderr.contains(needle), "no {needle:?} in:\n{stderr}");
    }
    stderr
}

/// The speed the message names ("moving at about X m/s").
fn named_speed(message: &str) -> f64 {
    message
        .split("moving at about ")
        .nth(1)
        .and_then(|rest| rest.split_whitespace().next())
        .and_then(|word| word.parse().ok())
        .unwrap_or_else(|| panic!("no speed in:\n{message}"))
}

#[test]
fn a_block_dropped_through_a_mesh_wall_is_stopped() {
    // `left` (deformable) falls 0.24 m onto the ramp's top face, `resting` (rigid) starts on
    // it; on main both went through the 5 cm slab (and at 20 m/s ended 3.6 cm inside it)
    // with exit 0.
    let cases = [
        ("left", "velocity = [4.0, 0.0, 0.0]", 20.0),
        ("left", "velocity = [4.0, 0.0, 0.0]", 40.0),
        ("left", "velocity = [4.0, 0.0, 0.0]", 200.0),
        ("resting", "rigid = true", 40.0),
        ("resting", "rigid = true", 200.0),
    ];
    for (body, line, speed) in cases {
        let tmp = TempDir::new("through-wall");
        let edited = match body {
            "left" => format!("velocity = [0.0, 0.0, -{speed:.1}]"),
            _ => format!("rigid = true\nvelocity = [0.0, 0.0, -{speed:.1}]"),
        };
        let scene = variant("contact/collision.toml", &[(line, &edited)], &tmp);
        // At 200 m/s the block moves 0.67 of a radius per step (dt = 2.67e-5 s), at 40 m/s
        // 0.13: a smaller dt is the fix only in the first case, a stiffer contact in both.
        let step_fix = match speed > 100.0 {
            true => "Fix: a smaller dt (it moves",
            false => "a smaller dt does not help here",
        };
        let message = refused(
            &run(&scene, &tmp.path().join("out")),
            &[
                "a body passes through at step",
                &format!("the contact sphere of body `{body}`"),
                "wall #1",
                step_fix,
                "a thicker wall",
                "a stiffer contact",
            ],
        );
        // The speed named is the block's, within what gravity and the wall's push change
        // over the fall (at most about 2.5 m/s of gravity and the contact's braking).
        let named = named_speed(&message);
        assert!(
            named > 0.3 * speed && named < 1.2 * speed,
            "{body} at {speed} m/s named {named} m/s:\n{message}"
        );
    }
}

#[test]
fn blocks_thrown_together_with_a_stiff_contact_are_stopped() {
    // The blocks of `collision.toml` at ±40 m/s with a 39-fold stiffer contact: no two
    // spheres overlap by a radius (the interpenetration watch stays silent), yet on main the
    // blocks went through each other between their spheres, exit 0.
    let tmp = TempDir::new("between-spheres");
    let scene = variant(
        "contact/collision.toml",
        &[
            ("velocity = [4.0, 0.0, 0.0]", "velocity = [40.0, 0.0, 0.0]"),
            (
                "velocity = [-1.0, 0.0, 0.0]",
                "velocity = [-40.0, 0.0, 0.0]",
            ),
            ("normal_stiffness = 2e5", "normal_stiffness = 7.8e6"),
        ],
        &tmp,
    );
    let message = refused(
        &run(&scene, &tmp.path().join("out")),
        &[
            "a body passes through at step",
            "the contact sphere of body `left`",
            "inside body `right`, deeper than its radius",
        ],
    );
    // The sphere's own speed since the last check: of the order of the 40 m/s its block was
    // thrown at (a vertex of a deformable block vibrates about its block's motion), and
    // below the blocks' 80 m/s relative speed.
    let named = named_speed(&message);
    assert!(named > 10.0 && named < 80.0, "{named} m/s:\n{message}");
}

/// A scene of a rigid block (the fixture's 0.1 m cube, 8 mm spheres at its surface vertices
/// about 33 mm apart) resting on a floor, and one-sphere `[granular]` stones of radius
/// `radius` at `(x, y, z)` given velocity `speed` downwards, written into `tmp`.
fn stones_on_a_block(tmp: &TempDir, stones: &[[f64; 3]], radius: f64, speed: f64) -> PathBuf {
    let mut csv = String::from("stone,x,y,z,radius\n");
    for (k, [x, y, z]) in stones.iter().enumerate() {
        writeln!(csv, "{},{x},{y},{z},{radius}", k + 1).unwrap();
    }
    let sample = tmp.path().join("stones.csv");
    std::fs::write(&sample, csv).unwrap();
    let block = workspace().join("fixtures/contact/block.msh");
    let scene = format!(
        r#"
[run]
t_end = 0.03
gravity = [0.0, 0.0, -9.81]
probe_every = 1e-3

[[material]]
name = "rubber"
density = 1100.0
young = 5e7
poisson = 0.3

[[body]]
name = "block"
mesh = "{block}"
material = "rubber"
rigid = true
contact_radius = 0.008
translate = [0.0, 0.0, 0.0585]

[granular]
name = "stones"
material = "rubber"
sample = "{sample}"
velocity = [0.0, 0.0, -{speed}]

[contact]
law = "linear"
normal_stiffness = 2e5
tangential_stiffness = 1e5
friction = 0.0

[[wall]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]

[[probe]]
name = "stone"
body = "stones"
stone = 1

[output]
dir = "out"
"#,
        block = block.display(),
        sample = sample.display(),
    );
    let path = tmp.path().join("stones.toml");
    std::fs::write(&path, scene).unwrap();
    path
}

/// A 5 × 5 grid of stone centres 20 mm apart over the block's top face, at height `z`.
fn grid(z: f64) -> Vec<[f64; 3]> {
    let at = [-0.04, -0.02, 0.0, 0.02, 0.04];
    at.iter()
        .flat_map(|&x| at.iter().map(move |&y| [x, y, z]))
        .collect()
}

#[test]
fn stones_falling_between_a_blocks_spheres_are_stopped() {
    // 4 mm stones fit through the gaps between the block's 8 mm spheres (a triangle of
    // vertices 33 mm apart leaves a hole some 7 mm wide around its centre): on main they
    // went on through the block at their speed, exit 0.
    for speed in [2.0, 40.0] {
        let tmp = TempDir::new("through-gap");
        let scene = stones_on_a_block(&tmp, &grid(0.14), 0.004, speed);
        let message = refused(
            &run(&scene, &tmp.path().join("out")),
            &[
                "a body passes through at step",
                "the contact sphere of body `stones stone",
                "inside body `block`, deeper than its radius",
                "larger contact spheres (contact_radius) or a finer mesh of the body",
            ],
        );
        let named = named_speed(&message);
        assert!(
            named > 0.5 * speed && named < 1.5 * speed,
            "{speed} m/s named {named} m/s:\n{message}"
        );
    }
    // The control: 12 mm stones are wider than the gaps, so they land on the block's spheres
    // and stay above its top face (z = 0.1085 m) to the end, and the check stays silent.
    let tmp = TempDir::new("on-block");
    let stones = [[-0.025, -0.025, 0.14], [0.025, 0.025, 0.14]];
    let scene = stones_on_a_block(&tmp, &stones, 0.012, 2.0);
    let out = tmp.path().join("out");
    let done = run(&scene, &out);
    assert!(
        done.status.success(),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    let height = 0.14 + common::last_probe(&out, "stone.uz");
    assert!(height > 0.1085, "the stone ended at z = {height} m");
}

#[test]
fn a_stone_placed_inside_a_block_is_refused_before_the_run() {
    // A stone at the block's centre touches none of its spheres: on main it was accepted
    // and ran.
    let tmp = TempDir::new("inside-at-start");
    let scene = stones_on_a_block(&tmp, &[[0.0, 0.0, 0.0585]], 0.004, 0.0);
    let out = tmp.path().join("out");
    refused(
        &run(&scene, &out),
        &[
            "body `stones stone 1` starts inside body `block`",
            "5.000e-2 m inside it",
            "fix: place it outside body `block`; in this scene: [granular] `sample` (the \
             stones' rows) or `crop`",
        ],
    );
    assert!(!out.join("probes.csv").exists(), "the run started");
}
