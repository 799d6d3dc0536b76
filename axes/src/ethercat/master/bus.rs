//! The EtherCAT MainDevice as a [`CyclicBus`]: ethercrab brings the segment up (INIT → PRE-OP, SII,
//! mailboxes, the PDO assignment by SDO, SAFE-OP, OP); in OP the cyclic exchange is cellrt's
//! own frame (one LRW over the process image, preallocated, no heap allocation per cycle; see
//! ARCHITECTURE.md on ethercrab's `tx_rx_dc()`), with the working counter checked every cycle.

use std::collections::VecDeque;
use std::future::Future;
use std::ops::Range;
use std::pin::pin;
use std::task::{Context, Poll, Waker};
use std::time::Duration;

use ethercrab::std::ethercat_now;
use ethercrab::subdevice_group::{DcConfiguration, HasDc, Op};
use ethercrab::{
    DcSync, DefaultLock, MainDevice, MainDeviceConfig, PduRx, PduStorage, PduTx, RetryBehaviour,
    SubDeviceGroup, SubDevicePdi, SubDeviceRef, Timeouts,
};

use super::link::Link;
use crate::bus::{
    AcyclicBus, BusError, CyclicBus, FaultInjection, FrameCounters, LinkState, MailboxNotice,
    SDO_UNSUPPORTED,
};
use crate::cia402::mode::ModeOfOperation;
use crate::cycles::{CycleTime, Cycles};
use crate::ethercat::emergency::{Emergency, MailboxMessage};
use crate::ethercat::frame::{self, Command, DatagramSpan, FrameBuilder};
use crate::ethercat::identity::{ExpectedIdentity, SubDeviceIdentity};
use crate::ethercat::register::{self as reg, AlState, AlStatus};
use crate::pdo::objects::MODES_OF_OPERATION;
use crate::pdo::PdoEntry;
use crate::profiles::mr_j5_g_n1::unit_pdo_limit;
use crate::profiles::PdoAssignment;
use crate::profiles::{DataType, DriveProfile};

/// SubDevices one segment can hold.
pub const MAX_SUBDEVICES: usize = 16;
/// Bytes of process image one segment can hold.
pub const MAX_PDI: usize = 1024;
/// Frames in flight during bring-up.
const MAX_FRAMES: usize = 16;
/// ethercrab's PDU storage element size.
const MAX_PDU_DATA: usize = PduStorage::element_size(1100);
/// Bytes of an Ethernet frame buffer (1514 without FCS, rounded up).
const FRAME_BUF: usize = 1536;
/// The source MAC of cellrt's own cyclic frames (ethercrab's MainDevice address, so a
/// segment sees one master).
const MASTER_MAC: [u8; 6] = [0x10, 0x10, 0x10, 0x10, 0x10, 0x10];
/// Retries of a bring-up PDU that timed out.
const BRINGUP_RETRIES: usize = 3;
/// How long bring-up waits for an SII EEPROM read (ethercrab's default is 10 ms; a host that
/// stalls for milliseconds — a virtual machine, a loaded emulator — needs more; bring-up only).
const BRINGUP_EEPROM_TIMEOUT: Duration = Duration::from_millis(100);
/// How long bring-up waits for a PDU's return (the cyclic exchange has its own frame timeout).
const BRINGUP_PDU_TIMEOUT: Duration = Duration::from_millis(100);
/// Delay from DC configuration to the first SYNC0 pulse.
const SYNC0_START_DELAY: Duration = Duration::from_millis(10);
/// Where in the SYNC0 cycle the cyclic frame should pass the DC reference clock: this fraction
/// of a cycle after a SYNC0 edge, so the drives take its outputs at the next edge and the frame
/// may be late by the rest of the cycle (wakeup latency is one-sided) before it misses it.
pub const SYNC0_FRAME_PHASE_DIVISOR: u64 = 8;
/// Share of the DC phase error corrected per cycle once locked (1/16: the wakeup jitter of a
/// non-RT kernel averages out; a step of the reference clock is followed in about 50 cycles).
const DC_PHASE_GAIN_DIVISOR: i64 = 16;
/// Largest deadline correction per cycle once locked, as a share of the cycle (1/50 = 2 %).
const DC_MAX_STEP_DIVISOR: i64 = 50;
/// 1C32h:02 SM2 cycle time.
const SM2_CYCLE_TIME: (u16, u8) = (0x1C32, 2);
/// 1C12h / 1C13h PDO assignment.
const RX_ASSIGN: u16 = 0x1C12;
const TX_ASSIGN: u16 = 0x1C13;
/// SM status (0805h + 8n) bit 3: mailbox full.
const SM_STATUS_FULL: u8 = 0x08;
/// Largest SM1 mailbox the master drains itself (bigger ones are left to ethercrab's clearing).
const MAX_MAILBOX_READ: usize = 1024;
/// Zeros to send as the data of a mailbox read (no allocation per read).
static MAILBOX_READ_ZEROS: [u8; MAX_MAILBOX_READ] = [0; MAX_MAILBOX_READ];
/// Mailbox messages drained before an SDO at most (a firmware that refills SM1 faster than
/// this is left to ethercrab's clearing, which discards).
const MAX_DRAIN: usize = 8;
/// Notices held for [`Bus::take_mailbox_notice`] (preallocated; more are dropped and counted).
const NOTICE_QUEUE: usize = 16;

/// One axis of the segment, in axis order.
#[derive(Debug, Clone)]
pub struct SegmentDrive {
    /// The axis name (for errors).
    pub axis: String,
    /// The drive's profile.
    pub profile: &'static DriveProfile,
    /// What its 1018h must show.
    pub identity: ExpectedIdentity,
    /// The mode written to 6060h at bring-up where 6060h is not in the RxPDO.
    pub mode: ModeOfOperation,
    /// The multi-axis amplifier this axis is a slot of; `None`: a station of its own (slot 0).
    pub amplifier: Option<AmplifierSlot>,
}

/// An axis' place on a multi-axis amplifier (config keys `amplifier`, `amplifier_axis`).
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct AmplifierSlot {
    /// The amplifier's label; axes with the same label are one SubDevice.
    pub label: String,
    /// The axis' slot on it (0 = axis A).
    pub slot: u8,
}

/// The segment cellrt expects on the link.
#[derive(Debug, Clone)]
pub struct SegmentConfig {
    /// The cycle time of the cell.
    pub cycle: CycleTime,
    /// The axes in axis order; the SubDevices are in line in the order of their first axis.
    pub drives: Vec<SegmentDrive>,
}

/// One SubDevice of the segment: a drive, or a multi-axis amplifier with its slots.
#[derive(Debug, Clone)]
pub struct SegmentStation {
    /// The model's profile (the unit's base profile).
    pub model: &'static DriveProfile,
    /// The amplifier label, where the axes named one.
    pub label: Option<String>,
    /// Per slot of the unit: the configured axis (index into `SegmentConfig::drives`); `None`
    /// for a slot no axis uses (its drive is configured with the model's default maps and
    /// left disabled).
    pub slots: Vec<Option<usize>>,
}

