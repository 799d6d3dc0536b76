//! The detail text of each event kind, as the recording, the log and the summary show it.

use cellrt_cia402::fsa::FsaState;
use cellrt_cia402::profiles::DriveProfile;

use crate::handoff::{CellCommand, CellState, EventKind, EventRecord, RejectReason, StopReason};

/// Human-readable detail of an event's value; `profile` is the drive of the event's axis, which
/// decodes a drive fault's or an Emergency's error code into the manual's words.
pub fn describe_event(e: &EventRecord, profile: Option<&DriveProfile>) -> String {
    match e.kind {
        EventKind::CellState => CellState::from_u8(e.value as u8)
            .map(|s| s.as_str().to_string())
            .unwrap_or_default(),
        EventKind::FsaState => u8::try_from(e.value)
            .ok()
            .and_then(FsaState::from_repr)
            .map_or("unknown", FsaState::as_str)
            .to_string(),
        EventKind::Command | EventKind::CommandRefused => CellCommand::from_code(e.value)
            .map(|c| c.as_str().to_string())
            .unwrap_or_default(),
        EventKind::MotionStarted | EventKind::MotionFinished | EventKind::Underrun => {
            format!("motion {}", e.value)
        }
        EventKind::SetpointRejected => RejectReason::from_u8(e.value as u8)
            .map(|r| r.as_str().to_string())
            .unwrap_or_default(),
        EventKind::StopStarted => {
            let reason = StopReason::from_u8((e.value / 16) as u8)
                .map(|r| r.as_str())
                .unwrap_or("unknown");
            let reaction = ["controlled_stop", "quick_stop", "disable"]
                .get((e.value % 16) as usize)
                .copied()
                .unwrap_or("unknown");
            format!("{reason} ({reaction})")
        }
        EventKind::Overrun => format!("woke {} µs past the next deadline", e.value / 1000),
        EventKind::DriveFault if e.value < 0 => {
            "fault (603Fh error code neither mapped nor readable)".to_string()
        }
        EventKind::DriveFault => match profile {
            Some(p) => p.alarm_text(e.value as u16).long(),
            None => format!("error code 0x{:04X}", e.value),
        },
        EventKind::RecordsDropped => format!("{} records dropped", e.value),
        EventKind::StartSlipped => format!("the motion started {} cycles late", e.value),
        EventKind::ProfileStarted => match e.value {
            1 => "drive-side move (pp)",
            2 => "drive-side jog (pv)",
            3 => "drive-side torque (tq)",
            4 => "halt on",
            5 => "halt off",
            6 => "mode switch to pp",
            _ => "mode switch to csp",
        }
        .to_string(),
        EventKind::ProfileFinished => match e.value {
            0 => "done",
            1 => "refused",
            2 => "cancelled (the drive left Operation enabled, or a stop before its start)",
            _ => "superseded by the next motion",
        }
        .to_string(),
        EventKind::ModeSwitched => i8::try_from(e.value)
            .ok()
            .and_then(cellrt_cia402::mode::ModeOfOperation::from_i8)
            .map_or_else(
                || format!("mode {} (6061h)", e.value),
                |m| format!("now in {} (6061h)", m.as_str()),
            ),
        EventKind::ModeSwitchFailed => match e.value {
            1 => "withdrawn: 6061h did not show the mode in time",
            _ => "withdrawn: the drive faulted",
        }
        .to_string(),
        EventKind::HomingStarted => match e.value {
            crate::handoff::HOME_BY_C_CR => "home setting by C_CR (current position)".to_string(),
            crate::handoff::HOME_BY_C_CR2 => "home setting by C_CR2 (last Z phase)".to_string(),
            m => format!("method {m} (6098h)"),
        },
        EventKind::HomingFinished => match u8::try_from(e.value)
            .ok()
            .and_then(cellrt_cia402::homing::HomingFailure::from_u8)
        {
            None => "homing attained".to_string(),
            Some(f) => f.as_str().to_string(),
        },
        EventKind::CommunicationError => cellrt_config::CommWatchdog::from_code(e.value)
            .map_or(
                "unknown communication watchdog",
                cellrt_config::CommWatchdog::describe,
            )
            .to_string(),
        EventKind::AlStatus => cellrt_ethercat::register::AlStatus::decode(e.value).describe(),
        EventKind::Emergency => {
            let m = crate::handoff::decode_emergency(e.value);
            let d = m.data;
            let named = profile
                .and_then(|p| p.alarm_text(m.error_code).name())
                .map(|n| format!(" ({n})"))
                .unwrap_or_default();
            format!(
                "error code 0x{:04X}{named}, error register 0x{:02X}, data {:02X} {:02X} {:02X} {:02X} {:02X}",
                m.error_code, m.error_register, d[0], d[1], d[2], d[3], d[4]
            )
        }
        EventKind::MailboxDiscarded => format!(
            "mailbox type {}, CoE service {} (discarded)",
            e.value & 0xFF,
            e.value >> 8
        ),
        EventKind::BringUpWarning => format!(
            "optional {} at bring-up; continued (SYNC0 sets the cycle)",
            crate::handoff::decode_refused_sdo(e.value)
        ),
        EventKind::FaultInjected | EventKind::FaultLeftToSegment => {
            cellrt_config::FaultKind::from_code(e.value)
                .map_or("unknown", cellrt_config::FaultKind::name)
                .to_string()
        }
        EventKind::StopFinished
        | EventKind::MasterTimeout
        | EventKind::BusError
        | EventKind::PlannerConnected
        | EventKind::PlannerLost => String::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cellrt_cia402::profiles::{generic_cia402, mr_j5_g_n1, profile, DriveModel};

    fn fault(code: i64) -> EventRecord {
        EventRecord {
            cycle: 7,
            kind: EventKind::DriveFault,
            axis: 0,
            value: code,
        }
    }

    #[test]
    fn a_drive_fault_reads_in_the_manuals_words() {
        let generic = profile(DriveModel::GenericCia402);
        assert_eq!(
            describe_event(
                &fault(i64::from(generic_cia402::FOLLOWING_ERROR)),
                Some(generic)
            ),
            "8611h Following error (CiA 402) (603Fh = 8611h)"
        );
        let j5 = profile(DriveModel::MrJ5GN1);
        let text = describe_event(&fault(i64::from(mr_j5_g_n1::AL_011_2)), Some(j5));
        assert!(
            text.starts_with("AL.011.2 Invalid axis setting error (603Fh = 0112h); cause: "),
            "{text}"
        );
        assert!(!text.contains("remedy"), "the manual gives none: {text}");
        assert_eq!(
            describe_event(&fault(0x2220), Some(j5)),
            "603Fh = 2220h (not listed for Mitsubishi MR-J5-G-N1)"
        );
        assert_eq!(describe_event(&fault(0x2220), None), "error code 0x2220");
        assert!(describe_event(&fault(-1), Some(j5)).contains("neither mapped nor readable"));
    }
}
