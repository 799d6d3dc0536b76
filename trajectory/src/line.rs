//! Coordinated straight-line moves of an axis group in Cartesian space (a gantry): the axes
//! follow `start + u·s(t)` with `u` the unit direction and `s` a jerk-limited path parameter,
//! so every sample lies on the line. The path limits are the largest for which no axis exceeds
//! its own: `v_path = min_i v_i / |u_i|` (likewise acceleration and jerk).
//!
//! The path parameter is itself an [`OnlineMotion`] of one degree of freedom, so a line can be
//! halted (it brakes along the line) and follows the feed override like any other motion.

use nalgebra::DVector;
use thiserror::Error;

use crate::axis::AxisState;
use crate::limits::{KinematicLimits, PositionRange};
use crate::online::{OnlineAxis, OnlineError, OnlineMotion};

/// Shortest line (in axis units) planned as a move; shorter ones are already there.
pub const MIN_LINE_LENGTH: f64 = 1e-9;

/// Why a line cannot be planned.
#[derive(Debug, Error, PartialEq)]
pub enum LineError {
    /// Start, end and limits must name the same number of axes (at least two).
    #[error("a line needs at least two axes with a start, an end and limits each (got {0})")]
    Shape(usize),
    /// A coordinate is NaN or infinite.
    #[error("axis {axis}: {what} {value} is not finite")]
    NotFinite {
        /// Index in the group.
        axis: usize,
        /// Start or end.
        what: &'static str,
        /// The value.
        value: f64,
    },
    /// A path velocity above what the axes allow along this line.
    #[error(
        "path velocity {requested} exceeds {limit}, the most every axis allows along this line"
    )]
    PathVelocity {
        /// Requested path velocity.
        requested: f64,
        /// The largest the axes allow.
        limit: f64,
    },
    /// The path parameter's motion refused (limits).
    #[error("path: {0}")]
    Path(#[from] OnlineError),
}

/// A straight-line move in progress.
pub struct LineMove {
    start: DVector<f64>,
    end: DVector<f64>,
    direction: DVector<f64>,
    length: f64,
    path: OnlineMotion,
    path_limits: KinematicLimits,
    state: AxisState,
}

impl LineMove {
    /// A line from `start` to `end` (at rest at both ends), no axis beyond its `limits`, the
    /// path speed at most `path_velocity` (refused above what the axes allow), sampled every
    /// `period` seconds.
    pub fn new(
        start: &[f64],
        end: &[f64],
        limits: &[KinematicLimits],
        path_velocity: Option<f64>,
        period: f64,
    ) -> Result<LineMove, LineError> {
        let n = start.len();
        if n < 2 || end.len() != n || limits.len() != n {
            return Err(LineError::Shape(n));
        }
        for (axis, (&s, &e)) in start.iter().zip(end).enumerate() {
            for (what, value) in [("start", s), ("end", e)] {
                if !value.is_finite() {
                    return Err(LineError::NotFinite { axis, what, value });
                }
            }
        }
        for l in limits {
            l.validate()
                .map_err(|source| LineError::Path(OnlineError::Limits { axis: 0, source }))?;
        }
        let start = DVector::from_column_slice(start);
        let end = DVector::from_column_slice(end);
        let delta = &end - &start;
        let length = delta.norm();
        let direction = if length > MIN_LINE_LENGTH {
            delta / length
        } else {
            DVector::zeros(n)
        };
        let mut path_limits = path_limits(&direction, limits);
        if let Some(v) = path_velocity {
            if !(v.is_finite() && v > 0.0) || v > path_limits.velocity * (1.0 + 1e-12) {
                return Err(LineError::PathVelocity {
                    requested: v,
                    limit: path_limits.velocity,
                });
            }
            path_limits.velocity = v.min(path_limits.velocity);
        }
        let path = OnlineMotion::new(
            vec![OnlineAxis {
                limits: path_limits,
                range: PositionRange {
                    min: 0.0,
                    max: length.max(MIN_LINE_LENGTH),
                },
            }],
            period,
            &[0.0],
        );
        let mut line = LineMove {
            start,
            end,
            direction,
            length,
            path,
            path_limits,
            state: AxisState::default(),
        };
        if length > MIN_LINE_LENGTH {
            line.path.move_to(&[(0, length, path_limits)])?;
        }
        Ok(line)
    }

    /// Length of the line, unit.
    pub fn length(&self) -> f64 {
        self.length
    }

    /// The path limits (the largest no axis exceeds).
    pub fn path_limits(&self) -> KinematicLimits {
        self.path_limits
    }

    /// Brakes along the line to rest; the move then ends where it stopped.
    pub fn halt(&mut self) {
        // One axis that exists: cannot fail.
        let _ = self.path.halt(None);
    }

    /// Feed override (0..=1) of the path speed.
    pub fn set_override(&mut self, value: f64) -> Result<(), LineError> {
        Ok(self.path.set_override(value)?)
    }

    /// Whether the path has come to rest at its end (or where a halt stopped it).
    pub fn is_done(&self) -> bool {
        self.length <= MIN_LINE_LENGTH || self.path.is_done()
    }

    /// Advances one period; writes the state of each axis of the group to `out`.
    pub fn step(&mut self, out: &mut [AxisState]) -> Result<(), LineError> {
        if self.length > MIN_LINE_LENGTH {
            let mut s = [AxisState::default()];
            self.path.step(&mut s)?;
            self.state = s[0];
        }
        let at_end = self.state.position == self.length;
        for (i, o) in out.iter_mut().enumerate().take(self.start.len()) {
            let u = self.direction[i];
            if at_end {
                // Exactly the end point (start + u·L can differ from it by rounding).
                *o = AxisState {
                    position: self.end[i],
                    velocity: 0.0,
                    acceleration: 0.0,
                };
                continue;
            }
            *o = AxisState {
                position: self.start[i] + u * self.state.position,
                velocity: u * self.state.velocity,
                acceleration: u * self.state.acceleration,
            };
        }
        Ok(())
    }
}

/// The largest path velocity along the line from `start` to `end` under which no axis exceeds
/// its velocity limit (infinite for a zero-length line).
pub fn max_path_velocity(start: &[f64], end: &[f64], limits: &[KinematicLimits]) -> f64 {
    let delta = DVector::from_iterator(start.len(), start.iter().zip(end).map(|(a, b)| b - a));
    let length = delta.norm();
    if length <= MIN_LINE_LENGTH || limits.len() != start.len() {
        return f64::INFINITY;
    }
    path_limits(&(delta / length), limits).velocity
}

/// The largest path limits under which no axis exceeds its own, for unit direction `u`.
fn path_limits(u: &DVector<f64>, limits: &[KinematicLimits]) -> KinematicLimits {
    let cap = |f: fn(&KinematicLimits) -> f64| {
        u.iter()
            .zip(limits)
            .filter(|(c, _)| c.abs() > 1e-12)
            .map(|(c, l)| f(l) / c.abs())
            .fold(f64::INFINITY, f64::min)
    };
    let finite = |x: f64, fallback: f64| if x.is_finite() { x } else { fallback };
    KinematicLimits {
        velocity: finite(cap(|l| l.velocity), limits[0].velocity),
        acceleration: finite(cap(|l| l.acceleration), limits[0].acceleration),
        jerk: finite(cap(|l| l.jerk), limits[0].jerk),
    }
}
