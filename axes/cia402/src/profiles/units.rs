//! The units of the objects cellrt exchanges with a drive, as typed data: what one LSB of a
//! velocity, acceleration or torque object means on each model, per its manual.

/// A fact the manual states, or a documented default cellrt assumes where the manual is silent
/// (the axis config may then choose another value).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Stated<T> {
    /// Stated by the model's manual; fixed.
    Manual(T),
    /// Not stated by the manual: the default, overridable in the axis config.
    Unstated(T),
}

impl<T: Copy> Stated<T> {
    /// The value (stated or default).
    pub const fn value(self) -> T {
        match self {
            Stated::Manual(v) | Stated::Unstated(v) => v,
        }
    }

    /// True if the manual fixes the value.
    pub const fn is_manual(self) -> bool {
        matches!(self, Stated::Manual(_))
    }
}

/// What one LSB of a velocity object (60FFh, 606Ch, 6081h, 6099h, 2D20h) means.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum VelocityUnit {
    /// 10^`exp10` r/min of a rotary motor, or 10^`exp10` mm/s of a linear motor (e.g. −3:
    /// 0.001 r/min).
    MotorSpeed {
        /// Decimal exponent of one LSB.
        exp10: i8,
    },
    /// Position units per second: CiA 402 velocity units with the factor group at identity
    /// (position units = encoder counts).
    CountsPerSecond,
}

impl VelocityUnit {
    /// 0.001 r/min (MR-J3-T04 manual §9.6).
    pub const MILLI_RPM: VelocityUnit = VelocityUnit::MotorSpeed { exp10: -3 };
    /// 0.01 r/min or 0.01 mm/s (MR-J4-TM manual §4.2 "Vel unit").
    pub const CENTI_RPM: VelocityUnit = VelocityUnit::MotorSpeed { exp10: -2 };

    /// The configuration spelling, e.g. "0.001 r/min" (rotary) or "counts/s".
    pub fn name(self, motor: MotorKind) -> String {
        match (self, motor) {
            (VelocityUnit::CountsPerSecond, _) => "counts/s".to_owned(),
            (VelocityUnit::MotorSpeed { exp10 }, m) => {
                format!("{} {}", 10f64.powi(i32::from(exp10)), m.speed_unit())
            }
        }
    }

    /// Parses a configuration spelling: "counts/s", or "<10^n> r/min" / "<10^n> mm/s" with
    /// n in −6…0 (the r/min and mm/s forms are the same scale for rotary and linear motors).
    pub fn parse(text: &str) -> Option<VelocityUnit> {
        let t = text.trim();
        if t == "counts/s" {
            return Some(VelocityUnit::CountsPerSecond);
        }
        let (lsb, unit) = t.split_once(' ')?;
        if unit != "r/min" && unit != "mm/s" {
            return None;
        }
        let lsb: f64 = lsb.parse().ok()?;
        (-6i8..=0)
            .find(|e| {
                let step = 10f64.powi(i32::from(*e));
                (step - lsb).abs() <= 1e-9 * step
            })
            .map(|exp10| VelocityUnit::MotorSpeed { exp10 })
    }
}

/// Whether the motor turns (speeds in r/min, resolution per revolution) or moves linearly
/// (mm/s, resolution per mm).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MotorKind {
    /// A rotary servo motor.
    Rotary,
    /// A linear servo motor (MR-J4-TM manual §4.2: 0.01 mm/s).
    Linear,
}

impl MotorKind {
    /// "r/min" or "mm/s".
    pub const fn speed_unit(self) -> &'static str {
        match self {
            MotorKind::Rotary => "r/min",
            MotorKind::Linear => "mm/s",
        }
    }
}

/// What one LSB of the acceleration / deceleration objects (6083h, 6084h, 6085h) means.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum AccelerationUnit {
    /// A time constant in ms: the time from 0 to the motor's rated speed (MR-J4-TM manual §4.2;
    /// the reference speed is Mitsubishi's convention, the copy used does not print it).
    TimeConstantMs,
    /// Velocity units per second (CiA 402 acceleration units with the factor group at identity).
    VelocityUnitsPerSecond,
    /// Not supported by the model (MR-J3-T04 manual §8.3.2: 6083h reserved).
    NotSupported,
}

