//! MR-JE-C axes in a cell: one exchange per link period on a non-RT thread per axis, the same
//! over every transport ([`io::DriveIo`]), the controller's power sequence, profile jobs and
//! communication watchdog ([`control::AxisControl`]).

pub mod control;
pub mod io;
pub mod positioning_link;
pub mod thread;

pub use control::{
    AxisCommand, AxisControl, PositioningMode, StopReaction, Stopped, HOMING_ERROR, JOG_REVERSE,
};
pub use io::{
    uncommanded_rww, CyclicDriveIo, DeviceTable, DriveIo, ExchangeError, Inputs, ObjectIo, Outputs,
};
pub use positioning_link::{PositioningCommand, PositioningFeedback};
pub use thread::{AxisFeedback, AxisHandle, AxisThread, ExchangeRecord, StartError};
