//! Setpoint blocks: what the planner publishes and the RT thread consumes.

mod block;
mod stream;

pub use block::{
    AxisSetpoint, SetpointBlock, SetpointHeader, BLOCK_CYCLES, FLAG_LAST, FLAG_TORQUE, MAX_AXES,
};
pub use stream::{SetpointStream, SetpointSubscriber, StreamError};
