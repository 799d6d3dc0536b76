//! One emulated EtherCAT SubDevice: an ESC (registers, SII EEPROM, FMMUs, SyncManagers with
//! mailbox semantics, DC registers, the AL state machine) in front of a simulated drive, or of
//! the drives of every axis of a multi-axis unit (MR-J5W2/W3-G-N1, MR-J5-G-N1 manual §2.2, §3.1, §4.3, §4.4: one ESM
//! for the station, one PDS per axis, the axes' PDOs concatenated in assignment order).
//!
//! The ESC is modelled as its 12 KiB address space (registers 0000h–0FFFh, process RAM from
//! 1000h); datagrams read and write it, and the registers with side effects (AL control, SII
//! control, DC latch, mailbox buffers) act on access.

use std::collections::VecDeque;

use super::coe::{PdoConfig, SegmentedUpload};
use super::layout::StationLayout;
use super::sii::{self, SiiPdo};
use super::variant::{EmulatedDc, SubDeviceVariant};
use crate::sim::drive::SimDrive;
use cellrt_cia402::cycles::Cycles;
use cellrt_cia402::profiles::mapping::PdoDirection;
use cellrt_ethercat::frame::Command;
use cellrt_ethercat::identity::SubDeviceIdentity;
use cellrt_ethercat::register::{self as reg, al_code, AlState, AL_ERROR_INDICATION};

mod esc;
mod mailbox;
#[cfg(test)]
mod tests;

use mailbox::Outbox;

/// Bytes of the emulated address space.
const MEMORY_LEN: usize = 0x3000;
/// Process RAM in KiB (register 0006h).
const RAM_KIB: u8 = 8;
/// ESC type (0000h): an ET1100-class ESC.
const ESC_TYPE: u8 = 0x11;
/// Features (0008h): FMMU bit-wise, DC supported, 64-bit DC.
const FEATURES: u16 = 0x0001 | FEATURE_DC | 0x0008;
/// Feature bit 2 (0008h): distributed clocks.
const FEATURE_DC: u16 = 0x0004;
/// Propagation delay per hop in the emulated line, ns (a named parameter; real ESC + cable
/// delays are tens to hundreds of ns).
pub const HOP_DELAY_NS: u64 = 100;
/// SII control bit: read (0502h bit 8).
const SII_READ: u16 = 0x0100;
/// SII control bit: 8-byte reads (0502h bit 6).
const SII_READ_8: u16 = 0x0040;
/// At most this many missed SYNC0 cycles are replayed as lost RxPDOs after a gap (1 s at
/// 1 ms; every model's communication alarm has fired long before).
const MAX_LOST_REPLAY: u64 = 1000;
/// Frames in OP taken one SYNC0 each while the master locks onto the SYNC0 grid, before misses count.
const LOCK_FRAMES: u32 = 16;
/// SM status bit 3: mailbox full.
const SM_FULL: u8 = 0x08;
/// Emergencies a station holds while SM1 is occupied (preallocated; one more is dropped and
/// counted in [`Station::emergencies_lost`]). 8: a J5W3 can raise one alarm per axis and its
/// leaving-OP alarms at once with room to spare.
pub const EMERGENCY_QUEUE: usize = 8;

/// What processing one datagram did at this station.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Access {
    /// Working-counter increment.
    pub wkc: u16,
}

/// A multi-axis unit that cannot be built from the drives given.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum UnitError {
    /// No drive given.
    #[error("a station needs at least one drive")]
    Empty,
    /// The drives are not all of one model.
    #[error("the drives of one station must be of one model ({first} and {other} given)")]
    MixedModels {
        /// The first drive's model.
        first: &'static str,
        /// Another model.
        other: &'static str,
    },
    /// Not one drive per axis of the unit.
    #[error("{model} has {per_unit} axis/axes per unit, {given} drive(s) given")]
    AxisCount {
        /// The model.
        model: &'static str,
        /// Axes per unit.
        per_unit: u8,
        /// Drives given.
        given: usize,
    },
}

