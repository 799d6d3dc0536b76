//! The live view: a running cell's records served over the Foxglove WebSocket protocol
//! (`foxglove.websocket.v1`, by the Foxglove SDK's server), so Foxglove, PlotJuggler or any
//! client of that protocol can watch it — the recording's topics with their protobuf schemas
//! (`/cell/cycle`, `/cell/events`, `/axis/<name>`), fed by the recorder thread as it encodes each
//! record, never by the RT thread.
//!
//! Nothing a viewer does can slow the cell: the recorder offers each message to a bounded queue
//! and never waits (a full queue counts the message as dropped); a feeder thread logs them to
//! the server, which keeps a bounded backlog per viewer and drops the oldest messages of one
//! that does not keep up.

use std::collections::HashMap;
use std::net::SocketAddr;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Duration;

use crossbeam::queue::ArrayQueue;
use foxglove::{ChannelBuilder, Context, PartialMetadata, RawChannel, Schema, WebSocketServer};

use crate::host::record::{channel_ids, channel_specs, proto};
use cellrt_config::CellConfig;

/// Messages the queue between the recorder and the feeder holds (about a second of a 16-axis
/// 1 kHz cell).
pub const LIVE_QUEUE: usize = 32_768;
/// Messages the server keeps per viewer before it drops a slow viewer's oldest.
pub const VIEWER_BACKLOG: usize = 16_384;

/// One encoded record.
struct LiveMessage {
    channel: u16,
    log_time: u64,
    data: Vec<u8>,
}

/// The recorder's end: offers messages, never waits.
#[derive(Clone)]
pub struct LiveFeed {
    queue: Arc<ArrayQueue<LiveMessage>>,
    dropped: Arc<AtomicU64>,
    sent: Arc<AtomicU64>,
}

impl LiveFeed {
    /// Offers the message `data` of MCAP channel `channel`; dropped (and counted) when the
    /// queue is full.
    pub fn offer(&self, channel: u16, log_time: u64, data: &[u8]) {
        let m = LiveMessage {
            channel,
            log_time,
            data: data.to_vec(),
        };
        if self.queue.push(m).is_err() {
            self.dropped.fetch_add(1, Ordering::Relaxed);
        }
    }

    /// Messages dropped because the feeder did not keep up.
    pub fn dropped(&self) -> u64 {
        self.dropped.load(Ordering::Relaxed)
    }

    /// Messages handed to the server.
    pub fn sent(&self) -> u64 {
        self.sent.load(Ordering::Relaxed)
    }
}

/// Why the live view could not start.
#[derive(Debug, thiserror::Error)]
pub enum LiveError {
    /// The server could not listen.
    #[error("live view on {addr}: {reason}")]
    Listen {
        /// The address.
        addr: SocketAddr,
        /// Why.
        reason: String,
    },
    /// A channel could not be made.
    #[error("live view channel {topic}: {reason}")]
    Channel {
        /// Its topic.
        topic: String,
        /// Why.
        reason: String,
    },
}

/// The running live view: server and feeder; stopped on drop.
pub struct LiveServer {
    /// Where it listens.
    pub addr: SocketAddr,
    feed: LiveFeed,
    stop: Arc<AtomicBool>,
    feeder: Option<JoinHandle<()>>,
    server: Option<foxglove::WebSocketServerHandle>,
    /// The SDK's context of the channels (the server and channels only refer to it).
    _context: Arc<Context>,
}

impl LiveServer {
    /// Serves `cell`'s topics on `addr`.
    pub fn start(cell: &CellConfig, addr: SocketAddr) -> Result<LiveServer, LiveError> {
        let ctx = Context::new();
        let ids = channel_ids(cell).map_err(|e| LiveError::Channel {
            topic: "(all)".into(),
            reason: e.to_string(),
        })?;
        let mut channels: HashMap<u16, Arc<RawChannel>> = HashMap::new();
        for (id, spec) in ids.iter().zip(channel_specs(cell)) {
            let schema = Schema::new(spec.schema, "protobuf", proto::FILE_DESCRIPTOR_SET);
            let channel = ChannelBuilder::new(&spec.topic)
                .context(&ctx)
                .message_encoding("protobuf")
                .schema(schema)
                .metadata(spec.metadata.clone())
                .build_raw()
                .map_err(|e| LiveError::Channel {
                    topic: spec.topic.clone(),
                    reason: e.to_string(),
                })?;
            channels.insert(*id, channel);
        }
        let server = WebSocketServer::new()
            .name(format!("cellrt {}", cell.name))
            .context(&ctx)
            .bind(addr.ip().to_string(), addr.port())
            .message_backlog_size(VIEWER_BACKLOG)
            .start_blocking()
            .map_err(|e| LiveError::Listen {
                addr,
                reason: e.to_string(),
            })?;
        let addr = SocketAddr::new(addr.ip(), server.port());
        let feed = LiveFeed {
            queue: Arc::new(ArrayQueue::new(LIVE_QUEUE)),
            dropped: Arc::default(),
            sent: Arc::default(),
        };
        let stop = Arc::new(AtomicBool::new(false));
        let (f, s) = (feed.clone(), stop.clone());
        let feeder = std::thread::Builder::new()
            .name("cellrt-live".into())
            .spawn(move || feed_loop(&f, &channels, &s))
            .map_err(|e| LiveError::Listen {
                addr,
                reason: format!("cannot start the feeder: {e}"),
            })?;
        Ok(LiveServer {
            addr,
            feed,
            stop,
            feeder: Some(feeder),
            server: Some(server),
            _context: ctx,
        })
    }

    /// The recorder's end.
    pub fn feed(&self) -> LiveFeed {
        self.feed.clone()
    }
}

impl Drop for LiveServer {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Release);
        if let Some(t) = self.feeder.take() {
            let _ = t.join();
        }
        if let Some(s) = self.server.take() {
            let _ = s.stop();
        }
    }
}

/// Logs queued messages to their channels until stopped.
fn feed_loop(feed: &LiveFeed, channels: &HashMap<u16, Arc<RawChannel>>, stop: &AtomicBool) {
    while !stop.load(Ordering::Acquire) {
        let mut any = false;
        while let Some(m) = feed.queue.pop() {
            any = true;
            if let Some(c) = channels.get(&m.channel) {
                c.log_with_meta(
                    &m.data,
                    PartialMetadata {
                        log_time: Some(m.log_time),
                    },
                );
                feed.sent.fetch_add(1, Ordering::Relaxed);
            }
        }
        if !any {
            std::thread::sleep(Duration::from_millis(2));
        }
    }
}
