//! Helpers shared by the output tests.

#![allow(dead_code)] // each test binary uses a subset

use std::path::{Path, PathBuf};

/// A fresh, empty directory for one test.
pub fn test_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("qdem-io-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The names of all entries of `dir`, sorted.
pub fn entries(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// `rel` under the workspace's `fixtures/`.
pub fn fixture(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../fixtures")
        .join(rel)
}

/// The paper's cantilever on its coarse mesh (named by absolute path), shortened to 0.02 s
/// with its load ramped on over 0.01 s, with the further `(from, to)` text `edits`; written
/// to `dir/cantilever.toml`.
pub fn short_cantilever(dir: &Path, edits: &[(&str, &str)]) -> PathBuf {
    let mesh = format!(
        "mesh = \"{}\"",
        fixture("cantilever/cantilever_lc100.msh").display()
    );
    let base = [
        ("t_end = 3.0", "t_end = 0.02"),
        ("[0.0, 0.0], [1.0, 1.0]", "[0.0, 0.0], [0.01, 1.0]"),
        ("mesh = \"cantilever_lc100.msh\"", mesh.as_str()),
    ];
    let text = std::fs::read_to_string(fixture("cantilever/cantilever_lc100.toml")).unwrap();
    let text = base
        .iter()
        .chain(edits)
        .fold(text, |text, (from, to)| text.replace(from, to));
    let path = dir.join("cantilever.toml");
    std::fs::write(&path, text).unwrap();
    path
}
