//! Master-side homing in the drive's homing mode (hm), cycle-driven and allocation-free.
//!
//! The sequence is the one the MR-J5-G-N1 / MR-JET-G-N1 bring-up gives (MR-J5-G-N1 manual §8.3
//! step 5, MR-JET-G-N1 manual §8.3): with the axis in Operation enabled, set 6060h = 6 and wait for
//! 6061h = 6, start the method selected in 6098h with controlword bit 4 (homing operation
//! start), wait for statusword bit 12 (homing attained) or bit 13 (homing error), then switch
//! back to the cyclic mode and wait for 6061h to show it. 6098h itself is written acyclically
//! before the start (the caller's job).
//!
//! Where the TxPDO does not map 6061h (MR-J3-T04, MR-J3-T04 manual §8.4.2) the mode is taken to have
//! switched after [`HomingParams::mode_settle`] consecutive cycles at standstill (a drive
//! changes a position mode only at zero speed, and statusword bit 12 means "following the
//! command" in csp, so it must not be read as "homing attained" before the switch): the manual
//! gives no figure, so this is a named parameter.
//!
//! A drive with home setting by Controlword2 (MR-J3-T04 C_CR / C_CR2, MR-J3-T04 manual §8.11.6) is
//! homed in its cyclic mode instead: raise the bit, wait for S_OSET (statusword2), drop the
//! bit, wait for S_OSET to drop; the master then reads 607Ch (the caller's job). C_CR is the
//! manual's "clear method" (§8.11.6.5): home = where the axis stands.

use super::mode::ModeOfOperation;
use super::statusword::Statusword;
use crate::Cycles;

/// Statusword bit 12 in hm: homing attained.
pub const HOMING_ATTAINED_BIT: u16 = 1 << 12;
/// Statusword bit 13 in hm: homing error.
pub const HOMING_ERROR_BIT: u16 = 1 << 13;
/// Controlword bit 4 in hm: homing operation start (HOS).
pub const HOMING_START_BIT: u16 = 1 << 4;

/// Home position setting in the cyclic modes by Controlword2 edges, without hm (MR-J3-T04
/// C_CR / C_CR2, MR-J3-T04 manual §8.11.6).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct HomeSetting {
    /// Controlword2 bit C_CR: rising edge → 607Ch := −(current position).
    pub clear_bit: u8,
    /// Controlword2 bit C_CR2: rising edge → 607Ch := −(last Z-phase position).
    pub clear_z_bit: u8,
    /// Statusword2 (2011h) bit S_OSET: home setting by C_CR/C_CR2 completed.
    pub set_bit: u8,
    /// Statusword2 bit S_ZPAS: Z phase passed at least once since power-on.
    pub z_passed_bit: u8,
    /// Statusword2 bit S_OP: the encoder is at its Z phase.
    pub z_pulse_bit: u8,
    /// Warning for C_CR2 before the Z phase (AL.96; the manual's procedures name it).
    pub before_z_warning: u16,
    /// The alarm the manual's alarm list gives for the same cause (AL.26; §7.2 ambiguity).
    pub before_z_alarm: u16,
}

/// What homing needs to know of a drive model, built from its profile
/// (`DriveProfile::homing_facts`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HomingFacts {
    /// Product name, for the refusals.
    pub name: &'static str,
    /// Homing methods (6098h) the manual lists.
    pub methods: &'static [i8],
    /// Of those, the data-set methods: home = the current position, no motion.
    pub data_set_methods: &'static [i8],
    /// Home setting by Controlword2 edges, where the model has it.
    pub home_setting: Option<HomeSetting>,
    /// True if the default TxPDO carries 6061h (modes of operation display).
    pub shows_mode: bool,
    /// True if the default PDOs carry Controlword2 (2001h, RxPDO) and Statusword2 (2011h,
    /// TxPDO).
    pub carries_controlword2: bool,
    /// What the manual says instead where it lists no methods, for the refusal.
    pub no_methods_statement: &'static str,
}

/// Which Controlword2 edge sets home (MR-J3-T04 §8.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum HomeSettingEdge {
    /// C_CR: home = the current position (use at standstill).
    Clear,
    /// C_CR2: home = the last Z-phase position (needs S_ZPAS).
    ClearZ,
}

impl HomeSettingEdge {
    /// The Controlword2 bit of this edge on a drive with `bits`.
    pub fn bit(self, bits: &HomeSetting) -> u8 {
        match self {
            HomeSettingEdge::Clear => bits.clear_bit,
            HomeSettingEdge::ClearZ => bits.clear_z_bit,
        }
    }
}

/// How an axis is homed (MC_Home).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HomeProcedure {
    /// The drive's homing mode (hm) with this 6098h method.
    HomingMode(i8),
    /// In the cyclic mode by a Controlword2 edge.
    Controlword2(HomeSettingEdge),
}

