//! Files cellrt writes at a path it is given (recordings, run summaries): a link, a FIFO or a
//! device planted at that path by another user (in `/tmp`, say) must not make a controller
//! running as root overwrite what it points to or hang. The file is opened without following a
//! link at the path and without blocking, and only a regular file of this user with one name
//! is truncated and written.

use std::fs::{File, OpenOptions};
use std::io;
use std::os::unix::fs::{MetadataExt, OpenOptionsExt};
use std::path::Path;

/// Creates or truncates `path` for writing, refusing a link, a non-regular file, a file of
/// another user or one with other names (hard links).
pub fn create(path: &Path) -> io::Result<File> {
    let refuse = |why: String| io::Error::new(io::ErrorKind::InvalidInput, why);
    let file = OpenOptions::new()
        .write(true)
        .create(true)
        .truncate(false)
        .mode(0o644)
        .custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK)
        .open(path)
        .map_err(|e| {
            // A link gives ELOOP, or EACCES in a sticky directory (such as /tmp).
            let link = std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink());
            match e.raw_os_error() {
                _ if link => {
                    refuse("it is a symbolic link (cellrt does not write through links)".into())
                }
                Some(libc::ENXIO) => refuse("it is not a regular file".into()),
                _ => e,
            }
        })?;
    let m = file.metadata()?;
    let uid = nix::unistd::getuid().as_raw();
    if !m.is_file() {
        return Err(refuse("it is not a regular file".into()));
    }
    if m.uid() != uid {
        return Err(refuse(format!(
            "it belongs to uid {}, not to this user (uid {uid})",
            m.uid()
        )));
    }
    if m.nlink() > 1 {
        return Err(refuse(format!("it has {} names (hard links)", m.nlink())));
    }
    file.set_len(0)?;
    Ok(file)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_link_a_fifo_or_a_second_name_is_refused_and_its_target_kept() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("precious");
        std::fs::write(&target, b"precious").unwrap();
        let link = dir.path().join("link.mcap");
        std::os::unix::fs::symlink(&target, &link).unwrap();
        let e = create(&link).unwrap_err().to_string();
        assert!(e.contains("symbolic link"), "{e}");
        let hard = dir.path().join("hard.mcap");
        std::fs::hard_link(&target, &hard).unwrap();
        let e = create(&hard).unwrap_err().to_string();
        assert!(e.contains("2 names"), "{e}");
        assert_eq!(std::fs::read(&target).unwrap(), b"precious");
        let fifo = dir.path().join("fifo.mcap");
        nix::unistd::mkfifo(&fifo, nix::sys::stat::Mode::S_IRWXU).unwrap();
        let e = create(&fifo).unwrap_err().to_string();
        assert!(e.contains("not a regular file"), "{e}");
        // A file of this user is truncated and written.
        let own = dir.path().join("own.mcap");
        std::fs::write(&own, b"old contents").unwrap();
        create(&own).unwrap();
        assert_eq!(std::fs::read(&own).unwrap(), b"");
    }
}
