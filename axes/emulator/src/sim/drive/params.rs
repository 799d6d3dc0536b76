//! The configuration of a simulated drive: the values the manuals leave to the amplifier's
//! parameters or do not state.

use super::units::SimMotor;
#[cfg(doc)]
use super::{SimDrive, FOLLOWING_ERROR_ALARM};
use crate::motion::profile_position::{PositionUnit, PpParams};
use crate::motion::profile_torque::TqParams;
use crate::motion::profile_velocity::PvParams;
use crate::sim::comm::CommParams;
use crate::sim::fsoe::FsoeSlaveParams;
use crate::sim::home_setting::BeforeZReaction;
use crate::sim::plant::{PlantParams, Stoppers};
use cellrt_cia402::mode::ModeOfOperation;
#[cfg(doc)]
use cellrt_cia402::profiles::{DriveProfile, HomeReference, TorqueLimitSelection};

/// Configuration of one simulated drive.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimDriveParams {
    /// The motor and its servo loops.
    pub plant: PlantParams,
    /// The motor's kind and encoder resolution, and the velocity unit where the manual leaves
    /// it open: how 60FFh / 2D20h / 606Ch map to the plant's motion.
    pub motor: SimMotor,
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
    /// Statusword bit 13 following error window in counts, where 6065h has not been written
    /// (the manuals give no default; default 100 000, half the default alarm limit).
    pub following_error_window: u32,
    /// Statusword bit 13 following error time out in ms, where 6066h has not been written
    /// (the manuals give no default; default 10 ms).
    pub following_error_time_out_ms: u16,
    /// S_INP in-position range in counts ([Pr. PA10]; the manuals' default is 100 pulses
    /// [background]): the droop at or below which a position mode reports in-position.
    pub in_position_range: u32,
    /// The fixed part of the S_SA speed-reached band, counts/s (MR-J4-TM manual §5.3.2: 20
    /// r/min, here in the simulated motor's counts; default 0: the 5 % part only).
    pub speed_reached_band: f64,
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
    /// (MR-J3-T04 manual §3.9, §8.11.7); "rated speed" is taken as `plant.max_velocity`. 0: stop at the
    /// plant's maximum deceleration.
    pub slow_stop_time_ms: u32,
    /// How long a parameter save through 1010h:01 takes (MR-JET-G-N1 manual: "about 25 s").
    pub store_parameters_ms: u32,
    /// 6064h after a homing on a drive that presets it ([`HomeReference::PositionPreset`],
    /// MR-J4-TM): the "home position address" parameter, not in the extract; default 0.
    pub home_position_address: i32,
    /// What the drive commands at a SYNC0 that brought no RxPDO in DC mode (the manuals state
    /// only the free-run rule — hold the last command — and leave DC mode unstated).
    pub dc_missed_command: MissedCommand,
    /// What C_CR2 before the first Z phase raises on a model with Controlword2 home setting
    /// (MR-J3-T04: AL.96 warning by default, AL.26 selectable; MR-J3-T04 manual §7.1, §7.2, §3.7, §3.9, §5.1, §8.5.2).
    pub before_z_reaction: BeforeZReaction,
    /// Raw position of the encoder's Z phase within a revolution (counts; the manual gives no
    /// figure, TV-HOME-1 uses 262100); default 0.
    pub z_phase_position: i32,
    /// The home dog and limit switches on the axis, raw counts (60FDh and the searching
    /// homing methods, `sim::homing_switches`); default none.
    pub homing_switches: crate::sim::homing_switches::HomingSwitches,
    /// Mechanical stoppers on the axis, raw counts: hard stops the plant cannot pass (the
    /// stopper type homing −4/−36 presses against one); default none.
    pub stoppers: Stoppers,
    /// The homing figures the manuals name without a value (`motion::homing_search`).
    pub homing: HomingParams,
    /// The alarm a SYNC0 cycle other than 1C32h:02 raises, one of the profile's
    /// `pdo.rules.sync_mismatch_alarms` (MR-J3-T04 TV-IC-5: AL.76 or AL.74); `None`: the
    /// profile's first.
    pub sync_mismatch_alarm: Option<u16>,
    /// Profile position mode (pp) values the manuals leave open (`motion::profile_position`).
    pub pp: PpParams,
    /// Profile velocity mode (pv) objects the manuals leave open (`motion::profile_velocity`).
    pub pv: PvParams,
    /// Profile torque mode (tq) behaviour the manuals leave open (`motion::profile_torque`).
    pub tq: TqParams,
    /// [Pr. PT01.2] position data unit (acts on relative pp set-points, MR-J4-TM manual §5.4.6).
    pub position_unit: PositionUnit,
    /// The DIP switch SW3 (axis selection) as set on the amplifier, read at power-on; see
    /// [`AxisSwitch`].
    pub axis_switch: AxisSwitch,
    /// FSoE safety process data (safety PDOs 1608h/1A08h) on a model with FSoE
    /// ([`DriveProfile::fsoe`], MR-JET-G-N1); `None` (default): FSoE not used, no STO from the
    /// network. See `sim::fsoe`.
    pub fsoe: Option<FsoeSlaveParams>,
}