/// Why a drive cannot be homed as asked, in the words of its manual.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum HomingChoiceError {
    /// Both a method and a Controlword2 edge were named.
    #[error("name a homing method or a Controlword2 edge, not both")]
    MethodAndEdge,
    /// The model has no home setting by Controlword2.
    #[error("the {model} has no home setting by Controlword2 (C_CR / C_CR2)")]
    NoHomeSetting {
        /// The model's product name.
        model: &'static str,
    },
    /// The default PDOs do not carry Controlword2 and Statusword2.
    #[error("the {model} default PDOs do not carry 2001h and 2011h for C_CR / S_OSET")]
    NoControlword2 {
        /// The model's product name.
        model: &'static str,
    },
    /// The manual lists no 6098h method; what it says instead.
    #[error(
        "the {model} manual lists no homing methods (6098h): {statement}; hm cannot be used on it"
    )]
    NoMethods {
        /// The model's product name.
        model: &'static str,
        /// What the manual says instead.
        statement: &'static str,
    },
    /// The default TxPDO does not carry 6061h.
    #[error("the {model} default TxPDO does not carry 6061h, so the end of a homing in hm cannot be told from csp's statusword bit 12")]
    NoModeDisplay {
        /// The model's product name.
        model: &'static str,
    },
    /// The manual does not list the method asked.
    #[error("the {model} manual lists no homing method {method} (6098h; it lists {listed:?})")]
    NotListed {
        /// The model's product name.
        model: &'static str,
        /// The method asked.
        method: i8,
        /// The methods the manual lists.
        listed: Vec<i8>,
    },
    /// No method was asked and the model has no data-set method to default to.
    #[error("the {model} manual lists no homing methods (6098h); hm cannot be used on it")]
    NoDataSetMethod {
        /// The model's product name.
        model: &'static str,
    },
    /// The manual lists the method, but the emulator does not run it.
    #[error("homing method {method} of the {model} manual is not emulated")]
    NotEmulated {
        /// The model's product name.
        model: &'static str,
        /// The method asked.
        method: i8,
    },
}

/// Whether `drive` can set home by Controlword2 with its default maps (2001h in the RxPDO,
/// 2011h in the TxPDO).
fn controlword2_home_setting(drive: &HomingFacts) -> Result<(), HomingChoiceError> {
    if drive.home_setting.is_none() {
        return Err(HomingChoiceError::NoHomeSetting { model: drive.name });
    }
    if !drive.carries_controlword2 {
        return Err(HomingChoiceError::NoControlword2 { model: drive.name });
    }
    Ok(())
}

/// How to home `drive` (its [`HomingFacts`], e.g. from a `DriveProfile`): hm with `method`
/// (see [`choose_method`]) or the Controlword2 `edge` as asked; by default the model's data-set
/// method in hm where hm can be used, else the manual's clear method by C_CR (MR-J3-T04
/// §8.11.6.5: home where it stands).
pub fn choose_procedure(
    drive: impl Into<HomingFacts>,
    method: Option<i8>,
    edge: Option<HomeSettingEdge>,
) -> Result<HomeProcedure, HomingChoiceError> {
    let drive = drive.into();
    match (method, edge) {
        (Some(_), Some(_)) => Err(HomingChoiceError::MethodAndEdge),
        (None, Some(e)) => {
            controlword2_home_setting(&drive).map(|()| HomeProcedure::Controlword2(e))
        }
        (Some(m), None) => method_of(&drive, Some(m)).map(HomeProcedure::HomingMode),
        (None, None) => match method_of(&drive, None) {
            Ok(m) => Ok(HomeProcedure::HomingMode(m)),
            Err(hm) => controlword2_home_setting(&drive)
                .map(|()| HomeProcedure::Controlword2(HomeSettingEdge::Clear))
                .map_err(|_| hm),
        },
    }
}

/// The 6098h method to home `drive` with: `requested` if its manual lists it, else the model's
/// first data-set method (home = the current position). Refused, with the reason, where the
/// manual lists none, or where the TxPDO does not carry 6061h (in csp bit 12 of the statusword
/// means "following the command", so homing attained could not be told apart without the mode
/// display).
pub fn choose_method(
    drive: impl Into<HomingFacts>,
    requested: Option<i8>,
) -> Result<i8, HomingChoiceError> {
    method_of(&drive.into(), requested)
}

