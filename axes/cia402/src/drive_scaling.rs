//! The master's conversion between axis counts and the drive's object units: counts/s ↔ the
//! velocity LSB of 60FFh / 606Ch / 2D20h (r/min or mm/s scaling by the motor's resolution),
//! % ↔ the 0.1 % LSB of the torque objects. Factors are computed once at set-up, so the RT
//! loop only multiplies.

use crate::profiles::{MotorKind, TorqueUnit, Units, VelocityUnit};

/// The motor behind a drive: rotary with encoder counts per revolution, or linear with
/// counts per mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Motor {
    /// Rotary or linear.
    pub kind: MotorKind,
    /// Encoder counts per revolution (rotary) or per mm (linear).
    pub counts_per: f64,
}

/// Why a drive scaling cannot be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DriveScalingError {
    /// The velocity unit is a motor speed and neither the manual nor the config gives the
    /// motor's resolution.
    #[error("the drive's velocity unit is {unit} and its manual gives no encoder resolution: set the motor's counts per revolution (or per mm)")]
    MissingResolution {
        /// The velocity unit, e.g. "0.01 r/min".
        unit: String,
    },
    /// A resolution that is not a positive finite number.
    #[error("{0} is not a resolution (counts, finite, > 0)")]
    InvalidResolution(f64),
}

/// A value the drive's object cannot represent.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error("{value} is beyond the object's range in drive units")]
pub struct OutOfRange {
    /// The value in drive units (LSB).
    pub value: f64,
}

/// Axis counts ↔ drive units for one axis, precomputed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DriveScaling {
    velocity: VelocityUnit,
    motor: Option<Motor>,
    /// Velocity LSBs per count/s.
    lsb_per_count_per_s: f64,
    torque: TorqueUnit,
}

impl DriveScaling {
    /// The scaling for a drive whose objects have `units`, whose velocity objects are in
    /// `velocity` (the manual's unit, or the configured one where the manual is silent), with
    /// `motor` (the configured resolution; `None`: the manual's rotary resolution).
    pub fn new(
        units: &Units,
        velocity: VelocityUnit,
        motor: Option<Motor>,
    ) -> Result<DriveScaling, DriveScalingError> {
        let motor = motor.or(units.counts_per_rev.map(|c| Motor {
            kind: MotorKind::Rotary,
            counts_per: f64::from(c),
        }));
        if let Some(m) = motor {
            if !(m.counts_per.is_finite() && m.counts_per > 0.0) {
                return Err(DriveScalingError::InvalidResolution(m.counts_per));
            }
        }
        let lsb_per_count_per_s = match (velocity, motor) {
            (VelocityUnit::CountsPerSecond, _) => 1.0,
            (VelocityUnit::MotorSpeed { exp10 }, Some(m)) => {
                let lsb = 10f64.powi(i32::from(exp10));
                match m.kind {
                    MotorKind::Rotary => 60.0 / (m.counts_per * lsb),
                    MotorKind::Linear => 1.0 / (m.counts_per * lsb),
                }
            }
            (v, None) => {
                return Err(DriveScalingError::MissingResolution {
                    unit: v.name(MotorKind::Rotary),
                })
            }
        };
        Ok(DriveScaling {
            velocity,
            motor,
            lsb_per_count_per_s,
            torque: units.torque,
        })
    }

    /// The velocity unit of the drive's objects.
    pub const fn velocity_unit(&self) -> VelocityUnit {
        self.velocity
    }

    /// The motor (resolution and kind), where known.
    pub const fn motor(&self) -> Option<Motor> {
        self.motor
    }

    /// Velocity LSBs per count/s.
    pub const fn lsb_per_count_per_s(&self) -> f64 {
        self.lsb_per_count_per_s
    }

    /// A velocity in counts/s as the drive's velocity object (60FFh, I32), rounded to the
    /// nearest LSB; out of range (or not finite) is an error, never clamped.
    pub fn velocity_to_drive(&self, counts_per_s: f64) -> Result<i32, OutOfRange> {
        let v = (counts_per_s * self.lsb_per_count_per_s).round();
        if v.is_finite() && v >= f64::from(i32::MIN) && v <= f64::from(i32::MAX) {
            Ok(v as i32)
        } else {
            Err(OutOfRange { value: v })
        }
    }

