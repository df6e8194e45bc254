//! Atomic file replacement: write to a temporary file, sync, rename.
//!
//! Every output of a run goes through this module, so that a reader (ParaView polling a
//! `.pvd`, a script tailing results, a crash) never sees a half-written file: the target
//! either keeps its previous content or gets the complete new one.
//!
//! The temporary file lives in the target's directory (a rename is only atomic within one
//! file system) and is named `.NAME.tmp-<pid>`. Two writers of the *same* target in the
//! same process at the same time would share that name; the writers of this crate never
//! do that.
//!
//! A run that is killed mid-write leaves its temporary file behind; at the start of every run
//! [`remove_stale_temporaries`] removes those of processes that no longer run (never those of
//! a live process, which may be writing them right now).
//!
//! After the rename the containing directory is synced too (on Unix), on a best-effort
//! basis: the rename has already happened at that point, so a failure there is not
//! reported as a failed write.

use std::fs::{self, File};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

use super::error::{IoStage, OutputError};

/// The buffer size of the writers handed out by this module.
const BUFFER_SIZE: usize = 1 << 16;

/// Writes a file atomically.
///
/// `write` receives a buffered writer onto a temporary file `.NAME.tmp-<pid>` in the
/// directory of `path`. When it returns `Ok`, the buffer is flushed, the file is synced to
/// disk (`sync_all`) and renamed over `path`. On any error the temporary file is removed
/// and `path` is left untouched.
///
/// # Errors
/// [`OutputError::NoFileName`] if `path` has no file name, [`OutputError::Io`] if creating,
/// writing, syncing or renaming fails (including an error returned by `write`).
///
/// # Example
/// ```
/// # use qdem_io::output::write_atomic;
/// let path = std::env::temp_dir().join(format!("qdem-doc-atomic-{}.txt", std::process::id()));
/// write_atomic(&path, |w| w.write_all(b"hello\n")).unwrap();
/// assert_eq!(std::fs::read_to_string(&path).unwrap(), "hello\n");
/// # std::fs::remove_file(&path).unwrap();
/// ```
pub fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> Result<(), OutputError> {
    write_atomic_as(path, "file", write)
}

