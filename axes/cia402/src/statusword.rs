//! Statusword (6041h, U16): the drive's state report.
//!
//! Bits from MR-J5-G-N1 manual §7.3.

use std::fmt;

use super::fsa::FsaState;

/// The statusword 6041h as received from the drive every cycle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Statusword(pub u16);

const FAULT_BIT: u16 = 1 << 3;
const VOLTAGE_ENABLED_BIT: u16 = 1 << 4;
const QUICK_STOP_BIT: u16 = 1 << 5;
const WARNING_BIT: u16 = 1 << 7;
const REMOTE_BIT: u16 = 1 << 9;
const TARGET_REACHED_BIT: u16 = 1 << 10;
const INTERNAL_LIMIT_BIT: u16 = 1 << 11;
const OMS12_BIT: u16 = 1 << 12;
const OMS13_BIT: u16 = 1 << 13;

/// Bit 10 in pp and pv: Target reached.
pub const TARGET_REACHED: u16 = TARGET_REACHED_BIT;
/// Bit 11: Internal limit active (a 607Dh software limit reached, MR-J4-TM manual §5.3 ILA).
pub const INTERNAL_LIMIT_ACTIVE: u16 = INTERNAL_LIMIT_BIT;
/// Bit 12 in pp: Set-point acknowledge (Mitsubishi: positioning being executed).
pub const SET_POINT_ACKNOWLEDGE: u16 = OMS12_BIT;
/// Bit 12 in pv: Speed (1 = the speed is 0).
pub const SPEED_ZERO: u16 = OMS12_BIT;

/// CiA 402 mask for the states whose pattern ignores bit 5 (§3.4).
pub const MASK_NO_QS: u16 = 0x004F;
/// CiA 402 mask for the states whose pattern includes bit 5 (§3.4).
pub const MASK_WITH_QS: u16 = 0x006F;
/// Mitsubishi mask with bits 8 and 14 (0x414F); for checking what a simulator emits only (§3.4).
pub const STRICT_MASK_NO_QS: u16 = 0x414F;
/// Mitsubishi mask with bits 8 and 14 (0x416F); for checking what a simulator emits only (§3.4).
pub const STRICT_MASK_WITH_QS: u16 = 0x416F;

impl Statusword {
    /// The raw word.
    pub const fn bits(self) -> u16 {
        self.0
    }

    /// Decodes the PDS state as a master must: CiA 402 masks 0x004F / 0x006F, ignoring the
    /// "undefined" bits 8 and 14 (MR-J5-G-N1 manual §7.3). `None` for a pattern of no state.
    pub const fn state(self) -> Option<FsaState> {
        Self::decode(self.0 & MASK_NO_QS, self.0 & MASK_WITH_QS)
    }

    /// Decodes with the Mitsubishi masks 0x414F / 0x416F (bits 8 and 14 must be 0).
    ///
    /// Only for checking a simulator's output; a master uses [`Statusword::state`] (§3.4).
    pub const fn state_strict(self) -> Option<FsaState> {
        if self.0 & 0x4100 != 0 {
            return None;
        }
        self.state()
    }

    const fn decode(no_qs: u16, with_qs: u16) -> Option<FsaState> {
        match no_qs {
            0x0000 => return Some(FsaState::NotReadyToSwitchOn),
            0x0040 => return Some(FsaState::SwitchOnDisabled),
            0x000F => return Some(FsaState::FaultReactionActive),
            0x0008 => return Some(FsaState::Fault),
            _ => {}
        }
        match with_qs {
            0x0021 => Some(FsaState::ReadyToSwitchOn),
            0x0023 => Some(FsaState::SwitchedOn),
            0x0027 => Some(FsaState::OperationEnabled),
            0x0007 => Some(FsaState::QuickStopActive),
            _ => None,
        }
    }

