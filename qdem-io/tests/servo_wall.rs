//! `[[wall]] servo`: a lid whose servo holds a target stress on a settled bed of one-sphere
//! grains in a cell periodic in x and y on a floor. Once the lid has settled, the stress the
//! grains put on it averages to the target, and the floor carries the lid's force plus the
//! bed's weight (statics of the bed); a resumed run equals the uninterrupted one bit for bit;
//! the inputs a servo cannot have are refused by name.

mod common;

use qdem_io::build::Simulation;
use qdem_io::checkpoint::CHECKPOINT_FILE;
use qdem_io::runner::{RunError, RunOptions};
use qdem_io::scene::Scene;
use std::path::{Path, PathBuf};

use common::{
    build, columns, grain_bed, run, test_dir, BED_DENSITY as DENSITY, BED_G as G,
    BED_WIDTH as WIDTH,
};
/// The lid's target stress (Pa): about five times the bed's weight over its area (1.6 kPa).
const TARGET: f64 = 8000.0;

/// The bed under a servo lid that starts at z = 0.26 m, above the grains' region: `t_end`,
/// and `lid` the extra keys of the lid's `[[wall]]`.
fn bed_scene(dir: &Path, t_end: f64, lid: &str) -> PathBuf {
    let area = WIDTH * WIDTH;
    let walls = format!(
        r#"
[[wall]]
point = [0.0, 0.0, 0.26]
normal = [0.0, 0.0, -1.0]
servo = {{ stress = {TARGET}, area = {area}, max_velocity = 0.5 }}
{lid}
"#
    );
    let text = grain_bed(t_end, 0.005, 200, &walls);
    let path = dir.join("scene.toml");
    std::fs::write(&path, text).unwrap();
    path
}

/// g Σ m of the one-sphere stones of `stones.csv`.
fn weight(out: &Path) -> f64 {
    let text = std::fs::read_to_string(out.join("stones.csv")).unwrap();
    text.lines()
        .skip(1)
        .map(|line| {
            let r: f64 = line.split(',').nth(4).unwrap().parse().unwrap();
            DENSITY * 4.0 / 3.0 * std::f64::consts::PI * r.powi(3) * G
        })
        .sum()
}

fn mean(xs: &[f64]) -> f64 {
    xs.iter().sum::<f64>() / xs.len() as f64
}

/// The layer of thickness `LAYER` (m) under the lid at its start, measured where it starts
/// (`fixed`) and following the lid (`top`).
const LAYER: f64 = 0.03;

