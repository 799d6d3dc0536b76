//! The simulated drive: PDS, modes, alarms and PDO images around a [`ServoPlant`].
//!
//! Follows the simulator checklist of mr-j5-g-n1.md §10 where this crate models it: PDS with
//! shortcuts and no transition 16 (§3.1/§3.2), quick stop ending in SOD, Fault Reset on the
//! edge, statusword bits 8/14 = 0 and no statusword in NRTSO (§3.4), byte-exact default maps
//! (§5.2), the zero-speed gate on mode switches (§4.3). Deterministic and allocation-free.

use super::plant::{PlantParams, ServoPlant};
use crate::cia402::controlword::Controlword;
use crate::cia402::fsa::{drive_transition, FsaState};
use crate::cia402::mode::ModeOfOperation;
use crate::cia402::statusword::Statusword;
use crate::cycles::{CycleTime, Cycles};
use crate::pdo::{PdoError, RxPdo, TxPdo};
use crate::profiles::DriveProfile;

/// Error code (603Fh) of the following-error alarm: CiA 402 8611h "following error" [background].
pub const FOLLOWING_ERROR_ALARM: u16 = 0x8611;

/// Configuration of one simulated drive.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimDriveParams {
    /// The motor and its servo loops.
    pub plant: PlantParams,
    /// Position actual value (6064h) at start-up, in counts.
    pub initial_position: i32,
    /// Following-error limit in counts; exceeding it in Operation enabled (csp) raises
    /// [`FOLLOWING_ERROR_ALARM`] → Fault reaction active → Fault.
    pub following_error_limit: u32,
    /// Cycles spent in Not ready to switch on after start before (1) to Switch on disabled.
    pub startup_cycles: u32,
    /// Velocity feed-forward gain in csp, 0.0…1.0 of the target's rate of change.
    /// Default 0: Mitsubishi's feed-forward gain defaults to 0 % [background].
    pub velocity_feedforward: f64,
    /// Speed (counts/s) at or below which the motor counts as stopped: ends a quick stop or
    /// fault reaction, and opens the mode-switch gate (S_ZSP, §4.3 rules 4–5).
    pub zero_speed: f64,
    /// 6061h at start-up (csp with PT01.2 = pulse, §1.2).
    pub initial_mode: ModeOfOperation,
}

impl Default for SimDriveParams {
    /// Default plant, position 0, 200 000 counts following-error limit, 2 start-up cycles.
    fn default() -> Self {
        SimDriveParams {
            plant: PlantParams::default(),
            initial_position: 0,
            following_error_limit: 200_000,
            startup_cycles: 2,
            velocity_feedforward: 0.0,
            zero_speed: 0.0,
            initial_mode: ModeOfOperation::CyclicSyncPosition,
        }
    }
}

/// One simulated servo axis that exchanges PDO images like the real drive.
#[derive(Debug, Clone)]
pub struct SimDrive {
    profile: &'static DriveProfile,
    params: SimDriveParams,
    cycle_time: CycleTime,
    state: FsaState,
    prev_cw: Controlword,
    mode_display: ModeOfOperation,
    plant: ServoPlant,
    alarm: Option<u16>,
    startup_left: u32,
    /// Position demand in counts (csp: from 607Ah; csv: integrated 60FFh; others: held).
    demand: f64,
    prev_target: i32,
    following_error: i32,
    tx: TxPdo,
}

impl SimDrive {
    /// A drive at rest in Not ready to switch on, running the `profile`'s default maps.
    pub fn new(
        profile: &'static DriveProfile,
        params: SimDriveParams,
        cycle_time: CycleTime,
    ) -> Self {
        let pos = f64::from(params.initial_position);
        let mut d = SimDrive {
            profile,
            params,
            cycle_time,
            state: FsaState::NotReadyToSwitchOn,
            prev_cw: Controlword::DISABLE_VOLTAGE,
            mode_display: params.initial_mode,
            plant: ServoPlant::new(params.plant, pos),
            alarm: None,
            startup_left: params.startup_cycles,
            demand: pos,
            prev_target: params.initial_position,
            following_error: 0,
            tx: TxPdo::default(),
        };
        d.tx = d.make_tx();
        d
    }

