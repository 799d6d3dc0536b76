//! MCAP recordings as `inspect`, `report`, `replay` and `recover` read them.

use std::path::Path;

use cellrt_recording::{
    chunk_records, parse_record, read_summary, CellInfo, RecFile, RecordWalker,
};
use mcap::records::Record;

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
    let _ = read_summary(data);
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
