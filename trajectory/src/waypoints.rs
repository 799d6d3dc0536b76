//! Waypoint sequences: one jerk-limited move from rest through intermediate positions to a
//! target at rest, planned offline by rsruckig's waypoint calculator (never the official
//! `ruckig` crate, which sends waypoint problems to a cloud service; docs/architecture.md).

use rsruckig::prelude::{Ruckig, RuckigResult, ThrowErrorHandler, Trajectory};

use crate::axis::{AxisState, MoveAxis};
use crate::planner::{ruckig_input, PlanError, PlannedMove, MAX_MOVE_AXES};
use crate::verify::verify_axis;

/// Most intermediate positions of one waypoint move.
pub const MAX_WAYPOINTS: usize = 64;

/// Plans a move of `axes` (start state, final target, limits) through `via` (one position per
/// axis each, in order). Every section of the plan is checked against the limits; a plan that
/// violates one is refused. Allocates; off the RT thread.
pub fn plan_waypoints(axes: &[MoveAxis], via: &[Vec<f64>]) -> Result<PlannedMove, PlanError> {
    let n = axes.len();
    if n == 0 {
        return Err(PlanError::Empty);
    }
    if n > MAX_MOVE_AXES {
        return Err(PlanError::TooManyAxes {
            count: n,
            max: MAX_MOVE_AXES,
        });
    }
    if via.len() > MAX_WAYPOINTS {
        return Err(PlanError::TooManyWaypoints {
            count: via.len(),
            max: MAX_WAYPOINTS,
        });
    }
    for (w, point) in via.iter().enumerate() {
        if point.len() != n {
            return Err(PlanError::WaypointShape {
                waypoint: w,
                got: point.len(),
                axes: n,
            });
        }
        if let Some((axis, &value)) = point.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(PlanError::NonFiniteTarget { axis, value });
        }
    }
    let mut targets = [0.0; MAX_MOVE_AXES];
    for (i, a) in axes.iter().enumerate() {
        if !a.target.is_finite() {
            return Err(PlanError::NonFiniteTarget {
                axis: i,
                value: a.target,
            });
        }
        let s: AxisState = a.start;
        if !(s.position.is_finite() && s.velocity.is_finite() && s.acceleration.is_finite()) {
            return Err(PlanError::NonFiniteStart { axis: i, state: s });
        }
        a.limits
            .validate()
            .map_err(|source| PlanError::InvalidLimits { axis: i, source })?;
        targets[i] = a.target;
    }
    let mut input = ruckig_input(axes);
    for point in via {
        let mut p = rsruckig::util::DataArrayOrVec::new(Some(n), 0.0);
        for (i, v) in point.iter().enumerate() {
            p[i] = *v;
        }
        input.intermediate_positions.push(p);
    }
    let mut otg = Ruckig::<0, ThrowErrorHandler>::with_waypoints(Some(n), 1e-3, via.len());
    let mut trajectory = Trajectory::<0>::new(Some(n));
    match otg.calculate(&input, &mut trajectory)? {
        RuckigResult::Working | RuckigResult::Finished => {}
        other => return Err(PlanError::RuckigResult(other)),
    }
    let duration = trajectory.get_duration();
    if !(duration.is_finite() && duration >= 0.0) {
        return Err(PlanError::BadDuration(duration));
    }
    for section in &trajectory.profiles {
        for (i, (profile, axis)) in section.iter().zip(axes).enumerate() {
            verify_axis(i, profile, axis)?;
        }
    }
    Ok(PlannedMove::new(trajectory, n, targets))
}
