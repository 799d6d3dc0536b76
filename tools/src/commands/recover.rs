//! `cellrt recover IN.mcap OUT.mcap`: rewrites a recording cut short (a crash, SIGKILL, power
//! loss) into a complete, indexed file. Reads the input linearly, tolerating a truncated or
//! damaged end, and copies every schema, channel, metadata record, attachment and every message
//! of every complete chunk, with the same ids; the open chunk at the moment of the crash is lost
//! (the recorder closes a chunk at least every `recording.flush_ms`).

use std::collections::{BTreeMap, HashSet};
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use mcap::records::{MessageHeader, Record};
use mcap::{Attachment, WriteOptions, Writer};

use crate::cli::RecoverArgs;
use crate::exit::Exit;
use cellrt_recording::{chunk_records, parse_record, read_summary, RecordError, RecordWalker};

/// Why a recording cannot be recovered.
#[derive(Debug, thiserror::Error)]
pub enum RecoverError {
    /// The input does not start with a header record.
    #[error("the input has no MCAP header record")]
    NoHeader,
    /// The output cannot be created.
    #[error("{}: cannot create: {source}", path.display())]
    Create {
        /// The output file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The output's folder cannot be created, or the output cannot be flushed or synced.
    #[error("{}: {source}", path.display())]
    Io {
        /// The folder or the output file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The output cannot be written.
    #[error("{}: {source}", path.display())]
    Write {
        /// The output file.
        path: PathBuf,
        /// Why.
        source: mcap::McapError,
    },
}

/// Why a record of the input was skipped as damaged.
#[derive(Debug, thiserror::Error)]
pub enum Damage {
    /// A record that does not parse.
    #[error("record {op:#04x}: {source}")]
    Record {
        /// Its opcode.
        op: u8,
        /// Why.
        source: RecordError,
    },
    /// A chunk whose records cannot all be read.
    #[error(transparent)]
    Chunk(#[from] RecordError),
}

/// What a recovery copied.
#[derive(Debug, Default)]
pub struct Recovered {
    /// Messages copied.
    pub messages: u64,
    /// Complete chunks copied.
    pub chunks: u64,
    /// Damaged chunks skipped (their messages are lost), and why the first one was.
    pub damaged: (u64, Option<Damage>),
    /// Messages dropped because their channel was defined only in a damaged chunk and the
    /// file has no summary to take it from.
    pub undefined: u64,
    /// Why reading stopped before the end of the data section, if it did.
    pub stopped: Option<RecordError>,
    /// Whether the input already was complete (had its data end record).
    pub was_complete: bool,
    /// Last message log time copied, ns.
    pub last_log_time: u64,
}

impl Recovered {
    fn skip_damaged(&mut self, why: Damage) {
        self.damaged.0 += 1;
        self.damaged.1.get_or_insert(why);
    }
}

/// Runs `cellrt recover`.
pub fn run(args: RecoverArgs) -> Exit {
    let bytes = match cellrt_config::input_file::read_bytes(&args.input, None) {
        Ok(b) => b,
        Err(e) => {
            eprintln!("error: {}: cannot read: {e}", args.input.display());
            return Exit::BadInput;
        }
    };
    if !bytes.starts_with(mcap::MAGIC) {
        eprintln!(
            "error: {}: not an MCAP file (no MCAP magic at the start)",
            args.input.display()
        );
        return Exit::BadInput;
    }
    if args.input.canonicalize().ok() == args.output.canonicalize().ok() && args.output.exists() {
        eprintln!(
            "error: {}: output must differ from the input",
            args.output.display()
        );
        return Exit::BadInput;
    }
    match recover(&bytes, &args.output) {
        Ok(r) => {
            if let (n @ 1.., Some(why)) = &r.damaged {
                eprintln!(
                    "warning: {}: {n} damaged chunk(s) skipped, their messages lost (first: {why})",
                    args.input.display()
                );
            }
            if r.undefined > 0 {
                eprintln!(
                    "warning: {}: {} messages dropped: their channel was defined only in a damaged chunk",
                    args.input.display(),
                    r.undefined
                );
            }
            println!(
                "recovered {} messages in {} chunks from {} into {}{}",
                r.messages,
                r.chunks,
                args.input.display(),
                args.output.display(),
                if r.was_complete {
                    " (the input was complete)".to_string()
                } else {
                    format!(
                        "; the input ends early ({}): what followed the last complete chunk is lost",
                        r.stopped
                            .as_ref()
                            .map_or("no data end record".to_string(), ToString::to_string)
                    )
                }
            );
            Exit::Ok
        }
        Err(e) => {
            eprintln!("error: {e}");
            Exit::Failed
        }
    }
}

/// Copies everything readable of `input` into a new indexed MCAP at `out`.
pub fn recover(input: &[u8], out: &Path) -> Result<Recovered, RecoverError> {
    let werr = |source: mcap::McapError| RecoverError::Write {
        path: out.to_path_buf(),
        source,
    };
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source: std::io::Error| RecoverError::Io { path, source }
    };
    let mut r = Recovered::default();
    let mut records = RecordWalker::new(input, mcap::MAGIC.len());
    let (profile, library) = match records.next().map(|r| r.map(|(op, b)| parse_record(op, b))) {
        Some(Ok(Ok(Record::Header(h)))) => (h.profile, h.library),
        _ => return Err(RecoverError::NoHeader),
    };
    // The compression of the first chunk, for the rewritten file.
    let compression = input_compression(input);
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(io(dir))?;
    }
    let file = File::create(out).map_err(|source| RecoverError::Create {
        path: out.to_path_buf(),
        source,
    })?;
    let mut w = WriteOptions::new()
        .compression(compression)
        .profile(profile)
        .library(library)
        .create(BufWriter::with_capacity(1 << 20, file))
        .map_err(werr)?;
    // Channels defined in a damaged chunk come from the summary section, where there is one.
    let summary = read_summary(input);
    let mut defined = Defined::default();
    for item in records {
        // A record that runs past the end ends the data; one that does not parse is skipped
        // (its length still frames the next).
        let (op, body) = match item {
            Ok(record) => record,
            Err(e) => {
                r.stopped = Some(e);
                break;
            }
        };
        let rec = match parse_record(op, body) {
            Ok(rec) => rec,
            Err(e) => {
                r.skip_damaged(Damage::Record { op, source: e });
                continue;
            }
        };
        match rec {
            Record::Chunk { header, data } => {
                // All or nothing per chunk: decoded completely before anything is written.
                let (defs, messages) = match decode_chunk(&header, &data) {
                    Ok(decoded) => decoded,
                    Err(e) => {
                        // The chunk's own length framed it: the records after it are intact.
                        r.skip_damaged(e.into());
                        continue;
                    }
                };
                for d in defs {
                    defined.define(&mut w, d).map_err(werr)?;
                }
                for (h, d) in &messages {
                    copy_message(&mut w, &mut defined, &mut r, summary.as_ref(), h, d)
                        .map_err(werr)?;
                }
                r.chunks += 1;
            }
            Record::Schema { .. } | Record::Channel(_) => {
                defined.define(&mut w, rec).map_err(werr)?
            }
            Record::Message { header, data } => copy_message(
                &mut w,
                &mut defined,
                &mut r,
                summary.as_ref(),
                &header,
                &data,
            )
            .map_err(werr)?,
            Record::Metadata(m) => w.write_metadata(&m).map_err(werr)?,
            Record::Attachment { header, data, .. } => w
                .attach(&Attachment {
                    log_time: header.log_time,
                    create_time: header.create_time,
                    name: header.name,
                    media_type: header.media_type,
                    data,
                })
                .map_err(werr)?,
            Record::DataEnd(_) => {
                r.was_complete = true;
                break;
            }
            _ => {}
        }
    }
    w.finish().map_err(werr)?;
    let file = w
        .into_inner()
        .into_inner()
        .map_err(|e| io(out)(e.into_error()))?;
    file.sync_all().map_err(io(out))?;
    Ok(r)
}

/// A chunk's schema and channel records and its messages, all decoded; an error where any
/// part of it is damaged (the whole chunk is then lost, not half of it).
#[allow(clippy::type_complexity)]
fn decode_chunk(
    header: &mcap::records::ChunkHeader,
    data: &[u8],
) -> Result<(Vec<Record<'static>>, Vec<(MessageHeader, Vec<u8>)>), RecordError> {
    let inner_bytes = chunk_records(header, data)?;
    let mut defs = Vec::new();
    let mut messages = Vec::new();
    for inner in RecordWalker::new(&inner_bytes, 0) {
        let (op, body) = inner?;
        match parse_record(op, body)? {
            Record::Message { header, data } => messages.push((header, data.into_owned())),
            other @ (Record::Schema { .. } | Record::Channel(_)) => defs.push(other.into_owned()),
            _ => {}
        }
    }
    Ok((defs, messages))
}

/// Writes one message to the output if its channel is (or can be) defined there; counts it
/// as written or as undefined.
fn copy_message<W: std::io::Write + std::io::Seek>(
    w: &mut mcap::Writer<W>,
    defined: &mut Defined,
    r: &mut Recovered,
    summary: Option<&mcap::Summary>,
    header: &MessageHeader,
    data: &[u8],
) -> Result<(), mcap::McapError> {
    if !defined.ensure(w, header.channel_id, summary)? {
        r.undefined += 1;
        return Ok(());
    }
    w.write_to_known_channel(header, data)?;
    r.messages += 1;
    r.last_log_time = r.last_log_time.max(header.log_time);
    Ok(())
}

/// The schema and channel ids written to the output so far.
#[derive(Default)]
struct Defined {
    schemas: HashSet<u16>,
    channels: HashSet<u16>,
}

impl Defined {
    /// Adds a schema or channel record to `w` with its original id.
    fn define<W: std::io::Write + std::io::Seek>(
        &mut self,
        w: &mut Writer<W>,
        rec: Record<'_>,
    ) -> mcap::McapResult<()> {
        match rec {
            Record::Schema { header, data } if header.id != 0 => {
                w.add_schema_with_id(header.id, &header.name, &header.encoding, &data)?;
                self.schemas.insert(header.id);
            }
            Record::Channel(c) => {
                let meta: BTreeMap<String, String> = c.metadata;
                w.add_channel_with_id(c.id, c.schema_id, &c.topic, &c.message_encoding, &meta)?;
                self.channels.insert(c.id);
            }
            _ => {}
        }
        Ok(())
    }

