//! The CoE mailbox server of an emulated drive (ETG.1000.6 §5.6): SDO upload (expedited, normal
//! and segmented) and download (expedited and normal) with CiA 301 abort codes. The communication
//! objects (1000h, 1008h, 1018h, 1C12h/1C13h, the PDO mapping objects) are served here; every
//! other object is the simulated drive's own SDO surface (`sim::sdo`), so abort codes such as
//! MR-J4-TM's 0609 0030h for 1C32h:03 (MR-J4-TM TV-10 (docs/test-vectors.md)) come from the drive model.

use std::collections::VecDeque;

use crate::sim::drive::SimDrive;
use crate::sim::sdo::SdoAbort;
use cellrt_cia402::pdo::objects::ERROR_CODE;
use cellrt_cia402::pdo::{PdoEntry, PdoMap};
use cellrt_cia402::profiles::mapping::PdoDirection;
use cellrt_cia402::profiles::{DriveProfile, PdoAssignment, PdoRules};
use cellrt_ethercat::identity::SubDeviceIdentity;
use cellrt_ethercat::register::AlState;

/// Mailbox header bytes (length, address, channel/priority, type/counter).
pub const MAILBOX_HEADER_LEN: usize = 6;
/// Mailbox type CoE.
pub const MAILBOX_TYPE_COE: u8 = 3;
/// CoE service: SDO request.
const SERVICE_SDO_REQUEST: u16 = 2;
/// CoE service: SDO response.
const SERVICE_SDO_RESPONSE: u16 = 3;
/// 1000h Device type: CiA 402 (0192h), servo drive (additional information 0002h).
pub const DEVICE_TYPE: u32 = 0x0002_0192;
/// 0504 0001h Client/server command specifier not valid or unknown.
pub const ABORT_BAD_COMMAND: SdoAbort = SdoAbort(0x0504_0001);
/// 0800 0022h Data cannot be transferred because of the present device state.
pub const ABORT_DEVICE_STATE: SdoAbort = SdoAbort(0x0800_0022);
/// 0604 0043h General parameter incompatibility: a PDO mapping the emulator cannot serve.
pub const ABORT_PARAMETER_INCOMPATIBLE: SdoAbort = SdoAbort(0x0604_0043);
/// 0601 0000h for complete access, which the SII does not advertise.
const ABORT_UNSUPPORTED: SdoAbort = SdoAbort::UNSUPPORTED_ACCESS;

/// 1C32h SM2 synchronisation; sub 2 the cycle time.
const SM2_SYNC: u16 = 0x1C32;
/// 1009h Manufacturer hardware version (CiA 301, VISIBLE_STRING).
const HARDWARE_VERSION: u16 = 0x1009;
/// 100Ah Manufacturer software version (CiA 301; MR-J3-T04 manual §8.3.2 lists it).
const SOFTWARE_VERSION: u16 = 0x100A;
/// What the emulator answers for 1009h: no manual gives a drive's value, so it names itself.
pub const EMULATED_HARDWARE_VERSION: &str = "cellrt emulated";
/// What the emulator answers for 100Ah: cellrt's version, not a drive firmware's (the manuals
/// give none).
pub fn emulated_software_version() -> String {
    format!("cellrt {}", env!("CARGO_PKG_VERSION"))
}
/// 1C00h Sync manager communication type (ETG.1000.6 §5.6.7.4.9; MR-J3-T04 manual §8.3.2 lists
/// it, and SOEM reads it to map the PDOs).
const SM_COMMUNICATION_TYPE: u16 = 0x1C00;
/// 1C00h:01–04, the emulated ESC's four sync managers: mailbox out (1), mailbox in (2), process
/// data outputs (3), process data inputs (4) (ETG.1000.6 Table 67).
pub const SM_COMMUNICATION_TYPES: [u8; 4] = [1, 2, 3, 4];
/// 1C33h SM3 synchronisation; sub 2 follows 1C32h:02.
const SM3_SYNC: u16 = 0x1C33;

