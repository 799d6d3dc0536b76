//! Ramped torque commands for cst axes: from zero up to the commanded torque at the axis'
//! torque slope, held for the commanded time, and back down to zero at the same slope, so no
//! torque setpoint ever steps by more than the slope allows.

/// A ramp–hold–ramp torque profile of one axis, in % of rated torque.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TorqueRamp {
    target: f64,
    slope: f64,
    hold_s: f64,
}

/// A torque command that cannot be profiled.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum TorqueRampError {
    /// NaN or infinite torque.
    #[error("torque {0} % is not a finite number")]
    NotFinite(f64),
    /// Slope not finite and > 0.
    #[error("torque slope {0} %/s must be a finite number > 0")]
    BadSlope(f64),
    /// Hold time not finite and ≥ 0.
    #[error("hold time {0} s must be a finite number ≥ 0")]
    BadHold(f64),
}

impl TorqueRamp {
    /// Ramps to `target` % at `slope` %/s, holds it `hold_s` seconds, ramps back to 0.
    pub fn new(target: f64, slope: f64, hold_s: f64) -> Result<Self, TorqueRampError> {
        if !target.is_finite() {
            return Err(TorqueRampError::NotFinite(target));
        }
        if !(slope.is_finite() && slope > 0.0) {
            return Err(TorqueRampError::BadSlope(slope));
        }
        if !(hold_s.is_finite() && hold_s >= 0.0) {
            return Err(TorqueRampError::BadHold(hold_s));
        }
        Ok(TorqueRamp {
            target,
            slope,
            hold_s,
        })
    }

    /// The slope, %/s.
    pub fn slope(&self) -> f64 {
        self.slope
    }

    /// Time of one ramp, s.
    pub fn ramp_s(&self) -> f64 {
        self.target.abs() / self.slope
    }

    /// Total duration, s.
    pub fn duration_s(&self) -> f64 {
        2.0 * self.ramp_s() + self.hold_s
    }

    /// The torque at time `t` s (0 before the start and after the end).
    pub fn at(&self, t: f64) -> f64 {
        let ramp = self.ramp_s();
        let mag = if t <= 0.0 || t >= self.duration_s() {
            0.0
        } else if t < ramp {
            t * self.slope
        } else if t <= ramp + self.hold_s {
            self.target.abs()
        } else {
            (self.duration_s() - t) * self.slope
        };
        mag.min(self.target.abs()) * self.target.signum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ramps_up_holds_and_ramps_down_within_the_slope() {
        let r = TorqueRamp::new(-50.0, 500.0, 0.2).unwrap();
        assert!((r.duration_s() - 0.4).abs() < 1e-12);
        assert_eq!(r.at(0.0), 0.0);
        assert!((r.at(0.05) + 25.0).abs() < 1e-9);
        assert_eq!(r.at(0.2), -50.0);
        assert!((r.at(0.35) + 25.0).abs() < 1e-9);
        assert_eq!(r.at(0.4), 0.0);
        let dt = 1e-3;
        let mut last = 0.0;
        for k in 0..=500 {
            let v = r.at(k as f64 * dt);
            assert!((v - last).abs() <= 500.0 * dt + 1e-9, "step at {k}");
            last = v;
        }
    }

    #[test]
    fn bad_input_is_refused() {
        assert!(TorqueRamp::new(f64::NAN, 1.0, 1.0).is_err());
        assert!(TorqueRamp::new(10.0, 0.0, 1.0).is_err());
        assert!(TorqueRamp::new(10.0, 1.0, -1.0).is_err());
    }
}
