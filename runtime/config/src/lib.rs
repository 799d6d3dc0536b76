//! The cell configuration: a TOML file parsed into raw serde structs ([`raw`]) and validated into
//! the typed [`CellConfig`] before anything starts. Every error names the file and the key.
//!
//! A crate of its own below the runtime, so that the tools, an external planner and the fuzz
//! targets read and check a cell's configuration without the RT thread and its services.

#![warn(missing_docs)]

pub mod axes;
pub mod capture;
mod comm_watchdog;
pub mod echo;
mod error;
pub mod events;
mod fault;
pub mod homing;
pub mod input_file;
pub mod je_c_axis;
pub mod je_c_positioning;
pub mod live;
pub mod plausible;
pub mod profile_axis;
pub mod raw;
mod validate;

pub use axes::{Axis, AxisKind, Backend, CellAxes};
pub use comm_watchdog::{
    CommWatchdog, CommWatchdogConfig, DEFAULT_MAX_CYCLES_OUT_OF_OP, DEFAULT_MAX_LOST_FRAMES,
    DEFAULT_MAX_WORKING_COUNTER_ERRORS,
};
pub use error::parse_toml;
pub use error::ConfigError;
pub use fault::{FaultKind, InjectedFault, Injection};
pub use profile_axis::{ProfileMode, ProfileObjects};

use std::path::{Path, PathBuf};

use cellrt_cia402::mode::ModeOfOperation;
use cellrt_cia402::profiles::{DriveModel, SharedProfile};
use cellrt_cia402::{CycleTime, Cycles};
use cellrt_emulator::ethercat::ScheduledFault;
use cellrt_trajectory::limits::{KinematicLimits, PositionRange};
use cellrt_trajectory::units::Scaling;

/// Most axes one cell may have: the width of a setpoint block.
pub const MAX_AXES: usize = 256;

/// Cycles covered by one setpoint block.
pub const BLOCK_CYCLES: usize = 16;

/// Setpoint blocks the RT thread's subscriber buffers (its lookahead, in blocks): bounds how far
/// ahead of the RT cycle a planner may publish.
pub const SETPOINT_BUFFER_BLOCKS: usize = 256;

/// A validated cell configuration.
#[derive(Debug, Clone)]
pub struct CellConfig {
    /// Where it was read from (for messages and the recording's attachment).
    pub source: PathBuf,
    /// The file's text, kept for the recording.
    pub text: String,
    /// Cell name: names the iceoryx2 services and the recording.
    pub name: String,
    /// Bus cycle time of the RT loop.
    pub cycle_time: CycleTime,
    /// Program run by default, resolved relative to the config file.
    pub program: Option<PathBuf>,
    /// RT thread settings.
    pub rt: RtConfig,
    /// Recording settings.
    pub recording: RecordingConfig,
    /// Setpoint transport settings.
    pub setpoints: SetpointConfig,
    /// Watchdogs and their fault reactions.
    pub watchdogs: WatchdogConfig,
    /// Who besides the cell's user may command it.
    pub operator: OperatorConfig,
    /// Where the live view (Foxglove WebSocket protocol) listens; none: no live view.
    pub live: Option<std::net::SocketAddr>,
    /// The live page's port beside the live view.
    pub live_page: live::PagePort,
    /// Scheduled fault injection, sorted by cycle (tests, commissioning drills).
    pub inject: Vec<Injection>,
    /// The axes, in configuration order, each with the backend that moves it.
    pub axes: CellAxes,
    /// The EtherCAT segment, where the axes use `transport = "ethercat"`.
    pub ethercat: Option<EthercatConfig>,
}

/// An axis of the cell as program steps, operator requests and the summary name it: the
/// backend that carries out its motion and its place there. Every command is refused or
/// dispatched on this one type, so no consumer keeps a list of its own per axis kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum AxisRef {
    /// Run by the RT loop (slot in [`CellAxes::on_loop`]): streamed setpoints in csp/csv/cst,
    /// or its drive's own profile generator over the cyclic bus (pp/pv/tq/hm).
    Loop(usize),
    /// Driven over its MR-JE-C link by an I/O thread of its own, never by the RT loop (index
    /// in [`CellAxes::on_link`]).
    Link(usize),
}