/// The MR-J4-TM homing figures its manual names but gives neither number nor default for
/// (MR-J4-TM manual §5.4.9(4), (6)(b), (d)–(f), (i): the "travel distance after proximity dog";
/// §5.4.9(6)(d): [Pr. PT10] and [Pr. PT11], named in the stopper figure only). The defaults
/// are the simulator's choice, each stated below.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HomingParams {
    /// "Travel distance after proximity dog", raw counts (≥ 0, in the search direction): the
    /// count types −2/−34 (then the Z phase) and −7/−39, the dog types −6/−38 (from the rear
    /// end) and −10/−42, and 19–24, 27, 28. Default 0: home on the dog edge itself (+ shift);
    /// −2/−34 then fail with AL. 90 at any 6099h:1 above the creep speed, as the manual warns
    /// ("set the travel distance after proximity dog enough for deceleration").
    pub travel_after_dog: u32,
    /// [Pr. PT10] Stopper type home position return stopper time, ms: how long the motor
    /// stands at its torque limit before −4/−36 take the position as home. Default 100 ms
    /// (the simulator's choice; the figure marks only "5 ms or longer").
    pub stopper_time_ms: u16,
    /// [Pr. PT11] stopper type torque limit, % of rated torque: while −4/−36 search, the
    /// torque in the search direction is limited to the lower of this and the torque limit
    /// object the manual names for the method (60E0h for −4, 60E1h for −36). Default 15.0 %
    /// (the simulator's choice: "the home position return speed must be low enough").
    pub stopper_torque_limit: f64,
}

impl Default for HomingParams {
    fn default() -> Self {
        HomingParams {
            travel_after_dog: 0,
            stopper_time_ms: 100,
            stopper_torque_limit: 15.0,
        }
    }
}

/// DIP switch SW3 of the MR-J5-G-N1 family (MR-J5-G-N1 manual §2.2, §3.1, §4.3, §4.4, TV-14; ON = up).
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

/// 2D6Dh Torque limit 2 (MR-JET-G-N1 manual/§9.1), in 0.1 % of rated torque; defaults per the
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

/// MR-J3-T04 torque-limit parameters, % of rated torque (MR-J3-T04 manual §8.14, §1.2.1). Their defaults
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
            motor: SimMotor::default(),
            initial_position: 0,
            following_error_limit: 200_000,
            startup_cycles: 2,
            velocity_feedforward: 0.0,
            zero_speed: 0.0,
            in_position_range: 100,
            following_error_window: 100_000,
            following_error_time_out_ms: 10,
            speed_reached_band: 0.0,
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
            homing_switches: crate::sim::homing_switches::HomingSwitches::default(),
            stoppers: Stoppers::default(),
            homing: HomingParams::default(),
            sync_mismatch_alarm: None,
            axis_switch: AxisSwitch::default(),
            fsoe: None,
            slow_stop_time_ms: 0,
            store_parameters_ms: 25_000,
            pp: PpParams::default(),
            pv: PvParams::default(),
            tq: TqParams::default(),
            position_unit: PositionUnit::Pulse,
        }
    }
}

/// A drive's command in a DC cycle whose RxPDO is missing (a named parameter: the manuals
/// are silent, MR-J4-TM manual §1.1(4) and MR-J5-G-N1 manual §6 state only the free-run hold).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MissedCommand {
    /// Keep the last command (the free-run rule): a moving csp axis stops for the cycle and
    /// the next target jumps by two cycles' travel.
    Hold,
    /// csp: continue the last target step (the interpolator runs on); csv/cst: hold.
    #[default]
    Extrapolate,
}
