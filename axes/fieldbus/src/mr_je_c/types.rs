//! What the MR-JE-C object dictionary adds to the drives' one object-dictionary vocabulary
//! (`cellrt_cia402::profiles::facts`: data types, access rules, ranges, units, re-exported
//! here): the software versions objects appear in and per-version defaults (MR-JE-C manual
//! §7.2, §7.3 column heads).

pub use cellrt_cia402::profiles::facts::{Access, DataType, Range, Unit};

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
