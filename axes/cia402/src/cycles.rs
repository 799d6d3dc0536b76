//! Bus-cycle counts and the communication cycle time.
//!
//! The cycle times are the seven PDO cycles of the Mitsubishi CoE drives
//! (MR-J5-G-N1 manual §2.1, §4.1, §6.2, §6.3, §6.2).

use std::fmt;
use std::time::Duration;

/// A count of bus cycles (one cycle = one PDO exchange).
///
/// Used for every timeout and hold time so the cyclic code never reads a clock.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
pub struct Cycles(pub u32);

impl Cycles {
    /// Zero cycles.
    pub const ZERO: Cycles = Cycles(0);

    /// The count as a plain integer.
    pub const fn get(self) -> u32 {
        self.0
    }
}

impl fmt::Display for Cycles {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} cycles", self.0)
    }
}

/// The PDO cycle times accepted by the drives, in µs (0.125 … 8 ms; MR-J5-G-N1 manual §2.1, §4.1, §6.2, §6.3).
pub const ALLOWED_MICROS: [u32; 7] = [125, 250, 500, 1000, 2000, 4000, 8000];

/// A validated communication cycle time (one of [`ALLOWED_MICROS`]).
///
/// Constructed only through [`CycleTime::from_micros`], so any `CycleTime` is one a drive can run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct CycleTime {
    ns: u32,
}

/// A cycle time that is not one of [`ALLOWED_MICROS`].
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("cycle time {micros} µs is not supported; allowed values are 125, 250, 500, 1000, 2000, 4000, 8000 µs")]
pub struct CycleTimeError {
    /// The rejected value in µs.
    pub micros: u32,
}

impl CycleTime {
    /// Validates a cycle time given in µs against [`ALLOWED_MICROS`].
    pub fn from_micros(micros: u32) -> Result<CycleTime, CycleTimeError> {
        if ALLOWED_MICROS.contains(&micros) {
            Ok(CycleTime { ns: micros * 1000 })
        } else {
            Err(CycleTimeError { micros })
        }
    }

    /// The cycle time in ns.
    pub const fn as_nanos(self) -> u64 {
        self.ns as u64
    }

    /// The cycle time in µs (exact: every allowed value is a whole number of µs).
    pub const fn as_micros(self) -> u32 {
        self.ns / 1000
    }

    /// The cycle time in seconds, for the plant integration.
    pub fn as_secs_f64(self) -> f64 {
        f64::from(self.ns) * 1e-9
    }

    /// The cycle time as a [`Duration`].
    pub const fn as_duration(self) -> Duration {
        Duration::from_nanos(self.ns as u64)
    }

    /// The number of whole cycles that cover `d`, rounding up (a hold of 10 ms at 4 ms is 3 cycles).
    ///
    /// Saturates at `u32::MAX` cycles.
    pub fn cycles_for(self, d: Duration) -> Cycles {
        let ns = d.as_nanos();
        let per = u128::from(self.ns);
        let n = ns.div_ceil(per);
        Cycles(u32::try_from(n).unwrap_or(u32::MAX))
    }
}

impl fmt::Display for CycleTime {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} µs", self.as_micros())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accepts_exactly_the_allowed_values() {
        for us in ALLOWED_MICROS {
            let c = CycleTime::from_micros(us).unwrap();
            assert_eq!(c.as_micros(), us);
            assert_eq!(c.as_nanos(), u64::from(us) * 1000);
        }
        for us in [0, 1, 124, 126, 100, 3000, 16000, u32::MAX] {
            let e = CycleTime::from_micros(us).unwrap_err();
            let msg = e.to_string();
            assert!(msg.contains(&us.to_string()), "{msg}");
            assert!(msg.contains("125, 250, 500"), "{msg}");
        }
    }

    #[test]
    fn cycles_for_rounds_up() {
        let c4 = CycleTime::from_micros(4000).unwrap();
        assert_eq!(c4.cycles_for(Duration::from_millis(10)), Cycles(3));
        assert_eq!(c4.cycles_for(Duration::from_millis(8)), Cycles(2));
        assert_eq!(c4.cycles_for(Duration::ZERO), Cycles(0));
        let c125 = CycleTime::from_micros(125).unwrap();
        assert_eq!(c125.cycles_for(Duration::from_millis(10)), Cycles(80));
        assert_eq!(
            c125.cycles_for(Duration::from_secs(u64::MAX)),
            Cycles(u32::MAX)
        );
        assert!((c125.as_secs_f64() - 125e-6).abs() < 1e-15);
    }
}
