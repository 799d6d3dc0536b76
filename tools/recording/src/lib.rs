//! Reading recordings back for `inspect`, `report`, `replay` and `recover`: the whole file in
//! memory, its summary (when the file is complete), and the decoded per-topic messages, read
//! chunk by chunk in parallel through the chunk indexes when the file has them.
//!
//! Also the record walk `recover` makes and the `mcap_recording` fuzz target drives: every
//! record framed by its length, chunks decompressed within their claimed size.
#![warn(missing_docs)]

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

use cellrt_runtime::host::record::proto::{AxisCycle, CycleStats, Event};
use cellrt_runtime::host::record::topics::{
    AXIS_TOPIC_PREFIX, CELL_METADATA, CYCLE_TOPIC, EVENTS_TOPIC,
};
use mcap::records::{ChunkIndex, Record};
use mcap::Summary;
use prost::Message as _;

/// Why a recording cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum RecordingError {
    /// The file cannot be read.
    #[error("{}: cannot read: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The file does not start with the MCAP magic.
    #[error("{}: not an MCAP file (no MCAP magic at the start)", path.display())]
    NotMcap {
        /// The file.
        path: PathBuf,
    },
    /// The file has no `cellrt.cell` metadata.
    #[error("{}: no '{CELL_METADATA}' metadata: not a cellrt recording", path.display())]
    NotCellrt {
        /// The file.
        path: PathBuf,
    },
    /// A chunk that the summary indexes cannot be read.
    #[error("{}: chunk at byte {offset}: {source}", path.display())]
    Chunk {
        /// The file.
        path: PathBuf,
        /// Where the chunk starts, bytes.
        offset: u64,
        /// Why.
        source: ChunkIndexError,
    },
    /// A message of a wanted channel does not decode.
    #[error("{}: {topic}: {source}", path.display())]
    Message {
        /// The file.
        path: PathBuf,
        /// The channel's topic.
        topic: String,
        /// Why.
        source: prost::DecodeError,
    },
    /// A decoding thread panicked.
    #[error("decoder panicked")]
    DecoderPanicked,
}

/// Why one record of an MCAP byte stream cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum RecordError {
    /// A record's length field runs past the end of the bytes.
    #[error("record {op:#04x} at byte {at} claims {len} bytes, past the end")]
    PastTheEnd {
        /// The record's opcode.
        op: u8,
        /// Where it starts, bytes.
        at: usize,
        /// Its claimed body length, bytes.
        len: u64,
    },
    /// An attachment whose lengths run past its record.
    #[error("an attachment record whose lengths run past its end")]
    AttachmentOverrun,
    /// The mcap crate refuses the record.
    #[error(transparent)]
    Mcap(#[from] mcap::McapError),
    /// A chunk claims more than [`MAX_CHUNK_BYTES`] uncompressed.
    #[error("claims {uncompressed} bytes uncompressed, more than the {} MiB a chunk may hold", MAX_CHUNK_BYTES >> 20)]
    ChunkTooLarge {
        /// The claimed size, bytes.
        uncompressed: u64,
    },
    /// A zstd chunk does not decompress.
    #[error("zstd: {0}")]
    Zstd(std::io::Error),
    /// An lz4 chunk does not decompress.
    #[error("lz4: {0}")]
    Lz4(std::io::Error),
    /// A chunk compressed by a method cellrt does not read.
    #[error("unknown compression '{0}'")]
    UnknownCompression(String),
    /// A chunk decompresses to another size than it claims.
    #[error("decompresses to {actual} bytes, the chunk says {claimed}")]
    SizeMismatch {
        /// The decompressed size, bytes.
        actual: usize,
        /// The claimed size, bytes.
        claimed: usize,
    },
}

