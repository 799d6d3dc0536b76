//! The recorder thread: drains cycle, axis and event records from the hand-off queues and writes
//! them to a chunked, compressed, indexed MCAP file. It never runs on the RT thread.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufWriter, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use mcap::records::{MessageHeader, Metadata};
use mcap::{Attachment, WriteOptions, Writer};
use prost::Message;
use serde::Serialize;

use super::capture::Capturer;
pub use super::describe::describe_event;
use super::proto;
use super::topics::*;
use crate::config::capture::Quantity;
use crate::config::{CellConfig, Compression};
use crate::handoff::{AxisRecord, CycleRecord, EventKind, EventRecord, HostEnd, NO_AXIS};
use crate::host::live::LiveFeed;
use crate::rt::clock::realtime_offset_ns;
use crate::rt::executive::fsa_index;

/// Chunks one file holds at most before the recording rotates to its next part: the MCAP
/// writer keeps an index entry of every chunk (about 50 bytes per channel) in memory for the
/// file's summary, so an endless file would grow the recorder without bound. At the default
/// `flush_ms` of 200 a file spans about 7 minutes; with 16 axes its index holds about 2 MiB.
pub const MAX_CHUNKS_PER_FILE: u64 = 2048;

/// Event lines the run's summary keeps (the first ones, about 1 MiB): `events` counts every
/// event and the recording holds them all.
pub const EVENT_LOG_LINES: usize = 10_000;

/// Bytes an MCAP Message record adds to its payload inside a chunk (opcode, length, channel,
/// sequence, log and publish time).
const MESSAGE_RECORD_OVERHEAD: u64 = 31;

/// Recording failed.
#[derive(Debug, thiserror::Error)]
pub enum RecorderError {
    /// The file could not be created.
    #[error("cannot create recording {path}: {source}")]
    Create {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The MCAP writer failed.
    #[error("recording {path}: {source}")]
    Mcap {
        /// The file.
        path: PathBuf,
        /// Why.
        source: mcap::McapError,
    },
    /// The recorder thread panicked.
    #[error("recorder thread failed")]
    Thread,
}

/// What was recorded.
#[derive(Debug, Clone, Default, Serialize)]
pub struct RecordingInfo {
    /// The (first) MCAP file, if recording was on.
    pub path: Option<PathBuf>,
    /// Every file written, in order (more than one when the recording rotated).
    pub files: Vec<PathBuf>,
    /// Size of all files, bytes.
    pub bytes: u64,
    /// Cycle messages written.
    pub cycle_messages: u64,
    /// Axis messages written.
    pub axis_messages: u64,
    /// Events seen (recorded or not).
    pub events: u64,
    /// The first [`EVENT_LOG_LINES`] events, as text lines `cycle N: kind [axis]: detail`.
    pub event_log: Vec<String>,
    /// Why and where the recording stopped before the run ended (a full disk, an I/O error):
    /// the cell went on without it; the file holds the records up to its last closed chunk.
    pub stopped: Option<String>,
}

/// Handle of the running recorder thread.
pub struct Recorder {
    stop: Arc<AtomicBool>,
    handle: JoinHandle<Result<RecordingInfo, RecorderError>>,
}

/// The channel ids of a cell's recording (the same in every file of the cell).
#[derive(Debug, Clone)]
pub(super) struct Channels {
    cycle: u16,
    events: u16,
    axes: Vec<u16>,
}

/// A file that counts the bytes written to it (for rotation by size).
pub(super) struct CountingFile {
    file: BufWriter<File>,
    pos: u64,
    /// Bytes in the file so far, shared with the [`Sink`].
    len: Arc<AtomicU64>,
}

impl Write for CountingFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = self.file.write(buf)?;
        self.pos += n as u64;
        self.len.fetch_max(self.pos, Ordering::Relaxed);
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.file.flush()
    }
}

impl Seek for CountingFile {
    fn seek(&mut self, to: SeekFrom) -> std::io::Result<u64> {
        self.pos = self.file.seek(to)?;
        self.len.fetch_max(self.pos, Ordering::Relaxed);
        Ok(self.pos)
    }
}

