//! `mpirun -np N qdem run SCENE` (the binary built with `--features mpi`) writes the files one
//! process writes, byte for byte, for 1, 2 and 3 ranks (oversubscribed on a 2-core machine) and
//! 1 or 2 threads per rank; a checkpoint written at 2 ranks resumes at 1 and at 3 ranks to the
//! same files. `summary.json` is compared without its wall-clock figures and its thread and
//! rank counts. Needs Open MPI's `mpirun` on the PATH (scripts/test.sh installs it).

#![cfg(feature = "mpi")]

mod common;
use common::{workspace, TempDir};
use std::path::{Path, PathBuf};
use std::process::Command;

const QDEM: &str = env!("CARGO_BIN_EXE_qdem");

/// Open MPI's settings for the tests: as root (CI), and without the single-copy transport
/// that containers often forbid (it would fail the shared-memory exchanges there).
const MPI_ENV: [(&str, &str); 3] = [
    ("OMPI_ALLOW_RUN_AS_ROOT", "1"),
    ("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1"),
    ("OMPI_MCA_btl_vader_single_copy_mechanism", "none"),
];

/// A copy of a fixture scene beside it (so that its relative paths hold) with `[run] t_end`
/// replaced; removed on drop.
struct ShortScene(PathBuf);

impl ShortScene {
    fn new(fixture: &str, t_end: f64, tag: &str) -> ShortScene {
        ShortScene::edited(fixture, tag, &[("t_end = ", &format!("t_end = {t_end:?}"))])
    }

    /// A copy with each line that starts with an edit's key (exactly one per key) replaced by
    /// the edit's text.
    fn edited(fixture: &str, tag: &str, edits: &[(&str, &str)]) -> ShortScene {
        let path = workspace().join("fixtures").join(fixture);
        let text = std::fs::read_to_string(&path).expect("read the fixture scene");
        for (key, _) in edits {
            assert!(
                text.lines().filter(|l| l.starts_with(key)).count() == 1,
                "{key}"
            );
        }
        let lines: Vec<String> = text
            .lines()
            .map(|l| match edits.iter().find(|(key, _)| l.starts_with(key)) {
                Some((_, line)) => line.to_string(),
                None => l.to_string(),
            })
            .collect();
        let name = format!(".mpi-{tag}-{}.toml", std::process::id());
        let copy = path.with_file_name(name);
        std::fs::write(&copy, lines.join("\n") + "\n").expect("write the short scene");
        ShortScene(copy)
    }
}

impl Drop for ShortScene {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

/// Runs `qdem run` of `scene` into `out` on `ranks` processes of `threads` threads (one
/// process without mpirun for `ranks` = 0), with extra arguments; a run stopped by
/// `--stop-after` (exit status 130, with its checkpoint) counts as a success.
fn run(scene: &Path, out: &Path, ranks: usize, threads: usize, extra: &[&str]) {
    let threads = threads.to_string();
    let mut args = vec![
        "run",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend(["--threads", &threads]);
    args.extend(extra);
    let mut command = match ranks {
        0 => Command::new(QDEM),
        n => {
            let mut c = Command::new("mpirun");
            c.args([
                "--oversubscribe",
                "--bind-to",
                "none",
                "-np",
                &n.to_string(),
                QDEM,
            ]);
            c.envs(MPI_ENV);
            c
        }
    };
    let output = command
        .args(&args)
        .output()
        .expect("start qdem (is mpirun installed?)");
    let stopped = extra.contains(&"--stop-after") && output.status.code() == Some(130);
    assert!(
        output.status.success() || stopped,
        "{ranks} ranks x {threads} threads: {}",
        String::from_utf8_lossy(&output.stderr)
    );
}

/// Every file under `dir`, relative to it, sorted.
fn files(dir: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            match path.is_dir() {
                true => stack.push(path),
                false => found.push(path.strip_prefix(dir).unwrap().to_path_buf()),
            }
        }
    }
    found.sort();
    found
}