/// Why a chunk that the summary indexes cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum ChunkIndexError {
    /// The index's span is not within the file.
    #[error("chunk index points outside the file")]
    OutsideTheFile,
    /// The index's span holds another record.
    #[error("chunk index does not point at a chunk")]
    NotAChunk,
    /// The chunk or one of its records cannot be read.
    #[error(transparent)]
    Record(#[from] RecordError),
    /// One of its messages does not decode.
    #[error(transparent)]
    Message(#[from] prost::DecodeError),
}

/// Why a linear read stopped before the data end record: a damaged or truncated file.
#[derive(Debug, thiserror::Error)]
pub enum Truncation {
    /// A record's length runs past the end of the file or of its chunk.
    #[error(transparent)]
    Frame(RecordError),
    /// A chunk cannot be read.
    #[error("chunk: {0}")]
    Chunk(RecordError),
    /// A chunk opcode whose record parses as something else.
    #[error("a chunk record that is no chunk")]
    NotAChunk,
    /// A record does not parse.
    #[error("record {op:#04x}: {source}")]
    Record {
        /// Its opcode.
        op: u8,
        /// Why.
        source: RecordError,
    },
    /// The file ends before its data end record.
    #[error("the data section has no end")]
    NoDataEnd,
    /// The file has no summary section (read linearly to its data end).
    #[error("no summary section")]
    NoSummary,
}

/// A recording file loaded into memory.
pub struct RecFile {
    /// Where it was read from.
    pub path: PathBuf,
    /// Its bytes.
    pub bytes: Vec<u8>,
    /// The summary section, if the file was finished (not truncated).
    pub summary: Option<Summary>,
}

/// One message of a wanted channel, decoded.
pub enum Decoded {
    /// `/cell/cycle`.
    Cycle(CycleStats),
    /// `/axis/<name>` (axis index in the channel order of the recording's metadata).
    Axis(usize, AxisCycle),
    /// `/cell/events`.
    Event(Event),
}

/// A recording decoded per topic.
#[derive(Default)]
pub struct Records {
    /// `/cell/cycle`, in file order.
    pub cycles: Vec<CycleStats>,
    /// Per axis (in [`CellInfo::axes`] order), in file order.
    pub axes: Vec<Vec<AxisCycle>>,
    /// `/cell/events`, in file order.
    pub events: Vec<Event>,
    /// Why the file was read linearly, and where that stopped: a damaged or truncated end.
    pub truncated: Option<Truncation>,
}

/// The cell as the recording's `cellrt.cell` metadata describes it.
#[derive(Debug, Clone, Default)]
pub struct CellInfo {
    /// Cell name.
    pub name: String,
    /// Cycle time, µs.
    pub cycle_time_us: u64,
    /// Axis names, in order.
    pub axes: Vec<String>,
    /// Per axis: the `axis.<name>` description.
    pub axis_details: Vec<String>,
    /// Every axis of the cell in configuration order, whichever backend ran it, with its
    /// `axis.<name>` description (`cell_axes`; the RT loop's axes where a recording predates it).
    pub cell_axes: Vec<(String, String)>,
    /// Software that wrote it.
    pub software: String,
}

impl CellInfo {
    /// The value of `key` in loop axis `axis`' description (`key=value` words, as the recorder
    /// writes them: `unit`, `counts_per_unit`, `mode`…); `None` where it is missing.
    pub fn axis_field(&self, axis: usize, key: &str) -> Option<&str> {
        self.axis_details.get(axis).and_then(|d| {
            d.split_whitespace()
                .find_map(|kv| kv.strip_prefix(key)?.strip_prefix('='))
        })
    }
}

impl RecFile {
    /// Reads `path`; a file that is not MCAP at all is an error naming it.
    pub fn open(path: &Path) -> Result<RecFile, RecordingError> {
        let bytes = cellrt_config::input_file::read_bytes(path, None).map_err(|source| {
            RecordingError::Read {
                path: path.to_path_buf(),
                source,
            }
        })?;
        Self::from_bytes(path, bytes)
    }

    /// The recording in `bytes`, read from `path` (named in messages).
    pub fn from_bytes(path: &Path, bytes: Vec<u8>) -> Result<RecFile, RecordingError> {
        if !bytes.starts_with(mcap::MAGIC) {
            return Err(RecordingError::NotMcap {
                path: path.to_path_buf(),
            });
        }
        let summary =
            read_summary(&bytes).filter(|s| !s.chunk_indexes.is_empty() || s.stats.is_some());
        Ok(RecFile {
            path: path.to_path_buf(),
            bytes,
            summary,
        })
    }

    /// Whether the file has a summary with chunk indexes.
    pub fn indexed(&self) -> bool {
        self.summary
            .as_ref()
            .is_some_and(|s| !s.chunk_indexes.is_empty())
    }

    /// The records before the first chunk error, read linearly (tolerates truncation): the
    /// metadata and attachments of an unfinished file.
    fn linear_records(&self) -> impl Iterator<Item = Record<'_>> {
        RecordWalker::new(&self.bytes, mcap::MAGIC.len())
            .map_while(Result::ok)
            .map_while(|(op, body)| parse_record(op, body).ok())
    }

    /// The `cellrt.cell` metadata.
    pub fn cell(&self) -> Result<CellInfo, RecordingError> {
        let mut meta = None;
        if let Some(s) = &self.summary {
            for idx in s
                .metadata_indexes
                .iter()
                .filter(|m| m.name == CELL_METADATA)
            {
                let op = mcap::records::op::METADATA;
                if one_record_at(&self.bytes, idx.offset, idx.length, op).is_none() {
                    continue;
                }
                if let Ok(m) = mcap::read::metadata(&self.bytes, idx) {
                    meta = Some(m.metadata);
                    break;
                }
            }
        }
        if meta.is_none() {
            meta = self.linear_records().find_map(|r| match r {
                Record::Metadata(m) if m.name == CELL_METADATA => Some(m.metadata),
                _ => None,
            });
        }
        let all = meta.ok_or_else(|| RecordingError::NotCellrt {
            path: self.path.clone(),
        })?;
        let names = |key: &str| -> Option<Vec<String>> {
            all.get(key).map(|a| {
                a.split(',')
                    .map(|s| s.trim().to_string())
                    .filter(|s| !s.is_empty())
                    .collect()
            })
        };
        let axes = names("axes").unwrap_or_default();
        let detail = |a: &String| all.get(&format!("axis.{a}")).cloned().unwrap_or_default();
        let cell_axes = names("cell_axes")
            .unwrap_or_else(|| axes.clone())
            .into_iter()
            .map(|a| {
                let d = detail(&a);
                (a, d)
            })
            .collect();
        Ok(CellInfo {
            name: all.get("cell").cloned().unwrap_or_default(),
            cycle_time_us: all
                .get("cycle_time_us")
                .and_then(|v| v.parse().ok())
                .unwrap_or(0),
            axis_details: axes.iter().map(detail).collect(),
            axes,
            cell_axes,
            software: all.get("software").cloned().unwrap_or_default(),
        })
    }

    /// The attachments (name, bytes).
    pub fn attachments(&self) -> Vec<(String, Vec<u8>)> {
        if let Some(s) = &self.summary {
            if !s.attachment_indexes.is_empty() {
                return s
                    .attachment_indexes
                    .iter()
                    .filter(|i| attachment_at(&self.bytes, i.offset, i.length))
                    .filter_map(|i| mcap::read::attachment(&self.bytes, i).ok())
                    .map(|a| (a.name, a.data.into_owned()))
                    .collect();
            }
        }
        self.linear_records()
            .filter_map(|r| match r {
                Record::Attachment { header, data, .. } => Some((header.name, data.into_owned())),
                _ => None,
            })
            .collect()
    }

    /// Decodes every message of the cycle, event and (if `with_axes`) axis channels.
    pub fn decode(&self, cell: &CellInfo, with_axes: bool) -> Result<Records, RecordingError> {
        let axis_index: HashMap<String, usize> = cell
            .axes
            .iter()
            .enumerate()
            .map(|(i, a)| (format!("{AXIS_TOPIC_PREFIX}{a}"), i))
            .collect();
        let classify = |topic: &str| -> Option<Kind> {
            match topic {
                CYCLE_TOPIC => Some(Kind::Cycle),
                EVENTS_TOPIC => Some(Kind::Event),
                t if with_axes => axis_index.get(t).map(|i| Kind::Axis(*i)),
                _ => None,
            }
        };
        let mut out = Records {
            axes: vec![Vec::new(); cell.axes.len()],
            ..Records::default()
        };
        let mut push = |d: Decoded| match d {
            Decoded::Cycle(c) => out.cycles.push(c),
            Decoded::Axis(i, a) => out.axes[i].push(a),
            Decoded::Event(e) => out.events.push(e),
        };
        match self
            .summary
            .as_ref()
            .filter(|s| !s.chunk_indexes.is_empty())
        {
            Some(summary) => {
                let kinds: HashMap<u16, Kind> = summary
                    .channels
                    .iter()
                    .filter_map(|(id, ch)| classify(&ch.topic).map(|k| (*id, k)))
                    .collect();
                let mut chunks: Vec<&ChunkIndex> = summary.chunk_indexes.iter().collect();
                chunks.sort_by_key(|c| c.chunk_start_offset);
                let threads = std::thread::available_parallelism()
                    .map(|n| n.get())
                    .unwrap_or(1)
                    .clamp(1, 8);
                let per = chunks.len().div_ceil(threads).max(1);
                let parts: Vec<Result<Vec<Decoded>, RecordingError>> = std::thread::scope(|s| {
                    let handles: Vec<_> = chunks
                        .chunks(per)
                        .map(|group| {
                            let kinds = &kinds;
                            s.spawn(move || {
                                let mut v = Vec::new();
                                for c in group {
                                    self.decode_chunk(c, kinds, &mut v)?;
                                }
                                Ok(v)
                            })
                        })
                        .collect();
                    handles
                        .into_iter()
                        .map(|h| h.join().unwrap_or(Err(RecordingError::DecoderPanicked)))
                        .collect()
                });
                for p in parts {
                    p?.into_iter().for_each(&mut push);
                }
            }
            None => {
                let stopped = self.walk_messages(&mut |_, ch, data| {
                    if let Some(k) = classify(&ch.topic) {
                        let decoded =
                            decode_one(k, data).map_err(|source| RecordingError::Message {
                                path: self.path.clone(),
                                topic: ch.topic.clone(),
                                source,
                            })?;
                        push(decoded);
                    }
                    Ok(())
                })?;
                out.truncated = Some(stopped.unwrap_or(Truncation::NoSummary));
            }
        }
        Ok(out)
    }

    /// Calls `each` with every message of the data section in file order (channel id, channel,
    /// data), read record by record: channels as defined so far, each chunk decompressed
    /// within its claimed size ([`chunk_records`]). Returns why the walk stopped before the
    /// data end record (a damaged or truncated file), `None` when it reached it.
    fn walk_messages(
        &self,
        each: &mut MessageVisitor<'_>,
    ) -> Result<Option<Truncation>, RecordingError> {
        let mut defs = LinearDefs::default();
        for item in RecordWalker::new(&self.bytes, mcap::MAGIC.len()) {
            let (op, body) = match item {
                Ok(record) => record,
                Err(e) => return Ok(Some(Truncation::Frame(e))),
            };
            match op {
                mcap::records::op::DATA_END | mcap::records::op::FOOTER => return Ok(None),
                mcap::records::op::CHUNK => {
                    let inner = match parse_record(op, body) {
                        Ok(Record::Chunk { header, data }) => chunk_records(&header, &data)
                            .map(|b| b.into_owned())
                            .map_err(Truncation::Chunk),
                        Ok(_) => Err(Truncation::NotAChunk),
                        Err(e) => Err(Truncation::Chunk(e)),
                    };
                    let inner = match inner {
                        Ok(inner) => inner,
                        Err(e) => return Ok(Some(e)),
                    };
                    for item in RecordWalker::new(&inner, 0) {
                        match item {
                            Ok((op, body)) => {
                                if let Some(why) = defs.visit(op, body, each)? {
                                    return Ok(Some(why));
                                }
                            }
                            Err(e) => return Ok(Some(Truncation::Frame(e))),
                        }
                    }
                }
                _ => {
                    if let Some(why) = defs.visit(op, body, each)? {
                        return Ok(Some(why));
                    }
                }
            }
        }
        Ok(Some(Truncation::NoDataEnd))
    }

    /// Decodes the wanted channels' messages of the chunk `chunk` indexes, walking its records
    /// in place (no copy of the others). Every record is framed by its length and only
    /// messages are decoded: the mcap crate's chunk stream parses whatever a chunk holds,
    /// an attachment unchecked.
    fn decode_chunk(
        &self,
        chunk: &ChunkIndex,
        kinds: &HashMap<u16, Kind>,
        out: &mut Vec<Decoded>,
    ) -> Result<(), RecordingError> {
        self.chunk_messages(chunk, kinds, out)
            .map_err(|source| RecordingError::Chunk {
                path: self.path.clone(),
                offset: chunk.chunk_start_offset,
                source,
            })
    }

    /// [`RecFile::decode_chunk`] before the error names the file and the chunk.
    fn chunk_messages(
        &self,
        chunk: &ChunkIndex,
        kinds: &HashMap<u16, Kind>,
        out: &mut Vec<Decoded>,
    ) -> Result<(), ChunkIndexError> {
        check_chunk_size(chunk.uncompressed_size)?;
        let start = chunk.chunk_start_offset as usize;
        let end = start
            .checked_add(chunk.chunk_length as usize)
            .filter(|e| *e <= self.bytes.len() && start + 9 <= *e)
            .ok_or(ChunkIndexError::OutsideTheFile)?;
        let (header, data) =
            match parse_record(mcap::records::op::CHUNK, &self.bytes[start + 9..end])? {
                Record::Chunk { header, data } => (header, data),
                _ => return Err(ChunkIndexError::NotAChunk),
            };
        let records = chunk_records(&header, &data)?;
        for record in RecordWalker::new(&records, 0) {
            let (op, body) = record?;
            // Message: channel id u16, sequence u32, log time u64, publish time u64, data.
            if op == mcap::records::op::MESSAGE && body.len() >= 22 {
                let channel = u16::from_le_bytes([body[0], body[1]]);
                if let Some(k) = kinds.get(&channel) {
                    out.push(decode_one(*k, &body[22..])?);
                }
            }
        }
        Ok(())
    }

    /// Message counts per channel topic (summary statistics, or counted linearly).
    pub fn channel_counts(&self) -> Vec<ChannelCount> {
        let mut out = Vec::new();
        if let Some(s) = &self.summary {
            if let Some(stats) = &s.stats {
                let mut ids: Vec<&u16> = s.channels.keys().collect();
                ids.sort();
                for id in ids {
                    let ch = &s.channels[id];
                    out.push(ChannelCount {
                        topic: ch.topic.clone(),
                        schema: ch
                            .schema
                            .as_ref()
                            .map(|s| s.name.clone())
                            .unwrap_or_default(),
                        count: stats.channel_message_counts.get(id).copied().unwrap_or(0),
                    });
                }
                return out;
            }
        }
        let mut counts: BTreeMap<u16, (ChannelCount, u64)> = BTreeMap::new();
        let _ = self.walk_messages(&mut |id, ch, _| {
            counts
                .entry(id)
                .or_insert_with(|| {
                    let count = ChannelCount {
                        topic: ch.topic.clone(),
                        schema: ch.schema.clone(),
                        count: 0,
                    };
                    (count, 0)
                })
                .1 += 1;
            Ok(())
        });
        for (mut ch, n) in counts.into_values() {
            ch.count = n;
            out.push(ch);
        }
        out
    }
}

