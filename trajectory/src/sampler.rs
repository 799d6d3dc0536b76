//! Turns a [`PlannedMove`] into one state per bus cycle.

use thiserror::Error;

use crate::axis::AxisState;
use crate::planner::PlannedMove;

/// Relative slack when counting cycles, so that a duration that is a whole number of periods
/// up to rounding (e.g. 0.5 s / 1 ms = 500.0000000001) does not get an extra cycle.
const CYCLE_COUNT_SLACK: f64 = 1e-9;

/// Errors from building a [`MoveSampler`].
#[derive(Debug, Clone, Copy, PartialEq, Error)]
pub enum SamplerError {
    /// The cycle period is NaN, infinite, zero or negative.
    #[error("cycle period must be finite and > 0 s, got {0} s")]
    InvalidPeriod(f64),
    /// The move would take more cycles than fit in a `u64` (absurd duration or period).
    #[error("a move of {duration} s at {period} s per cycle has too many cycles")]
    TooManyCycles {
        /// Move duration, s.
        duration: f64,
        /// Cycle period, s.
        period: f64,
    },
}

/// Samples a planned move once per cycle: cycle `k` (1-based) is the state at `t = k * period`,
/// and the last cycle `n = ceil(duration / period)` is exactly the target at rest.
///
/// Owns its move; [`MoveSampler::fill`] does not allocate.
#[derive(Debug, Clone)]
pub struct MoveSampler {
    plan: PlannedMove,
    period: f64,
    cycles: u64,
}

impl MoveSampler {
    /// Builds a sampler for `plan` at a cycle period of `period` seconds (finite, > 0).
    pub fn new(plan: PlannedMove, period: f64) -> Result<MoveSampler, SamplerError> {
        if !(period.is_finite() && period > 0.0) {
            return Err(SamplerError::InvalidPeriod(period));
        }
        let duration = plan.duration();
        let exact = duration / period;
        let cycles = (exact * (1.0 - CYCLE_COUNT_SLACK)).ceil();
        // u64::MAX as f64 rounds up to 2^64, so `<` excludes it.
        if !(cycles.is_finite() && cycles < u64::MAX as f64) {
            return Err(SamplerError::TooManyCycles { duration, period });
        }
        Ok(MoveSampler {
            plan,
            period,
            cycles: cycles.max(0.0) as u64,
        })
    }

    /// Number of cycles `n` the move takes (0 for a move of zero duration).
    pub fn cycles(&self) -> u64 {
        self.cycles
    }

    /// Cycle period, s.
    pub fn period(&self) -> f64 {
        self.period
    }

    /// The sampled move.
    pub fn plan(&self) -> &PlannedMove {
        &self.plan
    }

    /// Gives the move back.
    pub fn into_plan(self) -> PlannedMove {
        self.plan
    }

    /// Time of cycle `k`, s: `k * period`, and exactly the duration for `k >= cycles()`.
    pub fn time_of(&self, k: u64) -> f64 {
        if k >= self.cycles {
            self.plan.duration()
        } else {
            (k as f64 * self.period).min(self.plan.duration())
        }
    }

    /// Writes the states of cycle `k` into `out` and returns the number of axes written
    /// (see [`PlannedMove::state_at`]). `k = 0` is the start state, `k >= cycles()` the
    /// target at rest. Does not allocate.
    pub fn fill(&self, k: u64, out: &mut [AxisState]) -> usize {
        self.plan.state_at(self.time_of(k), out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::axis::MoveAxis;
    use crate::limits::KinematicLimits;
    use crate::planner::plan_move;

    fn plan(target: f64) -> PlannedMove {
        plan_move(&[MoveAxis {
            start: AxisState::default(),
            target,
            limits: KinematicLimits {
                velocity: 1.0,
                acceleration: 4.0,
                jerk: 40.0,
            },
        }])
        .unwrap()
    }

    #[test]
    fn cycle_count_and_end() {
        let p = plan(1.0);
        let d = p.duration();
        let s = MoveSampler::new(p, 1e-3).unwrap();
        assert_eq!(s.cycles(), (d / 1e-3).ceil() as u64);
        assert!((s.cycles() as f64 - 1.0) * 1e-3 < d && d <= s.cycles() as f64 * 1e-3 + 1e-12);
        let mut out = [AxisState::default()];
        s.fill(s.cycles(), &mut out);
        assert_eq!(out[0].position, 1.0);
        assert_eq!(out[0].velocity, 0.0);
        s.fill(s.cycles() - 1, &mut out);
        assert!(out[0].position < 1.0);
        s.fill(0, &mut out);
        assert_eq!(out[0].position, 0.0);
        assert_eq!(s.time_of(1), 1e-3);
        assert_eq!(s.time_of(u64::MAX), d);
        assert_eq!(s.into_plan().axis_count(), 1);
    }

    #[test]
    fn zero_duration_has_no_cycles() {
        let s = MoveSampler::new(plan(0.0), 1e-3).unwrap();
        assert_eq!(s.cycles(), 0);
        let mut out = [AxisState::default()];
        s.fill(1, &mut out);
        assert_eq!(out[0], AxisState::default());
    }

    #[test]
    fn bad_period() {
        for bad in [0.0, -1e-3, f64::NAN, f64::INFINITY] {
            assert!(matches!(
                MoveSampler::new(plan(1.0), bad),
                Err(SamplerError::InvalidPeriod(_))
            ));
        }
        assert!(matches!(
            MoveSampler::new(plan(1.0), 1e-300),
            Err(SamplerError::TooManyCycles { .. })
        ));
    }
}
