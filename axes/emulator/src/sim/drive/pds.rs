//! The PDS of the simulated drive (CiA 402 state machine with the model's quirks), the AL
//! state it follows, alarms and warnings, the power inputs and the checks at power-on.

use super::{AxisSwitch, SimDrive};
use crate::device::pds::{controlword_step, ControlwordStep, FaultReaction};
use crate::sim::home_setting::HomeSettingState;
use cellrt_cia402::controlword::Controlword;
use cellrt_cia402::cycles::Cycles;
use cellrt_cia402::fsa::FsaState;
#[cfg(doc)]
use cellrt_cia402::profiles::DriveProfile;

/// Main circuit power and EM1 (forced stop) inputs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct PowerInputs {
    pub(super) main_circuit: bool,
    pub(super) em1: bool,
    /// AL.E9: Enable operation was asked for while the main circuit was off.
    pub(super) main_off_warning: bool,
}

impl Default for PowerInputs {
    fn default() -> Self {
        PowerInputs {
            main_circuit: true,
            em1: true,
            main_off_warning: false,
        }
    }
}

impl SimDrive {
    /// The settings the amplifier checks at power-on: the axis switch SW3 against the
    /// profile's refused setting (MR-J5-G-N1 1-axis AL.011.2, TV-14; the moment of detection is
    /// [inferred], see [`AxisSwitch`]).
    pub(super) fn power_on_checks(&mut self) {
        // MR-J3-T04 §2.4, TV-IC-5: free-run (PO02 = 0001h) with the incremental-counter check
        // enabled (PO03 digit 0 ≠ 0) is a parameter error.
        if let cellrt_cia402::profiles::CommCheck::IncrementalCounter { free_run_alarm, .. } =
            self.profile.comm.check
        {
            let comm = self.comm_in_force();
            if comm.po02 & 0xF == 1 && comm.po03 & 0xF != 0 {
                self.raise(free_run_alarm);
            }
        }
        if let Some(rule) = self.profile.invalid_axis_switch {
            let sw = self.params.axis_switch;
            if sw.sw3_1 == rule.sw3_1 && sw.sw3_2 == rule.sw3_2 {
                self.raise(rule.alarm);
            }
        }
    }

    /// Sets the DIP switch SW3; the amplifier reads it at the next power-on
    /// ([`SimDrive::power_cycle`]).
    pub fn set_axis_switch(&mut self, switch: AxisSwitch) {
        self.params.axis_switch = switch;
    }

    /// The AL state leaves OP (to SafeOp, PreOp or Init). Switched on, Operation enabled or
    /// Quick stop active at that moment raises the model's `leave_op_alarm` (MR-J3-T04 AL.61 per
    /// §2.5's recommended model; AL.086.1 / AL. 86.1 on the others, spec README "Leaving OP");
    /// Ready to switch on and below leave cleanly and silence the communication checks. Drives
    /// that re-initialise on leaving OP return to Switch on disabled. Returns the alarm raised.
    pub fn leave_op(&mut self) -> Option<u16> {
        if !self.op {
            return None;
        }
        let operating = matches!(
            self.state,
            FsaState::SwitchedOn | FsaState::OperationEnabled | FsaState::QuickStopActive
        );
        let alarm = operating.then_some(self.profile.comm.leave_op_alarm);
        if let Some(code) = alarm {
            self.raise(code);
        } else if self.profile.comm.reinit_on_leaving_op
            && !self.state.is_fault()
            && self.state != FsaState::NotReadyToSwitchOn
        {
            self.state = FsaState::SwitchOnDisabled;
        }
        self.op = false;
        self.tx = self.make_tx();
        alarm
    }

    /// The AL state returns to OP: the checks start afresh with the next frame, with the sync
    /// error counter limit the master may have written to 10F1h:02 meanwhile.
    pub fn enter_op(&mut self) {
        if !self.op {
            self.op = true;
            self.comm.reset();
        }
        self.comm
            .set_sync_error_limit(self.comm_in_force().sync_error_limit);
    }

    /// Distributed clocks start with SYNC0 every `sync0_ns` (SAFE-OP → OP). On a model whose
    /// manual names an alarm for it, a SYNC0 cycle other than the PDO cycle the master wrote
    /// to 1C32h:02 raises that alarm (MR-J3-T04 TV-IC-5 (docs/test-vectors.md), §8.2.3(1)); returns it.
    pub fn start_sync(&mut self, sync0_ns: u32) -> Option<u16> {
        let alarms = self.profile.pdo.rules.sync_mismatch_alarms;
        let alarm = self
            .params
            .sync_mismatch_alarm
            .filter(|a| alarms.contains(a))
            .or(alarms.first().copied())?;
        let cycle = self.sdo_upload(0x1C32, 2).ok()?;
        if cycle == i64::from(sync0_ns) {
            return None;
        }
        self.raise(alarm);
        self.tx = self.make_tx();
        Some(alarm)
    }

    /// True while the AL state is Operational.
    pub fn in_op(&self) -> bool {
        self.op
    }

    /// Control-power cycle: every alarm clears, the drive restarts in Not ready to switch on
    /// (the motor stays where it is), the checks restart, the AL state is OP again.
    pub fn power_cycle(&mut self) {
        self.alarm = None;
        self.state = FsaState::NotReadyToSwitchOn;
        self.startup_left = self.params.startup_cycles;
        self.prev_cw = Controlword::DISABLE_VOLTAGE;
        self.plant.hold(0.0);
        self.reload_parameters();
        let counter_mapped = self.profile.pdo.rx.has_counter() && self.profile.pdo.tx.has_counter();
        self.comm = super::DriveComm::new(
            self.profile.comm.check,
            self.comm_in_force(),
            self.cycle_time,
            counter_mapped,
        );
        self.op = true;
        self.following_error = 0;
        // S_ZPAS is "since power-on"; the C_CR edges start afresh.
        self.home_set = HomeSettingState::default();
        if let Some(f) = self.fsoe.as_mut() {
            f.reset();
        }
        self.power_on_checks();
        self.tx = self.make_tx();
    }

