//! Staged loading across `[run] start_from`: `fixtures/oedometer/`'s bed of 300 grains in a
//! box with frictionless sides, loaded by a servo lid to 20 kPa (`load.toml`), unloaded to
//! 5 kPa (`unload.toml`) and reloaded to 40 kPa (`reload.toml`), each stage from the last
//! one's checkpoint with its lid's target following a load path (`servo.ramp`).
//!
//! What must hold: a stage's walls start where the checkpoint left them, so the bed does not
//! spring back: the floor force over a stage's first 20 ms (the lid's target held) stays
//! within 1% of the force at the last stage's end; the servo holds each target, and the floor
//! carries the lid's force plus the bed's weight (statics of a bed in a box with frictionless
//! sides); a stage may still start a wall at its own `point` (`start = "scene"`), which is
//! checked for overlaps against the checkpoint's positions, not the sample's pour positions.
//! A stage stopped and resumed equals the uninterrupted one.

mod common;

use common::{build, columns, fixture, run, test_dir};
use qdem_io::build::Simulation;
use qdem_io::checkpoint::CHECKPOINT_FILE;
use qdem_io::runner::{RunError, RunOptions};
use qdem_io::scene::Scene;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The lid's area (m²) and the stages' targets (Pa) at their ends.
const AREA: f64 = 0.0036;
const LOADED: f64 = 20e3;
const UNLOADED: f64 = 5e3;
const RELOADED: f64 = 40e3;

/// The first 20 ms of a stage, when its lid holds the last stage's target: the rows at
/// `probe_every` = 2 ms.
const HOLD_ROWS: usize = 11;

/// The directory every stage of this binary writes into (one per process).
fn dir() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| test_dir("staged-loading"))
}

