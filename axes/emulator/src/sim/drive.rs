//! The simulated drive: PDS, modes, alarms, communication checks and PDO images around a
//! [`ServoPlant`], with every model difference read from its [`DriveProfile`].
//!
//! Follows the simulator checklists ("What a faithful simulator must reproduce") of the four
//! EtherCAT spec extracts where this crate models them: PDS with the model's quirks (shortcuts,
//! no quick stop on the MR-J3-T04 with statusword bit 5 always 1, no transition 16), quick stop
//! ending in SOD, Fault Reset on the edge clearing only resettable alarms (the rest need
//! [`SimDrive::power_cycle`]), statusword bits 8/14 = 0 and no statusword in NRTSO, byte-exact
//! default maps, the zero-speed gate on mode switches, csp/csv/cst with the torque limits, pp,
//! pv and tq (`motion::profile_position`, `motion::profile_velocity`, `motion::profile_torque`) with
//! the 605Ah quick-stop and 605Dh halt decelerations, the csp position offset 60B0h,
//! following-error and overspeed alarms, the communication checks of `sim::comm`, and the alarm
//! on leaving OP while switched on ([`SimDrive::leave_op`]), the axis switch SW3 checked at
//! power-on ([`AxisSwitch`]), and FSoE safety process data with STO acting on the PDS and the
//! plant where configured (`sim::fsoe`, [`SimDrive::fsoe_exchange`]). Deterministic and
//! allocation-free.

use super::comm::DriveComm;
use super::fsoe::FsoeSlave;
use super::home_setting::HomeSettingState;
use super::plant::ServoPlant;
use crate::motion::profile_position::ProfilePosition;
use crate::motion::profile_torque::ProfileTorque;
use crate::motion::profile_velocity::ProfileVelocity;
use cellrt_cia402::controlword::Controlword;
use cellrt_cia402::cycles::{CycleTime, Cycles};
use cellrt_cia402::fsa::FsaState;
use cellrt_cia402::mode::ModeOfOperation;
use cellrt_cia402::pdo::objects::{TxExtras, POSITION_DEMAND, STATUSWORD2};
use cellrt_cia402::pdo::{PdoError, PdoLayout, RxPdo, TxPdo};
use cellrt_cia402::profiles::SharedProfile;
use cellrt_cia402::statusword::Statusword;

/// Error code (603Fh) of the following-error alarm: CiA 402 8611h "following error"
/// [background]; each model's code is `LimitFacts::following_error_alarm`.
pub const FOLLOWING_ERROR_ALARM: u16 = cellrt_cia402::error_code::FOLLOWING_ERROR;

pub mod alarm_history;
mod following_error;
mod homing;
mod modes;
mod objects;
mod parameters;
mod params;
mod pds;
mod pp;
mod pv_tq;
mod safety;
mod status_do;
mod stroke;
mod units;

use homing::HomingState;
pub use params::{
    AxisSwitch, HomingParams, InternalTorqueLimits, MissedCommand, SimDriveParams, TorqueLimit2,
};
use pds::PowerInputs;
use stroke::{ManualStop, StrokeState};
pub use units::{SimMotor, SIM_DEFAULT_COUNTS_PER_REV};

