//! The files a scene reads besides itself, and their fingerprints: what a checkpoint depends
//! on ([`crate::checkpoint`]).
//!
//! A run is built from its scene file and from every file the scene names: the meshes of
//! `[[body]]`s and mesh `[[wall]]`s, `[[body]] pose_from` files, `[[load]] series` CSVs, the
//! `[granular] sample`, the `[ballast] meshes` and the `[run] start_from` checkpoint. A run
//! resumed from a checkpoint rebuilds the simulation from all of them, so a checkpoint records
//! each file (as written in the scene, relative to it) with an FNV-1a fingerprint of its
//! bytes, and a resume with any of them changed or missing is refused before the first step:
//! a mesh whose nodes moved keeps its counts, so the checkpoint's state would load and the
//! run would fail later for no visible reason (a "tetrahedron turned inside out").

use crate::scene::Scene;
use qdem_core::{checkpoint::CheckpointError, checkpoint::Decoder, checkpoint::Encoder};
use std::path::{Path, PathBuf};

/// FNV-1a, 64 bit.
pub(crate) fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// The fingerprint of the file at `path`, `None` if it cannot be read.
pub(crate) fn file_fingerprint(path: &Path) -> Option<u64> {
    std::fs::read(path).ok().map(|bytes| fnv1a(&bytes))
}

/// Every file `scene` names for reading, as written (relative to the scene file's directory
/// unless absolute), each once, in scene order: `[[body]]` meshes and `pose_from` files,
/// `[[wall]]` meshes, `[[load]]` series, the `[granular]` sample, the `[ballast]` meshes and
/// the `[run] start_from` checkpoint. The output directory is not an input.
pub fn input_files(scene: &Scene) -> Vec<PathBuf> {
    let mut files: Vec<&Path> = Vec::new();
    for body in &scene.bodies {
        files.push(&body.mesh);
        files.extend(body.pose_from.as_deref());
    }
    files.extend(scene.walls.iter().filter_map(|w| w.mesh.as_deref()));
    files.extend(
        scene
            .loads
            .iter()
            .filter_map(|l| l.series.as_ref().map(|s| s.file.as_path())),
    );
    files.extend(scene.granular.as_ref().and_then(|g| g.sample.as_deref()));
    if let Some(ballast) = &scene.ballast {
        files.extend(ballast.meshes.iter().map(PathBuf::as_path));
    }
    files.extend(scene.run.start_from.as_deref());
    let mut unique: Vec<PathBuf> = Vec::with_capacity(files.len());
    for file in files {
        if !unique.iter().any(|f| f == file) {
            unique.push(file.to_path_buf());
        }
    }
    unique
}

/// One file a scene reads, with the fingerprint of its content.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Input {
    /// The file as written in the scene.
    pub file: PathBuf,
    /// FNV-1a of its bytes; `None` if it could not be read.
    pub fingerprint: Option<u64>,
}

/// How an input differs from the one a checkpoint recorded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InputChange {
    /// Its content is not the recorded one (or it was unreadable then and is readable now).
    Changed,
    /// It was read then and cannot be read now.
    Missing,
}

/// The fingerprints of a scene file and of every file it reads: what a checkpoint of a run of
/// the scene is valid for.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SceneFingerprint {
    /// The scene file.
    pub path: PathBuf,
    /// FNV-1a of the scene file's bytes; 0 if it cannot be read (a scene built from text in
    /// a test), which skips the check of the scene file itself.
    pub scene: u64,
    /// The files it reads ([`input_files`]), in scene order.
    pub inputs: Vec<Input>,
}

impl SceneFingerprint {
    /// Reads the scene file and every file it names and fingerprints them.
    pub fn of(scene: &Scene) -> SceneFingerprint {
        SceneFingerprint {
            path: scene.path.clone(),
            scene: file_fingerprint(&scene.path).unwrap_or(0),
            inputs: input_files(scene)
                .into_iter()
                .map(|file| Input {
                    fingerprint: file_fingerprint(&resolve(&scene.path, &file)),
                    file,
                })
                .collect(),
        }
    }