/// `summary.json` without what differs between two runs of the same scene: wall-clock
/// figures, thread and rank counts, the step a resumed run resumed at.
fn summary_physics(path: &Path) -> serde_json::Value {
    fn strip(v: &mut serde_json::Value) {
        if let Some(map) = v.as_object_mut() {
            map.retain(|k, _| {
                !(k.contains("second")
                    || k == "stages"
                    || k == "threads"
                    || k == "ranks"
                    || k == "resumed_at_step")
            });
            map.values_mut().for_each(strip);
        }
    }
    let mut value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    strip(&mut value);
    value
}

/// Asserts that `b` holds the same files as `a`, byte for byte (summary.json: its physics).
fn assert_same_outputs(a: &Path, b: &Path, what: &str) {
    let (fa, fb) = (files(a), files(b));
    assert_eq!(fa, fb, "{what}: not the same files");
    assert!(
        fa.iter().any(|f| f.ends_with("probes.csv")),
        "{what}: no probes"
    );
    for f in &fa {
        if f.ends_with("summary.json") {
            assert_eq!(
                summary_physics(&a.join(f)),
                summary_physics(&b.join(f)),
                "{what}: {f:?}"
            );
            continue;
        }
        let same = std::fs::read(a.join(f)).unwrap() == std::fs::read(b.join(f)).unwrap();
        assert!(same, "{what}: {} differs", f.display());
    }
}

/// One process, then 2 and 3 ranks of 1 thread and 2 ranks of 2 threads: the same files.
fn same_for_any_ranks(fixture: &str, t_end: f64, tag: &str) {
    same_scene_for_any_ranks(ShortScene::new(fixture, t_end, tag), fixture, tag);
}

/// [`same_for_any_ranks`] of a scene already cut.
fn same_scene_for_any_ranks(scene: ShortScene, fixture: &str, tag: &str) {
    let tmp = TempDir::new(tag);
    let single = tmp.path().join("single");
    run(&scene.0, &single, 0, 1, &[]);
    for (ranks, threads) in [(2, 1), (3, 1), (2, 2)] {
        let out = tmp.path().join(format!("r{ranks}t{threads}"));
        run(&scene.0, &out, ranks, threads, &[]);
        let what = format!("{fixture} on {ranks} ranks x {threads} threads");
        assert_same_outputs(&single, &out, &what);
    }
}

#[test]
fn the_cantilever_is_byte_identical_on_any_number_of_ranks() {
    same_for_any_ranks("cantilever/cantilever_lc100.toml", 0.02, "cantilever");
}

#[test]
fn the_cantilever_stepped_by_explicit_newmark_is_byte_identical_on_any_number_of_ranks() {
    let fixture = "cantilever/cantilever_lc100.toml";
    let newmark = "integrator = \"newmark\"\nbeta = 0.0\ngamma = 0.5";
    let edits = [("t_end = ", "t_end = 0.02"), ("integrator = ", newmark)];
    let scene = ShortScene::edited(fixture, "newmark", &edits);
    same_scene_for_any_ranks(scene, fixture, "newmark");
}

/// The cantilever of a nearly incompressible viscoelastic material in the averaged-pressure
/// formulation (issue 62: refused over ranks before): its nodal averages sum over blocks of
/// different ranks, through the reverse exchange to their owners and back.
#[test]
fn an_averaged_pressure_cantilever_is_byte_identical_on_any_number_of_ranks() {
    let fixture = "cantilever/cantilever_lc100.toml";
    let material = "poisson = 0.45\nformulation = \"averaged-pressure\"";
    let edits = [
        ("t_end = ", "t_end = 0.01"),
        ("poisson = ", material),
        ("shear_viscosity = ", "shear_viscosity = 1e5"),
        ("bulk_viscosity = ", "bulk_viscosity = 1e5"),
    ];
    let scene = ShortScene::edited(fixture, "averaged", &edits);
    same_scene_for_any_ranks(scene, fixture, "averaged");
}

#[test]
fn the_collision_is_byte_identical_on_any_number_of_ranks() {
    same_for_any_ranks("contact/collision.toml", 0.01, "collision");
}

#[test]
fn a_periodic_granular_packing_is_byte_identical_on_any_number_of_ranks() {
    same_for_any_ranks("boxtest/small_deposit_cell_bed.toml", 0.02, "packing");
}

