//! The directory of cellrt's runtime files (cell locks, the iceoryx2 root) for the current
//! user: private to the user, never a shared world-writable place where another user could
//! pre-create, replace or link the files. Root uses `/run/cellrt`; other users
//! `/run/user/UID/cellrt` where their systemd runtime directory exists, else `/tmp/cellrt-uUID`.
//! The directory is created mode 0700 and refused unless it is a real directory owned by the
//! user that no one else may enter.

use std::os::unix::fs::{DirBuilderExt, MetadataExt, PermissionsExt};
use std::path::{Path, PathBuf};

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
    #[error("the runtime directory {path} is not safe: {reason} (remove it; cellrt creates it private to its user)")]
    Unsafe {
        /// The directory.
        path: PathBuf,
        /// What is wrong: a link, another owner, a group or other access.
        reason: String,
    },
}

/// The runtime directory of the current user (not created; see [`ensure`]).
pub fn path() -> PathBuf {
    let uid = nix::unistd::getuid().as_raw();
    if uid == 0 {
        return PathBuf::from("/run/cellrt");
    }
    let user_run = PathBuf::from(format!("/run/user/{uid}"));
    match std::fs::symlink_metadata(&user_run) {
        Ok(m) if m.is_dir() && m.uid() == uid => user_run.join("cellrt"),
        _ => std::env::temp_dir().join(format!("cellrt-u{uid}")),
    }
}

/// The runtime directory, created private if absent and checked if present.
pub fn ensure() -> Result<PathBuf, RuntimeDirError> {
    let dir = path();
    create_private(&dir)?;
    Ok(dir)
}

/// Creates `dir` mode 0700 (if absent) and checks that it is a directory, not a link, owned by
/// this user, with no group or other access.
pub fn create_private(dir: &Path) -> Result<(), RuntimeDirError> {
    match std::fs::DirBuilder::new().mode(0o700).create(dir) {
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
    let mode = m.permissions().mode() & 0o777;
    if mode & 0o077 != 0 {
        return Err(unsafe_because(format!("its mode is {mode:03o}, not 700")));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_directory_is_created_private_and_a_shared_one_is_refused() {
        let base = tempfile::tempdir().unwrap();
        let dir = base.path().join("rt");
        create_private(&dir).unwrap();
        let mode = std::fs::metadata(&dir).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o700);
        create_private(&dir).unwrap();
        // Opened up to the group: refused, with the mode named.
        std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o770)).unwrap();
        let e = create_private(&dir).unwrap_err();
        assert!(e.to_string().contains("770"), "{e}");
        // A symbolic link planted where the directory belongs: refused.
        let link = base.path().join("link");
        std::os::unix::fs::symlink(&dir, &link).unwrap();
        let e = create_private(&link).unwrap_err();
        assert!(e.to_string().contains("symbolic link"), "{e}");
        // A file: refused.
        let file = base.path().join("file");
        std::fs::write(&file, b"x").unwrap();
        assert!(create_private(&file)
            .unwrap_err()
            .to_string()
            .contains("not a directory"));
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
        let e = create_private(&dir).unwrap_err();
        assert!(e.to_string().contains("uid 65534"), "{e}");
    }
}