/// An emulated drive, or multi-axis unit, on the segment.
#[derive(Debug)]
pub struct Station {
    mem: Vec<u8>,
    /// The segment's clock at the datagram being handled, ns.
    now_ns: u64,
    sii: Vec<u8>,
    layout: StationLayout,
    identity: SubDeviceIdentity,
    /// One drive per axis of the unit (slot 0 = axis A).
    drives: Vec<SimDrive>,
    /// Per axis: the RxPDO and TxPDO bytes it takes from SM2 / gives to SM3, in slot order.
    axis_lens: Vec<(usize, usize)>,
    pdo: PdoConfig,
    mailbox_counter: u8,
    /// A segmented SDO upload in progress.
    upload: SegmentedUpload,
    al_state: AlState,
    /// Position in the line (0 = next to the master) and line length, for DC receive times.
    position: u16,
    line_len: u16,
    /// The last SYNC0 edge (cycles since the DC start time) a frame was taken at.
    last_edge: Option<u64>,
    /// SYNC0 edges before the next frame that are a stall of the master's host, not lost frames.
    excused_sync0: u64,
    /// Frames taken while the master locks on.
    lock_frames: u32,
    /// Exchanges the drive has run (diagnostics).
    exchanges: u64,
    /// SYNC0 edges that brought the drive no RxPDO (diagnostics).
    missed_sync0: u64,
    /// Local time of the last write to SM2 that triggered the process-data watchdog (in OP).
    pd_watchdog_trigger: Option<u64>,
    /// The mailbox traffic to the master waiting for SM1 ([`Station::fill_mailbox_in`]).
    outbox: Outbox,
    /// How this SubDevice departs from its profile ([`Station::present`]).
    variant: SubDeviceVariant,
    /// The ESI device this station presents ([`Station::describe_by`]), if any.
    esi: Option<std::sync::Arc<cellrt_ethercat::esi::EsiDevice>>,
}

impl Station {
    /// A station in INIT with `drive` behind it at `position` of a line of `line_len`.
    pub fn new(drive: SimDrive, position: u16, line_len: u16) -> Self {
        Self::build(vec![drive], position, line_len)
    }

    /// A station in INIT presenting a multi-axis unit: `drives` are its axes in slot order
    /// (axis A first), one per axis of the model.
    pub fn unit(drives: Vec<SimDrive>, position: u16, line_len: u16) -> Result<Self, UnitError> {
        let first = drives.first().ok_or(UnitError::Empty)?.profile();
        if let Some(other) = drives.iter().find(|d| d.profile().model != first.model) {
            return Err(UnitError::MixedModels {
                first: first.model.as_str(),
                other: other.profile().model.as_str(),
            });
        }
        if drives.len() != usize::from(first.axes_per_unit) {
            return Err(UnitError::AxisCount {
                model: first.model.as_str(),
                per_unit: first.axes_per_unit,
                given: drives.len(),
            });
        }
        Ok(Self::build(drives, position, line_len))
    }

