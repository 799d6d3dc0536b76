//! The operator socket: how users other than the cell's own reach its operator service. A
//! Unix socket `NAME.sock` in the operator directory of the cell's user
//! ([`crate::runtime_dir::operator_path_of`]), mode 0600 (only that
//! user and root may connect), or 0660 and owned by the `[operator] group` (its members may
//! too): the kernel checks the connecting user against the socket's mode. The controller relays
//! each request to the operator service over iceoryx2 as its own user and writes the reply
//! back, so the iceoryx2 resources stay private to the cell's user. A request is the bytes a
//! client writes before it shuts its side; the answer is `R` and the reply document, or `E`
//! and a one-line error.

use std::io::{Read, Write};
use std::os::unix::fs::{DirBuilderExt, PermissionsExt};
use std::os::unix::net::{UnixListener, UnixStream};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{mpsc, Arc};
use std::thread::JoinHandle;
use std::time::Duration;

use super::client::{OperatorClient, REPLY_TIMEOUT};
pub use super::socket_client::{exchange, find_foreign, socket_path_in, Found};
use super::socket_client::{TAG_ERROR, TAG_REPLY};
use crate::services::MAX_OPERATOR_REQUEST_BYTES;
use cellrt_config::OperatorConfig;

/// Connections served at once; more are closed at once (a client holding one open cannot
/// keep the others out).
const MAX_CONNECTIONS: usize = 16;

/// How long a connection may take to send its request or read its answer.
const CONNECTION_TIMEOUT: Duration = Duration::from_secs(2);

/// How often the accepting thread looks at its stop flag.
const ACCEPT_POLL_MS: i32 = 100;

