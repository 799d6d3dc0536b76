//! Online motion of a whole cell: rsruckig's `update()` stepped once per bus cycle, with the
//! goal of each axis changeable at any cycle (re-targeting, jogging, halting, feed override).
//!
//! Every change starts from the current position, velocity and acceleration of every axis, so
//! no quantity steps (rsruckig recalculates from the state of the last cycle). Each axis has a
//! goal: a position to reach at rest (position interface) or a velocity to hold (velocity
//! interface). Axes named together by one command are time-synchronised; the others keep their
//! own goal and finish it time-optimally.
//!
//! Allocates on construction only; [`OnlineMotion::step`] recalculates (without allocating in
//! rsruckig's dynamic-DoF mode after the first call) when a goal changed. Non-RT.

use rsruckig::prelude::{
    ControlInterface, InputParameter, OutputParameter, Ruckig, RuckigResult, Synchronization,
    ThrowErrorHandler,
};
use thiserror::Error;

use crate::axis::AxisState;
use crate::limits::{KinematicLimits, LimitsError, PositionRange};

/// Cycles of travel at the current velocity kept in reserve when a jog is turned into a stop
/// at the end of the position range (covers the setpoint lookahead of the caller).
pub const JOG_RANGE_RESERVE_CYCLES: f64 = 4.0;

/// Relative distance to a position target below which a sample is the target (numerical
/// noise of the profile evaluation, far below any encoder resolution).
pub const POLISH_TOLERANCE: f64 = 1e-9;

/// One axis as the online motion sees it: its limits and its position range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OnlineAxis {
    /// Axis limits; per-command limits must not exceed them.
    pub limits: KinematicLimits,
    /// Software position range; targets outside are refused, jogs stop at its ends.
    pub range: PositionRange,
}

/// What an axis is doing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AxisGoal {
    /// Reach this position at rest (and stay there).
    Position(f64),
    /// Hold this velocity (a jog, or zero: a halt).
    Velocity(f64),
}

/// A command the online motion refused; nothing changed.
#[derive(Debug, Error, PartialEq)]
pub enum OnlineError {
    /// No such axis index.
    #[error("axis index {0} does not exist")]
    UnknownAxis(usize),
    /// A target or velocity is NaN or infinite.
    #[error("axis {axis}: {what} {value} is not finite")]
    NotFinite {
        /// Axis index.
        axis: usize,
        /// Which value.
        what: &'static str,
        /// The value.
        value: f64,
    },
    /// A target is outside the axis range, or a limit is invalid or above the axis limit.
    #[error("axis {axis}: {source}")]
    Limits {
        /// Axis index.
        axis: usize,
        /// What is wrong.
        #[source]
        source: LimitsError,
    },
    /// A jog velocity above the axis velocity limit.
    #[error("axis {axis}: velocity {velocity} exceeds the axis limit {limit}")]
    VelocityAboveLimit {
        /// Axis index.
        axis: usize,
        /// Requested |velocity|.
        velocity: f64,
        /// Axis limit.
        limit: f64,
    },
    /// A feed override outside [0, 1].
    #[error("override {0} is outside 0..=1 (0–100 %)")]
    Override(f64),
    /// rsruckig refused the input or failed.
    #[error("rsruckig: {0}")]
    Ruckig(String),
}

/// The online motion of a cell's axes (in axis units).
pub struct OnlineMotion {
    otg: Ruckig<0, ThrowErrorHandler>,
    input: InputParameter<0>,
    output: OutputParameter<0>,
    axes: Vec<OnlineAxis>,
    goals: Vec<AxisGoal>,
    limits: Vec<KinematicLimits>,
    synchronised: Vec<bool>,
    feed_override: f64,
    period: f64,
    finished: bool,
}