    /// The word a simulated drive emits in `state` with main power on (§3.4, TV-1 typical words).
    ///
    /// State pattern, bit 4 VE, bit 9 RM, bit 5 QS = 1 except in Quick stop active; bits 8 and 14
    /// are 0. In Not ready to switch on the drive sends no statusword, so this is 0x0000.
    pub const fn for_state(state: FsaState) -> Statusword {
        Self::for_state_with_power(state, true)
    }

    /// Like [`Statusword::for_state`], with bit 4 VE following the main-circuit power.
    pub const fn for_state_with_power(state: FsaState, main_power: bool) -> Statusword {
        let pattern = match state {
            FsaState::NotReadyToSwitchOn => return Statusword(0),
            FsaState::SwitchOnDisabled => 0x0040 | QUICK_STOP_BIT,
            FsaState::ReadyToSwitchOn => 0x0021,
            FsaState::SwitchedOn => 0x0023,
            FsaState::OperationEnabled => 0x0027,
            FsaState::QuickStopActive => 0x0007,
            FsaState::FaultReactionActive => 0x000F | QUICK_STOP_BIT,
            FsaState::Fault => 0x0008 | QUICK_STOP_BIT,
        };
        let ve = if main_power { VOLTAGE_ENABLED_BIT } else { 0 };
        Statusword(pattern | ve | REMOTE_BIT)
    }

    /// Bit 3 F: a fault is present.
    pub const fn fault(self) -> bool {
        self.0 & FAULT_BIT != 0
    }

    /// Bit 4 VE: main-circuit bus voltage is at or above the RA level.
    pub const fn voltage_enabled(self) -> bool {
        self.0 & VOLTAGE_ENABLED_BIT != 0
    }

    /// Bit 5 QS as on the wire: 0 means a quick stop is in progress.
    pub const fn quick_stop(self) -> bool {
        self.0 & QUICK_STOP_BIT != 0
    }

    /// Bit 7 W: a warning is present (no state change, §9 [background]).
    pub const fn warning(self) -> bool {
        self.0 & WARNING_BIT != 0
    }

    /// Bit 9 RM: the drive is operated by the controlword.
    pub const fn remote(self) -> bool {
        self.0 & REMOTE_BIT != 0
    }

    /// Bit 10: target reached (mode-specific OMS bit).
    pub const fn target_reached(self) -> bool {
        self.0 & TARGET_REACHED_BIT != 0
    }

    /// Bit 11 ILA: stroke end or software limit reached (valid in csp, csv, pp, pv, hm).
    pub const fn internal_limit_active(self) -> bool {
        self.0 & INTERNAL_LIMIT_BIT != 0
    }

    /// Bit 12 (OMS): in csp/csv/cst "drive follows the command value" [background CiA 402].
    pub const fn drive_follows_command(self) -> bool {
        self.0 & OMS12_BIT != 0
    }

    /// Bit 13 (OMS): in csp/pp "following error" [background CiA 402].
    pub const fn following_error(self) -> bool {
        self.0 & OMS13_BIT != 0
    }

    const fn with(self, mask: u16, on: bool) -> Self {
        if on {
            Statusword(self.0 | mask)
        } else {
            Statusword(self.0 & !mask)
        }
    }

    /// Sets or clears bit 7 W (warning).
    pub const fn with_warning(self, on: bool) -> Self {
        self.with(WARNING_BIT, on)
    }

    /// Sets or clears bit 10 (target reached).
    pub const fn with_target_reached(self, on: bool) -> Self {
        self.with(TARGET_REACHED_BIT, on)
    }

    /// Sets or clears bit 11 ILA (internal limit active).
    pub const fn with_internal_limit_active(self, on: bool) -> Self {
        self.with(INTERNAL_LIMIT_BIT, on)
    }

    /// Sets or clears bit 12 (OMS; csp/csv/cst: drive follows the command value).
    pub const fn with_drive_follows_command(self, on: bool) -> Self {
        self.with(OMS12_BIT, on)
    }

