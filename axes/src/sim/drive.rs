//! The simulated drive: PDS, modes, alarms, communication checks and PDO images around a
//! [`ServoPlant`], with every model difference read from its [`DriveProfile`].
//!
//! Follows the simulator checklists ("What a faithful simulator must reproduce") of the four
//! EtherCAT spec extracts where this crate models them: PDS with the model's quirks (shortcuts,
//! no quick stop on the MR-J3-T04 with statusword bit 5 always 1, no transition 16), quick stop
//! ending in SOD, Fault Reset on the edge clearing only resettable alarms (the rest need
//! [`SimDrive::power_cycle`]), statusword bits 8/14 = 0 and no statusword in NRTSO, byte-exact
//! default maps, the zero-speed gate on mode switches, csp/csv/cst with the torque limits, pp
//! (`sim::profile_position`), the csp position offset 60B0h,
//! following-error and overspeed alarms, the communication checks of `sim::comm`, and the alarm
//! on leaving OP while switched on ([`SimDrive::leave_op`]), the axis switch SW3 checked at
//! power-on ([`AxisSwitch`]), and FSoE safety process data with STO acting on the PDS and the
//! plant where configured (`sim::fsoe`, [`SimDrive::fsoe_exchange`]). Deterministic and
//! allocation-free.

use super::comm::{CommParams, DriveComm};
use super::fsoe::{FsoeSlave, FsoeSlaveParams, StoStop};
use super::home_setting::{BeforeZReaction, HomeSettingOutcome, HomeSettingState, ZPhase};
use super::plant::{PlantParams, ServoPlant};
use super::profile_position::{
    HaltOption, PositionUnit, PpCommand, PpFeedback, PpParams, ProfilePosition,
};
use crate::cia402::controlword::Controlword;
use crate::cia402::fsa::{drive_transition, FsaState};
use crate::cia402::mode::ModeOfOperation;
use crate::cia402::statusword::Statusword;
use crate::cycles::{CycleTime, Cycles};
use crate::fsoe::{ConnectionParams, FsoeError, FsoeFrame, SafetyStatus};
use crate::pdo::objects::{
    RxField, POSITION_OFFSET, POSITION_WINDOW, POSITION_WINDOW_TIME, PROFILE_ACCELERATION,
    PROFILE_DECELERATION, PROFILE_VELOCITY,
};
use crate::pdo::{PdoError, PdoLayout, RxPdo, TxPdo};
use crate::profiles::{DriveProfile, HomeReference, TorqueLimitSelection};

/// Error code (603Fh) of the following-error alarm: CiA 402 8611h "following error"
/// [background]; each model's code is `DriveProfile::following_error_alarm`.
pub const FOLLOWING_ERROR_ALARM: u16 = crate::cia402::error_code::FOLLOWING_ERROR;

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
    /// 6061h at start-up (csp with PT01.2 = pulse, §1.2; MR-J3-T04: from PO02).
    pub initial_mode: ModeOfOperation,
    /// Communication checks (counter, RxPDO loss, sync-error counter).
    pub comm: CommParams,
    /// Command speed (counts/s) above which a csp target step raises the model's overspeed alarm
    /// (MR-J3-T04 AL.35); `None`: 1.2 × `plant.max_velocity` (the MR-J3 clamps 60FFh at 120 %
    /// of the maximum speed, §9.6). csv targets are clamped to it instead.
    pub overspeed_limit: Option<f64>,
    /// Alarm codes overriding the profile's (following error, overspeed); `None`: profile's.
    pub alarm_codes: Option<(u16, u16)>,
    /// The drive's own torque-limit parameters, used where the profile selects them
    /// ([`TorqueLimitSelection::Controlword2`], MR-J3-T04).
    pub internal_torque_limits: InternalTorqueLimits,
    /// Torque limit 2 (2D6Dh), used where the profile selects it by controlword
    /// ([`TorqueLimitSelection::TorqueLimit2`], MR-JET / MR-J5).
    pub torque_limit_2: TorqueLimit2,
    /// PC02 slow-stop time (ms, rated speed to 0) of a stroke-end stop on MR-J3-T04
    /// (mr-j3-t04.md §9.1); "rated speed" is taken as `plant.max_velocity`. 0: stop at the
    /// plant's maximum deceleration.
    pub slow_stop_time_ms: u32,
    /// How long a parameter save through 1010h:01 takes (mr-jet-g-n1.md §6: "about 25 s").
    pub store_parameters_ms: u32,
    /// 6064h after a homing on a drive that presets it ([`HomeReference::PositionPreset`],
    /// MR-J4-TM): the "home position address" parameter, not in the extract; default 0.
    pub home_position_address: i32,
    /// What the drive commands at a SYNC0 that brought no RxPDO in DC mode (the manuals state
    /// only the free-run rule — hold the last command — and leave DC mode unstated).
    pub dc_missed_command: MissedCommand,
    /// What C_CR2 before the first Z phase raises on a model with Controlword2 home setting
    /// (MR-J3-T04: AL.96 warning by default, AL.26 selectable; mr-j3-t04.md §7.2).
    pub before_z_reaction: BeforeZReaction,
    /// Raw position of the encoder's Z phase within a revolution (counts; the manual gives no
    /// figure, TV-HOME-1 uses 262100); default 0.
    pub z_phase_position: i32,
    /// The alarm a SYNC0 cycle other than 1C32h:02 raises, one of the profile's
    /// `pdo_rules.sync_mismatch_alarms` (MR-J3-T04 TV-IC-5: AL.76 or AL.74); `None`: the
    /// profile's first.
    pub sync_mismatch_alarm: Option<u16>,
    /// Profile position mode (pp) values the manuals leave open (`sim::profile_position`).
    pub pp: PpParams,
    /// [Pr. PT01.2] position data unit (acts on relative pp set-points, mr-j4-tm.md §4.7).
    pub position_unit: PositionUnit,
    /// The DIP switch SW3 (axis selection) as set on the amplifier, read at power-on; see
    /// [`AxisSwitch`].
    pub axis_switch: AxisSwitch,
    /// FSoE safety process data (safety PDOs 1608h/1A08h) on a model with FSoE
    /// ([`DriveProfile::fsoe`], MR-JET-G-N1); `None` (default): FSoE not used, no STO from the
    /// network. See `sim::fsoe`.
    pub fsoe: Option<FsoeSlaveParams>,
}

