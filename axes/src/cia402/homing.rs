//! Master-side homing in the drive's homing mode (hm), cycle-driven and allocation-free.
//!
//! The sequence is the one the MR-J5-G-N1 / MR-JET-G-N1 bring-up gives (mr-j5-g-n1.md §2.2
//! step 5, mr-jet-g-n1.md §2.2): with the axis in Operation enabled, set 6060h = 6 and wait for
//! 6061h = 6, start the method selected in 6098h with controlword bit 4 (homing operation
//! start), wait for statusword bit 12 (homing attained) or bit 13 (homing error), then switch
//! back to the cyclic mode and wait for 6061h to show it. 6098h itself is written acyclically
//! before the start (the caller's job).
//!
//! Where the TxPDO does not map 6061h (MR-J3-T04, mr-j3-t04.md §3.9) the mode is taken to have
//! switched after [`HomingParams::mode_settle`] consecutive cycles at standstill (a drive
//! changes a position mode only at zero speed, and statusword bit 12 means "following the
//! command" in csp, so it must not be read as "homing attained" before the switch): the manual
//! gives no figure, so this is a named parameter.

use super::mode::ModeOfOperation;
use super::statusword::Statusword;
use crate::Cycles;

/// Statusword bit 12 in hm: homing attained.
pub const HOMING_ATTAINED_BIT: u16 = 1 << 12;
/// Statusword bit 13 in hm: homing error.
pub const HOMING_ERROR_BIT: u16 = 1 << 13;
/// Controlword bit 4 in hm: homing operation start (HOS).
pub const HOMING_START_BIT: u16 = 1 << 4;

/// The 6098h method to home a drive of `profile` with: `requested` if its manual lists it,
/// else the model's first data-set method (home = the current position). Refused, with the
/// reason, where the manual lists none, or where the TxPDO does not carry 6061h (in csp bit 12
/// of the statusword means "following the command", so homing attained could not be told
/// apart without the mode display).
pub fn choose_method(
    profile: &crate::profiles::DriveProfile,
    requested: Option<i8>,
) -> Result<i8, String> {
    if !profile
        .tx_pdo
        .maps(crate::pdo::objects::MODES_OF_OPERATION_DISPLAY)
    {
        return Err(format!(
            "the {} default TxPDO does not carry 6061h, so the end of a homing in hm cannot be told from csp's statusword bit 12",
            profile.name
        ));
    }
    match requested {
        Some(m) if profile.homing_methods.contains(&m) => Ok(m),
        Some(m) => Err(format!(
            "the {} manual lists no homing method {m} (6098h; it lists {:?})",
            profile.name, profile.homing_methods
        )),
        None => profile
            .data_set_homing_methods
            .first()
            .copied()
            .ok_or_else(|| {
                format!(
                    "the {} manual lists no homing methods (6098h); hm cannot be used on it",
                    profile.name
                )
            }),
    }
}

/// Timing of the sequence.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HomingParams {
    /// Cycles the sequence may take in all before it fails.
    pub timeout: Cycles,
    /// Cycles after which a mode change counts as done where 6061h is not in the TxPDO.
    pub mode_settle: Cycles,
}

/// Why homing failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum HomingFailure {
    /// The drive set statusword bit 13 (e.g. a method it does not run).
    DriveError = 1,
    /// 6061h never showed hm, or never came back to the cyclic mode, or the method never
    /// ended, within the timeout.
    Timeout = 2,
    /// The axis left Operation enabled (fault, disable) during homing.
    NotEnabled = 3,
    /// The drive refused the method written to 6098h (SDO abort).
    MethodRefused = 4,
}

impl HomingFailure {
    /// Short name for events and messages.
    pub fn as_str(self) -> &'static str {
        match self {
            HomingFailure::DriveError => "the drive reported a homing error (statusword bit 13)",
            HomingFailure::Timeout => "homing did not complete within the timeout",
            HomingFailure::NotEnabled => "the axis left Operation enabled during homing",
            HomingFailure::MethodRefused => "the drive refused the homing method (6098h)",
        }
    }

    /// Inverse of `as u8`.
    pub fn from_u8(v: u8) -> Option<HomingFailure> {
        match v {
            1 => Some(HomingFailure::DriveError),
            2 => Some(HomingFailure::Timeout),
            3 => Some(HomingFailure::NotEnabled),
            4 => Some(HomingFailure::MethodRefused),
            _ => None,
        }
    }
}

/// Where the sequence stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HomingPhase {
    /// Not homing.
    Idle,
    /// 6060h = 6 sent; waiting for 6061h = 6.
    EnterHm,
    /// Controlword bit 4 set; waiting for bit 12 or 13.
    Running,
    /// Back to the cyclic mode; waiting for 6061h. Carries the result to report.
    LeaveHm(Option<HomingFailure>),
    /// Ended: `None` = homing attained.
    Done(Option<HomingFailure>),
}