/// The fixture stage `name` written into [`dir`] as `<file>.toml`, starting from the
/// checkpoints of the stages there, after the text `edits`.
fn stage(name: &str, file: &str, edits: &[(&str, &str)]) -> PathBuf {
    let text = std::fs::read_to_string(fixture(&format!("oedometer/{name}.toml"))).unwrap();
    let out = format!("{}/", dir().display());
    let text = edits
        .iter()
        .fold(text.replace("../../out/oedometer/", &out), |t, (a, b)| {
            t.replace(a, b)
        });
    let path = dir().join(format!("{file}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

/// Runs stage `name` (edited, as `file`) into `dir/<file>`; its `walls.csv` by column.
fn run_stage(name: &str, file: &str, edits: &[(&str, &str)]) -> HashMap<String, Vec<f64>> {
    let scene = stage(name, file, edits);
    let mut sim = build(&scene);
    let out = dir().join(file);
    run(&mut sim, &out, RunOptions::default()).unwrap();
    columns(&out.join("walls.csv"))
}

/// The three stages, run once for every test of this binary, in order.
fn stages() -> &'static [HashMap<String, Vec<f64>>; 3] {
    static STAGES: OnceLock<[HashMap<String, Vec<f64>>; 3]> = OnceLock::new();
    STAGES.get_or_init(|| {
        let load = run_stage("load", "load", &[]);
        let unload = run_stage("unload", "unload", &[]);
        let reload = run_stage("reload", "reload", &[]);
        [load, unload, reload]
    })
}

/// g Σ m of the one-sphere grains of the stage's `stones.csv` (N).
fn weight() -> f64 {
    stages();
    let text = std::fs::read_to_string(dir().join("load/stones.csv")).unwrap();
    text.lines()
        .skip(1)
        .map(|line| {
            let r: f64 = line.split(',').nth(4).unwrap().parse().unwrap();
            2600.0 * 4.0 / 3.0 * std::f64::consts::PI * r.powi(3) * 9.81
        })
        .sum()
}

fn mean(xs: &[f64]) -> f64 {
    xs.iter().sum::<f64>() / xs.len() as f64
}

/// The floor's force (N, upwards) at each row of a stage.
fn floor(walls: &HashMap<String, Vec<f64>>) -> Vec<f64> {
    walls["wall1.fz"].iter().map(|f| -f).collect()
}

/// The largest relative change of the floor force over a stage's first rows from `before`.
fn largest_jump(before: f64, walls: &HashMap<String, Vec<f64>>) -> f64 {
    floor(walls)[..HOLD_ROWS]
        .iter()
        .fold(0.0f64, |m, f| m.max((f / before - 1.0).abs()))
}

/// The unload stage with its lid's scene `point` at height `z` (named `name`) is refused for
/// the lid's overlap with the grains, naming the lid.
fn lid_is_refused(name: &str, z: f64) {
    let point = format!("point = [0.0, 0.0, {z}]\nstart = \"scene\"");
    let scene = stage("unload", name, &[("point = [0.0, 0.0, 0.16]", &point)]);
    let refused = Simulation::build(Scene::load(&scene).unwrap())
        .err()
        .unwrap();
    eprintln!("{refused}");
    assert!(
        refused.to_string().contains("penetrates wall 6"),
        "{refused}"
    );
}

#[test]
fn the_floor_force_is_continuous_across_the_stages() {
    let stages = stages();
    for (k, pair) in stages.windows(2).enumerate() {
        let before = *floor(&pair[0]).last().unwrap();
        let jump = largest_jump(before, &pair[1]);
        eprintln!(
            "stage {}: floor {before:.4} N at the end; over the next stage's first 20 ms \
             within {:.2e} of it",
            k + 1,
            jump
        );
        assert!(
            jump < 0.01,
            "the bed sprang: floor moved {jump:.3e} from {before} N"
        );
    }
}

#[test]
fn the_servo_holds_each_target_and_the_floor_carries_lid_and_weight() {
    let weight = weight();
    for (walls, target) in stages().iter().zip([LOADED, UNLOADED, RELOADED]) {
        // The last 40 ms of each stage, 0.1 s and more after its target stopped moving.
        let rows = walls["time"].len();
        let last = rows - 20..rows;
        // The servo sets the lid's speed v = G (σ_target − σ) with G = α A / R, R = Σ (k_n Δt +
        // c_n) over the lid's contacts: over a window its mean force error is R/α times its
        // mean speed. The lid touches at most 65 grains (d ≥ 8 mm packed on 60 mm × 60 mm),
        // each with k_n Δt = 1e5 × 1.07e-5 = 1.1 N·s/m and c_n = 2ζ √(k_n m) ≤ 7.0 N·s/m, so
        // R/α ≤ 1.1e3 N·s/m. A bed at rest, the lid moved less than 3 µm over these 40 ms
        // (7.5e-5 m/s), leaves at most 0.08 N of lag, under 0.5% of the smallest target
        // (18 N); the rest of the 1% is the grains' rearrangements. A bed still slipping is
        // not: a load stage that ended in a slip (the lid sinking 0.16 mm in 60 ms, 2.7 mm/s)
        // had its lid at 71.0 N.
        let sank = walls["wall6.uz"][rows - 21] - walls["wall6.uz"][rows - 1];
        assert!(
            sank.abs() < 3e-6,
            "the bed is still moving at the stage's end (the lid moved {sank:.3e} m in 40 ms): \
             the stage must run until it rests"
        );
        let lid = mean(&walls["wall6.fz"][last.clone()]);
        let floor = mean(&floor(walls)[last]);
        eprintln!(
            "target {target} Pa: lid {:.5} Pa, floor {floor:.4} N against lid {lid:.4} N + \
             weight {weight:.4} N",
            lid / AREA
        );
        assert!((lid / AREA / target - 1.0).abs() < 0.01, "lid {lid} N");
        assert!(((floor / (lid + weight)) - 1.0).abs() < 0.01);
    }
}

#[test]
fn a_stage_may_start_its_lid_at_its_point_and_is_checked_where_the_bed_is() {
    let lid_reached = 0.16 + stages()[0]["wall6.uz"].last().unwrap();
    // The lid at its `point` where the servo had pushed it, well below the pour's top grains
    // (up to 0.15 m high): checked against the checkpoint's bed, not the sample's pour
    // positions.
    let point = format!("point = [0.0, 0.0, {lid_reached}]\nstart = \"scene\"");
    let walls = run_stage(
        "unload",
        "unload-at-point",
        &[
            ("point = [0.0, 0.0, 0.16]", &point),
            ("t_end = 0.25", "t_end = 0.02"),
        ],
    );
    let before = *floor(&stages()[0]).last().unwrap();
    let jump = largest_jump(before, &walls);
    eprintln!("lid at {lid_reached:.5} m: the floor within {jump:.2e} of {before:.4} N");
    assert!(jump < 0.01);
    // By default it starts there, and says so (the lid alone: the other walls stood still).
    let warnings = build(&stage("unload", "unload-said", &[])).warnings;
    let moved: Vec<&String> = (warnings.iter())
        .filter(|w| w.contains("starts where the checkpoint left it"))
        .collect();
    assert!(
        moved.len() == 1 && moved[0].contains("[[wall]] #6"),
        "{warnings:?}"
    );
    // 3 mm lower it would start in the bed's top grains: refused, naming the lid.
    lid_is_refused("unload-into-bed", lid_reached - 0.003);
    // At its scene `point`, 0.16 m high, the lid leaves the bed: the floor carries its weight.
    let walls = run_stage(
        "unload",
        "unload-from-scene",
        &[
            ("servo =", "start = \"scene\"\nservo ="),
            ("t_end = 0.25", "t_end = 0.02"),
        ],
    );
    let sprung = *floor(&walls).last().unwrap();
    eprintln!("lid at its point: the floor carries {sprung:.4} N after 20 ms");
    assert!(sprung < 0.5 * before);
}

/// The stones `(centre, radius)` of the one-sphere grains of a stage's `stones.csv`.
fn stones(file: &str) -> Vec<([f64; 3], f64)> {
    let text = std::fs::read_to_string(dir().join(file).join("stones.csv")).unwrap();
    let row = |line: &str| {
        let v: Vec<f64> = line
            .split(',')
            .skip(1)
            .map(|x| x.parse().unwrap())
            .collect();
        ([v[0], v[1], v[2]], v[3])
    };
    text.lines().skip(1).map(row).collect()
}

/// The largest overlap of two stones as a fraction of their reduced radius, and the largest of
/// a stone and a wall (the floor, the four sides, the lid at height `lid`) as a fraction of
/// the stone's radius: the measures `overlap_tolerance` bounds.
fn largest_overlaps(stones: &[([f64; 3], f64)], lid: f64) -> (f64, f64) {
    let mut pairs = 0.0f64;
    for (i, (a, ra)) in stones.iter().enumerate() {
        for (b, rb) in &stones[i + 1..] {
            let d = (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt();
            pairs = pairs.max((ra + rb - d) / (ra * rb / (ra + rb)));
        }
    }
    let walls = stones.iter().fold(0.0f64, |m, ([x, y, z], r)| {
        let gaps = [*z, *x, 0.06 - x, *y, 0.06 - y, lid - z];
        gaps.iter().fold(m, |m, gap| m.max((r - gap) / r))
    });
    (pairs, walls)
}

#[test]
fn a_stage_checks_what_it_places_not_the_contacts_its_checkpoint_left() {
    // The loaded bed's grains overlap as the lid's 72 N presses them: a few newtons on a
    // contact of k_n = 1e5 N/m is some 1e-5 m, 1% of the reduced radius of 2.25 mm, and more in
    // a force chain. A tolerance below the largest of the checkpoint's pair overlaps and above
    // its wall overlaps would refuse the stage if those pairs were checked.
    let lid = 0.16 + stages()[0]["wall6.uz"].last().unwrap();
    let (pairs, walls) = largest_overlaps(&stones("load"), lid);
    eprintln!("the load stage leaves overlaps up to {pairs:.3e} (pairs), {walls:.3e} (walls)");
    assert!(pairs > walls);
    let tolerance = 0.5 * (pairs + walls);
    // Those pairs are the checkpoint's contacts, not a placement: the stage starts from them.
    let tight = format!("local_damping = 0.7\noverlap_tolerance = {tolerance}");
    let accepted = stage("unload", "unload-tight", &[("local_damping = 0.7", &tight)]);
    let built = Simulation::build(Scene::load(&accepted).unwrap());
    assert!(built.is_ok(), "{}", built.err().unwrap());
    // A wall it places is still checked against them: the lid at its scene point 0.5 mm
    // below where the servo left it is 0.5 mm into the top grains (10-12.5% of a radius of
    // 4-5 mm), beyond the default 5%.
    lid_is_refused("unload-lid-in-grains", lid - 5e-4);
}

#[test]
fn a_resumed_stage_equals_the_uninterrupted_one() {
    stages();
    // The unloading stage stopped at three quarters, its lid carried and under its servo,
    // then resumed: its walls come back from its own checkpoint, not the stage's start.
    let scene = stage("unload", "unload-resumed", &[]);
    let out = dir().join("unload-resumed");
    let mut sim = build(&scene);
    let stop = RunOptions {
        stop_after: Some(sim.steps() * 3 / 4),
        ..RunOptions::default()
    };
    assert!(matches!(
        run(&mut sim, &out, stop),
        Err(RunError::Interrupted { .. })
    ));
    let checkpoint = out.join(CHECKPOINT_FILE);
    let resume = RunOptions {
        resume: Some(&checkpoint),
        ..RunOptions::default()
    };
    run(&mut build(&scene), &out, resume).unwrap();
    for f in ["walls.csv", "stones.csv"] {
        let whole = std::fs::read(dir().join("unload").join(f)).unwrap();
        let resumed = std::fs::read(out.join(f)).unwrap();
        assert!(whole == resumed, "{f} differs after a resume");
    }
}