/// One simulated servo axis that exchanges PDO images like the real drive.
#[derive(Debug, Clone)]
pub struct SimDrive {
    profile: SharedProfile,
    /// The profile's objects for the per-cycle lookups ([`SimDrive::object`]).
    od: cellrt_cia402::profiles::ObjectIndex,
    /// 60B0h's default where the model lists 60B0h (read every cycle in csp).
    position_offset_default: Option<Option<i64>>,
    /// 605Ah's default (read every cycle by the PDS step; none where the manual states none).
    quick_stop_option_default: Option<i64>,
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
    /// The TxPDO carries Status DO 1 (2D11h): the Status DO words are computed.
    status_do_mapped: bool,
    /// True if the TxPDO maps 6062h Position demand value (MR-J3-T04 §4.5: mappable).
    position_demand_mapped: bool,
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
    /// Seconds the droop has stayed at or above the following error window (statusword bit 13).
    following_error_over: f64,
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
    /// Saved parameters and the `*` parameters' power-on values (`drive::parameters`).
    memory: parameters::ParameterMemory,
    /// The alarm history (`drive::alarm_history`).
    history: alarm_history::AlarmHistory,
    /// Cycles since the first start, for the history's hours of operation.
    uptime_cycles: u64,
    /// Homing state (hm): 607Ch, the 6064h preset, statusword bits 12/13, the HOS edge.
    homing: HomingState,
    /// Stroke-end inputs and the stop they cause.
    stroke: StrokeState,
    /// csp manual stop (MR-J3-T04 C_MSTOP, Controlword2 bit 8).
    mstop: ManualStop,
    /// The ramp velocity (counts/s) of a quick stop on the 6085h time constant, while one runs.
    quick_stop_ramp: Option<f64>,
    home_set: HomeSettingState,
    /// Profile position mode (pp): set-point handshake and trajectory generator.
    pp: ProfilePosition,
    /// Profile velocity mode (pv): the velocity ramp and its statusword bits.
    pv: ProfileVelocity,
    /// Profile torque mode (tq): the torque ramp.
    tq: ProfileTorque,
    /// The FSoE slave, when configured on a model with FSoE.
    fsoe: Option<FsoeSlave>,
}

impl SimDrive {
    /// A drive at rest in Not ready to switch on, running the `profile`'s default maps.
    pub fn new(
        profile: impl Into<SharedProfile>,
        params: SimDriveParams,
        cycle_time: CycleTime,
    ) -> Self {
        let profile: SharedProfile = profile.into();
        let pos = f64::from(params.initial_position);
        let counter_mapped = profile.pdo.rx.has_counter() && profile.pdo.tx.has_counter();
        // An unsupported initial mode falls back to csp, or to the first mode the profile
        // lists where csp is not in its group (MR-J4-TM PA01 `___2`: pp).
        let initial_mode = if profile.supports_mode(params.initial_mode) {
            params.initial_mode
        } else if profile.supports_mode(ModeOfOperation::CyclicSyncPosition) {
            ModeOfOperation::CyclicSyncPosition
        } else {
            profile
                .cycle
                .modes
                .first()
                .copied()
                .unwrap_or(ModeOfOperation::CyclicSyncPosition)
        };
        let mut d = SimDrive {
            profile: profile.clone(),
            od: cellrt_cia402::profiles::ObjectIndex::of(&profile),
            position_offset_default: profile
                .object(cellrt_cia402::pdo::objects::POSITION_OFFSET, 0)
                .map(|o| o.default),
            quick_stop_option_default: profile
                .object(cellrt_cia402::pdo::objects::QUICK_STOP_OPTION, 0)
                .and_then(|o| o.default),
            params,
            cycle_time,
            state: FsaState::NotReadyToSwitchOn,
            prev_cw: Controlword::DISABLE_VOLTAGE,
            mode_display: initial_mode,
            plant: ServoPlant::new(params.plant, pos).with_stoppers(params.stoppers),
            rx_layout: PdoLayout::new(&profile.pdo.rx),
            mode_mapped: profile
                .pdo
                .rx
                .maps(cellrt_cia402::pdo::objects::MODES_OF_OPERATION),
            status_do_mapped: profile
                .pdo
                .tx
                .maps(cellrt_cia402::pdo::objects::STATUS_DO[0]),
            position_demand_mapped: profile.pdo.tx.maps(POSITION_DEMAND),
            tx_layout: PdoLayout::new(&profile.pdo.tx),
            alarm: None,
            power: PowerInputs::default(),
            startup_left: params.startup_cycles,
            demand: pos,
            prev_target: params.initial_position,
            last_step: 0,
            following_error: 0,
            following_error_over: 0.0,
            tx: TxPdo::default(),
            last_cmd: RxPdo {
                mode: 0,
                controlword: Controlword::DISABLE_VOLTAGE,
                target_position: params.initial_position,
                ..RxPdo::default()
            },
            comm: DriveComm::new(profile.comm.check, params.comm, cycle_time, counter_mapped),
            op: true,
            sdo_mode: 0,
            // One slot per object of the dictionary: an SDO write never allocates.
            sdo_values: Vec::with_capacity(profile.objects.len()),
            saving_left: 0,
            memory: parameters::ParameterMemory::default(),
            history: alarm_history::AlarmHistory::default(),
            uptime_cycles: 0,
            homing: HomingState::default(),
            stroke: StrokeState::default(),
            mstop: ManualStop::default(),
            quick_stop_ramp: None,
            home_set: HomeSettingState::default(),
            pp: ProfilePosition::default(),
            pv: ProfileVelocity::default(),
            tq: ProfileTorque::default(),
            fsoe: params
                .fsoe
                .zip(profile.fsoe)
                .map(|(p, f)| FsoeSlave::new(f, p, cycle_time.as_micros())),
        };
        d.pp.reset(pos, 0);
        d.plant.prepare_cycle(cycle_time.as_secs_f64());
        d.seed_saved_parameters();
        d.reload_parameters();
        d.seed_profile_selector();
        d.power_on_checks();
        d.tx = d.make_tx();
        d
    }