/// The station-level state the CoE server needs besides the drives.
#[derive(Debug)]
pub struct CoeContext<'a> {
    /// The drives behind the station, one per axis of the unit (slot 0 = axis A).
    pub drives: &'a mut [SimDrive],
    /// 1018h.
    pub identity: SubDeviceIdentity,
    /// The AL state (PDO configuration only in PRE-OP).
    pub al_state: AlState,
    /// The station's PDO assignment and mapping, as written by the master.
    pub pdo: &'a mut PdoConfig,
    /// The mailbox counter of the last response (1..=7).
    pub counter: &'a mut u8,
    /// A segmented upload in progress.
    pub upload: &'a mut SegmentedUpload,
    /// How the station departs from its profile (objects it lacks, a read-only 1C32h:02).
    pub variant: &'a super::SubDeviceVariant,
    /// The ESI device the station presents: its dictionary decides which objects exist and
    /// their access rights ([`super::esi_od`]).
    pub esi: Option<&'a cellrt_ethercat::esi::EsiDevice>,
    /// SDO Information response fragments after the first, each a whole mailbox message, for
    /// SM1 in order ([`info`]).
    pub info_fragments: &'a mut VecDeque<Vec<u8>>,
}

impl CoeContext<'_> {
    /// The unit's model (every axis' drive runs the same model).
    fn profile(&self) -> &DriveProfile {
        self.drives[0].profile()
    }
}

/// An SDO upload too long for one mailbox (ETG.1000.6 §5.6.2.3, CiA 301 §7.2.4.3.4): the
/// initiate response gives the complete size with no data, then each Upload SDO Segment
/// request (toggle bit alternating from 0) is answered with the next part, the last with
/// bit 0 (no more segments) set. Any other request ends it.
#[derive(Debug, Clone, Default)]
pub struct SegmentedUpload {
    data: Vec<u8>,
    sent: usize,
    toggle: bool,
}

impl SegmentedUpload {
    /// True while segments remain to be uploaded.
    pub fn active(&self) -> bool {
        self.sent < self.data.len()
    }
}

/// 0503 0000h Toggle bit not alternated.
pub const ABORT_TOGGLE: SdoAbort = SdoAbort(0x0503_0000);
/// CoE command specifier of an Upload SDO Segment request (ccs = 3).
const CCS_UPLOAD_SEGMENT: u8 = 3;
/// Bytes of an SDO segment's header (CoE header and the command byte).
const SEGMENT_HEADER_LEN: usize = 3;
/// Segment data bytes below which the command byte's `n` counts the unused ones (CiA 301).
const MIN_SEGMENT_DATA: usize = 7;

/// Answers an Upload SDO Segment request (command byte `cmd`) into `response`.
fn upload_segment(ctx: &mut CoeContext<'_>, cmd: u8, response: &mut [u8]) {
    let toggle = cmd & 0x10 != 0;
    let up = &mut *ctx.upload;
    let head = MAILBOX_HEADER_LEN;
    let body_len = if !up.active() || toggle != up.toggle {
        let abort = if up.active() {
            ABORT_TOGGLE
        } else {
            ABORT_BAD_COMMAND
        };
        *up = SegmentedUpload::default();
        let mut out = [0u8; 10];
        write_abort(&mut out, abort);
        response[head..head + 10].copy_from_slice(&out);
        10
    } else {
        let room = response.len() - head - SEGMENT_HEADER_LEN;
        let n = (up.data.len() - up.sent).min(room);
        let last = up.sent + n == up.data.len();
        let unused = MIN_SEGMENT_DATA.saturating_sub(n) as u8;
        let start = head + SEGMENT_HEADER_LEN;
        response[head..head + 2].copy_from_slice(&(SERVICE_SDO_RESPONSE << 12).to_le_bytes());
        response[head + 2] = (u8::from(toggle) << 4) | (unused << 1) | u8::from(last);
        response[start..start + n].copy_from_slice(&up.data[up.sent..up.sent + n]);
        response[start + n..(start + MIN_SEGMENT_DATA).max(start + n)].fill(0);
        up.sent += n;
        up.toggle = !up.toggle;
        if last {
            *up = SegmentedUpload::default();
        }
        SEGMENT_HEADER_LEN + n.max(MIN_SEGMENT_DATA)
    };
    finish_response(ctx, response, body_len);
}