    fn build(mut drives: Vec<SimDrive>, position: u16, line_len: u16) -> Self {
        let profile = drives[0].profile().clone();
        let identity = SubDeviceIdentity::of_profile(&profile);
        let pdo = PdoConfig::new(&drives);
        let axis_lens: Vec<(usize, usize)> = (0..drives.len())
            .map(|slot| {
                let (rx, tx) = pdo.byte_lens(slot as u8);
                (usize::from(rx), usize::from(tx))
            })
            .collect();
        let total = |f: fn(&(usize, usize)) -> usize| axis_lens.iter().map(f).sum::<usize>();
        let layout = StationLayout::of_lengths(total(|l| l.0) as u16, total(|l| l.1) as u16);
        let pdos = |d: PdoDirection| -> Vec<SiiPdo> {
            drives
                .iter()
                .enumerate()
                .map(|(slot, drive)| {
                    let p = drive.profile();
                    let map = match d {
                        PdoDirection::Rx => &p.pdo.rx,
                        PdoDirection::Tx => &p.pdo.tx,
                    };
                    SiiPdo::of_slot(p, map, slot as u8)
                })
                .collect()
        };
        let sii = sii::image(
            identity,
            profile.comm.sdo_info.offered,
            profile.name,
            &layout,
            &pdos(PdoDirection::Rx),
            &pdos(PdoDirection::Tx),
        );
        for d in &mut drives {
            d.leave_op();
        }
        let mailbox_in_len = usize::from(layout.mailbox_in.len);
        let mut s = Station {
            mem: vec![0; MEMORY_LEN],
            now_ns: 0,
            sii,
            layout,
            identity,
            pdo,
            drives,
            axis_lens,
            mailbox_counter: 0,
            upload: SegmentedUpload::default(),
            al_state: AlState::Init,
            position,
            line_len,
            last_edge: None,
            excused_sync0: 0,
            lock_frames: 0,
            exchanges: 0,
            missed_sync0: 0,
            pd_watchdog_trigger: None,
            variant: SubDeviceVariant::default(),
            outbox: Outbox {
                sends_emergencies: profile.comm.emergency.sends,
                emergencies: VecDeque::with_capacity(EMERGENCY_QUEUE),
                lost: 0,
                alarms: Vec::new(),
                response: vec![0; mailbox_in_len],
                response_len: 0,
                fragments: VecDeque::new(),
                counter: 0,
                response_due_ns: 0,
            },
            esi: None,
        };
        s.outbox.alarms = s.drives.iter().map(SimDrive::alarm).collect();
        s.mem[usize::from(reg::TYPE)] = ESC_TYPE;
        s.mem[usize::from(reg::FMMU_COUNT)] = 8;
        s.mem[usize::from(reg::SM_COUNT)] = 8;
        s.mem[usize::from(reg::RAM_SIZE)] = RAM_KIB;
        s.mem[usize::from(reg::PORT_DESCRIPTOR)] = 0x0F; // ports 0/1 EBUS... MII
        s.put16(reg::SUPPORT_FLAGS, FEATURES);
        s.put16(reg::WATCHDOG_DIVIDER, reg::WATCHDOG_DIVIDER_DEFAULT);
        s.put16(reg::SM_WATCHDOG, reg::SM_WATCHDOG_DEFAULT);
        s.put16(reg::SM_WATCHDOG_STATUS, 1);
        let last = position + 1 == line_len;
        // DL status: PDI operational, watchdog ok, link and communication on port 0, and on
        // port 1 unless this is the last station of the line.
        let mut dl = 0x0001 | 0x0002 | 0x0010 | 0x0200;
        if !last {
            dl |= 0x0020 | 0x0800;
        }
        s.put16(reg::DL_STATUS, dl);
        s.set_al_status(AlState::Init, None);
        s.put16(reg::SII_CONTROL, SII_READ_8);
        s
    }

    /// Presents the SubDevice as `variant` departs from its profile (before bring-up): a
    /// variant without distributed clocks clears the ESC's DC feature bit (0008h bit 2).
    pub fn present(&mut self, variant: SubDeviceVariant) {
        let dc = if variant.distributed_clocks == EmulatedDc::Absent {
            0
        } else {
            FEATURE_DC
        };
        self.put16(reg::SUPPORT_FLAGS, (FEATURES & !FEATURE_DC) | dc);
        if dc == 0 {
            self.sii = sii::without_dc(&self.sii);
        }
        self.variant = variant;
    }

    /// How this SubDevice departs from its profile.
    pub fn variant(&self) -> SubDeviceVariant {
        self.variant
    }