impl SegmentConfig {
    /// The SubDevices the axes make, in line order (one per amplifier label, or per unlabelled
    /// axis), with the labels, slots and models checked.
    pub fn stations(&self) -> Result<Vec<SegmentStation>, EthercatError> {
        plan_stations(self)
    }
}

impl SegmentStation {
    /// The first configured axis (identity and error messages).
    pub fn first_axis(&self) -> usize {
        self.slots.iter().flatten().copied().next().unwrap_or(0)
    }

    /// The profile slot `slot` runs: its axis' (with its mapping), or the model's default for
    /// an unused slot.
    fn slot_profile(&self, config: &SegmentConfig, slot: usize) -> &'static DriveProfile {
        self.slots[slot].map_or(self.model, |a| config.drives[a].profile)
    }
}

/// Groups the axes of `config` into SubDevices (one per amplifier label, or per unlabelled
/// axis), checking labels, slots and models.
fn plan_stations(config: &SegmentConfig) -> Result<Vec<SegmentStation>, EthercatError> {
    let mut plans: Vec<SegmentStation> = Vec::new();
    for (i, d) in config.drives.iter().enumerate() {
        let model = crate::profiles::profile(d.profile.model);
        let per_unit = usize::from(model.axes_per_unit);
        let amplifier_error = |what: String| EthercatError::Amplifier {
            axis: d.axis.clone(),
            what,
        };
        let Some(a) = &d.amplifier else {
            let mut slots = vec![None; per_unit];
            slots[0] = Some(i);
            plans.push(SegmentStation {
                model,
                label: None,
                slots,
            });
            continue;
        };
        let slot = usize::from(a.slot);
        if slot >= per_unit {
            return Err(amplifier_error(format!(
                "amplifier_axis {} on amplifier '{}': {} has slots 0..={}",
                a.slot,
                a.label,
                model.model,
                per_unit - 1
            )));
        }
        let plan = match plans
            .iter_mut()
            .position(|p| p.label.as_deref() == Some(a.label.as_str()))
        {
            Some(p) => &mut plans[p],
            None => {
                plans.push(SegmentStation {
                    model,
                    label: Some(a.label.clone()),
                    slots: vec![None; per_unit],
                });
                plans.last_mut().expect("just pushed")
            }
        };
        if plan.model.model != model.model {
            return Err(amplifier_error(format!(
                "amplifier '{}' is a {}, not a {}",
                a.label, plan.model.model, model.model
            )));
        }
        if let Some(other) = plan.slots[slot] {
            return Err(amplifier_error(format!(
                "slot {} of amplifier '{}' is already axis '{}'",
                a.slot, a.label, config.drives[other].axis
            )));
        }
        plan.slots[slot] = Some(i);
    }
    Ok(plans)
}

/// A bring-up or shutdown that failed, naming the drive and the step.
#[derive(Debug, thiserror::Error)]
pub enum EthercatError {
    /// An ethercrab operation failed.
    #[error("EtherCAT {step}: {source}")]
    Bringup {
        /// What was being done.
        step: String,
        /// ethercrab's error.
        source: ethercrab::error::Error,
    },
    /// The segment does not have the configured number of drives.
    #[error("EtherCAT segment has {found} SubDevice(s), the cell config names {expected}")]
    Count {
        /// Configured.
        expected: usize,
        /// Found on the wire.
        found: usize,
    },
    /// A drive's identity does not match its configured model.
    #[error(
        "EtherCAT SubDevice {position} (axis '{axis}', configured as {model}): identity vendor \
         {found_vendor:#010x} product {found_product:#010x} does not match the model (expected vendor \
         {expected_vendor:#010x}{expected_product})"
    )]
    Identity {
        /// Position in the line.
        position: usize,
        /// The axis.
        axis: String,
        /// The configured model.
        model: &'static str,
        /// 1018h:01 found.
        found_vendor: u32,
        /// 1018h:02 found.
        found_product: u32,
        /// Required vendor.
        expected_vendor: u32,
        /// ", product …" or "".
        expected_product: String,
    },
    /// The cycle time is not one the model allows.
    #[error("axis '{axis}': {model} does not support a {cycle_us} µs cycle (allowed: {allowed})")]
    CycleTime {
        /// The axis.
        axis: String,
        /// The model.
        model: &'static str,
        /// The cell's cycle.
        cycle_us: u32,
        /// The model's cycles.
        allowed: String,
    },
    /// The axes' amplifier labels and slots do not describe the units.
    #[error("axis '{axis}' (config keys amplifier / amplifier_axis): {what}")]
    Amplifier {
        /// The axis.
        axis: String,
        /// What is wrong.
        what: String,
    },
    /// The mode is not one the model runs (pv and tq on a multi-axis unit, mr-j5-g-n1.md §1.2,
    /// TV-8).
    #[error("axis '{axis}': {model} does not run mode {mode} (allowed: {allowed})")]
    Mode {
        /// The axis.
        axis: String,
        /// The model.
        model: &'static str,
        /// The configured mode.
        mode: &'static str,
        /// The model's modes.
        allowed: String,
    },
    /// A drive refused the process image, or the image does not fit.
    #[error("EtherCAT SubDevice {position} (axis '{axis}'): {what}")]
    ProcessImage {
        /// Position.
        position: usize,
        /// Axis.
        axis: String,
        /// What is wrong.
        what: String,
    },
    /// A state change did not complete.
    #[error("EtherCAT: SubDevice {position} did not reach {state} (AL status {status:#04x}, AL status code {code:#06x})")]
    State {
        /// Position.
        position: usize,
        /// The requested state.
        state: &'static str,
        /// AL status read.
        status: u8,
        /// AL status code read.
        code: u16,
    },
    /// The link failed.
    #[error("EtherCAT link: {0}")]
    Link(#[from] super::link::LinkError),
}

fn step<T>(
    what: impl Into<String>,
    r: Result<T, ethercrab::error::Error>,
) -> Result<T, EthercatError> {
    r.map_err(|source| EthercatError::Bringup {
        step: what.into(),
        source,
    })
}