/// The mailbox header of a response of `body_len` bytes, with the next mailbox counter.
fn finish_response(ctx: &mut CoeContext<'_>, response: &mut [u8], body_len: usize) {
    response[0..2].copy_from_slice(&(body_len as u16).to_le_bytes());
    response[2..5].fill(0);
    *ctx.counter = if *ctx.counter >= 7 {
        1
    } else {
        *ctx.counter + 1
    };
    response[5] = MAILBOX_TYPE_COE | (*ctx.counter << 4);
}

/// The PDO assignment (1C12h/1C13h) and mapping (16xxh/1Axxh) objects of a station: variable
/// mapping as the model's [`PdoRules`] allow it (in PRE-OP: count to 0, entries, count last;
/// each entry checked when written, the whole mapping when the count is written). The drives
/// take the mapping at PRE-OP → SAFE-OP ([`PdoConfig::mapping`]). Only the model's default
/// mapping objects (e.g. 1600h/1A00h, 1614h/1A14h) can be assigned; on a multi-axis unit each
/// axis has its own at the offset index (1610h, 1620h…; MR-J5-G-N1 manual §2.2, §3.1, §4.3, §4.4).
#[derive(Debug, Clone)]
pub struct PdoConfig {
    /// Per axis of the unit: its RxPDO and TxPDO mapping objects.
    axes: Vec<[PdoObject; 2]>,
    /// 1C12h:00 / 1C13h:00 counts (0 while being rewritten).
    assign_counts: [u8; 2],
    rules: PdoRules,
    /// The mapping and the cycle time are frozen until power-off
    /// ([`PdoRules::frozen_after_safe_op`], set once the station has reached SAFE-OP).
    frozen: bool,
}

#[derive(Debug, Clone)]
struct PdoObject {
    index: u16,
    direction: PdoDirection,
    count: u8,
    /// Every sub-index 1..=max_entries, as written (0 where never written); on a multi-axis
    /// unit at the axis' own object indexes.
    words: Vec<u32>,
}

/// `entry` of axis `slot` at its offset index on `profile`'s unit (padding unchanged).
fn entry_at_slot(profile: &DriveProfile, entry: PdoEntry, slot: u8) -> PdoEntry {
    match profile.axis_object(entry.index, slot) {
        Some(index) if !entry.is_padding() => PdoEntry { index, ..entry },
        _ => entry,
    }
}

impl PdoObject {
    fn new(profile: &DriveProfile, map: &PdoMap, direction: PdoDirection, slot: u8) -> Self {
        let max_entries = profile.pdo.rules.max_entries;
        let mut words = vec![0u32; usize::from(max_entries).max(map.entries.len())];
        for (w, e) in words.iter_mut().zip(map.entries.iter()) {
            *w = entry_at_slot(profile, *e, slot).mapping_word();
        }
        PdoObject {
            index: profile.axis_object(map.index, slot).unwrap_or(map.index),
            direction,
            count: map.entries.len() as u8,
            words,
        }
    }

    /// The entries as written (at the axis' own indexes).
    fn entries(&self) -> Vec<PdoEntry> {
        self.words[..usize::from(self.count)]
            .iter()
            .map(|w| PdoEntry::from_mapping_word(*w))
            .collect()
    }
}

/// `entry` as written into the mapping object of axis `slot`, at the axis-A index the drive
/// model knows; `None` if it names another axis' object (e.g. 6040h in axis B's 1610h).
fn entry_of_slot(profile: &DriveProfile, entry: PdoEntry, slot: u8) -> Option<PdoEntry> {
    if entry.is_padding() {
        return Some(entry);
    }
    match profile.object_slot(entry.index) {
        Some((s, index)) if s == slot => Some(PdoEntry { index, ..entry }),
        _ => None,
    }
}

