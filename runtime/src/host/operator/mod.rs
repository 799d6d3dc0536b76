//! The operator interface: an iceoryx2 request-response service per cell through which the CLI
//! and other processes power, move, halt, stop, reset and query the cell, with a wake-up event
//! and a status publisher (all three named and built in [`crate::services`]). Requests, replies
//! and the status are JSON ([`wire`]). Users other than the cell's own reach it through its
//! operator [`socket`], where the cell's `[operator] group` lets them.

mod alarms;
pub mod backend;
pub mod bus_diag;
pub mod client;
mod param;
pub mod sdo;
mod sdo_job;
pub mod sdo_list;
pub mod server;
pub mod socket;
mod socket_client;
mod targets;
pub mod wire;

/// How often the operator status is published.
pub const STATUS_PERIOD: std::time::Duration = std::time::Duration::from_millis(100);
