//! [`FolderLock`]: one run at a time in an output folder.
//!
//! Two runs writing into one folder mix their files (one run's `results.pvd` beside the
//! other's VTUs, one's checkpoint over the other's). A run therefore holds the folder's lock
//! file `.qdem-run.lock` from its start to its end, by a kernel advisory lock
//! ([`std::fs::File::try_lock`]: `flock(2)` on Linux) on the file, kept open for the whole run.
//!
//! The kernel decides who holds the folder, never the file's content: it frees a lock when
//! its process ends however it ends (SIGKILL included), so a lock file left empty, holding
//! garbage, or the pid of a dead or of an unrelated live process is simply taken over, and two
//! runs started at the same instant cannot both get it. The file holds the holder's process
//! id only for the refusal's message.
//!
//! Taking the lock: open the file (creating it if missing, never truncating it), try the
//! lock, then check that the path still names the file locked. The holder removes the file
//! at its end, while it still holds the lock; a run that opened the file just before that
//! removal and gets the lock after it holds a file no longer in the folder, which the check
//! sees, and it starts over on the file now there. So exactly one run holds the lock of the
//! file the folder names, and only the holder ever removes it.

use std::fs::{self, File, OpenOptions, TryLockError};
use std::io::{self, Read, Seek, Write};
use std::path::{Path, PathBuf};
use std::time::Duration;

/// The lock file's name in an output folder.
pub const LOCK_FILE: &str = ".qdem-run.lock";

/// Why a folder's lock could not be taken.
#[derive(Debug, thiserror::Error)]
pub enum LockError {
    /// Another process holds it.
    #[error(
        "the output folder {dir} is in use by another qdem run ({holder}, which holds {lock}): \
         two runs into one folder would mix their files; fix: wait for that run to end (or \
         stop it: Ctrl-C or SIGTERM checkpoints it), or give this one another --out (or \
         [output] dir)",
        dir = lock.parent().unwrap_or(lock).display(),
        holder = match pid { Some(pid) => format!("pid {pid}"), None => "pid not yet written".to_string() },
        lock = lock.display()
    )]
    Held {
        /// The lock file.
        lock: PathBuf,
        /// The holder's process id, as the file holds it (`None` when it holds none yet).
        pid: Option<u32>,
    },
    /// The lock file could not be opened, locked, read or written.
    #[error("cannot {action} the lock file {path} of the output folder: {source}", path = path.display())]
    Io {
        /// What was being done: open, lock, write.
        action: &'static str,
        /// The lock file.
        path: PathBuf,
        /// The underlying error.
        source: io::Error,
    },
}

/// The held lock of an output folder; dropping it removes the lock file and frees the lock.
#[derive(Debug)]
pub struct FolderLock {
    path: PathBuf,
    /// The locked file, open for the whole run: closing it frees the lock.
    file: File,
}

/// How many times the lock is tried again after the file it locked was removed under it (by
/// a holder ending at that instant): each retry needs another run to have ended meanwhile.
const RETRIES: usize = 100;

impl FolderLock {
    /// Takes the lock of `dir` (which must exist).
    ///
    /// # Errors
    /// [`LockError::Held`] when another process holds it; [`LockError::Io`] when the file
    /// cannot be opened, locked or written (a file system without locks among the causes).
    pub fn acquire(dir: &Path) -> Result<FolderLock, LockError> {
        let path = dir.join(LOCK_FILE);
        let io = |action, source| LockError::Io {
            action,
            path: path.clone(),
            source,
        };
        for _ in 0..RETRIES {
            let mut file = OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .open(&path)
                .map_err(|e| io("open", e))?;
            match file.try_lock() {
                Ok(()) => {}
                Err(TryLockError::WouldBlock) => {
                    let pid = holder_pid(&mut file);
                    return Err(LockError::Held { lock: path, pid });
                }
                Err(TryLockError::Error(e)) => return Err(io("lock", e)),
            }
            if !names(&path, &file) {
                // Locked after its holder removed it: the folder's lock is another file now.
                continue;
            }
            let pid = std::process::id();
            file.set_len(0)
                .and_then(|()| file.rewind())
                .and_then(|()| file.write_all(format!("{pid}\n").as_bytes()))
                .map_err(|e| io("write", e))?;
            return Ok(FolderLock { path, file });
        }
        Err(io(
            "lock",
            io::Error::other("it was removed under this run 100 times in a row"),
        ))
    }