/// On a multi-axis unit, the sum of its slots' PDOs must fit the unit's limit at the cycle
/// (mr-j5-g-n1.md §5.1, TV-7: e.g. J5W3 at 0.25 ms: 120 bytes each way).
fn check_unit_pdo_limits(
    config: &SegmentConfig,
    plans: &[SegmentStation],
) -> Result<(), EthercatError> {
    for (position, plan) in plans.iter().enumerate() {
        if !plan.model.is_multi_axis() {
            continue;
        }
        let d = &config.drives[plan.first_axis()];
        let Some((max_rx, max_tx)) =
            unit_pdo_limit(plan.model.axes_per_unit, config.cycle.as_micros())
        else {
            return Err(EthercatError::CycleTime {
                axis: d.axis.clone(),
                model: plan.model.model.as_str(),
                cycle_us: config.cycle.as_micros(),
                allowed: plan.model.cycle_times_text(),
            });
        };
        let (mut rx, mut tx) = (0, 0);
        for slot in 0..plan.slots.len() {
            let p = plan.slot_profile(config, slot);
            rx += p.rx_pdo.byte_len();
            tx += p.tx_pdo.byte_len();
        }
        if rx > usize::from(max_rx) || tx > usize::from(max_tx) {
            return Err(EthercatError::ProcessImage {
                position,
                axis: d.axis.clone(),
                what: format!(
                    "the axes of amplifier {} map {rx} RxPDO and {tx} TxPDO bytes; {} takes at most {max_rx} and {max_tx} at {} µs",
                    plan.label.as_deref().unwrap_or("(unlabelled)"),
                    plan.model.model,
                    config.cycle.as_micros()
                ),
            });
        }
    }
    Ok(())
}

/// Configures station `plan` in PRE-OP: each slot's PDO mapping objects at its offset index
/// (count to 0, entries, count last; mr-j3-t04.md §3.3, mr-j5-g-n1.md §5.1, §1.5), the
/// assignment 1C12h/1C13h with every slot's PDO in slot order (mr-j5-g-n1.md §1.5
/// [inferred]: one assigned PDO per axis), as far as the model lets it be written (MR-J3-T04:
/// read-only, §4.4; MR-J4-TM: the count fixed at 1, §5.1), each axis' 6060h (at its offset
/// index) where its RxPDO does not carry it, and the station's cycle time 1C32h:02 once.
async fn configure_station<S: std::ops::Deref<Target = ethercrab::SubDevice>>(
    sd: &ethercrab::SubDeviceRef<'_, S>,
    config: &SegmentConfig,
    plan: &SegmentStation,
) -> Result<(), ethercrab::error::Error> {
    let model = plan.model;
    let assignment = model.pdo_rules.assignment;
    let at = |index: u16, slot: usize| model.axis_object(index, slot as u8).unwrap_or(index);
    for (direction, assign) in [RX_ASSIGN, TX_ASSIGN].into_iter().enumerate() {
        if assignment == PdoAssignment::Writable {
            sd.sdo_write(assign, 0, 0u8).await?;
        }
        for slot in 0..plan.slots.len() {
            let p = plan.slot_profile(config, slot);
            let map = if direction == 0 { &p.rx_pdo } else { &p.tx_pdo };
            let index = at(map.index, slot);
            sd.sdo_write(index, 0, 0u8).await?;
            for (i, e) in map.entries.iter().enumerate() {
                let e = if e.is_padding() {
                    *e
                } else {
                    PdoEntry {
                        index: at(e.index, slot),
                        ..*e
                    }
                };
                sd.sdo_write(index, (i + 1) as u8, e.mapping_word()).await?;
            }
            sd.sdo_write(index, 0, map.entries.len() as u8).await?;
            if assignment != PdoAssignment::ReadOnly {
                sd.sdo_write(assign, (slot + 1) as u8, index).await?;
            }
        }
        if assignment == PdoAssignment::Writable {
            sd.sdo_write(assign, 0, plan.slots.len() as u8).await?;
        }
    }
    for (slot, axis) in plan.slots.iter().enumerate() {
        let Some(d) = axis.map(|a| &config.drives[a]) else {
            continue;
        };
        if !d.profile.rx_pdo.maps(MODES_OF_OPERATION) {
            sd.sdo_write(at(MODES_OF_OPERATION, slot), 0, d.mode.as_i8())
                .await?;
        }
    }
    if model.object(SM2_CYCLE_TIME.0, SM2_CYCLE_TIME.1).is_some() {
        sd.sdo_write(
            SM2_CYCLE_TIME.0,
            SM2_CYCLE_TIME.1,
            config.cycle.as_nanos() as u32,
        )
        .await?;
    }
    Ok(())
}

/// Drives an ethercrab future to completion, passing its frames over `link`.
fn pump<F: Future>(
    fut: F,
    tx: &mut PduTx<'static>,
    rx: &mut PduRx<'static>,
    link: &mut dyn Link,
    buf: &mut [u8],
) -> F::Output {
    let mut fut = pin!(fut);
    let mut cx = Context::from_waker(Waker::noop());
    loop {
        if let Poll::Ready(v) = fut.as_mut().poll(&mut cx) {
            return v;
        }
        let mut sent = false;
        while let Some(frame) = tx.next_sendable_frame() {
            sent = true;
            let mut len = 0;
            let ok = frame.send_blocking(|data| {
                len = data.len().min(buf.len());
                buf[..len].copy_from_slice(&data[..len]);
                Ok(data.len())
            });
            if ok.is_ok() {
                if let Ok(n) = link.round_trip(buf, len) {
                    let _ = rx.receive_frame(&buf[..n]);
                }
            }
        }
        if !sent {
            std::thread::sleep(Duration::from_micros(20));
        }
    }
}

/// A SubDevice's SubDevice→master mailbox (SM1), read back at bring-up.
#[derive(Debug, Clone, Copy)]
struct MailboxIn {
    /// Physical start address and length of the buffer.
    start: u16,
    len: u16,
}

/// Per SubDevice with a mailbox: the SM1 watch and drain that read CoE Emergencies in the cyclic
/// frame's cycle and before every SDO, so that ethercrab meets none left over (one that comes
/// during an SDO is [`EthercatBus::emergency_in_sdo`]'s).
#[derive(Debug, Default)]
struct MailboxWatch {
    /// Per SubDevice: its SM1, `None` without a mailbox (or one over [`MAX_MAILBOX_READ`]).
    sm1: Vec<Option<MailboxIn>>,
    /// Per SubDevice: where the cyclic frame's read of its SM1 status sits.
    spans: Vec<Option<DatagramSpan>>,
    /// Per SubDevice: the last cyclic frame saw SM1 full.
    full: Vec<bool>,
    /// Per SubDevice: the axes of its slots (slot 0 = axis A) and whether it is multi-axis.
    slots: Vec<(Vec<Option<usize>>, bool)>,
    /// Decoded messages not yet taken.
    notices: VecDeque<MailboxNotice>,
    /// Notices dropped because [`NOTICE_QUEUE`] was full.
    dropped: u64,
}

/// One axis' place in the process image and its images.
#[derive(Debug)]
struct AxisImage {
    /// The SubDevice (position in the line) and the axis' slot on it.
    station: usize,
    slot: u8,
    outputs: Range<usize>,
    inputs: Range<usize>,
    rx: Vec<u8>,
    tx: Vec<u8>,
}