    /// Whether channel `id` is defined in the output, defining it (and its schema) from the
    /// input's summary section where it is not yet.
    fn ensure<W: std::io::Write + std::io::Seek>(
        &mut self,
        w: &mut Writer<W>,
        id: u16,
        summary: Option<&mcap::Summary>,
    ) -> mcap::McapResult<bool> {
        if self.channels.contains(&id) {
            return Ok(true);
        }
        let Some(c) = summary.and_then(|s| s.channels.get(&id)) else {
            return Ok(false);
        };
        let schema_id = match &c.schema {
            Some(s) => {
                if self.schemas.insert(s.id) {
                    w.add_schema_with_id(s.id, &s.name, &s.encoding, &s.data)?;
                }
                s.id
            }
            None => 0,
        };
        w.add_channel_with_id(id, schema_id, &c.topic, &c.message_encoding, &c.metadata)?;
        self.channels.insert(id);
        Ok(true)
    }
}

/// Compression of the first chunk of `input` (zstd if none can be read).
fn input_compression(input: &[u8]) -> Option<mcap::Compression> {
    let first = RecordWalker::new(input, mcap::MAGIC.len())
        .map_while(Result::ok)
        .find_map(|(op, body)| match parse_record(op, body) {
            Ok(Record::Chunk { header, .. }) => Some(header.compression),
            _ => None,
        });
    match first.as_deref() {
        Some("lz4") => Some(mcap::Compression::Lz4),
        Some("") => None,
        _ => Some(mcap::Compression::Zstd),
    }
}