    /// The next frame comes `cycles` SYNC0 edges late because the master's host stalled (an
    /// overrun of its RT loop): those edges run the drive on, they are not lost RxPDOs.
    /// Stalls excused before one frame reaches the drive add up (frames lost in between).
    pub fn excuse_host_stall(&mut self, cycles: u64) {
        self.excused_sync0 = self.excused_sync0.saturating_add(cycles);
        // Nor do they run the process-data watchdog down; a link lost around the stall still
        // does (with SYNC0 the stall's length is known: the watchdog's start moves by it).
        if let Some(at) = self.pd_watchdog_trigger {
            let cycle_ns = u64::from(self.sync0_cycle_ns());
            self.pd_watchdog_trigger = (self.sync_active() && cycle_ns > 0)
                .then(|| at.saturating_add(cycles.saturating_mul(cycle_ns)));
        }
    }

    /// The process-data watchdog time (0420h × the 0400h divider's (n + 2) × 40 ns), ns; 0 when
    /// disabled.
    pub fn pd_watchdog_ns(&self) -> u64 {
        let unit_ns = (u64::from(self.get16(reg::WATCHDOG_DIVIDER)) + 2) * 40;
        u64::from(self.get16(reg::SM_WATCHDOG)) * unit_ns
    }

    /// Expirations of the process-data watchdog (0442h).
    pub fn pd_watchdog_expirations(&self) -> u8 {
        self.mem[usize::from(reg::SM_WATCHDOG_COUNTER)]
    }

    /// The process-data watchdog at local time `now_ns`: in OP, no output write for longer than
    /// [`Station::pd_watchdog_ns`] expires it (0440h bit 0 cleared, 0442h counted), and the
    /// application leaves OP for SAFE-OP with AL status code 001Bh (ETG.1000.6 Table 11), as
    /// a drive's firmware does when its outputs are no longer refreshed. Checked when a frame
    /// reaches the station: the ESC's timer has no effect that a master could see sooner.
    fn check_pd_watchdog(&mut self, now_ns: u64) {
        let Some(at) = self.pd_watchdog_trigger else {
            return;
        };
        let limit = self.pd_watchdog_ns();
        if self.al_state != AlState::Op || limit == 0 || now_ns.saturating_sub(at) <= limit {
            return;
        }
        self.pd_watchdog_trigger = None;
        self.put16(reg::SM_WATCHDOG_STATUS, 0);
        let c = usize::from(reg::SM_WATCHDOG_COUNTER);
        self.mem[c] = self.mem[c].saturating_add(1);
        for d in &mut self.drives {
            d.leave_op();
        }
        self.set_al_status(AlState::SafeOp, Some(al_code::SM_WATCHDOG));
        self.watch_alarms();
    }

    /// The simulated drive (axis A of a multi-axis unit).
    pub fn drive(&self) -> &SimDrive {
        &self.drives[0]
    }

    /// The simulated drive, mutably (fault injection; axis A of a multi-axis unit).
    pub fn drive_mut(&mut self) -> &mut SimDrive {
        &mut self.drives[0]
    }

    /// The drives of every axis of the unit, in slot order (one for a 1-axis drive).
    pub fn drives(&self) -> &[SimDrive] {
        &self.drives
    }

    /// The drive of axis `slot` (0 = A), mutably (fault injection).
    pub fn drive_at_mut(&mut self, slot: usize) -> Option<&mut SimDrive> {
        self.drives.get_mut(slot)
    }

    /// The AL state.
    pub fn al_state(&self) -> AlState {
        self.al_state
    }

    /// The AL status code (0 when no error is indicated).
    pub fn al_status_code(&self) -> u16 {
        self.get16(reg::AL_STATUS_CODE)
    }

    /// The configured station address.
    pub fn station_address(&self) -> u16 {
        self.get16(reg::STATION_ADDRESS)
    }

    /// The identity it presents.
    pub fn identity(&self) -> SubDeviceIdentity {
        self.identity
    }

