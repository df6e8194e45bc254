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
