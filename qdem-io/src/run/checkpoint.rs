//! Checkpoint files (`checkpoint.qdc`): the whole state of a run, so that `qdem run SCENE
//! --resume CHECKPOINT` continues it bit for bit.
//!
//! Layout: the magic bytes `QDEMCKPT`, the format version, a fingerprint of the scene file
//! (FNV-1a of its bytes: a checkpoint is refused for an edited or another scene), the files
//! the scene reads with their fingerprints (each mesh, sample, series, poses file and start
//! checkpoint, as written in the scene: [`crate::inputs`]; a checkpoint is refused when any
//! of them changed or is missing), the body and an FNV-1a checksum of everything after the
//! scene's fingerprint. The body is the run loop's record (step, output
//! schedules, probe rows written, the plot's history), then the [`qdem_core::step::State`], the
//! stepper's and every model's history, each part tagged ([`qdem_core::checkpoint`]). The
//! file is written atomically (temporary file, fsync, rename), so a kill at any moment leaves
//! the previous checkpoint intact.

use crate::inputs::{decode_inputs, fnv1a, InputChange};
use crate::output::{write_atomic, OutputError};
use crate::scene::Scene;
use qdem_core::checkpoint::CheckpointError;
use std::path::{Path, PathBuf};
use thiserror::Error;

pub use crate::inputs::SceneFingerprint;

/// The checkpoint's file name in the output directory.
pub const CHECKPOINT_FILE: &str = "checkpoint.qdc";

/// The version of the layout this build writes and reads (3: the files the scene reads are
/// recorded with their fingerprints, and the run record is one block, the recorders' histories;
/// 4: a one-sphere stone is one rotating particle, not a rigid body of a centre and a member,
/// and the Verlet stepper keeps the particles' moments beside the rigid bodies' torques;
/// 5: an implicit Newmark stepper keeps, with each factorisation, the matrix it factorised and
/// the assembler's sparsity pattern, and its step counts include redos and iterative solves;
/// 6: its tangent records how many of its leading entries a model keeps; 7: the run record
/// holds `walls.csv`'s rows in a scene with walls and each `[[measure]]`'s rows, and the
/// contacts keep each servo wall's point and velocity after their lists: nothing without a
/// servo wall, so a version 7 file of a scene without one reads as before; 8: each model's history is a
/// block (a reader may skip it) and the contacts' history starts with their spheres'
/// particles, by which `[run] start_from` carries their springs; 9: the contacts keep every
/// wall's place and velocity after their lists, in place of the servo walls' after the
/// time-delayed boundary, by which `[run] start_from` starts the walls where they were).
pub const FORMAT_VERSION: u64 = 9;

const MAGIC: &[u8; 8] = b"QDEMCKPT";
const HEADER: usize = 8 + 8 + 8;

/// The largest format version a checkpoint is taken to have: versions go up by one with each
/// change of the layout, so a larger number after the magic bytes (a file of random bytes that
/// happens to start with them, or a damaged header) was written by no qdem.
const LAST_VERSION_READ_AS_ONE: u64 = u16::MAX as u64;