/// Who may command the cell: always the user that runs it (and root); with `group`, also the
/// members of that group (the operator socket is group-owned, mode 0660).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct OperatorConfig {
    /// The operator group, resolved when the configuration is read.
    pub group: Option<OperatorGroup>,
}

/// A local group whose members may command the cell.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OperatorGroup {
    /// Its name.
    pub name: String,
    /// Its id.
    pub gid: u32,
}

/// RT thread settings; each is best effort when the OS refuses it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RtConfig {
    /// CPU to pin the RT thread to; `None` leaves affinity alone.
    pub cpu: Option<usize>,
    /// SCHED_FIFO priority, 1..=99.
    pub priority: u8,
    /// SCHED_FIFO priority of the planner thread, the setpoint producer, below `priority`:
    /// so the recorder and services cannot hold back setpoints until the lookahead runs out
    /// (an underrun stops the cell). `None` (config 0): SCHED_OTHER.
    pub planner_priority: Option<u8>,
    /// mlockall(MCL_CURRENT | MCL_FUTURE) before the loop starts.
    pub lock_memory: bool,
    /// With `cpu` set: run cellrt's other threads (planner, recorder, services) on the other
    /// online CPUs, so they neither preempt the RT thread nor evict its caches (default true).
    pub reserve_cpu: bool,
    /// What a late cycle does with the deadlines it missed (`rt.missed_deadlines`).
    pub missed_deadlines: MissedDeadlines,
}

/// What the RT loop does when a cycle ends after later deadlines have passed (an overrun).
/// Either way the overrun is counted, recorded and watched by `max_consecutive_overruns`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MissedDeadlines {
    /// The missed cycles are skipped: the cell keeps wall-clock time, its setpoints step by
    /// the skipped cycles' travel (the default: real drives run on their own clock).
    #[default]
    Skip,
    /// No cycle is skipped: the next one runs at the next deadline on the cycle grid and the
    /// cell's clock falls behind wall time by the missed cycles. Deterministic in cycles
    /// whatever the machine's load; for drives that live on the master's clock (`transport =
    /// "sim"`, `interface = "in-process"`, `cellrt drive-sim ethercat --excuse-host-stalls`).
    Stretch,
}

impl MissedDeadlines {
    /// The names `rt.missed_deadlines` takes.
    pub const NAMES: &'static str = "\"skip\", \"stretch\"";

    /// The policy named `name` in a configuration.
    pub fn parse(name: &str) -> Option<Self> {
        match name {
            "skip" => Some(Self::Skip),
            "stretch" => Some(Self::Stretch),
            _ => None,
        }
    }
}

/// MCAP chunk compression.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Compression {
    /// zstd (default): smallest files.
    Zstd,
    /// lz4: cheaper to write.
    Lz4,
    /// No compression.
    None,
}

/// Recording settings.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordingConfig {
    /// Record unless the command line says otherwise.
    pub enabled: bool,
    /// Path template; `{cell}` and `{timestamp}` are substituted.
    pub path: String,
    /// Chunk compression.
    pub compression: Compression,
    /// Target chunk size in bytes (bounds what a crash can lose).
    pub chunk_size: u64,
    /// Hand-off queue length between the RT thread and the recorder, in seconds of cycles.
    pub queue_seconds: f64,
    /// The recorder closes the open chunk and flushes the file at least this often, ms
    /// (bounds in time what a crash can lose).
    pub flush_ms: u64,
    /// Start a new file once the current one has this many bytes (`None`: never).
    pub rotate_bytes: Option<u64>,
    /// Start a new file once the current one spans this many seconds (`None`: never).
    pub rotate_seconds: Option<f64>,
    /// Triggered capture instead of a continuous recording (`None`: continuous).
    pub capture: Option<capture::CaptureConfig>,
}

