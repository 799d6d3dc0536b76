//! The configuration file as written: serde structs with defaults, no cross-field checks.

use std::path::PathBuf;

use serde::Deserialize;

/// Top level of a cell configuration file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawCellConfig {
    /// `[cell]`.
    pub cell: RawCell,
    /// `[rt]`.
    #[serde(default)]
    pub rt: RawRt,
    /// `[recording]`.
    #[serde(default)]
    pub recording: RawRecording,
    /// `[setpoints]`.
    #[serde(default)]
    pub setpoints: RawSetpoints,
    /// `[watchdogs]`.
    #[serde(default)]
    pub watchdogs: RawWatchdogs,
    /// `[operator]`: who besides the cell's user may command it.
    #[serde(default)]
    pub operator: RawOperator,
    /// `[live]`: the live view.
    #[serde(default)]
    pub live: RawLive,
    /// `[[inject]]`: scheduled fault injection.
    #[serde(default)]
    pub inject: Vec<RawInjection>,
    /// `[ethercat]`: the EtherCAT segment of axes with `transport = "ethercat"`.
    #[serde(default)]
    pub ethercat: Option<RawEthercat>,
    /// `[[axes]]`.
    #[serde(default)]
    pub axes: Vec<RawAxis>,
}

/// `[operator]`.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawOperator {
    /// A group whose members may command the cell besides its user.
    pub group: Option<String>,
}

/// `[ethercat]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawEthercat {
    /// Network interface of the segment, or "in-process" for the emulated segment.
    pub interface: String,
    /// A cyclic frame not back within this time is lost, µs.
    pub frame_timeout_us: Option<u32>,
}

/// `[axes.ethercat]`: the identity the drive must report, where it differs from the model's.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawEthercatAxis {
    /// 1018h:01 required.
    pub vendor_id: Option<u32>,
    /// 1018h:02 required.
    pub product_code: Option<u32>,
    /// SYNC0 from distributed clocks on this SubDevice (default true); false: free-run.
    pub distributed_clocks: Option<bool>,
    /// `[[axes.ethercat.startup_sdo]]`: downloads made in PRE-OP before the PDO configuration.
    #[serde(default)]
    pub startup_sdo: Vec<RawStartupSdo>,
}

/// `[[axes.ethercat.startup_sdo]]`: one download of the axis' start-up list.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawStartupSdo {
    /// The object: index in hex with an optional decimal sub-index, e.g. "2001h" or "6085:0".
    pub object: String,
    /// The value.
    pub value: i64,
    /// Its CiA 301 type ("bool", "i8", "u8", "i16", "u16", "i32", "u32"); may be left out for
    /// an object the drive's dictionary lists.
    #[serde(rename = "type")]
    pub data_type: Option<String>,
}

/// `[axes.pdo]`: a PDO mapping other than the model's default, as CoE mapping words
/// (`index << 16 | sub << 8 | bits`, e.g. 0x60400010).
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawPdo {
    /// RxPDO entries (master → drive), in order.
    pub rx: Option<Vec<u32>>,
    /// TxPDO entries (drive → master), in order.
    pub tx: Option<Vec<u32>>,
}

/// `[cell]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawCell {
    /// Cell name.
    pub name: String,
    /// Cycle time in µs.
    pub cycle_time_us: u32,
    /// Default program, relative to the config file.
    pub program: Option<PathBuf>,
}

/// `[rt]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawRt {
    /// CPU to pin to.
    pub cpu: Option<usize>,
    /// SCHED_FIFO priority.
    #[serde(default = "default_priority")]
    pub priority: u8,
    /// The planner thread's SCHED_FIFO priority (0: SCHED_OTHER).
    #[serde(default = "default_planner_priority")]
    pub planner_priority: u8,
    /// mlockall.
    #[serde(default = "default_true")]
    pub lock_memory: bool,
    /// Keep cellrt's other threads off `cpu`.
    #[serde(default = "default_true")]
    pub reserve_cpu: bool,
    /// "skip" or "stretch": what a late cycle does with the deadlines it missed.
    #[serde(default = "default_missed_deadlines")]
    pub missed_deadlines: String,
}

impl Default for RawRt {
    fn default() -> Self {
        RawRt {
            cpu: None,
            priority: default_priority(),
            planner_priority: default_planner_priority(),
            lock_memory: true,
            reserve_cpu: true,
            missed_deadlines: default_missed_deadlines(),
        }
    }
}

fn default_missed_deadlines() -> String {
    "skip".into()
}

