//! The master-side sequencer: walks one drive's PDS to the state a request asks for.
//!
//! Controlword choices follow MR-J5-G-N1 manual §7.1/§3.2; the fault-reset hold follows §7.1.
//! Called once per cycle; allocation-free, no clock (time is counted in [`Cycles`]).

use super::controlword::{Command, Controlword};
use super::fsa::{FsaQuirks, FsaState};
use super::statusword::Statusword;
use crate::cycles::Cycles;

/// What [`MasterRequest::QuickStop`] sends to a drive that has no quick stop (MR-J3-T04:
/// "Masters must not use Quick stop on this drive. Use Disable operation, Shutdown or MSTOP",
/// MR-J3-T04 manual §8.4.1(3)). The drive then does not ramp: the RT loop must bring the axis to a stop
/// with its own setpoints (controlled stop) before requesting it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum QuickStopSubstitute {
    /// Shutdown (0x0006): (8) servo off to Ready to switch on, the clean state for leaving OP.
    /// The default for drives without quick stop.
    Shutdown,
    /// Disable Voltage (0x0000): (9) servo off to Switch on disabled.
    DisableVoltage,
}

/// What the application wants from an axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MasterRequest {
    /// Clean shutdown to Ready to switch on via Shutdown (spec README "Leaving OP"). Does not reset faults.
    Disable,
    /// Servo on: reach Operation enabled, resetting a fault that is present when requested.
    Enable,
    /// Quick Stop from Operation enabled (11); the MR-J5 ends in Switch on disabled (12).
    QuickStop,
    /// Acknowledge a present fault (held reset, §2.4), then end like [`MasterRequest::Disable`].
    FaultReset,
}

/// Where the sequencer stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MasterState {
    /// No request yet; the master sends Disable Voltage and changes nothing.
    Idle,
    /// The drive is not enabled and the master wants it so (Disable/FaultReset/QuickStop reached).
    Disabled,
    /// Walking the drive towards Operation enabled.
    Enabling,
    /// The drive reports Operation enabled.
    Enabled,
    /// Walking the drive towards Ready to switch on.
    Disabling,
    /// Quick stop commanded; waiting for the drive to stop and leave Quick stop active.
    QuickStopping,
    /// The drive reports a fault the current request may not reset; needs Enable or FaultReset.
    Faulted,
    /// Holding Fault Reset, or waiting for the drive to leave Fault after the hold.
    ResettingFault,
    /// The drive left Operation enabled on its own (not faulted); needs a new request.
    EnableLost,
    /// The drive did not reach the next state within the timeout; needs a new request.
    TimedOut,
}

/// Tuning of the sequencer, in cycles.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct MasterParams {
    /// Cycles to hold controlword bit 7 (≥ 10 ms, ≥ 20 ms at 8 ms; see `DriveProfile::fault_reset_hold`).
    pub fault_reset_hold: Cycles,
    /// Cycles the drive may stay in one state while the master waits for the next one.
    /// Must cover the longest quick stop and fault reaction.
    pub transition_timeout: Cycles,
}

/// Progress of the held fault reset.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum ResetPhase {
    /// No reset in progress.
    Ready,
    /// Sending 0x0000 for one cycle so the next 0x0080 is a rising edge.
    Priming,
    /// Bit 7 sent for this many cycles.
    Holding(u32),
    /// Hold done; waiting for the drive to report a non-fault state.
    Released,
}

/// CiA 402 master for one axis: call [`AxisMaster::update`] once per cycle with the latest statusword.
#[derive(Debug, Clone)]
pub struct AxisMaster {
    params: MasterParams,
    request: Option<MasterRequest>,
    state: MasterState,
    drive_state: Option<FsaState>,
    last_cw: Controlword,
    waited: u32,
    reset: ResetPhase,
    may_reset: bool,
    quick_stop: Option<QuickStopSubstitute>,
    halt: bool,
}

