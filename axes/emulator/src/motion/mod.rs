//! The motion of every emulated drive, one implementation for the simulated EtherCAT drives
//! (`sim::drive`) and the emulated MR-JE-C (`mr_je_c`): the velocity ramp (`ramp`), the
//! trapezoid generator and its braking curves (`generator`), the profile position set-point
//! handshake (`profile_position`), profile velocity (`profile_velocity`), the torque slope of
//! profile torque (`profile_torque`), the homing start and the searching homing methods
//! (`homing`, `homing_search`), the S-pattern filter of [Pr. PC03] (`s_pattern`) and the
//! window times of the status bits (`window_time`). Where
//! the models differ, the difference is a named parameter citing the manual; units are the
//! caller's (plant counts or the MR-JE-C's pos units). Allocation-free in steady state.

pub mod generator;
pub mod homing;
pub mod homing_search;
pub mod profile_position;
pub mod profile_torque;
pub mod profile_velocity;
pub mod ramp;
pub(crate) mod s_pattern;
pub mod window_time;
