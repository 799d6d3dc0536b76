//! iceoryx2's one world-writable shared-memory object kept to the cell's user: iceoryx2 0.10
//! creates its global management object (`/dev/shm/<prefix>…global_mgmt`, the node id counter)
//! mode 0666 whatever its config says, so another local user could overwrite it and cut the
//! user's operators off their cell. Before a node is made, such an object owned by another user
//! is refused (it was planted); after, the user's own are made 0600. A process of another user
//! that opens the object in the moment between its creation and the chmod keeps its access:
//! the guard narrows that window to the first node of a cell, it cannot close it.

use std::os::unix::fs::{MetadataExt, PermissionsExt};
use std::path::{Path, PathBuf};

/// Where Linux keeps POSIX shared-memory objects.
pub const SHM_DIR: &str = "/dev/shm";

/// How iceoryx2 ends the name of its global management object.
const GLOBAL_MGMT_SUFFIX: &str = "global_mgmt";

/// The global management objects in `dir` whose names start with `prefix`, with their owners.
fn global_mgmt_objects(dir: &Path, prefix: &str) -> Vec<(PathBuf, u32)> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    entries
        .flatten()
        .filter(|e| {
            let name = e.file_name();
            let name = name.to_string_lossy();
            name.starts_with(prefix) && name.ends_with(GLOBAL_MGMT_SUFFIX)
        })
        .filter_map(|e| {
            let meta = std::fs::symlink_metadata(e.path()).ok()?;
            Some((e.path(), meta.uid()))
        })
        .collect()
}

/// Refuses a global management object with `prefix` in `dir` that `uid` does not own.
pub fn refuse_foreign(dir: &Path, prefix: &str, uid: u32) -> Result<(), String> {
    match global_mgmt_objects(dir, prefix)
        .into_iter()
        .find(|(_, owner)| *owner != uid)
    {
        Some((path, owner)) => Err(format!(
            "{} is owned by uid {owner}, not by this user (uid {uid}): another user could \
             control this user's cells through it; remove it",
            path.display()
        )),
        None => Ok(()),
    }
}

/// Makes each global management object with `prefix` in `dir` that `uid` owns readable and
/// writable by its owner only.
pub fn restrict_own(dir: &Path, prefix: &str, uid: u32) -> Result<(), String> {
    for (path, owner) in global_mgmt_objects(dir, prefix) {
        if owner != uid {
            continue;
        }
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o600))
            .map_err(|e| format!("{}: cannot make it private: {e}", path.display()))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_planted_object_is_refused_and_own_ones_are_made_private() {
        let dir = tempfile::tempdir().unwrap();
        let uid = nix::unistd::getuid().as_raw();
        let own = dir
            .path()
            .join("iox2_cellrt_u0_abc_node.0_10_0.global_mgmt");
        std::fs::write(&own, b"").unwrap();
        std::fs::set_permissions(&own, std::fs::Permissions::from_mode(0o666)).unwrap();
        std::fs::write(dir.path().join("iox2_other_node.global_mgmt"), b"").unwrap();
        // Owned by this user: accepted, then private.
        assert_eq!(refuse_foreign(dir.path(), "iox2_cellrt_u0_", uid), Ok(()));
        restrict_own(dir.path(), "iox2_cellrt_u0_", uid).unwrap();
        let mode = std::fs::metadata(&own).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o600);
        // Seen from another user it is foreign: refused, named, and left alone.
        let e = refuse_foreign(dir.path(), "iox2_cellrt_u0_", uid + 1).unwrap_err();
        assert!(
            e.contains(&own.display().to_string()) && e.contains(&format!("uid {uid}")),
            "{e}"
        );
        std::fs::set_permissions(&own, std::fs::Permissions::from_mode(0o644)).unwrap();
        restrict_own(dir.path(), "iox2_cellrt_u0_", uid + 1).unwrap();
        let mode = std::fs::metadata(&own).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o644, "another user's object is not touched");
    }

    #[test]
    fn a_cell_node_leaves_no_world_writable_object_of_its_user() {
        let _node = crate::services::node("shm-guard-test", "t").unwrap();
        let prefix = format!("iox2_cellrt_u{}_", nix::unistd::getuid().as_raw());
        let objects = global_mgmt_objects(Path::new(SHM_DIR), &prefix);
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