/// What [`RecFile::walk_messages`] calls per message: channel id, channel, data.
type MessageVisitor<'a> = dyn FnMut(u16, &LinearChannel, &[u8]) -> Result<(), RecordingError> + 'a;

/// A channel as a linear read has met it.
struct LinearChannel {
    topic: String,
    schema: String,
}

/// The schemas and channels a linear read has met so far.
#[derive(Default)]
struct LinearDefs {
    schemas: HashMap<u16, String>,
    channels: HashMap<u16, LinearChannel>,
}

impl LinearDefs {
    /// Takes in one record: a definition is kept, a message on a known channel is handed to
    /// `each`. Returns why reading must stop (a record that does not parse).
    fn visit(
        &mut self,
        op: u8,
        body: &[u8],
        each: &mut MessageVisitor<'_>,
    ) -> Result<Option<Truncation>, RecordingError> {
        match parse_record(op, body) {
            Ok(Record::Schema { header, .. }) => {
                self.schemas.insert(header.id, header.name);
            }
            Ok(Record::Channel(c)) => {
                let schema = self.schemas.get(&c.schema_id).cloned().unwrap_or_default();
                let topic = c.topic;
                self.channels.insert(c.id, LinearChannel { topic, schema });
            }
            Ok(Record::Message { header, data }) => {
                if let Some(ch) = self.channels.get(&header.channel_id) {
                    each(header.channel_id, ch, &data)?;
                }
            }
            Ok(_) => {}
            Err(source) => return Ok(Some(Truncation::Record { op, source })),
        }
        Ok(None)
    }
}

