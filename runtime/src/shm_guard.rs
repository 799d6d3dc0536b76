//! The user's iceoryx2 objects in `/dev/shm` kept to the user: their names start with a
//! prefix naming the user's uid, so an object with that prefix owned by another user was
//! planted (a global management object, a service's dynamic config made ahead of the service)
//! to cut the user's operators off their cells. Before a node is made such objects are removed
//! where this user may (root may in the sticky `/dev/shm`) and refused, named, where not.
//! iceoryx2 0.10 creates its global management object (the node id counter) mode 0666 whatever
//! its config says: after a node is made, the user's own are made 0600. A process of another
//! user that opens the object in the moment between its creation and the chmod keeps its
//! access: the guard narrows that window to the first node of a cell, it cannot close it.

use std::os::unix::fs::{MetadataExt, PermissionsExt};
use std::path::{Path, PathBuf};

/// Where Linux keeps POSIX shared-memory objects.
pub const SHM_DIR: &str = "/dev/shm";

/// How iceoryx2 ends the name of its global management object.
const GLOBAL_MGMT_SUFFIX: &str = "global_mgmt";

/// The objects in `dir` whose names start with `prefix` and end with `suffix`, with their
/// owners.
fn objects(dir: &Path, prefix: &str, suffix: &str) -> Vec<(PathBuf, u32)> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    entries
        .flatten()
        .filter(|e| {
            let name = e.file_name();
            let name = name.to_string_lossy();
            name.starts_with(prefix) && name.ends_with(suffix)
        })
        .filter_map(|e| {
            let meta = std::fs::symlink_metadata(e.path()).ok()?;
            Some((e.path(), meta.uid()))
        })
        .collect()
}

/// Why the shared-memory objects of this user's cells cannot be made safe.
#[derive(Debug, thiserror::Error)]
pub enum ShmGuardError {
    /// Another user's object that this user cannot remove.
    #[error("{} is owned by uid {owner}, not by this user (uid {uid}): another user could control this user's cells through it, and it cannot be removed ({source}); remove it as root", path.display())]
    Planted {
        /// The object.
        path: PathBuf,
        /// Its owner.
        owner: u32,
        /// This user.
        uid: u32,
        /// Why it cannot be removed.
        source: std::io::Error,
    },
    /// An own object whose permissions cannot be set.
    #[error("{}: cannot make it private: {source}", path.display())]
    CannotRestrict {
        /// The object.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
}

/// Removes each object with `prefix` in `dir` that `uid` does not own; refuses, naming it, one
/// this user may not remove.
pub fn clear_foreign(dir: &Path, prefix: &str, uid: u32) -> Result<(), ShmGuardError> {
    for (path, owner) in objects(dir, prefix, "") {
        if owner == uid {
            continue;
        }
        match std::fs::remove_file(&path) {
            Ok(()) => tracing::warn!(
                "removed {} (owned by uid {owner}, not by this user, uid {uid}: planted)",
                path.display()
            ),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(source) => {
                return Err(ShmGuardError::Planted {
                    path,
                    owner,
                    uid,
                    source,
                })
            }
        }
    }
    Ok(())
}

/// Makes each global management object with `prefix` in `dir` that `uid` owns readable and
/// writable by its owner only.
pub fn restrict_own(dir: &Path, prefix: &str, uid: u32) -> Result<(), ShmGuardError> {
    for (path, owner) in objects(dir, prefix, GLOBAL_MGMT_SUFFIX) {
        if owner != uid {
            continue;
        }
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o600)).map_err(
            |source| ShmGuardError::CannotRestrict {
                path: path.clone(),
                source,
            },
        )?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_planted_object_is_removed_and_own_ones_are_made_private() {
        let dir = tempfile::tempdir().unwrap();
        let uid = nix::unistd::getuid().as_raw();
        let own = dir
            .path()
            .join("iox2_cellrt_u0_abc_node.0_10_0.global_mgmt");
        std::fs::write(&own, b"").unwrap();
        std::fs::set_permissions(&own, std::fs::Permissions::from_mode(0o666)).unwrap();
        std::fs::write(dir.path().join("iox2_other_node.global_mgmt"), b"").unwrap();
        // Owned by this user: kept, then private.
        clear_foreign(dir.path(), "iox2_cellrt_u0_", uid).unwrap();
        restrict_own(dir.path(), "iox2_cellrt_u0_", uid).unwrap();
        let mode = std::fs::metadata(&own).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o600);
        // Another user's chmod leaves it alone.
        std::fs::set_permissions(&own, std::fs::Permissions::from_mode(0o644)).unwrap();
        restrict_own(dir.path(), "iox2_cellrt_u0_", uid + 1).unwrap();
        let mode = std::fs::metadata(&own).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o644, "another user's object is not touched");
        // Seen from another user (who may remove it here) it was planted: removed; objects of
        // other prefixes stay.
        clear_foreign(dir.path(), "iox2_cellrt_u0_", uid + 1).unwrap();
        assert!(!own.exists());
        assert!(dir.path().join("iox2_other_node.global_mgmt").exists());
    }

    #[test]
    fn a_cell_node_leaves_no_world_writable_object_of_its_user() {
        let _node = crate::services::node("shm-guard-test", "t").unwrap();
        let prefix = format!("iox2_cellrt_u{}_", nix::unistd::getuid().as_raw());
        let objects = objects(Path::new(SHM_DIR), &prefix, GLOBAL_MGMT_SUFFIX);
        assert!(
            !objects.is_empty(),
            "iceoryx2 made no global management object"
        );
        for (path, _) in objects {
            let mode = std::fs::metadata(&path).unwrap().permissions().mode() & 0o777;
            assert_eq!(mode, 0o600, "{}", path.display());
        }
    }
}