/// DIP switch SW3 of the MR-J5-G-N1 family (mr-j5-g-n1.md §1.5, TV-14; ON = up).
///
/// The manual states one rule: on a 1-axis amplifier SW3-1 OFF with SW3-2 ON raises AL.011.2
/// Invalid axis setting error (the profile's [`DriveProfile::invalid_axis_switch`]). It does not
/// say what SW3 selects, what the factory setting is, what multi-axis units accept, nor when
/// the setting is checked. **[inferred]** The simulator checks it at power-on
/// ([`SimDrive::new`], [`SimDrive::power_cycle`]) like the other start-up settings of manual
/// §8, so a switch changed while the drive runs ([`SimDrive::set_axis_switch`]) takes effect at
/// the next power cycle. The default (both OFF) is a setting the manual does not refuse.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct AxisSwitch {
    /// SW3-1 (ON = up).
    pub sw3_1: bool,
    /// SW3-2 (ON = up).
    pub sw3_2: bool,
}

/// 2D6Dh Torque limit 2 (mr-jet-g-n1.md §6/§9.1), in 0.1 % of rated torque; defaults per the
/// object table: select 0, both values 10000. Polarity (POL, which swaps :02 and :03) is taken
/// as disabled.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TorqueLimit2 {
    /// 2D6Dh:01 = 1: controlword bits CPTL / CNTL switch to the values below.
    pub select: bool,
    /// 2D6Dh:02 Positive torque limit value 2.
    pub positive: u16,
    /// 2D6Dh:03 Negative torque limit value 2.
    pub negative: u16,
}

impl Default for TorqueLimit2 {
    fn default() -> Self {
        TorqueLimit2 {
            select: false,
            positive: 10_000,
            negative: 10_000,
        }
    }
}

/// MR-J3-T04 torque-limit parameters, % of rated torque (mr-j3-t04.md §9.4). Their defaults
/// are in the J3A manual, which the extract does not include: the default here is the motor
/// maximum, [`InternalTorqueLimits::MOTOR_MAXIMUM_PERCENT`], so an unconfigured drive does not
/// limit below what the plant can do.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InternalTorqueLimits {
    /// PA11 forward (CCW driving / CW regeneration) torque limit.
    pub pa11_forward: f64,
    /// PA12 reverse (CW driving / CCW regeneration) torque limit.
    pub pa12_reverse: f64,
    /// PC35 internal torque limit (selected by C_TL1).
    pub pc35_internal: f64,
}

impl InternalTorqueLimits {
    /// The plant's maximum torque: `PlantParams::max_acceleration` stands for 300 % rated.
    pub const MOTOR_MAXIMUM_PERCENT: f64 = 300.0;
}

impl Default for InternalTorqueLimits {
    fn default() -> Self {
        InternalTorqueLimits {
            pa11_forward: Self::MOTOR_MAXIMUM_PERCENT,
            pa12_reverse: Self::MOTOR_MAXIMUM_PERCENT,
            pc35_internal: Self::MOTOR_MAXIMUM_PERCENT,
        }
    }
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
            comm: CommParams::default(),
            overspeed_limit: None,
            alarm_codes: None,
            internal_torque_limits: InternalTorqueLimits::default(),
            torque_limit_2: TorqueLimit2::default(),
            home_position_address: 0,
            dc_missed_command: MissedCommand::Extrapolate,
            before_z_reaction: BeforeZReaction::Warning,
            z_phase_position: 0,
            sync_mismatch_alarm: None,
            axis_switch: AxisSwitch::default(),
            fsoe: None,
            slow_stop_time_ms: 0,
            store_parameters_ms: 25_000,
            pp: PpParams::default(),
            position_unit: PositionUnit::Pulse,
        }
    }
}

/// A drive's command in a DC cycle whose RxPDO is missing (a named parameter: the manuals
/// are silent, mr-j4-tm.md §1.5 and mr-j5-g-n1.md §1.4 state only the free-run hold).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MissedCommand {
    /// Keep the last command (the free-run rule): a moving csp axis stops for the cycle and
    /// the next target jumps by two cycles' travel.
    Hold,
    /// csp: continue the last target step (the interpolator runs on); csv/cst: hold.
    #[default]
    Extrapolate,
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
    /// The profile's RxPDO and TxPDO maps, resolved once for the cyclic codec.
    rx_layout: PdoLayout,
    tx_layout: PdoLayout,
    /// The RxPDO carries 6060h (else the mode comes by SDO, e.g. MR-J3-T04).
    mode_mapped: bool,
    alarm: Option<u16>,
    /// Main circuit power and forced stop EM1 inputs (MR-J3-T04 §3.7), and AL.E9 latched by
    /// an Enable operation refused for a missing main circuit.
    power: PowerInputs,
    startup_left: u32,
    /// Position demand in counts (csp: from 607Ah; csv: integrated 60FFh; others: held).
    demand: f64,
    prev_target: i32,
    /// 607Ah step between the last two commands received (for [`MissedCommand::Extrapolate`]).
    last_step: i32,
    following_error: i32,
    tx: TxPdo,
    /// The last RxPDO received (held when a frame is lost: §1.5 "keeps the previous command").
    last_cmd: RxPdo,
    comm: DriveComm,
    /// AL state Operational: commands are acted on only in OP.
    op: bool,
    /// 6060h as last written by SDO (used when the RxPDO does not map 6060h, e.g. MR-J3-T04).
    sdo_mode: i8,
    /// Objects written by SDO download ([`SimDrive::sdo_download`]), by index and sub-index.
    sdo_values: Vec<(u16, u8, i64)>,
    /// Cycles left of a parameter save started through 1010h:01.
    saving_left: u32,
    /// Homing state (hm): 607Ch, the 6064h preset, statusword bits 12/13, the HOS edge.
    homing: HomingState,
    /// Stroke-end inputs and the stop they cause.
    stroke: StrokeState,
    /// csp manual stop (MR-J3-T04 C_MSTOP, Controlword2 bit 8).
    mstop: ManualStop,
    home_set: HomeSettingState,
    /// Profile position mode (pp): set-point handshake and trajectory generator.
    pp: ProfilePosition,
    /// The FSoE slave, when configured on a model with FSoE.
    fsoe: Option<FsoeSlave>,
}