pub(super) struct Sink {
    pub(super) writer: Writer<CountingFile>,
    channels: Channels,
    pub(super) path: PathBuf,
    /// Bytes written to the file so far.
    len: Arc<AtomicU64>,
    /// When the open chunk was last closed and the file flushed.
    last_flush: Instant,
    /// Deadline of the first cycle in this file (for rotation by duration).
    first_deadline: Option<u64>,
    /// Chunks closed in this file so far (by flush or by size), for [`MAX_CHUNKS_PER_FILE`].
    chunks: u64,
    /// Uncompressed bytes in the open chunk.
    chunk_bytes: u64,
    /// Target chunk size, bytes.
    chunk_size: u64,
}

impl Sink {
    fn writer_len(&self) -> u64 {
        self.len.load(Ordering::Relaxed)
    }

    /// Counts a message of `payload` bytes into the open chunk; the writer closes the chunk
    /// once it reaches the chunk size.
    pub(super) fn count_message(&mut self, payload: usize) {
        self.chunk_bytes += payload as u64 + MESSAGE_RECORD_OVERHEAD;
        if self.chunk_bytes >= self.chunk_size {
            self.chunks += 1;
            self.chunk_bytes = 0;
        }
    }

    /// Closes the open chunk and hands everything to the OS: after a crash (even SIGKILL) the
    /// file is readable up to here.
    fn flush(&mut self) -> Result<(), RecorderError> {
        self.last_flush = Instant::now();
        if self.chunk_bytes > 0 {
            self.chunks += 1;
            self.chunk_bytes = 0;
        }
        self.writer.flush().map_err(|source| RecorderError::Mcap {
            path: self.path.clone(),
            source,
        })
    }

    /// Writes the summary and indexes, syncs, and returns the file and its size.
    pub(super) fn finish(mut self) -> Result<(PathBuf, u64), RecorderError> {
        self.writer.finish().map_err(|source| RecorderError::Mcap {
            path: self.path.clone(),
            source,
        })?;
        let file = self.writer.into_inner();
        let io_err = |source| RecorderError::Create {
            path: self.path.clone(),
            source,
        };
        let file = file.file.into_inner().map_err(|e| io_err(e.into_error()))?;
        file.sync_all().map_err(io_err)?;
        let bytes = std::fs::metadata(&self.path).map(|m| m.len()).unwrap_or(0);
        Ok((self.path, bytes))
    }
}

/// Path of part `n` of a rotating recording: `run.mcap`, `run.1.mcap`, `run.2.mcap`, …
pub fn part_path(first: &Path, n: u32) -> PathBuf {
    if n == 0 {
        return first.to_path_buf();
    }
    let stem = first
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "recording".into());
    let ext = first
        .extension()
        .map(|e| e.to_string_lossy().into_owned())
        .unwrap_or_else(|| "mcap".into());
    first.with_file_name(format!("{stem}.{n}.{ext}"))
}

impl Recorder {
    /// Opens `path` (if any) and starts draining `handoff`. Without a path the thread still
    /// drains events (for the summary and the log) and discards per-cycle records.
    pub fn start(
        cell: &CellConfig,
        path: Option<&Path>,
        handoff: Arc<HostEnd>,
    ) -> Result<Recorder, RecorderError> {
        Recorder::start_with_live(cell, path, handoff, None)
    }

    /// [`Recorder::start`], also offering every encoded record to the live view `live`.
    pub fn start_with_live(
        cell: &CellConfig,
        path: Option<&Path>,
        handoff: Arc<HostEnd>,
        live: Option<LiveFeed>,
    ) -> Result<Recorder, RecorderError> {
        let live = match live {
            Some(feed) => {
                let channels = template_channels(cell).map_err(|source| RecorderError::Mcap {
                    path: PathBuf::new(),
                    source,
                })?;
                Some((feed, channels))
            }
            None => None,
        };
        let (sink, capture) = match (path, &cell.recording.capture) {
            (Some(p), Some(c)) => {
                let channels = template_channels(cell).map_err(|source| RecorderError::Mcap {
                    path: p.to_path_buf(),
                    source,
                })?;
                handoff.arm_capture();
                (None, Some(Capturer::new(cell, c.clone(), p, channels)))
            }
            (Some(p), None) => (Some(open(cell, p)?), None),
            (None, _) => (None, None),
        };
        let stop = Arc::new(AtomicBool::new(false));
        let stop2 = stop.clone();
        let cell = cell.clone();
        let handle = std::thread::Builder::new()
            .name("cellrt-recorder".into())
            .spawn(move || drain_loop(&cell, sink, capture, live, &handoff, &stop2))
            .map_err(|e| RecorderError::Create {
                path: path.map(Path::to_path_buf).unwrap_or_default(),
                source: e,
            })?;
        Ok(Recorder { stop, handle })
    }

