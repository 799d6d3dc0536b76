//! SLMP (binary 3E and 4E frames) as the MR-JE-C speaks it (MR-JE-C manual §2.4): CiA 402 object
//! access through command 4020h (SDO upload / download, sub-index block upload / download) and
//! the model code read 0101h, over UDP 5010 or TCP 5012, and NodeSearch / IPAddressSet
//! ([`node_search`]) on UDP 61451. Both ends use these codecs: the
//! controller's client and the drive emulator. No maintained crate covers SLMP; the frame is
//! small and table-driven here.

pub mod client;
pub mod discovery;
mod end_code;
mod frame;
mod monitoring;
pub mod node_search;

pub use end_code::EndCode;
pub use frame::{
    decode_request, decode_response, encode_request, encode_response, Command, Reply, Request,
    Response, Route, SlmpError, Subheader, MAX_FRAME,
};
pub use monitoring::{monitoring_timer_expires, monitoring_timer_for, MONITORING_TIMER_UNIT};

/// UDP port of the drive's SLMP server.
pub const UDP_PORT: u16 = 5010;
/// TCP port of the drive's SLMP server (one connection).
pub const TCP_PORT: u16 = 5012;
