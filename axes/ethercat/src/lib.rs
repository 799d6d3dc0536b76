//! EtherCAT for cellrt: the wire format, the ESC registers, the drive identities, the MainDevice
//! backend (ethercrab for bring-up, cellrt's own cyclic frame in OP) and ESI import.
//!
//! The master's mailbox worker thread (`master::worker`, `cellrt-mailbox`) is started here, by
//! the layer that owns it, when a segment enters OP.

#![warn(missing_docs)]

pub mod emergency;
pub mod esi;
pub mod frame;
pub mod identity;
pub mod master;
pub mod raw_socket;
pub mod register;