/// Messages on one channel.
pub struct ChannelCount {
    /// Topic.
    pub topic: String,
    /// Schema name.
    pub schema: String,
    /// Messages.
    pub count: u64,
}

#[derive(Clone, Copy)]
enum Kind {
    Cycle,
    Axis(usize),
    Event,
}

/// The most bytes a chunk may claim uncompressed: four times the largest chunk the recorder
/// writes (`recording.chunk_size_kib` ≤ 64 MiB). A claim beyond it is refused before anything
/// is allocated for it.
pub const MAX_CHUNK_BYTES: u64 = 256 << 20;

/// One record parsed by the mcap crate, after the checks the crate leaves out: an attachment
/// whose lengths run past its record is refused here (mcap 0.26 slices it unchecked and
/// panics; found by the `mcap_recording` fuzz target).
pub fn parse_record(op: u8, body: &[u8]) -> Result<Record<'_>, RecordError> {
    if op == mcap::records::op::ATTACHMENT && !attachment_fits(body) {
        return Err(RecordError::AttachmentOverrun);
    }
    Ok(mcap::read::parse_record(op, body)?)
}

/// Whether an attachment record's body holds what its lengths claim: log and create time,
/// name, media type, the data length, that much data and the CRC.
pub fn attachment_fits(body: &[u8]) -> bool {
    let mut at = 16usize;
    for _ in 0..2 {
        let Some(len) = body.get(at..at + 4) else {
            return false;
        };
        let len = u32::from_le_bytes([len[0], len[1], len[2], len[3]]) as usize;
        at = match at.checked_add(4 + len) {
            Some(next) if next <= body.len() => next,
            _ => return false,
        };
    }
    let Some(data_len) = body.get(at..at + 8) else {
        return false;
    };
    let data_len = u64::from_le_bytes(data_len.try_into().unwrap_or([0xFF; 8]));
    (at as u64 + 8)
        .checked_add(data_len)
        .and_then(|end| end.checked_add(4))
        .is_some_and(|end| end <= body.len() as u64)
}