    /// A speed limit in counts/s as an unsigned velocity object (2D20h as the RxPDO carries
    /// it); out of range is an error.
    pub fn speed_limit_to_drive(&self, counts_per_s: f64) -> Result<u32, OutOfRange> {
        let v = (counts_per_s.abs() * self.lsb_per_count_per_s).round();
        if v.is_finite() && v <= f64::from(i32::MAX) {
            Ok(v as u32)
        } else {
            Err(OutOfRange { value: v })
        }
    }

    /// The drive's velocity object (606Ch) in counts/s.
    pub fn velocity_from_drive(&self, raw: i32) -> f64 {
        f64::from(raw) / self.lsb_per_count_per_s
    }

    /// A velocity in counts/s as motor speed: r/min (rotary) or mm/s (linear); `None` without
    /// a known motor.
    pub fn motor_speed(&self, counts_per_s: f64) -> Option<f64> {
        let m = self.motor?;
        Some(match m.kind {
            MotorKind::Rotary => counts_per_s * 60.0 / m.counts_per,
            MotorKind::Linear => counts_per_s / m.counts_per,
        })
    }

    /// A motor speed (r/min or mm/s) in counts/s; `None` without a known motor.
    pub fn counts_per_s(&self, motor_speed: f64) -> Option<f64> {
        let m = self.motor?;
        Some(match m.kind {
            MotorKind::Rotary => motor_speed * m.counts_per / 60.0,
            MotorKind::Linear => motor_speed * m.counts_per,
        })
    }

    /// A torque in % of rated torque as the drive's torque object (6071h, I16); out of range is
    /// an error.
    pub fn torque_to_drive(&self, percent: f64) -> Result<i16, OutOfRange> {
        let TorqueUnit::PerMilleOfRated = self.torque;
        let v = (percent * 10.0).round();
        if v.is_finite() && v >= f64::from(i16::MIN) && v <= f64::from(i16::MAX) {
            Ok(v as i16)
        } else {
            Err(OutOfRange { value: v })
        }
    }

    /// A torque limit in % of rated torque as 60E0h / 60E1h (U16); out of range is an error.
    pub fn torque_limit_to_drive(&self, percent: f64) -> Result<u16, OutOfRange> {
        let TorqueUnit::PerMilleOfRated = self.torque;
        let v = (percent * 10.0).round();
        if v.is_finite() && v >= 0.0 && v <= f64::from(u16::MAX) {
            Ok(v as u16)
        } else {
            Err(OutOfRange { value: v })
        }
    }

