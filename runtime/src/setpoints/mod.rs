//! Setpoint blocks: the fixed-size payload the planner publishes and the RT thread consumes.

mod block;
mod stream;

pub use block::{AxisSetpoint, SetpointBlock, BLOCK_CYCLES, FLAG_LAST, MAX_AXES};
pub use stream::{SetpointStream, StreamError};