/// An EtherCAT segment in OP as a [`Bus`].
pub struct EthercatBus {
    link: Box<dyn Link>,
    tx: PduTx<'static>,
    rx: PduRx<'static>,
    maindevice: MainDevice<'static>,
    group: SubDeviceGroup<MAX_SUBDEVICES, MAX_PDI, DefaultLock, Op, HasDc>,
    config: SegmentConfig,
    axes: Vec<AxisImage>,
    /// SubDevices on the segment.
    stations: usize,
    /// Per SubDevice: its configured station address, where its AL status is read each cycle.
    station_addresses: Vec<u16>,
    /// Per SubDevice: where its AL status read sits in the current frame.
    al_spans: Vec<Option<DatagramSpan>>,
    /// Per SubDevice: the AL status the last returned frame read (ETG.1000.6 §6.4: 0130h, 0134h).
    al: Vec<Option<AlStatus>>,
    pdi: Vec<u8>,
    frame: Vec<u8>,
    expected_wkc: u16,
    counters: FrameCounters,
    index: u8,
    dc: DcAlignment,
    /// The correction the RT loop took since the last exchange, ns.
    dc_taken: i64,
    mailbox: MailboxWatch,
}

/// The RT loop's deadline aligned to the DC system time: each cyclic frame carries an FRMW of
/// the reference clock's system time (0910h, which also keeps the other clocks on it), whose
/// phase in the SYNC0 grid (start 0990h, cycle 09A0h) gives how far the master's cycle is off
/// [`SYNC0_FRAME_PHASE_DIVISOR`]; the next deadline is moved by the correction
/// ([`Bus::deadline_correction_ns`]): at once on the first frame, then by a share of the error.
#[derive(Debug, Clone, Copy, Default)]
struct DcAlignment {
    /// Configured address of the reference clock (the first SubDevice).
    reference: u16,
    /// SYNC0 start time in DC system time, ns.
    start: u64,
    /// SYNC0 cycle, ns.
    cycle: u64,
    /// The correction not yet taken by the RT loop, ns.
    pending: i64,
    /// The last phase error, ns (frame phase − target, in (−cycle/2, cycle/2]).
    error: i64,
    /// A first phase has been measured.
    locked: bool,
}

impl DcAlignment {
    /// Takes the reference clock's system time `t` seen by this cycle's frame.
    fn observe(&mut self, t: u64) {
        if self.cycle == 0 || t < self.start {
            return;
        }
        let cycle = self.cycle as i64;
        let phase = ((t - self.start) % self.cycle) as i64;
        let mut error = phase - cycle / SYNC0_FRAME_PHASE_DIVISOR as i64;
        if error > cycle / 2 {
            error -= cycle;
        } else if error <= -cycle / 2 {
            error += cycle;
        }
        self.error = error;
        let step = if self.locked {
            let max = cycle / DC_MAX_STEP_DIVISOR;
            (-error / DC_PHASE_GAIN_DIVISOR).clamp(-max, max)
        } else {
            self.locked = true;
            -error
        };
        self.pending += step;
    }
}

impl std::fmt::Debug for EthercatBus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("EthercatBus")
            .field("axes", &self.axes.len())
            .field("pdi", &self.pdi.len())
            .field("counters", &self.counters)
            .finish_non_exhaustive()
    }
}