/// Why a checkpoint cannot be resumed from.
#[derive(Debug, Error)]
pub enum CheckpointFileError {
    /// The file cannot be read.
    #[error("cannot read the checkpoint `{path}`: {source}")]
    Read {
        /// The file.
        path: PathBuf,
        /// The io error.
        source: std::io::Error,
    },
    /// Not a checkpoint at all.
    #[error(
        "`{path}` is not a qdem checkpoint (it does not start with the bytes QDEMCKPT that \
         every checkpoint starts with); fix: give the checkpoint.qdc that a qdem run wrote in \
         its output folder"
    )]
    NotCheckpoint {
        /// The file.
        path: PathBuf,
    },
    /// A file that starts with the magic bytes but whose version is no version any qdem
    /// writes: random bytes after them, or a damaged header.
    #[error(
        "`{path}` is not a qdem checkpoint: it starts with the bytes QDEMCKPT, but the format \
         version after them reads {found:#018x}, which no qdem writes (versions are small \
         numbers; this qdem writes {expected}), so the file is damaged or was not written by \
         qdem; fix: give a checkpoint.qdc that a qdem run wrote (an earlier one), or run the \
         scene from the start"
    )]
    DamagedHeader {
        /// The file.
        path: PathBuf,
        /// The eight bytes where the version belongs, as a little-endian number.
        found: u64,
        /// The version this build reads.
        expected: u64,
    },
    /// A checkpoint cut short before the end of its header (a copy or a disk that ran out).
    #[error(
        "the checkpoint `{path}` is cut short: it starts like a qdem checkpoint but has only \
         {length} bytes, fewer than its header; use an earlier checkpoint or run the scene \
         from the start"
    )]
    Truncated {
        /// The file.
        path: PathBuf,
        /// Its length in bytes.
        length: usize,
    },
    /// A checkpoint of another format version.
    #[error(
        "the checkpoint `{path}` has format version {found}, but this qdem reads version \
         {expected}: resume it with the qdem that wrote it, or run the scene from the start"
    )]
    Version {
        /// The file.
        path: PathBuf,
        /// Its version.
        found: u64,
        /// The version this build reads.
        expected: u64,
    },
    /// A checkpoint of another scene, or of the scene before it was edited.
    #[error(
        "the checkpoint `{path}` was written for another scene file, or for `{scene}` before \
         it was edited: resume with the scene exactly as it was, or run it from the start"
    )]
    Scene {
        /// The file.
        path: PathBuf,
        /// The scene file.
        scene: PathBuf,
    },
    /// A file the scene reads whose content is not the one the checkpointed run was built
    /// from.
    #[error(
        "cannot resume from `{path}`: `{input}`, which the scene reads (at {resolved}), has \
         changed since the checkpoint was written, so the resumed run would not continue the \
         checkpointed one: restore the file exactly as it was, or run the scene from the start"
    )]
    InputChanged {
        /// The checkpoint.
        path: PathBuf,
        /// The file as written in the scene.
        input: PathBuf,
        /// Where it is on disk.
        resolved: PathBuf,
    },
    /// A file the scene reads that existed when the checkpoint was written and is gone.
    #[error(
        "cannot resume from `{path}`: `{input}`, which the scene reads (at {resolved}), is \
         missing or unreadable, but the checkpointed run was built from it: restore the file \
         exactly as it was, or run the scene from the start"
    )]
    InputMissing {
        /// The checkpoint.
        path: PathBuf,
        /// The file as written in the scene.
        input: PathBuf,
        /// Where it is on disk.
        resolved: PathBuf,
    },
    /// A checksum that does not match.
    #[error(
        "the checkpoint `{path}` is corrupt (its checksum does not match): use an earlier \
         checkpoint or run the scene from the start"
    )]
    Corrupt {
        /// The file.
        path: PathBuf,
    },
    /// A body that does not fit the scene.
    #[error("cannot resume from `{path}`: {source}")]
    Content {
        /// The file.
        path: PathBuf,
        /// What does not fit.
        source: CheckpointError,
    },
}

/// The fingerprints of the scene file and of every file it reads, for
/// [`write_checkpoint`] and [`read_checkpoint`].
pub fn scene_fingerprint(scene: &Scene) -> SceneFingerprint {
    SceneFingerprint::of(scene)
}

/// Writes a checkpoint with `body` for the scene and inputs of `fingerprint`, atomically.
///
/// # Errors
/// [`OutputError::Io`] if the file cannot be written; the previous file is then untouched.
pub fn write_checkpoint(
    path: &Path,
    fingerprint: &SceneFingerprint,
    body: &[u8],
) -> Result<(), OutputError> {
    let inputs = fingerprint.encode_inputs();
    let mut checked = Vec::with_capacity(8 + inputs.len() + body.len());
    checked.extend_from_slice(&(inputs.len() as u64).to_le_bytes());
    checked.extend_from_slice(&inputs);
    checked.extend_from_slice(body);
    write_atomic(path, |w| {
        w.write_all(MAGIC)?;
        w.write_all(&FORMAT_VERSION.to_le_bytes())?;
        w.write_all(&fingerprint.scene.to_le_bytes())?;
        w.write_all(&checked)?;
        w.write_all(&fnv1a(&checked).to_le_bytes())
    })
}

