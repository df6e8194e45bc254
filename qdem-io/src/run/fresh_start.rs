//! A fresh run (not a resume) in a folder an earlier run wrote to: before its first step it
//! removes the earlier run's outputs, which it might otherwise leave beside its own and
//! unlisted (the VTUs of an earlier, longer run past this run's last one; the `boundary.csv`
//! or `stones.csv` of another scene). Only files with the names a run writes are touched:
//! `results.pvd`, `probes.csv`, `probes.svg`, `boundary.csv`, `sections.csv`,
//! `reactions.csv`, `node_reactions.csv`, `crack.svg`, `stones.csv`, `poses.csv`,
//! `summary.json`, `walls.csv`, `settlement.csv`, `settlement.svg`, `grading.csv`,
//! `grading.svg`, every `measure_*.csv`
//! and `measure_*.svg`, and in `vtu/` the numbered `state_`,
//! `spheres_`, `contacts_`, `bonds_` and `walls_` VTUs and `walls.vtu`. `checkpoint.qdc` is
//! kept: a resume checks that it belongs to the scene and its files, and the run's first
//! checkpoint replaces it.
//!
//! A run never writes over a file it reads: [`overwritten_input`] finds a file the scene reads
//! (a sample's `stones.csv`, a `pose_from`'s `poses.csv`, a `start_from` checkpoint) among
//! these names or `checkpoint.qdc` in the output folder, and the run is refused before it
//! removes or writes anything.

use crate::checkpoint::CHECKPOINT_FILE;
use std::fs;
use std::path::{Path, PathBuf};

/// The files a run writes at the top of its output folder.
const TOP_FILES: [&str; 16] = [
    "results.pvd",
    "probes.csv",
    "probes.svg",
    "boundary.csv",
    "sections.csv",
    "reactions.csv",
    "node_reactions.csv",
    "crack.svg",
    "stones.csv",
    "poses.csv",
    "summary.json",
    "walls.csv",
    "settlement.csv",
    "settlement.svg",
    "grading.csv",
    "grading.svg",
];

/// Whether `name` is one of a `[[measure]]`'s files (`measure_NAME.csv`, `.svg`).
fn measure_file(name: &str) -> bool {
    name.starts_with("measure_") && (name.ends_with(".csv") || name.ends_with(".svg"))
}

/// The prefixes of the numbered VTUs a run writes in `vtu/` (`state_00012.vtu`).
const NUMBERED_VTU: [&str; 5] = ["state_", "spheres_", "contacts_", "bonds_", "walls_"];

/// Whether `name` is one of the VTU files a run writes in `vtu/`.
fn run_vtu(name: &str) -> bool {
    if name == "walls.vtu" {
        return true;
    }
    let Some(stem) = name.strip_suffix(".vtu") else {
        return false;
    };
    NUMBERED_VTU.iter().any(|prefix| {
        stem.strip_prefix(prefix)
            .is_some_and(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()))
    })
}

/// The files in `out_dir` a run writes or, starting fresh, removes, that exist: the names of
/// the module docs, `checkpoint.qdc` last.
fn run_files(out_dir: &Path) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = TOP_FILES.iter().map(|f| out_dir.join(f)).collect();
    if let Ok(entries) = fs::read_dir(out_dir) {
        let mut measures: Vec<PathBuf> = entries
            .flatten()
            .filter(|e| e.file_name().to_str().is_some_and(measure_file))
            .map(|e| e.path())
            .collect();
        measures.sort();
        files.extend(measures);
    }
    if let Ok(entries) = fs::read_dir(out_dir.join("vtu")) {
        let mut vtus: Vec<PathBuf> = entries
            .flatten()
            .filter(|e| e.file_name().to_str().is_some_and(run_vtu))
            .map(|e| e.path())
            .collect();
        vtus.sort();
        files.extend(vtus);
    }
    files.push(out_dir.join(CHECKPOINT_FILE));
    files.retain(|f| f.is_file());
    files
}

/// The first of `inputs` (each as written in the scene, and resolved) that is one of the files
/// a run into `out_dir` writes or removes ([`run_files`]: the same file, by any path), with
/// that file.
pub(crate) fn overwritten_input(
    out_dir: &Path,
    inputs: &[(PathBuf, PathBuf)],
) -> Option<(PathBuf, PathBuf)> {
    let written = run_files(out_dir);
    inputs.iter().find_map(|(named, resolved)| {
        written
            .iter()
            .find(|w| same_file(w, resolved))
            .map(|w| (named.clone(), w.clone()))
    })
}

