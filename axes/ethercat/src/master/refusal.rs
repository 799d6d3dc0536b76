//! What a SubDevice refused during bring-up: an SDO (with the CiA 301 abort code), an optional
//! setting skipped with a warning, and a state change it would not make, explained with the
//! AL status code's ETG meaning and the model's likely causes.

use crate::register::al_code;
use cellrt_cia402::mode::ModeOfOperation;
use cellrt_cia402::profiles::BringUpCause;

/// CiA 301 abort codes that say a drive does not have an object or does not let it be
/// written: 0601 0002h "attempt to write a read only object", 0602 0000h "object does not
/// exist", 0609 0011h "sub-index does not exist". For an optional setting the master goes on
/// with a warning.
pub const OPTIONAL_OBJECT_ABORTS: [u32; 3] = [0x0601_0002, 0x0602_0000, 0x0609_0011];

/// The CiA 301 meaning of an SDO abort code (CiA 301 §7.2.4.3.17, ETG.1000.6 Table 41).
pub fn abort_meaning(code: u32) -> &'static str {
    match code {
        0x0503_0000 => "toggle bit not alternated",
        0x0504_0000 => "SDO protocol timed out",
        0x0504_0001 => "command specifier not valid or unknown",
        0x0601_0000 => "unsupported access to an object",
        0x0601_0001 => "attempt to read a write only object",
        0x0601_0002 => "attempt to write a read only object",
        0x0602_0000 => "object does not exist in the object dictionary",
        0x0604_0041 => "object cannot be mapped to the PDO",
        0x0604_0042 => "number and length of the objects to be mapped would exceed the PDO length",
        0x0604_0043 => "general parameter incompatibility",
        0x0607_0010 => "data type does not match, length of service parameter does not match",
        0x0607_0012 => "data type does not match, length of service parameter too high",
        0x0607_0013 => "data type does not match, length of service parameter too low",
        0x0609_0011 => "sub-index does not exist",
        0x0609_0030 => "value range of parameter exceeded",
        0x0800_0000 => "general error",
        0x0800_0020 => "data cannot be transferred or stored to the application",
        0x0800_0021 => "data cannot be transferred because of local control",
        0x0800_0022 => "data cannot be transferred because of the present device state",
        _ => "not a CiA 301 code (vendor specific)",
    }
}

/// An SDO a SubDevice refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RefusedSdo {
    /// Object index.
    pub index: u16,
    /// Sub-index.
    pub sub: u8,
    /// CiA 301 abort code.
    pub abort: u32,
}

impl RefusedSdo {
    /// The refusal an ethercrab SDO error carries, where it is an abort.
    pub(super) fn of(e: &ethercrab::error::Error) -> Option<RefusedSdo> {
        match *e {
            ethercrab::error::Error::Mailbox(ethercrab::error::MailboxError::Aborted {
                code,
                address,
                sub_index,
            }) => Some(RefusedSdo {
                index: address,
                sub: sub_index,
                abort: u32::from(code),
            }),
            _ => None,
        }
    }

    /// True if the abort says the object is absent or read-only ([`OPTIONAL_OBJECT_ABORTS`]).
    pub fn is_optional_object_abort(&self) -> bool {
        OPTIONAL_OBJECT_ABORTS.contains(&self.abort)
    }
}

impl std::fmt::Display for RefusedSdo {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{:04X}h:{:02X} aborted with {:04X} {:04X}h ({})",
            self.index,
            self.sub,
            self.abort >> 16,
            self.abort & 0xFFFF,
            abort_meaning(self.abort)
        )
    }
}

/// An optional setting bring-up skipped because the SubDevice does not have the object or
/// does not let it be written; the segment came up without it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BringUpWarning {
    /// Position of the SubDevice in the line.
    pub position: usize,
    /// Its (first) axis.
    pub axis: String,
    /// The SDO it refused.
    pub sdo: RefusedSdo,
    /// The value read from the object before the write, where it could be read.
    pub read: Option<u32>,
    /// The value the master wanted there.
    pub wanted: u32,
}

impl std::fmt::Display for BringUpWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "EtherCAT SubDevice {} (axis '{}'): optional {}; wanted {}",
            self.position, self.axis, self.sdo, self.wanted
        )?;
        if let Some(v) = self.read {
            write!(f, ", the drive reports {v}")?;
        }
        write!(f, "; continued: SYNC0 sets the cycle")
    }
}

/// A state change a SubDevice refused (AL status error indication, ETG.1000.6 §6.4.1.4),
/// with what can explain it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StateRefusal {
    /// Position in the line.
    pub position: usize,
    /// The SubDevice's name from its SII.
    pub name: String,
    /// Its (first) axis.
    pub axis: String,
    /// The configured model.
    pub model: &'static str,
    /// The state requested.
    pub requested: &'static str,
    /// The state it stays in.
    pub state: &'static str,
    /// AL status code (0134h).
    pub code: u16,
    /// The last SDO it refused during bring-up (an optional one skipped), if any.
    pub last_refused_sdo: Option<RefusedSdo>,
    /// The model's likely causes that fit the refusal, each with its source.
    pub causes: Vec<&'static BringUpCause>,
}

