//! The EtherCAT MainDevice side: links (in-process, raw socket) and the bus.

mod al_state;
mod bring_up;
pub mod bus;
mod carrier;
pub mod commission;
mod cyclic;
mod dc;
pub mod diag;
mod diag_read;
mod dictionary;
mod error;
mod group;
pub mod link;
mod mailbox;
mod notices;
mod od_walk;
mod pdo_config;
mod process_image;
mod pump;
mod refusal;
pub mod scan;
mod sdo;
mod sdo_slot;
mod segment;
mod worker;

pub use bus::EthercatBus;
pub use dc::SYNC0_FRAME_PHASE_DIVISOR;
pub use diag::{BusDiagnostics, PortDiag, SegmentDiag, SubDeviceDiag};
pub use dictionary::{DictionaryReader, DictionaryReading, NoSdoInformation};
pub use error::EthercatError;
pub use link::{Link, LinkError, RawSocketLink, Retrying, DEFAULT_FRAME_TIMEOUT};
pub use refusal::{
    abort_meaning, fitting_causes, BringUpWarning, RefusedSdo, StateRefusal, OPTIONAL_OBJECT_ABORTS,
};
pub use sdo::object_type;
pub use segment::{AmplifierSlot, SegmentConfig, SegmentDrive, SegmentStation, StartupSdo};