/// The file's summary section as the mcap crate reads it, or `None` where there is none or it
/// is damaged. The section is walked first: it may hold only the records the MCAP format puts
/// there (schemas, channels, chunk, attachment and metadata indexes, statistics, summary
/// offsets), each framed inside the file. mcap 0.26 decodes whatever it finds there, an
/// attachment by slicing unchecked (a panic found by the `mcap_recording` fuzz target).
pub fn read_summary(bytes: &[u8]) -> Option<mcap::Summary> {
    summary_section_plain(bytes)
        .then(|| mcap::Summary::read(bytes).ok().flatten())
        .flatten()
}

/// Whether the summary section that the footer points at holds only summary records up to the
/// footer; true where there is no footer or no summary (the crate finds none either).
fn summary_section_plain(bytes: &[u8]) -> bool {
    use mcap::records::op;
    /// Footer record (opcode, length, 20-byte body) and the closing magic.
    const FOOTER_AND_MAGIC: usize = 1 + 8 + 20 + 8;
    let Some(footer) = bytes
        .len()
        .checked_sub(FOOTER_AND_MAGIC)
        .and_then(|at| bytes.get(at + 9..at + 17))
    else {
        return true;
    };
    let summary_start = u64::from_le_bytes(footer.try_into().unwrap_or([0; 8]));
    if summary_start == 0 {
        return true;
    }
    let Ok(start) = usize::try_from(summary_start) else {
        return false;
    };
    for record in RecordWalker::new(bytes, start) {
        match record {
            Ok((op::FOOTER, _)) => return true,
            Ok((
                op::SCHEMA
                | op::CHANNEL
                | op::CHUNK_INDEX
                | op::ATTACHMENT_INDEX
                | op::STATISTICS
                | op::METADATA_INDEX
                | op::SUMMARY_OFFSET,
                _,
            )) => {}
            Ok(_) | Err(_) => return false,
        }
    }
    false
}