    /// Drains what is left, finishes the file (summary, indexes) and returns what was written.
    pub fn finish(self) -> Result<RecordingInfo, RecorderError> {
        self.stop.store(true, Ordering::Release);
        self.handle.join().map_err(|_| RecorderError::Thread)?
    }
}

/// Creates the MCAP file of `path` with its schemas, channels, the cell's metadata and its
/// configuration file attached, and flushes that header to disk.
pub(super) fn open(cell: &CellConfig, path: &Path) -> Result<Sink, RecorderError> {
    let create_err = |source| RecorderError::Create {
        path: path.to_path_buf(),
        source,
    };
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(create_err)?;
    }
    let file = crate::output_file::create(path).map_err(create_err)?;
    let mcap_err = |source| RecorderError::Mcap {
        path: path.to_path_buf(),
        source,
    };
    let len = Arc::new(AtomicU64::new(0));
    let compression = match cell.recording.compression {
        Compression::Zstd => Some(mcap::Compression::Zstd),
        Compression::Lz4 => Some(mcap::Compression::Lz4),
        Compression::None => None,
    };
    let mut writer = WriteOptions::new()
        .compression(compression)
        .chunk_size(Some(cell.recording.chunk_size))
        .profile("")
        .library(format!("cellrt {}", env!("CARGO_PKG_VERSION")))
        .create(CountingFile {
            file: BufWriter::with_capacity(1 << 20, file),
            pos: 0,
            len: len.clone(),
        })
        .map_err(mcap_err)?;
    let channels = add_channels(&mut writer, cell).map_err(mcap_err)?;
    write_cell_metadata(&mut writer, cell).map_err(mcap_err)?;
    let mut sink = Sink {
        writer,
        channels,
        path: path.to_path_buf(),
        len,
        last_flush: Instant::now(),
        first_deadline: None,
        chunks: 0,
        chunk_bytes: 0,
        chunk_size: cell.recording.chunk_size,
    };
    // Header, schemas, channels, metadata and the configuration reach the disk at once.
    sink.flush()?;
    Ok(sink)
}

/// The channel ids every file of `cell` gets (schemas and channels are added in one order).
fn template_channels(cell: &CellConfig) -> Result<Channels, mcap::McapError> {
    let mut writer = Writer::new(std::io::Cursor::new(Vec::new()))?;
    add_channels(&mut writer, cell)
}

/// The protobuf schemas and the channels: cycle, events, and one per axis (its unit, scaling,
/// drive and mode as channel metadata).
fn add_channels<W: Write + Seek>(
    writer: &mut Writer<W>,
    cell: &CellConfig,
) -> Result<Channels, mcap::McapError> {
    let schema =
        |w: &mut Writer<_>, name| w.add_schema(name, "protobuf", proto::FILE_DESCRIPTOR_SET);
    let cycle_schema = schema(writer, CYCLE_SCHEMA)?;
    let axis_schema = schema(writer, AXIS_SCHEMA)?;
    let event_schema = schema(writer, EVENT_SCHEMA)?;
    let mut ids = Vec::new();
    for spec in channel_specs(cell) {
        let schema = match spec.schema {
            CYCLE_SCHEMA => cycle_schema,
            EVENT_SCHEMA => event_schema,
            _ => axis_schema,
        };
        ids.push(writer.add_channel(schema, &spec.topic, "protobuf", &spec.metadata)?);
    }
    Ok(Channels {
        cycle: ids[0],
        events: ids[1],
        axes: ids[2..].to_vec(),
    })
}

/// A channel of the recording: topic, schema name and metadata.
#[derive(Debug, Clone)]
pub struct ChannelSpec {
    /// Topic.
    pub topic: String,
    /// Schema name (in [`proto::FILE_DESCRIPTOR_SET`]).
    pub schema: &'static str,
    /// Channel metadata (an axis' unit, scaling, drive and mode).
    pub metadata: BTreeMap<String, String>,
}

