//! One controller per cell name on a machine: an exclusive `flock` on a per-user lock file,
//! held for the controller's lifetime (the iceoryx2 services of a cell are shared by name, so a
//! second controller would otherwise connect to the first one's planner). The file lives in
//! the user's runtime directory (no one else may create, replace or link it there), is opened
//! without following a link, must be a regular file of the user, and is removed when its
//! controller ends. A controller killed outright leaves its file unlocked (the kernel drops a
//! dead process's `flock`): the next controller of the cell takes it over, and any controller
//! sweeps such stale files (and their operator sockets) when it starts.

use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, Write};
use std::os::unix::fs::{MetadataExt, OpenOptionsExt};
use std::path::{Path, PathBuf};

use nix::fcntl::{Flock, FlockArg};

use crate::runtime_dir::{self, RuntimeDirError};

/// Another controller runs this cell, or the lock file cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum CellLockError {
    /// Another process (a cell, or a `cellrt bus` command) has the EtherCAT interface.
    #[error("EtherCAT interface '{interface}' is in use by process {pid} ({by}); stop it first, or reach the running cell's drives with `cellrt sdo` / `cellrt bus diag --cell NAME`")]
    InterfaceBusy {
        /// The interface.
        interface: String,
        /// Pid written by the holder.
        pid: String,
        /// The holder's command line, as far as it can be read.
        by: String,
    },
    /// An interface name no interface can have.
    #[error("'{interface}' is no network interface name")]
    InterfaceName {
        /// The name given.
        interface: String,
    },
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
    /// The lock file is not a regular file of this user.
    #[error("the cell lock {path} is not safe: {reason}")]
    Unsafe {
        /// Lock file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
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

/// Held while the controller of a cell runs; the lock file is removed on drop.
#[derive(Debug)]
pub struct CellLock {
    path: PathBuf,
    lock: Option<Flock<File>>,
}

/// Path of the lock file of `cell` for the current user, in its runtime directory.
pub fn lock_path(cell: &str) -> PathBuf {
    runtime_dir::path().join(format!("{cell}{LOCK_SUFFIX}"))
}

/// How a lock file's name ends.
const LOCK_SUFFIX: &str = ".lock";

/// How often a controller looks again at a lock whose holder has not written a live pid yet
/// (it may be a controller sweeping the file as stale), 2 ms apart.
const UNSETTLED_RETRIES: u32 = 50;

/// Opens (creating it mode 0600) the lock file at `path` without following a link and checks
/// that it is a regular file of this user.
fn open_lock(path: &Path, create: bool) -> Result<File, CellLockError> {
    let file = OpenOptions::new()
        .read(true)
        .write(true)
        .create(create)
        .truncate(false)
        .mode(0o600)
        .custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK)
        .open(path)
        .map_err(|source| CellLockError::Io {
            path: path.to_path_buf(),
            source,
        })?;
    let m = file.metadata().map_err(|source| CellLockError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let uid = nix::unistd::getuid().as_raw();
    let reason = if !m.is_file() {
        Some("it is not a regular file".to_string())
    } else if m.uid() != uid {
        Some(format!("it belongs to uid {}, not {uid}", m.uid()))
    } else {
        None
    };
    match reason {
        Some(reason) => Err(CellLockError::Unsafe {
            path: path.to_path_buf(),
            reason,
        }),
        None => Ok(file),
    }
}

/// Whether `lock` is still the file at `path` (not removed or replaced since it was opened).
fn still_at(lock: &File, path: &Path) -> bool {
    let (Ok(held), Ok(now)) = (lock.metadata(), std::fs::symlink_metadata(path)) else {
        return false;
    };
    (held.dev(), held.ino()) == (now.dev(), now.ino())
}

/// Whether the pid text written by a lock's holder names a live process.
fn pid_alive(pid: &str) -> bool {
    pid.parse::<i32>()
        .ok()
        .filter(|p| *p > 0)
        .is_some_and(|p| nix::sys::signal::kill(nix::unistd::Pid::from_raw(p), None).is_ok())
}

/// Removes the lock files in `dir` that no process holds (their controllers were killed), and
/// the operator sockets of their cells.
fn sweep_stale(dir: &Path) {
    let sockets = runtime_dir::operator_path_of(nix::unistd::getuid().as_raw());
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        let Some(cell) = name.strip_suffix(LOCK_SUFFIX) else {
            continue;
        };
        let path = e.path();
        let Ok(file) = open_lock(&path, false) else {
            continue;
        };
        if let Ok(lock) = Flock::lock(file, FlockArg::LockExclusiveNonblock) {
            if still_at(&lock, &path) {
                let _ = std::fs::remove_file(crate::host::operator::socket::socket_path_in(
                    &sockets, cell,
                ));
                let _ = std::fs::remove_file(&path);
            }
        }
    }
}

