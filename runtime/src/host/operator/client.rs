//! The operator service's client end (the CLI and any other process): finds the running cell,
//! sends a request and waits for its reply (over iceoryx2 to a cell of this user, through the
//! operator socket to another user's).

use std::time::{Duration, Instant};

use iceoryx2::node::{NodeState, NodeView};
use iceoryx2::prelude::*;

use super::socket_client::{self as socket, Found};
use super::wire::{self, Reply, Request};
use crate::services::{self, OperatorClientPort};

/// How long a request waits for its reply by default.
pub const REPLY_TIMEOUT: Duration = Duration::from_secs(5);

/// First pause between looks for the reply; each further one doubles, up to
/// [`LAST_REPLY_POLL`], so a hundred waiting clients do not keep the CPUs busy.
const FIRST_REPLY_POLL: Duration = Duration::from_micros(20);
/// Longest pause between looks for the reply.
const LAST_REPLY_POLL: Duration = Duration::from_millis(1);

/// Why a request got no reply.
#[derive(Debug, thiserror::Error)]
pub enum ClientError {
    /// No cell runs, or not the one named.
    #[error("{0}")]
    NoCell(String),
    /// The cell runs as another user who does not let this one command it.
    #[error("{0}")]
    NotPermitted(String),
    /// The iceoryx2 side failed.
    #[error("operator service: {0}")]
    Service(String),
    /// No reply in time.
    #[error("cell '{cell}' did not answer within {timeout:?}")]
    Timeout {
        /// Cell name.
        cell: String,
        /// How long we waited.
        timeout: Duration,
    },
    /// The reply is not a reply document.
    #[error("cell '{cell}' sent a malformed reply: {detail}")]
    BadReply {
        /// Cell name.
        cell: String,
        /// Decoder message.
        detail: String,
    },
}

/// Names of the cells whose planner (the operator service's owner) is alive.
pub fn running_cells() -> Vec<String> {
    let mut cells = Vec::new();
    let _ = Node::<ipc::Service>::list(&services::config(), |state| {
        if let NodeState::Alive(view) = &state {
            if let Some(d) = NodeView::details(view).as_ref() {
                let name = d.name().as_str();
                if let Some(cell) = name
                    .strip_prefix("cellrt-")
                    .and_then(|n| n.strip_suffix("-planner"))
                {
                    if !cells.iter().any(|c| c == cell) {
                        cells.push(cell.to_string());
                    }
                }
            }
        }
        CallbackProgression::Continue
    });
    cells.sort();
    cells
}

/// A connection to one cell's operator service.
pub struct OperatorClient {
    transport: Transport,
    cell: String,
}

/// The iceoryx2 ports of a client of the cell's own user.
struct IpcPorts {
    port: OperatorClientPort,
    wake: iceoryx2::port::notifier::Notifier<ipc::Service>,
    _node: Node<ipc::Service>,
}

/// How requests reach the cell.
enum Transport {
    /// The cell's own user: iceoryx2, directly.
    Ipc(Box<IpcPorts>),
    /// Another user (root, or a member of the cell's operator group): the cell's operator
    /// socket, relayed by its controller.
    Socket(std::path::PathBuf),
}

impl OperatorClient {
    /// Connects to `cell`, or to the only running cell of this user when `None`. A cell of
    /// another user is reached through its operator socket where that user permits it.
    pub fn connect(cell: Option<&str>) -> Result<OperatorClient, ClientError> {
        let running = running_cells();
        let cell = match cell {
            Some(c) if running.iter().any(|r| r == c) => c.to_string(),
            Some(c) => {
                return match socket::find_foreign(c) {
                    Some(Found::Reachable(path)) => Ok(OperatorClient {
                        transport: Transport::Socket(path),
                        cell: c.to_string(),
                    }),
                    Some(Found::NotPermitted(why)) => Err(ClientError::NotPermitted(why)),
                    None => Err(ClientError::NoCell(format!(
                        "no cell named '{}' is running{}",
                        cellrt_config::echo::Echo(c),
                        others(&running)
                    ))),
                }
            }
            None => match running.as_slice() {
                [one] => one.clone(),
                [] => {
                    return Err(ClientError::NoCell(
                        "no cell of this user is running (start one with `cellrt run CONFIG \
                         --no-program`; name another user's cell with --cell)"
                            .into(),
                    ))
                }
                many => {
                    return Err(ClientError::NoCell(format!(
                        "{} cells are running ({}); name one with --cell",
                        many.len(),
                        many.join(", ")
                    )))
                }
            },
        };
        Self::connect_own(&cell)
    }