    /// Where `file` (as written in the scene) is on disk.
    pub fn resolve(&self, file: &Path) -> PathBuf {
        resolve(&self.path, file)
    }

    /// The first file whose fingerprint differs from the one in `recorded` (the inputs a
    /// checkpoint holds), as written in the scene, with how: a recorded file the scene no
    /// longer names, or one it names now but did not then, counts as changed.
    pub fn first_change(&self, recorded: &[Input]) -> Option<(PathBuf, InputChange)> {
        let changed = recorded.iter().find_map(|old| {
            let Some(now) = self.inputs.iter().find(|i| i.file == old.file) else {
                return Some((old.file.clone(), InputChange::Changed));
            };
            match (old.fingerprint, now.fingerprint) {
                (Some(_), None) => Some((old.file.clone(), InputChange::Missing)),
                (a, b) if a != b => Some((old.file.clone(), InputChange::Changed)),
                _ => None,
            }
        });
        changed.or_else(|| {
            self.inputs
                .iter()
                .find(|i| !recorded.iter().any(|old| old.file == i.file))
                .map(|i| (i.file.clone(), InputChange::Changed))
        })
    }

    /// The inputs' part of a checkpoint header: their count, then each file and fingerprint.
    pub(crate) fn encode_inputs(&self) -> Vec<u8> {
        let mut out = Encoder::new();
        out.u64(self.inputs.len() as u64);
        for input in &self.inputs {
            out.str(&input.file.to_string_lossy());
            out.bool(input.fingerprint.is_some());
            out.u64(input.fingerprint.unwrap_or(0));
        }
        out.into_bytes()
    }
}

/// Reads the inputs written by [`SceneFingerprint::encode_inputs`].
pub(crate) fn decode_inputs(bytes: &[u8]) -> Result<Vec<Input>, CheckpointError> {
    let mut input = Decoder::new(bytes);
    let count = input.u64("the input count")?;
    let mut inputs = Vec::new();
    for _ in 0..count {
        let file = PathBuf::from(input.str("an input file")?);
        let present = input.bool("an input flag")?;
        let fingerprint = input.u64("an input fingerprint")?;
        inputs.push(Input {
            file,
            fingerprint: present.then_some(fingerprint),
        });
    }
    if !input.is_done() {
        return Err(CheckpointError::Invalid {
            what: "input list",
            detail: "bytes are left over after the last input".to_string(),
        });
    }
    Ok(inputs)
}

/// `file` resolved against the directory of the scene file `scene` (as [`Scene::resolve`]).
fn resolve(scene: &Path, file: &Path) -> PathBuf {
    match scene.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir.join(file),
        _ => file.to_path_buf(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn input(file: &str, fingerprint: Option<u64>) -> Input {
        Input {
            file: PathBuf::from(file),
            fingerprint,
        }
    }

    #[test]
    fn the_inputs_round_trip_and_a_change_is_named() {
        let now = SceneFingerprint {
            path: PathBuf::from("dir/scene.toml"),
            scene: 7,
            inputs: vec![input("a.msh", Some(1)), input("b.csv", None)],
        };
        let recorded = decode_inputs(&now.encode_inputs()).unwrap();
        assert_eq!(recorded, now.inputs);
        assert_eq!(now.first_change(&recorded), None);
        assert_eq!(now.resolve(Path::new("a.msh")), Path::new("dir/a.msh"));

        let edited = [input("a.msh", Some(2))];
        assert_eq!(
            now.first_change(&edited),
            Some((PathBuf::from("a.msh"), InputChange::Changed))
        );
        let gone = [input("b.csv", Some(3))];
        assert_eq!(
            now.first_change(&gone).map(|(_, c)| c),
            Some(InputChange::Missing)
        );
        let unknown = [
            input("a.msh", Some(1)),
            input("b.csv", None),
            input("c.csv", None),
        ];
        assert_eq!(
            now.first_change(&unknown),
            Some((PathBuf::from("c.csv"), InputChange::Changed))
        );
        let new = [input("a.msh", Some(1))];
        assert_eq!(
            now.first_change(&new),
            Some((PathBuf::from("b.csv"), InputChange::Changed))
        );
    }
}