    /// Process-data exchanges the drive has run.
    pub fn exchanges(&self) -> u64 {
        self.exchanges
    }

    /// SYNC0 edges at which the drive had no new RxPDO (counted as lost by its communication
    /// checks).
    pub fn missed_sync0(&self) -> u64 {
        self.missed_sync0
    }

    fn set_al_status(&mut self, state: AlState, error: Option<u16>) {
        self.al_state = state;
        let flag = if error.is_some() {
            AL_ERROR_INDICATION
        } else {
            0
        };
        self.mem[usize::from(reg::AL_STATUS)] = state as u8 | flag;
        self.put16(reg::AL_STATUS_CODE, error.unwrap_or(0));
    }

    fn al_control(&mut self, control: u8, now_ns: u64) {
        let _ = now_ns;
        let ack = control & AL_ERROR_INDICATION != 0;
        let error_pending = self.mem[usize::from(reg::AL_STATUS)] & AL_ERROR_INDICATION != 0;
        if error_pending && !ack {
            // ETG.1000.6 §6.4.1.4: with an error indicated, a request without the
            // acknowledge bit keeps the state and the error.
            return;
        }
        let Some(target) = AlState::from_bits(control) else {
            self.set_al_status(self.al_state, Some(al_code::UNKNOWN_STATE));
            return;
        };
        let from = self.al_state;
        let result = match (from, target) {
            (_, AlState::Bootstrap) => Err(al_code::INVALID_STATE_CHANGE),
            (_, AlState::Init) => Ok(()),
            (AlState::Init, AlState::PreOp) => {
                let (o, i) = (self.layout.mailbox_out, self.layout.mailbox_in);
                if self.sm_matches(0, o.start, o.len) && self.sm_matches(1, i.start, i.len) {
                    Ok(())
                } else {
                    Err(al_code::INVALID_MAILBOX_CONFIG)
                }
            }
            (AlState::PreOp | AlState::SafeOp | AlState::Op, AlState::PreOp) => Ok(()),
            (AlState::PreOp, AlState::SafeOp) => self.check_process_data(),
            (AlState::SafeOp | AlState::Op, AlState::SafeOp) => Ok(()),
            (AlState::SafeOp | AlState::Op, AlState::Op) => Ok(()),
            _ => Err(al_code::INVALID_STATE_CHANGE),
        };
        match result {
            Ok(()) => {
                // One ESM for the station: every axis leaves or enters OP with it
                // (MR-J5-G-N1 manual §2.2: leaving OP re-initialises all axes at once).
                let sync0 = self.sync_active().then(|| self.sync0_cycle_ns());
                for d in &mut self.drives {
                    if from == AlState::Op && target != AlState::Op {
                        d.leave_op();
                    }
                    if target == AlState::Op && from != AlState::Op {
                        d.enter_op();
                        if let Some(ns) = sync0 {
                            let _ = d.start_sync(ns);
                        }
                    }
                }
                if target == AlState::SafeOp && from == AlState::PreOp {
                    self.pdo.reached_safe_op();
                }
                if target != AlState::Op {
                    self.pd_watchdog_trigger = None;
                }
                if target == AlState::Init {
                    // The mapping objects keep what was written (until power-off); the SYNC0
                    // grid starts anew; the mailboxes are reset (ETG.1000.6 §6.4.1.1).
                    self.last_edge = None;
                    self.lock_frames = 0;
                    self.outbox.emergencies.clear();
                    self.outbox.response_len = 0;
                    self.outbox.fragments.clear();
                }
                self.set_al_status(target, None);
                self.watch_alarms();
            }
            Err(code) => self.set_al_status(from, Some(code)),
        }
    }

    /// The segment's clock moved to `now_ns`: an SDO response that has become due goes into
    /// SM1.
    fn tick(&mut self, now_ns: u64) {
        self.now_ns = self.now_ns.max(now_ns);
        if self.outbox.response_len > 0 {
            self.fill_mailbox_in();
        }
    }