/// `[recording]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawRecording {
    /// Record by default.
    #[serde(default = "default_true")]
    pub enabled: bool,
    /// Path template.
    #[serde(default = "default_recording_path")]
    pub path: String,
    /// "zstd", "lz4" or "none".
    #[serde(default = "default_compression")]
    pub compression: String,
    /// Chunk size in KiB.
    #[serde(default = "default_chunk_kib")]
    pub chunk_size_kib: u64,
    /// Hand-off queue length in seconds of cycles.
    #[serde(default = "default_queue_seconds")]
    pub queue_seconds: f64,
    /// Longest time between chunk flushes, ms.
    #[serde(default = "default_flush_ms")]
    pub flush_ms: u64,
    /// Rotate to a new file at this size, MiB.
    #[serde(default)]
    pub rotate_mib: Option<u64>,
    /// Rotate to a new file after this many seconds.
    #[serde(default)]
    pub rotate_seconds: Option<f64>,
    /// "continuous" or "triggered".
    #[serde(default = "default_recording_mode")]
    pub mode: String,
    /// Triggered: seconds kept before a trigger.
    #[serde(default = "default_capture_s")]
    pub pre_s: f64,
    /// Triggered: seconds written after it.
    #[serde(default = "default_capture_s")]
    pub post_s: f64,
    /// Triggered: event kinds and thresholds.
    #[serde(default)]
    pub triggers: Vec<String>,
}

fn default_recording_mode() -> String {
    "continuous".into()
}

fn default_capture_s() -> f64 {
    5.0
}

impl Default for RawRecording {
    fn default() -> Self {
        RawRecording {
            enabled: true,
            path: default_recording_path(),
            compression: default_compression(),
            chunk_size_kib: default_chunk_kib(),
            queue_seconds: default_queue_seconds(),
            flush_ms: default_flush_ms(),
            rotate_mib: None,
            rotate_seconds: None,
            mode: default_recording_mode(),
            pre_s: default_capture_s(),
            post_s: default_capture_s(),
            triggers: Vec::new(),
        }
    }
}

/// `[setpoints]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawSetpoints {
    /// Planner lookahead in ms.
    #[serde(default = "default_lookahead_ms")]
    pub lookahead_ms: f64,
    /// Delay from first publish to first cycle of a move, ms.
    #[serde(default = "default_start_delay_ms")]
    pub start_delay_ms: f64,
    /// How late a motion's first block may reach the RT thread and still start, ms (absent:
    /// 100 ms, or what the setpoint buffer holds beyond the lookahead if that is less).
    pub max_start_slip_ms: Option<f64>,
}

impl Default for RawSetpoints {
    fn default() -> Self {
        RawSetpoints {
            lookahead_ms: default_lookahead_ms(),
            start_delay_ms: default_start_delay_ms(),
            max_start_slip_ms: None,
        }
    }
}

/// `[watchdogs]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawWatchdogs {
    /// Consecutive overrun cycles that trigger `overrun_reaction`; 0 disables.
    #[serde(default = "default_consecutive_overruns")]
    pub max_consecutive_overruns: u32,
    /// Reaction to consecutive overruns.
    #[serde(default = "default_reaction")]
    pub overrun_reaction: String,
    /// Reaction to a setpoint underrun or a rejected setpoint during motion.
    #[serde(default = "default_reaction")]
    pub underrun_reaction: String,
    /// Reaction of the other axes when one drive faults.
    #[serde(default = "default_reaction")]
    pub drive_fault_reaction: String,
    /// Reaction to any communication watchdog.
    #[serde(default = "default_reaction")]
    pub communication_reaction: String,
    /// Cyclic frames lost in a row that stop the cell; 0 disables.
    #[serde(default = "default_max_lost_frames")]
    pub max_lost_frames: u32,
    /// Working-counter errors in a row that stop the cell; 0 disables.
    #[serde(default = "default_max_working_counter_errors")]
    pub max_working_counter_errors: u32,
    /// Cycles a SubDevice may stay out of OP; 0 disables.
    #[serde(default = "default_max_cycles_out_of_op")]
    pub max_cycles_out_of_op: u32,
    /// Incremental-counter errors in a row (default: the model's).
    pub counter_continuous_errors: Option<u32>,
    /// Incremental-counter errors within the window (default: the model's).
    pub counter_intermittent_errors: Option<u32>,
    /// The intermittent check's window, cycles (default: the model's).
    pub counter_intermittent_window: Option<u32>,
}