impl EthercatBus {
    /// Checks `config` against the models, then brings the segment on `link` to OP.
    pub fn bring_up(config: SegmentConfig, mut link: Box<dyn Link>) -> Result<Self, EthercatError> {
        for d in &config.drives {
            if !d.profile.supports_cycle_time(config.cycle) {
                return Err(EthercatError::CycleTime {
                    axis: d.axis.clone(),
                    model: d.profile.model.as_str(),
                    cycle_us: config.cycle.as_micros(),
                    allowed: d.profile.cycle_times_text(),
                });
            }
            if !d.profile.supports_mode(d.mode) {
                return Err(EthercatError::Mode {
                    axis: d.axis.clone(),
                    model: d.profile.model.as_str(),
                    mode: d.mode.as_str(),
                    allowed: d.profile.modes_text(),
                });
            }
        }
        let plans = plan_stations(&config)?;
        check_unit_pdo_limits(&config, &plans)?;
        let storage: &'static PduStorage<MAX_FRAMES, MAX_PDU_DATA> =
            Box::leak(Box::new(PduStorage::new()));
        let (mut tx, mut rx, pdu_loop) =
            storage.try_split().map_err(|()| EthercatError::Bringup {
                step: "PDU storage".into(),
                source: ethercrab::error::Error::Internal,
            })?;
        let maindevice = MainDevice::new(
            pdu_loop,
            Timeouts {
                wait_loop_delay: Duration::from_micros(100),
                mailbox_response: Duration::from_millis(1000),
                mailbox_echo: Duration::from_millis(1000),
                eeprom: BRINGUP_EEPROM_TIMEOUT,
                pdu: BRINGUP_PDU_TIMEOUT,
                ..Timeouts::default()
            },
            MainDeviceConfig {
                dc_static_sync_iterations: 100,
                // A frame lost on the wire during bring-up is sent again.
                retry_behaviour: RetryBehaviour::Count(BRINGUP_RETRIES),
            },
        );
        let mut buf = vec![0u8; FRAME_BUF];
        let link_ref: &mut dyn Link = link.as_mut();
        let group = step(
            "bring-up to PRE-OP",
            pump(
                maindevice.init_single_group::<MAX_SUBDEVICES, MAX_PDI>(ethercat_now),
                &mut tx,
                &mut rx,
                link_ref,
                &mut buf,
            ),
        )?;
        let found = group.len();
        if found != plans.len() {
            return Err(EthercatError::Count {
                expected: plans.len(),
                found,
            });
        }
        for (position, (sd, plan)) in group.iter(&maindevice).zip(&plans).enumerate() {
            let d = &config.drives[plan.first_axis()];
            let id = sd.identity();
            let found = SubDeviceIdentity {
                vendor_id: id.vendor_id,
                product_code: id.product_id,
                revision: id.revision,
                serial: id.serial,
            };
            if !d.identity.matches(&found) {
                return Err(EthercatError::Identity {
                    position,
                    axis: d.axis.clone(),
                    model: d.profile.model.as_str(),
                    found_vendor: found.vendor_id,
                    found_product: found.product_code,
                    expected_vendor: d.identity.vendor_id,
                    expected_product: d
                        .identity
                        .product_code
                        .map(|p| format!(", product {p:#010x}"))
                        .unwrap_or_default(),
                });
            }
        }
        for (position, plan) in plans.iter().enumerate() {
            let sd = step("SubDevice lookup", group.subdevice(&maindevice, position))?;
            let axis = &config.drives[plan.first_axis()].axis;
            let configure = configure_station(&sd, &config, plan);
            step(
                format!("PDO configuration of axis '{axis}' (SubDevice {position})"),
                pump(configure, &mut tx, &mut rx, link_ref, &mut buf),
            )?;
        }
        // Distributed clocks: SYNC0 at the cell's cycle time on every drive.
        let mut group = group;
        for mut sd in group.iter_mut(&maindevice) {
            sd.set_dc_sync(DcSync::Sync0);
        }
        let cycle = config.cycle.as_duration();
        let up = async {
            let g = group.into_pre_op_pdi(&maindevice).await?;
            let g = g
                .configure_dc_sync(
                    &maindevice,
                    DcConfiguration {
                        start_delay: SYNC0_START_DELAY,
                        sync0_period: cycle,
                        sync0_shift: Duration::ZERO,
                    },
                )
                .await?;
            g.into_safe_op(&maindevice)
                .await?
                .into_op(&maindevice)
                .await
        };
        let group = step(
            "PRE-OP → SAFE-OP → OP",
            pump(up, &mut tx, &mut rx, link_ref, &mut buf),
        )?;

        // Where each station's images sit in the logical process image: read back its FMMUs;
        // each axis has its part, the slots' PDOs in assignment order.
        let mut axes: Vec<Option<AxisImage>> = config.drives.iter().map(|_| None).collect();
        let mut pdi_len = 0usize;
        let mut expected_wkc = 0u16;
        for (position, plan) in plans.iter().enumerate() {
            let sd = step("SubDevice lookup", group.subdevice(&maindevice, position))?;
            let mut outputs = 0..0;
            let mut inputs = 0..0;
            for n in 0..4u8 {
                let r = reg::fmmu(n);
                let read = async {
                    let start: u32 = sd.register_read(r).await?;
                    let len: u16 = sd.register_read(r + 4).await?;
                    let kind: u8 = sd.register_read(r + 11).await?;
                    let enable: u8 = sd.register_read(r + 12).await?;
                    Ok::<_, ethercrab::error::Error>((
                        start as usize,
                        usize::from(len),
                        kind,
                        enable,
                    ))
                };
                let (start, len, kind, enable) = step(
                    "FMMU read-back",
                    pump(read, &mut tx, &mut rx, link_ref, &mut buf),
                )?;
                if enable & 1 == 0 {
                    continue;
                }
                match kind & 3 {
                    2 => outputs = start..start + len,
                    1 => inputs = start..start + len,
                    _ => {}
                }
            }
            let lens: Vec<(usize, usize)> = (0..plan.slots.len())
                .map(|slot| {
                    let p = plan.slot_profile(&config, slot);
                    (p_len(&p.rx_pdo), p_len(&p.tx_pdo))
                })
                .collect();
            let rx_len: usize = lens.iter().map(|l| l.0).sum();
            let tx_len: usize = lens.iter().map(|l| l.1).sum();
            if outputs.len() != rx_len || inputs.len() != tx_len {
                let d = &config.drives[plan.first_axis()];
                return Err(EthercatError::ProcessImage {
                    position,
                    axis: d.axis.clone(),
                    what: format!(
                        "process image of {} output and {} input bytes, the {} maps need {rx_len} and {tx_len}",
                        outputs.len(),
                        inputs.len(),
                        d.profile.model.as_str()
                    ),
                });
            }
            pdi_len = pdi_len.max(outputs.end).max(inputs.end);
            expected_wkc += 3;
            let (mut o, mut i) = (outputs.start, inputs.start);
            for (slot, (&(rl, tl), a)) in lens.iter().zip(&plan.slots).enumerate() {
                if let Some(a) = *a {
                    axes[a] = Some(AxisImage {
                        station: position,
                        slot: slot as u8,
                        outputs: o..o + rl,
                        inputs: i..i + tl,
                        rx: vec![0; rl],
                        tx: vec![0; tl],
                    });
                }
                o += rl;
                i += tl;
            }
        }
        let axes: Vec<AxisImage> = axes.into_iter().flatten().collect();
        // The SYNC0 grid of the reference clock (the first SubDevice, ethercrab's choice).
        let reference = step("SubDevice lookup", group.subdevice(&maindevice, 0))?;
        let reference_address = reference.configured_address();
        let read = async {
            let start: u64 = reference.register_read(reg::DC_SYNC_START_TIME).await?;
            let cycle: u32 = reference.register_read(reg::DC_SYNC0_CYCLE).await?;
            Ok::<_, ethercrab::error::Error>((start, cycle))
        };
        let (start, sync0_cycle) = step(
            "DC SYNC0 read-back",
            pump(read, &mut tx, &mut rx, link_ref, &mut buf),
        )?;
        let mut station_addresses = Vec::with_capacity(plans.len());
        let mut sm1 = Vec::with_capacity(plans.len());
        for position in 0..plans.len() {
            let sd = step("SubDevice lookup", group.subdevice(&maindevice, position))?;
            station_addresses.push(sd.configured_address());
            let r = reg::sync_manager(1);
            let read = async {
                let start: u16 = sd.register_read(r).await?;
                let len: u16 = sd.register_read(r + 2).await?;
                let control: u8 = sd.register_read(r + 4).await?;
                let activate: u8 = sd.register_read(r + 6).await?;
                Ok::<_, ethercrab::error::Error>((start, len, control, activate))
            };
            let (start, len, control, activate) = step(
                "SM1 read-back",
                pump(read, &mut tx, &mut rx, link_ref, &mut buf),
            )?;
            // A mailbox (control bits 0–1 = 10b), enabled, that the drain can read in one go.
            let mailbox = control & 0x03 == 0x02
                && activate & 1 != 0
                && (8..=MAX_MAILBOX_READ).contains(&usize::from(len));
            sm1.push(mailbox.then_some(MailboxIn { start, len }));
        }
        let mailbox = MailboxWatch {
            spans: vec![None; sm1.len()],
            full: vec![false; sm1.len()],
            slots: plans
                .iter()
                .map(|p| (p.slots.clone(), p.model.is_multi_axis()))
                .collect(),
            sm1,
            notices: VecDeque::with_capacity(NOTICE_QUEUE),
            dropped: 0,
        };
        let dc = DcAlignment {
            reference: reference_address,
            start,
            cycle: u64::from(sync0_cycle),
            ..DcAlignment::default()
        };
        Ok(EthercatBus {
            link,
            tx,
            rx,
            maindevice,
            group,
            config,
            axes,
            stations: plans.len(),
            al_spans: vec![None; station_addresses.len()],
            al: vec![None; station_addresses.len()],
            station_addresses,
            pdi: vec![0; pdi_len],
            frame: buf,
            expected_wkc,
            counters: FrameCounters::default(),
            index: 0,
            dc,
            dc_taken: 0,
            mailbox,
        })
    }

    /// Notices dropped because the queue of untaken ones was full (diagnostics).
    pub fn mailbox_notices_dropped(&self) -> u64 {
        self.mailbox.dropped
    }