impl AxisMaster {
    /// A master with no request (state [`MasterState::Idle`]).
    pub fn new(params: MasterParams) -> Self {
        AxisMaster {
            params,
            request: None,
            state: MasterState::Idle,
            drive_state: None,
            last_cw: Controlword::DISABLE_VOLTAGE,
            waited: 0,
            reset: ResetPhase::Ready,
            may_reset: false,
            quick_stop: None,
            halt: false,
        }
    }

    /// A master for a drive with `quirks` (its model's PDS deviations): on a drive without quick
    /// stop, the [`QuickStopSubstitute::Shutdown`] substitute. `AxisMaster::for_profile` builds
    /// it from a drive profile.
    pub fn for_drive(params: MasterParams, quirks: FsaQuirks) -> Self {
        let mut m = AxisMaster::new(params);
        if !quirks.has_quick_stop {
            m.quick_stop = Some(QuickStopSubstitute::Shutdown);
        }
        m
    }

    /// Sets what [`MasterRequest::QuickStop`] sends: `None` = the drive's own Quick Stop
    /// (0x0002), `Some` = a substitute for drives without one.
    pub fn set_quick_stop_substitute(&mut self, substitute: Option<QuickStopSubstitute>) {
        self.quick_stop = substitute;
    }

    /// The quick-stop substitute in use, if any.
    pub fn quick_stop_substitute(&self) -> Option<QuickStopSubstitute> {
        self.quick_stop
    }

    /// Sets controlword bit 8 HALT on every Enable Operation word from the next
    /// [`AxisMaster::update`] on (§3.3). Whether the drive acts on it depends on the model and
    /// mode (`CycleFacts::halt_in_cyclic_modes`; MR-J3-T04 and MR-J4-TM: not in csp/csv/cst).
    pub fn set_halt(&mut self, on: bool) {
        self.halt = on;
    }

    /// True while HALT is requested.
    pub fn halt(&self) -> bool {
        self.halt
    }

    /// True when the drive may leave OP without a communication alarm: the clean shutdown has
    /// reached Ready to switch on (or the drive is in Switch on disabled, Fault or not ready).
    /// Sequence: stop the motion, [`MasterRequest::Disable`] (Shutdown), wait for this, then
    /// request PRE-OP (spec README "Leaving OP").
    pub fn ready_to_leave_op(&self) -> bool {
        matches!(
            self.drive_state,
            Some(
                FsaState::ReadyToSwitchOn
                    | FsaState::SwitchOnDisabled
                    | FsaState::Fault
                    | FsaState::NotReadyToSwitchOn
            )
        )
    }

    /// Sets the goal. Repeating the current request is a no-op, except from
    /// [`MasterState::TimedOut`], [`MasterState::Faulted`] and [`MasterState::EnableLost`], where
    /// it restarts the sequence (so a request every cycle cannot reset faults in a loop).
    pub fn request(&mut self, request: MasterRequest) {
        let latched = matches!(
            self.state,
            MasterState::TimedOut | MasterState::Faulted | MasterState::EnableLost
        );
        if self.request == Some(request) && !latched {
            return;
        }
        self.request = Some(request);
        self.waited = 0;
        self.reset = ResetPhase::Ready;
        self.may_reset = matches!(request, MasterRequest::Enable | MasterRequest::FaultReset);
        self.state = match request {
            MasterRequest::Disable => MasterState::Disabling,
            MasterRequest::Enable => MasterState::Enabling,
            MasterRequest::QuickStop => MasterState::QuickStopping,
            MasterRequest::FaultReset => MasterState::ResettingFault,
        };
    }

    /// One cycle: decode `sw`, advance the sequence, return the controlword to send this cycle.
    pub fn update(&mut self, sw: Statusword) -> Controlword {
        let ds = sw.state();
        if ds == self.drive_state {
            self.waited = self.waited.saturating_add(1);
        } else {
            self.waited = 0;
            self.drive_state = ds;
        }
        let mut cw = self.step(ds);
        if self.halt && !cw.fault_reset() && cw.state_command() == Command::EnableOperation {
            cw = cw.with_halt(true);
        }
        self.last_cw = cw;
        cw
    }

