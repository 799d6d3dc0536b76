//! The power drive system (PDS) steps every emulated drive takes the same way around the
//! CiA 402 state machine of `cellrt_cia402::fsa` (CiA 402 §3, transitions by number): a
//! controlword either resets a fault (15) or moves the state, an alarm starts the model's fault
//! reaction (13), and a stop ends in Fault (14) or Switch on disabled (12). What a model adds
//! (which alarms a reset clears, the main circuit, STO) stays with the model.

use cellrt_cia402::controlword::Controlword;
use cellrt_cia402::fsa::{drive_transition, FsaQuirks, FsaState};

/// What a controlword asks of the PDS.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ControlwordStep {
    /// (15) Fault Reset edge in Fault: the model clears the alarms it can, which leaves Fault
    /// for Switch on disabled.
    FaultReset,
    /// The state the transitions of [`drive_transition`] lead to (the same one where none
    /// applies).
    To(FsaState),
}

/// The step controlword `cw` (after `prev`) takes from `state` on a drive with `quirks`.
pub fn controlword_step(
    state: FsaState,
    cw: Controlword,
    prev: Controlword,
    quirks: &FsaQuirks,
) -> ControlwordStep {
    let next = drive_transition(state, cw, prev, quirks);
    if state == FsaState::Fault && next == FsaState::SwitchOnDisabled {
        ControlwordStep::FaultReset
    } else {
        ControlwordStep::To(next)
    }
}

/// How a model enters Fault when an alarm occurs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FaultReaction {
    /// (13) Fault reaction active while the motor stops, then (14) Fault ([`end_of_stop`]):
    /// the simulated EtherCAT drives.
    StopThenFault,
    /// Fault at once, the reaction (base off, dynamic brake) passing within the step: the
    /// MR-JE-C (MR-JE-C manual §7.6.1).
    Immediate,
}

impl FaultReaction {
    /// The state an alarm in `state` leads to (Fault stays Fault).
    pub fn on_alarm(self, state: FsaState) -> FsaState {
        match (state, self) {
            (FsaState::Fault, _) | (_, FaultReaction::Immediate) => FsaState::Fault,
            (_, FaultReaction::StopThenFault) => FsaState::FaultReactionActive,
        }
    }
}

/// The state after a step in which the motor `stopped` (or not): (14) Fault reaction active →
/// Fault, and (12) Quick stop active → Switch on disabled unless the quick stop option keeps
/// the drive there (`quick_stop_stays`, option codes 5–8, CiA 402 §3.1). Other states stay.
pub fn end_of_stop(state: FsaState, stopped: bool, quick_stop_stays: bool) -> FsaState {
    match state {
        FsaState::FaultReactionActive if stopped => FsaState::Fault,
        FsaState::QuickStopActive if stopped && !quick_stop_stays => FsaState::SwitchOnDisabled,
        s => s,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const QUIRKS: FsaQuirks = FsaQuirks::STRICT;

    #[test]
    fn a_fault_reset_edge_in_fault_is_the_models_to_judge() {
        let reset = Controlword(0x80);
        let step = controlword_step(FsaState::Fault, reset, Controlword(0), &QUIRKS);
        assert_eq!(step, ControlwordStep::FaultReset);
        let held = controlword_step(FsaState::Fault, reset, reset, &QUIRKS);
        assert_eq!(held, ControlwordStep::To(FsaState::Fault));
    }

    #[test]
    fn the_reaction_and_the_stops_end_where_the_model_says() {
        let s = FsaState::OperationEnabled;
        assert_eq!(FaultReaction::Immediate.on_alarm(s), FsaState::Fault);
        let reacting = FaultReaction::StopThenFault.on_alarm(s);
        assert_eq!(reacting, FsaState::FaultReactionActive);
        assert_eq!(end_of_stop(reacting, false, false), reacting);
        assert_eq!(end_of_stop(reacting, true, false), FsaState::Fault);
        let qs = FsaState::QuickStopActive;
        assert_eq!(end_of_stop(qs, true, true), qs);
        assert_eq!(end_of_stop(qs, true, false), FsaState::SwitchOnDisabled);
    }
}
