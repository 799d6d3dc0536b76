//! The simulated servo drive: a mechanical plant under a cascaded servo loop (`plant`) and the
//! drive firmware around it (`drive`: PDS, modes, alarms, PDO images).

pub mod comm;
pub mod drive;
pub mod fsoe;
pub mod home_setting;
pub mod homing_switches;
pub mod plant;
pub mod sdo;
mod sdo_abort;
