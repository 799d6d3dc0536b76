//! The EtherCAT MainDevice side: links (in-process, raw socket) and the bus.

pub mod bus;
pub mod link;

pub use bus::{
    AmplifierSlot, EthercatBus, EthercatError, SegmentConfig, SegmentDrive, SegmentStation,
};
pub use link::{InProcessLink, Link, LinkError, RawSocketLink};
