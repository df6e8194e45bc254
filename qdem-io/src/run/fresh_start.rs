//! A fresh run (not a resume) in a folder an earlier run wrote to: before its first step it
//! removes the earlier run's outputs, which it might otherwise leave beside its own and
//! unlisted (the VTUs of an earlier, longer run past this run's last one; the `boundary.csv`
//! or `stones.csv` of another scene). Only files with the names a run writes are touched:
//! `results.pvd`, `probes.csv`, `probes.svg`, `boundary.csv`, `sections.csv`,
//! `reactions.csv`, `node_reactions.csv`, `crack.svg`, `stones.csv`, `poses.csv`, `summary.json`, `walls.csv`,
//! `settlement.csv`, `settlement.svg`, `grading.csv`, `grading.svg`, every `measure_*.csv`
//! and `measure_*.svg`, and in `vtu/` the numbered `state_`,
//! `spheres_`, `contacts_`, `bonds_` and `walls_` VTUs and `walls.vtu`. A file the scene reads (a
//! sample's `stones.csv`, a `pose_from`'s `poses.csv`) is kept, and so is `checkpoint.qdc`:
//! a resume checks that it belongs to the scene and its files, and the run's first checkpoint
//! replaces it.

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

/// Removes from `out_dir` the outputs of an earlier run (see the module docs), except the
/// files of `inputs` (paths the scene reads, resolved). Best effort: a file that cannot be
/// removed stays. Returns the files removed.
pub(crate) fn remove_earlier_outputs(out_dir: &Path, inputs: &[PathBuf]) -> Vec<PathBuf> {
    let read = inputs
        .iter()
        .filter_map(|p| p.canonicalize().ok())
        .collect::<Vec<_>>();
    let mut candidates: Vec<PathBuf> = TOP_FILES.iter().map(|f| out_dir.join(f)).collect();
    if let Ok(entries) = fs::read_dir(out_dir) {
        let mut measures: Vec<PathBuf> = entries
            .flatten()
            .filter(|e| e.file_name().to_str().is_some_and(measure_file))
            .map(|e| e.path())
            .collect();
        measures.sort();
        candidates.extend(measures);
    }
    if let Ok(entries) = fs::read_dir(out_dir.join("vtu")) {
        let mut vtus: Vec<PathBuf> = entries
            .flatten()
            .filter(|e| e.file_name().to_str().is_some_and(run_vtu))
            .map(|e| e.path())
            .collect();
        vtus.sort();
        candidates.extend(vtus);
    }
    let mut removed = Vec::new();
    for path in candidates {
        let Ok(real) = path.canonicalize() else {
            continue;
        };
        if read.contains(&real) || !real.is_file() {
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
    fn earlier_outputs_go_and_the_scene_inputs_and_other_files_stay() {
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
        let removed = remove_earlier_outputs(&dir, &[dir.join("stones.csv")]);
        assert_eq!(
            removed,
            vec![
                dir.join("probes.csv"),
                dir.join("walls.csv"),
                dir.join("measure_bed.csv"),
                dir.join("measure_bed_energy.svg"),
                dir.join("vtu/state_00031.vtu")
            ]
        );
        let kept = ["stones.csv", "notes.txt", "checkpoint.qdc", "vtu/mine.vtu"];
        for kept in kept.into_iter().chain(["measure_notes.txt"]) {
            assert!(dir.join(kept).exists(), "{kept} was removed");
        }
        fs::remove_dir_all(&dir).unwrap();
    }
}