impl PdoConfig {
    /// The mapping of `drives` (each drive's default maps, or the mapping it runs), one per
    /// axis of the unit, with the model's rules.
    pub fn new(drives: &[SimDrive]) -> Self {
        let axes: Vec<[PdoObject; 2]> = drives
            .iter()
            .enumerate()
            .map(|(slot, d)| {
                let p = d.profile();
                [
                    PdoObject::new(p, &p.pdo.rx, PdoDirection::Rx, slot as u8),
                    PdoObject::new(p, &p.pdo.tx, PdoDirection::Tx, slot as u8),
                ]
            })
            .collect();
        let n = axes.len() as u8;
        PdoConfig {
            axes,
            assign_counts: [n, n],
            rules: drives.first().map_or(
                cellrt_cia402::profiles::generic_cia402::PROFILE.pdo.rules,
                |d| d.profile().pdo.rules,
            ),
            frozen: false,
        }
    }

    /// Axes of the unit.
    fn axis_count(&self) -> u8 {
        self.axes.len() as u8
    }

    /// True if every axis' RxPDO and TxPDO is assigned and mapped (what SAFE-OP requires; on a
    /// multi-axis unit one assigned PDO per axis, MR-J5-G-N1 manual §2.2, §3.1, §4.3, §4.4 [inferred]).
    pub fn complete(&self) -> bool {
        let n = self.axis_count();
        self.assign_counts == [n, n]
            && self
                .axes
                .iter()
                .all(|[rx, tx]| rx.count != 0 && tx.count != 0)
    }

    /// The RxPDO and TxPDO entries of axis `slot` as mapped now, at the axis-A indexes the
    /// drive model knows (`profile`: the unit's model).
    pub fn mapping(&self, profile: &DriveProfile, slot: u8) -> (Vec<PdoEntry>, Vec<PdoEntry>) {
        let Some([rx, tx]) = self.axes.get(usize::from(slot)) else {
            return (Vec::new(), Vec::new());
        };
        let base = |o: &PdoObject| {
            o.entries()
                .into_iter()
                .filter_map(|e| entry_of_slot(profile, e, slot))
                .collect()
        };
        (base(rx), base(tx))
    }

    /// The RxPDO and TxPDO bytes of axis `slot` as mapped now.
    pub fn byte_lens(&self, slot: u8) -> (u16, u16) {
        let len = |o: &PdoObject| {
            (o.entries()
                .iter()
                .map(|e| usize::from(e.bits))
                .sum::<usize>()
                / 8) as u16
        };
        self.axes
            .get(usize::from(slot))
            .map_or((0, 0), |[rx, tx]| (len(rx), len(tx)))
    }

    /// The station reached SAFE-OP: a model whose mapping freezes then keeps it until power-off.
    pub fn reached_safe_op(&mut self) {
        self.frozen |= self.rules.frozen_after_safe_op;
    }

    /// True if mapping and cycle-time writes are refused now (frozen, see
    /// [`PdoRules::frozen_after_safe_op`]).
    pub fn frozen(&self) -> bool {
        self.frozen
    }

    /// The mapping object `index` and the axis it belongs to.
    fn object(&mut self, index: u16) -> Option<(&mut PdoObject, u8)> {
        self.axes.iter_mut().enumerate().find_map(|(slot, objs)| {
            objs.iter_mut()
                .find(|o| o.index == index)
                .map(|o| (o, slot as u8))
        })
    }

    /// Every axis' mapping object indexes.
    fn object_indexes(&self) -> impl Iterator<Item = u16> + '_ {
        self.axes
            .iter()
            .flat_map(|objs| objs.iter().map(|o| o.index))
    }

    /// The direction and the number of entry sub-indexes of mapping object `index`.
    fn object_shape(&self, index: u16) -> Option<(PdoDirection, u8)> {
        self.axes
            .iter()
            .flatten()
            .find(|o| o.index == index)
            .map(|o| (o.direction, o.words.len() as u8))
    }

    /// The mapping object of `direction` of axis `slot`: the one sub-index `slot + 1` of
    /// 1C12h/1C13h assigns.
    fn assigned(&self, direction: usize, slot: usize) -> Option<u16> {
        self.axes.get(slot).map(|objs| objs[direction].index)
    }
}

/// A value to upload: up to 64 bytes of little-endian data.
type Value = Vec<u8>;

