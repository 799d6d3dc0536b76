//! Drive faults in words for the run's summary: which axis, which alarm (the manual's number,
//! name, cause and remedy through [`AlarmText`]) and when. Built by the recorder from the RT
//! thread's `drive_fault` events and by the MR-JE-C links from 2A42h, never on the RT thread.

use cellrt_cia402::profiles::AlarmText;
use serde::Serialize;

/// Drive faults a run's summary keeps (the first ones; `faults` counts them all).
pub const MAX_DRIVE_FAULTS: usize = 64;

/// One drive fault, in words.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct DriveFault {
    /// The axis.
    pub axis: String,
    /// The RT cycle of the fault's event; `None` for an axis on an MR-JE-C link.
    pub cycle: Option<u64>,
    /// The code the drive reported; `None` where it could not be read.
    pub code: Option<u16>,
    /// The object it was read from ("603Fh", "2A42h").
    pub register: Option<&'static str>,
    /// The manual's number and name, e.g. "AL.36 Receive error 2"; `None` where the model's
    /// manual does not list the code.
    pub alarm: Option<String>,
    /// The manual's cause, where it gives one.
    pub cause: Option<&'static str>,
    /// The manual's remedy, where it gives one.
    pub remedy: Option<&'static str>,
    /// The one-line text: the alarm with its code, or why the code is unknown.
    pub text: String,
}

impl DriveFault {
    /// The fault of `axis` at `cycle`, `text` being its decoded code (`None`: not readable).
    pub fn new(axis: &str, cycle: Option<u64>, text: Option<AlarmText>) -> DriveFault {
        DriveFault {
            axis: axis.to_string(),
            cycle,
            code: text.map(|t| t.code),
            register: text.map(|t| t.register.object()),
            alarm: text.and_then(|t| t.name()),
            cause: text.and_then(|t| t.cause()),
            remedy: text.and_then(|t| t.remedy()),
            text: text.map_or_else(
                || "fault (603Fh error code neither mapped nor readable)".to_string(),
                |t| t.to_string(),
            ),
        }
    }
}

/// "axis 'y': AL.36 Receive error 2 (603Fh = 0036h) at cycle 900".
impl std::fmt::Display for DriveFault {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "axis '{}': {}", self.axis, self.text)?;
        if let Some(c) = self.cycle {
            write!(f, " at cycle {c}")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cellrt_cia402::profiles::{mr_j3_t04, profile, DriveModel};

    #[test]
    fn a_listed_code_is_named_with_the_manuals_cause_and_remedy() {
        let p = profile(DriveModel::MrJ3T04);
        let f = DriveFault::new("y", Some(900), Some(p.alarm_text(mr_j3_t04::AL_36)));
        assert_eq!(f.alarm.as_deref(), Some("AL.36 Receive error 2"));
        assert_eq!(
            f.to_string(),
            "axis 'y': AL.36 Receive error 2 (603Fh = 0036h) at cycle 900"
        );
        assert!(f.cause.unwrap().contains("EtherCAT cable"));
        assert!(f.remedy.unwrap().contains("Replace the EtherCAT cable"));
    }

    #[test]
    fn an_unlisted_code_says_so_and_invents_nothing() {
        let p = profile(DriveModel::MrJ5GN1);
        let f = DriveFault::new("y", Some(3), Some(p.alarm_text(0x2220)));
        assert_eq!(f.alarm, None);
        assert_eq!((f.cause, f.remedy), (None, None));
        assert_eq!(
            f.text,
            "603Fh = 2220h (not listed for Mitsubishi MR-J5-G-N1)"
        );
        let unread = DriveFault::new("x", Some(3), None);
        assert_eq!(unread.code, None);
        assert!(unread.text.contains("neither mapped nor readable"));
    }
}
