//! Modes of operation (6060h / 6061h).
//!
//! Values from MR-J5-G-N1 manual §1.1, §6.1, §7.4.

use std::str::FromStr;

/// A CiA 402 mode of operation, as written to 6060h and echoed in 6061h.
///
/// Only the standard modes are listed; the manufacturer mode −101 is undocumented (§1.2).
///
/// The names are the short symbols used in configuration and logs (§1.2 "Symbol").
#[derive(
    Debug,
    Clone,
    Copy,
    PartialEq,
    Eq,
    Hash,
    PartialOrd,
    Ord,
    strum::Display,
    strum::IntoStaticStr,
    strum::FromRepr,
)]
#[repr(i8)]
pub enum ModeOfOperation {
    /// Profile position (pp): the drive plans a move to an end position.
    #[strum(serialize = "pp")]
    ProfilePosition = 1,
    /// Profile velocity (pv): the drive ramps to a target speed.
    #[strum(serialize = "pv")]
    ProfileVelocity = 3,
    /// Profile torque (tq): the drive ramps to a target torque.
    #[strum(serialize = "tq")]
    ProfileTorque = 4,
    /// Homing (hm): the drive runs the method selected in 6098h.
    #[strum(serialize = "hm")]
    Homing = 6,
    /// Cyclic synchronous position (csp): an absolute position setpoint every cycle.
    #[strum(serialize = "csp")]
    CyclicSyncPosition = 8,
    /// Cyclic synchronous velocity (csv): a velocity setpoint every cycle.
    #[strum(serialize = "csv")]
    CyclicSyncVelocity = 9,
    /// Cyclic synchronous torque (cst): a torque setpoint every cycle.
    #[strum(serialize = "cst")]
    CyclicSyncTorque = 10,
}

/// Text that names no mode of operation.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown mode of operation {text:?}; valid names are pp, pv, tq, hm, csp, csv, cst")]
pub struct ParseModeError {
    /// The rejected text.
    pub text: String,
}

impl ModeOfOperation {
    /// Every mode, in 6060h value order.
    pub const ALL: [ModeOfOperation; 7] = [
        Self::ProfilePosition,
        Self::ProfileVelocity,
        Self::ProfileTorque,
        Self::Homing,
        Self::CyclicSyncPosition,
        Self::CyclicSyncVelocity,
        Self::CyclicSyncTorque,
    ];

    /// Decodes a 6060h/6061h value; `None` for 0 (no mode), manufacturer modes and garbage.
    pub const fn from_i8(v: i8) -> Option<Self> {
        Self::from_repr(v)
    }

    /// The 6060h value.
    pub const fn as_i8(self) -> i8 {
        self as i8
    }

    /// The short symbol used in configuration and logs ("csp", "pp", …; §1.2 "Symbol").
    pub fn as_str(self) -> &'static str {
        self.into()
    }

    /// True for the cyclic synchronous modes (csp, csv, cst) that need a setpoint every cycle.
    pub const fn is_cyclic(self) -> bool {
        matches!(
            self,
            Self::CyclicSyncPosition | Self::CyclicSyncVelocity | Self::CyclicSyncTorque
        )
    }

    /// True for the position modes (pp, csp), which switch only at zero speed (§4.3 rule 4).
    pub const fn is_position(self) -> bool {
        matches!(self, Self::ProfilePosition | Self::CyclicSyncPosition)
    }
}

impl FromStr for ModeOfOperation {
    type Err = ParseModeError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .into_iter()
            .find(|m| m.as_str() == s)
            .ok_or_else(|| ParseModeError { text: s.to_owned() })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn i8_and_names_round_trip() {
        for m in ModeOfOperation::ALL {
            assert_eq!(ModeOfOperation::from_i8(m.as_i8()), Some(m));
            assert_eq!(m.as_str().parse::<ModeOfOperation>(), Ok(m));
        }
        assert_eq!(ModeOfOperation::CyclicSyncPosition.as_i8(), 8);
        for v in [0i8, 2, 5, 7, 11, -101, -1, i8::MIN, i8::MAX] {
            assert_eq!(ModeOfOperation::from_i8(v), None);
        }
    }

    #[test]
    fn bad_name_lists_valid_names() {
        let e = "CSP".parse::<ModeOfOperation>().unwrap_err().to_string();
        assert!(e.contains("\"CSP\"") && e.contains("csp, csv, cst"), "{e}");
    }
}