impl Default for RawWatchdogs {
    fn default() -> Self {
        RawWatchdogs {
            max_consecutive_overruns: default_consecutive_overruns(),
            overrun_reaction: default_reaction(),
            underrun_reaction: default_reaction(),
            drive_fault_reaction: default_reaction(),
            communication_reaction: default_reaction(),
            max_lost_frames: default_max_lost_frames(),
            max_working_counter_errors: default_max_working_counter_errors(),
            max_cycles_out_of_op: default_max_cycles_out_of_op(),
            counter_continuous_errors: None,
            counter_intermittent_errors: None,
            counter_intermittent_window: None,
        }
    }
}

/// `[[inject]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawInjection {
    /// When, in ms after the RT loop starts.
    pub at_ms: f64,
    /// "stall", "drive_alarm" or "planner_stall".
    pub fault: String,
    /// Axis name (drive_alarm).
    pub axis: Option<String>,
    /// Alarm code, 603Fh (drive_alarm).
    pub code: Option<u32>,
    /// Duration in ms (stall, planner_stall, rx_loss, … link_loss).
    pub duration_ms: Option<f64>,
    /// Frame delay in µs (frame_delay).
    pub delay_us: Option<f64>,
}

/// `[[axes]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawAxis {
    /// Axis name.
    pub name: String,
    /// Drive model name, e.g. "mr-j5-g-n1".
    pub drive: String,
    /// "sim" or "ethercat".
    #[serde(default = "default_transport")]
    pub transport: String,
    /// `[axes.ethercat]`.
    #[serde(default)]
    pub ethercat: RawEthercatAxis,
    /// `[axes.pdo]`.
    #[serde(default)]
    pub pdo: RawPdo,
    /// Mode name, e.g. "csp".
    #[serde(default = "default_mode")]
    pub mode: String,
    /// MR-J4-TM [Pr. PA01] control-mode group: "cyclic" (csp/csv/cst/hm, the default) or
    /// "profile" (pp/pv/tq/hm).
    pub mode_group: Option<String>,
    /// Unit name for display.
    #[serde(default = "default_unit")]
    pub unit: String,
    /// Counts per unit.
    pub counts_per_unit: f64,
    /// `[axes.limits]`.
    pub limits: RawLimits,
    /// `[axes.sim]`.
    #[serde(default)]
    pub sim: RawSimAxis,
    /// `[axes.motor]`.
    #[serde(default)]
    pub motor: RawMotor,
    /// `[axes.homing]`.
    #[serde(default)]
    pub homing: Option<RawHoming>,
    /// Multi-axis amplifier this axis belongs to (any label, e.g. "w3-1"); axes with the same
    /// label share one unit. None: the axis has an amplifier of its own.
    #[serde(default)]
    pub amplifier: Option<String>,
    /// The axis' slot on its amplifier, 0-based (0 = axis A); defaults to the order in the file.
    #[serde(default)]
    pub amplifier_axis: Option<u8>,
    /// csv: gain of the master's position correction added to the velocity setpoint, 1/s.
    pub csv_position_gain: Option<f64>,
    /// The drive's ESI file (ETG.2000 XML), relative to the config file (`drive = "cia402"`).
    pub esi: Option<PathBuf>,
    /// The device in the ESI file, by its Type (order code) or Name.
    pub esi_device: Option<String>,
    /// The device in the ESI file, by its product code.
    pub esi_product_code: Option<u32>,
    /// The device in the ESI file, by its revision.
    pub esi_revision: Option<u32>,
    /// `[axes.je_c]`: how an `mr-je-c` axis is reached.
    pub je_c: Option<RawJecAxis>,
}

/// `[axes.limits]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawLimits {
    /// `[min, max]` in units.
    pub position: [f64; 2],
    /// unit/s.
    pub velocity: f64,
    /// unit/s².
    pub acceleration: f64,
    /// unit/s³.
    pub jerk: f64,
    /// Controlled-stop deceleration, unit/s²; defaults to `acceleration`.
    pub stop_deceleration: Option<f64>,
    /// Controlled-stop jerk, unit/s³; defaults to `jerk`.
    pub stop_jerk: Option<f64>,
    /// Following-error alarm limit in units; defaults to 1 s × velocity / 10.
    pub following_error: Option<f64>,
    /// Largest torque a cst setpoint may ask for, % of rated torque (required for cst).
    pub torque: Option<f64>,
    /// Largest torque change, % of rated torque per second.
    pub torque_slope: Option<f64>,
}