    /// The drive's torque object (6077h) in % of rated torque.
    pub fn torque_from_drive(&self, raw: i16) -> f64 {
        let TorqueUnit::PerMilleOfRated = self.torque;
        f64::from(raw) / 10.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profiles::{profile, DriveModel};

    fn scaling(model: DriveModel, motor: Option<Motor>) -> DriveScaling {
        let u = &profile(model).units;
        DriveScaling::new(u, u.velocity.value(), motor).unwrap()
    }

    fn rotary(counts_per_rev: f64) -> Option<Motor> {
        Some(Motor {
            kind: MotorKind::Rotary,
            counts_per: counts_per_rev,
        })
    }

    #[test]
    fn mr_j3_t04_velocity_in_milli_rpm() {
        // MR-J3-T04 manual §9.6, TV-UNITS-1: 1500 r/min is 60FFh = 1 500 000; 262 144 counts/rev.
        let s = scaling(DriveModel::MrJ3T04, None);
        let cps = s.counts_per_s(1500.0).unwrap();
        assert_eq!(cps, 6_553_600.0);
        assert_eq!(s.velocity_to_drive(cps), Ok(1_500_000));
        assert!((s.velocity_from_drive(1_500_000) - 6_553_600.0).abs() < 1e-6);
        let rpm = s.motor_speed(s.velocity_from_drive(123_456)).unwrap();
        assert!((rpm - 123.456).abs() < 1e-9, "{rpm}");
        // I32 of 0.001 r/min ends at 2 147 483.647 r/min: more is refused, not clamped.
        assert!(s
            .velocity_to_drive(s.counts_per_s(2_147_484.0).unwrap())
            .is_err());
        // The 17-bit motors (131 072 counts/rev) by config.
        let s17 = scaling(DriveModel::MrJ3T04, rotary(131_072.0));
        assert_eq!(s17.velocity_to_drive(3_276_800.0), Ok(1_500_000));
    }

    #[test]
    fn mr_j4_tm_velocity_in_centi_rpm_or_centi_mm_per_s() {
        // MR-J4-TM manual §4.2: Vel unit 0.01 r/min; 4 194 304 counts/rev (§1.2).
        let s = scaling(DriveModel::MrJ4TM, None);
        assert_eq!(
            s.velocity_to_drive(s.counts_per_s(1500.0).unwrap()),
            Ok(150_000)
        );
        assert_eq!(s.velocity_to_drive(69_905_066.0), Ok(100_000)); // 1000 r/min
                                                                    // 607Fh default 2 000 000 = 20 000.00 r/min.
        let rpm = s.motor_speed(s.velocity_from_drive(2_000_000)).unwrap();
        assert!((rpm - 20_000.0).abs() < 1e-9, "{rpm}");
        // A linear motor: 0.01 mm/s, here 1000 counts/mm.
        let lin = scaling(
            DriveModel::MrJ4TM,
            Some(Motor {
                kind: MotorKind::Linear,
                counts_per: 1000.0,
            }),
        );
        assert_eq!(lin.velocity_to_drive(250_000.0), Ok(25_000)); // 250 mm/s
    }

    #[test]
    fn unstated_models_need_a_resolution() {
        for m in [
            DriveModel::MrJ5GN1,
            DriveModel::MrJ5W3GN1,
            DriveModel::MrJetGN1,
        ] {
            let u = &profile(m).units;
            let e = DriveScaling::new(u, u.velocity.value(), None).unwrap_err();
            assert!(e.to_string().contains("0.01 r/min"), "{m}: {e}");
            // Default 0.01 r/min: 3000 r/min on a 2^26 motor is 300 000.
            let s = scaling(m, rotary(67_108_864.0));
            assert_eq!(
                s.velocity_to_drive(s.counts_per_s(3000.0).unwrap()),
                Ok(300_000)
            );
        }
        // Generic CiA 402: counts/s by default, no resolution needed.
        let g = scaling(DriveModel::GenericCia402, None);
        assert_eq!(g.velocity_to_drive(123_456.4), Ok(123_456));
        assert!(g.velocity_to_drive(3.0e9).is_err());
        let bad = DriveScaling::new(
            &profile(DriveModel::MrJ5GN1).units,
            VelocityUnit::CENTI_RPM,
            rotary(0.0),
        );
        assert_eq!(bad, Err(DriveScalingError::InvalidResolution(0.0)));
    }

    #[test]
    fn torque_in_per_mille_of_rated_on_every_model() {
        // Every manual (MR-J3-T04 §9.6, MR-J4-TM §4.2, MR-JET-G-N1 §9.1, MR-J5-G-N1) and
        // CiA 402: 60E0h = 1000 is 100.0 % rated torque (TV-UNITS-1).
        for m in DriveModel::ALL {
            let s = scaling(*m, rotary(262_144.0));
            assert_eq!(s.torque_limit_to_drive(100.0), Ok(1000), "{m}");
            assert_eq!(s.torque_to_drive(-35.5), Ok(-355), "{m}");
            assert_eq!(s.torque_from_drive(3000), 300.0, "{m}");
            assert!(s.torque_limit_to_drive(7000.0).is_err(), "{m}");
            assert!(s.torque_to_drive(-4000.0).is_err(), "{m}");
        }
    }
}