    /// The sync-error counter of the communication check (0 on the MR-J3-T04).
    pub fn sync_errors(&self) -> u32 {
        self.comm.sync_errors()
    }

    /// PDS: own transitions (1) and the controlword transitions of the shared device core
    /// ([`controlword_step`]).
    pub(super) fn run_pds(&mut self, cw: Controlword, elapsed: Cycles) {
        let before = self.state;
        match self.state {
            FsaState::NotReadyToSwitchOn => {
                // (1) automatic once initialised.
                self.startup_left = self.startup_left.saturating_sub(elapsed.0);
                if self.startup_left == 0 {
                    self.state = FsaState::SwitchOnDisabled;
                }
            }
            FsaState::FaultReactionActive => {} // (14) when the motor has stopped, see run_plant.
            s => {
                let quirks = self
                    .profile
                    .quirks
                    .for_quick_stop_option(self.quick_stop_option());
                match controlword_step(s, cw, self.prev_cw, &quirks) {
                    // (15) resets only the alarms a fault reset can clear; the others stay
                    // latched until a power cycle (e.g. MR-J3-T04 AL.34/36/61).
                    ControlwordStep::FaultReset => match self.alarm {
                        Some(code) if !self.profile.alarm_resettable(code) => {}
                        _ => {
                            self.alarm = None;
                            self.state = FsaState::SwitchOnDisabled;
                        }
                    },
                    ControlwordStep::To(next) => self.state = next,
                }
            }
        }
        self.prev_cw = cw;
        if self.safe_torque_off() {
            // STO (sim::fsoe): no state with the power stage ready; a fault reaction is over
            // at once, the energy being cut ([inferred], the manual states no PDS reaction).
            match self.state {
                FsaState::ReadyToSwitchOn
                | FsaState::SwitchedOn
                | FsaState::OperationEnabled
                | FsaState::QuickStopActive => self.state = FsaState::SwitchOnDisabled,
                FsaState::FaultReactionActive => self.state = FsaState::Fault,
                _ => {}
            }
        }
        if self.profile.limits.power_warnings.is_some() && !self.power.main_circuit {
            // (8B) main circuit off → Ready to switch on; asking for more raises AL.E9.
            if matches!(
                self.state,
                FsaState::SwitchedOn | FsaState::OperationEnabled
            ) {
                if before == FsaState::ReadyToSwitchOn {
                    self.power.main_off_warning = true;
                }
                self.state = FsaState::ReadyToSwitchOn;
            }
        }
        if self.state == FsaState::OperationEnabled && before != FsaState::OperationEnabled {
            self.servo_on();
        }
    }

    /// Servo on: the demand starts where the motor is.
    pub(super) fn servo_on(&mut self) {
        self.demand = self.plant.position();
        self.plant.set_last_command(self.demand);
        self.prev_target = self.position_actual().wrapping_sub(self.position_offset());
        self.reset_profiles();
    }

    pub(super) fn raise(&mut self, code: u16) {
        if self.alarm != Some(code) {
            self.record_alarm(code);
        }
        self.alarm = Some(code);
        // (13)
        self.state = FaultReaction::StopThenFault.on_alarm(self.state);
    }

    /// Raises alarm `code` (603Fh): (13) Fault reaction active, then (14) Fault once stopped.
    pub fn inject_alarm(&mut self, code: u16) {
        self.raise(code);
        self.tx = self.make_tx();
    }

    /// The active warning code, if any (statusword bit 7); the most severe first: EM1 (AL.E6),
    /// main circuit off (AL.E9), stroke end (AL.99).
    pub fn warning(&self) -> Option<u16> {
        let pw = self.profile.limits.power_warnings;
        if let Some((e6, e9)) = pw {
            if !self.power.em1 {
                return Some(e6);
            }
            if self.power.main_off_warning {
                return Some(e9);
            }
        }
        if let Some(w) = self.pp.warning().or(self.homing.warning) {
            return Some(w);
        }
        if let Some(w) = self
            .profile
            .homing
            .setting
            .and_then(|b| self.home_set.warning(&b))
        {
            return Some(w);
        }
        self.profile
            .limits
            .stroke_end_warning
            .filter(|_| self.stroke.warning)
    }

    /// Sets the main circuit power input. Off in Switched on or Operation enabled goes to Ready
    /// to switch on (8B); Enable operation while it is off raises AL.E9 and stays there
    /// (MR-J3-T04 manual §8.4.1, §8.5.1, §8.5.2, §3.7, §3.10, §4.1(4), §7, on models with `LimitFacts::power_warnings`).
    pub fn set_main_circuit_power(&mut self, on: bool) {
        self.power.main_circuit = on;
        if on {
            self.power.main_off_warning = false;
        }
    }

    /// Sets the forced stop input EM1 (ON = run). OFF: base circuit off with a dynamic-brake
    /// stop and warning AL.E6; the FSA state is kept (the spec's inferred default) and commands
    /// keep being processed, so the motor follows them again as soon as EM1 is ON.
    pub fn set_em1(&mut self, on: bool) {
        self.power.em1 = on;
    }
}