    /// One bus cycle: decode `rx`, run the PDS and the plant for `elapsed` cycles, encode `tx`.
    ///
    /// `elapsed` is the number of cycle periods since the previous call (1 in steady state).
    /// A bad image size returns an error and changes nothing.
    pub fn cycle(&mut self, rx: &[u8], tx: &mut [u8], elapsed: Cycles) -> Result<(), PdoError> {
        let cmd = self.profile.rx_pdo.decode_rx(rx)?;
        self.profile.tx_pdo.check_len(tx.len())?;
        let dt = self.cycle_time.as_secs_f64() * f64::from(elapsed.0);

        self.run_pds(cmd.controlword, elapsed);
        self.switch_mode(cmd.mode);
        self.run_plant(&cmd, dt);
        self.tx = self.make_tx();
        self.profile.tx_pdo.encode_tx(&self.tx, tx)
    }

    /// PDS: own transitions (1) and the controlword transitions of [`drive_transition`].
    fn run_pds(&mut self, cw: Controlword, elapsed: Cycles) {
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
                let next = drive_transition(s, cw, self.prev_cw, &self.profile.quirks);
                if s == FsaState::Fault && next == FsaState::SwitchOnDisabled {
                    // (15): every simulated alarm is resettable.
                    self.alarm = None;
                }
                self.state = next;
            }
        }
        self.prev_cw = cw;
        if self.state == FsaState::OperationEnabled && before != FsaState::OperationEnabled {
            self.servo_on();
        }
    }

    /// Servo on: the demand starts where the motor is.
    fn servo_on(&mut self) {
        self.demand = self.plant.position();
        self.plant.set_last_command(self.demand);
        self.prev_target = self.position_actual();
    }

    /// 6060h → 6061h: supported modes are taken when the zero-speed gate allows (§4.3);
    /// 0, unknown and unsupported values keep the previous display (TV-8 "6061h keeps the old value").
    fn switch_mode(&mut self, raw: i8) {
        let Some(mode) = ModeOfOperation::from_i8(raw) else {
            return;
        };
        if mode == self.mode_display || !self.profile.supports_mode(mode) {
            return;
        }
        let old = self.mode_display;
        let gated = old.is_position() || mode.is_position() || old.is_cyclic() != mode.is_cyclic();
        if gated && self.plant.velocity().abs() > self.params.zero_speed {
            return;
        }
        self.mode_display = mode;
        self.demand = self.plant.position();
        self.plant.set_last_command(self.demand);
        self.prev_target = self.position_actual();
    }

    fn run_plant(&mut self, cmd: &RxPdo, dt: f64) {
        self.following_error = 0;
        match self.state {
            FsaState::OperationEnabled => self.follow(cmd, dt),
            FsaState::QuickStopActive => {
                self.plant.hold(dt);
                if self.stopped() {
                    // (12) automatic at the end of the quick stop (option codes 1–4, §3.1).
                    self.state = FsaState::SwitchOnDisabled;
                }
            }
            FsaState::FaultReactionActive => {
                self.plant.hold(dt);
                if self.stopped() {
                    // (14) automatic after the fault reaction.
                    self.state = FsaState::Fault;
                }
            }
            _ => self.plant.hold(dt),
        }
    }

    fn stopped(&self) -> bool {
        self.plant.velocity().abs() <= self.params.zero_speed
    }

    /// Servo on in the current mode. csp follows 607Ah, csv integrates 60FFh; the profile modes
    /// and cst are not simulated and hold the position.
    fn follow(&mut self, cmd: &RxPdo, dt: f64) {
        let ff = match self.mode_display {
            ModeOfOperation::CyclicSyncPosition => {
                // Work in the i32 domain relative to the actual position so 607Ah may wrap.
                let rel = cmd.target_position.wrapping_sub(self.position_actual());
                self.demand = self.plant.position() + f64::from(rel);
                let step = cmd.target_position.wrapping_sub(self.prev_target);
                self.prev_target = cmd.target_position;
                if dt > 0.0 {
                    self.params.velocity_feedforward * f64::from(step) / dt
                } else {
                    0.0
                }
            }
            ModeOfOperation::CyclicSyncVelocity => {
                let v = f64::from(cmd.target_velocity);
                self.demand += v * dt;
                v
            }
            _ => 0.0,
        };
        self.plant.step(self.demand, ff, dt);
        // 60F4h = demand − 6064h in the wrapping i32 domain of the wire values.
        let demand = (self.demand.round() as i64) as i32;
        let demand = match self.mode_display {
            ModeOfOperation::CyclicSyncPosition => cmd.target_position,
            _ => demand,
        };
        self.following_error = demand.wrapping_sub(self.position_actual());
        let checked = matches!(
            self.mode_display,
            ModeOfOperation::CyclicSyncPosition | ModeOfOperation::ProfilePosition
        );
        if checked && self.following_error.unsigned_abs() > self.params.following_error_limit {
            self.raise(FOLLOWING_ERROR_ALARM);
        }
    }

    fn raise(&mut self, code: u16) {
        self.alarm = Some(code);
        if self.state != FsaState::Fault {
            // (13)
            self.state = FsaState::FaultReactionActive;
        }
    }

    /// Raises alarm `code` (603Fh): (13) Fault reaction active, then (14) Fault once stopped.
    pub fn inject_alarm(&mut self, code: u16) {
        self.raise(code);
        self.tx = self.make_tx();
    }

    fn position_actual(&self) -> i32 {
        // Wraps like a 32-bit position counter.
        (self.plant.position().round() as i64) as i32
    }

    fn make_tx(&self) -> TxPdo {
        let oe = self.state == FsaState::OperationEnabled;
        let sw = Statusword::for_state(self.state)
            .with_drive_follows_command(oe && self.mode_display.is_cyclic());
        let amax = self.params.plant.max_acceleration.abs();
        // Torque proxy in 0.1 % of rated torque, with max_acceleration = 300 % rated.
        let torque = if amax > 0.0 {
            (self.plant.acceleration() / amax * 3000.0).round() as i16
        } else {
            0
        };
        TxPdo {
            mode_display: self.mode_display.as_i8(),
            statusword: sw,
            position_actual: self.position_actual(),
            velocity_actual: self.plant.velocity().round() as i32,
            following_error: self.following_error,
            torque_actual: torque,
            error_code: self.alarm.unwrap_or(0),
        }
    }

    /// The PDS state.
    pub fn state(&self) -> FsaState {
        self.state
    }

    /// The latched alarm code, if any (cleared by a successful Fault Reset).
    pub fn alarm(&self) -> Option<u16> {
        self.alarm
    }

    /// The typed TxPDO of the last cycle (includes 603Fh even when the map does not carry it).
    pub fn tx_pdo(&self) -> &TxPdo {
        &self.tx
    }

    /// The current mode of operation display (6061h).
    pub fn mode_display(&self) -> ModeOfOperation {
        self.mode_display
    }

    /// The motor model.
    pub fn plant(&self) -> &ServoPlant {
        &self.plant
    }

    /// The drive's profile.
    pub fn profile(&self) -> &'static DriveProfile {
        self.profile
    }

    /// The cycle time the drive integrates with.
    pub fn cycle_time(&self) -> CycleTime {
        self.cycle_time
    }

    /// The configuration.
    pub fn params(&self) -> &SimDriveParams {
        &self.params
    }
}
