//! The CiA 402 power drive system (PDS) finite state automaton, drive side.
//!
//! Transitions from MR-J5-G-N1 manual §7.1; shortcuts from §3.2.

use super::controlword::{Command, Controlword};

/// A PDS state (MR-J5-G-N1 manual §7.1, §3.4), numbered from 1 in CiA 402 order (the number the
/// recordings store, 0 being "unknown": `FsaState` in `runtime/proto/cellrt.proto`) and named
/// in snake_case for logs, records and the operator ("operation_enabled").
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, strum::Display, strum::IntoStaticStr, strum::FromRepr,
)]
#[strum(serialize_all = "snake_case")]
#[repr(u8)]
pub enum FsaState {
    /// Initialising after control-circuit power-on; no statusword is sent (§3.4 \*1).
    NotReadyToSwitchOn = 1,
    /// Initialised, power stage disabled; the state after start-up and after a fault reset.
    SwitchOnDisabled = 2,
    /// Ready for Switch On; dynamic brake applied.
    ReadyToSwitchOn = 3,
    /// Power stage ready, servo off; dynamic brake released.
    SwitchedOn = 4,
    /// Servo on: the drive follows its setpoints.
    OperationEnabled = 5,
    /// Quick stop ramp running; ends in Switch on disabled on MR-J5 (§3.1 (12)).
    QuickStopActive = 6,
    /// An alarm is being processed (servo off, dynamic brake); left automatically to Fault.
    FaultReactionActive = 7,
    /// An alarm is latched; left only by a Fault Reset edge (15).
    Fault = 8,
}

impl FsaState {
    /// Every state, in CiA 402 order.
    pub const ALL: [FsaState; 8] = [
        Self::NotReadyToSwitchOn,
        Self::SwitchOnDisabled,
        Self::ReadyToSwitchOn,
        Self::SwitchedOn,
        Self::OperationEnabled,
        Self::QuickStopActive,
        Self::FaultReactionActive,
        Self::Fault,
    ];

    /// A snake_case name for logs and records, e.g. "operation_enabled".
    pub fn as_str(self) -> &'static str {
        self.into()
    }

    /// The state's number (1–8, CiA 402 order); [`FsaState::from_repr`] is the inverse.
    pub const fn code(self) -> u8 {
        self as u8
    }

    /// True in the states where the servo is on and the motor is controlled (OE, QSA).
    pub const fn is_servo_on(self) -> bool {
        matches!(self, Self::OperationEnabled | Self::QuickStopActive)
    }

    /// True in Fault reaction active and Fault.
    pub const fn is_fault(self) -> bool {
        matches!(self, Self::FaultReactionActive | Self::Fault)
    }
}

/// Model-specific deviations of a drive's PDS from plain CiA 402 (spec README "FSA quirks").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct FsaQuirks {
    /// One controlword jumps several states: SOD+Switch On → SO, SOD/RTSO+Enable Operation → OE
    /// (MR-J5-G-N1 manual §7.1 shortcut table).
    pub shortcut_transitions: bool,
    /// The drive has Quick stop active; without it a Quick Stop in OE acts as Disable Voltage (9)
    /// (MR-J3-T04 has no quick stop, statusword bit 5 always 1).
    pub has_quick_stop: bool,
    /// Transition (16) QSA → OE on Enable Operation, whatever 605Ah says (unsupported on MR-J5,
    /// §3.1). See [`FsaQuirks::for_quick_stop_option`] for drives where 605Ah decides.
    pub quick_stop_returns_to_enabled: bool,
    /// The drive honours 605Ah quick stop option codes 5–8: it stays in Quick stop active after
    /// the stop, and Enable Operation returns it to Operation enabled (16) (MR-JET-G-N1 manual
    /// §7.1, FW D0 or later; CiA 402). Codes 1–4 end the stop in Switch on disabled (12).
    pub quick_stop_options_5_to_8: bool,
}

impl FsaQuirks {
    /// Plain CiA 402: no shortcuts, quick stop present, no transition (16).
    pub const STRICT: FsaQuirks = FsaQuirks {
        shortcut_transitions: false,
        has_quick_stop: true,
        quick_stop_returns_to_enabled: false,
        quick_stop_options_5_to_8: true,
    };

    /// Whether a quick stop under option code `option` (605Ah) ends in Quick stop active rather
    /// than Switch on disabled.
    pub fn quick_stop_stays_active(self, option: Option<i64>) -> bool {
        self.quick_stop_options_5_to_8 && matches!(option, Some(5..=8))
    }