fn method_of(drive: &HomingFacts, requested: Option<i8>) -> Result<i8, HomingChoiceError> {
    let model = drive.name;
    if drive.methods.is_empty() {
        return Err(HomingChoiceError::NoMethods {
            model,
            statement: drive.no_methods_statement,
        });
    }
    if !drive.shows_mode {
        return Err(HomingChoiceError::NoModeDisplay { model });
    }
    match requested {
        Some(m) if drive.methods.contains(&m) => Ok(m),
        Some(method) => Err(HomingChoiceError::NotListed {
            model,
            method,
            listed: drive.methods.to_vec(),
        }),
        None => drive
            .data_set_methods
            .first()
            .copied()
            .ok_or(HomingChoiceError::NoDataSetMethod { model }),
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
#[derive(Debug, Clone, Copy, PartialEq, Eq, strum::IntoStaticStr, strum::FromRepr)]
#[repr(u8)]
pub enum HomingFailure {
    /// The drive set statusword bit 13 (e.g. a method it does not run).
    #[strum(serialize = "the drive reported a homing error (statusword bit 13)")]
    DriveError = 1,
    /// 6061h never showed hm, or never came back to the cyclic mode, or the method never
    /// ended, within the timeout.
    #[strum(serialize = "homing did not complete within the timeout")]
    Timeout = 2,
    /// The axis left Operation enabled (fault, disable) during homing.
    #[strum(serialize = "the axis left Operation enabled during homing")]
    NotEnabled = 3,
    /// The drive refused the method written to 6098h (SDO abort), or has no home setting by
    /// Controlword2.
    #[strum(serialize = "the drive refused the homing method (6098h)")]
    MethodRefused = 4,
    /// The drive answered a Controlword2 home setting with a warning instead of S_OSET
    /// (MR-J3-T04 AL.96: C_CR2 before the Z phase was passed).
    #[strum(
        serialize = "the drive answered the home setting with a warning (AL.96: C_CR2 before the Z phase was passed)"
    )]
    SettingRefused = 5,
}

impl HomingFailure {
    /// Short name for events and messages.
    pub fn as_str(self) -> &'static str {
        self.into()
    }

    /// Inverse of `as u8`.
    pub fn from_u8(v: u8) -> Option<HomingFailure> {
        Self::from_repr(v)
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
    /// Controlword2 edge raised; waiting for S_OSET (statusword2).
    Setting,
    /// Controlword2 bit dropped; waiting for S_OSET to drop. Carries the result to report.
    SettingRelease(Option<HomingFailure>),
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
    /// Bits to OR into Controlword2 (C_CR / C_CR2 of a home setting).
    pub controlword2: u16,
}