/// What one LSB of the torque objects (6071h, 6072h, 6077h, 60E0h, 60E1h) means.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum TorqueUnit {
    /// 0.1 % of the motor's rated torque (per mille), every model's manual and CiA 402.
    PerMilleOfRated,
}

/// Encoder resolution and the units of the objects the master and the simulator use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Units {
    /// Encoder counts per motor revolution the manual states; `None` where it gives none (the
    /// axis config must then give `motor.counts_per_rev`).
    pub counts_per_rev: Option<u32>,
    /// Other resolutions the manual names (e.g. the 17-bit motors of the MR-J3).
    pub other_counts_per_rev: &'static [u32],
    /// Position objects (607Ah, 6064h, 60F4h): encoder counts on every model (the electronic
    /// gear fixed at or required to be 1/1 in the cyclic modes).
    pub position: PositionUnit,
    /// Velocity objects: 60FFh, 606Ch, 6081h, 6099h and the speed limit 2D20h.
    pub velocity: Stated<VelocityUnit>,
    /// Whether the manual states linear motors (mm/s) besides rotary ones.
    pub linear_motors: bool,
    /// The resolution the drive truncates velocity commands to, 10^exp10 of the velocity
    /// unit's quantity (MR-J3-T04 manual §9.6: 0.01 r/min); `None`: taken as received.
    pub command_truncation_exp10: Option<i8>,
    /// 6083h, 6084h, 6085h.
    pub acceleration: Stated<AccelerationUnit>,
    /// 6071h, 6072h, 6077h, 60E0h, 60E1h.
    pub torque: TorqueUnit,
    /// Where the facts come from, with the gaps named.
    pub source: &'static str,
}

/// What one LSB of a position object means.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PositionUnit {
    /// One encoder count (pulse).
    Count,
}

/// The quantity of an object, for the units table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Quantity {
    /// Position (607Ah, 6064h, 60F4h, 6062h).
    Position,
    /// Velocity (60FFh, 606Ch, 6081h, 6099h, 2D20h).
    Velocity,
    /// Acceleration / deceleration (6083h, 6084h, 6085h).
    Acceleration,
    /// Torque (6071h, 6072h, 6077h, 60E0h, 60E1h).
    Torque,
}

impl Quantity {
    /// The quantity of object `index`, for the objects cellrt scales; `None` for the others.
    pub const fn of(index: u16) -> Option<Quantity> {
        match index {
            0x607A | 0x6064 | 0x60F4 | 0x6062 => Some(Quantity::Position),
            0x60FF | 0x606C | 0x6081 | 0x6099 | 0x2D20 => Some(Quantity::Velocity),
            0x6083..=0x6085 => Some(Quantity::Acceleration),
            0x6071 | 0x6072 | 0x6077 | 0x60E0 | 0x60E1 => Some(Quantity::Torque),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn velocity_unit_spellings() {
        assert_eq!(
            VelocityUnit::parse("0.001 r/min"),
            Some(VelocityUnit::MILLI_RPM)
        );
        assert_eq!(
            VelocityUnit::parse("0.01 mm/s"),
            Some(VelocityUnit::CENTI_RPM)
        );
        assert_eq!(
            VelocityUnit::parse("1 r/min"),
            Some(VelocityUnit::MotorSpeed { exp10: 0 })
        );
        assert_eq!(
            VelocityUnit::parse("counts/s"),
            Some(VelocityUnit::CountsPerSecond)
        );
        assert_eq!(VelocityUnit::parse("0.003 r/min"), None);
        assert_eq!(VelocityUnit::parse("0.01 rpm"), None);
        assert_eq!(
            VelocityUnit::MILLI_RPM.name(MotorKind::Rotary),
            "0.001 r/min"
        );
        assert_eq!(VelocityUnit::CENTI_RPM.name(MotorKind::Linear), "0.01 mm/s");
        assert_eq!(Quantity::of(0x6085), Some(Quantity::Acceleration));
        assert_eq!(Quantity::of(0x6040), None);
    }
}