/// What the RxPDO carries for the axis this cycle while homing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HomingCommand {
    /// 6060h.
    pub mode: ModeOfOperation,
    /// Controlword bit 4 (HOS) to OR into the controlword.
    pub start_bit: u16,
}

/// The homing sequence of one axis.
#[derive(Debug, Clone, Copy)]
pub struct HomingSequencer {
    params: HomingParams,
    cyclic: ModeOfOperation,
    phase: HomingPhase,
    /// Cycles since the start.
    elapsed: u32,
    /// Cycles in the current phase.
    in_phase: u32,
    /// Consecutive standstill cycles in the current phase (mode change without 6061h).
    quiet: u32,
}

impl HomingSequencer {
    /// A sequencer returning to `cyclic` mode afterwards.
    pub fn new(params: HomingParams, cyclic: ModeOfOperation) -> Self {
        HomingSequencer {
            params,
            cyclic,
            phase: HomingPhase::Idle,
            elapsed: 0,
            in_phase: 0,
            quiet: 0,
        }
    }

    /// Starts the sequence (6098h must already hold the method).
    pub fn start(&mut self) {
        self.phase = HomingPhase::EnterHm;
        self.elapsed = 0;
        self.in_phase = 0;
        self.quiet = 0;
    }

    /// Where it stands.
    pub fn phase(&self) -> HomingPhase {
        self.phase
    }

    /// Whether the sequence drives the axis (between start and the end).
    pub fn is_active(&self) -> bool {
        !matches!(self.phase, HomingPhase::Idle | HomingPhase::Done(_))
    }

    /// Forgets a finished result.
    pub fn clear(&mut self) {
        self.phase = HomingPhase::Idle;
    }

