//! The bus a cell runs on, chosen by its config: the in-process simulated drives, or an
//! EtherCAT segment (emulated in-process or on a network interface).

use std::sync::Arc;

use cellrt_cia402::bus::{LinkState, MailboxNotice, PostError, SdoOutcome, SdoRequest};
use cellrt_cia402::mode::ModeOfOperation;
use cellrt_cia402::{AcyclicBus, BusError, Cycles, CyclicBus, FaultInjection, FrameCounters};
use cellrt_emulator::ethercat::InProcessLink;
use cellrt_emulator::ethercat::{Segment, SubDeviceVariant};
use cellrt_emulator::motion::profile_position::PpParams;
use cellrt_emulator::sim::plant::PlantParams;
use cellrt_emulator::{SimBus, SimDrive, SimDriveParams};
use cellrt_ethercat::esi::conform::FixedPdo;
use cellrt_ethercat::esi::EsiDevice;
use cellrt_ethercat::master::{EthercatBus, Link, RawSocketLink, SegmentConfig, SegmentDrive};

use cellrt_cia402::profiles::{MotorKind, SharedProfile};
use cellrt_cia402::CycleTime;
use cellrt_config::{AxisConfig, CellConfig, EthercatInterface};
use cellrt_emulator::sim::drive::SimMotor;

/// The cell's bus.
#[derive(Debug)]
pub enum CellBus {
    /// Simulated drives called directly.
    Sim(SimBus),
    /// An EtherCAT segment.
    Ethercat(Box<EthercatBus>),
}