    /// The SYNC0 cycle programmed in the DC registers, ns.
    fn sync0_cycle_ns(&self) -> u32 {
        let a = usize::from(reg::DC_SYNC0_CYCLE);
        u32::from_le_bytes([
            self.mem[a],
            self.mem[a + 1],
            self.mem[a + 2],
            self.mem[a + 3],
        ])
    }

    /// Where local time `now_ns` falls in this station's SYNC0 cycle: (ns since the last SYNC0
    /// edge, the cycle), or `None` without SYNC0 or before its start time.
    pub fn sync0_phase(&self, now_ns: u64) -> Option<(u64, u64)> {
        let cycle = u64::from(self.sync0_cycle_ns());
        if !self.sync_active() || cycle == 0 {
            return None;
        }
        let system = now_ns.wrapping_add(self.get_u64(reg::DC_SYSTEM_TIME_OFFSET));
        let start = self.get_u64(reg::DC_SYNC_START_TIME);
        (system >= start).then(|| ((system - start) % cycle, cycle))
    }

    /// True if the master has activated SYNC0/SYNC1 generation (0981h).
    fn sync_active(&self) -> bool {
        self.mem[usize::from(reg::DC_SYNC_ACTIVE)] & 0x03 != 0
    }

    /// PRE-OP → SAFE-OP: the PDOs must be assigned and mapped, SM2/SM3 must match the mapping's
    /// lengths (the axes' PDOs concatenated), the unit's PDO size limit must hold at the SYNC0
    /// cycle (multi-axis), and each axis' drive takes its mapping ([`PdoConfig`]).
    fn check_process_data(&mut self) -> Result<(), u16> {
        let (o, i) = (self.layout.outputs, self.layout.inputs);
        if !self.pdo.complete() {
            return Err(al_code::INVALID_OUTPUT_CONFIG);
        }
        let lens: Vec<(u16, u16)> = (0..self.drives.len())
            .map(|slot| self.pdo.byte_lens(slot as u8))
            .collect();
        let rx_len: u16 = lens.iter().map(|l| l.0).sum();
        let tx_len: u16 = lens.iter().map(|l| l.1).sum();
        if !self.sm_matches(2, o.start, rx_len) {
            return Err(al_code::INVALID_OUTPUT_CONFIG);
        }
        if !self.sm_matches(3, i.start, tx_len) {
            return Err(al_code::INVALID_INPUT_CONFIG);
        }
        let profile = self.drives[0].profile().clone();
        if self.variant.distributed_clocks == EmulatedDc::Required && !self.sync_active() {
            return Err(al_code::INVALID_DC_SYNC);
        }
        if self.sync_active() && !super::allows_cycle_ns(&profile, self.sync0_cycle_ns()) {
            return Err(al_code::INVALID_SYNC_CYCLE);
        }
        if profile.is_multi_axis() {
            let cycle_us = self.sync0_cycle_ns() / 1000;
            match profile.unit_pdo_limit(cycle_us) {
                Some((max_rx, _)) if rx_len > max_rx => return Err(al_code::INVALID_OUTPUT_CONFIG),
                Some((_, max_tx)) if tx_len > max_tx => return Err(al_code::INVALID_INPUT_CONFIG),
                _ => {}
            }
        }
        for slot in 0..self.drives.len() {
            let (rx, tx) = self.pdo.mapping(&profile, slot as u8);
            if self.drives[slot].remap(&rx, &tx).is_err() {
                return Err(al_code::INVALID_OUTPUT_CONFIG);
            }
        }
        self.axis_lens = lens
            .iter()
            .map(|&(r, t)| (usize::from(r), usize::from(t)))
            .collect();
        self.layout.outputs.len = rx_len;
        self.layout.inputs.len = tx_len;
        Ok(())
    }