/// The csp manual stop of mr-j3-t04.md §9.2 (TV-STROKE-2).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct ManualStop {
    /// C_MSTOP is on: 607Ah is discarded.
    active: bool,
    /// Velocity of the linear PC02 ramp of the demand, counts/s.
    ramp_velocity: f64,
    /// The internal command has been fully output: S_FLW (statusword bit 14).
    done: bool,
}

/// Main circuit power and EM1 (forced stop) inputs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct PowerInputs {
    main_circuit: bool,
    em1: bool,
    /// AL.E9: Enable operation was asked for while the main circuit was off.
    main_off_warning: bool,
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

/// LSP/LSN inputs (ON = may run in that direction) and the stroke-end slow stop.
#[derive(Debug, Clone, Copy, PartialEq)]
struct StrokeState {
    /// LSP: CCW (positive) motion allowed.
    lsp: bool,
    /// LSN: CW (negative) motion allowed.
    lsn: bool,
    /// The slow stop runs: commands are discarded until the motor has stopped once.
    stopping: bool,
    /// Velocity of the slow-stop ramp, counts/s.
    ramp_velocity: f64,
    /// AL.99 active: an input is OFF or its slow stop still runs.
    warning: bool,
}

impl Default for StrokeState {
    fn default() -> Self {
        StrokeState {
            lsp: true,
            lsn: true,
            stopping: false,
            ramp_velocity: 0.0,
            warning: false,
        }
    }
}

/// What homing has done to this drive.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
struct HomingState {
    /// 607Ch Home offset.
    home_offset: i32,
    /// Added to the motor position to give 6064h ([`HomeReference::PositionPreset`]).
    position_shift: i64,
    /// Statusword bit 12 in hm: homing attained (cleared at power-on and at homing start).
    attained: bool,
    /// Statusword bit 13 in hm: homing error.
    error: bool,
    /// Controlword bit 4 (HOS) of the previous cycle.
    hos: bool,
}

impl SimDrive {
    /// A drive at rest in Not ready to switch on, running the `profile`'s default maps.
    pub fn new(
        profile: &'static DriveProfile,
        params: SimDriveParams,
        cycle_time: CycleTime,
    ) -> Self {
        let pos = f64::from(params.initial_position);
        let counter_mapped = profile.rx_pdo.has_counter() && profile.tx_pdo.has_counter();
        // An unsupported initial mode falls back to csp, or to the first mode the profile
        // lists where csp is not in its group (MR-J4-TM PA01 `___2`: pp).
        let initial_mode = if profile.supports_mode(params.initial_mode) {
            params.initial_mode
        } else if profile.supports_mode(ModeOfOperation::CyclicSyncPosition) {
            ModeOfOperation::CyclicSyncPosition
        } else {
            profile
                .modes
                .first()
                .copied()
                .unwrap_or(ModeOfOperation::CyclicSyncPosition)
        };
        let mut d = SimDrive {
            profile,
            params,
            cycle_time,
            state: FsaState::NotReadyToSwitchOn,
            prev_cw: Controlword::DISABLE_VOLTAGE,
            mode_display: initial_mode,
            plant: ServoPlant::new(params.plant, pos),
            rx_layout: PdoLayout::new(&profile.rx_pdo),
            mode_mapped: profile.rx_pdo.maps(crate::pdo::objects::MODES_OF_OPERATION),
            tx_layout: PdoLayout::new(&profile.tx_pdo),
            alarm: None,
            power: PowerInputs::default(),
            startup_left: params.startup_cycles,
            demand: pos,
            prev_target: params.initial_position,
            last_step: 0,
            following_error: 0,
            tx: TxPdo::default(),
            last_cmd: RxPdo {
                mode: 0,
                controlword: Controlword::DISABLE_VOLTAGE,
                target_position: params.initial_position,
                ..RxPdo::default()
            },
            comm: DriveComm::new(profile.comm_check, params.comm, cycle_time, counter_mapped),
            op: true,
            sdo_mode: 0,
            sdo_values: Vec::new(),
            saving_left: 0,
            homing: HomingState::default(),
            stroke: StrokeState::default(),
            mstop: ManualStop::default(),
            home_set: HomeSettingState::default(),
            pp: ProfilePosition::default(),
            fsoe: params
                .fsoe
                .zip(profile.fsoe)
                .map(|(p, f)| FsoeSlave::new(f, p, cycle_time.as_micros())),
        };
        d.pp.reset(pos, 0);
        d.plant.prepare_cycle(cycle_time.as_secs_f64());
        d.power_on_checks();
        d.tx = d.make_tx();
        d
    }

    /// Runs `rx` and `tx` as the drive's PDO mapping from now on: a variable mapping the master
    /// wrote by SDO (taken when the EtherCAT emulator goes to SAFE-OP), checked against the
    /// model's [`crate::profiles::PdoRules`].
    pub fn remap(
        &mut self,
        rx: &[crate::pdo::PdoEntry],
        tx: &[crate::pdo::PdoEntry],
    ) -> Result<(), crate::profiles::mapping::MappingError> {
        let profile = self.profile.with_pdo_maps(rx, tx)?;
        self.profile = profile;
        self.rx_layout = PdoLayout::new(&profile.rx_pdo);
        self.tx_layout = PdoLayout::new(&profile.tx_pdo);
        self.mode_mapped = profile.rx_pdo.maps(crate::pdo::objects::MODES_OF_OPERATION);
        self.comm
            .set_counter_mapped(profile.rx_pdo.has_counter() && profile.tx_pdo.has_counter());
        Ok(())
    }

