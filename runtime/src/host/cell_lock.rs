//! One controller per cell name on a machine: an exclusive `flock` on a per-user lock file,
//! held for the controller's lifetime (the iceoryx2 services of a cell are shared by name, so a
//! second controller would otherwise connect to the first one's planner).

use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, Write};
use std::path::PathBuf;

use nix::fcntl::{Flock, FlockArg};

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
    /// The lock file could not be opened.
    #[error("cannot open the cell lock {path}: {source}")]
    Io {
        /// Lock file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
}

/// Held while the controller of a cell runs; released on drop.
#[derive(Debug)]
pub struct CellLock {
    _lock: Flock<File>,
}

/// Path of the lock file of `cell` for the current user.
pub fn lock_path(cell: &str) -> PathBuf {
    std::env::temp_dir().join(format!(
        "cellrt-u{}-{cell}.lock",
        nix::unistd::getuid().as_raw()
    ))
}

impl CellLock {
    /// Takes the lock of `cell` or says who holds it.
    pub fn acquire(cell: &str) -> Result<CellLock, CellLockError> {
        let path = lock_path(cell);
        let io = |source| CellLockError::Io {
            path: path.clone(),
            source,
        };
        let file = OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(&path)
            .map_err(io)?;
        match Flock::lock(file, FlockArg::LockExclusiveNonblock) {
            Ok(mut lock) => {
                lock.set_len(0).map_err(io)?;
                lock.rewind().map_err(io)?;
                write!(lock, "{}", std::process::id()).map_err(io)?;
                Ok(CellLock { _lock: lock })
            }
            Err((mut file, _)) => {
                let mut pid = String::new();
                let _ = file.read_to_string(&mut pid);
                Err(CellLockError::Busy {
                    cell: cell.to_string(),
                    pid: pid.trim().to_string(),
                })
            }
        }
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
        CellLock::acquire(&name).unwrap();
    }
}