    /// Handles the station's part of a logical datagram at `logical` on `data`: outputs are
    /// written through the write FMMUs, the drive runs one exchange (as if SYNC0 fell as the
    /// frame passed, so the images match `SimBus`), then inputs are read through the read FMMUs.
    pub fn logical(
        &mut self,
        command: Command,
        logical: u32,
        data: &mut [u8],
        now_ns: u64,
    ) -> Access {
        self.tick(now_ns);
        let mut wrote = false;
        let mut read = false;
        let mut fmmus = [(0u32, 0u16, 0u16, 0u8); 8];
        for (n, f) in fmmus.iter_mut().enumerate() {
            let r = usize::from(reg::fmmu(n as u8));
            let m = &self.mem[r..r + 16];
            let enabled = m[12] & 1 != 0;
            *f = (
                u32::from_le_bytes([m[0], m[1], m[2], m[3]]),
                u16::from_le_bytes([m[4], m[5]]),
                u16::from_le_bytes([m[8], m[9]]),
                if enabled { m[11] & 3 } else { 0 },
            );
        }
        let data_len = data.len() as u64;
        let overlap = |(ls, len, ps, _): (u32, u16, u16, u8)| {
            let (ds, de) = (u64::from(logical), u64::from(logical) + data_len);
            let (fs, fe) = (u64::from(ls), u64::from(ls) + u64::from(len));
            let (s, e) = (ds.max(fs), de.min(fe));
            (s < e).then(|| {
                (
                    (s - ds) as usize,
                    u64::from(ps) + (s - fs),
                    (e - s) as usize,
                )
            })
        };
        self.check_pd_watchdog(now_ns);
        if !matches!(self.al_state, AlState::SafeOp | AlState::Op) {
            return Access::default();
        }
        // The output SyncManager runs in OP only: in SAFE-OP the application keeps its outputs
        // safe and the ESC takes no output write (ETG.1000.6 §6.4.1), so the working counter
        // shows a SubDevice that left OP.
        if command.writes() && self.al_state == AlState::Op {
            for f in fmmus.iter().filter(|f| f.3 & 2 != 0) {
                if let Some((d, p, n)) = overlap(*f) {
                    let p = p as usize;
                    if p + n <= MEMORY_LEN {
                        self.mem[p..p + n].copy_from_slice(&data[d..d + n]);
                        wrote = true;
                    }
                }
            }
        }
        if wrote {
            let sm2_control = self.mem[usize::from(reg::sync_manager(2)) + 4];
            if self.al_state == AlState::Op && sm2_control & reg::SM_CONTROL_WATCHDOG != 0 {
                self.pd_watchdog_trigger = Some(now_ns);
                self.put16(reg::SM_WATCHDOG_STATUS, 1);
            }
            self.exchange(now_ns);
        }
        if command.reads() {
            for f in fmmus.iter().filter(|f| f.3 & 1 != 0) {
                if let Some((d, p, n)) = overlap(*f) {
                    let p = p as usize;
                    if p + n <= MEMORY_LEN {
                        data[d..d + n].copy_from_slice(&self.mem[p..p + n]);
                        read = true;
                    }
                }
            }
        }
        Access {
            wkc: u16::from(read) + 2 * u16::from(wrote),
        }
    }

