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

// The drive's profile generators live in the shared `motion` module; these paths stay for the
// runtime and the test vectors that name them.
pub use crate::motion::{homing_search, profile_position, profile_torque, profile_velocity};
