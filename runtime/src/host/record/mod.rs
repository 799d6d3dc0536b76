//! Recording to MCAP: the protobuf schema, topic names, and the non-RT recorder thread that
//! drains the RT thread's hand-off queues.

pub mod capture;
mod describe;
pub mod proto;
mod recorder;
pub mod topics;

pub use recorder::{
    channel_ids, channel_specs, part_path, ChannelSpec, Recorder, RecorderError, RecordingInfo,
    EVENT_LOG_LINES, MAX_CHUNKS_PER_FILE,
};