    /// Connects to `cell` of this user over iceoryx2.
    pub fn connect_own(cell: &str) -> Result<OperatorClient, ClientError> {
        let role = format!("cli-{}", std::process::id());
        let node = services::node(cell, &role).map_err(|e| ClientError::Service(e.to_string()))?;
        let port = services::operator_client(&node, cell)
            .map_err(|e| ClientError::Service(e.to_string()))?;
        let wake = services::operator_wake_notifier(&node, cell)
            .map_err(|e| ClientError::Service(e.to_string()))?;
        Ok(OperatorClient {
            transport: Transport::Ipc(Box::new(IpcPorts {
                port,
                wake,
                _node: node,
            })),
            cell: cell.to_string(),
        })
    }

    /// The cell connected to.
    pub fn cell(&self) -> &str {
        &self.cell
    }

    /// Sends `req` and waits up to `timeout` for the reply.
    pub fn request(&self, req: &Request, timeout: Duration) -> Result<Reply, ClientError> {
        self.request_bytes(&wire::encode(req), timeout)
    }

    /// Sends raw bytes as a request (for tools and tests of malformed payloads).
    pub fn request_bytes(&self, bytes: &[u8], timeout: Duration) -> Result<Reply, ClientError> {
        let doc = self.exchange(bytes, timeout)?;
        serde_json::from_slice(&doc).map_err(|e| ClientError::BadReply {
            cell: self.cell.clone(),
            detail: e.to_string(),
        })
    }

    /// Sends raw bytes as a request and returns the reply document undecoded.
    pub fn exchange(&self, bytes: &[u8], timeout: Duration) -> Result<Vec<u8>, ClientError> {
        match &self.transport {
            Transport::Ipc(p) => self.exchange_ipc(&p.port, &p.wake, bytes, timeout),
            Transport::Socket(path) => {
                socket::exchange(path, bytes, timeout).map_err(|e| match e.kind() {
                    std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut => {
                        ClientError::Timeout {
                            cell: self.cell.clone(),
                            timeout,
                        }
                    }
                    std::io::ErrorKind::Other => ClientError::Service(e.to_string()),
                    _ => ClientError::Service(format!("operator socket {}: {e}", path.display())),
                })
            }
        }
    }

    fn exchange_ipc(
        &self,
        port: &OperatorClientPort,
        wake: &iceoryx2::port::notifier::Notifier<ipc::Service>,
        bytes: &[u8],
        timeout: Duration,
    ) -> Result<Vec<u8>, ClientError> {
        let service = |e: String| ClientError::Service(e);
        let pending = port
            .loan_slice_uninit(bytes.len().max(1))
            .map_err(|e| service(format!("{e:?}")))?
            .write_from_fn(|i| bytes.get(i).copied().unwrap_or(b' '))
            .send()
            .map_err(|e| service(format!("{e:?}")))?;
        // Without the wake-up the server still answers at its next poll (≤ 1 ms).
        let _ = wake.notify();
        let end = Instant::now() + timeout;
        let mut pause = FIRST_REPLY_POLL;
        loop {
            match pending.receive() {
                Ok(Some(r)) => return Ok(r.payload().to_vec()),
                Ok(None) => {}
                Err(e) => return Err(service(format!("{e:?}"))),
            }
            if Instant::now() >= end {
                return Err(ClientError::Timeout {
                    cell: self.cell.clone(),
                    timeout,
                });
            }
            std::thread::sleep(pause);
            pause = (pause * 2).min(LAST_REPLY_POLL);
        }
    }
}

fn others(running: &[String]) -> String {
    if running.is_empty() {
        String::new()
    } else {
        format!(" (running: {})", running.join(", "))
    }
}