/// The channels of `cell`'s recording in their one order: cycle, events, one per axis.
pub fn channel_specs(cell: &CellConfig) -> Vec<ChannelSpec> {
    let plain = |topic: &str, schema| ChannelSpec {
        topic: topic.to_string(),
        schema,
        metadata: BTreeMap::new(),
    };
    let mut specs = vec![
        plain(CYCLE_TOPIC, CYCLE_SCHEMA),
        plain(EVENTS_TOPIC, EVENT_SCHEMA),
    ];
    specs.extend(cell.axes.iter().map(|a| ChannelSpec {
        topic: axis_topic(&a.name),
        schema: AXIS_SCHEMA,
        metadata: BTreeMap::from([
            ("unit".to_string(), a.unit.clone()),
            (
                "counts_per_unit".to_string(),
                a.scaling.counts_per_unit().to_string(),
            ),
            ("drive".to_string(), a.profile.name.to_string()),
            ("mode".to_string(), a.mode.as_str().to_string()),
        ]),
    }));
    specs
}

/// The MCAP channel ids of `cell`'s recording, in [`channel_specs`] order.
pub fn channel_ids(cell: &CellConfig) -> Result<Vec<u16>, mcap::McapError> {
    let c = template_channels(cell)?;
    Ok([c.cycle, c.events].into_iter().chain(c.axes).collect())
}

/// The cell metadata record (cell, cycle time, axes and their limits, software) and the
/// configuration file as an attachment, so a recording explains itself.
fn write_cell_metadata<W: Write + Seek>(
    writer: &mut Writer<W>,
    cell: &CellConfig,
) -> Result<(), mcap::McapError> {
    let mut cell_meta = BTreeMap::from([
        ("cell".to_string(), cell.name.clone()),
        (
            "cycle_time_us".to_string(),
            cell.cycle_time.as_micros().to_string(),
        ),
        ("axes".to_string(), cell.axis_names()),
        (
            "software".to_string(),
            format!("cellrt {}", env!("CARGO_PKG_VERSION")),
        ),
        ("config_file".to_string(), cell.source.display().to_string()),
    ]);
    for a in &cell.axes {
        cell_meta.insert(
            format!("axis.{}", a.name),
            format!(
                "drive={} mode={} unit={} counts_per_unit={} position=[{}, {}] velocity={} acceleration={} jerk={}",
                a.profile.name,
                a.mode.as_str(),
                a.unit,
                a.scaling.counts_per_unit(),
                a.position.min,
                a.position.max,
                a.limits.velocity,
                a.limits.acceleration,
                a.limits.jerk
            ),
        );
    }
    writer.write_metadata(&Metadata {
        name: CELL_METADATA.to_string(),
        metadata: cell_meta,
    })?;
    let now =
        (realtime_offset_ns() + i128::from(crate::rt::clock::MonoTime::now().0)).max(0) as u64;
    writer.attach(&Attachment {
        log_time: now,
        create_time: now,
        name: cell
            .source
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| "cell.toml".into()),
        media_type: "application/toml".to_string(),
        data: std::borrow::Cow::Borrowed(cell.text.as_bytes()),
    })?;
    Ok(())
}

struct Drain<'a> {
    cell: &'a CellConfig,
    sink: Option<Sink>,
    /// Triggered capture instead of `sink`.
    capture: Option<Capturer>,
    /// The live view's feed and the channel ids it knows the records by.
    live: Option<(LiveFeed, Channels)>,
    /// Part number of the open file (rotation).
    part: u32,
    /// Records popped ahead of their cycle record.
    pending_axis: Option<AxisRecord>,
    pending_event: Option<EventRecord>,
    offset: i128,
    seq: u32,
    buf: Vec<u8>,
    info: RecordingInfo,
    /// Monotonic deadline of each recent cycle, to time-stamp axis records and events.
    last_deadline: u64,
    last_cycle: u64,
}

