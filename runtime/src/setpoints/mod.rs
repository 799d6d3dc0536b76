//! Setpoint blocks: what the planner publishes and the RT thread consumes (its RT end is
//! [`crate::rt::setpoint_stream`]).

mod block;

pub use block::{
    AxisSetpoint, SetpointBlock, SetpointHeader, BLOCK_CYCLES, FLAG_LAST, FLAG_TORQUE, MAX_AXES,
    MAX_START_CYCLE,
};