/// `[axes.motor]`: the motor behind the drive and the drive's velocity unit where its manual
/// leaves it open.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawMotor {
    /// Encoder counts per motor revolution (rotary motor).
    pub counts_per_rev: Option<f64>,
    /// Encoder counts per mm (linear motor).
    pub counts_per_mm: Option<f64>,
    /// The unit of the drive's velocity objects, e.g. "0.01 r/min" or "counts/s".
    pub velocity_unit: Option<String>,
    /// The motor's maximum speed, r/min (rotary) or mm/s (linear).
    pub max_speed: Option<f64>,
    /// The motor's rated speed, r/min (rotary) or mm/s (linear): the speed the drive's
    /// 6083h/6084h time constants refer to (profile axes).
    pub rated_speed: Option<f64>,
}

/// `[axes.homing]`: the homing method and its objects (6099h, 609Ah, the shift).
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawHoming {
    /// 6098h method of a `home` naming none.
    pub method: Option<i8>,
    /// 6099h:1 speed during search for switch, unit/s.
    pub switch_speed: Option<f64>,
    /// 6099h:2 speed during search for zero (creep), unit/s.
    pub creep_speed: Option<f64>,
    /// 609Ah homing acceleration time constant, ms.
    pub acceleration_ms: Option<u32>,
    /// Home position shift distance from the Z phase, unit.
    pub shift: Option<f64>,
    /// How long a homing may take, s.
    pub timeout_s: Option<f64>,
}

/// `[axes.sim]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawSimAxis {
    /// Start position in units.
    #[serde(default)]
    pub initial_position: f64,
    /// Position loop bandwidth, Hz.
    #[serde(default = "default_position_bw")]
    pub position_bandwidth_hz: f64,
    /// Velocity loop bandwidth, Hz.
    #[serde(default = "default_velocity_bw")]
    pub velocity_bandwidth_hz: f64,
    /// Position of the encoder's Z phase, in units.
    #[serde(default)]
    pub z_phase_position: f64,
    /// The motor's speed as a multiple of the axis velocity limit.
    #[serde(default = "default_motor_speed_factor")]
    pub motor_speed_factor: f64,
    /// Emulated SubDevice (`drive = "cia402"`): 1C32h:02 "read-write", "read-only" or "absent".
    #[serde(default)]
    pub cycle_time_object: Option<String>,
    /// Emulated SubDevice (`drive = "cia402"`): 60F4h in the object dictionary.
    #[serde(default)]
    pub following_error_object: Option<bool>,
    /// Emulated SubDevice (`drive = "cia402"`): distributed clocks "optional", "required" or
    /// "absent".
    #[serde(default)]
    pub distributed_clocks: Option<String>,
    /// Emulated SubDevice (EtherCAT axes): how long its firmware takes to answer an SDO, ms.
    #[serde(default)]
    pub sdo_response_ms: Option<f64>,
    /// The home dog's `[from, to]`, unit.
    #[serde(default)]
    pub home_dog: Option<[f64; 2]>,
    /// The positive limit switch (on at and above), unit.
    #[serde(default)]
    pub positive_limit: Option<f64>,
    /// The negative limit switch (on at and below), unit.
    #[serde(default)]
    pub negative_limit: Option<f64>,
    /// The simulated drive's "travel distance after proximity dog" (MR-J4-TM manual
    /// §5.4.9(4)), unit.
    #[serde(default)]
    pub travel_after_dog: Option<f64>,
    /// The emulated MR-J4-TM's [Pr. PA01] group at power-on ("cyclic" or "profile"); by
    /// default the axis' `mode_group` (a drive already set up).
    #[serde(default)]
    pub mode_group: Option<String>,
}

impl Default for RawSimAxis {
    fn default() -> Self {
        RawSimAxis {
            initial_position: 0.0,
            position_bandwidth_hz: default_position_bw(),
            velocity_bandwidth_hz: default_velocity_bw(),
            z_phase_position: 0.0,
            motor_speed_factor: default_motor_speed_factor(),
            cycle_time_object: None,
            following_error_object: None,
            distributed_clocks: None,
            sdo_response_ms: None,
            home_dog: None,
            positive_limit: None,
            negative_limit: None,
            travel_after_dog: None,
            mode_group: None,
        }
    }
}

fn default_motor_speed_factor() -> f64 {
    crate::DEFAULT_MOTOR_SPEED_FACTOR
}

