//! A checkpoint depends on every file its scene reads (issue 21): a resume after a mesh's
//! nodes were moved (the counts unchanged, so the state would load and the run fail later
//! with a false inverted tetrahedron), or after a load series or a granular sample was
//! edited, is refused before the first step, naming the file; restored exactly, the same
//! checkpoint resumes. Also: at a run's start the temporary files that killed runs left in
//! the output directory are removed, those of a live process kept.

mod common;

use common::{build, fixture, short_cantilever, test_dir};
use qdem_io::build::Simulation;
use qdem_io::checkpoint::{CheckpointFileError, CHECKPOINT_FILE};
use qdem_io::runner::{run_with, RunError, RunOptions};
use std::path::{Path, PathBuf};

/// Runs `scene` into `out` and stops it with a checkpoint after `steps` steps.
fn checkpointed(scene: &Path, out: &Path, steps: u64) -> PathBuf {
    let stop = RunOptions {
        stop_after: Some(steps),
        ..RunOptions::default()
    };
    match run_with(&mut build(scene), out, stop, &mut |_| {}) {
        Err(RunError::Interrupted { .. }) => out.join(CHECKPOINT_FILE),
        other => panic!("expected an interrupted run, got {other:?}"),
    }
}

/// Resumes `scene` from `checkpoint` into `out`.
fn resume(scene: &Path, out: &Path, checkpoint: &Path) -> Result<Simulation, RunError> {
    let mut sim = build(scene);
    let options = RunOptions {
        resume: Some(checkpoint),
        ..RunOptions::default()
    };
    run_with(&mut sim, out, options, &mut |_| {}).map(|_| sim)
}

/// The resume's refusal, which must name `file` and say what to do; no step is taken.
fn refused(scene: &Path, out: &Path, checkpoint: &Path, file: &str) -> CheckpointFileError {
    let mut sim = build(scene);
    let options = RunOptions {
        resume: Some(checkpoint),
        ..RunOptions::default()
    };
    let error = match run_with(&mut sim, out, options, &mut |_| {}) {
        Err(RunError::Checkpoint(error)) => error,
        other => panic!("expected the checkpoint to be refused, got {other:?}"),
    };
    let message = error.to_string();
    eprintln!("{message}");
    assert!(message.contains(&format!("`{file}`")), "{message}");
    assert!(
        message.contains("restore the file exactly as it was")
            && message.contains("run the scene from the start"),
        "{message}"
    );
    assert_eq!(sim.world.state.time, 0.0, "no step may be taken");
    error
}

/// `text` with every node coordinate x = 2.4 (the beam's tip face) moved to 2.5 inside the
/// `$Nodes` section: the same nodes, elements and groups, another shape.
fn stretched(text: &str) -> String {
    let (start, end) = (
        text.find("$Nodes").unwrap(),
        text.find("$EndNodes").unwrap(),
    );
    let nodes = text[start..end]
        .lines()
        .map(|l| match l.strip_prefix("2.4 ") {
            Some(rest) if l.split(' ').count() == 3 => format!("2.5 {rest}"),
            _ => l.to_string(),
        })
        .collect::<Vec<_>>()
        .join("\n");
    assert_ne!(nodes, text[start..end].trim_end(), "the tip's nodes moved");
    format!("{}{nodes}\n{}", &text[..start], &text[end..])
}

#[test]
fn a_resume_with_a_moved_mesh_or_an_edited_series_is_refused_by_name() {
    let dir = test_dir("ckpt-inputs-cantilever");
    let mesh = dir.join("beam.msh");
    std::fs::copy(fixture("cantilever/cantilever_lc100.msh"), &mesh).unwrap();
    let series = dir.join("tip.csv");
    let series_text = "t,force\n0.0,0.0\n0.01,1.0\n1.0,1.0\n";
    std::fs::write(&series, series_text).unwrap();
    let ramp = "ramp = [[0.0, 0.0], [0.01, 1.0], [2.0, 1.0], [2.0, 0.0]]";
    let scene = short_cantilever(&dir, &[]);
    let text = std::fs::read_to_string(&scene)
        .unwrap()
        .lines()
        .map(|l| match l {
            l if l.starts_with("mesh = ") => "mesh = \"beam.msh\"".to_string(),
            l if l == ramp => "series = { file = \"tip.csv\", column = \"force\" }".to_string(),
            l => l.to_string(),
        })
        .collect::<Vec<_>>()
        .join("\n");
    assert!(text.contains("series = {"), "{text}");
    std::fs::write(&scene, text).unwrap();
    let out = dir.join("out");
    let checkpoint = checkpointed(&scene, &out, 20);

    let original = std::fs::read_to_string(&mesh).unwrap();
    std::fs::write(&mesh, stretched(&original)).unwrap();
    let error = refused(&scene, &out, &checkpoint, "beam.msh");
    assert!(matches!(error, CheckpointFileError::InputChanged { .. }));
    std::fs::write(&mesh, &original).unwrap();

    std::fs::write(&series, series_text.replace("1.0,1.0", "1.0,2.0")).unwrap();
    let error = refused(&scene, &out, &checkpoint, "tip.csv");
    assert!(matches!(error, CheckpointFileError::InputChanged { .. }));

    // A missing file fails the scene's build already; a checkpoint that recorded a file the
    // resumed run cannot read is refused as missing (checked in the checkpoint's unit tests).
    std::fs::write(&series, series_text).unwrap();
    let resumed = resume(&scene, &out, &checkpoint).unwrap();
    assert!(
        resumed.world.state.time > 0.019,
        "restored exactly, the checkpoint resumes"
    );
}

