//! How the simulated drive reads and writes its velocity objects (60FFh, 2D20h, 606Ch) by the
//! unit its manual states: its own arithmetic, independent of the master's conversion
//! (`drive_scaling`), so tests pinning manual literals on both sides catch a wrong scale.

use super::SimDrive;
use cellrt_cia402::profiles::{MotorKind, VelocityUnit};

/// Encoder counts per revolution of the simulated motor where neither the profile nor the
/// parameters give one (MR-J5 / MR-JET / generic): 2^26, the resolution of the MR-JET-G-N1
/// manual's infinite-feed example (§8).
pub const SIM_DEFAULT_COUNTS_PER_REV: f64 = 67_108_864.0;

/// The simulated motor: rotary or linear, and its encoder resolution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimMotor {
    /// Rotary (r/min) or linear (mm/s).
    pub kind: MotorKind,
    /// Counts per revolution (rotary) or per mm (linear); `None`: the profile's resolution,
    /// else [`SIM_DEFAULT_COUNTS_PER_REV`].
    pub counts_per: Option<f64>,
    /// The velocity unit of the drive's objects where its manual leaves it open (MR-JET, MR-J5,
    /// generic CiA 402); `None`: the profile's (stated or default) unit.
    pub velocity_unit: Option<VelocityUnit>,
}

impl Default for SimMotor {
    fn default() -> Self {
        SimMotor {
            kind: MotorKind::Rotary,
            counts_per: None,
            velocity_unit: None,
        }
    }
}

impl SimDrive {
    /// Encoder counts per revolution (rotary) or per mm (linear) of the simulated motor.
    pub fn motor_resolution(&self) -> f64 {
        self.params
            .motor
            .counts_per
            .or(self.profile.units.counts_per_rev.map(f64::from))
            .unwrap_or(SIM_DEFAULT_COUNTS_PER_REV)
    }

    fn velocity_unit(&self) -> VelocityUnit {
        match self.profile.units.velocity {
            cellrt_cia402::profiles::Stated::Manual(u) => u,
            cellrt_cia402::profiles::Stated::Unstated(u) => {
                self.params.motor.velocity_unit.unwrap_or(u)
            }
        }
    }

    /// Motor speed (r/min rotary, mm/s linear) of `counts_per_s`.
    fn speed_of(&self, counts_per_s: f64) -> f64 {
        match self.params.motor.kind {
            MotorKind::Rotary => counts_per_s / self.motor_resolution() * 60.0,
            MotorKind::Linear => counts_per_s / self.motor_resolution(),
        }
    }

    /// counts/s of a motor speed (r/min rotary, mm/s linear).
    pub(super) fn counts_of(&self, speed: f64) -> f64 {
        match self.params.motor.kind {
            MotorKind::Rotary => speed / 60.0 * self.motor_resolution(),
            MotorKind::Linear => speed * self.motor_resolution(),
        }
    }

    /// The plant's speed: r/min (rotary) or mm/s (linear).
    pub fn motor_speed(&self) -> f64 {
        self.speed_of(self.plant.velocity())
    }

    /// A received velocity object (60FFh, 2D20h) in counts/s of the motor, after the model's
    /// command truncation (MR-J3-T04 manual §9.6: 0.001 r/min, applied at 0.01 r/min, so
    /// 123 456 runs at 123.45 r/min; toward zero for negative values, which the manual leaves
    /// open).
    pub(super) fn commanded_counts_per_s(&self, raw: i64) -> f64 {
        match self.velocity_unit() {
            VelocityUnit::CountsPerSecond => raw as f64,
            VelocityUnit::MotorSpeed { exp10 } => {
                let mut lsbs = raw;
                if let Some(t) = self.profile.units.command_truncation_exp10 {
                    let step = 10i64.pow(u32::from(t.abs_diff(exp10)));
                    if t > exp10 {
                        lsbs = lsbs / step * step;
                    }
                }
                self.counts_of(lsbs as f64 * 10f64.powi(i32::from(exp10)))
            }
        }
    }

    /// The motor's `counts_per_s` as the drive reports it in 606Ch (nearest LSB, saturating at
    /// the I32 range like a hardware register).
    pub(super) fn reported_velocity(&self, counts_per_s: f64) -> i32 {
        let v = match self.velocity_unit() {
            VelocityUnit::CountsPerSecond => counts_per_s,
            VelocityUnit::MotorSpeed { exp10 } => {
                self.speed_of(counts_per_s) / 10f64.powi(i32::from(exp10))
            }
        };
        v.round() as i32
    }
}