impl std::fmt::Display for StateRefusal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "EtherCAT SubDevice {} '{}' (axis '{}', {}) refused {}: it stays in {} with AL status code {:#06x} ({}, ETG.1000.6 Table 11)",
            self.position,
            self.name,
            self.axis,
            self.model,
            self.requested,
            self.state,
            self.code,
            al_code::name(self.code)
        )?;
        match &self.last_refused_sdo {
            Some(sdo) => write!(f, "; the last SDO it refused: {sdo}")?,
            None => write!(f, "; it refused no SDO")?,
        }
        for c in &self.causes {
            write!(f, "; likely cause: {} ({})", c.cause, c.source)?;
        }
        Ok(())
    }
}

/// The causes of `all` that fit a refusal with AL status `code` on a SubDevice whose axes run
/// `modes`, with distributed clocks `dc`.
pub fn fitting_causes(
    all: &'static [BringUpCause],
    code: u16,
    modes: &[ModeOfOperation],
    dc: bool,
) -> Vec<&'static BringUpCause> {
    all.iter()
        .filter(|c| c.al_codes.is_empty() || c.al_codes.contains(&code))
        .filter(|c| c.modes.is_empty() || modes.iter().any(|m| c.modes.contains(m)))
        .filter(|c| !(c.free_run_only && dc))
        .collect()
}

/// The SDO abort code of an ethercrab error: an Abort SDO Transfer's or an SDO Info Error's
/// code, 0800 0000h (general error) for any other failure.
pub(super) fn abort_code(e: ethercrab::error::Error) -> u32 {
    match e {
        ethercrab::error::Error::Mailbox(
            ethercrab::error::MailboxError::Aborted { code, .. }
            | ethercrab::error::MailboxError::SdoInfoAborted { code },
        ) => u32::from(code),
        _ => 0x0800_0000,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cellrt_cia402::profiles::{bring_up_causes, DriveModel};
    use ModeOfOperation::{CyclicSyncPosition as Csp, Homing};

    #[test]
    fn a_refused_sdo_names_object_code_and_meaning() {
        let r = RefusedSdo {
            index: 0x1C32,
            sub: 2,
            abort: 0x0601_0002,
        };
        assert_eq!(
            r.to_string(),
            "1C32h:02 aborted with 0601 0002h (attempt to write a read only object)"
        );
        assert!(r.is_optional_object_abort());
        assert!(!RefusedSdo {
            abort: 0x0609_0030,
            ..r
        }
        .is_optional_object_abort());
    }

    #[test]
    fn mr_j4_tm_causes_fit_the_mode_and_the_clock() {
        let all = bring_up_causes(DriveModel::MrJ4TM);
        let csp_free = fitting_causes(all, 0x0011, &[Csp], false);
        let text: Vec<&str> = csp_free.iter().map(|c| c.cause).collect();
        assert!(text.iter().any(|t| t.contains("PA01")), "{text:?}");
        assert!(text.iter().any(|t| t.contains("DC mode")), "{text:?}");
        assert!(text.iter().any(|t| t.contains("AL. 37")), "{text:?}");
        for c in &csp_free {
            assert!(c.source.starts_with("MR-J4-TM manual §"), "{}", c.source);
        }
        // With SYNC0 on, the free-run cause does not fit; in hm only, the csp/csv/cst ones not.
        let csp_dc = fitting_causes(all, 0x0011, &[Csp], true);
        assert!(csp_dc.iter().all(|c| !c.cause.contains("DC mode")));
        let hm = fitting_causes(all, 0x0011, &[Homing], false);
        assert!(hm.iter().all(|c| !c.cause.contains("PA01")));
    }

    #[test]
    fn a_state_refusal_reads_as_one_line_with_everything_named() {
        let r = StateRefusal {
            position: 1,
            name: "MR-J4-TM".into(),
            axis: "y".into(),
            model: "mr-j4-tm",
            requested: "SAFE-OP",
            state: "PRE-OP",
            code: 0x0030,
            last_refused_sdo: Some(RefusedSdo {
                index: 0x1C32,
                sub: 2,
                abort: 0x0601_0002,
            }),
            causes: fitting_causes(bring_up_causes(DriveModel::MrJ4TM), 0x0030, &[Csp], false),
        };
        let s = r.to_string();
        for part in [
            "SubDevice 1 'MR-J4-TM' (axis 'y', mr-j4-tm) refused SAFE-OP",
            "stays in PRE-OP with AL status code 0x0030 (invalid DC SYNC configuration, ETG.1000.6 Table 11)",
            "the last SDO it refused: 1C32h:02 aborted with 0601 0002h",
            "likely cause: ",
            "(MR-J4-TM manual §5.4.1",
        ] {
            assert!(s.contains(part), "{part:?} in {s}");
        }
    }
}
