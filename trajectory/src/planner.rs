//! Time-synchronised, jerk-limited multi-axis point-to-point planning with `rsruckig`.
//!
//! Planning (non-RT) allocates: rsruckig is used in its dynamic-DoF mode
//! (`Ruckig::<0, _>`), so the trajectory holds exactly the move's axes. Evaluating a
//! [`PlannedMove`] walks the stored profiles and does not allocate.

use rsruckig::prelude::{
    InputParameter, Ruckig, RuckigError, RuckigResult, Synchronization, ThrowErrorHandler,
    Trajectory,
};
use rsruckig::util::integrate;
use thiserror::Error;

use crate::axis::{AxisState, MoveAxis};
use crate::limits::{LimitsError, Quantity};
use crate::verify::{polish_end_state, verify_axis, Violation};

/// Most axes one move plans at once (the fixed capacity of a [`PlannedMove`]'s targets).
pub const MAX_MOVE_AXES: usize = 16;

/// Cycle time handed to rsruckig. It only matters for discrete duration rounding and for
/// `update()`, neither of which is used: moves are continuous-time and sampled by
/// [`crate::sampler::MoveSampler`].
const RUCKIG_DELTA_TIME: f64 = 1e-3;

/// Why a move could not be planned.
#[derive(Debug, Error)]
pub enum PlanError {
    /// No axes were given.
    #[error("a move needs at least one axis")]
    Empty,
    /// More axes than [`MAX_MOVE_AXES`].
    #[error("a move plans at most {max} axes at once, got {count}")]
    TooManyAxes {
        /// Axes given.
        count: usize,
        /// [`MAX_MOVE_AXES`].
        max: usize,
    },
    /// More intermediate positions than [`crate::waypoints::MAX_WAYPOINTS`].
    #[error("a waypoint move takes at most {max} waypoints, got {count}")]
    TooManyWaypoints {
        /// Waypoints given.
        count: usize,
        /// The maximum.
        max: usize,
    },
    /// A waypoint does not give one position per axis.
    #[error("waypoint {waypoint} has {got} positions for {axes} axes")]
    WaypointShape {
        /// Index of the waypoint.
        waypoint: usize,
        /// Positions it has.
        got: usize,
        /// Axes of the move.
        axes: usize,
    },
    /// A target position is NaN or infinite.
    #[error("axis {axis}: target position {value} is not finite")]
    NonFiniteTarget {
        /// Index of the axis in the move.
        axis: usize,
        /// The target.
        value: f64,
    },
    /// A start position, velocity or acceleration is NaN or infinite.
    #[error("axis {axis}: start state {state:?} is not finite")]
    NonFiniteStart {
        /// Index of the axis in the move.
        axis: usize,
        /// The start state.
        state: AxisState,
    },
    /// An axis' limits failed [`crate::limits::KinematicLimits::validate`].
    #[error("axis {axis}: {source}")]
    InvalidLimits {
        /// Index of the axis in the move.
        axis: usize,
        /// What is wrong with the limits.
        #[source]
        source: LimitsError,
    },
    /// rsruckig rejected the input or failed in its calculator.
    #[error("rsruckig rejected the move: {0}")]
    Ruckig(#[from] RuckigError),
    /// rsruckig returned an error result code instead of a trajectory.
    #[error("rsruckig could not plan the move: {0:?}")]
    RuckigResult(RuckigResult),
    /// rsruckig produced a trajectory whose duration is negative or not finite.
    #[error("planned duration {0} s is not finite and >= 0")]
    BadDuration(f64),
    /// rsruckig's plan exceeds a limit (the first violation found); the plan is refused.
    #[error("axis {axis}: planned {quantity} {value} {} exceeds the limit {limit} {}", quantity.unit(), quantity.unit())]
    LimitViolation {
        /// Index of the axis in the move.
        axis: usize,
        /// Which quantity.
        quantity: Quantity,
        /// The planned |value|.
        value: f64,
        /// The limit (including any allowance for a start state beyond it).
        limit: f64,
    },
}

impl From<Violation> for PlanError {
    fn from(v: Violation) -> Self {
        PlanError::LimitViolation {
            axis: v.axis,
            quantity: v.quantity,
            value: v.value,
            limit: v.limit,
        }
    }
}

/// A planned move: all axes start at their start state and reach their targets at rest
/// together after [`PlannedMove::duration`] seconds.
#[derive(Debug, Clone)]
pub struct PlannedMove {
    trajectory: Trajectory<0>,
    axis_count: usize,
    targets: [f64; MAX_MOVE_AXES],
}

/// Plans a time-synchronised, jerk-limited move of `axes` to rest at their targets.
///
/// rsruckig's plan is checked and post-processed (module `verify`): every phase of every axis
/// is checked against the limits, then each axis' profile is polished so that it ends at its
/// target to rounding — rsruckig tolerates an end-position error of up to 1e-8, which the
/// exact end state would turn into a position step (a jerk spike) in the last cycle — and the
/// polished profile is kept if it passes the same check. A plan that violates a limit is never
/// returned: [`PlanError::LimitViolation`]. That happens only for a start state outside the
/// move's limits (|a0|, |v0| or the velocity reached while ramping a0 to zero above them: a
/// moving axis re-targeted with lower limits), and re-planning such a move with a longer
/// duration, phase synchronisation or per axis does not find a plan within the limits either.
///
/// Allocates (rsruckig dynamic-DoF mode); call it off the RT thread.
pub fn plan_move(axes: &[MoveAxis]) -> Result<PlannedMove, PlanError> {
    validate(axes)?;
    let mut targets = [0.0; MAX_MOVE_AXES];
    for (slot, axis) in targets.iter_mut().zip(axes) {
        *slot = axis.target;
    }
    let mut trajectory = calculate(&ruckig_input(axes))?;
    finish(&mut trajectory, axes)?;
    Ok(PlannedMove::new(trajectory, axes.len(), targets))
}

/// rsruckig input for a time-synchronised move of `axes` to rest.
pub(crate) fn ruckig_input(axes: &[MoveAxis]) -> InputParameter<0> {
    let mut input = InputParameter::<0>::new(Some(axes.len()));
    input.synchronization = Synchronization::Time;
    for (i, axis) in axes.iter().enumerate() {
        input.current_position[i] = axis.start.position;
        input.current_velocity[i] = axis.start.velocity;
        input.current_acceleration[i] = axis.start.acceleration;
        input.target_position[i] = axis.target;
        input.target_velocity[i] = 0.0;
        input.target_acceleration[i] = 0.0;
        input.max_velocity[i] = axis.limits.velocity;
        input.max_acceleration[i] = axis.limits.acceleration;
        input.max_jerk[i] = axis.limits.jerk;
    }
    input
}

/// Runs rsruckig on `input` and checks its result code and duration.
fn calculate(input: &InputParameter<0>) -> Result<Trajectory<0>, PlanError> {
    let n = input.degrees_of_freedom;
    let mut otg = Ruckig::<0, ThrowErrorHandler>::new(Some(n), RUCKIG_DELTA_TIME);
    let mut trajectory = Trajectory::<0>::new(Some(n));
    match otg.calculate(input, &mut trajectory)? {
        RuckigResult::Working | RuckigResult::Finished => {}
        other => return Err(PlanError::RuckigResult(other)),
    }
    let duration = trajectory.get_duration();
    if !(duration.is_finite() && duration >= 0.0) {
        return Err(PlanError::BadDuration(duration));
    }
    Ok(trajectory)
}

/// Verifies every axis of `trajectory` against its limits, then polishes each axis' end
/// state ([`polish_end_state`]) and keeps the polished profile if it still passes. The
/// move's duration grows to the longest polished axis (by rounding-sized amounts; the other
/// axes hold their end state).
fn finish(trajectory: &mut Trajectory<0>, axes: &[MoveAxis]) -> Result<(), Violation> {
    if trajectory.profiles.len() != 1 {
        // Only waypoint moves have several sections; plan_move never asks for them.
        return Err(Violation {
            axis: 0,
            quantity: Quantity::Velocity,
            value: f64::NAN,
            limit: f64::NAN,
        });
    }
    let mut duration = trajectory.duration;
    for (i, (profile, axis)) in trajectory.profiles[0].iter_mut().zip(axes).enumerate() {
        verify_axis(i, profile, axis)?;
        let mut polished = *profile;
        if polish_end_state(&mut polished, axis.target) && verify_axis(i, &polished, axis).is_ok() {
            *profile = polished;
            duration = duration.max(profile.brake.duration + profile.t_sum[6]);
        }
    }
    trajectory.duration = duration;
    trajectory.cumulative_times[0] = duration;
    Ok(())
}

/// Checks the move's shape and every axis' numbers before handing them to rsruckig.
fn validate(axes: &[MoveAxis]) -> Result<(), PlanError> {
    if axes.is_empty() {
        return Err(PlanError::Empty);
    }
    if axes.len() > MAX_MOVE_AXES {
        return Err(PlanError::TooManyAxes {
            count: axes.len(),
            max: MAX_MOVE_AXES,
        });
    }
    for (axis, a) in axes.iter().enumerate() {
        if !a.target.is_finite() {
            return Err(PlanError::NonFiniteTarget {
                axis,
                value: a.target,
            });
        }
        let s = a.start;
        if !(s.position.is_finite() && s.velocity.is_finite() && s.acceleration.is_finite()) {
            return Err(PlanError::NonFiniteStart { axis, state: s });
        }
        a.limits
            .validate()
            .map_err(|source| PlanError::InvalidLimits { axis, source })?;
    }
    Ok(())
}

impl PlannedMove {
    pub(crate) fn new(
        trajectory: Trajectory<0>,
        axis_count: usize,
        targets: [f64; MAX_MOVE_AXES],
    ) -> Self {
        PlannedMove {
            trajectory,
            axis_count,
            targets,
        }
    }

