//! The directories of cellrt's runtime files for the current user: owned by the user, never a
//! shared world-writable place where another user could pre-create, replace or link the files.
//! The runtime directory (cell locks, the iceoryx2 root) is private, mode 0700: root uses
//! `/run/cellrt`; other users `/run/user/UID/cellrt` where their systemd runtime directory
//! exists, else `/tmp/cellrt-uUID`. Beside it, `…-operator` (mode 0711) holds the cells'
//! operator sockets: only its user may list, create or remove entries; others may pass through
//! to a socket by name, which the socket's own mode guards (see `host::operator::socket`).
//! Each is refused unless it is a real directory owned by the user that no one else may write.

use std::os::unix::fs::{DirBuilderExt, MetadataExt, PermissionsExt};
use std::path::{Path, PathBuf};

/// Mode of the operator directory: its user's; others may only pass through by name.
pub const OPERATOR_DIR_MODE: u32 = 0o711;

/// Mode of the runtime directory and the iceoryx2 root: nobody else may enter.
pub const PRIVATE_DIR_MODE: u32 = 0o700;

/// Why the runtime directory cannot be used.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum RuntimeDirError {
    /// It could not be created.
    #[error("cannot create the runtime directory {path}: {reason}")]
    Create {
        /// The directory.
        path: PathBuf,
        /// The OS error.
        reason: String,
    },
    /// It exists but another user could interfere with it.
    #[error("the runtime directory {path} is not safe: {reason} (remove it; cellrt creates it owned by its user)")]
    Unsafe {
        /// The directory.
        path: PathBuf,
        /// What is wrong: a link, another owner, group or other write access.
        reason: String,
    },
}

/// The runtime directory of the current user (not created; see [`ensure`]).
pub fn path() -> PathBuf {
    path_of(nix::unistd::getuid().as_raw())
}

/// The runtime directory `uid` uses (for finding another user's cell).
pub fn path_of(uid: u32) -> PathBuf {
    if uid == 0 {
        return PathBuf::from("/run/cellrt");
    }
    let user_run = PathBuf::from(format!("/run/user/{uid}"));
    match std::fs::symlink_metadata(&user_run) {
        Ok(m) if m.is_dir() && m.uid() == uid => user_run.join("cellrt"),
        _ => std::env::temp_dir().join(format!("cellrt-u{uid}")),
    }
}

/// The directory of the operator sockets of `uid`'s cells: beside its runtime directory.
pub fn operator_path_of(uid: u32) -> PathBuf {
    let dir = path_of(uid);
    let name = dir
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    dir.with_file_name(format!("{name}-operator"))
}

/// The root of the current user's iceoryx2 files: inside the runtime directory, private.
pub fn iceoryx2_root() -> PathBuf {
    path().join("iceoryx2")
}

/// The runtime directory and the iceoryx2 root in it, created if absent and checked.
pub fn ensure() -> Result<PathBuf, RuntimeDirError> {
    let dir = path();
    create_owned(&dir, PRIVATE_DIR_MODE)?;
    create_owned(&iceoryx2_root(), PRIVATE_DIR_MODE)?;
    Ok(dir)
}

/// The current user's operator directory, created if absent and checked.
pub fn ensure_operator() -> Result<PathBuf, RuntimeDirError> {
    let dir = operator_path_of(nix::unistd::getuid().as_raw());
    create_owned(&dir, OPERATOR_DIR_MODE)?;
    Ok(dir)
}

/// Creates `dir` with `mode` (if absent), checks that it is a directory, not a link, owned by
/// this user, that no one else may write, and sets its mode to `mode`.
pub fn create_owned(dir: &Path, mode: u32) -> Result<(), RuntimeDirError> {
    match std::fs::DirBuilder::new().mode(mode).create(dir) {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {}
        Err(e) => {
            return Err(RuntimeDirError::Create {
                path: dir.to_path_buf(),
                reason: e.to_string(),
            })
        }
    }
    let unsafe_because = |reason: String| RuntimeDirError::Unsafe {
        path: dir.to_path_buf(),
        reason,
    };
    let m = std::fs::symlink_metadata(dir).map_err(|e| unsafe_because(e.to_string()))?;
    let uid = nix::unistd::getuid().as_raw();
    if m.file_type().is_symlink() {
        return Err(unsafe_because("it is a symbolic link".into()));
    }
    if !m.is_dir() {
        return Err(unsafe_because("it is not a directory".into()));
    }
    if m.uid() != uid {
        return Err(unsafe_because(format!(
            "it belongs to uid {}, not {uid}",
            m.uid()
        )));
    }
    let now = m.permissions().mode() & 0o7777;
    if now & 0o022 != 0 {
        return Err(unsafe_because(format!(
            "its mode is {now:03o}: others may write it"
        )));
    }
    if now != mode {
        std::fs::set_permissions(dir, std::fs::Permissions::from_mode(mode))
            .map_err(|e| unsafe_because(format!("cannot set its mode to {mode:03o}: {e}")))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_directory_is_created_owned_and_a_shared_one_is_refused() {
        let base = tempfile::tempdir().unwrap();
        let dir = base.path().join("rt");
        create_owned(&dir, OPERATOR_DIR_MODE).unwrap();
        let mode = std::fs::metadata(&dir).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o711);
        // Readable by others (an older cellrt, a user's chmod): narrowed, not refused.
        std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o755)).unwrap();
        create_owned(&dir, PRIVATE_DIR_MODE).unwrap();
        let mode = std::fs::metadata(&dir).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o700);
        // Writable by the group: refused, with the mode named.
        std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o770)).unwrap();
        let e = create_owned(&dir, PRIVATE_DIR_MODE).unwrap_err();
        assert!(e.to_string().contains("770"), "{e}");
        // A symbolic link planted where the directory belongs: refused.
        let link = base.path().join("link");
        std::os::unix::fs::symlink(&dir, &link).unwrap();
        let e = create_owned(&link, PRIVATE_DIR_MODE).unwrap_err();
        assert!(e.to_string().contains("symbolic link"), "{e}");
        // A file: refused.
        let file = base.path().join("file");
        std::fs::write(&file, b"x").unwrap();
        assert!(create_owned(&file, PRIVATE_DIR_MODE)
            .unwrap_err()
            .to_string()
            .contains("not a directory"));
    }

    #[test]
    fn the_operator_directory_lies_beside_the_runtime_directory() {
        assert_eq!(operator_path_of(0), Path::new("/run/cellrt-operator"));
        let uid = nix::unistd::getuid().as_raw();
        assert_eq!(
            operator_path_of(uid).parent(),
            path_of(uid).parent(),
            "same parent"
        );
    }

    #[test]
    fn a_directory_of_another_user_is_refused() {
        if !nix::unistd::getuid().is_root() {
            eprintln!("SKIPPED a_directory_of_another_user_is_refused: needs root to chown");
            return;
        }
        let base = tempfile::tempdir().unwrap();
        let dir = base.path().join("theirs");
        std::fs::DirBuilder::new().mode(0o700).create(&dir).unwrap();
        nix::unistd::chown(&dir, Some(nix::unistd::Uid::from_raw(65534)), None).unwrap();
        let e = create_owned(&dir, PRIVATE_DIR_MODE).unwrap_err();
        assert!(e.to_string().contains("uid 65534"), "{e}");
    }
}