/// Whether `a` and `b` name one file: the same device and inode on Unix (symbolic and hard
/// links alike), the same canonical path elsewhere.
fn same_file(a: &Path, b: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        match (fs::metadata(a), fs::metadata(b)) {
            (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
            _ => false,
        }
    }
    #[cfg(not(unix))]
    {
        matches!((a.canonicalize(), b.canonicalize()), (Ok(a), Ok(b)) if a == b)
    }
}

/// Removes from `out_dir` the outputs of an earlier run (see the module docs; none of them is
/// a file the scene reads: [`overwritten_input`] refused that run). Best effort: a file that
/// cannot be removed stays. Returns the files removed.
pub(crate) fn remove_earlier_outputs(out_dir: &Path) -> Vec<PathBuf> {
    let mut removed = Vec::new();
    for path in run_files(out_dir) {
        if path.ends_with(CHECKPOINT_FILE) {
            continue;
        }
        if fs::remove_file(&path).is_ok() {
            removed.push(path);
        }
    }
    removed
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_the_names_a_run_writes_are_vtus_of_a_run() {
        assert!(run_vtu("state_00030.vtu"));
        assert!(run_vtu("contacts_00001.vtu"));
        assert!(run_vtu("walls.vtu"));
        assert!(!run_vtu("state_.vtu"));
        assert!(!run_vtu("state_0001a.vtu"));
        assert!(!run_vtu("my_mesh.vtu"));
        assert!(!run_vtu("state_00001.vtu.bak"));
    }

    #[test]
    fn earlier_outputs_go_and_the_checkpoint_and_other_files_stay() {
        let dir = std::env::temp_dir().join(format!("qdem-fresh-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(dir.join("vtu")).unwrap();
        for f in [
            "probes.csv",
            "stones.csv",
            "notes.txt",
            "checkpoint.qdc",
            "vtu/state_00031.vtu",
            "vtu/mine.vtu",
            "walls.csv",
            "measure_bed.csv",
            "measure_bed_energy.svg",
            "measure_notes.txt",
        ] {
            fs::write(dir.join(f), "x").unwrap();
        }
        let removed = remove_earlier_outputs(&dir);
        assert_eq!(
            removed,
            vec![
                dir.join("probes.csv"),
                dir.join("stones.csv"),
                dir.join("walls.csv"),
                dir.join("measure_bed.csv"),
                dir.join("measure_bed_energy.svg"),
                dir.join("vtu/state_00031.vtu")
            ]
        );
        let kept = ["notes.txt", "checkpoint.qdc", "vtu/mine.vtu"];
        for kept in kept.into_iter().chain(["measure_notes.txt"]) {
            assert!(dir.join(kept).exists(), "{kept} was removed");
        }
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn an_input_among_the_files_a_run_writes_is_found_by_any_path() {
        let dir = std::env::temp_dir().join(format!("qdem-overwrite-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(dir.join("out/vtu")).unwrap();
        for f in [
            "out/stones.csv",
            "out/notes.csv",
            "out/checkpoint.qdc",
            "out/vtu/state_00001.vtu",
        ] {
            fs::write(dir.join(f), "x").unwrap();
        }
        let input = |named: &str| (PathBuf::from(named), dir.join(named));
        let out = dir.join("out");
        assert_eq!(overwritten_input(&out, &[input("out/notes.csv")]), None);
        for named in [
            "out/stones.csv",
            "out/checkpoint.qdc",
            "out/vtu/state_00001.vtu",
        ] {
            let found = overwritten_input(&out, &[input("out/notes.csv"), input(named)]);
            assert_eq!(found, Some((PathBuf::from(named), dir.join(named))));
        }
        // The output folder named another way: the same files.
        let other = dir.join("out/../out/.");
        let found = overwritten_input(&other, &[input("out/stones.csv")]);
        assert_eq!(found.map(|f| f.0), Some(PathBuf::from("out/stones.csv")));
        fs::remove_dir_all(&dir).unwrap();
    }
}