impl CellLock {
    /// Takes the lock of `cell` or says who holds it. The file is opened without following a
    /// link; a lock taken on a file that was removed meanwhile (by its previous holder, or by a
    /// controller sweeping it as stale) is taken again on the new one.
    pub fn acquire(cell: &str) -> Result<CellLock, CellLockError> {
        let dir = runtime_dir::ensure()?;
        sweep_stale(&dir);
        let path = lock_path(cell);
        let io = |source| CellLockError::Io {
            path: path.clone(),
            source,
        };
        let mut unsettled = 0;
        loop {
            match Flock::lock(open_lock(&path, true)?, FlockArg::LockExclusiveNonblock) {
                Ok(mut lock) => {
                    if !still_at(&lock, &path) {
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
                    let pid = pid.trim().to_string();
                    if !pid_alive(&pid) && unsettled < UNSETTLED_RETRIES {
                        unsettled += 1;
                        std::thread::sleep(std::time::Duration::from_millis(2));
                        continue;
                    }
                    return Err(CellLockError::Busy {
                        cell: cell.to_string(),
                        pid,
                    });
                }
            }
        }
    }
}

/// Held by whoever drives an EtherCAT interface's SubDevices (a cell that runs on it, a
/// `cellrt bus` command that takes them to PRE-OP), so that two never talk to one segment at
/// once. The same per-user lock file as a cell's, named after the interface.
#[derive(Debug)]
pub struct InterfaceLock {
    _held: CellLock,
}

impl InterfaceLock {
    /// Takes the lock of `interface` or says which process holds it.
    pub fn acquire(interface: &str) -> Result<InterfaceLock, CellLockError> {
        // IFNAMSIZ − 1 bytes, no path separator (the name becomes a file name).
        let named = !interface.is_empty()
            && interface.len() <= 15
            && !interface.contains(['/', '\0'])
            && interface != "."
            && interface != "..";
        if !named {
            return Err(CellLockError::InterfaceName {
                interface: interface.to_string(),
            });
        }
        match CellLock::acquire(&format!("ethercat@{interface}")) {
            Ok(lock) => Ok(InterfaceLock { _held: lock }),
            Err(CellLockError::Busy { pid, .. }) => Err(CellLockError::InterfaceBusy {
                interface: interface.to_string(),
                by: command_line(&pid),
                pid,
            }),
            Err(e) => Err(e),
        }
    }
}

/// The command line of process `pid` (its first three words), or "unknown".
fn command_line(pid: &str) -> String {
    let words: Vec<String> = std::fs::read(format!("/proc/{pid}/cmdline"))
        .unwrap_or_default()
        .split(|b| *b == 0)
        .filter(|w| !w.is_empty())
        .take(3)
        .map(|w| String::from_utf8_lossy(w).into_owned())
        .collect();
    if words.is_empty() {
        "unknown".to_string()
    } else {
        words.join(" ")
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

    #[test]
    fn a_lock_left_by_a_killed_controller_is_taken_over_and_others_are_swept() {
        let name = format!("staletest-{}", std::process::id());
        let other = format!("staletest-other-{}", std::process::id());
        runtime_dir::ensure().unwrap();
        let dir = runtime_dir::ensure_operator().unwrap();
        // Files of killed controllers: nobody holds their flock; their pids are long gone. The
        // socket first: a controller sweeping meanwhile (another test of this process) that
        // finds the stale lock removes the socket with it (it failed under load when the
        // socket came after the lock another test had already swept).
        let sock = crate::host::operator::socket::socket_path_in(&dir, &other);
        std::fs::write(&sock, b"").unwrap();
        std::fs::write(lock_path(&name), b"999999999").unwrap();
        std::fs::write(lock_path(&other), b"999999998").unwrap();
        let lock = CellLock::acquire(&name).unwrap();
        assert_eq!(
            std::fs::read_to_string(lock_path(&name)).unwrap(),
            std::process::id().to_string()
        );
        assert!(!lock_path(&other).exists(), "a stale lock is swept");
        assert!(!sock.exists(), "and its cell's socket with it");
        drop(lock);
        assert!(!lock_path(&name).exists());
    }
}