/// Three single-sphere stones above a floor, read from `stones.csv` beside the scene.
fn granular_scene(dir: &Path) -> PathBuf {
    let text = r#"
[run]
t_end = 0.01
gravity = [0.0, 0.0, -9.81]
probe_every = 0.001

[[material]]
name = "granite"
density = 2600.0
young = 1e9
poisson = 0.25

[contact]
law = "hertz-mindlin"
friction = 0.6

[granular]
name = "ballast"
material = "granite"
sample = "stones.csv"

[[wall]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
"#;
    let path = dir.join("granular.toml");
    std::fs::write(&path, text).unwrap();
    path
}

const STONES: &str = "stone,x,y,z,radius\n\
                      1,0.0,0.0,0.06,0.05\n\
                      2,0.2,0.0,0.06,0.05\n\
                      3,0.4,0.0,0.06,0.05\n";

#[test]
fn a_resume_with_an_edited_granular_sample_is_refused_by_name() {
    let dir = test_dir("ckpt-inputs-granular");
    let scene = granular_scene(&dir);
    let sample = dir.join("stones.csv");
    std::fs::write(&sample, STONES).unwrap();
    let out = dir.join("out");
    let checkpoint = checkpointed(&scene, &out, 5);
    std::fs::write(&sample, STONES.replace("0.4,0.0,0.06", "0.4,0.0,0.07")).unwrap();
    let error = refused(&scene, &out, &checkpoint, "stones.csv");
    assert!(matches!(error, CheckpointFileError::InputChanged { .. }));
    std::fs::write(&sample, STONES).unwrap();
    resume(&scene, &out, &checkpoint).unwrap();
}

/// A process id above Linux's largest `pid_max` (2^22): no such process can run.
#[cfg(target_os = "linux")]
const DEAD_PID: u32 = 999_999_999;

#[cfg(target_os = "linux")]
#[test]
fn a_run_removes_the_temporary_files_of_dead_processes_and_keeps_those_of_live_ones() {
    let dir = test_dir("ckpt-stale-temporaries");
    let scene = short_cantilever(&dir, &[("vtu_every = 0.05", "vtu_every = 0.01")]);
    let out = dir.join("out");
    std::fs::create_dir_all(out.join("vtu")).unwrap();
    // This process and its parent run; the run writes none of these names itself.
    let (own, parent) = (std::process::id(), std::os::unix::process::parent_id());
    let dead = [
        out.join(format!(".checkpoint.qdc.tmp-{DEAD_PID}")),
        out.join(format!(".probes.csv.publish-{DEAD_PID}")),
        out.join("vtu")
            .join(format!(".state_00001.vtu.tmp-{DEAD_PID}")),
    ];
    let kept = [
        out.join(format!(".earlier.csv.tmp-{own}")),
        out.join(format!(".probes.csv.tmp-{parent}")),
        out.join("vtu")
            .join(format!(".state_00009.vtu.tmp-{parent}")),
        out.join(format!("notes.tmp-{DEAD_PID}")),
    ];
    for file in dead.iter().chain(&kept) {
        std::fs::write(file, "left by a run").unwrap();
    }
    checkpointed(&scene, &out, 5);
    for file in &dead {
        assert!(!file.exists(), "{} is left", file.display());
    }
    for file in &kept {
        assert!(file.exists(), "{} was removed", file.display());
    }
}
