//! One axis of a move: its kinematic state and what a move asks of it (target and limits).
//!
//! Shared by the planner ([`crate::planner`]), the limit verification of its plans and the
//! online and line motions, so that none of them depends on another for these types.

use serde::{Deserialize, Serialize};

use crate::limits::{KinematicLimits, LimitsError, PositionRange};

/// Kinematic state of one axis, in axis units: unit, unit/s, unit/s².
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct AxisState {
    /// Position, unit.
    pub position: f64,
    /// Velocity, unit/s.
    pub velocity: f64,
    /// Acceleration, unit/s².
    pub acceleration: f64,
}

/// One axis of a move: where it is now, where it should stop, and the limits for this move.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MoveAxis {
    /// Current state (the move starts continuous with it; may be moving: re-targeting).
    pub start: AxisState,
    /// Target position, unit; the axis arrives at rest (velocity and acceleration zero).
    pub target: f64,
    /// Limits for this move (check them against the axis with [`KinematicLimits::capped_by`]).
    pub limits: KinematicLimits,
}

impl MoveAxis {
    /// Builds a move axis after checking `move_limits` against the axis' `axis_limits`
    /// ([`KinematicLimits::capped_by`]) and, if given, `target` against the axis' `range`.
    pub fn checked(
        start: AxisState,
        target: f64,
        move_limits: &KinematicLimits,
        axis_limits: &KinematicLimits,
        range: Option<&PositionRange>,
    ) -> Result<MoveAxis, LimitsError> {
        let limits = move_limits.capped_by(axis_limits)?;
        if let Some(range) = range {
            range.check(target)?;
        }
        Ok(MoveAxis {
            start,
            target,
            limits,
        })
    }
}
