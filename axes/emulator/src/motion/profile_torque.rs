//! Profile torque mode (tq) of every emulated drive: the torque demand (6074h) ramps toward
//! 6071h at the torque slope 6087h; HALT ramps it to 0 at 6087h and releasing HALT ramps it
//! back as [`HaltRelease`] says (MR-J4-TM manual §5.4.8(4); MR-JE-C manual §7.6.3; MR-JET-G-N1 / MR-J5-G-N1 manuals §4.2 "tq: a target torque
//! with 6087h slope", speed limited by 2D20h). Statusword bit 10 is not supported in tq and
//! bits 12/13 are reserved (MR-J4-TM manual §5.4.8): the drive sends them as 0.
//!
//! Torques are in 0.1 % of the rated torque, slopes in 0.1 %/s. Allocation-free.

/// What the drive does with 6087h = 0, which the MR-J4-TM manual leaves open (§5.4.8 "[D]
/// What a slope of 0 means is not stated"): a named parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ZeroSlope {
    /// 6074h takes 6071h at once (no ramp).
    #[default]
    Step,
    /// 6074h keeps its value (a ramp of zero rate).
    Hold,
}

/// What releasing HALT does while the demand is still ramping to 0.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum HaltRelease {
    /// The demand ramps back toward 6071h at once (MR-J4-TM manual §5.4.8(4)).
    #[default]
    Resume,
    /// The demand ramps on to 0 and the operation restarts once it is 0 (MR-JE-C manual
    /// §7.6.3: "the operation restarts" after Halt once the torque has reached 0).
    AfterZero,
}

/// Distance (0.1 %) within which the slope lands on its goal: float error of the cycle sums.
const SLOPE_LANDING: f64 = 1e-9;

/// tq values the manuals leave open.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct TqParams {
    /// 6087h = 0.
    pub zero_slope: ZeroSlope,
}

/// One cycle's tq inputs, resolved by the drive.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct TqCommand {
    /// HALT (controlword bit 8).
    pub halt: bool,
    /// 6071h, 0.1 % (after 6072h where the model has it).
    pub target: f64,
    /// 6087h, 0.1 %/s.
    pub slope: f64,
    /// What 6087h = 0 means.
    pub zero_slope: ZeroSlope,
    /// What releasing HALT does.
    pub halt_release: HaltRelease,
}

/// The tq state of one axis: the torque demand 6074h.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct ProfileTorque {
    demand: f64,
    /// HALT ramps the demand to 0; with [`HaltRelease::AfterZero`] on until it is 0 and HALT
    /// is off.
    halting: bool,
}

impl ProfileTorque {
    /// Restarts with no torque demand (servo on, entering tq).
    pub(crate) fn reset(&mut self) {
        *self = ProfileTorque::default();
    }

    /// 6074h Torque demand, 0.1 %.
    pub(crate) fn demand(&self) -> f64 {
        self.demand
    }

    /// Whether the demand is being ramped to 0 by a HALT.
    pub(crate) fn halting(&self) -> bool {
        self.halting
    }

    /// One cycle of `dt` s; returns 6074h.
    pub(crate) fn step(&mut self, cmd: &TqCommand, dt: f64) -> f64 {
        self.halting = cmd.halt
            || (cmd.halt_release == HaltRelease::AfterZero && self.halting && self.demand != 0.0);
        let goal = if self.halting { 0.0 } else { cmd.target };
        if dt > 0.0 && dt.is_finite() && goal != self.demand {
            self.ramp(cmd, goal, dt);
        }
        if self.halting && !cmd.halt && self.demand == 0.0 {
            self.halting = false;
        }
        self.demand
    }

    /// One slope step toward `goal`.
    fn ramp(&mut self, cmd: &TqCommand, goal: f64, dt: f64) {
        if cmd.slope <= 0.0 {
            if cmd.zero_slope == ZeroSlope::Step {
                self.demand = goal;
            }
            return;
        }
        let step = cmd.slope * dt;
        let rest = goal - self.demand;
        self.demand = if rest.abs() <= step + SLOPE_LANDING {
            goal
        } else {
            self.demand + rest.signum() * step
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cycles_to(tq: &mut ProfileTorque, c: &TqCommand, goal: f64) -> u32 {
        for k in 1..=100_000 {
            if tq.step(c, 1e-3) == goal {
                return k;
            }
        }
        panic!("never reached {goal}");
    }

    #[test]
    fn slope_sets_the_ramp_time_and_halt_ramps_to_zero() {
        // 6071h = 500 (50.0 %) at 6087h = 10000 (1000.0 %/s): 10 per 1 ms cycle, 50 cycles.
        let c = TqCommand {
            halt: false,
            target: 500.0,
            slope: 10_000.0,
            zero_slope: ZeroSlope::Step,
            halt_release: HaltRelease::Resume,
        };
        let mut tq = ProfileTorque::default();
        assert_eq!(cycles_to(&mut tq, &c, 500.0), 50);
        let h = TqCommand { halt: true, ..c };
        assert_eq!(cycles_to(&mut tq, &h, 0.0), 50);
        assert_eq!(cycles_to(&mut tq, &c, 500.0), 50, "released: back to 6071h");
    }

    #[test]
    fn zero_slope_is_the_named_parameter() {
        let step = TqCommand {
            halt: false,
            target: -300.0,
            slope: 0.0,
            zero_slope: ZeroSlope::Step,
            halt_release: HaltRelease::Resume,
        };
        let mut tq = ProfileTorque::default();
        assert_eq!(tq.step(&step, 1e-3), -300.0);
        let hold = TqCommand {
            target: 200.0,
            zero_slope: ZeroSlope::Hold,
            ..step
        };
        assert_eq!(tq.step(&hold, 1e-3), -300.0);
    }
}
