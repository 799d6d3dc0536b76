//! One controller per cell name on a machine: an exclusive `flock` on a per-user lock file,
//! held for the controller's lifetime (the iceoryx2 services of a cell are shared by name, so a
//! second controller would otherwise connect to the first one's planner).

use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, Write};
use std::os::unix::fs::{MetadataExt, OpenOptionsExt};
use std::path::PathBuf;

use nix::fcntl::{Flock, FlockArg};

use crate::runtime_dir::{self, RuntimeDirError};

/// Another controller runs this cell, or the lock file cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum CellLockError {
    /// The cell is running elsewhere.
    #[error("cell '{cell}' is already running (pid {pid}); stop it first or give this cell another name")]
    Busy {
        /// Cell name.
        cell: String,
        /// Pid written by the holder.
        pid: String,
    },
    /// The runtime directory cannot be used.
    #[error(transparent)]
    Dir(#[from] RuntimeDirError),
    /// The lock file could not be opened.
    #[error("cannot open the cell lock {path}: {source}")]
    Io {
        /// Lock file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
}

/// Held while the controller of a cell runs; the lock file is removed on drop.
#[derive(Debug)]
pub struct CellLock {
    path: PathBuf,
    lock: Option<Flock<File>>,
}

/// Path of the lock file of `cell` for the current user, in its private runtime directory.
pub fn lock_path(cell: &str) -> PathBuf {
    runtime_dir::path().join(format!("{cell}.lock"))
}

impl CellLock {
    /// Takes the lock of `cell` or says who holds it. The file is opened without following a
    /// link; a lock taken on a file that was removed meanwhile (by its previous holder) is
    /// taken again on the new one.
    pub fn acquire(cell: &str) -> Result<CellLock, CellLockError> {
        runtime_dir::ensure()?;
        let path = lock_path(cell);
        let io = |source| CellLockError::Io {
            path: path.clone(),
            source,
        };
        loop {
            let file = OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .mode(0o600)
                .custom_flags(libc::O_NOFOLLOW)
                .open(&path)
                .map_err(io)?;
            match Flock::lock(file, FlockArg::LockExclusiveNonblock) {
                Ok(mut lock) => {
                    let held = lock.metadata().map_err(io)?;
                    let now = std::fs::symlink_metadata(&path).ok();
                    if now.is_none_or(|m| (m.dev(), m.ino()) != (held.dev(), held.ino())) {
                        continue;
                    }
                    lock.set_len(0).map_err(io)?;
                    lock.rewind().map_err(io)?;
                    write!(lock, "{}", std::process::id()).map_err(io)?;
                    return Ok(CellLock {
                        path,
                        lock: Some(lock),
                    });
                }
                Err((mut file, _)) => {
                    let mut pid = String::new();
                    let _ = file.read_to_string(&mut pid);
                    return Err(CellLockError::Busy {
                        cell: cell.to_string(),
                        pid: pid.trim().to_string(),
                    });
                }
            }
        }
    }
}

impl Drop for CellLock {
    fn drop(&mut self) {
        // Removed while still locked: a controller waiting on it re-opens the new file.
        let _ = std::fs::remove_file(&self.path);
        self.lock.take();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn second_lock_of_a_cell_is_refused_until_the_first_is_dropped() {
        let name = format!("locktest-{}", std::process::id());
        let first = CellLock::acquire(&name).unwrap();
        let err = CellLock::acquire(&name).unwrap_err();
        assert!(err.to_string().contains("already running"), "{err}");
        assert!(err.to_string().contains(&std::process::id().to_string()));
        drop(first);
        assert!(
            !lock_path(&name).exists(),
            "the lock file goes with its lock"
        );
        let again = CellLock::acquire(&name).unwrap();
        let mode = std::fs::metadata(lock_path(&name)).unwrap().mode() & 0o777;
        assert_eq!(mode, 0o600);
        drop(again);
    }

    #[test]
    fn a_link_planted_at_the_lock_path_is_not_followed() {
        let name = format!("linktest-{}", std::process::id());
        runtime_dir::ensure().unwrap();
        let target = tempfile::NamedTempFile::new().unwrap();
        std::fs::write(target.path(), b"precious").unwrap();
        std::os::unix::fs::symlink(target.path(), lock_path(&name)).unwrap();
        let e = CellLock::acquire(&name).unwrap_err();
        assert!(matches!(e, CellLockError::Io { .. }), "{e}");
        assert_eq!(std::fs::read(target.path()).unwrap(), b"precious");
        std::fs::remove_file(lock_path(&name)).unwrap();
    }
}