impl OnlineMotion {
    /// An online motion of `axes` sampled every `period` seconds, at rest at `positions`.
    pub fn new(axes: Vec<OnlineAxis>, period: f64, positions: &[f64]) -> OnlineMotion {
        let n = axes.len();
        let mut m = OnlineMotion {
            otg: Ruckig::new(Some(n), period),
            input: InputParameter::new(Some(n)),
            output: OutputParameter::new(Some(n)),
            goals: vec![AxisGoal::Position(0.0); n],
            limits: axes.iter().map(|a| a.limits).collect(),
            synchronised: vec![false; n],
            axes,
            feed_override: 1.0,
            period,
            finished: true,
        };
        m.input.synchronization = Synchronization::Time;
        m.input.per_dof_control_interface = Some(rsruckig::util::DataArrayOrVec::new(
            Some(n),
            ControlInterface::Position,
        ));
        m.input.per_dof_synchronization = Some(rsruckig::util::DataArrayOrVec::new(
            Some(n),
            Synchronization::None,
        ));
        m.reset(positions);
        m
    }

    /// Puts every axis at rest at `positions` with a hold goal (a new motion starts here).
    pub fn reset(&mut self, positions: &[f64]) {
        for (i, &p) in positions.iter().enumerate().take(self.axes.len()) {
            self.input.current_position[i] = p;
            self.input.current_velocity[i] = 0.0;
            self.input.current_acceleration[i] = 0.0;
            self.goals[i] = AxisGoal::Position(p);
            self.limits[i] = self.axes[i].limits;
            self.synchronised[i] = false;
        }
        self.otg.reset();
        self.finished = true;
        self.apply_goals();
    }

    /// Takes over a motion planned elsewhere at its current `states` (each axis then holds
    /// where it is until given a goal: call [`OnlineMotion::halt`] or
    /// [`OnlineMotion::move_to`] next to brake or re-target smoothly).
    pub fn continue_from(&mut self, states: &[AxisState]) {
        for (i, s) in states.iter().enumerate().take(self.axes.len()) {
            self.input.current_position[i] = s.position;
            self.input.current_velocity[i] = s.velocity;
            self.input.current_acceleration[i] = s.acceleration;
            self.goals[i] = AxisGoal::Position(s.position);
            self.limits[i] = self.axes[i].limits;
            self.synchronised[i] = false;
        }
        self.otg.reset();
        self.finished = false;
        self.apply_goals();
    }

    /// Number of axes.
    pub fn axis_count(&self) -> usize {
        self.axes.len()
    }

    /// The state the last [`OnlineMotion::step`] reached (or the reset state).
    pub fn state(&self, axis: usize) -> AxisState {
        AxisState {
            position: self.input.current_position[axis],
            velocity: self.input.current_velocity[axis],
            acceleration: self.input.current_acceleration[axis],
        }
    }

    /// The goal of `axis`.
    pub fn goal(&self, axis: usize) -> AxisGoal {
        self.goals[axis]
    }

    /// The feed override in effect (0..=1).
    pub fn feed_override(&self) -> f64 {
        self.feed_override
    }

    /// Moves the named axes to their targets, time-synchronised, with per-axis limits (each
    /// checked against the axis limits: an excess is refused, never clamped). Axes not named
    /// keep their goals. Checks everything before changing anything.
    pub fn move_to(
        &mut self,
        targets: &[(usize, f64, KinematicLimits)],
    ) -> Result<(), OnlineError> {
        for &(axis, target, limits) in targets {
            let a = self.axis(axis)?;
            if !target.is_finite() {
                return Err(OnlineError::NotFinite {
                    axis,
                    what: "target",
                    value: target,
                });
            }
            limits
                .capped_by(&a.limits)
                .and_then(|_| a.range.check(target))
                .map_err(|source| OnlineError::Limits { axis, source })?;
        }
        for s in &mut self.synchronised {
            *s = false;
        }
        for &(axis, target, limits) in targets {
            self.goals[axis] = AxisGoal::Position(target);
            self.limits[axis] = limits;
            self.synchronised[axis] = targets.len() > 1;
        }
        self.finished = false;
        self.apply_goals();
        Ok(())
    }