pub(super) fn upload(ctx: &mut CoeContext<'_>, index: u16, sub: u8) -> Result<Value, SdoAbort> {
    let u8v = |v: u8| vec![v];
    let u16v = |v: u16| v.to_le_bytes().to_vec();
    let u32v = |v: u32| v.to_le_bytes().to_vec();
    let profile = ctx.drives[0].profile().clone();
    if let Some(answer) = ctx.variant.upload(index, sub) {
        return answer;
    }
    match (index, sub) {
        (0x1000, 0) => return Ok(u32v(DEVICE_TYPE)),
        (0x1000, _) | (0x1008, 1..) => return Err(SdoAbort::NO_SUBINDEX),
        (0x1008, 0) => return Ok(profile.name.as_bytes().to_vec()),
        (0x1018, 0) => return Ok(u8v(4)),
        (0x1018, 1) => return Ok(u32v(ctx.identity.vendor_id)),
        (0x1018, 2) => return Ok(u32v(ctx.identity.product_code)),
        (0x1018, 3) => return Ok(u32v(ctx.identity.revision)),
        (0x1018, 4) => return Ok(u32v(ctx.identity.serial)),
        (0x1018, _) => return Err(SdoAbort::NO_SUBINDEX),
        (HARDWARE_VERSION, 0) => return Ok(EMULATED_HARDWARE_VERSION.as_bytes().to_vec()),
        (SOFTWARE_VERSION, 0) => return Ok(emulated_software_version().into_bytes()),
        (HARDWARE_VERSION | SOFTWARE_VERSION, _) => return Err(SdoAbort::NO_SUBINDEX),
        (SM_COMMUNICATION_TYPE, 0) => return Ok(u8v(SM_COMMUNICATION_TYPES.len() as u8)),
        (SM_COMMUNICATION_TYPE, s) => {
            return SM_COMMUNICATION_TYPES
                .get(usize::from(s) - 1)
                .map(|&t| u8v(t))
                .ok_or(SdoAbort::NO_SUBINDEX)
        }
        (0x1C12 | 0x1C13, s) => {
            let i = usize::from(index == 0x1C13);
            return match s {
                0 => Ok(u8v(ctx.pdo.assign_counts[i])),
                s => ctx
                    .pdo
                    .assigned(i, usize::from(s) - 1)
                    .map(u16v)
                    .ok_or(SdoAbort::NO_SUBINDEX),
            };
        }
        (SM3_SYNC, 2) => return upload(ctx, SM2_SYNC, 2),
        _ => {}
    }
    if let Some((obj, _)) = ctx.pdo.object(index) {
        return match sub {
            0 => Ok(u8v(obj.count)),
            s if usize::from(s) <= obj.words.len() => Ok(u32v(obj.words[usize::from(s) - 1])),
            _ => Err(SdoAbort::NO_SUBINDEX),
        };
    }
    // The axis' own object: the drive of its slot at the axis-A index (1000h–1FFFh: the
    // station's, served by axis A's drive).
    let (slot, index) = profile.object_slot(index).ok_or(SdoAbort::NO_OBJECT)?;
    let drive = &ctx.drives[usize::from(slot)];
    let profile = drive.profile();
    // 603Fh Error code: mandatory in CiA 402, served live where the model's table and
    // TxPDO leave it out (MR-JET-G-N1, MR-J5-G-N1).
    if (index, sub) == (ERROR_CODE, 0) && profile.object(ERROR_CODE, 0).is_none() {
        return Ok(u16v(drive.tx_pdo().error_code));
    }
    if sub == 0 {
        if let Some(highest) = highest_sub_index(profile, index) {
            return Ok(u8v(highest));
        }
    }
    let value = drive.sdo_upload(index, sub)?;
    let n = usize::from(served_bits(profile, index, sub).div_ceil(8)).clamp(1, 8);
    Ok(value.to_le_bytes()[..n].to_vec())
}

/// Sub-index 0 of an array or record whose table row the model lacks: the highest sub-index
/// supported (CiA 301 §7.4.3, UNSIGNED8, read-only); `None` where the table has a sub-index 0 row
/// or the object has no other sub-index.
fn highest_sub_index(profile: &DriveProfile, index: u16) -> Option<u8> {
    if profile.object(index, 0).is_some() {
        return None;
    }
    profile
        .all_objects()
        .filter(|o| o.index == index)
        .map(|o| o.sub)
        .max()
        .filter(|&s| s > 0)
}