#[test]
fn a_reduced_ballast_deposit_is_byte_identical_on_any_number_of_ranks() {
    same_for_any_ranks("ballast/reduced_deposit.toml", 0.004, "deposit");
}

/// The last row of the CSV file `name` of the run in `dir`, read by column name, with the
/// file's text for a failure's message.
fn last_row(dir: &Path, name: &str) -> (impl Fn(&str) -> f64, String) {
    let text = std::fs::read_to_string(dir.join(name)).unwrap();
    let header: Vec<String> = text
        .lines()
        .next()
        .unwrap()
        .split(',')
        .map(String::from)
        .collect();
    let last: Vec<f64> = text
        .lines()
        .last()
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    let column = move |name: &str| last[header.iter().position(|h| h == name).unwrap()];
    (column, text)
}

/// Runs `scene` on one process, lets `check` read its outputs (so that the comparison is not
/// of zeros), then runs it on 2 and 3 ranks of a thread and 2 ranks of two threads and
/// compares their outputs with the single process's, byte for byte.
fn same_as_one_process(scene: &ShortScene, tag: &str, what: &str, check: impl Fn(&Path)) {
    let tmp = TempDir::new(tag);
    let single = tmp.path().join("single");
    run(&scene.0, &single, 0, 1, &[]);
    check(&single);
    for (ranks, threads) in [(2, 1), (3, 1), (2, 2)] {
        let out = tmp.path().join(format!("r{ranks}t{threads}"));
        run(&scene.0, &out, ranks, threads, &[]);
        let what = format!("{what} on {ranks} ranks x {threads} threads");
        assert_same_outputs(&single, &out, &what);
    }
}

/// A `[[measure]]` over the packing's clumps (one and two spheres) gathers the whole state and
/// the contacts before each sample, so `measure_bed.csv` (contact stress, solid fraction,
/// coordination, kinetic energy) is byte-identical too; by 0.1 s the falling stones touch
/// (a stress and contacts in the file, so the comparison is not of zeros).
#[test]
fn a_measure_over_a_packing_of_clumps_is_byte_identical_on_any_number_of_ranks() {
    let fixture = "boxtest/small_deposit_cell_bed.toml";
    let measure = "[[measure]]\nname = \"bed\"\nbox = [[0.0, 0.7, 0.0], [0.3, 1.4, 0.3]]\n\
                   every = 0.01\n\n[output]";
    let edits = [("t_end = ", "t_end = 0.1"), ("[output]", measure)];
    let scene = ShortScene::edited(fixture, "measure", &edits);
    same_as_one_process(
        &scene,
        "measure",
        &format!("{fixture} with a measure"),
        |dir| {
            let (column, text) = last_row(dir, "measure_bed.csv");
            assert!(column("contacts") > 0.0 && column("szz") < 0.0, "{text}");
        },
    );
}

/// A lid held at 1 kPa by its servo over the poured grains: its force is the sum over every
/// rank's contacts on it, in one process's order, so `walls.csv` (the lid's force and where
/// its servo moved it) is byte-identical too, and so is `measure_top.csv`, a layer that
/// follows the lid (`follow_wall`); by 0.1 s the lid has come down onto the grains (a force
/// and a displacement in the file, stones in the layer, so the comparison is not of zeros).
#[test]
fn a_servo_wall_over_poured_grains_is_byte_identical_on_any_number_of_ranks() {
    let fixture = "contact/grains.toml";
    let lid = "[[wall]]\npoint = [0.0, 0.0, 0.12]\nnormal = [0.0, 0.0, -1.0]\n\
               servo = { stress = 1e3, area = 0.04, max_velocity = 1.0 }\n\n\
               [[measure]]\nname = \"top\"\nbox = [[0.0, 0.0, 0.09], [0.2, 0.2, 0.12]]\n\
               follow_wall = 6\nevery = 0.01\n\n[[section]]";
    let edits = [("t_end = ", "t_end = 0.1"), ("[[section]]", lid)];
    let scene = ShortScene::edited(fixture, "servo", &edits);
    same_as_one_process(
        &scene,
        "servo",
        &format!("{fixture} with a servo lid"),
        |dir| {
            let (column, text) = last_row(dir, "walls.csv");
            assert!(
                column("wall6.fz") > 0.0 && column("wall6.uz") < 0.0,
                "{text}"
            );
            let (column, text) = last_row(dir, "measure_top.csv");
            assert!(column("stones") > 0.0 && column("szz") < 0.0, "{text}");
        },
    );
}