/// [`write_atomic`] with a description of the output (`what`) for error messages.
pub(crate) fn write_atomic_as(
    path: &Path,
    what: &'static str,
    write: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> Result<(), OutputError> {
    let mut file = AtomicFile::create_as(path, what)?;
    if let Err(source) = write(file.writer()) {
        return Err(file.error(IoStage::Write, source));
    }
    file.commit()
}

/// The temporary path `.NAME.tmp-<pid>` next to `path`.
fn temp_path(path: &Path) -> Result<PathBuf, OutputError> {
    let name = path.file_name().ok_or_else(|| OutputError::NoFileName {
        path: path.to_path_buf(),
    })?;
    let mut temp_name = std::ffi::OsString::from(".");
    temp_name.push(name);
    temp_name.push(format!(".tmp-{}", std::process::id()));
    Ok(path.with_file_name(temp_name))
}

/// Removes, in `out_dir` and its `vtu/` subfolder, the temporary files this module names
/// (`.NAME.tmp-<pid>`, and `.NAME.publish-<pid>` of [`AtomicFile::publish`]) whose process no
/// longer runs: the leftovers of killed runs. A file of a live process (this one included) is
/// kept, and so is every file when liveness cannot be told (no `/proc`, or not Linux). Best
/// effort: a directory that cannot be listed or a file that cannot be removed is skipped.
/// Returns the files removed.
pub fn remove_stale_temporaries(out_dir: &Path) -> Vec<PathBuf> {
    let mut removed = Vec::new();
    for dir in [out_dir.to_path_buf(), out_dir.join("vtu")] {
        let Ok(entries) = fs::read_dir(&dir) else {
            continue;
        };
        for entry in entries.flatten() {
            let name = entry.file_name();
            let Some(pid) = name.to_str().and_then(temporary_pid) else {
                continue;
            };
            if process_may_run(pid) || !entry.file_type().is_ok_and(|t| t.is_file()) {
                continue;
            }
            let path = entry.path();
            if fs::remove_file(&path).is_ok() {
                removed.push(path);
            }
        }
    }
    removed
}

/// The process id in a temporary file's name `.NAME.tmp-<pid>` or `.NAME.publish-<pid>`.
fn temporary_pid(name: &str) -> Option<u32> {
    let rest = name.strip_prefix('.')?;
    let (stem, pid) = [".tmp-", ".publish-"]
        .iter()
        .find_map(|marker| rest.rsplit_once(marker))?;
    if stem.is_empty() || pid.is_empty() || !pid.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    pid.parse().ok()
}

/// Whether process `pid` may be running: false only when it certainly is not (on Linux,
/// `/proc` is there and `/proc/<pid>` is not).
fn process_may_run(pid: u32) -> bool {
    if pid == std::process::id() {
        return true;
    }
    #[cfg(target_os = "linux")]
    {
        let proc = Path::new("/proc");
        !proc.join("self").exists() || proc.join(pid.to_string()).exists()
    }
    #[cfg(not(target_os = "linux"))]
    {
        true
    }
}

/// Syncs the directory containing `path`, so that a completed rename survives a crash.
/// Best effort: errors are ignored (see the module docs).
fn sync_parent_dir(path: &Path) {
    #[cfg(unix)]
    {
        let dir = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        if let Ok(d) = File::open(dir) {
            let _ = d.sync_all();
        }
    }
    #[cfg(not(unix))]
    let _ = path;
}

/// A file written in pieces (e.g. a CSV row by row during a long run) and made visible
/// atomically at the end.
///
/// [`AtomicFile::create`] opens the temporary file `.NAME.tmp-<pid>` next to the target,
/// [`AtomicFile::writer`] gives the buffered writer onto it, and [`AtomicFile::commit`]
/// flushes, syncs and renames it over the target. Dropping an `AtomicFile` without
/// committing removes the temporary file and leaves the target untouched.
///
/// # Example
/// ```
/// # use qdem_io::output::AtomicFile;
/// use std::io::Write;
/// let path = std::env::temp_dir().join(format!("qdem-doc-atomicfile-{}.csv", std::process::id()));
/// let mut file = AtomicFile::create(&path).unwrap();
/// for i in 0..3 {
///     writeln!(file.writer(), "{i}").unwrap();
/// }
/// file.commit().unwrap();
/// assert_eq!(std::fs::read_to_string(&path).unwrap(), "0\n1\n2\n");
/// # std::fs::remove_file(&path).unwrap();
/// ```
#[derive(Debug)]
pub struct AtomicFile {
    /// The target path.
    path: PathBuf,
    /// The temporary path.
    temp: PathBuf,
    /// What kind of output this is, for error messages.
    what: &'static str,
    /// The writer onto the temporary file; `None` once committed.
    writer: Option<BufWriter<File>>,
}

impl AtomicFile {
    /// Creates (or truncates) the temporary file for the target `path`.
    ///
    /// # Errors
    /// [`OutputError::NoFileName`] if `path` has no file name, [`OutputError::Io`] if the
    /// temporary file cannot be created (e.g. the directory does not exist).
    pub fn create(path: &Path) -> Result<Self, OutputError> {
        Self::create_as(path, "file")
    }

    /// [`AtomicFile::create`] with a description of the output for error messages.
    pub(crate) fn create_as(path: &Path, what: &'static str) -> Result<Self, OutputError> {
        let temp = temp_path(path)?;
        let file = File::create(&temp).map_err(|source| OutputError::Io {
            what,
            path: path.to_path_buf(),
            temp: temp.clone(),
            stage: IoStage::CreateTemp,
            source,
        })?;
        Ok(Self {
            path: path.to_path_buf(),
            temp,
            what,
            writer: Some(BufWriter::with_capacity(BUFFER_SIZE, file)),
        })
    }

    /// The target path (where the file appears on [`AtomicFile::commit`]).
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The temporary path the content is being written to.
    #[must_use]
    pub fn temp_path(&self) -> &Path {
        &self.temp
    }

    /// The buffered writer onto the temporary file.
    ///
    /// Write errors are plain `io::Error`s; wrap them with the paths yourself or use a
    /// higher-level writer such as [`ProbeCsv`](super::ProbeCsv).
    ///
    /// # Panics
    /// Never: the writer is present until [`AtomicFile::commit`] consumes `self`.
    pub fn writer(&mut self) -> &mut BufWriter<File> {
        self.writer
            .as_mut()
            .expect("AtomicFile writer is present until commit")
    }

    /// Wraps an I/O error with this file's paths.
    pub(crate) fn error(&self, stage: IoStage, source: io::Error) -> OutputError {
        OutputError::Io {
            what: self.what,
            path: self.path.clone(),
            temp: self.temp.clone(),
            stage,
            source,
        }
    }

    /// Flushes the buffer, syncs the temporary file to disk and renames it over the target.
    ///
    /// # Errors
    /// [`OutputError::Io`] if flushing, syncing or renaming fails; the temporary file is
    /// then removed and the target left untouched.
    pub fn commit(mut self) -> Result<(), OutputError> {
        let writer = self
            .writer
            .take()
            .expect("AtomicFile writer is present until commit");
        let file = match writer.into_inner() {
            Ok(file) => file,
            Err(e) => {
                let (source, writer) = e.into_parts();
                drop(writer);
                return Err(self.fail(IoStage::Sync, source));
            }
        };
        if let Err(source) = file.sync_all() {
            drop(file);
            return Err(self.fail(IoStage::Sync, source));
        }
        drop(file);
        if let Err(source) = fs::rename(&self.temp, &self.path) {
            return Err(self.fail(IoStage::Rename, source));
        }
        sync_parent_dir(&self.path);
        Ok(())
    }

    /// Makes what has been written so far visible under the target path, atomically, and goes
    /// on writing: the content is flushed, copied to a second temporary file
    /// `.NAME.publish-<pid>`, synced and renamed over the target. A run publishes its
    /// row-by-row outputs this way when it writes a checkpoint, so that the files on disk
    /// always hold at least what the latest checkpoint has seen.
    ///
    /// # Errors
    /// [`OutputError::Io`] if flushing, copying, syncing or renaming fails; the target is
    /// then untouched.
    pub fn publish(&mut self) -> Result<(), OutputError> {
        if let Err(source) = self.writer().flush() {
            return Err(self.error(IoStage::Write, source));
        }
        let copy = self.temp.with_file_name(
            self.temp
                .file_name()
                .expect("a temporary path has a file name")
                .to_string_lossy()
                .replacen(".tmp-", ".publish-", 1),
        );
        let result = fs::copy(&self.temp, &copy)
            .and_then(|_| File::open(&copy)?.sync_all())
            .and_then(|_| fs::rename(&copy, &self.path));
        if let Err(source) = result {
            let _ = fs::remove_file(&copy);
            return Err(self.error(IoStage::Rename, source));
        }
        sync_parent_dir(&self.path);
        Ok(())
    }

    /// Removes the temporary file (the writer is already closed) and builds the error.
    fn fail(&self, stage: IoStage, source: io::Error) -> OutputError {
        let _ = fs::remove_file(&self.temp);
        self.error(stage, source)
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        // `writer` is `None` after a commit, successful or not (a failed commit has
        // already removed the temporary file).
        if let Some(writer) = self.writer.take() {
            // Discard buffered content: `into_parts` does not flush.
            let (file, _) = writer.into_parts();
            drop(file);
            let _ = fs::remove_file(&self.temp);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn temp_name_is_hidden_and_has_pid() {
        let t = temp_path(Path::new("out/dir/result.vtu")).unwrap();
        assert_eq!(
            t,
            Path::new("out/dir").join(format!(".result.vtu.tmp-{}", std::process::id()))
        );
        let t = temp_path(Path::new("x.csv")).unwrap();
        assert_eq!(
            t,
            PathBuf::from(format!(".x.csv.tmp-{}", std::process::id()))
        );
    }

    #[test]
    fn a_temporary_name_gives_its_pid() {
        assert_eq!(temporary_pid(".probes.csv.tmp-123"), Some(123));
        assert_eq!(temporary_pid(".probes.csv.publish-45"), Some(45));
        assert_eq!(temporary_pid(".checkpoint.qdc.tmp-7"), Some(7));
        for other in [
            "probes.csv.tmp-123",
            ".probes.csv.tmp-",
            ".probes.csv.tmp-12x",
            ".tmp-12",
            ".probes.csv",
        ] {
            assert_eq!(temporary_pid(other), None, "{other}");
        }
        assert!(process_may_run(std::process::id()));
    }

    #[test]
    fn no_file_name_is_an_error() {
        assert!(matches!(
            temp_path(Path::new("/")),
            Err(OutputError::NoFileName { .. })
        ));
        assert!(matches!(
            temp_path(Path::new("a/..")),
            Err(OutputError::NoFileName { .. })
        ));
    }
}