/// Setpoint transport settings.
#[derive(Debug, Clone, PartialEq)]
pub struct SetpointConfig {
    /// How far ahead of the RT cycle the planner keeps setpoints, in seconds.
    pub lookahead: f64,
    /// How long the planner waits between the publish of a move's first block and its first cycle,
    /// in seconds (must cover the hand-over latency).
    pub start_delay: f64,
    /// How many cycles late a motion's first block may reach the RT thread and still start: the
    /// cell is at rest, so the whole motion then runs that many cycles later than planned
    /// (a stalled host delays the start instead of failing it). Later than this, it is refused.
    pub max_start_slip: Cycles,
}

/// What the RT thread does when a watchdog trips. After any reaction the cell refuses motion
/// until reset.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FaultReaction {
    /// The RT thread ramps every axis to a stop with its stop deceleration and jerk; the drives
    /// stay enabled and hold.
    ControlledStop,
    /// The drives stop on their own quick-stop ramp (controlword Quick stop); they end disabled.
    QuickStop,
    /// The drives are shut down at once (controlword Shutdown: servo off, dynamic brake).
    Disable,
}

impl FaultReaction {
    /// The configuration name.
    pub fn as_str(self) -> &'static str {
        match self {
            FaultReaction::ControlledStop => "controlled_stop",
            FaultReaction::QuickStop => "quick_stop",
            FaultReaction::Disable => "disable",
        }
    }

    /// Parses a configuration name.
    pub fn parse(s: &str) -> Option<FaultReaction> {
        [
            FaultReaction::ControlledStop,
            FaultReaction::QuickStop,
            FaultReaction::Disable,
        ]
        .into_iter()
        .find(|r| r.as_str() == s)
    }
}

/// Watchdog settings.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WatchdogConfig {
    /// Consecutive overrun cycles that trigger `overrun_reaction`; 0 disables the watchdog.
    pub max_consecutive_overruns: u32,
    /// Reaction to consecutive overruns.
    pub overrun_reaction: FaultReaction,
    /// Reaction to a setpoint underrun or rejected setpoint during motion.
    pub underrun_reaction: FaultReaction,
    /// Reaction of the other axes when one drive faults.
    pub drive_fault_reaction: FaultReaction,
    /// Reaction to any communication watchdog ([`WatchdogConfig::comm`]).
    pub communication_reaction: FaultReaction,
    /// The communication watchdog's thresholds.
    pub comm: CommWatchdogConfig,
}

/// Where an axis' drive is reached.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Transport {
    /// The in-process simulated drive.
    Sim,
    /// A SubDevice of the cell's EtherCAT segment (`[ethercat]`).
    Ethercat,
}

/// The interface name that selects the in-process emulated segment.
pub const IN_PROCESS_INTERFACE: &str = "in-process";

/// Where the EtherCAT segment is.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum EthercatInterface {
    /// The emulated segment in this process (no network, no root).
    InProcess,
    /// A network interface, by name (raw sockets: root or CAP_NET_RAW).
    Nic(String),
}

/// A name that is neither a network interface name nor [`IN_PROCESS_INTERFACE`].
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("'{0}' is not a network interface name (1–15 characters, no '/' or spaces) nor \"{in_process}\"", in_process = IN_PROCESS_INTERFACE)]
pub struct BadInterfaceName(pub String);

/// Why the `--interface` option could not be applied to a cell.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum InterfaceOptionError {
    /// Not an interface name.
    #[error("--interface: {0}")]
    BadName(#[from] BadInterfaceName),
    /// The cell has no EtherCAT segment to point anywhere.
    #[error("--interface: cell '{0}' has no EtherCAT axes (no [ethercat] section)")]
    NoEthercat(String),
}

impl EthercatInterface {
    /// A NIC name (1–15 characters, no '/', spaces or NUL) or [`IN_PROCESS_INTERFACE`].
    pub fn parse(name: &str) -> Result<EthercatInterface, BadInterfaceName> {
        let name = name.trim();
        if name == IN_PROCESS_INTERFACE {
            Ok(EthercatInterface::InProcess)
        } else if name.is_empty() || name.len() > 15 || name.contains(['/', ' ', '\0']) {
            Err(BadInterfaceName(name.to_owned()))
        } else {
            Ok(EthercatInterface::Nic(name.to_owned()))
        }
    }
}