fn drain_loop(
    cell: &CellConfig,
    sink: Option<Sink>,
    capture: Option<Capturer>,
    live: Option<(LiveFeed, Channels)>,
    handoff: &HostEnd,
    stop: &AtomicBool,
) -> Result<RecordingInfo, RecorderError> {
    let mut d = Drain {
        cell,
        sink,
        capture,
        live,
        part: 0,
        pending_axis: None,
        pending_event: None,
        offset: realtime_offset_ns(),
        seq: 0,
        buf: Vec::with_capacity(512),
        info: RecordingInfo::default(),
        last_deadline: 0,
        last_cycle: 0,
    };
    let period = cell.cycle_time.as_nanos();
    let flush_every = Duration::from_millis(cell.recording.flush_ms);
    loop {
        let finishing = stop.load(Ordering::Acquire);
        let mut n = 0usize;
        if handoff.take_capture_request() {
            if let Some(c) = d.capture.as_mut() {
                c.fire(format!("cycle {}: operator request", d.last_cycle));
            }
        }
        // Cycle by cycle: the cycle record (it carries the deadline that time-stamps the rest),
        // then that cycle's axis records (pushed before it) and events, so a file rotates at a
        // cycle boundary and messages are in time order.
        while let Some(c) = handoff.pop_cycle() {
            d.rotate_if_due(&c)?;
            d.cycle(&c, period)?;
            n += 1;
            while let Some(a) = d.pending_axis.take().or_else(|| handoff.pop_axis()) {
                if a.cycle > c.cycle {
                    d.pending_axis = Some(a);
                    break;
                }
                d.axis(&a, period)?;
                n += 1;
            }
            while let Some(e) = d.pending_event.take().or_else(|| handoff.pop_event()) {
                if e.cycle > c.cycle {
                    d.pending_event = Some(e);
                    break;
                }
                handoff.remember_event(&d.event(&e, period)?);
                n += 1;
            }
            d.flush_if_due(flush_every)?;
        }
        // Without a file (or at the end) nothing waits for its cycle record.
        if (d.sink.is_none() && d.capture.is_none() && d.live.is_none()) || finishing {
            while let Some(a) = d.pending_axis.take().or_else(|| handoff.pop_axis()) {
                d.axis(&a, period)?;
                n += 1;
            }
            while let Some(e) = d.pending_event.take().or_else(|| handoff.pop_event()) {
                handoff.remember_event(&d.event(&e, period)?);
                n += 1;
            }
        }
        if finishing && n == 0 {
            break;
        }
        d.flush_if_due(flush_every)?;
        if n == 0 {
            std::thread::sleep(Duration::from_millis(2));
        }
    }
    if let Some(sink) = d.sink.take() {
        d.close(sink)?;
    }
    d.finish_capture();
    Ok(d.info)
}