/// The bits an upload of the axis-A object `index:sub` of `profile` answers with: its size in
/// the default PDOs, else its table type's, else 32 (a type the manual does not state).
fn served_bits(profile: &DriveProfile, index: u16, sub: u8) -> u16 {
    profile
        .pdo
        .rx
        .entries
        .iter()
        .chain(profile.pdo.tx.entries.iter())
        .find(|e| e.index == index && e.sub == sub)
        .map(|e| e.bits)
        .or_else(|| profile.object(index, sub).and_then(|o| o.data_type.bits()))
        .unwrap_or(32)
}

pub(super) fn download(
    ctx: &mut CoeContext<'_>,
    index: u16,
    sub: u8,
    data: &[u8],
) -> Result<(), SdoAbort> {
    let word = |d: &[u8]| {
        let mut b = [0u8; 4];
        let n = d.len().min(4);
        b[..n].copy_from_slice(&d[..n]);
        u32::from_le_bytes(b)
    };
    let axes = ctx.pdo.axis_count();
    if let Some(abort) = ctx.variant.refuses_download(index, sub) {
        return Err(abort);
    }
    match index {
        0x1000 | 0x1008 | HARDWARE_VERSION | SOFTWARE_VERSION | 0x1018 | SM_COMMUNICATION_TYPE => {
            return Err(SdoAbort::READ_ONLY)
        }
        0x1C12 | 0x1C13 => {
            let rules = ctx.pdo.rules;
            let i = usize::from(index == 0x1C13);
            return match (sub, rules.assignment) {
                (0 | 1, PdoAssignment::ReadOnly) | (0, PdoAssignment::FixedCount) => {
                    Err(SdoAbort::READ_ONLY)
                }
                _ if ctx.al_state != AlState::PreOp || ctx.pdo.frozen => {
                    Err(SdoAbort(rules.wrong_state_abort))
                }
                (0, _) if data.len() != 1 => Err(SdoAbort::TOO_LONG),
                (0, _) if data[0] > axes => Err(SdoAbort::VALUE_RANGE),
                (0, _) => {
                    ctx.pdo.assign_counts[i] = data[0];
                    Ok(())
                }
                (s, _) if s == 0 || s > axes => Err(SdoAbort::NO_SUBINDEX),
                (_, PdoAssignment::Writable) if ctx.pdo.assign_counts[i] != 0 => {
                    Err(SdoAbort(rules.locked_abort))
                }
                (_, _) if data.len() != 2 => Err(SdoAbort::TOO_SHORT),
                // Sub-index n assigns axis n's own mapping object (one per axis in axis
                // order, MR-J5-G-N1 manual §2.2, §3.1, §4.3, §4.4 [inferred]).
                (s, _) if ctx.pdo.assigned(i, usize::from(s) - 1) != Some(word(data) as u16) => {
                    Err(ABORT_PARAMETER_INCOMPATIBLE)
                }
                _ => Ok(()),
            };
        }
        // 1C33h:02 follows 1C32h:02 (read-only on every model); the other subs as the profile says.
        SM3_SYNC if sub == 2 => return Err(SdoAbort::READ_ONLY),
        SM2_SYNC if sub == 2 => {
            // MR-J3-T04 TV-IC-5 (docs/test-vectors.md): written only in PRE-OP, and (MR-J3-T04) never once the
            // drive has reached SAFE-OP; the others: only in PRE-OP (§2.1 of each extract).
            if ctx.al_state != AlState::PreOp || ctx.pdo.frozen {
                return Err(SdoAbort(ctx.pdo.rules.wrong_state_abort));
            }
            let ns = word(data);
            if !super::allows_cycle_ns(ctx.profile(), ns) {
                return Err(SdoAbort::VALUE_RANGE);
            }
            // One cycle for the station: every axis' drive runs it.
            for d in ctx.drives.iter_mut() {
                d.sdo_download(index, sub, data)?;
            }
            return Ok(());
        }
        _ => {}
    }
    let pre_op = ctx.al_state == AlState::PreOp;
    let rules = ctx.pdo.rules;
    let frozen = ctx.pdo.frozen;
    let profile = ctx.drives[0].profile().clone();
    let variant = *ctx.variant;
    if let Some((obj, slot)) = ctx.pdo.object(index) {
        if !pre_op || frozen {
            return Err(SdoAbort(rules.wrong_state_abort));
        }
        let max = usize::from(rules.max_entries);
        let not_mappable = SdoAbort(rules.not_mappable_abort);
        return match sub {
            0 if data.len() != 1 => Err(SdoAbort::TOO_LONG),
            0 if data[0] == 0 => {
                obj.count = 0;
                Ok(())
            }
            0 if obj.count != 0 => Err(SdoAbort(rules.locked_abort)),
            0 if usize::from(data[0]) > max => Err(SdoAbort::VALUE_RANGE),
            0 => {
                let entries = obj.words[..usize::from(data[0])]
                    .iter()
                    .map(|w| entry_of_slot(&profile, PdoEntry::from_mapping_word(*w), slot))
                    .collect::<Option<Vec<PdoEntry>>>()
                    .ok_or(not_mappable)?;
                profile
                    .check_mapping(obj.direction, &entries)
                    .map_err(|e| SdoAbort(e.abort_code(&rules)))?;
                obj.count = data[0];
                Ok(())
            }
            s if usize::from(s) > max => Err(SdoAbort::NO_SUBINDEX),
            _ if obj.count != 0 => Err(SdoAbort(rules.locked_abort)),
            _ if data.len() < 4 => Err(SdoAbort::TOO_SHORT),
            _ if data.len() > 4 => Err(SdoAbort::TOO_LONG),
            s => {
                let w = word(data);
                let entry = entry_of_slot(&profile, PdoEntry::from_mapping_word(w), slot)
                    .filter(|e| e.is_padding() || !variant.lacks(e.index))
                    .ok_or(not_mappable)?;
                profile
                    .check_mapping_entry(obj.direction, entry)
                    .map_err(|e| SdoAbort(e.abort_code(&rules)))?;
                obj.words[usize::from(s) - 1] = w;
                Ok(())
            }
        };
    }
    let (slot, index) = profile.object_slot(index).ok_or(SdoAbort::NO_OBJECT)?;
    ctx.drives[usize::from(slot)].sdo_download(index, sub, data)?;
    if ctx.drives[usize::from(slot)].profile().name != profile.name {
        // A parameter selected another of the model's profiles (MR-J4-TM [Pr. PA01]): its
        // default mapping objects are the ones that exist and can be assigned now.
        *ctx.pdo = PdoConfig::new(ctx.drives);
    }
    // A station object (1000h–1FFFh, served by axis A) holds for the whole unit: every axis
    // of a multi-axis station takes the value (e.g. 10F1h:02, the one sync error counter
    // limit of the station's ESC).
    if index < 0x2000 && slot == 0 {
        for d in ctx.drives.iter_mut().skip(1) {
            let _ = d.sdo_download(index, sub, data);
        }
    }
    Ok(())
}