    /// One cycle: from the statusword, 6061h (`None` where the TxPDO does not map it) and
    /// whether the motor stands still (606Ch = 0), the mode and HOS bit to send, or `None` when
    /// not homing.
    pub fn update(
        &mut self,
        statusword: Statusword,
        enabled: bool,
        mode_display: Option<i8>,
        standstill: bool,
    ) -> Option<HomingCommand> {
        if !self.is_active() {
            return None;
        }
        self.elapsed = self.elapsed.saturating_add(1);
        self.in_phase = self.in_phase.saturating_add(1);
        self.quiet = if standstill {
            self.quiet.saturating_add(1)
        } else {
            0
        };
        let settled = |want: ModeOfOperation, quiet: u32, params: &HomingParams| match mode_display
        {
            Some(m) => m == want.as_i8(),
            None => quiet > params.mode_settle.0,
        };
        let timed_out = self.elapsed > self.params.timeout.0;
        let next = match self.phase {
            HomingPhase::EnterHm if !enabled => {
                HomingPhase::LeaveHm(Some(HomingFailure::NotEnabled))
            }
            HomingPhase::EnterHm if settled(ModeOfOperation::Homing, self.quiet, &self.params) => {
                HomingPhase::Running
            }
            HomingPhase::EnterHm if timed_out => HomingPhase::LeaveHm(Some(HomingFailure::Timeout)),
            HomingPhase::Running if !enabled => {
                HomingPhase::LeaveHm(Some(HomingFailure::NotEnabled))
            }
            // Bits 12/13 are read only after the start has been sent once (a previous
            // homing's bit 12 is cleared by the start, mr-j4-tm.md §4.10).
            HomingPhase::Running if self.in_phase > 1 && statusword.0 & HOMING_ERROR_BIT != 0 => {
                HomingPhase::LeaveHm(Some(HomingFailure::DriveError))
            }
            HomingPhase::Running
                if self.in_phase > 1 && statusword.0 & HOMING_ATTAINED_BIT != 0 =>
            {
                HomingPhase::LeaveHm(None)
            }
            HomingPhase::Running if timed_out => HomingPhase::LeaveHm(Some(HomingFailure::Timeout)),
            HomingPhase::LeaveHm(r) if settled(self.cyclic, self.quiet, &self.params) => {
                HomingPhase::Done(r)
            }
            HomingPhase::LeaveHm(r)
                if timed_out && self.elapsed > self.params.timeout.0.saturating_mul(2) =>
            {
                HomingPhase::Done(r.or(Some(HomingFailure::Timeout)))
            }
            p => p,
        };
        if next != self.phase {
            self.phase = next;
            self.in_phase = 0;
            self.quiet = 0;
        }
        Some(match self.phase {
            HomingPhase::EnterHm => HomingCommand {
                mode: ModeOfOperation::Homing,
                start_bit: 0,
            },
            HomingPhase::Running => HomingCommand {
                mode: ModeOfOperation::Homing,
                start_bit: HOMING_START_BIT,
            },
            _ => HomingCommand {
                mode: self.cyclic,
                start_bit: 0,
            },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const P: HomingParams = HomingParams {
        timeout: Cycles(100),
        mode_settle: Cycles(3),
    };

    fn sw(bits: u16) -> Statusword {
        Statusword(0x0027 | bits)
    }

    #[test]
    fn the_method_is_one_the_manual_lists_on_a_drive_that_shows_6061h() {
        use crate::profiles::{profile, DriveModel};
        let j4 = profile(DriveModel::MrJ4TM);
        assert_eq!(choose_method(j4, None), Ok(-3));
        assert_eq!(choose_method(j4, Some(35)), Ok(35));
        assert!(choose_method(j4, Some(99))
            .unwrap_err()
            .contains("no homing method 99"));
        let j5 = profile(DriveModel::MrJ5GN1);
        assert!(choose_method(j5, None)
            .unwrap_err()
            .contains("lists no homing methods"));
        let j3 = profile(DriveModel::MrJ3T04);
        assert!(choose_method(j3, Some(35)).unwrap_err().contains("6061h"));
    }

    #[test]
    fn enters_hm_starts_waits_for_attained_and_leaves() {
        let mut h = HomingSequencer::new(P, ModeOfOperation::CyclicSyncPosition);
        assert_eq!(h.update(sw(0), true, Some(8), true), None);
        h.start();
        let c = h.update(sw(0), true, Some(8), true).unwrap();
        assert_eq!((c.mode, c.start_bit), (ModeOfOperation::Homing, 0));
        // 6061h shows hm: the start bit goes out.
        let c = h.update(sw(0), true, Some(6), true).unwrap();
        assert_eq!(c.start_bit, HOMING_START_BIT);
        // A stale bit 12 in the first cycle of the start is not taken as the result.
        let c = h
            .update(sw(HOMING_ATTAINED_BIT), true, Some(6), true)
            .unwrap();
        assert_eq!(c.start_bit, HOMING_START_BIT);
        assert_eq!(h.phase(), HomingPhase::Running);
        let c = h
            .update(sw(HOMING_ATTAINED_BIT), true, Some(6), true)
            .unwrap();
        assert_eq!(c.mode, ModeOfOperation::CyclicSyncPosition);
        assert_eq!(h.phase(), HomingPhase::LeaveHm(None));
        h.update(sw(0), true, Some(8), true);
        assert_eq!(h.phase(), HomingPhase::Done(None));
        assert!(!h.is_active());
        assert_eq!(h.update(sw(0), true, Some(8), true), None);
    }

    #[test]
    fn a_homing_error_or_a_disable_fails_and_still_returns_to_the_cyclic_mode() {
        let mut h = HomingSequencer::new(P, ModeOfOperation::CyclicSyncVelocity);
        h.start();
        h.update(sw(0), true, Some(6), true);
        h.update(sw(0), true, Some(6), true);
        h.update(sw(HOMING_ERROR_BIT), true, Some(6), true);
        assert_eq!(
            h.phase(),
            HomingPhase::LeaveHm(Some(HomingFailure::DriveError))
        );
        let c = h.update(sw(0), true, Some(6), true).unwrap();
        assert_eq!(c.mode, ModeOfOperation::CyclicSyncVelocity);
        h.update(sw(0), true, Some(9), true);
        assert_eq!(
            h.phase(),
            HomingPhase::Done(Some(HomingFailure::DriveError))
        );

        let mut h = HomingSequencer::new(P, ModeOfOperation::CyclicSyncPosition);
        h.start();
        h.update(sw(0), false, Some(8), true);
        assert_eq!(
            h.phase(),
            HomingPhase::LeaveHm(Some(HomingFailure::NotEnabled))
        );
    }

    #[test]
    fn without_6061h_a_moving_motor_holds_the_switch_and_bit_12_is_not_taken_for_attained() {
        let mut h = HomingSequencer::new(P, ModeOfOperation::CyclicSyncPosition);
        h.start();
        // Still settling after a move: csp's bit 12 ("following the command") is set.
        for _ in 0..20 {
            let c = h
                .update(sw(HOMING_ATTAINED_BIT), true, None, false)
                .unwrap();
            assert_eq!(c.start_bit, 0);
            assert_eq!(h.phase(), HomingPhase::EnterHm);
        }
        for _ in 0..4 {
            h.update(sw(HOMING_ATTAINED_BIT), true, None, true);
        }
        assert_eq!(h.phase(), HomingPhase::Running);
    }

    #[test]
    fn without_6061h_the_mode_counts_as_switched_after_the_settle_cycles_and_a_hang_times_out() {
        let mut h = HomingSequencer::new(P, ModeOfOperation::CyclicSyncPosition);
        h.start();
        for _ in 0..3 {
            h.update(sw(0), true, None, true);
            assert_eq!(h.phase(), HomingPhase::EnterHm);
        }
        h.update(sw(0), true, None, true);
        assert_eq!(h.phase(), HomingPhase::Running);
        for _ in 0..200 {
            h.update(sw(0), true, None, true);
        }
        assert_eq!(h.phase(), HomingPhase::Done(Some(HomingFailure::Timeout)));
    }
}