impl CellConfig {
    /// The cell's wire faults as its EtherCAT segment injects them, by cycle (what `cellrt
    /// drive-sim ethercat` schedules); empty for a cell without EtherCAT axes.
    pub fn wire_schedule(&self) -> Vec<ScheduledFault> {
        if self.ethercat.is_none() {
            return Vec::new();
        }
        self.inject
            .iter()
            .filter_map(|i| {
                i.fault.wire_fault().map(|fault| ScheduledFault {
                    cycle: i.cycle,
                    fault,
                })
            })
            .collect()
    }

    /// The injections the master leaves to the segment on the far end of its network
    /// interface (the wire faults of a cell on a NIC: the master cannot inject them into a
    /// real wire); empty on the in-process segment and on sim drives.
    pub fn faults_left_to_segment(&self) -> Vec<Injection> {
        match self.ethercat.as_ref().map(|e| &e.interface) {
            Some(EthercatInterface::Nic(_)) => self
                .inject
                .iter()
                .filter(|i| i.fault.wire_fault().is_some())
                .copied()
                .collect(),
            _ => Vec::new(),
        }
    }

    /// Points the cell's EtherCAT segment at `interface` (the `--interface` option); an error
    /// if the cell has no EtherCAT axes or the name is not an interface name. On a network
    /// interface the wire faults are left to the segment ([`CellConfig::faults_left_to_segment`]).
    pub fn set_ethercat_interface(&mut self, interface: &str) -> Result<(), InterfaceOptionError> {
        let parsed = EthercatInterface::parse(interface)?;
        match &mut self.ethercat {
            Some(ec) => {
                ec.interface = parsed;
                Ok(())
            }
            None => Err(InterfaceOptionError::NoEthercat(self.name.clone())),
        }
    }
}

/// `[ethercat]`: the cell's EtherCAT segment.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct EthercatConfig {
    /// The interface.
    pub interface: EthercatInterface,
    /// A cyclic frame not back within this time is lost.
    pub frame_timeout: std::time::Duration,
}

/// Default `[ethercat] frame_timeout_us`: half of a 1 ms cycle is more than a line of drives
/// needs (docs/architecture.md: ≈ 9–40 µs round trip on a veth pair).
pub const DEFAULT_FRAME_TIMEOUT_US: u32 = 500;

