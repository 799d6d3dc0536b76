//! One MCAP file of a recording: created with the cell's schemas, channels (in their one
//! order, [`channel_specs`]), metadata and configuration, a byte count for rotation by size,
//! a chunk count for the writer's index, flushed and finished with its summary.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufWriter, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Instant;

use mcap::records::Metadata;
use mcap::{Attachment, WriteOptions, Writer};

use super::proto;
use super::topics::*;
use crate::rt::clock::realtime_offset_ns;
use cellrt_config::{AxisKind, CellConfig, Compression};

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

/// The channel ids of a cell's recording (the same in every file of the cell).
#[derive(Debug, Clone)]
pub(super) struct Channels {
    pub(super) cycle: u16,
    pub(super) events: u16,
    pub(super) axes: Vec<u16>,
    /// One per MR-JE-C axis.
    pub(super) je_c: Vec<u16>,
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
    pub(super) channels: Channels,
    pub(super) path: PathBuf,
    /// Bytes written to the file so far.
    pub(super) len: Arc<AtomicU64>,
    /// When the open chunk was last closed and the file flushed.
    pub(super) last_flush: Instant,
    /// Deadline of the first cycle in this file (for rotation by duration).
    pub(super) first_deadline: Option<u64>,
    /// Chunks closed in this file so far (by flush or by size), for [`MAX_CHUNKS_PER_FILE`].
    pub(super) chunks: u64,
    /// Uncompressed bytes in the open chunk.
    pub(super) chunk_bytes: u64,
    /// Target chunk size, bytes.
    pub(super) chunk_size: u64,
}

impl Sink {
    pub(super) fn writer_len(&self) -> u64 {
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
    pub(super) fn flush(&mut self) -> Result<(), RecorderError> {
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
        // Compressed on the recorder's own thread: mcap's default is a zstd worker pool per
        // file (one thread per physical core), which a rotation replaces with new threads,
        // each leaving a glibc arena of about 9 MiB behind (RSS grew by that per rotation),
        // and whose workers would run on the RT CPU too.
        .compression_threads(0)
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
pub(super) fn template_channels(cell: &CellConfig) -> Result<Channels, mcap::McapError> {
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
    let je_c_schema = if cell.axes.on_link().is_empty() {
        0
    } else {
        schema(writer, JE_C_SCHEMA)?
    };
    let mut ids = Vec::new();
    for spec in channel_specs(cell) {
        let schema = match spec.schema {
            CYCLE_SCHEMA => cycle_schema,
            EVENT_SCHEMA => event_schema,
            JE_C_SCHEMA => je_c_schema,
            _ => axis_schema,
        };
        ids.push(writer.add_channel(schema, &spec.topic, "protobuf", &spec.metadata)?);
    }
    let je_c_from = 2 + cell.axes.on_loop().len();
    Ok(Channels {
        cycle: ids[0],
        events: ids[1],
        axes: ids[2..je_c_from].to_vec(),
        je_c: ids[je_c_from..].to_vec(),
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

/// The channels of `cell`'s recording in their one order: cycle, events, one per axis, one per
/// MR-JE-C axis.
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
    specs.extend(cell.axes.on_loop().iter().map(|a| ChannelSpec {
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
    specs.extend(cell.axes.on_link().iter().map(|a| ChannelSpec {
        topic: je_c_topic(&a.name),
        schema: JE_C_SCHEMA,
        metadata: BTreeMap::from([
            ("unit".to_string(), a.unit.clone()),
            ("counts_per_unit".to_string(), a.counts_per_unit.to_string()),
            ("drive".to_string(), "mr-je-c".to_string()),
            ("transport".to_string(), a.transport.name().to_string()),
            ("period_ms".to_string(), a.period.as_millis().to_string()),
        ]),
    }));
    specs
}

/// The MCAP channel ids of `cell`'s recording, in [`channel_specs`] order.
pub fn channel_ids(cell: &CellConfig) -> Result<Vec<u16>, mcap::McapError> {
    let c = template_channels(cell)?;
    Ok([c.cycle, c.events]
        .into_iter()
        .chain(c.axes)
        .chain(c.je_c)
        .collect())
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
        ("axes".to_string(), cell.axes.loop_names()),
        ("cell_axes".to_string(), cell.axes.names()),
        (
            "software".to_string(),
            format!("cellrt {}", env!("CARGO_PKG_VERSION")),
        ),
        ("config_file".to_string(), cell.source.display().to_string()),
    ]);
    for axis in cell.axes.iter() {
        let detail = match axis.config {
            AxisKind::Loop(_, a) => format!(
                "backend={} drive={} mode={} unit={} counts_per_unit={} position=[{}, {}] velocity={} acceleration={} jerk={}",
                axis.backend().as_str(),
                a.profile.name,
                a.mode.as_str(),
                a.unit,
                axis.counts_per_unit(),
                a.position.min,
                a.position.max,
                a.limits.velocity,
                a.limits.acceleration,
                a.limits.jerk
            ),
            AxisKind::Link(_, a) => format!(
                "backend={} drive=MR-JE-C transport={} mode={} unit={} counts_per_unit={} position=[{}, {}] velocity={} acceleration={}",
                axis.backend().as_str(),
                a.transport.name(),
                a.mode.name(),
                a.unit,
                axis.counts_per_unit(),
                a.position[0],
                a.position[1],
                a.velocity,
                a.acceleration
            ),
        };
        cell_meta.insert(format!("axis.{}", axis.name()), detail);
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
