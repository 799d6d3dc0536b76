//! Generated protobuf types of `proto/cellrt.proto` and the descriptor set that MCAP stores as
//! each channel's schema (what Foxglove and the Python readers decode with).

#![allow(missing_docs)]

include!(concat!(env!("OUT_DIR"), "/cellrt.rs"));

/// The serialized `FileDescriptorSet` of `proto/cellrt.proto`.
pub const FILE_DESCRIPTOR_SET: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/cellrt.fds.bin"));