/// The body of the record of opcode `op` that the `length` bytes at `offset` hold, when they
/// hold exactly that one record (opcode, length field, body): the mcap crate's index readers
/// parse whatever else an index's span holds as a second record, unchecked.
fn one_record_at(bytes: &[u8], offset: u64, length: u64, op: u8) -> Option<&[u8]> {
    let (Ok(start), Ok(len)) = (usize::try_from(offset), usize::try_from(length)) else {
        return None;
    };
    let r = bytes.get(start..start.checked_add(len)?)?;
    let body = u64::from_le_bytes(r.get(1..9)?.try_into().ok()?);
    (r[0] == op && body.checked_add(9) == Some(r.len() as u64)).then(|| &r[9..])
}

/// Whether the `length` bytes at `offset` are one attachment record that the mcap crate can
/// parse whole.
fn attachment_at(bytes: &[u8], offset: u64, length: u64) -> bool {
    one_record_at(bytes, offset, length, mcap::records::op::ATTACHMENT).is_some_and(attachment_fits)
}

/// The records of `bytes` from offset `at` on, each as (opcode, body), framed by their length
/// fields; a length that runs past the end is an error and ends the walk.
pub struct RecordWalker<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> RecordWalker<'a> {
    /// Walks `bytes` from `at`.
    pub fn new(bytes: &'a [u8], at: usize) -> Self {
        RecordWalker { bytes, at }
    }
}

