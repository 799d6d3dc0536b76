//! The Ethernet and serial field buses of the MR-JE-C: Modbus/TCP and RTU, SLMP, CC-Link IE
//! Field Basic, the MR-JE-C's object dictionary and typed object access over them, and the
//! controller's side of an MR-JE-C axis (`mr_je_c::cell`, whose I/O thread it starts).

#![warn(missing_docs)]

pub mod cclink_ief_basic;
pub mod modbus;
pub mod mr_je_c;
mod reply_read;
pub mod slmp;
