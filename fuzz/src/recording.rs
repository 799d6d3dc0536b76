//! MCAP recordings as `inspect`, `report`, `replay` and `recover` read them.

use std::path::Path;

use mcap::records::Record;

/// The tools' recording reader, compiled here from its source (the `cellrt` package has no
/// library target).
#[path = "../../tools/src/recording.rs"]
#[allow(dead_code)]
mod reader;

use reader::{chunk_records, parse_record, CellInfo, RecFile, RecordWalker};

/// A recording file: metadata, attachments, per-channel counts and decoded messages through
/// the reader `inspect`, `report` and `replay` use, then the record walk `recover` makes
/// (every record framed by its length, chunks decompressed within their claimed size).
pub fn mcap_recording(data: &[u8]) {
    if let Ok(file) = RecFile::from_bytes(Path::new("fuzz.mcap"), data.to_vec()) {
        let _ = file.indexed();
        let _ = file.attachments();
        let _ = file.channel_counts();
        let cell = file.cell().unwrap_or_else(|_| CellInfo {
            axes: vec!["x".into(), "y".into()],
            ..CellInfo::default()
        });
        let _ = file.decode(&cell, true);
    }
    let _ = reader::read_summary(data);
    for (op, body) in RecordWalker::new(data, mcap::MAGIC.len()).map_while(Result::ok) {
        if let Ok(Record::Chunk { header, data }) = parse_record(op, body) {
            if let Ok(inner) = chunk_records(&header, &data) {
                for (op, body) in RecordWalker::new(&inner, 0).map_while(Result::ok) {
                    let _ = parse_record(op, body);
                }
            }
        }
    }
}