/// A bus that could not be opened, with the reason.
#[derive(Debug, thiserror::Error)]
pub enum BusOpenError {
    /// The network interface could not be opened.
    #[error("EtherCAT interface '{interface}': {source}")]
    Interface {
        /// The interface.
        interface: String,
        /// Why.
        source: std::io::Error,
    },
    /// Bring-up failed.
    #[error(transparent)]
    Ethercat(#[from] cellrt_ethercat::master::EthercatError),
    /// The emulated segment's units could not be built.
    #[error("emulated EtherCAT segment: {0}")]
    Unit(#[from] cellrt_emulator::ethercat::UnitError),
}

/// The simulated motor of axis `a`: its configured resolution and velocity unit.
fn sim_motor(a: &AxisConfig) -> SimMotor {
    let u = &a.drive_units;
    SimMotor {
        kind: u.motor().map_or(MotorKind::Rotary, |m| m.kind),
        counts_per: u.motor().map(|m| m.counts_per),
        velocity_unit: Some(u.velocity_unit()),
    }
}

/// Builds the simulated bus of `cell`.
pub fn sim_bus(cell: &CellConfig) -> SimBus {
    SimBus::new(sim_drives(cell))
}

/// The simulated drives of `cell`'s axes (behind a [`SimBus`] or an emulated EtherCAT segment).
pub fn sim_drives(cell: &CellConfig) -> Vec<SimDrive> {
    cell.axes
        .on_loop()
        .iter()
        .map(|a| {
            let s = a.scaling.counts_per_unit();
            // The drive's own profile: another MR-J4-TM group until a start-up list sets PA01.
            let own = a.sim.profile.clone().unwrap_or_else(|| a.profile.clone());
            let params = SimDriveParams {
                plant: PlantParams {
                    position_bandwidth_hz: a.sim.position_bandwidth_hz,
                    velocity_bandwidth_hz: a.sim.velocity_bandwidth_hz,
                    max_velocity: a.limits.velocity * s * a.sim.motor_speed_factor,
                    max_acceleration: a.limits.acceleration * s * 3.0,
                },
                initial_position: a
                    .scaling
                    .to_counts_i32(a.sim.initial_position)
                    .unwrap_or_default(),
                following_error_limit: (a.following_error_limit * s)
                    .round()
                    .min(f64::from(u32::MAX)) as u32,
                // A cst axis idles and brakes in csv (`AxisChannel::drive_command`).
                z_phase_position: a
                    .scaling
                    .to_counts_i32(a.sim.z_phase_position)
                    .unwrap_or_default(),
                homing_switches: a.sim.switches,
                homing: a.sim.homing,
                initial_mode: match a.mode {
                    ModeOfOperation::CyclicSyncTorque => ModeOfOperation::CyclicSyncVelocity,
                    m => m,
                },
                // The simulated motor is the configured one (its own decoding of the units).
                motor: sim_motor(a),
                // The time constants refer to the configured rated speed, as the master's.
                pp: PpParams {
                    time_constant_speed: a.rated_speed,
                    ..PpParams::default()
                },
                ..SimDriveParams::default()
            };
            SimDrive::new(own, params, cell.cycle_time)
        })
        .collect()
}

/// The EtherCAT segment `cell` expects, in axis order.
pub fn segment_config(cell: &CellConfig) -> SegmentConfig {
    SegmentConfig {
        cycle: cell.cycle_time,
        drives: cell
            .axes
            .on_loop()
            .iter()
            .map(|a| SegmentDrive {
                axis: a.name.clone(),
                profile: a.profile.clone(),
                identity: a.ethercat_identity,
                mode: a.mode,
                amplifier: a.amplifier.clone(),
                distributed_clocks: a.distributed_clocks,
                fixed_pdo: a.esi.as_deref().map_or_else(Default::default, |d| {
                    FixedPdo::of(d, a.profile.pdo.rx.index, a.profile.pdo.tx.index)
                }),
                startup_sdo: a.startup_sdo.clone(),
            })
            .collect(),
    }
}

/// One emulated SubDevice: the drives of its slots in slot order, how it departs from its
/// profile, and the ESI device whose object dictionary and access rights it presents.
#[derive(Debug)]
pub struct EmulatedStation {
    /// One drive per axis of the unit.
    pub drives: Vec<SimDrive>,
    /// How the SubDevice departs from its profile.
    pub variant: SubDeviceVariant,
    /// The ESI device that describes it, if any.
    pub esi: Option<Arc<EsiDevice>>,
}

impl EmulatedStation {
    /// A unit of `profile`'s model as it leaves the factory: every slot a drive with default
    /// settings at `cycle`, no departures from the profile, no ESI.
    pub fn of_model(profile: &SharedProfile, cycle: CycleTime) -> EmulatedStation {
        EmulatedStation {
            drives: (0..profile.axes_per_unit.max(1))
                .map(|_| default_drive(profile.clone(), cycle))
                .collect(),
            variant: SubDeviceVariant::default(),
            esi: None,
        }
    }
}

/// A drive of `profile`'s model with default settings (an unused slot of a unit).
fn default_drive(profile: impl Into<SharedProfile>, cycle: CycleTime) -> SimDrive {
    SimDrive::new(profile, SimDriveParams::default(), cycle)
}

/// The emulated segment of `stations`, in line order (position 0 next to the MainDevice).
pub fn segment_of(stations: Vec<EmulatedStation>) -> Result<Segment, BusOpenError> {
    let mut presented = Vec::with_capacity(stations.len());
    let units = stations
        .into_iter()
        .map(|st| {
            presented.push((st.variant, st.esi));
            st.drives
        })
        .collect();
    let mut segment = Segment::of_units(units)?;
    for (n, (variant, esi)) in presented.into_iter().enumerate() {
        if let Some(station) = segment.station_mut(n) {
            station.present(variant);
        }
        if let Some(esi) = esi {
            segment.describe_station(n, esi);
        }
    }
    Ok(segment)
}

/// The emulated segment of `cell`'s drives (what `cellrt drive-sim ethercat` serves): one
/// station per SubDevice of [`segment_config`], a multi-axis amplifier presenting the drives
/// of all its slots (an unused slot: a drive of the model with default settings), an axis
/// with an ESI file presenting that device's object dictionary and access rights.
pub fn emulated_segment(cell: &CellConfig) -> Result<Segment, BusOpenError> {
    let stations = segment_config(cell).stations()?;
    let axes = cell.axes.on_loop();
    let mut drives: Vec<Option<SimDrive>> = sim_drives(cell).into_iter().map(Some).collect();
    let emulated = stations
        .iter()
        .map(|st| EmulatedStation {
            drives: st
                .slots
                .iter()
                .map(|slot| {
                    slot.and_then(|a| drives.get_mut(a).and_then(Option::take))
                        .unwrap_or_else(|| default_drive(st.model, cell.cycle_time))
                })
                .collect(),
            variant: axes[st.first_axis()].sim.subdevice,
            esi: st.slots.iter().flatten().find_map(|&a| axes[a].esi.clone()),
        })
        .collect();
    segment_of(emulated)
}

impl CellBus {
    /// The optional settings bring-up skipped (none on simulated drives).
    pub fn bring_up_warnings(&self) -> &[cellrt_ethercat::master::BringUpWarning] {
        match self {
            CellBus::Sim(_) => &[],
            CellBus::Ethercat(bus) => bus.bring_up_warnings(),
        }
    }

    /// The segment's diagnostics handle, on EtherCAT.
    pub fn diagnostics(&self) -> Option<cellrt_ethercat::master::BusDiagnostics> {
        match self {
            CellBus::Sim(_) => None,
            CellBus::Ethercat(bus) => Some(bus.diagnostics()),
        }
    }

    /// The drives' dictionaries by SDO Information, on EtherCAT.
    pub fn dictionary_reader(&self) -> Option<cellrt_ethercat::master::DictionaryReader> {
        match self {
            CellBus::Sim(_) => None,
            CellBus::Ethercat(bus) => Some(bus.dictionary_reader()),
        }
    }

    /// Opens the bus `cell` names; EtherCAT segments are brought to OP here.
    pub fn open(cell: &CellConfig) -> Result<CellBus, BusOpenError> {
        let Some(ec) = &cell.ethercat else {
            return Ok(CellBus::Sim(sim_bus(cell)));
        };
        let link: Box<dyn Link> = match &ec.interface {
            EthercatInterface::InProcess => Box::new(
                InProcessLink::with_frame_timeout(emulated_segment(cell)?, ec.frame_timeout)
                    .excusing_host_stalls(),
            ),
            EthercatInterface::Nic(name) => Box::new(
                RawSocketLink::open(name, ec.frame_timeout).map_err(|source| {
                    BusOpenError::Interface {
                        interface: name.clone(),
                        source,
                    }
                })?,
            ),
        };
        Ok(CellBus::Ethercat(Box::new(EthercatBus::bring_up(
            segment_config(cell),
            link,
        )?)))
    }
}

macro_rules! each {
    ($self:ident, $b:ident => $e:expr) => {
        match $self {
            CellBus::Sim($b) => $e,
            CellBus::Ethercat($b) => $e,
        }
    };
}

impl CyclicBus for CellBus {
    fn axis_count(&self) -> usize {
        each!(self, b => b.axis_count())
    }
    fn rx_image_mut(&mut self, axis: usize) -> &mut [u8] {
        each!(self, b => b.rx_image_mut(axis))
    }
    fn tx_image(&self, axis: usize) -> &[u8] {
        each!(self, b => b.tx_image(axis))
    }
    fn exchange(&mut self, elapsed: Cycles) -> Result<(), BusError> {
        each!(self, b => b.exchange(elapsed))
    }
    fn frame_counters(&self) -> Option<FrameCounters> {
        each!(self, b => b.frame_counters())
    }
    fn link_state(&self, axis: usize) -> Option<LinkState> {
        each!(self, b => b.link_state(axis))
    }
    fn deadline_correction_ns(&mut self) -> i64 {
        each!(self, b => b.deadline_correction_ns())
    }
    fn dc_phase_error_ns(&self) -> Option<i64> {
        each!(self, b => b.dc_phase_error_ns())
    }
    fn take_mailbox_notice(&mut self) -> Option<MailboxNotice> {
        each!(self, b => b.take_mailbox_notice())
    }
}

impl AcyclicBus for CellBus {
    fn sdo_upload(&mut self, axis: usize, index: u16, sub: u8) -> Result<i64, u32> {
        each!(self, b => b.sdo_upload(axis, index, sub))
    }
    fn sdo_download(&mut self, axis: usize, index: u16, sub: u8, data: &[u8]) -> Result<(), u32> {
        each!(self, b => b.sdo_download(axis, index, sub, data))
    }
    fn post_sdo(&mut self, axis: usize, request: SdoRequest) -> Result<(), PostError> {
        each!(self, b => b.post_sdo(axis, request))
    }
    fn take_sdo(&mut self, axis: usize) -> Option<SdoOutcome> {
        each!(self, b => b.take_sdo(axis))
    }
    fn close(&mut self) -> Result<(), cellrt_cia402::bus::CloseError> {
        each!(self, b => b.close())
    }
}

impl FaultInjection for CellBus {
    fn inject_alarm(&mut self, axis: usize, code: u16) -> bool {
        each!(self, b => b.inject_alarm(axis, code))
    }
    fn inject_rx_loss(&mut self, axis: usize, cycles: u32) -> bool {
        each!(self, b => b.inject_rx_loss(axis, cycles))
    }
    fn inject_counter_corruption(&mut self, axis: usize, cycles: u32) -> bool {
        each!(self, b => b.inject_counter_corruption(axis, cycles))
    }
    fn inject_subdevice_stall(&mut self, axis: usize, cycles: u32) -> bool {
        each!(self, b => b.inject_subdevice_stall(axis, cycles))
    }
    fn inject_frame_delay(&mut self, delay_ns: u64, cycles: u32) -> bool {
        each!(self, b => b.inject_frame_delay(delay_ns, cycles))
    }
    fn inject_frame_corruption(&mut self, axis: usize, cycles: u32) -> bool {
        each!(self, b => b.inject_frame_corruption(axis, cycles))
    }
    fn inject_datagram_drop(&mut self, cycles: u32) -> bool {
        each!(self, b => b.inject_datagram_drop(cycles))
    }
    fn inject_link_loss(&mut self, axis: usize, cycles: u32) -> bool {
        each!(self, b => b.inject_link_loss(axis, cycles))
    }
}
