//! The one velocity ramp of every emulated drive: a generator velocity steps toward a goal at
//! the acceleration while the speed grows in the same direction and at the deceleration while
//! it falls (CiA 402 6083h/6084h; MR-J4-TM manual §5.4.7(4), MR-JE-C manual §7.3 6083h/6084h:
//! time constants from 0 to the rated speed, which each drive turns into rates before the
//! ramp). Profile position, profile velocity and the homing search of both emulators step
//! their velocity here. Allocation-free.

/// The rate (units/s²) of a time constant of `ms` from 0 to `rated_speed` (units/s), the way
/// the Mitsubishi drives state accelerations (MR-JE-C manual §7.3 6083h/6084h/6085h, MR-J4-TM
/// manual §4.2); `None` for 0 ms or less (the MR-JE-C's step; each model says what it does).
pub fn time_constant_rate(rated_speed: f64, ms: i64) -> Option<f64> {
    (ms > 0).then(|| rated_speed * 1000.0 / ms as f64)
}

/// What a ramp does when the goal lies on the other side of zero.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Reversal {
    /// The decelerating step ends at 0 for the cycle, the next accelerates away (MR-J4-TM
    /// manual §5.4.7(4): "reversing decelerates to 0 at 6084h, then accelerates at 6083h").
    StopAtZero,
    /// The decelerating step runs on through 0 at the deceleration (MR-JE-C manual §7.3 gives
    /// no stop at zero; the EtherCAT drives' homing search ramps the same way).
    #[default]
    Through,
}

/// The rates and rules of one velocity ramp.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VelocityRamp {
    /// Acceleration, units/s² (`None`: a step, the MR-JE-C's 0 ms time constant).
    pub acceleration: Option<f64>,
    /// Deceleration, units/s² (`None`: a step).
    pub deceleration: Option<f64>,
    /// The reversal rule.
    pub reversal: Reversal,
    /// Distance (units/s) within which a step lands on its end: float error of the cycle sums.
    pub landing: f64,
}

impl VelocityRamp {
    /// A ramp at `acceleration` / `deceleration` (units/s²; `None`: a step), passing through 0
    /// and landing exactly.
    pub fn new(acceleration: Option<f64>, deceleration: Option<f64>) -> Self {
        VelocityRamp {
            acceleration,
            deceleration,
            reversal: Reversal::Through,
            landing: 0.0,
        }
    }

    /// A ramp at one `rate` (units/s²) both ways.
    pub fn symmetric(rate: f64) -> Self {
        VelocityRamp::new(Some(rate), Some(rate))
    }

    /// Whether a move from `velocity` toward `goal` speeds up (same direction, larger speed).
    pub fn speeding_up(velocity: f64, goal: f64) -> bool {
        goal.abs() > velocity.abs() && goal * velocity >= 0.0
    }

    /// The velocity after `dt` s from `velocity` toward `goal`.
    pub fn step(&self, velocity: f64, goal: f64, dt: f64) -> f64 {
        if velocity == goal {
            return goal;
        }
        let speeding_up = VelocityRamp::speeding_up(velocity, goal);
        let rate = if speeding_up {
            self.acceleration
        } else {
            self.deceleration
        };
        let end = if !speeding_up
            && self.reversal == Reversal::StopAtZero
            && velocity.signum() != goal.signum()
        {
            0.0
        } else {
            goal
        };
        let Some(rate) = rate else {
            return end;
        };
        let change = end - velocity;
        let step = rate * dt;
        if change.abs() - step <= self.landing {
            end
        } else {
            velocity + step * change.signum()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_reversal_stops_at_zero_or_runs_through_as_named() {
        let through = VelocityRamp::symmetric(1_000.0);
        assert_eq!(through.step(0.5, -10.0, 1e-3), -0.5);
        let stop = VelocityRamp {
            reversal: Reversal::StopAtZero,
            ..through
        };
        assert_eq!(stop.step(0.5, -10.0, 1e-3), 0.0);
        assert_eq!(stop.step(0.0, -10.0, 1e-3), -1.0);
        assert_eq!(VelocityRamp::new(None, None).step(3.0, -7.0, 1e-3), -7.0);
    }
}