    /// The settings the amplifier checks at power-on: the axis switch SW3 against the
    /// profile's refused setting (MR-J5-G-N1 1-axis AL.011.2, TV-14; the moment of detection is
    /// [inferred], see [`AxisSwitch`]).
    fn power_on_checks(&mut self) {
        // MR-J3-T04 §2.4, TV-IC-5: free-run (PO02 = 0001h) with the incremental-counter check
        // enabled (PO03 digit 0 ≠ 0) is a parameter error.
        if let crate::profiles::CommCheck::IncrementalCounter { free_run_alarm, .. } =
            self.profile.comm_check
        {
            let comm = self.params.comm;
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

    /// The FSoE connection parameter set from the master (mr-jet-g-n1.md §7.1 item 4; see
    /// [`FsoeSlave::connect`]). A slave address other than [Pr. PSC07] raises the profile's
    /// AL.584.1 and returns [`FsoeError::AddressMismatch`]. Without FSoE on this drive:
    /// [`FsoeError::NotSupported`].
    pub fn fsoe_connect(&mut self, params: &ConnectionParams) -> Result<(), FsoeError> {
        let model = self.profile.model;
        let f = self
            .fsoe
            .as_mut()
            .ok_or(FsoeError::NotSupported { model })?;
        let r = f.connect(params);
        if let Err(FsoeError::AddressMismatch { alarm, .. }) = r {
            self.raise(alarm);
            self.tx = self.make_tx();
        }
        r
    }

    /// One safety PDO exchange: the master's frame `rx` (1608h, 11 bytes) in, the slave's
    /// frame (1A08h) into `tx`. Call it once per bus cycle next to [`SimDrive::cycle`]; a cycle
    /// without it counts against the FSoE watchdog. Bad sizes return an error and change
    /// nothing. Allocation-free.
    pub fn fsoe_exchange(&mut self, rx: &[u8], tx: &mut [u8]) -> Result<(), FsoeError> {
        let model = self.profile.model;
        let speed = self.plant.velocity();
        let f = self
            .fsoe
            .as_mut()
            .ok_or(FsoeError::NotSupported { model })?;
        let layout = self
            .profile
            .fsoe
            .map(|x| x.frame)
            .ok_or(FsoeError::NotSupported { model })?;
        if tx.len() != usize::from(layout.len) {
            return Err(FsoeError::FrameLength {
                expected: usize::from(layout.len),
                actual: tx.len(),
            });
        }
        let frame = FsoeFrame::decode(&layout, rx)?;
        f.frame(&frame, speed).encode(&layout, tx)
    }

    /// The FSoE status the slave reports now (`None` without FSoE).
    pub fn fsoe_status(&self) -> Option<SafetyStatus> {
        let speed = self.plant.velocity();
        self.fsoe.as_ref().map(|f| f.status(speed))
    }

    /// The FSoE slave, if configured.
    pub fn fsoe(&self) -> Option<&FsoeSlave> {
        self.fsoe.as_ref()
    }

    /// STO is in effect (FSoE): the drive cannot be switched on and gives no torque.
    pub fn safe_torque_off(&self) -> bool {
        self.fsoe.as_ref().is_some_and(FsoeSlave::sto)
    }

    /// Sets the DIP switch SW3; the amplifier reads it at the next power-on
    /// ([`SimDrive::power_cycle`]).
    pub fn set_axis_switch(&mut self, switch: AxisSwitch) {
        self.params.axis_switch = switch;
    }

    /// SDO download of 6060h Modes of operation. Refused with the model's abort code when 6060h
    /// is mapped in the RxPDO (MR-J3-T04 §3.9: 0x06010000; MR-J4-TM/MR-JET/MR-J5: 0x06010006).
    /// The switch itself waits for zero speed like a PDO request and stays pending until then.
    pub fn sdo_write_mode(&mut self, raw: i8) -> Result<(), u32> {
        self.sdo_download(crate::pdo::objects::MODES_OF_OPERATION, 0, &[raw as u8])
            .map_err(|e| e.0)
    }

    /// One bus cycle: decode `rx`, run the PDS and the plant for `elapsed` cycles, encode `tx`.
    ///
    /// `elapsed` is the number of cycle periods since the previous call (1 in steady state).
    /// A bad image size returns an error and changes nothing.
    pub fn cycle(&mut self, rx: &[u8], tx: &mut [u8], elapsed: Cycles) -> Result<(), PdoError> {
        let cmd = self.rx_layout.decode_rx(rx)?;
        self.tx_layout.check_len(tx.len())?;
        if self.op {
            if let Some(code) = self.comm.received(cmd.counter) {
                self.raise(code);
            }
        }
        self.last_step = cmd
            .target_position
            .wrapping_sub(self.last_cmd.target_position);
        self.last_cmd = cmd;
        self.run(cmd, elapsed);
        self.tx_layout.encode_tx(&self.tx, tx)
    }

    /// One bus cycle in which this drive's RxPDO did not arrive (lost or late frame): the
    /// communication checks count it, the drive keeps the previous command (§1.5 free-run rule;
    /// the DC-mode behaviour is not stated), the counter echo repeats last good + 1.
    pub fn cycle_lost(&mut self, tx: &mut [u8], elapsed: Cycles) -> Result<(), PdoError> {
        self.tx_layout.check_len(tx.len())?;
        if self.op {
            if let Some(code) = self.comm.lost() {
                self.raise(code);
            }
        }
        let cmd = self.last_cmd;
        self.run(cmd, elapsed);
        self.tx_layout.encode_tx(&self.tx, tx)
    }

    /// A SYNC0 in DC mode that brought no RxPDO: counted like [`SimDrive::cycle_lost`], the
    /// command per [`SimDriveParams::dc_missed_command`].
    pub fn cycle_missed_sync0(&mut self, tx: &mut [u8]) -> Result<(), PdoError> {
        self.tx_layout.check_len(tx.len())?;
        if self.op {
            if let Some(code) = self.comm.lost() {
                self.raise(code);
            }
        }
        let mut cmd = self.last_cmd;
        if self.params.dc_missed_command == MissedCommand::Extrapolate {
            cmd.target_position = cmd.target_position.wrapping_add(self.last_step);
            self.last_cmd.target_position = cmd.target_position;
        }
        self.run(cmd, Cycles(1));
        self.tx_layout.encode_tx(&self.tx, tx)
    }

    fn run(&mut self, cmd: RxPdo, elapsed: Cycles) {
        self.saving_left = self.saving_left.saturating_sub(elapsed.0);
        if let Some(code) = self.fsoe.as_mut().and_then(|f| f.tick(elapsed.0)) {
            self.raise(code);
        }
        let dt = self.cycle_time.as_secs_f64() * f64::from(elapsed.0);
        // Outside OP the controlword and the command values are not acted on (spec §2.1).
        let cw = if self.op {
            cmd.controlword
        } else {
            self.prev_cw
        };
        self.run_pds(cw, elapsed);
        if self.op {
            let raw = if self.mode_mapped {
                cmd.mode
            } else {
                self.sdo_mode
            };
            self.switch_mode(raw);
        }
        if self.op {
            self.run_homing(cw);
        }
        self.apply_torque_limits(&cmd);
        self.run_plant(&cmd, dt);
        self.run_home_setting(&cmd);
        self.tx = self.make_tx();
    }

    /// Controlword2 home setting and the Z phase, on models that have them (MR-J3-T04 §8.3).
    fn run_home_setting(&mut self, cmd: &RxPdo) {
        let Some(bits) = self.profile.home_setting else {
            return;
        };
        let raw = self.plant.position().round() as i64;
        if let Some(cpr) = self.profile.units.counts_per_rev {
            let z = ZPhase {
                counts_per_rev: i64::from(cpr),
                position: i64::from(self.params.z_phase_position),
            };
            self.home_set.track_encoder(raw, z);
        }
        let cyclic_position_or_velocity = matches!(
            self.mode_display,
            ModeOfOperation::CyclicSyncPosition | ModeOfOperation::CyclicSyncVelocity
        );
        if !(self.op && cyclic_position_or_velocity) {
            self.home_set.ignore(cmd.controlword2, &bits);
            return;
        }
        let position = self.position_actual();
        match self.home_set.controlword2(
            cmd.controlword2,
            &bits,
            position,
            self.params.before_z_reaction,
        ) {
            Some(HomeSettingOutcome::HomeOffset(v)) => {
                self.homing.home_offset = v;
                // PD22 note: the CR rising edge also clears the droop pulses.
                self.demand = self.plant.position();
            }
            Some(HomeSettingOutcome::Alarm(code)) => self.raise(code),
            None => {}
        }
    }

    /// The torque limits in effect for `cmd`, % of rated torque: (positive / CCW driving,
    /// negative / CW driving), per the profile's [`TorqueLimitSelection`].
    pub fn torque_limits_percent(&self, cmd: &RxPdo) -> (f64, f64) {
        let objects = (
            f64::from(cmd.torque_limit_positive) / 10.0,
            f64::from(cmd.torque_limit_negative) / 10.0,
        );
        match self.profile.torque_limit_selection {
            TorqueLimitSelection::Objects => objects,
            TorqueLimitSelection::Controlword2 {
                c_tl_bit,
                c_tl1_bit,
            } => {
                // §9.4 table: each direction takes the lowest of the selected sources.
                let p = self.params.internal_torque_limits;
                let bit = |b: u8| cmd.controlword2 & (1 << b) != 0;
                let (mut fwd, mut rev) = (p.pa11_forward, p.pa12_reverse);
                if bit(c_tl1_bit) {
                    fwd = fwd.min(p.pc35_internal);
                    rev = rev.min(p.pc35_internal);
                }
                if bit(c_tl_bit) {
                    fwd = fwd.min(objects.0);
                    rev = rev.min(objects.1);
                }
                (fwd, rev)
            }
            TorqueLimitSelection::TorqueLimit2 { cptl_bit, cntl_bit } => {
                let t2 = self.params.torque_limit_2;
                let bit = |b: u8| t2.select && cmd.controlword.0 & (1 << b) != 0;
                (
                    if bit(cptl_bit) {
                        f64::from(t2.positive) / 10.0
                    } else {
                        objects.0
                    },
                    if bit(cntl_bit) {
                        f64::from(t2.negative) / 10.0
                    } else {
                        objects.1
                    },
                )
            }
        }
    }

    fn apply_torque_limits(&mut self, cmd: &RxPdo) {
        let (pos, neg) = self.torque_limits_percent(cmd);
        let max = InternalTorqueLimits::MOTOR_MAXIMUM_PERCENT;
        self.plant.set_torque_limits(pos / max, neg / max);
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
        let alarm = operating.then_some(self.profile.leave_op_alarm);
        if let Some(code) = alarm {
            self.raise(code);
        } else if self.profile.reinit_on_leaving_op
            && !self.state.is_fault()
            && self.state != FsaState::NotReadyToSwitchOn
        {
            self.state = FsaState::SwitchOnDisabled;
        }
        self.op = false;
        self.tx = self.make_tx();
        alarm
    }

    /// The AL state returns to OP: the checks start afresh with the next frame.
    pub fn enter_op(&mut self) {
        if !self.op {
            self.op = true;
            self.comm.reset();
        }
    }

    /// Distributed clocks start with SYNC0 every `sync0_ns` (SAFE-OP → OP). On a model whose
    /// manual names an alarm for it, a SYNC0 cycle other than the PDO cycle the master wrote
    /// to 1C32h:02 raises that alarm (mr-j3-t04.md TV-IC-5, §8.2.3(1)); returns it.
    pub fn start_sync(&mut self, sync0_ns: u32) -> Option<u16> {
        let alarms = self.profile.pdo_rules.sync_mismatch_alarms;
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
        self.comm.reset();
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
                    // (15) resets only the alarms a fault reset can clear; the others stay
                    // latched until a power cycle (e.g. MR-J3-T04 AL.34/36/61).
                    match self.alarm {
                        Some(code) if !self.profile.alarm_resettable(code) => {}
                        _ => {
                            self.alarm = None;
                            self.state = next;
                        }
                    }
                } else {
                    self.state = next;
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
        if self.profile.power_warnings.is_some() && !self.power.main_circuit {
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
    fn servo_on(&mut self) {
        self.demand = self.plant.position();
        self.plant.set_last_command(self.demand);
        self.prev_target = self.position_actual().wrapping_sub(self.position_offset());
        self.pp.reset(self.demand, self.prev_cw.0);
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
        let gated = crate::cia402::mode_switch::switch_needs_zero_speed(old, mode);
        if gated && self.plant.velocity().abs() > self.params.zero_speed {
            return;
        }
        self.mode_display = mode;
        self.demand = self.plant.position();
        self.plant.set_last_command(self.demand);
        self.prev_target = self.position_actual().wrapping_sub(self.position_offset());
        self.pp.reset(self.demand, self.prev_cw.0);
    }

    /// 60B0h Position offset, added to 607Ah in csp (mr-j5-g-n1.md §4.3 rule 2, mr-jet-g-n1.md
    /// §4.3 rule 3: "607Ah + 60B0h follow 6064h"); only on models that list 60B0h, 0 unless
    /// written by SDO.
    pub fn position_offset(&self) -> i32 {
        if self.profile.object(POSITION_OFFSET, 0).is_none() {
            return 0;
        }
        self.sdo_value(POSITION_OFFSET, 0)
            .or_else(|| self.profile.object(POSITION_OFFSET, 0)?.default)
            .unwrap_or(0) as i32
    }

    /// An object pp reads: from the RxPDO where the map carries it, else the SDO value, else
    /// the profile's default.
    fn pp_object(&self, cmd: &RxPdo, index: u16) -> Option<i64> {
        if self.profile.rx_pdo.maps(index) {
            if let Some(f) = RxField::of(index, 0) {
                return Some(cmd.get(f) as i64);
            }
        }
        self.sdo_value(index, 0)
            .or_else(|| self.profile.object(index, 0)?.default)
    }

    /// This cycle's pp inputs (sim units: counts, counts/s; 6083h/6084h ms time constants).
    fn pp_command(&self, cmd: &RxPdo) -> PpCommand {
        let plant = self.params.plant;
        let pp = self.params.pp;
        let amax = plant.max_acceleration.abs();
        let ref_speed = pp
            .time_constant_speed
            .filter(|v| v.is_finite() && *v > 0.0)
            .unwrap_or(plant.max_velocity.abs());
        let ramp = |ms: Option<i64>| match ms {
            Some(ms) if ms > 0 => (ref_speed * 1000.0 / ms as f64).min(amax),
            _ => amax,
        };
        let mut velocity = self
            .pp_object(cmd, PROFILE_VELOCITY)
            .unwrap_or(i64::from(pp.profile_velocity)) as f64;
        if let Some(max) = self.pp_object(cmd, 0x607F) {
            velocity = velocity.min(max as f64);
        }
        let velocity = velocity.clamp(0.0, plant.max_velocity.abs());
        let deceleration = ramp(self.pp_object(cmd, PROFILE_DECELERATION));
        let window = self
            .pp_object(cmd, POSITION_WINDOW)
            .map_or(pp.position_window, |v| v as u32);
        let window_ms = self
            .pp_object(cmd, POSITION_WINDOW_TIME)
            .map_or(pp.position_window_time_ms, |v| v as u32);
        PpCommand {
            controlword: cmd.controlword.0,
            target: cmd.target_position,
            velocity,
            acceleration: ramp(self.pp_object(cmd, PROFILE_ACCELERATION)),
            deceleration,
            halt_deceleration: match pp.halt {
                HaltOption::ProfileDeceleration => deceleration,
                HaltOption::MaximumDeceleration => amax,
            },
            window,
            window_time_s: f64::from(window_ms) / 1000.0,
            relative_refused: match self.params.position_unit {
                PositionUnit::Degree => self.profile.relative_degree_warning,
                PositionUnit::Pulse => None,
            },
        }
    }

    /// pp in Operation enabled: the drive's own profile toward the accepted set-point
    /// (`sim::profile_position`), followed by the servo loop; following error checked as csp.
    fn follow_profile_position(&mut self, cmd: &RxPdo, dt: f64) {
        let c = self.pp_command(cmd);
        let fb = PpFeedback {
            actual: self.position_actual(),
            position: self.plant.position(),
            velocity: self.plant.velocity(),
        };
        self.demand = self.pp.step(&c, fb, dt);
        let ff = self.params.velocity_feedforward * self.pp.velocity();
        self.plant.step(self.demand, ff, dt);
        self.prev_target = cmd.target_position;
        self.following_error = self.position_demand().wrapping_sub(self.position_actual());
        if self.following_error.unsigned_abs() > self.params.following_error_limit {
            self.raise(self.following_error_code());
        }
    }

    fn run_plant(&mut self, cmd: &RxPdo, dt: f64) {
        self.following_error = 0;
        if let Some(stop) = self.fsoe.filter(FsoeSlave::sto).map(|f| f.sto_stop()) {
            // STO: energy cut, no torque from the drive.
            match stop {
                StoStop::Coast => self.plant.coast(dt),
                StoStop::DynamicBrake => self.plant.hold(dt),
            }
            self.demand = self.plant.position();
            return;
        }
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

    fn overspeed_limit(&self) -> f64 {
        self.params
            .overspeed_limit
            .unwrap_or(1.2 * self.params.plant.max_velocity.abs())
    }

    fn following_error_code(&self) -> u16 {
        self.params
            .alarm_codes
            .map_or(self.profile.following_error_alarm, |c| c.0)
    }

    fn overspeed_code(&self) -> u16 {
        self.params
            .alarm_codes
            .map_or(self.profile.overspeed_alarm, |c| c.1)
    }

    /// Servo on in the current mode. csp follows 607Ah, csv integrates 60FFh (clamped at the
    /// overspeed limit), cst applies 6071h (0.1 % rated, 300 % = `max_acceleration`) within the
    /// speed limit 2D20h (counts/s), pp runs the drive's own profile (`sim::profile_position`).
    /// pv and tq are not simulated and hold the position.
    /// HALT (bit 8) stops and holds where the model honours it in the cyclic modes.
    fn follow(&mut self, cmd: &RxPdo, dt: f64) {
        if self.profile.power_warnings.is_some() && !self.power.em1 {
            // EM1 OFF: base off, dynamic-brake stop; the commands stay live (§3.7).
            self.plant.hold(dt);
            self.demand = self.plant.position();
            self.prev_target = cmd.target_position;
            return;
        }
        if self.mode_display == ModeOfOperation::ProfilePosition {
            // pp handles HALT itself (605Dh, mr-j4-tm.md §4.7).
            self.follow_profile_position(cmd, dt);
            return;
        }
        if cmd.controlword.halt() && self.profile.halt_in_cyclic_modes {
            self.plant.hold(dt);
            self.demand = self.plant.position();
            self.prev_target = cmd.target_position;
            return;
        }
        if self.mode_display == ModeOfOperation::CyclicSyncTorque {
            let amax = self.params.plant.max_acceleration.abs();
            let a = f64::from(cmd.target_torque) / 3000.0 * amax;
            self.plant.step_torque(a, self.cst_velocity_limit(cmd), dt);
            self.demand = self.plant.position();
            self.prev_target = self.position_actual();
            return;
        }
        let manual_stop =
            self.mode_display == ModeOfOperation::CyclicSyncPosition && self.manual_stop(cmd, dt);
        let ff = match self.mode_display {
            ModeOfOperation::CyclicSyncPosition if manual_stop => 0.0,
            ModeOfOperation::CyclicSyncPosition => {
                // Work in the i32 domain relative to the actual position so 607Ah may wrap;
                // the command is 607Ah + 60B0h (§4.3 rule 2).
                let rel = cmd
                    .target_position
                    .wrapping_add(self.position_offset())
                    .wrapping_sub(self.position_actual());
                self.demand = self.plant.position() + f64::from(rel);
                let step = cmd.target_position.wrapping_sub(self.prev_target);
                self.prev_target = cmd.target_position;
                if dt > 0.0 && f64::from(step).abs() / dt > self.overspeed_limit() {
                    // A command implying more than the maximum speed (MR-J3-T04 AL.35).
                    self.raise(self.overspeed_code());
                    return;
                }
                if dt > 0.0 {
                    self.params.velocity_feedforward * f64::from(step) / dt
                } else {
                    0.0
                }
            }
            ModeOfOperation::CyclicSyncVelocity => {
                let lim = self.overspeed_limit();
                let v = f64::from(cmd.target_velocity).clamp(-lim, lim);
                let v = self.stroke_limited_velocity(v, dt);
                self.demand += v * dt;
                v
            }
            _ => 0.0,
        };
        self.plant.step(self.demand, ff, dt);
        // 60F4h = demand − 6064h in the wrapping i32 domain of the wire values (the demand in
        // 6064h's reference: shifted like it after a homing preset).
        let demand = self.position_demand();
        let demand = match self.mode_display {
            ModeOfOperation::CyclicSyncPosition => {
                cmd.target_position.wrapping_add(self.position_offset())
            }
            _ => demand,
        };
        self.following_error = demand.wrapping_sub(self.position_actual());
        let checked = matches!(
            self.mode_display,
            ModeOfOperation::CyclicSyncPosition | ModeOfOperation::ProfilePosition
        );
        if checked && self.following_error.unsigned_abs() > self.params.following_error_limit {
            self.raise(self.following_error_code());
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
        (self.plant.position().round() as i64).wrapping_add(self.homing.position_shift) as i32
    }

    /// hm (6060h = 6): a rising controlword bit 4 (HOS) starts the method in 6098h. The
    /// data-set methods set home at the current position at once, without motion (also outside
    /// Operation enabled, mr-j3-t04.md §8.1); a method the manual does not list, or 0, ends in
    /// a homing error (bit 13). Methods that search a dog, a stroke end or the Z phase are not
    /// simulated (no dog or Z-phase model) and also end in a homing error.
    fn run_homing(&mut self, cw: Controlword) {
        let hos = cw.0 & (1 << 4) != 0;
        let start = hos && !self.homing.hos;
        self.homing.hos = hos;
        if self.mode_display != ModeOfOperation::Homing || !start {
            return;
        }
        if matches!(self.state, FsaState::Fault | FsaState::FaultReactionActive) {
            return;
        }
        let method = self
            .sdo_value(0x6098, 0)
            .or_else(|| self.profile.object(0x6098, 0).and_then(|o| o.default))
            .unwrap_or(0) as i8;
        // Homing start clears bit 12 (mr-j4-tm.md §4.10 retention rules).
        self.homing.attained = false;
        self.homing.error = false;
        if !self.profile.data_set_homing_methods.contains(&method) {
            self.homing.error = true;
            return;
        }
        let raw = (self.plant.position().round() as i64) as i32;
        match self.profile.home_reference {
            HomeReference::OffsetObject => self.homing.home_offset = raw.wrapping_neg(),
            HomeReference::PositionPreset => {
                self.homing.position_shift =
                    i64::from(self.params.home_position_address) - i64::from(raw);
                // Re-reference the held command so the motor does not move.
                self.demand = self.plant.position();
                self.plant.set_last_command(self.demand);
                self.prev_target = self.position_actual();
            }
        }
        self.homing.attained = true;
    }

    /// The cst speed limit: the velocity-limit object (2D20h) as received where the RxPDO maps
    /// it, else its SDO value or default (0 where none is given); a model without such an
    /// object (plain CiA 402: the speed in cst is bounded by 6080h Max motor speed, not by a
    /// cyclic object) runs up to the motor's maximum speed.
    fn cst_velocity_limit(&self, cmd: &RxPdo) -> f64 {
        let index = crate::pdo::objects::VELOCITY_LIMIT;
        if self.profile.rx_pdo.maps(index) {
            return f64::from(cmd.velocity_limit);
        }
        match self.profile.object(index, 0) {
            Some(o) => self.sdo_value(index, 0).or(o.default).unwrap_or(0) as f64,
            None => f64::INFINITY,
        }
    }

    /// Sets the stroke-end inputs LSP (CCW allowed) and LSN (CW allowed); ON = may run. On a
    /// model with a stroke-end warning an input OFF raises it (MR-J3-T04 AL.99, §9.1); it
    /// clears by itself once both are ON again and the slow stop is over.
    pub fn set_stroke_end_inputs(&mut self, lsp: bool, lsn: bool) {
        self.stroke.lsp = lsp;
        self.stroke.lsn = lsn;
    }

    /// csv under the stroke-end rules (mr-j3-t04.md §9.1, TV-STROKE-1): moving into an OFF
    /// input starts a PC02 slow stop during which 60FFh is discarded; after the stop the
    /// blocked direction stays refused and the other one is accepted.
    fn stroke_limited_velocity(&mut self, v: f64, dt: f64) -> f64 {
        if self.profile.stroke_end_warning.is_none() {
            return v;
        }
        let moving = self.plant.velocity();
        let blocked = |dir: f64, s: &StrokeState| (dir > 0.0 && !s.lsp) || (dir < 0.0 && !s.lsn);
        if !self.stroke.stopping
            && blocked(moving, &self.stroke)
            && moving.abs() > self.params.zero_speed
        {
            self.stroke.stopping = true;
            self.stroke.ramp_velocity = moving;
        }
        self.stroke.warning = !(self.stroke.lsp && self.stroke.lsn) || self.stroke.stopping;
        if self.stroke.stopping {
            let decel = self.slow_stop_deceleration();
            let r = self.stroke.ramp_velocity;
            let next = r - r.signum() * decel * dt;
            self.stroke.ramp_velocity = if next * r <= 0.0 { 0.0 } else { next };
            // "Until the motor has stopped once": the motor, not only the ramp (at or below
            // `zero_speed`, and never above 1 count/s).
            if self.stroke.ramp_velocity == 0.0 && moving.abs() <= self.params.zero_speed.max(1.0) {
                self.stroke.stopping = false;
            }
            return self.stroke.ramp_velocity;
        }
        if blocked(v, &self.stroke) {
            0.0
        } else {
            v
        }
    }

    /// The PC02 deceleration of slow stops (stroke end, manual stop), counts/s².
    fn slow_stop_deceleration(&self) -> f64 {
        let amax = self.params.plant.max_acceleration.abs();
        if self.params.slow_stop_time_ms == 0 {
            amax
        } else {
            (self.params.plant.max_velocity.abs() * 1000.0
                / f64::from(self.params.slow_stop_time_ms))
            .min(amax)
        }
    }

    /// csp with C_MSTOP (mr-j3-t04.md §9.2): while it is on, 607Ah is discarded and the demand
    /// ramps linearly to rest with PC02; S_FLW = 1 once it has been fully output. Cleared, the
    /// drive tracks 607Ah again from where it stopped (the master copies 6062h into 607Ah
    /// first, or the motor jumps to the old target). True while the manual stop owns the demand.
    fn manual_stop(&mut self, cmd: &RxPdo, dt: f64) -> bool {
        let Some(bit) = self.profile.manual_stop_bit else {
            return false;
        };
        let on = cmd.controlword2 & (1 << bit) != 0;
        if on && !self.mstop.active {
            self.mstop = ManualStop {
                active: true,
                ramp_velocity: self.plant.velocity(),
                done: false,
            };
        }
        if !on {
            if self.mstop.active {
                self.mstop = ManualStop::default();
                self.prev_target = cmd.target_position;
            }
            return false;
        }
        let r = self.mstop.ramp_velocity;
        let next = r - r.signum() * self.slow_stop_deceleration() * dt;
        self.mstop.ramp_velocity = if next * r <= 0.0 { 0.0 } else { next };
        self.demand += 0.5 * (r + self.mstop.ramp_velocity) * dt;
        self.mstop.done = self.mstop.ramp_velocity == 0.0;
        self.prev_target = cmd.target_position;
        true
    }

    /// 6062h Position demand value, counts (what the master copies into 607Ah after a manual
    /// stop).
    pub fn position_demand(&self) -> i32 {
        (self.demand.round() as i64).wrapping_add(self.homing.position_shift) as i32
    }

    /// 607Ch Home offset.
    pub fn home_offset(&self) -> i32 {
        self.homing.home_offset
    }

    fn make_tx(&self) -> TxPdo {
        let oe = self.state == FsaState::OperationEnabled;
        let mut sw = Statusword::for_state(self.state)
            .with_drive_follows_command(oe && self.mode_display.is_cyclic() && !self.mstop.active);
        if self.mstop.active && self.mstop.done {
            sw.0 |= 1 << 14; // S_FLW
        }
        if self.warning().is_some() {
            sw.0 |= 1 << 7;
        }
        if oe && self.mode_display == ModeOfOperation::ProfilePosition {
            // pp bits 10 / 12 (mr-j4-tm.md §4.7).
            sw.0 |= self.pp.status_bits();
        }
        if self.mode_display == ModeOfOperation::Homing {
            // hm bits 13 / 12 / 10 (mr-j4-tm.md §4.10): no simulated method moves, so target
            // reached (bit 10) is always 1: "not started", "completed" or "error, v = 0".
            sw.0 = (sw.0 & !((1 << 13) | (1 << 12) | (1 << 10)))
                | (u16::from(self.homing.error) << 13)
                | (u16::from(self.homing.attained) << 12)
                | (1 << 10);
        }
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
            counter: self.comm.echo(),
            statusword2: self
                .profile
                .home_setting
                .map_or(0, |b| self.home_set.statusword2(&b)),
        }
    }

    /// The PDS state.
    pub fn state(&self) -> FsaState {
        self.state
    }

    /// The active warning code, if any (statusword bit 7); the most severe first: EM1 (AL.E6),
    /// main circuit off (AL.E9), stroke end (AL.99).
    pub fn warning(&self) -> Option<u16> {
        let pw = self.profile.power_warnings;
        if let Some((e6, e9)) = pw {
            if !self.power.em1 {
                return Some(e6);
            }
            if self.power.main_off_warning {
                return Some(e9);
            }
        }
        if let Some(w) = self.pp.warning() {
            return Some(w);
        }
        if let Some(w) = self
            .profile
            .home_setting
            .and_then(|b| self.home_set.warning(&b))
        {
            return Some(w);
        }
        self.profile
            .stroke_end_warning
            .filter(|_| self.stroke.warning)
    }

    /// Sets the main circuit power input. Off in Switched on or Operation enabled goes to Ready
    /// to switch on (8B); Enable operation while it is off raises AL.E9 and stays there
    /// (mr-j3-t04.md §3.7, on models with [`DriveProfile::power_warnings`]).
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

    /// The last RxPDO received (held over lost frames).
    pub fn last_command(&self) -> &RxPdo {
        &self.last_cmd
    }

    /// Whether a parameter save (1010h:01) is still running.
    pub fn saving(&self) -> bool {
        self.saving_left > 0
    }

    pub(super) fn start_saving(&mut self) {
        let ms = u64::from(self.params.store_parameters_ms);
        let cycles = self
            .cycle_time
            .cycles_for(std::time::Duration::from_millis(ms))
            .0
            .max(1);
        self.saving_left = cycles;
    }

    pub(super) fn set_sdo_mode(&mut self, raw: i8) {
        self.sdo_mode = raw;
    }

    pub(super) fn sdo_value(&self, index: u16, sub: u8) -> Option<i64> {
        self.sdo_values
            .iter()
            .find(|(i, s, _)| *i == index && *s == sub)
            .map(|v| v.2)
    }

    pub(super) fn store_sdo_value(&mut self, index: u16, sub: u8, value: i64) {
        match self
            .sdo_values
            .iter_mut()
            .find(|(i, s, _)| *i == index && *s == sub)
        {
            Some(v) => v.2 = value,
            None => self.sdo_values.push((index, sub, value)),
        }
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