    /// Duration of the move, s (the same for every axis).
    pub fn duration(&self) -> f64 {
        self.trajectory.get_duration()
    }

    /// Number of axes in the move.
    pub fn axis_count(&self) -> usize {
        self.axis_count
    }

    /// Target positions, one per axis, unit.
    pub fn targets(&self) -> &[f64] {
        &self.targets[..self.axis_count]
    }

    /// Writes the state of every axis at time `t` (s) into `out` and returns how many axes
    /// were written (`min(axis_count, out.len())`; extra `out` entries are left untouched).
    ///
    /// `t` is clamped to `[0, duration]` (NaN counts as 0). At `t >= duration` the state is
    /// exactly the target at rest. Does not allocate.
    pub fn state_at(&self, t: f64, out: &mut [AxisState]) -> usize {
        let n = self.axis_count.min(out.len());
        let out = &mut out[..n];
        let duration = self.duration();
        let t = if t.is_nan() { 0.0 } else { t.max(0.0) };
        if t >= duration {
            for (slot, &target) in out.iter_mut().zip(&self.targets) {
                *slot = AxisState {
                    position: target,
                    velocity: 0.0,
                    acceleration: 0.0,
                };
            }
            return n;
        }
        let mut section = 0;
        self.trajectory
            .state_to_integrate_from(t, &mut section, |dof, dt, p, v, a, j| {
                if let Some(slot) = out.get_mut(dof) {
                    let (position, velocity, acceleration) = integrate(dt, p, v, a, j);
                    *slot = AxisState {
                        position,
                        velocity,
                        acceleration,
                    };
                }
            });
        n
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::limits::KinematicLimits;

    const L: KinematicLimits = KinematicLimits {
        velocity: 1.0,
        acceleration: 5.0,
        jerk: 50.0,
    };

    fn axis(target: f64) -> MoveAxis {
        MoveAxis {
            start: AxisState::default(),
            target,
            limits: L,
        }
    }

    #[test]
    fn single_axis_rest_to_rest() {
        let m = plan_move(&[axis(1.0)]).unwrap();
        assert_eq!(m.axis_count(), 1);
        assert_eq!(m.targets(), &[1.0]);
        assert!(m.duration() > 1.0, "{}", m.duration()); // v_max = 1 unit/s
        let mut s = [AxisState::default(); 1];
        assert_eq!(m.state_at(0.0, &mut s), 1);
        assert_eq!(s[0], AxisState::default());
        m.state_at(m.duration() * 0.5, &mut s);
        assert!((s[0].position - 0.5).abs() < 1e-9, "{:?}", s[0]);
        m.state_at(f64::INFINITY, &mut s);
        assert_eq!(s[0].position, 1.0);
        m.state_at(-3.0, &mut s);
        assert_eq!(s[0].position, 0.0);
        m.state_at(f64::NAN, &mut s);
        assert_eq!(s[0].position, 0.0);
    }

    #[test]
    fn zero_length_move() {
        let m = plan_move(&[axis(0.0), axis(0.0)]).unwrap();
        assert_eq!(m.duration(), 0.0);
        let mut s = [AxisState::default(); 2];
        m.state_at(0.0, &mut s);
        assert_eq!(s, [AxisState::default(); 2]);
    }

    #[test]
    fn short_output_is_not_a_panic() {
        let m = plan_move(&[axis(1.0), axis(2.0), axis(3.0)]).unwrap();
        let mut s = [AxisState::default(); 2];
        assert_eq!(m.state_at(m.duration(), &mut s), 2);
        assert_eq!(s[1].position, 2.0);
        let mut big = [AxisState {
            position: 9.0,
            ..Default::default()
        }; 5];
        assert_eq!(m.state_at(0.1, &mut big), 3);
        assert_eq!(big[3].position, 9.0);
    }

    #[test]
    fn limit_violation_error_names_axis_and_quantity() {
        let err = PlanError::LimitViolation {
            axis: 1,
            quantity: Quantity::Jerk,
            value: 31.0,
            limit: 27.8,
        };
        let text = err.to_string();
        assert!(
            text.contains("axis 1") && text.contains("jerk") && text.contains("31"),
            "{text}"
        );
    }
}
