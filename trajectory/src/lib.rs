//! Units, scaling and jerk-limited multi-axis planning for cellrt.
//!
//! The non-RT side converts user units to drive counts ([`units`]), checks per-move limits
//! against the axis configuration ([`limits`]), plans a time-synchronised jerk-limited move
//! with `rsruckig` ([`planner`]) and turns it into one setpoint per bus cycle ([`sampler`]).
//! Planning allocates; evaluating a planned move ([`PlannedMove::state_at`],
//! [`MoveSampler::fill`]) does not.

#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod axis;
pub mod limits;
pub mod line;
pub mod online;
pub mod planner;
pub mod sampler;
pub mod torque;
pub mod units;
mod verify;
pub mod waypoints;

pub use axis::{AxisState, MoveAxis};
pub use limits::{KinematicLimits, LimitsError, PositionRange, Quantity};
pub use line::{LineError, LineMove};
pub use online::{AxisGoal, OnlineAxis, OnlineError, OnlineMotion};
pub use planner::{plan_move, PlanError, PlannedMove, MAX_MOVE_AXES};
pub use sampler::{MoveSampler, SamplerError};
pub use torque::{TorqueRamp, TorqueRampError};
pub use units::{Scaling, UnitsError};
pub use waypoints::{plan_waypoints, MAX_WAYPOINTS};
