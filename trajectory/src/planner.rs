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
use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::limits::{KinematicLimits, LimitsError, PositionRange, Quantity};
use crate::verify::{polish_end_state, verify_axis, Violation};

/// Most axes one move plans at once (the fixed capacity of a [`PlannedMove`]'s targets).
pub const MAX_MOVE_AXES: usize = 16;

/// Cycle time handed to rsruckig. It only matters for discrete duration rounding and for
/// `update()`, neither of which is used: moves are continuous-time and sampled by
/// [`crate::sampler::MoveSampler`].
const RUCKIG_DELTA_TIME: f64 = 1e-3;

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
    /// An axis' limits failed [`KinematicLimits::validate`].
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
    /// Every plan rsruckig produced (including the fallbacks of [`plan_move`]) exceeds a
    /// limit; reported for the first plan.
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

/// A planned move: all axes start at their start state and reach their targets at rest
/// together after [`PlannedMove::duration`] seconds.
#[derive(Debug, Clone)]
pub struct PlannedMove {
    trajectory: Trajectory<0>,
    axis_count: usize,
    targets: [f64; MAX_MOVE_AXES],
}

/// Minimum durations, as factors of the first plan's duration, tried (time-synchronised)
/// when the first plan fails the limit check (`verify::verify_axis`).
const RETRY_DURATION_FACTORS: [f64; 3] = [1.0 + 1e-6, 1.0 + 1e-4, 1.0 + 1e-2];

/// Plans a time-synchronised, jerk-limited move of `axes` to rest at their targets.
///
/// rsruckig's result is post-processed (see `verify.rs` for the finding and the checks):
/// every phase of every axis is checked against the limits, then each axis' profile is
/// polished so that it ends at its target to rounding — rsruckig tolerates an end-position
/// error of up to 1e-8, which the exact end state would turn into a position step (a jerk
/// spike) in the last cycle — and the polished profile is kept if it passes the same check.
/// If the check of rsruckig's own plan fails, the move is re-planned, in this order, until
/// one passes:
///
/// 1. time-synchronised with `minimum_duration` = 1 + 1e-6, 1 + 1e-4, 1 + 1e-2 times the
///    first plan's duration;
/// 2. phase-synchronised (rsruckig falls back to time synchronisation where phase
///    synchronisation is impossible);
/// 3. every axis planned on its own (no synchronisation between axes) with the longest
///    duration of (1) as its minimum duration, so all still end together.
///
/// If none passes: [`PlanError::LimitViolation`] for the first plan's violation. A plan that
/// violates a limit is never returned.
///
/// Allocates (rsruckig dynamic-DoF mode); call it off the RT thread.
pub fn plan_move(axes: &[MoveAxis]) -> Result<PlannedMove, PlanError> {
    validate(axes)?;
    let n = axes.len();
    let mut input = ruckig_input(axes);
    let mut targets = [0.0; MAX_MOVE_AXES];
    for (slot, axis) in targets.iter_mut().zip(axes) {
        *slot = axis.target;
    }

    let mut trajectory = calculate(&input)?;
    let first = match finish(&mut trajectory, axes) {
        Ok(()) => return Ok(PlannedMove::new(trajectory, n, targets)),
        Err(v) => v,
    };

    // 1. Slightly longer, still time-synchronised.
    let base = trajectory.get_duration();
    let mut longest = base;
    for factor in RETRY_DURATION_FACTORS {
        input.minimum_duration = Some(base * factor);
        if let Some(t) = attempt(&input, axes) {
            return Ok(PlannedMove::new(t, n, targets));
        }
        longest = base * factor;
    }
    // 2. Phase synchronisation.
    input.minimum_duration = None;
    input.synchronization = Synchronization::Phase;
    if let Some(t) = attempt(&input, axes) {
        return Ok(PlannedMove::new(t, n, targets));
    }
    // 3. Each axis on its own, all stretched to the longest duration tried.
    if let Some(t) = attempt_per_axis(axes, longest) {
        return Ok(PlannedMove::new(t, n, targets));
    }
    Err(PlanError::LimitViolation {
        axis: first.axis,
        quantity: first.quantity,
        value: first.value,
        limit: first.limit,
    })
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

/// One fallback plan: `Some` if rsruckig plans it and it passes [`finish`].
fn attempt(input: &InputParameter<0>, axes: &[MoveAxis]) -> Option<Trajectory<0>> {
    let mut trajectory = calculate(input).ok()?;
    finish(&mut trajectory, axes).ok()?;
    Some(trajectory)
}

/// Last fallback: plans each axis alone (no synchronisation between axes: the equivalent of
/// per-axis `Synchronization::None`), each stretched to `minimum_duration` (a one-DoF
/// time-synchronised plan; rsruckig ignores `minimum_duration` for a `None` DoF), and
/// combines the profiles into one trajectory (its duration is the longest axis duration).
fn attempt_per_axis(axes: &[MoveAxis], minimum_duration: f64) -> Option<Trajectory<0>> {
    let n = axes.len();
    let mut combined = Trajectory::<0>::new(Some(n));
    let mut duration = 0.0_f64;
    for (i, axis) in axes.iter().enumerate() {
        let mut input = ruckig_input(core::slice::from_ref(axis));
        input.minimum_duration = Some(minimum_duration);
        let single = calculate(&input).ok()?;
        if single.profiles.len() != 1 {
            return None;
        }
        combined.profiles[0][i] = single.profiles[0][0];
        combined.independent_min_durations[i] = single.independent_min_durations[0];
        duration = duration.max(single.get_duration());
    }
    combined.duration = duration;
    combined.cumulative_times[0] = duration;
    finish(&mut combined, axes).ok()?;
    Some(combined)
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
    fn per_axis_fallback_is_synchronised_and_exact() {
        let axes = [
            axis(1.0),
            MoveAxis {
                start: AxisState {
                    position: 0.5,
                    velocity: 0.3,
                    acceleration: -1.0,
                },
                target: -0.2,
                limits: L,
            },
        ];
        let normal = plan_move(&axes).unwrap();
        let t = attempt_per_axis(&axes, normal.duration() * 1.01).unwrap();
        let m = PlannedMove::new(
            t,
            2,
            [
                1.0, -0.2, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
            ],
        );
        let d = m.duration();
        assert!((d - normal.duration() * 1.01).abs() < 1e-9, "{d}");
        let mut s = [AxisState::default(); 2];
        m.state_at(0.0, &mut s);
        assert_eq!(s[1], axes[1].start);
        m.state_at(d * (1.0 - 1e-12), &mut s);
        assert!(
            (s[0].position - 1.0).abs() < 1e-9 && (s[1].position + 0.2).abs() < 1e-9,
            "{s:?}"
        );
        for p in m.trajectory.profiles[0].iter() {
            // Both axes are stretched to the common duration.
            assert!((p.brake.duration + p.t_sum[6] - d).abs() < 1e-9);
        }
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
