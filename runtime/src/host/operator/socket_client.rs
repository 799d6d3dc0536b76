//! The client's side of the operator socket ([`super::socket`]): where another user's cell
//! serves it, whether this user may connect, and one request through it. A request is the bytes
//! written before the write side is shut; the answer is `R` and the reply document, or `E` and
//! a one-line error.

use std::io::{Read, Write};
use std::os::unix::fs::{FileTypeExt, MetadataExt, PermissionsExt};
use std::os::unix::net::UnixStream;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// How a cell's operator socket's name ends.
const SOCKET_SUFFIX: &str = ".sock";

/// Tag of an answer carrying the reply document.
pub(super) const TAG_REPLY: u8 = b'R';
/// Tag of an answer carrying an error line.
pub(super) const TAG_ERROR: u8 = b'E';

/// Path of the operator socket of `cell` in the operator directory `dir`.
pub fn socket_path_in(dir: &Path, cell: &str) -> PathBuf {
    dir.join(format!("{cell}{SOCKET_SUFFIX}"))
}

/// Sends `request` through the socket at `path` and returns the reply document; the cell's
/// own error line comes back as an error of kind `Other`.
pub fn exchange(path: &Path, request: &[u8], timeout: Duration) -> std::io::Result<Vec<u8>> {
    let mut stream = UnixStream::connect(path)?;
    stream.set_read_timeout(Some(timeout))?;
    stream.set_write_timeout(Some(timeout))?;
    stream.write_all(request)?;
    stream.shutdown(std::net::Shutdown::Write)?;
    let mut answer = Vec::new();
    stream.read_to_end(&mut answer)?;
    match answer.split_first() {
        Some((&TAG_REPLY, doc)) => Ok(doc.to_vec()),
        Some((&TAG_ERROR, line)) => Err(std::io::Error::other(
            String::from_utf8_lossy(line).into_owned(),
        )),
        _ => Err(std::io::Error::other(format!(
            "{}: closed without an answer",
            path.display()
        ))),
    }
}

/// What a look for another user's cell found.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Found {
    /// Its socket accepts this user: request through it.
    Reachable(PathBuf),
    /// It runs, but this user may not connect (the one-line reason names cell and owner).
    NotPermitted(String),
}

/// Looks for a running cell named `cell` of another user: the socket in that user's runtime
/// directory, owned by that user, that a controller serves.
pub fn find_foreign(cell: &str) -> Option<Found> {
    if cell.is_empty() || cell.contains('/') || cell.starts_with('.') {
        return None;
    }
    let me = nix::unistd::getuid().as_raw();
    for (owner, dir) in other_users_dirs(me) {
        let path = socket_path_in(&dir, cell);
        let Ok(m) = std::fs::symlink_metadata(&path) else {
            continue;
        };
        if !m.file_type().is_socket() || m.uid() != owner {
            continue;
        }
        match UnixStream::connect(&path) {
            Ok(_) => return Some(Found::Reachable(path)),
            Err(e) if e.kind() == std::io::ErrorKind::PermissionDenied => {
                return Some(Found::NotPermitted(not_permitted(cell, owner, &m)))
            }
            Err(_) => continue,
        }
    }
    None
}

/// The operator directories other users' cells may use, with their users.
fn other_users_dirs(me: u32) -> Vec<(u32, PathBuf)> {
    let mut dirs = Vec::new();
    if me != 0 {
        dirs.push((0, crate::runtime_dir::operator_path_of(0)));
    }
    let uids_in = |dir: &Path, strip: &dyn Fn(&str) -> Option<u32>| -> Vec<u32> {
        std::fs::read_dir(dir)
            .map(|entries| {
                entries
                    .flatten()
                    .filter_map(|e| strip(&e.file_name().to_string_lossy()))
                    .collect()
            })
            .unwrap_or_default()
    };
    let mut uids = uids_in(Path::new("/run/user"), &|n| n.parse().ok());
    uids.extend(uids_in(&std::env::temp_dir(), &|n| {
        n.strip_prefix("cellrt-u")?
            .strip_suffix("-operator")?
            .parse()
            .ok()
    }));
    uids.sort_unstable();
    uids.dedup();
    for uid in uids.into_iter().filter(|u| *u != me && *u != 0) {
        dirs.push((uid, crate::runtime_dir::operator_path_of(uid)));
    }
    dirs
}

/// "cell 'NAME' runs as USER (uid N); USER (uid M) is not permitted to command it: …".
fn not_permitted(cell: &str, owner: u32, socket: &std::fs::Metadata) -> String {
    let user = |uid: u32| {
        nix::unistd::User::from_uid(nix::unistd::Uid::from_raw(uid))
            .ok()
            .flatten()
            .map_or_else(
                || format!("uid {uid}"),
                |u| format!("{} (uid {uid})", u.name),
            )
    };
    let who = if socket.permissions().mode() & 0o060 == 0o060 {
        let group = nix::unistd::Group::from_gid(nix::unistd::Gid::from_raw(socket.gid()))
            .ok()
            .flatten()
            .map_or_else(|| format!("gid {}", socket.gid()), |g| g.name);
        format!("only its user and the members of its operator group '{group}' may")
    } else {
        "only its user may (it has no [operator] group)".to_string()
    };
    format!(
        "cell '{cell}' runs as {}; {} is not permitted to command it: {who}",
        user(owner),
        user(nix::unistd::getuid().as_raw())
    )
}