    fn step(&mut self, ds: Option<FsaState>) -> Controlword {
        use FsaState as S;
        use MasterState as M;

        let Some(request) = self.request else {
            self.state = M::Idle;
            return Controlword::DISABLE_VOLTAGE;
        };
        match self.state {
            M::TimedOut | M::Faulted | M::EnableLost => return Controlword::DISABLE_VOLTAGE,
            M::Enabled if ds != Some(S::OperationEnabled) => {
                self.state = if ds.is_some_and(FsaState::is_fault) {
                    M::Faulted
                } else {
                    M::EnableLost
                };
                return Controlword::DISABLE_VOLTAGE;
            }
            _ => {}
        }
        // A started fault reset is held for its full length whatever the drive reports (§2.4).
        match self.reset {
            ResetPhase::Priming => return self.hold_reset(1),
            ResetPhase::Holding(n) if n < self.params.fault_reset_hold.0 => {
                return self.hold_reset(n + 1)
            }
            ResetPhase::Holding(_) => {
                self.reset = ResetPhase::Released;
                self.waited = 0;
            }
            ResetPhase::Ready | ResetPhase::Released => {}
        }

        let Some(ds) = ds else {
            // Undecodable statusword: keep the last word (without a fault reset, which is only
            // sent by a deliberate hold) and let the timeout decide.
            let keep = Controlword(self.last_cw.0 & !Controlword::FAULT_RESET.0);
            return self.waiting(self.state_for(request), keep);
        };
        match ds {
            S::Fault if self.may_reset && self.reset == ResetPhase::Ready => {
                if self.last_cw.fault_reset() {
                    self.reset = ResetPhase::Priming;
                    self.state = M::ResettingFault;
                    Controlword::DISABLE_VOLTAGE
                } else {
                    self.hold_reset(1)
                }
            }
            S::Fault | S::FaultReactionActive if self.may_reset => {
                self.waiting(M::ResettingFault, Controlword::DISABLE_VOLTAGE)
            }
            S::Fault | S::FaultReactionActive => {
                self.state = M::Faulted;
                Controlword::DISABLE_VOLTAGE
            }
            S::NotReadyToSwitchOn => {
                self.waiting(self.state_for(request), Controlword::DISABLE_VOLTAGE)
            }
            _ => {
                // The drive is out of Fault: a later fault is not this request's to reset.
                self.may_reset = false;
                self.reset = ResetPhase::Ready;
                self.towards(request, ds)
            }
        }
    }

    /// The controlword that moves a non-faulted drive one step towards the goal of `request`.
    fn towards(&mut self, request: MasterRequest, ds: FsaState) -> Controlword {
        use FsaState as S;
        use MasterState as M;
        match request {
            MasterRequest::Enable => match ds {
                S::OperationEnabled => self.reached(M::Enabled, Controlword::ENABLE_OPERATION),
                S::SwitchedOn => self.waiting(M::Enabling, Controlword::ENABLE_OPERATION), // (4)
                S::ReadyToSwitchOn => self.waiting(M::Enabling, Controlword::SWITCH_ON),   // (3)
                S::SwitchOnDisabled => self.waiting(M::Enabling, Controlword::SHUTDOWN),   // (2)
                _ => self.waiting(M::Enabling, Controlword::DISABLE_VOLTAGE), // QSA (12)
            },
            MasterRequest::Disable | MasterRequest::FaultReset => match ds {
                S::ReadyToSwitchOn => self.reached(M::Disabled, Controlword::SHUTDOWN),
                S::QuickStopActive => self.waiting(M::Disabling, Controlword::DISABLE_VOLTAGE), // (12)
                _ => self.waiting(M::Disabling, Controlword::SHUTDOWN), // (8), (6), (2)
            },
            MasterRequest::QuickStop => match (self.quick_stop, ds) {
                (None, S::SwitchOnDisabled) => self.reached(M::Disabled, Controlword::QUICK_STOP),
                (None, _) => self.waiting(M::QuickStopping, Controlword::QUICK_STOP), // (11), (10), (7)
                // Substitutes on a drive without quick stop (MR-J3-T04 §3.3).
                (Some(QuickStopSubstitute::Shutdown), S::ReadyToSwitchOn) => {
                    self.reached(M::Disabled, Controlword::SHUTDOWN)
                }
                (Some(QuickStopSubstitute::Shutdown), _) => {
                    self.waiting(M::QuickStopping, Controlword::SHUTDOWN) // (8), (6), (2)
                }
                (Some(QuickStopSubstitute::DisableVoltage), S::SwitchOnDisabled) => {
                    self.reached(M::Disabled, Controlword::DISABLE_VOLTAGE)
                }
                (Some(QuickStopSubstitute::DisableVoltage), _) => {
                    self.waiting(M::QuickStopping, Controlword::DISABLE_VOLTAGE)
                    // (9), (10), (7)
                }
            },
        }
    }

