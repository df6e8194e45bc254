//! Helpers shared by the command-line tests.

#![allow(dead_code)] // each test binary uses a subset

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::atomic::{AtomicUsize, Ordering};

/// The workspace root.
pub fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("qdem-cli lies in the workspace")
        .to_path_buf()
}

/// A unique temporary directory, removed on drop.
pub struct TempDir(PathBuf);

impl TempDir {
    /// A new empty directory whose name contains `tag`.
    pub fn new(tag: &str) -> TempDir {
        static COUNTER: AtomicUsize = AtomicUsize::new(0);
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos());
        let dir = std::env::temp_dir().join(format!(
            "qdem-cli-{tag}-{}-{}-{nanos}",
            std::process::id(),
            COUNTER.fetch_add(1, Ordering::Relaxed)
        ));
        std::fs::create_dir_all(&dir).expect("create the temporary directory");
        TempDir(dir)
    }

    /// The directory.
    pub fn path(&self) -> &Path {
        &self.0
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// `qdem run SCENE --out OUT --threads N`, which must succeed.
pub fn run(scene: &Path, out: &Path, threads: usize) -> Output {
    let output = Command::new(env!("CARGO_BIN_EXE_qdem"))
        .args([
            OsStr::new("run"),
            scene.as_os_str(),
            OsStr::new("--out"),
            out.as_os_str(),
        ])
        .args(["--threads", &threads.to_string()])
        .env("CI", "1")
        .output()
        .expect("start the qdem binary");
    assert!(
        output.status.success(),
        "qdem run {} --threads {threads} failed ({}):\n{}",
        scene.display(),
        output.status,
        String::from_utf8_lossy(&output.stderr)
    );
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    output
}

/// A fixture scene with each `(from, to)` of `edits` replaced once (each must be there), its
/// relative file paths made absolute, written into `tmp`: a variant of a good scene that
/// reads the fixture's files.
pub fn variant(fixture: &str, edits: &[(&str, &str)], tmp: &TempDir) -> PathBuf {
    let path = workspace().join("fixtures").join(fixture);
    let dir = path.parent().expect("a fixture lies in a folder");
    let mut text = std::fs::read_to_string(&path).expect("read the fixture");
    for (from, to) in edits {
        assert!(text.contains(from), "{fixture} has no {from:?}");
        text = text.replacen(from, to, 1);
    }
    // Quoted relative paths of files become absolute (odd pieces are inside quotes).
    let pieces: Vec<String> = text
        .split('"')
        .enumerate()
        .map(|(i, piece)| {
            let file = [".msh", ".csv", ".qdc"].iter().any(|e| piece.ends_with(e));
            match i % 2 == 1 && file && !piece.starts_with('/') {
                true => dir.join(piece).display().to_string(),
                false => piece.to_string(),
            }
        })
        .collect();
    let out = tmp.path().join(path.file_name().expect("a file name"));
    std::fs::write(&out, pieces.join("\"")).expect("write the variant");
    out
}

/// The last value of column `column` of a run's `probes.csv`.
pub fn last_probe(out: &Path, column: &str) -> f64 {
    let text = std::fs::read_to_string(out.join("probes.csv")).expect("probes.csv");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("a header").split(',').collect();
    let at = header
        .iter()
        .position(|h| *h == column)
        .expect("the column");
    let last = lines.last().expect("a row");
    last.split(',')
        .nth(at)
        .expect("the value")
        .parse()
        .expect("a number")
}
