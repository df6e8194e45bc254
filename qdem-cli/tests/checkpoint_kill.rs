//! Checkpoints survive the worst interruptions (issue 8): `qdem run` writing a checkpoint at
//! every step is killed with SIGKILL at staggered moments until two kills have landed inside
//! a checkpoint write (the killed process's leftover temporary file shows it: about one kill
//! in five does); each time the checkpoint on disk still reads back whole (magic, version,
//! scene and its input files, checksum) and a run resumes from it; that resumed run, stopped
//! by SIGTERM, exits with 130 after writing a fresh checkpoint, which reads back too.

mod common;
use common::{workspace, TempDir};
use qdem_io::checkpoint::{read_checkpoint, scene_fingerprint, CHECKPOINT_FILE};
use qdem_io::scene::Scene;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

const QDEM: &str = env!("CARGO_BIN_EXE_qdem");

/// The cantilever on its lc = 0.05 m mesh, long enough never to finish here, with a
/// checkpoint due at every step.
fn scene(dir: &Path) -> PathBuf {
    let fixtures = workspace().join("fixtures/cantilever");
    let mesh = fixtures.join("cantilever_lc050.msh");
    let text = std::fs::read_to_string(fixtures.join("cantilever_lc050.toml"))
        .unwrap()
        .replace(
            "mesh = \"cantilever_lc050.msh\"",
            &format!("mesh = \"{}\"", mesh.display()),
        )
        .replace(
            "vtu_every = 0.05",
            "vtu_every = 0.0\ncheckpoint_every = 1e-9",
        );
    assert!(
        text.contains("checkpoint_every"),
        "the scene has an [output] table"
    );
    let path = dir.join("cantilever.toml");
    std::fs::write(&path, text).unwrap();
    path
}

fn start(scene: &Path, out: &Path, resume: Option<&Path>) -> Child {
    let mut command = Command::new(QDEM);
    command
        .arg("run")
        .arg(scene)
        .arg("--out")
        .arg(out)
        .env("CI", "1")
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    if let Some(checkpoint) = resume {
        command.arg("--resume").arg(checkpoint);
    }
    command.spawn().expect("start the qdem binary")
}

/// Waits until the first checkpoint exists (the run is past its set-up).
fn wait_for(path: &Path) {
    let begin = Instant::now();
    while !path.exists() {
        assert!(
            begin.elapsed() < Duration::from_secs(60),
            "no checkpoint after 60 s"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
}

#[test]
fn a_kill_during_a_checkpoint_write_leaves_the_previous_checkpoint_intact() {
    let dir = TempDir::new("checkpoint-kill");
    let scene = scene(dir.path());
    let out = dir.path().join("out");
    let checkpoint = out.join(CHECKPOINT_FILE);
    let fingerprint = scene_fingerprint(&Scene::load(&scene).unwrap());
    let (mut mid_write, mut rounds) = (0, 0);
    // About one kill in five lands inside a write here; 60 rounds without one would happen
    // with probability 0.8^60 ≈ 2e-6.
    while mid_write < 2 && rounds < 60 {
        let (round, delay_ms) = (rounds, 40 + 37 * (rounds as u64 % 7));
        rounds += 1;
        let resume = (round > 0).then_some(checkpoint.as_path());
        let mut child = start(&scene, &out, resume);
        wait_for(&checkpoint);
        std::thread::sleep(Duration::from_millis(delay_ms));
        let pid = child.id();
        child.kill().expect("SIGKILL the run");
        child.wait().unwrap();
        // The killed process's temporary checkpoint is left only if the kill came between
        // its creation and its rename.
        mid_write += out.join(format!(".checkpoint.qdc.tmp-{pid}")).exists() as usize;
        let body = read_checkpoint(&checkpoint, Some(&fingerprint));
        assert!(
            body.is_ok(),
            "round {round}: the checkpoint is damaged: {}",
            body.unwrap_err()
        );
    }
    eprintln!("{mid_write} of {rounds} kills landed inside a checkpoint write");
    assert!(
        mid_write > 0,
        "no kill landed inside a write: the test proved nothing"
    );

    // The surviving checkpoint resumes; SIGTERM stops that run with a fresh checkpoint.
    let child = start(&scene, &out, Some(&checkpoint));
    std::thread::sleep(Duration::from_millis(1500));
    let status = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let output = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(130), "{stderr}");
    assert!(
        stderr.contains("resuming from") && stderr.contains("interrupted at t ="),
        "{stderr}"
    );
    read_checkpoint(&checkpoint, Some(&fingerprint)).expect("the SIGTERM checkpoint reads back");
}