    fn state_for(&self, request: MasterRequest) -> MasterState {
        match request {
            MasterRequest::Enable => MasterState::Enabling,
            MasterRequest::Disable => MasterState::Disabling,
            MasterRequest::QuickStop => MasterState::QuickStopping,
            MasterRequest::FaultReset => MasterState::ResettingFault,
        }
    }

    fn hold_reset(&mut self, sent: u32) -> Controlword {
        self.reset = ResetPhase::Holding(sent);
        self.state = MasterState::ResettingFault;
        self.waited = 0;
        Controlword::FAULT_RESET
    }

    fn reached(&mut self, state: MasterState, cw: Controlword) -> Controlword {
        self.state = state;
        self.waited = 0;
        cw
    }

    /// Not at the goal yet: send `cw`, or give up after `transition_timeout` cycles without progress.
    fn waiting(&mut self, state: MasterState, cw: Controlword) -> Controlword {
        if self.waited > self.params.transition_timeout.0 {
            self.state = MasterState::TimedOut;
            Controlword::DISABLE_VOLTAGE
        } else {
            self.state = state;
            cw
        }
    }

    /// The sequencer state.
    pub fn state(&self) -> MasterState {
        self.state
    }

    /// The current request, if any.
    pub fn current_request(&self) -> Option<MasterRequest> {
        self.request
    }

    /// The drive state decoded from the last statusword (`None` before the first or if undecodable).
    pub fn drive_state(&self) -> Option<FsaState> {
        self.drive_state
    }

    /// The controlword returned by the last [`AxisMaster::update`].
    pub fn last_controlword(&self) -> Controlword {
        self.last_cw
    }

    /// True when the drive reports Operation enabled.
    pub fn is_enabled(&self) -> bool {
        self.drive_state == Some(FsaState::OperationEnabled)
    }

    /// True when the drive reports Fault or Fault reaction active.
    pub fn fault(&self) -> bool {
        self.drive_state.is_some_and(FsaState::is_fault)
    }

    /// The parameters this master was built with.
    pub fn params(&self) -> MasterParams {
        self.params
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// Garbage statuswords and arbitrary request changes never panic, and fault reset is
        /// only ever sent while the drive reported Fault or a reset hold is running.
        #[test]
        fn random_statuswords_never_panic(
            steps in prop::collection::vec((any::<u16>(), 0u8..6), 1..200),
            hold in 0u32..5,
            timeout in 0u32..5,
        ) {
            let mut m = AxisMaster::new(MasterParams {
                fault_reset_hold: Cycles(hold),
                transition_timeout: Cycles(timeout),
            });
            for (sw, r) in steps {
                match r {
                    0 => m.request(MasterRequest::Enable),
                    1 => m.request(MasterRequest::Disable),
                    2 => m.request(MasterRequest::QuickStop),
                    3 => m.request(MasterRequest::FaultReset),
                    _ => {}
                }
                let cw = m.update(Statusword(sw));
                if cw.fault_reset() {
                    prop_assert_eq!(m.state(), MasterState::ResettingFault);
                }
                if m.state() == MasterState::TimedOut {
                    prop_assert_eq!(cw, Controlword::DISABLE_VOLTAGE);
                }
            }
        }
    }
}