    /// One drive exchange: RxPDO from SM2, TxPDO to SM3. The SYNC0 cycle time and the local
    /// time since the previous exchange tell how many cycles passed without a frame.
    fn exchange(&mut self, now_ns: u64) {
        let cycle = u64::from(self.sync0_cycle_ns());
        // SYNC0 falls at the DC start time (0990h) plus whole cycles (09A0h) of this station's
        // system time (local time + 0920h offset), as on a real ESC; the master aligns its
        // frames to this grid (`EthercatBus` reads the reference clock's 0910h in every frame).
        // The first frames in OP, and any before the start time, are taken one SYNC0 each while
        // the master locks on; after that the SYNC0 edges between two frames decide: none (two
        // frames in one cycle: the second waits in SM2), one (in step), or more (frames that
        // missed their SYNC0: lost RxPDOs for the drive's checks).
        let edges = if cycle == 0 {
            // Free-run (no SYNC0): each frame is one cycle of the drive, plus the cycles of a
            // stall of the master's host it excused (the drive lives on the master's clock).
            1 + self.excused_sync0.min(MAX_LOST_REPLAY)
        } else {
            let system = now_ns.wrapping_add(self.get_u64(reg::DC_SYSTEM_TIME_OFFSET));
            let start = self.get_u64(reg::DC_SYNC_START_TIME);
            let edge = (system >= start).then(|| (system - start) / cycle);
            let locking = self.lock_frames < LOCK_FRAMES || edge.is_none();
            if locking {
                self.lock_frames = self.lock_frames.saturating_add(1);
            }
            let edges = match (self.last_edge, edge) {
                (Some(last), Some(e)) if !locking => e.saturating_sub(last),
                _ => 1,
            };
            if let Some(e) = edge {
                self.last_edge = Some(e);
            }
            edges
        };
        if edges == 0 {
            // A second frame before the next SYNC0 (the previous one was over half a cycle
            // late): its outputs wait in SM2 for that SYNC0; the inputs are the last ones.
            return;
        }
        // SYNC0 edges the master excused as a stall of its own host (in-process segment: the
        // emulated drives live on the master's clock, see `Segment::excuse_host_stall`) are
        // elapsed time for the drive, not lost frames.
        let excused = std::mem::take(&mut self.excused_sync0).min(edges - 1);
        let elapsed = edges - excused;
        let (o, i) = (self.layout.outputs, self.layout.inputs);
        let (os, ol) = (usize::from(o.start), usize::from(o.len));
        let (is, il) = (usize::from(i.start), usize::from(i.len));
        let (lo, hi) = self.mem.split_at_mut(is);
        let mut rx = &lo[os..os + ol];
        let mut tx = &mut hi[..il];
        // Each axis' drive runs on its part of the images, in slot (assignment) order.
        for (drive, &(rl, tl)) in self.drives.iter_mut().zip(&self.axis_lens) {
            let (axis_rx, rest_rx) = rx.split_at(rl.min(rx.len()));
            let tl = tl.min(tx.len());
            let (axis_tx, rest_tx) = std::mem::take(&mut tx).split_at_mut(tl);
            rx = rest_rx;
            tx = rest_tx;
            // SYNC0 fired at every cycle in between without new outputs: those count as lost
            // RxPDOs for the drive's communication checks.
            for _ in 1..elapsed.min(MAX_LOST_REPLAY) {
                let _ = drive.cycle_missed_sync0(axis_tx);
            }
            let _ = drive.cycle(
                axis_rx,
                axis_tx,
                Cycles(1 + excused.min(u64::from(u32::MAX - 1)) as u32),
            );
        }
        self.missed_sync0 += elapsed.clamp(1, MAX_LOST_REPLAY) - 1;
        self.exchanges += 1;
        self.watch_alarms();
    }
}

impl Station {
    /// Presents ESI `device` from now on: an SDO to an object its dictionary lacks aborts
    /// 0602 0000h (0609 0011h for a missing sub-index), a download to a read-only entry
    /// 0601 0002h, an upload of a write-only entry 0601 0001h; entries the simulated drive
    /// does not model read as the ESI's default (writes to them are accepted, not kept).
    /// The identity (1018h, SII) is the profile's: build the drive with
    /// [`cellrt_cia402::profiles::DriveProfile::with_esi`].
    pub fn describe_by(&mut self, device: std::sync::Arc<cellrt_ethercat::esi::EsiDevice>) {
        self.esi = Some(device);
    }
}