    /// Sets or clears bit 13 (OMS; csp/pp: following error).
    pub const fn with_following_error(self, on: bool) -> Self {
        self.with(OMS13_BIT, on)
    }
}

impl fmt::Display for Statusword {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "0x{:04X}", self.0)
    }
}

impl From<u16> for Statusword {
    fn from(v: u16) -> Self {
        Statusword(v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use FsaState::*;

    /// MR-J5-G-N1 manual §7.3 decode table: (state, strict mask, value).
    const TABLE: [(FsaState, u16, u16); 8] = [
        (NotReadyToSwitchOn, 0x414F, 0x0000),
        (SwitchOnDisabled, 0x414F, 0x0040),
        (ReadyToSwitchOn, 0x416F, 0x0021),
        (SwitchedOn, 0x416F, 0x0023),
        (OperationEnabled, 0x416F, 0x0027),
        (QuickStopActive, 0x416F, 0x0007),
        (FaultReactionActive, 0x414F, 0x000F),
        (Fault, 0x414F, 0x0008),
    ];

    #[test]
    fn every_state_pattern_decodes() {
        for (state, mask, value) in TABLE {
            assert_eq!(Statusword(value).state(), Some(state), "{value:#06x}");
            // Bits outside the mask do not change the decoded state (W, RM, OMS, ILA, VE).
            let noise = 0xBE90 & !mask;
            assert_eq!(Statusword(value | noise).state(), Some(state));
            // The master ignores bits 8 and 14 (§3.4 ambiguity) ...
            assert_eq!(Statusword(value | 0x4100).state(), Some(state));
            // ... but the strict simulator check does not.
            assert_eq!(Statusword(value | 0x4100).state_strict(), None);
        }
    }

    #[test]
    fn simulator_words_match_the_strict_masks_and_typical_words() {
        for (state, mask, value) in TABLE {
            let sw = Statusword::for_state(state);
            assert_eq!(sw.0 & mask, value, "{state}");
            assert_eq!(sw.state_strict(), Some(state));
        }
        // TV-1 typical words (VE = 1, RM = 1, QS = 1 outside QSA).
        assert_eq!(Statusword::for_state(SwitchOnDisabled).0, 0x0270);
        assert_eq!(Statusword::for_state(ReadyToSwitchOn).0, 0x0231);
        assert_eq!(Statusword::for_state(SwitchedOn).0, 0x0233);
        assert_eq!(Statusword::for_state(OperationEnabled).0, 0x0237);
        assert!(!Statusword::for_state(QuickStopActive).quick_stop());
        assert!(Statusword::for_state(Fault).fault());
        assert!(Statusword::for_state(FaultReactionActive).fault());
        assert!(!Statusword::for_state_with_power(SwitchedOn, false).voltage_enabled());
        assert_eq!(Statusword::for_state(NotReadyToSwitchOn).0, 0);
    }

    #[test]
    fn patterns_of_no_state_decode_to_none() {
        // 0x0001 (RTSO bit without QS), 0x0060 (SOD with QS and nothing else is still SOD) ...
        assert_eq!(Statusword(0x0001).state(), None);
        assert_eq!(Statusword(0x0003).state(), None);
        assert_eq!(Statusword(0x0048).state(), None);
        assert_eq!(Statusword(0x0060).state(), Some(SwitchOnDisabled));
    }

    #[test]
    fn bit_helpers() {
        let sw = Statusword(0)
            .with_warning(true)
            .with_target_reached(true)
            .with_internal_limit_active(true)
            .with_drive_follows_command(true)
            .with_following_error(true);
        assert_eq!(sw.0, 0x3C80);
        assert!(sw.warning() && sw.target_reached() && sw.internal_limit_active());
        assert!(sw.drive_follows_command() && sw.following_error());
        assert_eq!(sw.with_warning(false).0, 0x3C00);
        assert!(Statusword(0x0200).remote() && Statusword(0x0010).voltage_enabled());
    }
}