#[test]
fn a_servo_lid_holds_its_target_stress_on_a_bed() {
    let dir = test_dir("servo-lid");
    let layer = |name: &str, follow: &str| {
        format!(
            "\n[[measure]]\nname = \"{name}\"\nbox = [[0.0, 0.0, {}], [{WIDTH}, {WIDTH}, 0.26]]\n{follow}\n",
            0.26 - LAYER
        )
    };
    let measures = layer("top", "follow_wall = 2") + &layer("fixed", "");
    let scene = bed_scene(&dir, 1.0, &measures);
    let out = dir.join("out");
    let mut sim = build(&scene);
    run(&mut sim, &out, RunOptions::default()).unwrap();
    let walls = columns(&out.join("walls.csv"));
    let rows = walls["time"].len();
    // The last quarter of the run, long after the lid reached the bed.
    let last = rows * 3 / 4..rows;
    let area = WIDTH * WIDTH;
    let lid: Vec<f64> = walls["wall2.fz"][last.clone()]
        .iter()
        .map(|f| f / area)
        .collect();
    let stress = mean(&lid);
    let error = stress / TARGET - 1.0;
    let spread = lid
        .iter()
        .fold(0.0f64, |m, s| m.max((s / TARGET - 1.0).abs()));
    eprintln!(
        "lid stress over the last quarter: mean {stress:.4} Pa against {TARGET} Pa (relative \
         error {error:.2e}), largest sample deviation {spread:.2e}"
    );
    assert!(error.abs() < 0.02, "lid stress {stress} Pa vs {TARGET} Pa");
    // The lid moved down from 0.26 m onto the bed (its top some 0.1 m high) and stays there.
    let uz = &walls["wall2.uz"];
    eprintln!("lid displacement at the end {:.5} m", uz[rows - 1]);
    assert!(
        (-0.24..-0.1).contains(&uz[rows - 1]),
        "lid at {}",
        uz[rows - 1]
    );
    assert!((uz[rows - 1] - uz[last.start]).abs() < 1e-3);
    // Its position is its point at the start moved by uz along its normal (to the ten
    // significant digits walls.csv writes, 1.3e-10 m at 0.26 m), the floor's stays.
    for k in 0..rows {
        assert_eq!([walls["wall2.x"][k], walls["wall2.y"][k]], [0.0, 0.0]);
        let z = walls["wall2.z"][k];
        assert!(
            (z - (0.26 + uz[k])).abs() < 3e-10,
            "lid at {z}, uz {}",
            uz[k]
        );
        assert_eq!(walls["wall1.z"][k], 0.0);
    }
    // Statics of the bed: the floor carries the lid's force and the weight.
    let weight = weight(&out);
    let floor = mean(&walls["wall1.fz"][last.clone()]);
    let lid_force = mean(&walls["wall2.fz"][last]);
    eprintln!("floor {floor:.4} N, lid {lid_force:.4} N + weight {weight:.4} N");
    assert!(
        ((-floor) / (lid_force + weight) - 1.0).abs() < 0.02,
        "floor {floor} N vs lid {lid_force} N + weight {weight} N"
    );
    // The layer that follows the lid holds, at the end, exactly the stones whose centres lie
    // between the lid and LAYER below it; the one left where the lid started holds none.
    let (top, fixed) = (
        columns(&out.join("measure_top.csv")),
        columns(&out.join("measure_fixed.csv")),
    );
    let end = top["time"].len() - 1;
    let state = &sim.world.state;
    let written = top["time"][end];
    assert!(
        (written - state.time).abs() < 1e-9,
        "the last row ({written} s) is the end"
    );
    let lid_z = 0.26 + sim.contacts().unwrap().wall_displacement(1, state.time).z;
    let info = sim.granular.as_ref().unwrap();
    let under = info
        .stones
        .iter()
        .filter(|(c, _)| (lid_z - LAYER..=lid_z).contains(&state.position[*c].z))
        .count();
    eprintln!(
        "layer under the lid: {under} stones, measured {}, σzz {:.1} Pa; at the lid's start {}",
        top["stones"][end], top["szz"][end], fixed["stones"][end]
    );
    assert!(under > 10, "the layer holds stones: {under}");
    assert_eq!(top["stones"][end], under as f64);
    assert_eq!(fixed["stones"][end], 0.0);
    // Its stress is the lid's, plus the weight of about half the layer (3% of it), to the
    // scatter of a layer 2.5 grains thick (README: 0.91-1.04 of the weight above).
    let szz = top["szz"][end];
    assert!(
        (szz / -TARGET - 1.0).abs() < 0.1,
        "σzz {szz} Pa under the lid"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_resumed_servo_run_equals_the_uninterrupted_one() {
    let dir = test_dir("servo-resume");
    let scene = bed_scene(&dir, 0.4, "");
    let (whole, parts) = (dir.join("whole"), dir.join("parts"));
    let mut a = build(&scene);
    run(&mut a, &whole, RunOptions::default()).unwrap();
    let mut b = build(&scene);
    let stop_after = b.steps() * 3 / 4;
    let stop = RunOptions {
        stop_after: Some(stop_after),
        ..RunOptions::default()
    };
    assert!(matches!(
        run(&mut b, &parts, stop),
        Err(RunError::Interrupted { .. })
    ));
    let mut c = build(&scene);
    let checkpoint = parts.join(CHECKPOINT_FILE);
    let resume = RunOptions {
        resume: Some(&checkpoint),
        ..RunOptions::default()
    };
    run(&mut c, &parts, resume).unwrap();
    let bits = |s: &Simulation| -> Vec<u64> {
        let st = &s.world.state;
        st.position
            .iter()
            .chain(&st.velocity)
            .flat_map(|x| x.iter().map(|c| c.to_bits()))
            .collect()
    };
    assert!(bits(&a) == bits(&c), "the resumed state differs");
    for f in ["walls.csv", "stones.csv"] {
        let (x, y) = (std::fs::read(whole.join(f)), std::fs::read(parts.join(f)));
        assert!(x.unwrap() == y.unwrap(), "{f} differs after a resume");
    }
    // The lid was moving under its servo at the checkpoint.
    let walls = columns(&whole.join("walls.csv"));
    assert!(walls["wall2.uz"].last().unwrap() < &-0.1);
    let _ = std::fs::remove_dir_all(&dir);
}

/// The error of loading the bed with `lid` added to the lid's `[[wall]]`, or with `walls`
/// added to the scene.
fn refusal(name: &str, lid: &str) -> String {
    let dir = test_dir(name);
    let scene = bed_scene(&dir, 0.1, lid);
    let message = Scene::load(&scene).unwrap_err().to_string();
    let _ = std::fs::remove_dir_all(&dir);
    message
}

#[test]
fn what_a_servo_cannot_have_is_refused_by_name() {
    let moving = refusal("servo-velocity", "velocity = [0.0, 0.0, -0.1]");
    assert!(
        moving.contains("[[wall]] #2") && moving.contains("velocity"),
        "{moving}"
    );
    let servo = |keys: &str| {
        format!(
            "[[wall]]\npoint = [0.0, 0.0, 0.3]\nnormal = [0.0, 0.0, -1.0]\nservo = {{ {keys} }}"
        )
    };
    for (keys, bad) in [
        ("stress = 1e3, area = 0.0, max_velocity = 0.1", "servo.area"),
        (
            "stress = 1e3, area = 1.0, max_velocity = -1.0",
            "servo.max_velocity",
        ),
        (
            "stress = 1e3, area = 1.0, max_velocity = 0.1, gain = 0.0",
            "servo.gain",
        ),
        (
            "stress = 1e3, area = 1.0, max_velocity = 0.1, ramp = [[0.0, 1.0], [-1.0, 2.0]]",
            "servo: ramp times must not decrease",
        ),
        (
            "stress = 1e3, area = 1.0, max_velocity = 0.1, ramp = []",
            "servo: ramp has no points",
        ),
    ] {
        let message = refusal("servo-bad", &servo(keys));
        assert!(
            message.contains("[[wall]] #3") && message.contains(bad),
            "{message}"
        );
    }
    let mesh = refusal(
        "servo-mesh",
        "[[wall]]\nmesh = \"box.msh\"\nservo = { stress = 1e3, area = 1.0, max_velocity = 0.1 }",
    );
    assert!(
        mesh.contains("[[wall]] #3") && mesh.contains("mesh wall"),
        "{mesh}"
    );
    // A measure can follow only a wall the scene has (two here).
    let follow = refusal(
        "servo-follow",
        "[[measure]]\nname = \"top\"\nbox = [[0.0, 0.0, 0.2], [0.06, 0.06, 0.26]]\nfollow_wall = 3",
    );
    assert!(
        follow.contains("follow_wall = 3") && follow.contains("has 2 [[wall]]s"),
        "{follow}"
    );
}