    /// The lock file.
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl Drop for FolderLock {
    fn drop(&mut self) {
        // Removed while still locked (the file closes after this), and only if the path
        // still names this file: a run that opens it meanwhile finds it gone once it gets
        // the lock, and starts over.
        if names(&self.path, &self.file) {
            let _ = fs::remove_file(&self.path);
        }
    }
}

/// The pid a held lock file holds, read a few times over 0.1 s: its holder writes it just
/// after taking the lock. `None` when it holds none by then.
fn holder_pid(file: &mut File) -> Option<u32> {
    for _ in 0..10 {
        let mut text = String::new();
        let read = file.rewind().and_then(|()| file.read_to_string(&mut text));
        if let Some(pid) = read.ok().and_then(|_| text.trim().parse().ok()) {
            return Some(pid);
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    None
}

/// Whether `path` names the open `file` (the same inode on the same device).
#[cfg(unix)]
fn names(path: &Path, file: &File) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (fs::metadata(path), file.metadata()) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

/// Whether `path` names the open `file`: elsewhere an open file cannot be removed, so the
/// path names it while it is open.
#[cfg(not(unix))]
fn names(path: &Path, _file: &File) -> bool {
    path.exists()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::sync::Barrier;

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
        // A second open file is a second holder to the kernel, even in this process.
        match FolderLock::acquire(&dir) {
            Err(LockError::Held { pid, .. }) => assert_eq!(pid, Some(std::process::id())),
            other => panic!("expected a held lock, got {other:?}"),
        }
        drop(lock);
        assert!(!dir.join(LOCK_FILE).exists());
        drop(FolderLock::acquire(&dir).unwrap());
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_lock_file_nobody_locks_is_taken_over_whatever_it_holds() {
        let dir = temp_dir("stale");
        // Its own pid: a live process, which does not lock the file.
        let contents = [
            "",
            "garbage\n",
            "4294967295\n",
            &std::process::id().to_string(),
        ];
        for text in contents {
            fs::write(dir.join(LOCK_FILE), text).unwrap();
            let lock = FolderLock::acquire(&dir).unwrap();
            let holder = fs::read_to_string(lock.path()).unwrap();
            assert_eq!(holder, format!("{}\n", std::process::id()), "over {text:?}");
            drop(lock);
        }
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn of_runs_racing_for_one_folder_one_holds_it_at_a_time() {
        let dir = temp_dir("race");
        let (threads, rounds) = (8, 200);
        let holding = AtomicUsize::new(0);
        let (taken, most) = (AtomicUsize::new(0), AtomicUsize::new(0));
        let start = Barrier::new(threads);
        std::thread::scope(|s| {
            for _ in 0..threads {
                s.spawn(|| {
                    start.wait();
                    for _ in 0..rounds {
                        match FolderLock::acquire(&dir) {
                            Ok(lock) => {
                                let now = holding.fetch_add(1, Ordering::SeqCst) + 1;
                                most.fetch_max(now, Ordering::SeqCst);
                                taken.fetch_add(1, Ordering::SeqCst);
                                std::thread::yield_now();
                                holding.fetch_sub(1, Ordering::SeqCst);
                                drop(lock);
                            }
                            Err(LockError::Held { .. }) => {}
                            Err(e) => panic!("{e}"),
                        }
                    }
                });
            }
        });
        assert_eq!(
            most.load(Ordering::SeqCst),
            1,
            "two held the folder at once"
        );
        assert!(taken.load(Ordering::SeqCst) > 0);
        assert!(!dir.join(LOCK_FILE).exists());
        fs::remove_dir_all(&dir).unwrap();
    }
}
