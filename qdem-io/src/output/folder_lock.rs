//! [`FolderLock`]: one run at a time in an output folder.
//!
//! Two runs writing into one folder mix their files (one run's `results.pvd` beside the
//! other's VTUs, one's checkpoint over the other's). A run therefore holds the folder's lock
//! file `.qdem-run.lock` from its start to its end: the file is created exclusively
//! (`O_EXCL`, [`std::fs::OpenOptions::create_new`]) and holds the run's process id. A run
//! that finds it refuses to start, naming the holder's pid, unless the holder no longer runs
//! (`/proc/PID` gone or a zombie, on Linux: a run killed by SIGKILL), in which case it takes
//! the lock over. The lock is removed when the run ends, failed, stopped or finished.
//!
//! Std only, for the workspace's minimum Rust version (`File::try_lock` came with 1.89).
//! Where liveness cannot be told (not Linux, no `/proc`) a lock is always held, and a stale
//! one is removed by hand, as the refusal says. Two runs taking over the same stale lock at
//! the same instant could both win; the window is the few microseconds between the removal
//! and the re-creation.

use std::fs::{self, OpenOptions};
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::time::Duration;

/// The lock file's name in an output folder.
pub const LOCK_FILE: &str = ".qdem-run.lock";

/// Why a folder's lock could not be taken.
#[derive(Debug, thiserror::Error)]
pub enum LockError {
    /// Another run that still runs holds it.
    #[error(
        "the output folder {dir} is in use by another qdem run (pid {pid}, which holds {lock}): \
         two runs into one folder would mix their files; fix: wait for that run to end, give \
         this one another --out (or [output] dir), or, if no process {pid} is a qdem run, \
         remove {lock}",
        dir = lock.parent().unwrap_or(lock).display(),
        lock = lock.display()
    )]
    Held {
        /// The lock file.
        lock: PathBuf,
        /// The holder's process id.
        pid: u32,
    },
    /// The lock file could not be created, read or removed.
    #[error("cannot {action} the lock file {path} of the output folder: {source}", path = path.display())]
    Io {
        /// What was being done: create, read, remove.
        action: &'static str,
        /// The lock file.
        path: PathBuf,
        /// The underlying error.
        source: io::Error,
    },
}

/// The held lock of an output folder; dropping it removes the lock file.
#[derive(Debug)]
pub struct FolderLock {
    path: PathBuf,
}

impl FolderLock {
    /// Takes the lock of `dir` (which must exist), taking over one whose holder is gone.
    ///
    /// # Errors
    /// [`LockError::Held`] when a running process holds it; [`LockError::Io`] when the file
    /// cannot be created or read.
    pub fn acquire(dir: &Path) -> Result<FolderLock, LockError> {
        let path = dir.join(LOCK_FILE);
        let io = |action, source| LockError::Io {
            action,
            path: path.clone(),
            source,
        };
        // A holder that has created the file but not yet written its pid gets a moment.
        for _ in 0..50 {
            match OpenOptions::new().write(true).create_new(true).open(&path) {
                Ok(mut file) => {
                    let pid = std::process::id();
                    file.write_all(format!("{pid}\n").as_bytes())
                        .and_then(|()| file.sync_all())
                        .map_err(|e| io("write", e))?;
                    return Ok(FolderLock { path });
                }
                Err(e) if e.kind() == io::ErrorKind::AlreadyExists => {}
                Err(e) => return Err(io("create", e)),
            }
            let text = match fs::read_to_string(&path) {
                Ok(text) => text,
                Err(e) if e.kind() == io::ErrorKind::NotFound => continue,
                Err(e) => return Err(io("read", e)),
            };
            match text.trim().parse::<u32>() {
                Ok(pid) if runs(pid) => return Err(LockError::Held { lock: path, pid }),
                Ok(_) => match fs::remove_file(&path) {
                    Ok(()) => continue,
                    Err(e) if e.kind() == io::ErrorKind::NotFound => continue,
                    Err(e) => return Err(io("remove", e)),
                },
                Err(_) => std::thread::sleep(Duration::from_millis(20)),
            }
        }
        // Still no pid after a second: a holder killed between creating and writing it.
        fs::remove_file(&path).map_err(|e| io("remove", e))?;
        FolderLock::acquire(dir)
    }

    /// The lock file.
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl Drop for FolderLock {
    fn drop(&mut self) {
        // Only our own lock: a file another run re-created after a takeover stays.
        let ours = fs::read_to_string(&self.path)
            .is_ok_and(|t| t.trim() == std::process::id().to_string());
        if ours {
            let _ = fs::remove_file(&self.path);
        }
    }
}

/// Whether process `pid` may still run: this process does; on Linux one whose `/proc/PID` is
/// gone, or is a zombie (killed, not yet reaped), does not; elsewhere every process may.
fn runs(pid: u32) -> bool {
    if pid == std::process::id() {
        return true;
    }
    #[cfg(target_os = "linux")]
    {
        let proc = Path::new("/proc");
        if !proc.join("self").exists() {
            return true;
        }
        match fs::read_to_string(proc.join(pid.to_string()).join("stat")) {
            // The state follows the command name, which is in parentheses.
            Ok(stat) => !stat
                .rsplit_once(')')
                .is_some_and(|(_, rest)| rest.trim_start().starts_with(['Z', 'X'])),
            Err(_) => false,
        }
    }
    #[cfg(not(target_os = "linux"))]
    {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp_dir(tag: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("qdem-lock-{tag}-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn a_held_lock_is_refused_with_its_pid_and_released_on_drop() {
        let dir = temp_dir("held");
        let lock = FolderLock::acquire(&dir).unwrap();
        match FolderLock::acquire(&dir) {
            Err(LockError::Held { pid, .. }) => assert_eq!(pid, std::process::id()),
            other => panic!("expected a held lock, got {other:?}"),
        }
        drop(lock);
        assert!(!dir.join(LOCK_FILE).exists());
        drop(FolderLock::acquire(&dir).unwrap());
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn the_lock_of_a_process_that_is_gone_is_taken_over() {
        if !Path::new("/proc/self").exists() {
            eprintln!("skipped: no /proc to tell whether a process runs");
            return;
        }
        let dir = temp_dir("stale");
        // A finished child: its pid no longer runs once it is reaped.
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let gone = child.id();
        child.wait().unwrap();
        fs::write(dir.join(LOCK_FILE), format!("{gone}\n")).unwrap();
        let lock = FolderLock::acquire(&dir).unwrap();
        let holder = fs::read_to_string(lock.path()).unwrap();
        assert_eq!(holder.trim(), std::process::id().to_string());
        drop(lock);
        fs::remove_dir_all(&dir).unwrap();
    }
}