/// Handles one mailbox request in `request` (the SM0 buffer) and writes the response into
/// `response` (the SM1 buffer). Returns false if the request needs no response (an abort
/// from the master, or not CoE).
pub fn serve(ctx: &mut CoeContext<'_>, request: &[u8], response: &mut [u8]) -> bool {
    if request.len() < MAILBOX_HEADER_LEN + 2 {
        return false;
    }
    let len = usize::from(u16::from_le_bytes([request[0], request[1]]));
    if request[5] & 0x0F != MAILBOX_TYPE_COE {
        return false;
    }
    let body = &request[MAILBOX_HEADER_LEN..(MAILBOX_HEADER_LEN + len).min(request.len())];
    let service = body
        .get(..2)
        .map(|b| u16::from_le_bytes([b[0], b[1]]) >> 12);
    if service == Some(info::SERVICE_SDO_INFO) {
        *ctx.upload = SegmentedUpload::default();
        let mut fragments = std::mem::take(ctx.info_fragments);
        info::serve(ctx, body, response, &mut fragments);
        *ctx.info_fragments = fragments;
        return true;
    }
    if body.len() < 2 + 4 || service != Some(SERVICE_SDO_REQUEST) {
        return false;
    }
    let cmd = body[2];
    let index = u16::from_le_bytes([body[3], body[4]]);
    let sub = body[5];
    let data = &body[6..];
    let ccs = cmd >> 5;
    if ccs == CCS_UPLOAD_SEGMENT {
        upload_segment(ctx, cmd, response);
        return true;
    }
    // Any other request (an abort included) ends a segmented upload.
    *ctx.upload = SegmentedUpload::default();
    if ccs == 4 {
        return false;
    }
    let complete_access = cmd & 0x10 != 0;
    let mut out = [0u8; 10];
    out[3..5].copy_from_slice(&index.to_le_bytes());
    out[5] = sub;
    let payload: Result<Option<Value>, SdoAbort> = if complete_access && ccs != 3 && ccs != 0 {
        Err(ABORT_UNSUPPORTED)
    } else {
        match ccs {
            1 => {
                let expedited = cmd & 0x02 != 0;
                let sized = cmd & 0x01 != 0;
                let value: Option<&[u8]> = if expedited {
                    let n = if sized {
                        4 - usize::from((cmd >> 2) & 3)
                    } else {
                        4
                    };
                    data.get(..n)
                } else {
                    data.get(..4).and_then(|s| {
                        let n = u32::from_le_bytes([s[0], s[1], s[2], s[3]]) as usize;
                        data.get(4..4 + n)
                    })
                };
                match value {
                    None => Err(SdoAbort::TOO_SHORT),
                    Some(v) => {
                        super::esi_od::download(ctx.esi, ctx, index, sub, v, download).map(|()| {
                            out[2] = 0x60;
                            None
                        })
                    }
                }
            }
            2 => super::esi_od::upload(ctx.esi, ctx, index, sub, upload).map(Some),
            _ => Err(ABORT_BAD_COMMAND),
        }
    };
    let body_len = match payload {
        Ok(None) => 6,
        Ok(Some(v)) if v.len() <= 4 => {
            out[2] = 0x43 | (((4 - v.len()) as u8) << 2);
            out[6..6 + v.len()].copy_from_slice(&v);
            10
        }
        Ok(Some(v)) => {
            let room = response.len().saturating_sub(MAILBOX_HEADER_LEN + 10);
            out[6..10].copy_from_slice(&(v.len() as u32).to_le_bytes());
            if v.len() > room {
                // Segmented: the complete size now, the data in Upload SDO Segments.
                out[2] = 0x41;
                *ctx.upload = SegmentedUpload {
                    data: v,
                    sent: 0,
                    toggle: false,
                };
                10
            } else {
                out[2] = 0x41;
                let start = MAILBOX_HEADER_LEN + 10;
                response[start..start + v.len()].copy_from_slice(&v);
                10 + v.len()
            }
        }
        Err(abort) => {
            write_abort(&mut out, abort);
            10
        }
    };
    let body_len = body_len.max(10);
    if out[2] != ABORT_COMMAND {
        out[0..2].copy_from_slice(&(SERVICE_SDO_RESPONSE << 12).to_le_bytes());
    }
    let head = MAILBOX_HEADER_LEN;
    response[head..head + 10].copy_from_slice(&out);
    finish_response(ctx, response, body_len);
    true
}

/// The command byte of Abort SDO Transfer (CiA 301: ccs/scs 4).
const ABORT_COMMAND: u8 = 0x80;

/// Writes Abort SDO Transfer with `abort` into `out` (the index and sub-index already there).
/// ETG.1000.6 §5.6.2.7.1: the abort is an SDO *request* (CoE service 2) whichever side sends
/// it, not an SDO response; SOEM reads a response's bytes 6..10 as a data length.
fn write_abort(out: &mut [u8; 10], abort: SdoAbort) {
    out[0..2].copy_from_slice(&(SERVICE_SDO_REQUEST << 12).to_le_bytes());
    out[2] = ABORT_COMMAND;
    out[6..10].copy_from_slice(&abort.0.to_le_bytes());
}

mod info;

#[cfg(test)]
mod tests;