impl<'a> Iterator for RecordWalker<'a> {
    type Item = Result<(u8, &'a [u8]), RecordError>;

    fn next(&mut self) -> Option<Self::Item> {
        let rest = self.bytes.get(self.at..)?;
        if rest.len() < 9 {
            return None;
        }
        let op = rest[0];
        let len = u64::from_le_bytes(rest[1..9].try_into().expect("8 bytes"));
        let Some(body) = usize::try_from(len)
            .ok()
            .and_then(|len| rest.get(9..9usize.checked_add(len)?))
        else {
            let at = self.at;
            self.at = self.bytes.len();
            return Some(Err(RecordError::PastTheEnd { op, at, len }));
        };
        self.at += 9 + body.len();
        Some(Ok((op, body)))
    }
}

/// The records of a chunk, decompressed into at most its claimed size (itself at most
/// [`MAX_CHUNK_BYTES`]): a damaged size field or compressed stream cannot make it allocate more.
pub fn chunk_records<'a>(
    header: &mcap::records::ChunkHeader,
    data: &'a [u8],
) -> Result<std::borrow::Cow<'a, [u8]>, RecordError> {
    use std::io::Read;
    check_chunk_size(header.uncompressed_size)?;
    let size = header.uncompressed_size as usize;
    let out = match header.compression.as_str() {
        "" => return Ok(std::borrow::Cow::Borrowed(data)),
        "zstd" => zstd::bulk::decompress(data, size).map_err(RecordError::Zstd)?,
        "lz4" => {
            let mut out = Vec::with_capacity(size);
            lz4::Decoder::new(data)
                .and_then(|d| d.take(size as u64 + 1).read_to_end(&mut out))
                .map_err(RecordError::Lz4)?;
            out
        }
        other => return Err(RecordError::UnknownCompression(other.to_string())),
    };
    if out.len() != size {
        return Err(RecordError::SizeMismatch {
            actual: out.len(),
            claimed: size,
        });
    }
    Ok(std::borrow::Cow::Owned(out))
}