    /// Reads SubDevice `station`'s SM1 status and, in the same frame, its buffer (which frees
    /// it; ETG.1000.4 §6.7.2): the message if SM1 was full. One acyclic round trip, no heap
    /// allocation. `Ok(false)`: SM1 was empty (or the station has no mailbox).
    fn read_mailbox(&mut self, station: usize) -> Result<bool, BusError> {
        let Some(Some(mb)) = self.mailbox.sm1.get(station).copied() else {
            return Ok(false);
        };
        let adp = u32::from(self.station_addresses[station]);
        let (status, data, len) = {
            let mut b = FrameBuilder::new(&mut self.frame, MASTER_MAC);
            let status = b.push(
                Command::Fprd,
                0,
                (u32::from(reg::sync_manager(1) + 5) << 16) | adp,
                &[0],
            );
            let data = b.push(
                Command::Fprd,
                0,
                (u32::from(mb.start) << 16) | adp,
                &MAILBOX_READ_ZEROS[..usize::from(mb.len)],
            );
            let (Some(status), Some(data)) = (status, data) else {
                return Err(BusError::FrameTooLarge {
                    bytes: usize::from(mb.len) + 1,
                });
            };
            (status, data, b.finish())
        };
        if self.link.round_trip(&mut self.frame, len).is_err() {
            return Err(BusError::FrameLost);
        }
        let full = frame::wkc(&self.frame, &status) == 1
            && self.frame[status.data_offset] & SM_STATUS_FULL != 0;
        if !full || frame::wkc(&self.frame, &data) != 1 {
            return Ok(false);
        }
        let message =
            MailboxMessage::decode(&self.frame[data.data_offset..][..usize::from(mb.len)]);
        let first = self.first_axis(station);
        let notice = match message {
            MailboxMessage::Emergency(emergency) => MailboxNotice::Emergency {
                axis: self.emergency_axis(station, &emergency),
                emergency,
            },
            MailboxMessage::Other {
                mailbox_type,
                service,
            } => MailboxNotice::Discarded {
                axis: first,
                mailbox_type,
                service,
            },
            MailboxMessage::Malformed => MailboxNotice::Discarded {
                axis: first,
                mailbox_type: 0,
                service: 0,
            },
        };
        self.push_notice(notice);
        Ok(true)
    }

    /// The axis an Emergency of SubDevice `station` is about: on a multi-axis unit the slot it
    /// names, else (or for a slot no axis uses) the SubDevice's first axis.
    fn emergency_axis(&self, station: usize, emergency: &Emergency) -> usize {
        let (slots, multi) = &self.mailbox.slots[station];
        let slot = if *multi {
            usize::from(emergency.slot())
        } else {
            0
        };
        slots
            .get(slot)
            .copied()
            .flatten()
            .unwrap_or_else(|| self.first_axis(station))
    }

    /// The first axis SubDevice `station` carries (0 if none: a unit with no slot used).
    fn first_axis(&self, station: usize) -> usize {
        self.mailbox.slots[station]
            .0
            .iter()
            .flatten()
            .copied()
            .next()
            .unwrap_or(0)
    }

    /// Queues a mailbox notice for the executive; a full queue counts it as dropped.
    fn push_notice(&mut self, notice: MailboxNotice) {
        if self.mailbox.notices.len() < NOTICE_QUEUE {
            self.mailbox.notices.push_back(notice);
        } else {
            self.mailbox.dropped += 1;
        }
    }

    /// Empties SubDevice `station`'s SM1 into the notices before an SDO transaction, so that
    /// ethercrab never reads an Emergency (bounded: [`MAX_DRAIN`] messages).
    fn drain_mailbox(&mut self, station: usize) {
        for _ in 0..MAX_DRAIN {
            if !matches!(self.read_mailbox(station), Ok(true)) {
                break;
            }
        }
        if let Some(f) = self.mailbox.full.get_mut(station) {
            *f = false;
        }
    }

    /// Counters of the cyclic exchange.
    pub fn counters(&self) -> FrameCounters {
        self.counters
    }

    /// The link (tests and fault injection reach the emulated segment through it).
    pub fn link_mut(&mut self) -> &mut dyn Link {
        self.link.as_mut()
    }

    /// The clean shutdown's bus part (after the master has sent Shutdown by controlword):
    /// every SubDevice to PRE-OP, so that none raises its leaving-OP alarm.
    pub fn leave_op(&mut self) -> Result<(), EthercatError> {
        self.request_state(AlState::PreOp)
    }

    fn request_state(&mut self, state: AlState) -> Result<(), EthercatError> {
        let mut len = {
            let mut b = FrameBuilder::new(&mut self.frame, MASTER_MAC);
            b.push(
                Command::Bwr,
                0,
                u32::from(reg::AL_CONTROL) << 16,
                &[state as u8, 0],
            );
            b.finish()
        };
        len = self.link.round_trip(&mut self.frame, len)?;
        let _ = len;
        for position in 0..self.stations {
            let adp = (position as u16).wrapping_neg();
            let mut b = FrameBuilder::new(&mut self.frame, MASTER_MAC);
            let span = b
                .push(
                    Command::Aprd,
                    1,
                    (u32::from(reg::AL_STATUS) << 16) | u32::from(adp),
                    &[0; 6],
                )
                .expect("frame buffer holds one datagram");
            let n = b.finish();
            self.link.round_trip(&mut self.frame, n)?;
            let d = &self.frame[span.data_offset..span.data_offset + 6];
            let status = d[0];
            let code = u16::from_le_bytes([d[4], d[5]]);
            if status & 0x0F != state as u8 || status & reg::AL_ERROR_INDICATION != 0 {
                return Err(EthercatError::State {
                    position,
                    state: state.as_str(),
                    status,
                    code,
                });
            }
        }
        Ok(())
    }

    /// The SubDevice of `axis` and the index of its axis-A object `index` there (on a
    /// multi-axis unit at the axis' offset index, mr-j5-g-n1.md §1.5).
    fn station_object(&self, axis: usize, index: u16) -> Option<(usize, u16)> {
        let a = self.axes.get(axis)?;
        let p = self.config.drives.get(axis)?.profile;
        Some((a.station, p.axis_object(index, a.slot).unwrap_or(index)))
    }

    fn sdo_read_value(&mut self, axis: usize, index: u16, sub: u8) -> Result<i64, u32> {
        let d = self.config.drives.get(axis).ok_or(SDO_UNSUPPORTED)?;
        // The type of an object given at another axis' offset index is its axis-A object's.
        let base = d.profile.object_slot(index).map_or(index, |(_, b)| b);
        let data_type = object_type(d.profile, base, sub);
        let (station, index) = self.station_object(axis, index).ok_or(SDO_UNSUPPORTED)?;
        self.sdo_transfer(axis, station, async |sd| {
            Ok(match data_type {
                DataType::I8 => i64::from(sd.sdo_read::<i8>(index, sub).await?),
                DataType::U8 | DataType::Bool => i64::from(sd.sdo_read::<u8>(index, sub).await?),
                DataType::I16 => i64::from(sd.sdo_read::<i16>(index, sub).await?),
                DataType::U16 => i64::from(sd.sdo_read::<u16>(index, sub).await?),
                DataType::U32 => i64::from(sd.sdo_read::<u32>(index, sub).await?),
                DataType::I32 | DataType::Unstated => {
                    i64::from(sd.sdo_read::<i32>(index, sub).await?)
                }
            })
        })
    }