/// The grains' contacts are split: each rank evaluates those of the grains it owns.
#[test]
fn poured_grains_are_byte_identical_on_any_number_of_ranks() {
    same_for_any_ranks("contact/grains.toml", 0.1, "grains");
}

/// With the third cube deformable too, every contact sphere sits on a deformable body's
/// vertex: the contacts are split along the mesh's decomposition.
#[test]
fn the_collision_of_deformable_cubes_is_byte_identical_on_any_number_of_ranks() {
    let fixture = "contact/collision.toml";
    let edits = [("t_end = ", "t_end = 0.01"), ("rigid = ", "rigid = false")];
    let scene = ShortScene::edited(fixture, "deformable", &edits);
    same_scene_for_any_ranks(scene, fixture, "deformable");
}

/// The time-delayed box test (paper 003 §5) on a crib deposit (itself on the cell's bed,
/// both run here by one process): the ranks measure the force through the delayed boundary
/// over all their pairs, as one process does over its list.
#[test]
fn a_time_delayed_box_test_is_byte_identical_on_any_number_of_ranks() {
    let tmp = TempDir::new("delayed-crib");
    let (bed, crib) = (tmp.path().join("bed"), tmp.path().join("crib"));
    let file = |dir: &Path, f: &str| format!("{:?}", dir.join(f).to_str().unwrap());
    let fixtures = workspace().join("fixtures");
    run(
        &fixtures.join("boxtest/small_deposit_cell_bed.toml"),
        &bed,
        0,
        2,
        &[],
    );
    let bed_sample = format!("sample = {}", file(&bed, "stones.csv"));
    let deposit = ShortScene::edited(
        "boxtest/small_deposit_cell_crib.toml",
        "delayed-crib",
        &[("sample = ", bed_sample.as_str())],
    );
    run(&deposit.0, &crib, 0, 2, &[]);
    let (poses, sample) = (
        format!("pose_from = {}", file(&crib, "poses.csv")),
        format!("sample = {}", file(&crib, "stones.csv")),
    );
    let fixture = "boxtest/small_single_delayed.toml";
    let edits = [
        ("t_end = ", "t_end = 0.12"),
        ("pose_from = ", poses.as_str()),
        ("sample = ", sample.as_str()),
    ];
    let scene = ShortScene::edited(fixture, "delayed", &edits);
    same_scene_for_any_ranks(scene, fixture, "delayed");
}

/// A run of `fixture` (cut to `t_end`) stopped after step `stop` on 2 ranks writes the
/// checkpoint one process writes, byte for byte, and resumed from it on 1 and 3 ranks ends
/// with the uninterrupted run's files.
fn resumes_on_other_ranks(fixture: &str, t_end: f64, tag: &str, stop: &str) {
    let scene = ShortScene::new(fixture, t_end, tag);
    let tmp = TempDir::new(tag);
    let whole = tmp.path().join("whole");
    run(&scene.0, &whole, 0, 1, &[]);
    let alone = tmp.path().join("alone");
    run(&scene.0, &alone, 0, 1, &["--stop-after", stop]);
    let half = tmp.path().join("half");
    run(&scene.0, &half, 2, 1, &["--stop-after", stop]);
    let checkpoint = tmp.path().join("half.qdc");
    std::fs::copy(half.join("checkpoint.qdc"), &checkpoint).unwrap();
    let one = std::fs::read(alone.join("checkpoint.qdc")).unwrap();
    assert!(
        one == std::fs::read(&checkpoint).unwrap(),
        "{fixture}: the checkpoint of 2 ranks differs from one process's"
    );
    for ranks in [0, 3] {
        let out = tmp.path().join(format!("resumed{ranks}"));
        copy_dir(&half, &out);
        std::fs::remove_file(out.join("checkpoint.qdc")).unwrap();
        run(
            &scene.0,
            &out,
            ranks,
            1,
            &["--resume", checkpoint.to_str().unwrap()],
        );
        assert_same_outputs(&whole, &out, &format!("{fixture} resumed at {ranks} ranks"));
    }
}