/// Statusword bit 7: warning (a home-setting warning such as MR-J3-T04 AL.96 shows here).
const WARNING_BIT: u16 = 1 << 7;

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
    /// Home setting by Controlword2: (edge bit mask, S_OSET mask in statusword2).
    setting: (u16, u16),
    /// Statusword bit 7 when the setting started (a warning already present is not its).
    warning_before: bool,
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
            setting: (0, 0),
            warning_before: false,
        }
    }

    /// Starts the sequence (6098h must already hold the method).
    pub fn start(&mut self) {
        self.phase = HomingPhase::EnterHm;
        self.elapsed = 0;
        self.in_phase = 0;
        self.quiet = 0;
    }

    /// Starts a home setting by the Controlword2 `edge` on a drive with `bits`, in the cyclic
    /// mode; `statusword` is the latest one (a warning already present is not a failure).
    pub fn start_setting(
        &mut self,
        edge: HomeSettingEdge,
        bits: &HomeSetting,
        statusword: Statusword,
    ) {
        self.start();
        self.phase = HomingPhase::Setting;
        self.setting = (1 << edge.bit(bits), 1 << bits.set_bit);
        self.warning_before = statusword.0 & WARNING_BIT != 0;
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

    /// One cycle: from the statusword, statusword2 (0 where not mapped), 6061h (`None` where
    /// the TxPDO does not map it) and whether the motor stands still (606Ch = 0), the mode, HOS
    /// bit and Controlword2 bits to send, or `None` when not homing.
    pub fn update(
        &mut self,
        statusword: Statusword,
        statusword2: u16,
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
            // homing's bit 12 is cleared by the start, MR-J4-TM manual §5.4.9).
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
            HomingPhase::Setting if !enabled => {
                HomingPhase::SettingRelease(Some(HomingFailure::NotEnabled))
            }
            HomingPhase::Setting if statusword2 & self.setting.1 != 0 => {
                HomingPhase::SettingRelease(None)
            }
            HomingPhase::Setting
                if self.in_phase > 1 && !self.warning_before && statusword.0 & WARNING_BIT != 0 =>
            {
                HomingPhase::SettingRelease(Some(HomingFailure::SettingRefused))
            }
            HomingPhase::Setting if timed_out => {
                HomingPhase::SettingRelease(Some(HomingFailure::Timeout))
            }
            HomingPhase::SettingRelease(r)
                if statusword2 & self.setting.1 == 0
                    || self.in_phase > self.params.mode_settle.0 =>
            {
                HomingPhase::Done(r)
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
                controlword2: 0,
            },
            HomingPhase::Running => HomingCommand {
                mode: ModeOfOperation::Homing,
                start_bit: HOMING_START_BIT,
                controlword2: 0,
            },
            HomingPhase::Setting => HomingCommand {
                mode: self.cyclic,
                start_bit: 0,
                controlword2: self.setting.0,
            },
            _ => HomingCommand {
                mode: self.cyclic,
                start_bit: 0,
                controlword2: 0,
            },
        })
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Timing for the sequencer tests.
    pub(crate) const P: HomingParams = HomingParams {
        timeout: Cycles(100),
        mode_settle: Cycles(3),
    };

    /// A statusword in Operation enabled with `bits` set.
    pub(crate) fn sw(bits: u16) -> Statusword {
        Statusword(0x0027 | bits)
    }

    #[test]
    fn enters_hm_starts_waits_for_attained_and_leaves() {
        let mut h = HomingSequencer::new(P, ModeOfOperation::CyclicSyncPosition);
        assert_eq!(h.update(sw(0), 0, true, Some(8), true), None);
        h.start();
        let c = h.update(sw(0), 0, true, Some(8), true).unwrap();
        assert_eq!((c.mode, c.start_bit), (ModeOfOperation::Homing, 0));
        // 6061h shows hm: the start bit goes out.
        let c = h.update(sw(0), 0, true, Some(6), true).unwrap();
        assert_eq!(c.start_bit, HOMING_START_BIT);
        // A stale bit 12 in the first cycle of the start is not taken as the result.
        let c = h
            .update(sw(HOMING_ATTAINED_BIT), 0, true, Some(6), true)
            .unwrap();
        assert_eq!(c.start_bit, HOMING_START_BIT);
        assert_eq!(h.phase(), HomingPhase::Running);
        let c = h
            .update(sw(HOMING_ATTAINED_BIT), 0, true, Some(6), true)
            .unwrap();
        assert_eq!(c.mode, ModeOfOperation::CyclicSyncPosition);
        assert_eq!(h.phase(), HomingPhase::LeaveHm(None));
        h.update(sw(0), 0, true, Some(8), true);
        assert_eq!(h.phase(), HomingPhase::Done(None));
        assert!(!h.is_active());
        assert_eq!(h.update(sw(0), 0, true, Some(8), true), None);
    }

    #[test]
    fn a_homing_error_or_a_disable_fails_and_still_returns_to_the_cyclic_mode() {
        let mut h = HomingSequencer::new(P, ModeOfOperation::CyclicSyncVelocity);
        h.start();
        h.update(sw(0), 0, true, Some(6), true);
        h.update(sw(0), 0, true, Some(6), true);
        h.update(sw(HOMING_ERROR_BIT), 0, true, Some(6), true);
        assert_eq!(
            h.phase(),
            HomingPhase::LeaveHm(Some(HomingFailure::DriveError))
        );
        let c = h.update(sw(0), 0, true, Some(6), true).unwrap();
        assert_eq!(c.mode, ModeOfOperation::CyclicSyncVelocity);
        h.update(sw(0), 0, true, Some(9), true);
        assert_eq!(
            h.phase(),
            HomingPhase::Done(Some(HomingFailure::DriveError))
        );

        let mut h = HomingSequencer::new(P, ModeOfOperation::CyclicSyncPosition);
        h.start();
        h.update(sw(0), 0, false, Some(8), true);
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
                .update(sw(HOMING_ATTAINED_BIT), 0, true, None, false)
                .unwrap();
            assert_eq!(c.start_bit, 0);
            assert_eq!(h.phase(), HomingPhase::EnterHm);
        }
        for _ in 0..4 {
            h.update(sw(HOMING_ATTAINED_BIT), 0, true, None, true);
        }
        assert_eq!(h.phase(), HomingPhase::Running);
    }

    #[test]
    fn without_6061h_the_mode_counts_as_switched_after_the_settle_cycles_and_a_hang_times_out() {
        let mut h = HomingSequencer::new(P, ModeOfOperation::CyclicSyncPosition);
        h.start();
        for _ in 0..3 {
            h.update(sw(0), 0, true, None, true);
            assert_eq!(h.phase(), HomingPhase::EnterHm);
        }
        h.update(sw(0), 0, true, None, true);
        assert_eq!(h.phase(), HomingPhase::Running);
        for _ in 0..200 {
            h.update(sw(0), 0, true, None, true);
        }
        assert_eq!(h.phase(), HomingPhase::Done(Some(HomingFailure::Timeout)));
    }
}