    /// A drive built with one of its model's other profiles holds the selecting parameter's
    /// value for it (an MR-J4-TM in the profile group reads [Pr. PA01] = 1002h, not 1000h), and
    /// starts in its group's mode where the one asked for is not in the group.
    fn seed_profile_selector(&mut self) {
        let Some(selector) = self.profile.profile_selector else {
            return;
        };
        let default = self
            .profile
            .object(selector.index, selector.sub)
            .and_then(|o| o.default)
            .unwrap_or(0);
        let name = self.profile.name;
        let selects = |v: i64| (selector.select)(v).filter(|(p, _)| p.name == name);
        let Some((value, (_, mode))) = (0..16)
            .map(|d| default & !0xF | d)
            .chain([default])
            .find_map(|v| selects(v).map(|s| (v, s)))
        else {
            return;
        };
        if value != default && selects(default).is_none() {
            self.store_sdo_value(selector.index, selector.sub, value);
        }
        if !self.profile.cycle.modes.contains(&self.mode_display) {
            self.mode_display = mode;
        }
    }

    /// Runs `rx` and `tx` as the drive's PDO mapping from now on: a variable mapping the master
    /// wrote by SDO (taken when the EtherCAT emulator goes to SAFE-OP), checked against the
    /// model's [`cellrt_cia402::profiles::PdoRules`].
    pub fn remap(
        &mut self,
        rx: &[cellrt_cia402::pdo::PdoEntry],
        tx: &[cellrt_cia402::pdo::PdoEntry],
    ) -> Result<(), cellrt_cia402::profiles::mapping::MappingError> {
        let profile = SharedProfile::new(self.profile.with_pdo_maps(rx, tx)?);
        self.adopt(profile);
        Ok(())
    }

    /// Runs the profile a parameter selected, starting in `mode` (its group's start-up mode).
    /// Its dictionary's defaults are the new profile's; 6061h shows `mode` at once.
    pub(crate) fn adopt_selected(&mut self, profile: SharedProfile, mode: ModeOfOperation) {
        self.od = cellrt_cia402::profiles::ObjectIndex::of(&profile);
        self.position_offset_default = profile
            .object(cellrt_cia402::pdo::objects::POSITION_OFFSET, 0)
            .map(|o| o.default);
        self.quick_stop_option_default = profile
            .object(cellrt_cia402::pdo::objects::QUICK_STOP_OPTION, 0)
            .and_then(|o| o.default);
        self.adopt(profile);
        self.mode_display = mode;
        self.tx = self.make_tx();
    }

