//! The vocabulary of the MR-JE-C object dictionary (MR-JE-C manual §7.2, §7.3 column heads):
//! data types, access rules, ranges, units and the software versions objects appear in.

/// The servo amplifier's software version where the manual makes a difference (MR-JE-C manual
/// §7.3 notes 1–2, §1.1): A3 adds SLMP over TCP, Modbus/TCP and the access logs; A4 adds
/// Modbus RTU, the positioning modes, [Pr. PN10] and the point-table objects.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default, strum::Display)]
pub enum SoftwareVersion {
    /// A0–A2: SLMP over UDP only.
    A0,
    /// A3.
    A3,
    /// A4 or later (the default).
    #[default]
    A4,
}

/// Text that names no MR-JE-C software version.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("software version {0:?}: expected A0, A3 or A4")]
pub struct ParseSoftwareVersionError(pub String);

impl std::str::FromStr for SoftwareVersion {
    type Err = ParseSoftwareVersionError;

    /// A0–A2 (all without TCP, §1.1), A3 or A4, in either case.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.to_ascii_uppercase().as_str() {
            "A0" | "A1" | "A2" => Ok(SoftwareVersion::A0),
            "A3" => Ok(SoftwareVersion::A3),
            "A4" => Ok(SoftwareVersion::A4),
            _ => Err(ParseSoftwareVersionError(s.to_string())),
        }
    }
}

/// A data type of the object dictionary (§7.3 "Data Type").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DataType {
    /// Signed 8 bit.
    I8,
    /// Unsigned 8 bit.
    U8,
    /// Signed 16 bit.
    I16,
    /// Unsigned 16 bit.
    U16,
    /// Signed 32 bit.
    I32,
    /// Unsigned 32 bit.
    U32,
    /// Visible string of a fixed number of Modbus registers (two characters each).
    Vs {
        /// Registers ("No. of points").
        registers: u8,
    },
}

impl DataType {
    /// Bytes of a value on SLMP (strings: two per register).
    pub const fn bytes(self) -> usize {
        match self {
            Self::I8 | Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
            Self::I32 | Self::U32 => 4,
            Self::Vs { registers } => 2 * registers as usize,
        }
    }

    /// Modbus registers of a value: 8- and 16-bit types one, 32-bit two (MR-JE-C manual §3.1,
    /// read with the examples of §3.6, not the POINT's garbled byte counts).
    pub const fn registers(self) -> usize {
        match self {
            Self::I8 | Self::U8 | Self::I16 | Self::U16 => 1,
            Self::I32 | Self::U32 => 2,
            Self::Vs { registers } => registers as usize,
        }
    }

    /// The values the type holds (strings: none).
    pub const fn bounds(self) -> Option<(i64, i64)> {
        Some(match self {
            Self::I8 => (i8::MIN as i64, i8::MAX as i64),
            Self::U8 => (0, u8::MAX as i64),
            Self::I16 => (i16::MIN as i64, i16::MAX as i64),
            Self::U16 => (0, u16::MAX as i64),
            Self::I32 => (i32::MIN as i64, i32::MAX as i64),
            Self::U32 => (0, u32::MAX as i64),
            Self::Vs { .. } => return None,
        })
    }
}

/// Access rule (§7.3 "Access").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, strum::Display)]
#[strum(serialize_all = "lowercase")]
pub enum Access {
    /// Read only.
    Ro,
    /// Read and write.
    Rw,
    /// Write only.
    Wo,
}

impl Access {
    /// Reading is allowed.
    pub const fn readable(self) -> bool {
        !matches!(self, Self::Wo)
    }

    /// Writing is allowed.
    pub const fn writable(self) -> bool {
        !matches!(self, Self::Ro)
    }
}

/// The values a write may carry (§7.3 "Range", or the tighter "[Setting range]" of an object's
/// description, which the manual gives precedence).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Range {
    /// Any value of the data type.
    Type,
    /// Only the default ("(fixed)").
    Fixed,
    /// One of these inclusive spans.
    Spans(&'static [(i64, i64)]),
    /// Only this value; any other is refused with "outside the parameter range" (2D52h,
    /// MR-JE-C manual §6.2).
    Only(i64),
    /// 0 up to the motor's instantaneous permissible speed (a property of the motor).
    PermissibleSpeed,
    /// Set automatically by the drive; a write is refused with "outside the parameter range"
    /// (607Bh:1/2, §7.3; 607Ch "causes an error", the same code by our choice).
    Automatic,
}

/// Unit of an object's value (§7.3 "Units", §10.4 of the extract).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, strum::Display)]
pub enum Unit {
    /// No unit.
    #[default]
    #[strum(serialize = "")]
    None,
    /// The position command unit of [Pr. PT01] (mm, inch, degree or pulse).
    #[strum(serialize = "pos units")]
    PosUnits,
    /// Encoder pulses.
    #[strum(serialize = "pulse")]
    Pulse,
    /// kpulse/s.
    #[strum(serialize = "kpulse/s")]
    KiloPulsePerSecond,
    /// r/min.
    #[strum(serialize = "r/min")]
    Rpm,
    /// 0.01 r/min.
    #[strum(serialize = "0.01 r/min")]
    CentiRpm,
    /// Milliseconds (accelerations are time constants to rated speed).
    #[strum(serialize = "ms")]
    Millisecond,
    /// Hours.
    #[strum(serialize = "hour")]
    Hour,
    /// Percent.
    #[strum(serialize = "%")]
    Percent,
    /// 0.1 % (of rated torque for torques).
    #[strum(serialize = "0.1%")]
    TenthPercent,
    /// 0.1 % per second (6087h).
    #[strum(serialize = "0.1%/s")]
    TenthPercentPerSecond,
    /// Volt.
    #[strum(serialize = "V")]
    Volt,
    /// 0.01 V.
    #[strum(serialize = "0.01 V")]
    CentiVolt,
    /// Revolutions.
    #[strum(serialize = "rev")]
    Revolution,
    /// 0.01 times (inertia ratio).
    #[strum(serialize = "0.01 times")]
    CentiTimes,
    /// Degree Celsius.
    #[strum(serialize = "°C")]
    Celsius,
    /// Hertz.
    #[strum(serialize = "Hz")]
    Hertz,
    /// Watt.
    #[strum(serialize = "W")]
    Watt,
    /// Watt hours.
    #[strum(serialize = "Wh")]
    WattHour,
    /// A count of events.
    #[strum(serialize = "times")]
    Times,
}

/// A default (§7.3 "Default"), which some objects give per software version.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Initial {
    /// The manual gives none (a property of the motor or the unit; 0 unless the emulator's
    /// parameters say otherwise).
    Unstated,
    /// This value.
    Value(i64),
    /// A3 or earlier / A4 or later.
    BySoftware {
        /// A3 or earlier.
        a3: i64,
        /// A4 or later.
        a4: i64,
    },
}

impl Initial {
    /// The value on software `sw` (`Unstated`: none).
    pub const fn value(self, sw: SoftwareVersion) -> Option<i64> {
        match self {
            Self::Unstated => None,
            Self::Value(v) => Some(v),
            Self::BySoftware { a3, a4 } => Some(match sw {
                SoftwareVersion::A4 => a4,
                _ => a3,
            }),
        }
    }
}