/// Why the operator socket is not served.
#[derive(Debug, thiserror::Error)]
pub enum SocketError {
    /// The user's operator directory cannot be made.
    #[error(transparent)]
    Dir(#[from] crate::runtime_dir::RuntimeDirError),
    /// The private directory the socket is bound in cannot be made.
    #[error("cannot create {}: {source}", .dir.display())]
    Staging {
        /// The directory.
        dir: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The socket cannot be bound.
    #[error("cannot bind {}: {source}", .path.display())]
    Bind {
        /// The socket's path.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The socket cannot be given to the operator group.
    #[error(
        "operator.group: cannot give the operator socket to group '{group}': {source} \
         (the cell's user must be root or a member of it)"
    )]
    Group {
        /// The group's name.
        group: String,
        /// Why.
        source: nix::Error,
    },
    /// The socket's mode, place or blocking cannot be set.
    #[error("{}: {source}", .path.display())]
    Socket {
        /// The socket's path.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The relay thread cannot be started.
    #[error("cannot start the operator socket relay: {0}")]
    Relay(#[source] std::io::Error),
    /// The accepting thread cannot be started.
    #[error("cannot start the operator socket: {0}")]
    Accept(#[source] std::io::Error),
}

/// A request waiting for the relay, with where its answer goes.
type Relayed = (Vec<u8>, mpsc::Sender<Vec<u8>>);

/// The served socket; removed and its threads ended on drop.
pub struct OperatorSocket {
    path: PathBuf,
    stop: Arc<AtomicBool>,
    accept: Option<JoinHandle<()>>,
}

impl OperatorSocket {
    /// Creates the socket of `cell` in the user's operator directory (replacing one left by a
    /// killed controller; the caller holds the cell lock) with the mode `operator` asks for,
    /// and starts serving it.
    pub fn serve(cell: &str, operator: &OperatorConfig) -> Result<OperatorSocket, SocketError> {
        let dir = crate::runtime_dir::ensure_operator()?;
        let path = socket_path_in(&dir, cell);
        let listener = bind_with_mode(&dir, &path, operator)?;
        listener
            .set_nonblocking(true)
            .map_err(|source| socket_error(&path, source))?;
        let stop = Arc::new(AtomicBool::new(false));
        let (to_relay, relayed) = mpsc::sync_channel::<Relayed>(MAX_CONNECTIONS);
        let cell_name = cell.to_string();
        std::thread::Builder::new()
            .name("cellrt-op-relay".into())
            .spawn(move || relay(&cell_name, &relayed))
            .map_err(SocketError::Relay)?;
        let stop2 = stop.clone();
        let accept = std::thread::Builder::new()
            .name("cellrt-op-socket".into())
            .spawn(move || accept_loop(&listener, &stop2, &to_relay))
            .map_err(SocketError::Accept)?;
        Ok(OperatorSocket {
            path,
            stop,
            accept: Some(accept),
        })
    }
}

impl Drop for OperatorSocket {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.path);
        self.stop.store(true, Ordering::Release);
        if let Some(a) = self.accept.take() {
            let _ = a.join();
        }
    }
}

/// Binds the socket in a staging directory only this user may enter, gives it its mode and
/// group there, and renames it into place: it is never reachable with a wider mode.
fn bind_with_mode(
    dir: &Path,
    path: &Path,
    operator: &OperatorConfig,
) -> Result<UnixListener, SocketError> {
    // One per call: cells of one process (tests) may start at once.
    static STAGED: AtomicUsize = AtomicUsize::new(0);
    let staging = dir.join(format!(
        ".staging-{}-{}",
        std::process::id(),
        STAGED.fetch_add(1, Ordering::Relaxed)
    ));
    let _ = std::fs::remove_dir_all(&staging);
    std::fs::DirBuilder::new()
        .mode(0o700)
        .create(&staging)
        .map_err(|source| SocketError::Staging {
            dir: staging.clone(),
            source,
        })?;
    let tmp = staging.join("s");
    let result = (|| {
        let listener = UnixListener::bind(&tmp).map_err(|source| SocketError::Bind {
            path: path.to_path_buf(),
            source,
        })?;
        let mode = match &operator.group {
            Some(g) => {
                nix::unistd::chown(&tmp, None, Some(nix::unistd::Gid::from_raw(g.gid))).map_err(
                    |source| SocketError::Group {
                        group: g.name.clone(),
                        source,
                    },
                )?;
                0o660
            }
            None => 0o600,
        };
        std::fs::set_permissions(&tmp, std::fs::Permissions::from_mode(mode))
            .map_err(|source| socket_error(path, source))?;
        std::fs::rename(&tmp, path).map_err(|source| socket_error(path, source))?;
        Ok(listener)
    })();
    let _ = std::fs::remove_dir_all(&staging);
    result
}

fn socket_error(path: &Path, source: std::io::Error) -> SocketError {
    SocketError::Socket {
        path: path.to_path_buf(),
        source,
    }
}

/// Accepts connections until `stop`, each served on its own short-lived thread.
fn accept_loop(listener: &UnixListener, stop: &AtomicBool, to_relay: &mpsc::SyncSender<Relayed>) {
    use std::os::fd::AsRawFd;
    let active = Arc::new(AtomicUsize::new(0));
    while !stop.load(Ordering::Acquire) {
        let mut pfd = libc::pollfd {
            fd: listener.as_raw_fd(),
            events: libc::POLLIN,
            revents: 0,
        };
        // SAFETY: one valid pollfd for the duration of the call.
        if unsafe { libc::poll(&mut pfd, 1, ACCEPT_POLL_MS) } <= 0 {
            continue;
        }
        let Ok((stream, _)) = listener.accept() else {
            continue;
        };
        if active.fetch_add(1, Ordering::AcqRel) >= MAX_CONNECTIONS {
            active.fetch_sub(1, Ordering::AcqRel);
            continue;
        }
        let (active2, to_relay) = (active.clone(), to_relay.clone());
        let spawned = std::thread::Builder::new()
            .name("cellrt-op-conn".into())
            .spawn(move || {
                serve_connection(stream, &to_relay);
                active2.fetch_sub(1, Ordering::AcqRel);
            });
        if spawned.is_err() {
            active.fetch_sub(1, Ordering::AcqRel);
        }
    }
}

/// Reads one request (bounded in size and time), has it relayed and writes the answer.
fn serve_connection(mut stream: UnixStream, to_relay: &mpsc::SyncSender<Relayed>) {
    let _ = stream.set_nonblocking(false);
    let _ = stream.set_read_timeout(Some(CONNECTION_TIMEOUT));
    let _ = stream.set_write_timeout(Some(CONNECTION_TIMEOUT));
    let mut request = Vec::new();
    let read = (&mut stream)
        .take(MAX_OPERATOR_REQUEST_BYTES as u64 + 1)
        .read_to_end(&mut request);
    let answer = match read {
        Err(e) => error_answer(&format!("the request was not received: {e}")),
        // A look for the cell (a connect, then nothing): no request.
        Ok(0) => return,
        Ok(_) if request.len() > MAX_OPERATOR_REQUEST_BYTES => error_answer(&format!(
            "request refused: more than {MAX_OPERATOR_REQUEST_BYTES} bytes"
        )),
        Ok(_) => {
            let (tx, rx) = mpsc::channel();
            match to_relay.try_send((request, tx)) {
                Ok(()) => rx
                    .recv_timeout(REPLY_TIMEOUT + CONNECTION_TIMEOUT)
                    .unwrap_or_else(|_| error_answer("the cell did not relay an answer")),
                Err(_) => error_answer("the operator socket is busy; try again"),
            }
        }
    };
    let _ = stream.write_all(&answer);
}

fn error_answer(line: &str) -> Vec<u8> {
    let mut a = vec![TAG_ERROR];
    a.extend_from_slice(line.as_bytes());
    a
}

/// Passes each request to the cell's operator service as the cell's user, one at a time (the
/// service answers each within its bound), until every sender is gone.
fn relay(cell: &str, relayed: &mpsc::Receiver<Relayed>) {
    let mut client: Option<OperatorClient> = None;
    while let Ok((request, answer)) = relayed.recv() {
        if client.is_none() {
            client = OperatorClient::connect_own(cell).ok();
        }
        let reply = match client.as_ref() {
            None => error_answer(&format!("cell '{cell}' serves no operator requests now")),
            Some(c) => match c.exchange(&request, REPLY_TIMEOUT) {
                Ok(doc) => {
                    let mut a = vec![TAG_REPLY];
                    a.extend_from_slice(&doc);
                    a
                }
                Err(e) => {
                    client = None;
                    error_answer(&e.to_string())
                }
            },
        };
        let _ = answer.send(reply);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cellrt_config::OperatorGroup;
    use std::os::unix::fs::{FileTypeExt, MetadataExt};

    fn socket_of(cell: &str) -> PathBuf {
        let uid = nix::unistd::getuid().as_raw();
        socket_path_in(&crate::runtime_dir::operator_path_of(uid), cell)
    }

    #[test]
    fn the_socket_has_its_mode_refuses_big_requests_and_goes_with_the_controller() {
        let cell = format!("socktest-{}", std::process::id());
        let served = OperatorSocket::serve(&cell, &OperatorConfig::default()).unwrap();
        let path = socket_of(&cell);
        let m = std::fs::symlink_metadata(&path).unwrap();
        assert!(m.file_type().is_socket());
        assert_eq!(m.permissions().mode() & 0o777, 0o600);
        // Refused before it reaches the cell, with the bound named.
        let big = vec![b' '; MAX_OPERATOR_REQUEST_BYTES + 1];
        let e = exchange(&path, &big, Duration::from_secs(5)).unwrap_err();
        assert!(e.to_string().contains("more than 65536 bytes"), "{e}");
        drop(served);
        assert!(!path.exists(), "the socket goes with its controller");
    }

    #[test]
    fn a_directory_that_cannot_be_staged_in_is_named() {
        let dir = Path::new("/nonexistent-cellrt-operator-dir");
        let e = bind_with_mode(dir, &dir.join("c.sock"), &OperatorConfig::default()).unwrap_err();
        assert!(matches!(&e, SocketError::Staging { .. }), "{e:?}");
        assert!(
            e.to_string()
                .starts_with("cannot create /nonexistent-cellrt-operator-dir/.staging-"),
            "{e}"
        );
    }

    #[test]
    fn with_an_operator_group_the_socket_is_the_groups() {
        if !nix::unistd::getuid().is_root() {
            eprintln!(
                "SKIPPED with_an_operator_group_the_socket_is_the_groups: needs root to chown"
            );
            return;
        }
        let cell = format!("socktest-group-{}", std::process::id());
        let group = OperatorConfig {
            group: Some(OperatorGroup {
                name: "daemon".into(),
                gid: 1,
            }),
        };
        let served = OperatorSocket::serve(&cell, &group).unwrap();
        let m = std::fs::symlink_metadata(socket_of(&cell)).unwrap();
        assert_eq!((m.permissions().mode() & 0o777, m.gid()), (0o660, 1));
        drop(served);
    }
}