/// Reads the body of the checkpoint at `path`, checking the magic, the version and the
/// checksum and, with `expected` (the scene being resumed; `None` to read another scene's
/// checkpoint, as `[run] start_from` does), the scene fingerprint (0 skips it) and every
/// recorded input file against the files as they are now.
///
/// # Errors
/// The [`CheckpointFileError`] that names what is wrong.
pub fn read_checkpoint(
    path: &Path,
    expected: Option<&SceneFingerprint>,
) -> Result<Vec<u8>, CheckpointFileError> {
    let bytes = std::fs::read(path).map_err(|source| CheckpointFileError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    let path = path.to_path_buf();
    if bytes.len() < 8 || &bytes[..8] != MAGIC {
        return Err(CheckpointFileError::NotCheckpoint { path });
    }
    if bytes.len() < HEADER + 8 + 8 {
        return Err(CheckpointFileError::Truncated {
            path,
            length: bytes.len(),
        });
    }
    let word = |at: usize| u64::from_le_bytes(bytes[at..at + 8].try_into().expect("8 bytes"));
    let version = word(8);
    if version == 0 || version > LAST_VERSION_READ_AS_ONE {
        return Err(CheckpointFileError::DamagedHeader {
            path,
            found: version,
            expected: FORMAT_VERSION,
        });
    }
    if version != FORMAT_VERSION {
        return Err(CheckpointFileError::Version {
            path,
            found: version,
            expected: FORMAT_VERSION,
        });
    }
    if let Some(scene) = expected.filter(|e| e.scene != 0 && word(16) != e.scene) {
        return Err(CheckpointFileError::Scene {
            path,
            scene: scene.path.clone(),
        });
    }
    let end = bytes.len() - 8;
    if fnv1a(&bytes[HEADER..end]) != word(end) {
        return Err(CheckpointFileError::Corrupt { path });
    }
    let body_start = usize::try_from(word(HEADER))
        .ok()
        .and_then(|n| n.checked_add(HEADER + 8))
        .filter(|&at| at <= end)
        .ok_or_else(|| CheckpointFileError::Corrupt { path: path.clone() })?;
    if let Some(expected) = expected {
        let recorded = decode_inputs(&bytes[HEADER + 8..body_start]).map_err(|source| {
            CheckpointFileError::Content {
                path: path.clone(),
                source,
            }
        })?;
        if let Some((input, change)) = expected.first_change(&recorded) {
            let resolved = expected.resolve(&input);
            return Err(match change {
                InputChange::Changed => CheckpointFileError::InputChanged {
                    path,
                    input,
                    resolved,
                },
                InputChange::Missing => CheckpointFileError::InputMissing {
                    path,
                    input,
                    resolved,
                },
            });
        }
    }
    Ok(bytes[body_start..end].to_vec())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("qdem-ckpt-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir.join(CHECKPOINT_FILE)
    }

    fn fingerprint(scene: u64, mesh: Option<u64>) -> SceneFingerprint {
        SceneFingerprint {
            path: PathBuf::from("dir/scene.toml"),
            scene,
            inputs: vec![crate::inputs::Input {
                file: PathBuf::from("beam.msh"),
                fingerprint: mesh,
            }],
        }
    }

    #[test]
    fn a_checkpoint_reads_back_and_refuses_what_does_not_fit() {
        let path = temp("roundtrip");
        let written = fingerprint(42, Some(1));
        write_checkpoint(&path, &written, b"body bytes").unwrap();
        assert_eq!(
            read_checkpoint(&path, Some(&written)).unwrap(),
            b"body bytes"
        );
        assert_eq!(read_checkpoint(&path, None).unwrap(), b"body bytes");
        assert!(matches!(
            read_checkpoint(&path, Some(&fingerprint(43, Some(1)))),
            Err(CheckpointFileError::Scene { .. })
        ));
        let message = match read_checkpoint(&path, Some(&fingerprint(42, Some(2)))) {
            Err(e @ CheckpointFileError::InputChanged { .. }) => e.to_string(),
            other => panic!("expected a changed input, got {other:?}"),
        };
        assert!(
            message.contains("`beam.msh`") && message.contains("dir/beam.msh"),
            "{message}"
        );
        assert!(matches!(
            read_checkpoint(&path, Some(&fingerprint(42, None))),
            Err(CheckpointFileError::InputMissing { .. })
        ));
        let mut bytes = std::fs::read(&path).unwrap();
        let at = bytes.len() - 10;
        bytes[at] ^= 1;
        std::fs::write(&path, &bytes).unwrap();
        assert!(matches!(
            read_checkpoint(&path, Some(&written)),
            Err(CheckpointFileError::Corrupt { .. })
        ));
        bytes[at] ^= 1;
        bytes[HEADER + 9] ^= 1;
        std::fs::write(&path, &bytes).unwrap();
        assert!(matches!(
            read_checkpoint(&path, None),
            Err(CheckpointFileError::Corrupt { .. })
        ));
        bytes[8] = 2;
        std::fs::write(&path, &bytes).unwrap();
        assert!(matches!(
            read_checkpoint(&path, Some(&written)),
            Err(CheckpointFileError::Version {
                found: 2,
                expected: FORMAT_VERSION,
                ..
            })
        ));
        // A version no qdem writes (0, or the random bytes of a file that starts with the
        // magic): named a damaged header, not a version to resume with another qdem.
        for garbage in [0, u64::from(u16::MAX) + 1, 0x1dbb_3025_18ca_4da5] {
            bytes[8..16].copy_from_slice(&garbage.to_le_bytes());
            std::fs::write(&path, &bytes).unwrap();
            let error = read_checkpoint(&path, None).unwrap_err();
            assert!(
                matches!(error, CheckpointFileError::DamagedHeader { found, .. } if found == garbage),
                "{error}"
            );
            assert!(
                error.to_string().contains("is not a qdem checkpoint"),
                "{error}"
            );
        }
        bytes[8..16].copy_from_slice(&u64::from(u16::MAX).to_le_bytes());
        std::fs::write(&path, &bytes).unwrap();
        assert!(matches!(
            read_checkpoint(&path, None),
            Err(CheckpointFileError::Version { .. })
        ));
        std::fs::write(&path, b"t,tip.ux\n0,0\n").unwrap();
        assert!(matches!(
            read_checkpoint(&path, Some(&written)),
            Err(CheckpointFileError::NotCheckpoint { .. })
        ));
        for cut in [8, 16, 24, 39] {
            std::fs::write(&path, &bytes[..cut]).unwrap();
            assert!(matches!(
                read_checkpoint(&path, Some(&written)),
                Err(CheckpointFileError::Truncated { length, .. }) if length == cut
            ));
        }
    }
}