/// One axis of the cell.
#[derive(Debug, Clone)]
pub struct AxisConfig {
    /// Axis name, unique in the cell.
    pub name: String,
    /// Drive model and its profile.
    pub drive: DriveModel,
    /// The drive's profile (modes, cycle times, PDO maps).
    pub profile: SharedProfile,
    /// Transport to the drive.
    pub transport: Transport,
    /// What the drive's 1018h must show on EtherCAT (the model's identity unless
    /// `[axes.ethercat]` overrides it).
    pub ethercat_identity: cellrt_ethercat::identity::ExpectedIdentity,
    /// Mode of operation (6060h): a cyclic mode (csp/csv/cst, streamed setpoints) or a profile
    /// mode (pp/pv/tq, the drive's own profile; see `profile_objects`).
    pub mode: ModeOfOperation,
    /// A profile axis (`mode` pp/pv/tq): its mode and which of its profile objects are in the
    /// RxPDO or go by SDO; `None` for a cyclic axis.
    pub profile_objects: Option<ProfileObjects>,
    /// `motor.rated_speed` in counts/s: the speed the drive's 6083h/6084h time constants run
    /// from 0 to (required for pp and pv axes on drives with time-constant objects).
    pub rated_speed: Option<f64>,
    /// Display name of the axis unit (e.g. "mm", "deg").
    pub unit: String,
    /// Counts per unit at the drive's position interface.
    pub scaling: Scaling,
    /// Allowed position range, in units.
    pub position: PositionRange,
    /// Velocity, acceleration and jerk limits, in units.
    pub limits: KinematicLimits,
    /// Deceleration of the RT thread's controlled stop, in unit/s².
    pub stop_deceleration: f64,
    /// Jerk of the RT thread's controlled stop, in unit/s³.
    pub stop_jerk: f64,
    /// Following error at which the simulated drive raises its alarm, in units.
    pub following_error_limit: f64,
    /// Simulated drive settings.
    pub sim: SimAxisConfig,
    /// `[axes.homing]`: the method of a `home` naming none and the homing objects.
    pub homing: homing::AxisHoming,
    /// Axis counts ↔ the drive's object units (`[axes.motor]` with the model's units).
    pub drive_units: cellrt_cia402::drive_scaling::DriveScaling,
    /// Torque limits of cst setpoints (required for cst, optional otherwise).
    pub torque: Option<TorqueLimits>,
    /// csv: the master closes the position loop around the drive's velocity loop; 60FFh =
    /// setpoint velocity + this gain × (setpoint − actual position), 1/s (default
    /// [`DEFAULT_CSV_POSITION_GAIN`]). The manuals leave the outer loop to the controller.
    pub csv_position_gain: f64,
    /// The multi-axis amplifier and slot (`amplifier`, `amplifier_axis`; the slot defaults to
    /// the order in the file); `None`: the axis has an amplifier of its own.
    pub amplifier: Option<cellrt_ethercat::master::AmplifierSlot>,
    /// SYNC0 from distributed clocks on the axis' SubDevice (`[axes.ethercat]
    /// distributed_clocks`, default true); false: the SubDevice runs free (SM2-synchronous).
    pub distributed_clocks: bool,
    /// `[[axes.ethercat.startup_sdo]]`: downloads bring-up makes in PRE-OP, checked at load.
    pub startup_sdo: Vec<cellrt_ethercat::master::StartupSdo>,
    /// The ESI device describing the drive (`esi`), checked against this configuration at
    /// load; the emulator presents its object dictionary and access rights.
    pub esi: Option<std::sync::Arc<cellrt_ethercat::esi::EsiDevice>>,
}

/// Default csv position-correction gain, 1/s: removes the drift between the planned positions
/// and the drive's integration of 60FFh with a time constant of 50 ms.
pub const DEFAULT_CSV_POSITION_GAIN: f64 = 20.0;

/// Torque limits of an axis, in % of rated torque (the unit of 6071h is 0.1 %).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TorqueLimits {
    /// Largest |torque| a setpoint may ask for, % (at most [`MAX_TORQUE_PERCENT`]).
    pub max: TorquePercent,
    /// Largest torque change, %/s.
    pub slope: f64,
}

/// Upper bound of `limits.torque`: 6071h/60E0h/60E1h range 0…10000 × 0.1 % (MR-J4-TM manual §5.9).
pub const MAX_TORQUE_PERCENT: f64 = 1000.0;

/// Default `limits.torque_slope`: full rated torque in 0.1 s.
pub const DEFAULT_TORQUE_SLOPE: f64 = 1000.0;

/// A torque in % of the motor's rated torque.
#[derive(Debug, Clone, Copy, PartialEq, PartialOrd, Default)]
pub struct TorquePercent(pub f64);

impl TorquePercent {
    /// The drive value in 0.1 % units (6071h), rounded; `None` outside the i16 range.
    pub fn to_drive(self) -> Option<i16> {
        let v = (self.0 * 10.0).round();
        (v.is_finite() && v >= f64::from(i16::MIN) && v <= f64::from(i16::MAX)).then_some(v as i16)
    }
}