#[test]
fn a_checkpoint_written_at_two_ranks_resumes_at_one_and_three() {
    resumes_on_other_ranks("contact/collision.toml", 0.01, "resume", "300");
}

/// The cantilever's ranks exchange only their halo between whole gathers: the stop's gather
/// must give the checkpoint the whole state.
#[test]
fn a_halo_exchanged_cantilever_checkpointed_at_two_ranks_resumes_at_one_and_three() {
    resumes_on_other_ranks(
        "cantilever/cantilever_lc100.toml",
        0.02,
        "resume-cantilever",
        "333",
    );
}

/// Split contacts: the stop's gather merges the ranks' contact lists and springs.
#[test]
fn poured_grains_checkpointed_at_two_ranks_resume_at_one_and_three() {
    resumes_on_other_ranks("contact/grains.toml", 0.06, "resume-grains", "1777");
}

/// The small bed's stones, scaled to measure their drawn sieve size, step at 1.06e-4 s: 0.048 s
/// is 450 steps, the stop at step 300 two thirds through.
#[test]
fn a_periodic_packing_checkpointed_at_two_ranks_resumes_at_one_and_three() {
    resumes_on_other_ranks(
        "boxtest/small_deposit_cell_bed.toml",
        0.048,
        "resume-packing",
        "300",
    );
}

/// Copies the files of `from` into a new `to`.
fn copy_dir(from: &Path, to: &Path) {
    for f in files(from) {
        let target = to.join(&f);
        std::fs::create_dir_all(target.parent().unwrap()).unwrap();
        std::fs::copy(from.join(&f), target).unwrap();
    }
}

/// Runs `qdem ARGS` on 2 ranks; its exit success and its stdout and stderr.
fn on_two_ranks(args: &[&str]) -> (bool, String, String) {
    let output = Command::new("mpirun")
        .args(["--oversubscribe", "--bind-to", "none", "-np", "2", QDEM])
        .args(args)
        .envs(MPI_ENV)
        .output()
        .expect("start mpirun");
    let text = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
    (
        output.status.success(),
        text(&output.stdout),
        text(&output.stderr),
    )
}

#[test]
fn check_on_two_ranks_reports_each_ranks_share_of_the_tetrahedra() {
    let scene = workspace().join("fixtures/contact/collision.toml");
    let (ok, out, err) = on_two_ranks(&["check", scene.to_str().unwrap(), "--threads", "1"]);
    assert!(ok, "{err}");
    let rows: Vec<Vec<&str>> = out
        .lines()
        .skip_while(|l| !l.starts_with("decomposed over 2 ranks"))
        .skip(2)
        .take(2)
        .map(|l| l.split_whitespace().collect())
        .collect();
    assert_eq!(rows.len(), 2, "{out}");
    let tets: usize = rows.iter().map(|r| r[1].parse::<usize>().unwrap()).sum();
    assert_eq!(
        tets,
        2 * 205,
        "the two deformable cubes' tetrahedra, each once: {out}"
    );
    assert!(out.contains("kernel imbalance (slowest / mean):"), "{out}");
    assert_eq!(
        out.matches("scene ").count(),
        1,
        "only rank 0 prints: {out}"
    );
}