    /// Jogs `axis` at `velocity` (signed), ramping with `limits`; the jog stops by itself at the
    /// end of the position range. A velocity above the limit is refused, never clamped.
    pub fn jog(
        &mut self,
        axis: usize,
        velocity: f64,
        limits: KinematicLimits,
    ) -> Result<(), OnlineError> {
        let a = self.axis(axis)?;
        if !velocity.is_finite() {
            return Err(OnlineError::NotFinite {
                axis,
                what: "velocity",
                value: velocity,
            });
        }
        limits
            .capped_by(&a.limits)
            .map_err(|source| OnlineError::Limits { axis, source })?;
        if velocity.abs() > a.limits.velocity {
            return Err(OnlineError::VelocityAboveLimit {
                axis,
                velocity: velocity.abs(),
                limit: a.limits.velocity,
            });
        }
        self.goals[axis] = AxisGoal::Velocity(velocity);
        self.limits[axis] = KinematicLimits {
            velocity: a.limits.velocity,
            ..limits
        };
        self.synchronised[axis] = false;
        self.finished = false;
        self.apply_goals();
        Ok(())
    }

    /// Halts the given axes (all when `None`): each brakes to rest with its current limits and
    /// then holds where it stopped.
    pub fn halt(&mut self, axes: Option<&[usize]>) -> Result<(), OnlineError> {
        if let Some(list) = axes {
            for &a in list {
                self.axis(a)?;
            }
        }
        for i in 0..self.axes.len() {
            if axes.is_none_or(|l| l.contains(&i)) {
                self.goals[i] = AxisGoal::Velocity(0.0);
                self.synchronised[i] = false;
            }
        }
        self.finished = false;
        self.apply_goals();
        Ok(())
    }

    /// Sets the feed override (0..=1): scales the velocity limit of every goal from the current
    /// state on (rsruckig brakes or speeds up within the acceleration and jerk limits); 0 holds
    /// every axis (feed hold) until the override is raised again.
    pub fn set_override(&mut self, value: f64) -> Result<(), OnlineError> {
        if !(value.is_finite() && (0.0..=1.0).contains(&value)) {
            return Err(OnlineError::Override(value));
        }
        self.feed_override = value;
        if !self.is_done() {
            self.finished = false;
        }
        self.apply_goals();
        Ok(())
    }

    /// Whether every axis has reached its goal and stands still (a halt has ended in a hold).
    pub fn is_done(&self) -> bool {
        self.finished
            && self.feed_override > 0.0
            && self
                .goals
                .iter()
                .all(|g| matches!(g, AxisGoal::Position(_)))
    }

    /// Advances one period and writes the new state of every axis to `out`.
    pub fn step(&mut self, out: &mut [AxisState]) -> Result<(), OnlineError> {
        self.protect_range();
        let result = self
            .otg
            .update(&self.input, &mut self.output)
            .map_err(|e| OnlineError::Ruckig(e.to_string()))?;
        match result {
            RuckigResult::Working | RuckigResult::Finished => {}
            other => return Err(OnlineError::Ruckig(format!("{other:?}"))),
        }
        self.output.pass_to_input(&mut self.input);
        self.finished = result == RuckigResult::Finished;
        if self.finished {
            self.settle();
        }
        for (i, o) in out.iter_mut().enumerate().take(self.axes.len()) {
            *o = self.state(i);
        }
        self.polish(out);
        Ok(())
    }

    fn axis(&self, axis: usize) -> Result<OnlineAxis, OnlineError> {
        self.axes
            .get(axis)
            .copied()
            .ok_or(OnlineError::UnknownAxis(axis))
    }