/// Settings of an axis' simulated drive.
#[derive(Debug, Clone, PartialEq)]
pub struct SimAxisConfig {
    /// Position of the axis at start, in units.
    pub initial_position: f64,
    /// Position loop bandwidth, Hz.
    pub position_bandwidth_hz: f64,
    /// Velocity loop bandwidth, Hz.
    pub velocity_bandwidth_hz: f64,
    /// Position of the encoder's Z phase, in units (one per motor revolution; used by the
    /// MR-J3-T04 C_CR2 home setting and S_ZPAS; the manuals give no figure).
    pub z_phase_position: f64,
    /// The home dog and limit switches, counts (`sim.home_dog`, `sim.positive_limit`,
    /// `sim.negative_limit`).
    pub switches: cellrt_emulator::sim::homing_switches::HomingSwitches,
    /// The simulated drive's homing figures; `travel_after_dog` in counts from
    /// `sim.travel_after_dog`, the others the simulator's defaults.
    pub homing: cellrt_emulator::HomingParams,
    /// The simulated motor's maximum speed as a multiple of the axis velocity limit; the
    /// drive's overspeed alarm trips at 1.2 × that (a csp target step implying more).
    pub motor_speed_factor: f64,
    /// How the emulated SubDevice departs from its profile (`sim.cycle_time_object`,
    /// `sim.following_error_object`, `sim.distributed_clocks`; generic CiA 402 drives only).
    pub subdevice: cellrt_emulator::ethercat::SubDeviceVariant,
    /// The emulated drive's own profile where it differs from the axis' (`sim.mode_group`: an
    /// MR-J4-TM whose [Pr. PA01] selects another group until the start-up list sets it).
    pub profile: Option<cellrt_cia402::SharedProfile>,
}

/// Default `rt.planner_priority`: 0, SCHED_OTHER like the other non-RT threads; a cell on a
/// machine with other load sets it (the demo uses 40, well below the RT thread's 80).
pub const DEFAULT_PLANNER_PRIORITY: u8 = 0;

/// Default `sim.motor_speed_factor`: the motor can do a bit more than the axis is allowed to.
pub const DEFAULT_MOTOR_SPEED_FACTOR: f64 = 1.5;

impl CellConfig {
    /// Reads and validates a cell configuration file.
    pub fn load(path: &Path) -> Result<CellConfig, ConfigError> {
        let text = input_file::read_text(path).map_err(|e| ConfigError::io(path, e))?;
        Self::parse(path, &text)
    }

    /// Parses and validates configuration text; `path` is used in messages and to resolve the
    /// program path.
    pub fn parse(path: &Path, text: &str) -> Result<CellConfig, ConfigError> {
        let raw: raw::RawCellConfig = error::parse_toml(path, text)?;
        validate::validate(path, text, raw)
    }

    /// The cycle-time period in seconds.
    pub fn period(&self) -> f64 {
        self.cycle_time.as_secs_f64()
    }

    /// The RT-loop slot of the axis called `name` (`None` for an axis the loop does not run).
    pub fn axis_index(&self, name: &str) -> Option<usize> {
        self.axis_ref(name)?.loop_slot()
    }

    /// The axis called `name`, whichever backend runs it.
    pub fn axis_ref(&self, name: &str) -> Option<AxisRef> {
        self.axes.find(name).map(|a| a.at)
    }

    /// The name of axis `axis`.
    pub fn axis_name(&self, axis: AxisRef) -> &str {
        self.axes.get(axis).name()
    }

    /// The velocity limit of axis `axis`, unit/s.
    pub fn velocity_limit(&self, axis: AxisRef) -> f64 {
        self.axes.get(axis).velocity_limit()
    }
}

#[cfg(test)]
mod esi_tests;
#[cfg(test)]
mod je_c_tests;
#[cfg(test)]
mod tests;

/// `ADDR` of `[live] listen` or `cellrt run --live`: an IP address and port (port 0: any free
/// one). Loopback unless the address says otherwise.
pub fn parse_live_addr(text: &str) -> Result<std::net::SocketAddr, LiveAddrError> {
    text.parse().map_err(|_| LiveAddrError {
        text: text.to_string(),
    })
}

/// An `ADDR` of `[live] listen` or `cellrt run --live` that is not an address and port.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("'{text}' is not an address and port like 127.0.0.1:8765")]
pub struct LiveAddrError {
    /// The text given.
    pub text: String,
}