    /// One SDO transfer with SubDevice `station` for `axis`: SM1 emptied first (so ethercrab
    /// meets no Emergency left there), repeated once where an Emergency came in its response's
    /// place. `Err(abort code)`.
    fn sdo_transfer<T>(
        &mut self,
        axis: usize,
        station: usize,
        transfer: impl AsyncFn(
            &SubDeviceRef<'_, SubDevicePdi<'_, MAX_PDI, DefaultLock>>,
        ) -> Result<T, ethercrab::error::Error>,
    ) -> Result<T, u32> {
        let mut emergency_met = false;
        loop {
            self.drain_mailbox(station);
            let sd = self
                .group
                .subdevice(&self.maindevice, station)
                .map_err(|_| SDO_UNSUPPORTED)?;
            let result = pump(
                transfer(&sd),
                &mut self.tx,
                &mut self.rx,
                self.link.as_mut(),
                &mut self.frame,
            );
            if !self.emergency_in_sdo(axis, &result, &mut emergency_met) {
                return result.map_err(abort_code);
            }
        }
    }

    /// An SDO of `axis` that met a CoE Emergency where its response should be (the drive
    /// raised an alarm after the request; patched ethercrab returns it as an error): the
    /// Emergency becomes a notice of the axis it names and the SDO is repeated once. True:
    /// repeat it.
    fn emergency_in_sdo<T>(
        &mut self,
        axis: usize,
        result: &Result<T, ethercrab::error::Error>,
        met: &mut bool,
    ) -> bool {
        let Err(ethercrab::error::Error::Mailbox(ethercrab::error::MailboxError::Emergency {
            error_code,
            error_register,
            data,
        })) = *result
        else {
            return false;
        };
        let emergency = Emergency {
            error_code,
            error_register,
            data,
        };
        let axis = self
            .axes
            .get(axis)
            .map_or(axis, |a| self.emergency_axis(a.station, &emergency));
        self.push_notice(MailboxNotice::Emergency { axis, emergency });
        let repeat = !*met;
        *met = true;
        repeat
    }
}

/// The data type of `index:sub`: the communication objects by CiA 301 / ETG.1000.6, the
/// mapped objects by their mapping size, the rest from the profile (INTEGER32 where unknown).
fn object_type(profile: &DriveProfile, index: u16, sub: u8) -> DataType {
    let mapped_bits = profile
        .rx_pdo
        .entries
        .iter()
        .chain(profile.tx_pdo.entries)
        .find(|e| !e.is_padding() && e.index == index && e.sub == sub)
        .map(|e| e.bits);
    match (index, sub) {
        (crate::pdo::objects::ERROR_CODE, 0) => DataType::U16,
        (0x1018 | 0x1C12 | 0x1C13 | 0x1600..=0x17FF | 0x1A00..=0x1BFF, 0) => DataType::U8,
        (0x1C12 | 0x1C13, _) => DataType::U16,
        (0x1000 | 0x1018 | 0x1600..=0x17FF | 0x1A00..=0x1BFF, _) => DataType::U32,
        _ => match (profile.object(index, sub), mapped_bits) {
            (Some(o), _) if o.data_type != DataType::Unstated => o.data_type,
            (_, Some(8)) => DataType::I8,
            (_, Some(16)) => DataType::I16,
            _ => DataType::I32,
        },
    }
}

fn p_len(map: &crate::pdo::PdoMap) -> usize {
    map.byte_len()
}

/// The SDO abort code of an ethercrab error (0800 0000h general error for others).
fn abort_code(e: ethercrab::error::Error) -> u32 {
    match e {
        ethercrab::error::Error::Mailbox(ethercrab::error::MailboxError::Aborted {
            code, ..
        }) => u32::from(code),
        _ => 0x0800_0000,
    }
}

impl EthercatBus {
    /// The AL status of the SubDevice that carries `axis`, as the last cyclic frame read it
    /// (ETG.1000.6 §6.4); `None` before it answered.
    pub fn al_status(&self, axis: usize) -> Option<AlStatus> {
        self.axes.get(axis).and_then(|a| self.al[a.station])
    }
}

impl CyclicBus for EthercatBus {
    fn axis_count(&self) -> usize {
        self.axes.len()
    }

    fn rx_image_mut(&mut self, axis: usize) -> &mut [u8] {
        self.axes
            .get_mut(axis)
            .map_or(&mut [], |a| a.rx.as_mut_slice())
    }

    fn tx_image(&self, axis: usize) -> &[u8] {
        self.axes.get(axis).map_or(&[], |a| a.tx.as_slice())
    }