    /// A finished halt (velocity zero reached) becomes a hold where the axis stopped; a finished
    /// position goal is snapped to its exact target.
    fn settle(&mut self) {
        let mut changed = false;
        for i in 0..self.axes.len() {
            match self.goals[i] {
                AxisGoal::Velocity(0.0) => {
                    self.goals[i] = AxisGoal::Position(self.input.current_position[i]);
                    self.input.current_velocity[i] = 0.0;
                    self.input.current_acceleration[i] = 0.0;
                    changed = true;
                }
                AxisGoal::Position(p) if self.feed_override > 0.0 => {
                    self.input.current_position[i] = p;
                    self.input.current_velocity[i] = 0.0;
                    self.input.current_acceleration[i] = 0.0;
                }
                _ => {}
            }
        }
        if changed {
            self.apply_goals();
        }
    }

    /// Removes floating-point noise at a position target from the samples handed out (rsruckig's
    /// last working sample may pass a target by ~1e-15): a position within
    /// [`POLISH_TOLERANCE`] of its target is the target, so a target at the end of the range
    /// never leaves the range by noise. rsruckig's own state is left as it computed it (an
    /// edited state would make it recalculate from a degenerate input).
    fn polish(&self, out: &mut [AxisState]) {
        for (o, goal) in out.iter_mut().zip(&self.goals) {
            if let AxisGoal::Position(target) = *goal {
                if (o.position - target).abs() <= POLISH_TOLERANCE * target.abs().max(1.0) {
                    o.position = target;
                }
            }
        }
    }

    /// Turns a jog into a stop at the end of the range once its braking distance (plus a
    /// reserve of [`JOG_RANGE_RESERVE_CYCLES`]) reaches it.
    fn protect_range(&mut self) {
        let mut changed = false;
        for i in 0..self.axes.len() {
            let AxisGoal::Velocity(v) = self.goals[i] else {
                continue;
            };
            let vel = self.input.current_velocity[i];
            let dir = if vel.abs() > 0.0 {
                vel.signum()
            } else {
                v.signum()
            };
            if dir == 0.0 {
                continue;
            }
            let l = self.limits[i];
            let acc = self.input.current_acceleration[i].abs();
            // Upper bound of the braking time from (v, a): shed a, ramp a up, decelerate.
            let t_brake = acc / l.jerk + vel.abs() / l.acceleration + l.acceleration / l.jerk;
            let reach = vel.abs() * (t_brake + JOG_RANGE_RESERVE_CYCLES * self.period);
            let pos = self.input.current_position[i];
            let range = self.axes[i].range;
            let end = if dir > 0.0 { range.max } else { range.min };
            if (end - pos) * dir <= reach {
                self.goals[i] = AxisGoal::Position(end);
                changed = true;
            }
        }
        if changed {
            self.apply_goals();
        }
    }

    /// Writes goals, limits and the override into rsruckig's input.
    fn apply_goals(&mut self) {
        let ov = self.feed_override;
        let any_sync = self.synchronised.iter().any(|s| *s);
        for i in 0..self.axes.len() {
            let l = self.limits[i];
            self.input.max_velocity[i] = (l.velocity * ov).max(f64::MIN_POSITIVE);
            self.input.max_acceleration[i] = l.acceleration;
            self.input.max_jerk[i] = l.jerk;
            self.input.target_acceleration[i] = 0.0;
            let (interface, target_velocity) = match self.goals[i] {
                _ if ov == 0.0 => (ControlInterface::Velocity, 0.0),
                AxisGoal::Position(p) => {
                    self.input.target_position[i] = p;
                    (ControlInterface::Position, 0.0)
                }
                AxisGoal::Velocity(v) => (ControlInterface::Velocity, v * ov),
            };
            self.input.target_velocity[i] = target_velocity;
            if let Some(ci) = self.input.per_dof_control_interface.as_mut() {
                ci[i] = interface;
            }
            if let Some(s) = self.input.per_dof_synchronization.as_mut() {
                s[i] = if any_sync && self.synchronised[i] {
                    Synchronization::Time
                } else {
                    Synchronization::None
                };
            }
        }
    }
}