#[test]
fn check_on_two_ranks_reports_each_ranks_contacts_ghosts_and_spheres() {
    let scene = workspace().join("fixtures/contact/grains.toml");
    let (ok, out, err) = on_two_ranks(&["check", scene.to_str().unwrap(), "--threads", "1"]);
    assert!(ok, "{err}");
    let whole: usize = out
        .lines()
        .find_map(|l| l.strip_prefix("  contacts after the measured steps: "))
        .and_then(|rest| rest.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("the whole candidate count: {out}"));
    let rows: Vec<Vec<usize>> = out
        .lines()
        .skip_while(|l| !l.starts_with("decomposed over 2 ranks"))
        .skip(2)
        .take(2)
        .map(|l| {
            l.split_whitespace()
                .take(8)
                .map(|v| v.parse().unwrap())
                .collect()
        })
        .collect();
    assert_eq!(rows.len(), 2, "{out}");
    let owned: usize = rows.iter().map(|r| r[2]).sum();
    assert_eq!(owned, 2000, "every grain owned once: {out}");
    let spheres: usize = rows.iter().map(|r| r[7]).sum();
    assert_eq!(spheres, 2000, "every grain's sphere owned once: {out}");
    // Each rank evaluates its grains' contacts, fewer than all, and receives ghosts; the
    // pairs across the cut are evaluated on both.
    for row in &rows {
        assert!(row[5] < whole && row[6] > 0, "{out}");
    }
    assert!(rows[0][5] + rows[1][5] > whole, "{out}");
    assert!(
        out.contains("contact imbalance (most candidates / mean):"),
        "{out}"
    );
}

#[test]
fn an_implicit_run_and_the_other_commands_are_refused_on_two_ranks() {
    let implicit = workspace().join("fixtures/bbm/beam_implicit_0.025.toml");
    let tmp = TempDir::new("implicit");
    let out = tmp.path().to_str().unwrap();
    let (ok, _, err) = on_two_ranks(&["run", implicit.to_str().unwrap(), "--out", out]);
    assert!(!ok);
    assert!(
        err.contains("only explicit runs (Verlet, explicit Newmark) can be decomposed")
            && err.contains("without mpirun"),
        "{err}"
    );
    let (ok, _, err) = on_two_ranks(&["modes", implicit.to_str().unwrap()]);
    assert!(!ok);
    assert!(err.contains("`qdem modes` runs as one process"), "{err}");
}

/// The first line of the error of `qdem run` of `scene` into `out` on `ranks` processes
/// (one without mpirun for 0), which must fail.
fn failed_run(scene: &Path, out: &Path, ranks: usize) -> String {
    let scene = scene.to_str().unwrap();
    let out = out.to_str().unwrap();
    let args = ["run", scene, "--out", out, "--threads", "1"];
    let output = match ranks {
        0 => Command::new(QDEM).args(args).output(),
        n => Command::new("mpirun")
            .args([
                "--oversubscribe",
                "--bind-to",
                "none",
                "-np",
                &n.to_string(),
            ])
            .arg(QDEM)
            .args(args)
            .envs(MPI_ENV)
            .output(),
    }
    .expect("start qdem (is mpirun installed?)");
    let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
    assert!(!output.status.success(), "{ranks} ranks: it ran to the end");
    assert!(!stderr.contains("panicked"), "{stderr}");
    stderr
        .lines()
        .find(|l| l.starts_with("error:"))
        .unwrap_or_else(|| panic!("{ranks} ranks: no error in:\n{stderr}"))
        .to_string()
}

/// The deformable cubes' collision with `left` dropped at 40 m/s onto the ramp: every rank
/// checks the spheres it owns at each rebuild of the lists, and all of them stop at the step
/// one process stops at (on main the block went through the slab on any number of ranks).
#[test]
fn a_block_through_a_mesh_wall_is_stopped_on_any_number_of_ranks() {
    let fixture = "contact/collision.toml";
    let edits = [
        ("t_end = ", "t_end = 0.01"),
        ("rigid = ", "rigid = false"),
        ("velocity = [4.0", "velocity = [0.0, 0.0, -40.0]"),
    ];
    let scene = ShortScene::edited(fixture, "through-wall", &edits);
    let tmp = TempDir::new("mpi-through-wall");
    let at_step = |line: &str| {
        let from = line.find("passes through at step").expect("the report");
        line[from..].split(':').next().unwrap().to_string()
    };
    let one = failed_run(&scene.0, &tmp.path().join("one"), 0);
    for ranks in [2, 3] {
        let many = failed_run(&scene.0, &tmp.path().join(format!("r{ranks}")), ranks);
        assert!(
            many.contains("body `left`") && many.contains("wall #1"),
            "{many}"
        );
        assert_eq!(
            at_step(&many),
            at_step(&one),
            "{ranks} ranks:\n{many}\n{one}"
        );
    }
}