    fn exchange(&mut self, elapsed: Cycles) -> Result<(), BusError> {
        // The time since the last frame: the cycles passed, moved by the deadline correction the
        // RT loop took (a virtual clock follows it; a real one ignores it).
        let period = u64::from(elapsed.0) * self.config.cycle.as_nanos();
        self.link
            .advance(period.saturating_add_signed(self.dc_taken));
        self.dc_taken = 0;
        if elapsed.0 > 1 {
            self.link.host_stall(u64::from(elapsed.0 - 1));
        }
        for a in &self.axes {
            self.pdi[a.outputs.clone()].copy_from_slice(&a.rx);
        }
        self.index = self.index.wrapping_add(1);
        let (span, dc_span, len) = {
            let mut b = FrameBuilder::new(&mut self.frame, MASTER_MAC);
            let Some(span) = b.push(Command::Lrw, self.index, 0, &self.pdi) else {
                return Err(BusError::FrameTooLarge {
                    bytes: self.pdi.len(),
                });
            };
            let address = (u32::from(reg::DC_SYSTEM_TIME) << 16) | u32::from(self.dc.reference);
            let Some(dc_span) = b.push(Command::Frmw, self.index, address, &[0; 8]) else {
                return Err(BusError::FrameTooLarge {
                    bytes: self.pdi.len() + 8,
                });
            };
            // Each SubDevice's AL status and code (monitoring, ETG.1000.6 §6.4).
            for (slot, &station) in self.al_spans.iter_mut().zip(&self.station_addresses) {
                let address = (u32::from(reg::AL_STATUS) << 16) | u32::from(station);
                *slot = b.push(
                    Command::Fprd,
                    self.index,
                    address,
                    &[0; reg::AL_STATUS_READ_LEN],
                );
                if slot.is_none() {
                    return Err(BusError::FrameTooLarge {
                        bytes: self.pdi.len()
                            + 8
                            + self.station_addresses.len() * reg::AL_STATUS_READ_LEN,
                    });
                }
            }
            // Each mailbox SubDevice's SM1 status: full means a message it sent unasked (an
            // Emergency), read by `take_mailbox_notice` (ETG.1000.4 §6.7.2).
            for ((slot, &station), mb) in self
                .mailbox
                .spans
                .iter_mut()
                .zip(&self.station_addresses)
                .zip(&self.mailbox.sm1)
            {
                *slot = None;
                if mb.is_none() {
                    continue;
                }
                let address = (u32::from(reg::sync_manager(1) + 5) << 16) | u32::from(station);
                *slot = b.push(Command::Fprd, self.index, address, &[0]);
                if slot.is_none() {
                    return Err(BusError::FrameTooLarge {
                        bytes: self.pdi.len() + 8 + self.station_addresses.len() * 8,
                    });
                }
            }
            (span, dc_span, b.finish())
        };
        self.counters.frames += 1;
        if self.link.round_trip(&mut self.frame, len).is_err() {
            self.counters.lost += 1;
            return Err(BusError::FrameLost);
        }
        if frame::wkc(&self.frame, &dc_span) != 0 {
            let at = dc_span.data_offset;
            let mut t = [0u8; 8];
            t.copy_from_slice(&self.frame[at..at + 8]);
            self.dc.observe(u64::from_le_bytes(t));
        }
        for (al, span) in self.al.iter_mut().zip(&self.al_spans) {
            if let Some(span) = span.filter(|s| frame::wkc(&self.frame, s) == 1) {
                let mut b = [0u8; reg::AL_STATUS_READ_LEN];
                b.copy_from_slice(&self.frame[span.data_offset..][..reg::AL_STATUS_READ_LEN]);
                *al = Some(AlStatus::from_bytes(&b));
            }
        }
        for (full, span) in self.mailbox.full.iter_mut().zip(&self.mailbox.spans) {
            if let Some(span) = span.filter(|s| frame::wkc(&self.frame, s) == 1) {
                *full |= self.frame[span.data_offset] & SM_STATUS_FULL != 0;
            }
        }
        let wkc = frame::wkc(&self.frame, &span);
        if wkc != self.expected_wkc {
            self.counters.wkc_errors += 1;
            return Err(BusError::WorkingCounter {
                expected: self.expected_wkc,
                found: wkc,
            });
        }
        let data = &self.frame[span.data_offset..span.data_offset + self.pdi.len()];
        for a in &mut self.axes {
            a.tx.copy_from_slice(&data[a.inputs.clone()]);
        }
        Ok(())
    }

    fn frame_counters(&self) -> Option<FrameCounters> {
        Some(self.counters)
    }

    fn link_state(&self, axis: usize) -> Option<LinkState> {
        self.al_status(axis).map(LinkState::from)
    }

    /// A notice already read (before an SDO), else one acyclic read of the first SubDevice
    /// whose SM1 the last cyclic frame saw full. A lost read frame is tried again next cycle.
    fn take_mailbox_notice(&mut self) -> Option<MailboxNotice> {
        if let Some(n) = self.mailbox.notices.pop_front() {
            return Some(n);
        }
        let station = self.mailbox.full.iter().position(|&f| f)?;
        if self.read_mailbox(station).is_ok() {
            self.mailbox.full[station] = false;
        }
        self.mailbox.notices.pop_front()
    }

    fn deadline_correction_ns(&mut self) -> i64 {
        let c = std::mem::take(&mut self.dc.pending);
        self.dc_taken += c;
        c
    }

    /// The cyclic frame's phase error in the SYNC0 cycle; `None` before the first frame has
    /// passed the reference clock.
    fn dc_phase_error_ns(&self) -> Option<i64> {
        self.dc.locked.then_some(self.dc.error)
    }
}

impl AcyclicBus for EthercatBus {
    fn sdo_upload(&mut self, axis: usize, index: u16, sub: u8) -> Result<i64, u32> {
        self.sdo_read_value(axis, index, sub)
    }

    fn sdo_download(&mut self, axis: usize, index: u16, sub: u8, data: &[u8]) -> Result<(), u32> {
        let (station, index) = self.station_object(axis, index).ok_or(SDO_UNSUPPORTED)?;
        self.sdo_transfer(axis, station, async |sd| match *data {
            [a] => sd.sdo_write(index, sub, a).await,
            [a, b] => sd.sdo_write(index, sub, u16::from_le_bytes([a, b])).await,
            [a, b, c, d] => {
                sd.sdo_write(index, sub, u32::from_le_bytes([a, b, c, d]))
                    .await
            }
            _ => Err(ethercrab::error::Error::Internal),
        })
    }

    fn close(&mut self) -> Result<(), String> {
        self.leave_op().map_err(|e| e.to_string())
    }

    fn read_error_code(&mut self, axis: usize) -> Option<u16> {
        self.sdo_read_value(axis, crate::pdo::objects::ERROR_CODE, 0)
            .ok()
            .map(|v| v as u16)
    }
}

impl FaultInjection for EthercatBus {
    /// On the in-process segment: the emulated drive of `axis` raises `code`.
    fn inject_alarm(&mut self, axis: usize, code: u16) -> bool {
        let Some(&AxisImage { station, slot, .. }) = self.axes.get(axis) else {
            return false;
        };
        match self
            .link
            .segment_mut()
            .and_then(|s| s.station_mut(station))
            .and_then(|st| st.drive_at_mut(usize::from(slot)))
        {
            Some(d) => {
                d.inject_alarm(code);
                true
            }
            None => false,
        }
    }

    /// The next `cycles` cyclic frames are lost on the wire: every SubDevice misses them (one
    /// frame carries the whole segment's process data), not only `axis`'.
    fn inject_rx_loss(&mut self, axis: usize, cycles: u32) -> bool {
        axis < self.axes.len() && self.link.drop_frames(cycles)
    }

    /// The SubDevice of `axis` (with every axis of its unit) stops answering.
    fn inject_subdevice_stall(&mut self, axis: usize, cycles: u32) -> bool {
        self.axes
            .get(axis)
            .is_some_and(|a| self.link.stall_subdevice(a.station, cycles))
    }

    fn inject_frame_delay(&mut self, delay_ns: u64, cycles: u32) -> bool {
        self.link.delay_frames(delay_ns, cycles)
    }

    fn inject_frame_corruption(&mut self, axis: usize, cycles: u32) -> bool {
        self.axes
            .get(axis)
            .is_some_and(|a| self.link.corrupt_frames(a.station, cycles))
    }

    fn inject_datagram_drop(&mut self, cycles: u32) -> bool {
        self.link.drop_datagrams(cycles)
    }

    fn inject_link_loss(&mut self, axis: usize, cycles: u32) -> bool {
        self.axes
            .get(axis)
            .is_some_and(|a| self.link.lose_link(a.station, cycles))
    }
}