impl Drain<'_> {
    /// Finishes `sink` and adds it to the files written.
    fn close(&mut self, sink: Sink) -> Result<(), RecorderError> {
        let (path, bytes) = sink.finish()?;
        self.info.bytes += bytes;
        if self.info.path.is_none() {
            self.info.path = Some(path.clone());
        }
        self.info.files.push(path);
        Ok(())
    }

    fn flush_if_due(&mut self, every: Duration) -> Result<(), RecorderError> {
        let flushed = match self.sink.as_mut() {
            Some(sink) if sink.last_flush.elapsed() >= every => sink.flush(),
            _ => Ok(()),
        };
        if let Err(e) = flushed {
            self.stop_recording(e);
        }
        Ok(())
    }

    /// Starts the next file before cycle `c` when the open one is over its size, its duration
    /// or [`MAX_CHUNKS_PER_FILE`].
    fn rotate_if_due(&mut self, c: &CycleRecord) -> Result<(), RecorderError> {
        let rec = &self.cell.recording;
        let Some(sink) = self.sink.as_mut() else {
            return Ok(());
        };
        let first = *sink.first_deadline.get_or_insert(c.deadline_ns);
        let by_size = rec.rotate_bytes.is_some_and(|b| sink.writer_len() >= b);
        let by_time = rec
            .rotate_seconds
            .is_some_and(|s| c.deadline_ns.saturating_sub(first) as f64 >= s * 1e9);
        let by_chunks = sink.chunks >= MAX_CHUNKS_PER_FILE;
        if !(by_size || by_time || by_chunks) {
            return Ok(());
        }
        let first_path = self.info.path.clone().unwrap_or_else(|| sink.path.clone());
        let old = self.sink.take().expect("checked above");
        self.part += 1;
        let next = self
            .close(old)
            .and_then(|()| open(self.cell, &part_path(&first_path, self.part)));
        match next {
            Ok(mut next) => {
                next.first_deadline = Some(c.deadline_ns);
                self.sink = Some(next);
            }
            Err(e) => self.stop_recording(e),
        }
        Ok(())
    }

    fn time_of(&self, cycle: u64, period: u64) -> u64 {
        // Deadline of `cycle`, extrapolated from the latest cycle record.
        let mono =
            self.last_deadline as i128 + (cycle as i128 - self.last_cycle as i128) * period as i128;
        (mono + self.offset).max(0) as u64
    }

    /// The channel ids messages are encoded for: the open file's, or the capture's.
    fn channels(&self) -> Option<&Channels> {
        self.sink
            .as_ref()
            .map(|s| &s.channels)
            .or(self.capture.as_ref().map(|c| &c.channels))
            .or(self.live.as_ref().map(|(_, c)| c))
    }

    /// The open capture's end and the captures written, into the run's recording info.
    fn finish_capture(&mut self) {
        let Some(mut c) = self.capture.take() else {
            return;
        };
        if let Err(e) = c.finish(self.cell, self.last_cycle) {
            self.info.stopped = Some(format!("capture at cycle {}: {e}", self.last_cycle));
        }
        for f in c.files {
            self.info.bytes += std::fs::metadata(&f).map_or(0, |m| m.len());
            self.info.path.get_or_insert_with(|| f.clone());
            self.info.files.push(f);
        }
    }

    fn write(&mut self, channel: u16, log_time: u64) -> Result<(), RecorderError> {
        if let Some((feed, _)) = &self.live {
            feed.offer(channel, log_time, &self.buf);
        }
        if let Some(c) = self.capture.as_mut() {
            if let Err(e) = c.record(channel, log_time, self.last_cycle, &self.buf) {
                // A capture that cannot be written ends the captures, not the cell.
                tracing::error!("capture stopped at cycle {}: {e}", self.last_cycle);
                self.finish_capture();
                self.info.stopped = Some(format!("capture at cycle {}: {e}", self.last_cycle));
            }
            return Ok(());
        }
        let Some(sink) = self.sink.as_mut() else {
            return Ok(());
        };
        self.seq = self.seq.wrapping_add(1);
        sink.count_message(self.buf.len());
        let written = sink
            .writer
            .write_to_known_channel(
                &MessageHeader {
                    channel_id: channel,
                    sequence: self.seq,
                    log_time,
                    publish_time: log_time,
                },
                &self.buf,
            )
            .map_err(|source| RecorderError::Mcap {
                path: sink.path.clone(),
                source,
            });
        if let Err(e) = written {
            self.stop_recording(e);
        }
        Ok(())
    }

    /// Stops recording after `e` (a full disk, an I/O error): the file is finished if it still
    /// can be, the loss goes into the summary, and the cell goes on without a recording.
    fn stop_recording(&mut self, e: RecorderError) {
        let mut why = e.to_string();
        let mut source = std::error::Error::source(&e);
        while let Some(s) = source {
            let text = s.to_string();
            if !why.contains(&text) {
                why = format!("{why}: {text}");
            }
            source = s.source();
        }
        let at = format!("at cycle {}: {why}", self.last_cycle);
        tracing::error!("recording stopped {at}; the cell goes on without it");
        self.info.stopped = Some(at);
        let Some(sink) = self.sink.take() else {
            return;
        };
        let path = sink.path.clone();
        if self.close(sink).is_err() {
            self.info.bytes += std::fs::metadata(&path).map_or(0, |m| m.len());
            self.info.path.get_or_insert_with(|| path.clone());
            self.info.files.push(path);
        }
    }

    fn cycle(&mut self, c: &CycleRecord, period: u64) -> Result<(), RecorderError> {
        self.last_deadline = c.deadline_ns;
        self.last_cycle = c.cycle;
        if let Some(capture) = self.capture.as_mut() {
            if let Err(e) = capture.cycle(self.cell, c.cycle) {
                tracing::error!("capture stopped at cycle {}: {e}", c.cycle);
                self.finish_capture();
                self.info.stopped = Some(format!("capture at cycle {}: {e}", c.cycle));
            }
        }
        let Some(channel) = self.channels().map(|ch| ch.cycle) else {
            return Ok(());
        };
        let msg = proto::CycleStats {
            cycle: c.cycle,
            deadline_ns: c.deadline_ns,
            wakeup_latency_ns: c.wakeup_latency_ns,
            loop_time_ns: c.loop_time_ns,
            overruns: c.overruns,
            cell_state: c.cell_state as i32,
            dropped_records: c.dropped_records,
            dc_phase_error_ns: c.dc_phase_error_ns,
        };
        self.buf.clear();
        msg.encode(&mut self.buf).expect("Vec grows");
        let t = self.time_of(c.cycle, period);
        self.write(channel, t)?;
        self.info.cycle_messages += 1;
        Ok(())
    }

    fn axis(&mut self, a: &AxisRecord, period: u64) -> Result<(), RecorderError> {
        let Some(channel) = self
            .channels()
            .and_then(|ch| ch.axes.get(a.axis as usize).copied())
        else {
            return Ok(());
        };
        let axis = &self.cell.axes[a.axis as usize];
        let s = axis.scaling;
        let msg = proto::AxisCycle {
            cycle: a.cycle,
            setpoint_position: s.to_units(a.setpoint),
            setpoint_velocity: s.to_units(a.setpoint_velocity),
            actual_position: s.to_units(f64::from(a.position_actual)),
            actual_velocity: s.to_units(axis.drive_units.velocity_from_drive(a.velocity_actual)),
            following_error: s.to_units(f64::from(a.following_error)),
            setpoint_counts: a.target_position,
            actual_position_counts: a.position_actual,
            actual_velocity_counts: a.velocity_actual,
            following_error_counts: a.following_error,
            controlword: u32::from(a.controlword),
            statusword: u32::from(a.statusword),
            fsa_state: a.fsa_state.map(fsa_index).unwrap_or(0) as i32,
            mode_display: i32::from(a.mode_display),
            error_code: u32::from(a.error_code),
            setpoint_torque: i32::from(a.target_torque),
            actual_torque: i32::from(a.torque_actual),
            // The drive profiles map no incremental counter yet.
            counter_sent: u32::from(a.counter_sent),
            counter_received: u32::from(a.counter_received),
            mode: i32::from(a.mode),
            setpoint_velocity_counts: a.target_velocity,
            status_do_1: u32::from(a.status_do[0]),
            status_do_2: u32::from(a.status_do[1]),
            status_do_3: u32::from(a.status_do[2]),
            controlword2: u32::from(a.controlword2),
        };
        if let Some(c) = self.capture.as_mut() {
            c.on_axis(a.axis as usize, a.cycle, |q| match q {
                Quantity::FollowingError => msg.following_error,
                Quantity::ActualPosition => msg.actual_position,
                Quantity::ActualVelocity => msg.actual_velocity,
                Quantity::SetpointPosition => msg.setpoint_position,
                Quantity::SetpointVelocity => msg.setpoint_velocity,
            });
        }
        self.buf.clear();
        msg.encode(&mut self.buf).expect("Vec grows");
        let t = self.time_of(a.cycle, period);
        self.write(channel, t)?;
        self.info.axis_messages += 1;
        Ok(())
    }

    /// Logs and records event `e`; returns its line (for the operator's recent events).
    fn event(&mut self, e: &EventRecord, period: u64) -> Result<String, RecorderError> {
        let axis = if e.axis == NO_AXIS {
            String::new()
        } else {
            self.cell
                .axes
                .get(e.axis as usize)
                .map(|a| a.name.clone())
                .unwrap_or_else(|| format!("#{}", e.axis))
        };
        let detail = describe_event(e);
        let line = format!(
            "cycle {}: {}{}{}",
            e.cycle,
            e.kind.as_str(),
            if axis.is_empty() {
                String::new()
            } else {
                format!(" [{axis}]")
            },
            if detail.is_empty() {
                String::new()
            } else {
                format!(": {detail}")
            }
        );
        match e.kind {
            EventKind::Underrun
            | EventKind::SetpointRejected
            | EventKind::DriveFault
            | EventKind::MasterTimeout
            | EventKind::BusError
            | EventKind::CommandRefused
            | EventKind::PlannerLost
            | EventKind::CommunicationError
            | EventKind::AlStatus
            | EventKind::Emergency
            | EventKind::MailboxDiscarded
            | EventKind::BringUpWarning
            | EventKind::RecordsDropped => tracing::warn!("{line}"),
            _ => tracing::debug!("{line}"),
        }
        self.info.events += 1;
        if self.info.event_log.len() < EVENT_LOG_LINES {
            self.info.event_log.push(line.clone());
        }
        if let Some(c) = self.capture.as_mut() {
            c.on_event(e.kind, &line);
        }
        let Some(channel) = self.channels().map(|ch| ch.events) else {
            return Ok(line);
        };
        let msg = proto::Event {
            cycle: e.cycle,
            kind: e.kind.as_str().to_string(),
            axis,
            detail,
            value: e.value,
        };
        self.buf.clear();
        msg.encode(&mut self.buf).expect("Vec grows");
        let t = self.time_of(e.cycle, period);
        self.write(channel, t)?;
        Ok(line)
    }
}
