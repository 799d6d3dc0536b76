//! The trapezoid generator of every emulated drive: the command's position and velocity,
//! stepped at a speed (pv, jog) or onto a target (pp, point table, indexer, homing's
//! positioning) through the one velocity ramp (`motion::ramp`). How a positioning brakes onto
//! its target is the named [`Braking`] curve of the model.

use super::ramp::VelocityRamp;

/// Distance (units) below which the [`Braking::AfterStep`] curve lands on the target (it
/// approaches the target geometrically).
pub const LANDING_TOLERANCE: f64 = 1e-6;

/// How a positioning brakes onto its target at the deceleration.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Braking {
    /// Ramp toward the profile velocity, then cap the speed at what still stops on the target
    /// after this step, s² ≤ 2·dec·(|d| − s·dt) (the discrete braking curve), and land within
    /// [`LANDING_TOLERANCE`]: the simulated EtherCAT drives' pp (MR-J4-TM manual §5.4.6 gives
    /// the trapezoid, 6083h/6084h, not its braking curve).
    #[default]
    AfterStep,
    /// Aim at min(profile velocity, √(2·dec·|d|)), ramp toward it (never braking harder than
    /// the deceleration) and land where a step reaches the target, reporting the part of the
    /// step moved: the MR-JE-C (MR-JE-C manual §7.3 6083h/6084h, 0 ms = a step, so no braking
    /// curve at 6084h = 0; §7.6.2 pp).
    Continuous,
}

/// Directions in which the drive has no torque to speed up the motor (MR-JE-C manual §7.3
/// 60E0h/60E1h = 0.0 %): the generator keeps the speed it has that way. The emulators have no
/// inertia to scale an acceleration by a limit, so a limit only gates it (an emulator choice).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct NoTorque {
    /// 60E0h forward torque limit is 0.
    pub forward: bool,
    /// 60E1h reverse torque limit is 0.
    pub reverse: bool,
}

impl NoTorque {
    /// Whether there is no torque toward `speed` (> 0 forward, else reverse).
    pub fn toward(&self, speed: f64) -> bool {
        if speed > 0.0 {
            self.forward
        } else {
            self.reverse
        }
    }
}

/// A positioning: where, how fast, with which ramp and braking curve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Positioning {
    /// The target, units.
    pub target: f64,
    /// The profile velocity (6081h after its caps), units/s, ≥ 0.
    pub speed: f64,
    /// The acceleration and deceleration.
    pub ramp: VelocityRamp,
    /// The braking curve.
    pub braking: Braking,
}

/// One step of a positioning.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Arrival {
    /// The generator arrived at the target in this step (it stands on it).
    pub arrived: bool,
    /// Seconds of the step the generator moved (less than the step where it arrived).
    pub moving: f64,
}

/// The command's position (units) and velocity (units/s).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Generator {
    /// Position demand, units.
    pub position: f64,
    /// Velocity demand, units/s.
    pub velocity: f64,
}

impl Generator {
    /// One step of `dt` s toward the signed `speed` (units/s); the position integrates the new
    /// velocity.
    pub fn run_at(&mut self, speed: f64, ramp: &VelocityRamp, no_torque: NoTorque, dt: f64) {
        self.ramp_toward(speed, ramp, no_torque, dt);
        self.position += self.velocity * dt;
    }

    /// The velocity after a ramp step toward `want`, unless the motor has no torque to speed
    /// up that way (then it keeps its velocity).
    fn ramp_toward(&mut self, want: f64, ramp: &VelocityRamp, no_torque: NoTorque, dt: f64) {
        if !(VelocityRamp::speeding_up(self.velocity, want) && no_torque.toward(want)) {
            self.velocity = ramp.step(self.velocity, want, dt);
        }
    }

    /// One step of `dt` s of the positioning `p`.
    pub fn position_to(&mut self, p: &Positioning, no_torque: NoTorque, dt: f64) -> Arrival {
        match p.braking {
            Braking::AfterStep => self.brake_after_step(p, dt),
            Braking::Continuous => self.brake_continuously(p, no_torque, dt),
        }
    }

    /// [`Braking::AfterStep`].
    fn brake_after_step(&mut self, p: &Positioning, dt: f64) -> Arrival {
        let d = p.target - self.position;
        let standing = Arrival {
            arrived: d == 0.0,
            moving: 0.0,
        };
        if d == 0.0 && self.velocity == 0.0 {
            return standing;
        }
        let dir = if d != 0.0 {
            d.signum()
        } else {
            -self.velocity.signum()
        };
        // The speed toward the target, ramped toward the profile velocity.
        let mut s = p.ramp.step(self.velocity * dir, p.speed, dt);
        // Never faster than what still stops on the target at the deceleration after this step:
        // s² ≤ 2·dec·(|d| − s·dt), the discrete form of the braking curve.
        let dec = p.ramp.deceleration.unwrap_or(f64::INFINITY);
        let h = dec * dt;
        s = s.min(-h + (h * h + 2.0 * dec * d.abs()).sqrt());
        let dx = s * dt;
        if s >= 0.0 && dx >= d.abs() - LANDING_TOLERANCE {
            self.position = p.target;
            self.velocity = 0.0;
            return Arrival {
                arrived: true,
                moving: dt,
            };
        }
        self.position += dir * dx;
        self.velocity = dir * s;
        Arrival {
            arrived: false,
            moving: dt,
        }
    }

    /// [`Braking::Continuous`].
    fn brake_continuously(&mut self, p: &Positioning, no_torque: NoTorque, dt: f64) -> Arrival {
        let left = p.target - self.position;
        let braking = p
            .ramp
            .deceleration
            .map_or(p.speed, |d| (2.0 * d * left.abs()).sqrt());
        let want = left.signum() * p.speed.min(braking);
        let moving = Arrival {
            arrived: false,
            moving: dt,
        };
        if VelocityRamp::speeding_up(self.velocity, want) && no_torque.toward(want) {
            // Held where it is: the speed it has, no more.
            self.position += self.velocity * dt;
            return moving;
        }
        self.velocity = p.ramp.step(self.velocity, want, dt);
        let step = self.velocity * dt;
        if left.abs() <= step.abs() || left == 0.0 {
            self.position = p.target;
            self.velocity = 0.0;
            let part = if step == 0.0 {
                0.0
            } else {
                (left / step).abs().min(1.0)
            };
            return Arrival {
                arrived: true,
                moving: dt * part,
            };
        }
        self.position += step;
        moving
    }
}