    /// The quirks in effect under 605Ah = `option`: (16) is open when the code keeps the
    /// drive in Quick stop active.
    pub fn for_quick_stop_option(self, option: Option<i64>) -> FsaQuirks {
        FsaQuirks {
            quick_stop_returns_to_enabled: self.quick_stop_returns_to_enabled
                || self.quick_stop_stays_active(option),
            ..self
        }
    }
}

/// The drive-side PDS transition for one received controlword (§3.1 transitions 2–16).
///
/// `prev_cw` is the word of the previous cycle, needed for the Fault Reset edge (15). Outside
/// Fault, bit 7 is ignored and bits 0–3 select the command. Not ready to switch on and Fault
/// reaction active are left by the drive itself ((1), (14)), as are the end of a quick stop
/// ((12) automatic) and alarms ((13)); this function returns those states unchanged.
pub fn drive_transition(
    state: FsaState,
    cw: Controlword,
    prev_cw: Controlword,
    quirks: &FsaQuirks,
) -> FsaState {
    use Command as C;
    use FsaState as S;

    let cmd = cw.state_command();
    match state {
        S::NotReadyToSwitchOn | S::FaultReactionActive => state,
        // (15) Fault → SOD on the 0→1 edge of bit 7 only.
        S::Fault => {
            if cw.fault_reset_edge(prev_cw) {
                S::SwitchOnDisabled
            } else {
                S::Fault
            }
        }
        S::SwitchOnDisabled => match cmd {
            // (2)
            C::Shutdown => S::ReadyToSwitchOn,
            // Shortcuts (§3.2): SOD + Switch On → SO, SOD + Enable Operation → OE.
            C::SwitchOn if quirks.shortcut_transitions => S::SwitchedOn,
            C::EnableOperation if quirks.shortcut_transitions => S::OperationEnabled,
            _ => S::SwitchOnDisabled,
        },
        S::ReadyToSwitchOn => match cmd {
            // (3)
            C::SwitchOn => S::SwitchedOn,
            // Shortcut (§3.2): RTSO + Enable Operation → OE.
            C::EnableOperation if quirks.shortcut_transitions => S::OperationEnabled,
            // (7)
            C::DisableVoltage | C::QuickStop => S::SwitchOnDisabled,
            _ => S::ReadyToSwitchOn,
        },
        S::SwitchedOn => match cmd {
            // (4)
            C::EnableOperation => S::OperationEnabled,
            // (6)
            C::Shutdown => S::ReadyToSwitchOn,
            // (10)
            C::DisableVoltage | C::QuickStop => S::SwitchOnDisabled,
            _ => S::SwitchedOn,
        },
        S::OperationEnabled => match cmd {
            // (5) Disable Operation shares the Switch On bits.
            C::SwitchOn | C::DisableOperation => S::SwitchedOn,
            // (8)
            C::Shutdown => S::ReadyToSwitchOn,
            // (9)
            C::DisableVoltage => S::SwitchOnDisabled,
            // (11), or (9) on a drive without quick stop.
            C::QuickStop if quirks.has_quick_stop => S::QuickStopActive,
            C::QuickStop => S::SwitchOnDisabled,
            _ => S::OperationEnabled,
        },
        S::QuickStopActive => match cmd {
            // (12) by Disable Voltage; the automatic (12) at the end of the stop is the drive's.
            C::DisableVoltage => S::SwitchOnDisabled,
            // (16), only where supported (not on MR-J5, §3.1).
            C::EnableOperation if quirks.quick_stop_returns_to_enabled => S::OperationEnabled,
            _ => S::QuickStopActive,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use FsaState::*;

    const J5: FsaQuirks = FsaQuirks {
        shortcut_transitions: true,
        has_quick_stop: true,
        quick_stop_returns_to_enabled: false,
        quick_stop_options_5_to_8: false,
    };
    const CW0: Controlword = Controlword(0);

    fn step(s: FsaState, cw: u16, q: &FsaQuirks) -> FsaState {
        drive_transition(s, Controlword(cw), CW0, q)
    }

    /// (transition number, from, controlword, to), MR-J5-G-N1 manual §7.1 with the §3.2 typical words.
    const TRANSITIONS: [(u8, FsaState, u16, FsaState); 16] = [
        (2, SwitchOnDisabled, 0x0006, ReadyToSwitchOn),
        (3, ReadyToSwitchOn, 0x0007, SwitchedOn),
        (4, SwitchedOn, 0x000F, OperationEnabled),
        (5, OperationEnabled, 0x0007, SwitchedOn),
        (6, SwitchedOn, 0x0006, ReadyToSwitchOn),
        (7, ReadyToSwitchOn, 0x0000, SwitchOnDisabled),
        (7, ReadyToSwitchOn, 0x0002, SwitchOnDisabled),
        (8, OperationEnabled, 0x0006, ReadyToSwitchOn),
        (9, OperationEnabled, 0x0000, SwitchOnDisabled),
        (10, SwitchedOn, 0x0000, SwitchOnDisabled),
        (10, SwitchedOn, 0x0002, SwitchOnDisabled),
        (11, OperationEnabled, 0x0002, QuickStopActive),
        (11, OperationEnabled, 0x000B, QuickStopActive),
        (12, QuickStopActive, 0x0000, SwitchOnDisabled),
        (15, Fault, 0x0080, SwitchOnDisabled),
        (15, Fault, 0x008F, SwitchOnDisabled),
    ];

    #[test]
    fn every_numbered_transition() {
        for q in [J5, FsaQuirks::STRICT] {
            for (n, from, cw, to) in TRANSITIONS {
                assert_eq!(
                    step(from, cw, &q),
                    to,
                    "transition ({n}) {from} + {cw:#06x}"
                );
            }
        }
    }

    #[test]
    fn shortcut_jumps_only_with_the_quirk() {
        // §3.2 shortcut table / TV-3.
        let shortcuts = [
            (SwitchOnDisabled, 0x0007, SwitchedOn),
            (SwitchOnDisabled, 0x000F, OperationEnabled),
            (ReadyToSwitchOn, 0x000F, OperationEnabled),
        ];
        for (from, cw, to) in shortcuts {
            assert_eq!(step(from, cw, &J5), to);
            assert_eq!(step(from, cw, &FsaQuirks::STRICT), from);
        }
    }

    #[test]
    fn quick_stop_active_does_not_return_to_enabled_on_mr_j5() {
        // (16) is marked "not supported" (§3.1, TV-4).
        assert_eq!(step(QuickStopActive, 0x000F, &J5), QuickStopActive);
        let with16 = FsaQuirks {
            quick_stop_returns_to_enabled: true,
            ..J5
        };
        assert_eq!(step(QuickStopActive, 0x000F, &with16), OperationEnabled);
        // Shutdown / Switch On do not leave QSA.
        assert_eq!(step(QuickStopActive, 0x0006, &J5), QuickStopActive);
        assert_eq!(step(QuickStopActive, 0x0007, &J5), QuickStopActive);
    }

    #[test]
    fn option_codes_5_to_8_open_transition_16_only_where_the_drive_honours_them() {
        let jet = FsaQuirks {
            quick_stop_options_5_to_8: true,
            ..J5
        };
        for code in 5..=8 {
            let q = jet.for_quick_stop_option(Some(code));
            assert!(jet.quick_stop_stays_active(Some(code)));
            assert_eq!(step(QuickStopActive, 0x000F, &q), OperationEnabled);
            assert_eq!(step(QuickStopActive, 0x0000, &q), SwitchOnDisabled);
        }
        for code in [None, Some(0), Some(1), Some(2), Some(4), Some(9)] {
            assert!(!jet.quick_stop_stays_active(code), "{code:?}");
            let q = jet.for_quick_stop_option(code);
            assert_eq!(step(QuickStopActive, 0x000F, &q), QuickStopActive);
        }
        // MR-J5: (16) unsupported whatever 605Ah holds.
        let q = J5.for_quick_stop_option(Some(6));
        assert_eq!(step(QuickStopActive, 0x000F, &q), QuickStopActive);
    }

    #[test]
    fn no_quick_stop_quirk_disables_voltage() {
        let q = FsaQuirks {
            has_quick_stop: false,
            ..FsaQuirks::STRICT
        };
        assert_eq!(step(OperationEnabled, 0x0002, &q), SwitchOnDisabled);
    }

    #[test]
    fn fault_reset_needs_a_rising_edge() {
        let fr = Controlword::FAULT_RESET;
        assert_eq!(drive_transition(Fault, fr, fr, &J5), Fault);
        assert_eq!(drive_transition(Fault, CW0, CW0, &J5), Fault);
        assert_eq!(
            drive_transition(Fault, Controlword(0x000F), CW0, &J5),
            Fault
        );
        assert_eq!(drive_transition(Fault, fr, CW0, &J5), SwitchOnDisabled);
    }

    #[test]
    fn self_left_states_are_unchanged() {
        for cw in [0x0000, 0x0006, 0x0007, 0x000F, 0x0080, 0xFFFF] {
            assert_eq!(step(NotReadyToSwitchOn, cw, &J5), NotReadyToSwitchOn);
            assert_eq!(step(FaultReactionActive, cw, &J5), FaultReactionActive);
        }
    }

    #[test]
    fn names() {
        assert_eq!(OperationEnabled.as_str(), "operation_enabled");
        assert_eq!(QuickStopActive.to_string(), "quick_stop_active");
    }

    /// Independent oracle: may `from` become `to` under `cw` (bits 0–3 read straight from the
    /// §3.2 bit table), `prev` and `q`? Staying is always allowed.
    fn allowed(from: FsaState, to: FsaState, cw: u16, prev: u16, q: &FsaQuirks) -> bool {
        if from == to {
            return true;
        }
        let (so, ev, qs, eo) = (cw & 1 != 0, cw & 2 != 0, cw & 4 != 0, cw & 8 != 0);
        let shutdown = ev && qs && !so;
        let switch_on = ev && qs && so && !eo;
        let enable = ev && qs && so && eo;
        let disable_voltage = !ev;
        let quick_stop = ev && !qs;
        match (from, to) {
            (Fault, SwitchOnDisabled) => cw & 0x80 != 0 && prev & 0x80 == 0, // (15)
            (Fault, _) => false,
            (SwitchOnDisabled, ReadyToSwitchOn) => shutdown, // (2)
            (SwitchOnDisabled, SwitchedOn) => q.shortcut_transitions && switch_on,
            (SwitchOnDisabled, OperationEnabled) => q.shortcut_transitions && enable,
            (ReadyToSwitchOn, SwitchedOn) => switch_on, // (3)
            (ReadyToSwitchOn, OperationEnabled) => q.shortcut_transitions && enable,
            (ReadyToSwitchOn, SwitchOnDisabled) => disable_voltage || quick_stop, // (7)
            (SwitchedOn, OperationEnabled) => enable,                             // (4)
            (SwitchedOn, ReadyToSwitchOn) => shutdown,                            // (6)
            (SwitchedOn, SwitchOnDisabled) => disable_voltage || quick_stop,      // (10)
            (OperationEnabled, SwitchedOn) => switch_on,                          // (5)
            (OperationEnabled, ReadyToSwitchOn) => shutdown,                      // (8)
            (OperationEnabled, SwitchOnDisabled) => {
                disable_voltage || (quick_stop && !q.has_quick_stop) // (9)
            }
            (OperationEnabled, QuickStopActive) => quick_stop && q.has_quick_stop, // (11)
            (QuickStopActive, SwitchOnDisabled) => disable_voltage,                // (12)
            (QuickStopActive, OperationEnabled) => q.quick_stop_returns_to_enabled && enable, // (16)
            _ => false,
        }
    }

    fn any_state() -> impl Strategy<Value = FsaState> {
        (0usize..8).prop_map(|i| FsaState::ALL[i])
    }

    fn any_quirks() -> impl Strategy<Value = FsaQuirks> {
        (any::<bool>(), any::<bool>(), any::<bool>(), any::<bool>()).prop_map(|(a, b, c, d)| {
            FsaQuirks {
                shortcut_transitions: a,
                has_quick_stop: b,
                quick_stop_returns_to_enabled: c,
                quick_stop_options_5_to_8: d,
            }
        })
    }

    /// Mostly meaningful words, sometimes garbage.
    fn any_cw() -> impl Strategy<Value = u16> {
        prop_oneof![
            prop::sample::select(vec![
                0x0000u16, 0x0002, 0x0006, 0x0007, 0x000B, 0x000F, 0x0080
            ]),
            any::<u16>(),
        ]
    }

    proptest! {
        #[test]
        fn sequences_only_take_allowed_transitions(
            start in any_state(),
            q in any_quirks(),
            words in prop::collection::vec(any_cw(), 1..64),
        ) {
            let mut s = start;
            let mut prev = 0u16;
            for cw in words {
                let next = drive_transition(s, Controlword(cw), Controlword(prev), &q);
                prop_assert!(allowed(s, next, cw, prev, &q),
                    "{s} --{cw:#06x} (prev {prev:#06x})--> {next} not allowed by §3.1");
                s = next;
                prev = cw;
            }
        }
    }
}