    /// Runs `profile` from now on (its PDO maps, its modes): a remap, or a parameter that
    /// selects another of the model's profiles ([`cellrt_cia402::profiles::ProfileSelector`],
    /// MR-J4-TM [Pr. PA01]). A mode the new profile does not list becomes its first.
    pub(crate) fn adopt(&mut self, profile: SharedProfile) {
        self.rx_layout = PdoLayout::new(&profile.pdo.rx);
        self.tx_layout = PdoLayout::new(&profile.pdo.tx);
        self.mode_mapped = profile
            .pdo
            .rx
            .maps(cellrt_cia402::pdo::objects::MODES_OF_OPERATION);
        self.status_do_mapped = profile
            .pdo
            .tx
            .maps(cellrt_cia402::pdo::objects::STATUS_DO[0]);
        self.position_demand_mapped = profile.pdo.tx.maps(POSITION_DEMAND);
        self.comm
            .set_counter_mapped(profile.pdo.rx.has_counter() && profile.pdo.tx.has_counter());
        if !profile.cycle.modes.contains(&self.mode_display) {
            if let Some(&first) = profile.cycle.modes.first() {
                self.mode_display = first;
            }
        }
        self.profile = profile;
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
        self.uptime_cycles += u64::from(elapsed.0);
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
        self.watch_following_error(dt);
        self.run_home_setting(&cmd);
        self.tx = self.make_tx();
    }

    fn position_actual(&self) -> i32 {
        // Wraps like a 32-bit position counter.
        (self.plant.position().round() as i64).wrapping_add(self.homing.position_shift) as i32
    }

    /// 6062h Position demand value, counts (what the master copies into 607Ah after a manual
    /// stop).
    pub fn position_demand(&self) -> i32 {
        (self.demand.round() as i64).wrapping_add(self.homing.position_shift) as i32
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
        if self.following_error_bit() {
            sw.0 |= 1 << 13;
        }
        if oe && self.mode_display == ModeOfOperation::ProfilePosition {
            // pp bits 10 / 11 / 12 (MR-J4-TM manual §5.4.6).
            sw.0 |= self.pp.status_bits(&self.params.pp.model);
        }
        if oe && self.mode_display == ModeOfOperation::ProfileVelocity {
            // pv bits 10 / 12 (MR-J4-TM manual §5.4.7); tq sends none (§5.4.8).
            sw.0 |= self.pv.status_bits();
        }
        if self.mode_display == ModeOfOperation::Homing {
            sw.0 = (sw.0 & !((1 << 13) | (1 << 12) | (1 << 10))) | self.homing_status_bits();
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
            velocity_actual: self.reported_velocity(self.plant.velocity()),
            following_error: self.following_error,
            torque_actual: torque,
            error_code: self.alarm.unwrap_or(0),
            extras: self.tx_extras(),
        }
    }

    /// The TxPDO objects the profile adds to CiA 402: the counter echo its communication check
    /// names, statusword2 where it has a home setting, Status DO 1–3 where the map carries them.
    fn tx_extras(&self) -> TxExtras {
        let mut extras = TxExtras::default();
        // At most five objects: within the table's MAX_TX_EXTRAS.
        if let Some((_, index)) = self.profile.comm.check.counter_objects() {
            let _ = extras.set(index, 0, u64::from(self.comm.echo()));
        }
        if let Some(b) = self.profile.homing.setting {
            let sw2 = self.home_set.statusword2(&b);
            let _ = extras.set(STATUSWORD2, 0, u64::from(sw2));
        }
        if self.status_do_mapped {
            let _ = self.status_do().write_to(&mut extras);
        }
        if self.position_demand_mapped {
            let demand = self.position_demand() as u32;
            let _ = extras.set(POSITION_DEMAND, 0, u64::from(demand));
        }
        extras
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

    /// Lets the plant read an equal cycle map of `pool` (one table for identical axes of a bus;
    /// [`ServoPlant::share_cycle_map`]). Start-up only: allocates.
    pub fn share_cycle_map(&mut self, pool: &mut crate::sim::plant::CycleMapPool) {
        self.plant.share_cycle_map(pool);
    }

    /// The motor model.
    pub fn plant(&self) -> &ServoPlant {
        &self.plant
    }

    /// The last RxPDO received (held over lost frames).
    pub fn last_command(&self) -> &RxPdo {
        &self.last_cmd
    }

    /// The drive's profile.
    pub fn profile(&self) -> &SharedProfile {
        &self.profile
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