fn default_true() -> bool {
    true
}
fn default_priority() -> u8 {
    80
}
fn default_planner_priority() -> u8 {
    crate::DEFAULT_PLANNER_PRIORITY
}
fn default_recording_path() -> String {
    "recordings/{cell}-{timestamp}.mcap".to_string()
}
fn default_compression() -> String {
    "zstd".to_string()
}
fn default_flush_ms() -> u64 {
    200
}

fn default_chunk_kib() -> u64 {
    1024
}
fn default_queue_seconds() -> f64 {
    2.0
}
fn default_lookahead_ms() -> f64 {
    50.0
}
fn default_start_delay_ms() -> f64 {
    20.0
}
fn default_consecutive_overruns() -> u32 {
    10
}
fn default_max_lost_frames() -> u32 {
    super::DEFAULT_MAX_LOST_FRAMES
}
fn default_max_working_counter_errors() -> u32 {
    super::DEFAULT_MAX_WORKING_COUNTER_ERRORS
}
fn default_max_cycles_out_of_op() -> u32 {
    super::DEFAULT_MAX_CYCLES_OUT_OF_OP
}
fn default_reaction() -> String {
    "controlled_stop".to_string()
}
fn default_transport() -> String {
    "sim".to_string()
}
fn default_mode() -> String {
    "csp".to_string()
}
fn default_unit() -> String {
    "unit".to_string()
}
fn default_position_bw() -> f64 {
    40.0
}
fn default_velocity_bw() -> f64 {
    200.0
}

/// `[live]`.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawLive {
    /// Where the Foxglove WebSocket server listens (none: no live view).
    #[serde(default)]
    pub listen: Option<String>,
    /// The live page's port on the same IP (none: the live view's port + 1).
    #[serde(default)]
    pub page_port: Option<i64>,
}

/// `[axes.je_c]` as written.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawJecAxis {
    /// The drive's IP address (Ethernet transports).
    pub address: Option<String>,
    /// The drive's port, where not the transport's own (61450, 5010, 502).
    pub port: Option<u16>,
    /// The serial device of the RS-485 line (modbus-rtu).
    pub serial: Option<PathBuf>,
    /// The drive's station number on the line, 1–247 (modbus-rtu).
    pub station: Option<u8>,
    /// The line's bit rate (modbus-rtu; 115200 by default).
    pub baud: Option<u32>,
    /// Link period, ms (≥ 10; 10 by default).
    pub period_ms: Option<u64>,
    /// How long one exchange waits for its answer, ms (50 by default).
    pub response_timeout_ms: Option<u64>,
    /// The master's watchdog: answers missed in a row that stop the axis (3 by default; 0
    /// switches it off).
    pub watchdog_missed: Option<u32>,
    /// The watchdog's reaction (`watchdogs.communication_reaction` by default).
    pub watchdog_reaction: Option<String>,
    /// The drive's own time-out for this transport, ms, written at start-up: [Pr. PN02]
    /// (cclink-ief-basic, ms), [Pr. PN10] (slmp, modbus-tcp, whole seconds), [Pr. PF46]
    /// (modbus-rtu, whole seconds). Not written when absent (the drive keeps its setting).
    pub drive_timeout_ms: Option<u64>,
    /// Pos units per motor revolution (6092h:1; 131072 by default, the encoder resolution).
    pub counts_per_rev: Option<f64>,
    /// The motor's rated speed, r/min, that 6083h/6084h refer to (3000 by default).
    pub rated_speed: Option<f64>,
    /// Start an emulated MR-JE-C for the axis on loopback (a pseudo-terminal for
    /// modbus-rtu) instead of reaching a real drive.
    #[serde(default)]
    pub emulate: bool,
    /// `mode = "indexer"`: the stations per revolution, [Pr. PT28] (2–255).
    pub stations: Option<u32>,
    /// `mode = "point_table"`: point tables 1, 2, … (2801h–28FFh), written at start-up.
    #[serde(default)]
    pub point_table: Vec<RawPointTable>,
}

/// One `[[axes.je_c.point_table]]` as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawPointTable {
    /// Target position, units.
    pub position: f64,
    /// Speed, unit/s (the axis' velocity limit when absent).
    pub velocity: Option<f64>,
    /// Acceleration, unit/s² (the axis' limit when absent).
    pub acceleration: Option<f64>,
    /// Deceleration, unit/s² (the acceleration when absent).
    pub deceleration: Option<f64>,
    /// M code 2D6Ah reads on completion (0–99).
    pub m_code: Option<u8>,
}