/// Refuses a chunk whose claimed uncompressed size is beyond [`MAX_CHUNK_BYTES`].
fn check_chunk_size(uncompressed: u64) -> Result<(), RecordError> {
    if uncompressed > MAX_CHUNK_BYTES {
        return Err(RecordError::ChunkTooLarge { uncompressed });
    }
    Ok(())
}

fn decode_one(k: Kind, data: &[u8]) -> Result<Decoded, prost::DecodeError> {
    Ok(match k {
        Kind::Cycle => Decoded::Cycle(CycleStats::decode(data)?),
        Kind::Axis(i) => Decoded::Axis(i, AxisCycle::decode(data)?),
        Kind::Event => Decoded::Event(Event::decode(data)?),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A finished recording with one message and one attachment, and the byte offset of the
    /// body of its summary's attachment index.
    fn with_attachment() -> (Vec<u8>, usize) {
        let mut out = std::io::Cursor::new(Vec::new());
        let mut w = mcap::Writer::new(&mut out).unwrap();
        let channel = w
            .add_channel(0, CYCLE_TOPIC, "protobuf", &BTreeMap::new())
            .unwrap();
        let header = mcap::records::MessageHeader {
            channel_id: channel,
            sequence: 0,
            log_time: 0,
            publish_time: 0,
        };
        w.write_to_known_channel(&header, &[]).unwrap();
        w.attach(&mcap::Attachment {
            log_time: 0,
            create_time: 0,
            name: "config".into(),
            media_type: "text/plain".into(),
            data: std::borrow::Cow::Borrowed(b"[cell]"),
        })
        .unwrap();
        w.finish().unwrap();
        drop(w);
        let bytes = out.into_inner();
        let at = RecordWalker::new(&bytes, mcap::MAGIC.len())
            .map_while(Result::ok)
            .find(|(op, _)| *op == mcap::records::op::ATTACHMENT_INDEX)
            .map(|(_, body)| body.as_ptr() as usize - bytes.as_ptr() as usize)
            .expect("an attachment index");
        (bytes, at)
    }

    #[test]
    fn an_index_past_the_end_of_the_file_is_skipped_not_sliced() {
        // Found by the mcap_recording fuzz target: the mcap crate adds an index's offset and
        // length unchecked and slices the file with them (a panic, or a wrap in release).
        let (good, at) = with_attachment();
        let file = RecFile::from_bytes(Path::new("ok.mcap"), good.clone()).unwrap();
        assert_eq!(file.attachments().len(), 1);
        for offset in [u64::MAX - 4, good.len() as u64] {
            let mut bad = good.clone();
            bad[at..at + 8].copy_from_slice(&offset.to_le_bytes());
            let file = RecFile::from_bytes(Path::new("bad.mcap"), bad).unwrap();
            assert!(file.attachments().is_empty(), "offset {offset}");
            assert!(matches!(file.cell(), Err(RecordingError::NotCellrt { .. })));
        }
    }

    #[test]
    fn errors_read_as_before() {
        let not_mcap = RecFile::from_bytes(Path::new("x.mcap"), b"hello".to_vec());
        assert_eq!(
            not_mcap.err().map(|e| e.to_string()).as_deref(),
            Some("x.mcap: not an MCAP file (no MCAP magic at the start)")
        );
        let mut walker = RecordWalker::new(&[0x06, 0xFF, 0, 0, 0, 0, 0, 0, 0], 0);
        let past = walker.next().and_then(Result::err);
        assert!(matches!(
            past,
            Some(RecordError::PastTheEnd {
                op: 0x06,
                at: 0,
                len: 255
            })
        ));
        assert_eq!(
            past.map(|e| e.to_string()).as_deref(),
            Some("record 0x06 at byte 0 claims 255 bytes, past the end")
        );
        let stop = Truncation::Chunk(RecordError::ChunkTooLarge {
            uncompressed: MAX_CHUNK_BYTES + 1,
        });
        assert_eq!(
            stop.to_string(),
            format!(
                "chunk: claims {} bytes uncompressed, more than the 256 MiB a chunk may hold",
                MAX_CHUNK_BYTES + 1
            )
        );
    }
}
