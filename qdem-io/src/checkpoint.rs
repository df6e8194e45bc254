//! Checkpoint files (`checkpoint.qdc`): the whole state of a run, so that `qdem run SCENE
//! --resume CHECKPOINT` continues it bit for bit.
//!
//! Layout: the magic bytes `QDEMCKPT`, the format version, a fingerprint of the scene file
//! (FNV-1a of its bytes: a checkpoint is refused for an edited or another scene), the body
//! and an FNV-1a checksum of the body. The body is the run loop's record (step, output
//! schedules, probe rows written, the plot's history), then the [`qdem_core::State`], the
//! stepper's and every model's history, each part tagged ([`qdem_core::checkpoint`]). The
//! file is written atomically (temporary file, fsync, rename), so a kill at any moment leaves
//! the previous checkpoint intact.

use crate::output::{write_atomic, OutputError};
use qdem_core::CheckpointError;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// The checkpoint's file name in the output directory.
pub const CHECKPOINT_FILE: &str = "checkpoint.qdc";

/// The version of the layout this build writes and reads.
pub const FORMAT_VERSION: u64 = 3;

const MAGIC: &[u8; 8] = b"QDEMCKPT";
const HEADER: usize = 8 + 8 + 8;

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
    #[error("`{path}` is not a qdem checkpoint (it does not start with QDEMCKPT)")]
    NotCheckpoint {
        /// The file.
        path: PathBuf,
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

/// FNV-1a, 64 bit.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// The fingerprint of the scene file at `path` (0 if it cannot be read, e.g. a scene built
/// from text in a test).
pub fn scene_fingerprint(path: &Path) -> u64 {
    std::fs::read(path).map_or(0, |bytes| fnv1a(&bytes))
}

/// Writes a checkpoint with `body` for the scene of fingerprint `scene`, atomically.
///
/// # Errors
/// [`OutputError::Io`] if the file cannot be written; the previous file is then untouched.
pub fn write_checkpoint(path: &Path, scene: u64, body: &[u8]) -> Result<(), OutputError> {
    write_atomic(path, |w| {
        w.write_all(MAGIC)?;
        w.write_all(&FORMAT_VERSION.to_le_bytes())?;
        w.write_all(&scene.to_le_bytes())?;
        w.write_all(body)?;
        w.write_all(&fnv1a(body).to_le_bytes())
    })
}

/// Reads the body of the checkpoint at `path`, checking the magic, the version, the scene
/// fingerprint (`scene` of `scene_path`; 0 skips the check) and the checksum.
///
/// # Errors
/// The [`CheckpointFileError`] that names what is wrong.
pub fn read_checkpoint(
    path: &Path,
    scene: u64,
    scene_path: &Path,
) -> Result<Vec<u8>, CheckpointFileError> {
    let bytes = std::fs::read(path).map_err(|source| CheckpointFileError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    let path = path.to_path_buf();
    if bytes.len() < HEADER + 8 || &bytes[..8] != MAGIC {
        return Err(CheckpointFileError::NotCheckpoint { path });
    }
    let word = |at: usize| u64::from_le_bytes(bytes[at..at + 8].try_into().expect("8 bytes"));
    let version = word(8);
    if version != FORMAT_VERSION {
        return Err(CheckpointFileError::Version {
            path,
            found: version,
            expected: FORMAT_VERSION,
        });
    }
    if scene != 0 && word(16) != scene {
        return Err(CheckpointFileError::Scene {
            path,
            scene: scene_path.to_path_buf(),
        });
    }
    let end = bytes.len() - 8;
    let body = &bytes[HEADER..end];
    if fnv1a(body) != word(end) {
        return Err(CheckpointFileError::Corrupt { path });
    }
    Ok(body.to_vec())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("qdem-ckpt-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir.join(CHECKPOINT_FILE)
    }

    #[test]
    fn a_checkpoint_reads_back_and_refuses_what_does_not_fit() {
        let path = temp("roundtrip");
        let scene = Path::new("scene.toml");
        write_checkpoint(&path, 42, b"body bytes").unwrap();
        assert_eq!(read_checkpoint(&path, 42, scene).unwrap(), b"body bytes");
        assert!(matches!(
            read_checkpoint(&path, 43, scene),
            Err(CheckpointFileError::Scene { .. })
        ));
        let mut bytes = std::fs::read(&path).unwrap();
        bytes[HEADER + 2] ^= 1;
        std::fs::write(&path, &bytes).unwrap();
        assert!(matches!(
            read_checkpoint(&path, 42, scene),
            Err(CheckpointFileError::Corrupt { .. })
        ));
        bytes[8] = 9;
        std::fs::write(&path, &bytes).unwrap();
        assert!(matches!(
            read_checkpoint(&path, 42, scene),
            Err(CheckpointFileError::Version {
                found: 9,
                expected: FORMAT_VERSION,
                ..
            })
        ));
        std::fs::write(&path, b"t,tip.ux\n0,0\n").unwrap();
        assert!(matches!(
            read_checkpoint(&path, 42, scene),
            Err(CheckpointFileError::NotCheckpoint { .. })
        ));
    }
}
