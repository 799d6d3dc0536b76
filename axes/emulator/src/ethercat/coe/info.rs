//! SDO Information (ETG.1000.6 §5.6.3), the CoE service a MainDevice browses a drive's object
//! dictionary with: Get OD List, Get Object Description and Get Entry Description, errors by
//! SDO Info Error Request. The dictionary described is the one the station serves: the
//! communication objects of [`super`], the ESI's objects where the station presents an ESI, the
//! profile's tables on each axis' offset indexes, each entry kept only if an SDO upload finds it
//! (so that a listed object can be read, and a readable one is listed).

use std::collections::{BTreeSet, VecDeque};

use super::{CoeContext, MAILBOX_HEADER_LEN, MAILBOX_TYPE_COE};
use crate::ethercat::CycleTimeObject;
use crate::sim::sdo::SdoAbort;
use cellrt_cia402::pdo::objects::ERROR_CODE;
use cellrt_cia402::profiles::facts::{Range, Unit};
use cellrt_cia402::profiles::mapping::PdoDirection;
use cellrt_cia402::profiles::{Access, DataType, DriveProfile, OdEntry, Pdo, PdoAssignment};

/// CoE service: SDO Information.
pub(super) const SERVICE_SDO_INFO: u16 = 8;
/// Bytes of the SDO Information header after the CoE header: opcode, reserved, fragments left.
const INFO_HEADER_LEN: usize = 4;
/// Bytes before an SDO Information message's data: mailbox, CoE and SDO Information headers.
const DATA_START: usize = MAILBOX_HEADER_LEN + 2 + INFO_HEADER_LEN;
/// Opcode bit 7: more fragments follow.
const INCOMPLETE: u8 = 0x80;

/// SDO Information opcodes (ETG.1000.6 Table 43).
mod opcode {
    pub const OD_LIST_REQUEST: u8 = 1;
    pub const OD_LIST_RESPONSE: u8 = 2;
    pub const OBJECT_REQUEST: u8 = 3;
    pub const OBJECT_RESPONSE: u8 = 4;
    pub const ENTRY_REQUEST: u8 = 5;
    pub const ENTRY_RESPONSE: u8 = 6;
    pub const ERROR: u8 = 7;
}

/// Get OD List list types (ETG.1000.6 §5.6.3.3; MR-J3-T04 manual §8.7): 0 the count of each
/// of 1–5; 1 all objects; 2 RxPDO-mappable; 3 TxPDO-mappable; 4 stored for device
/// replacement; 5 start-up parameters.
const LIST_TYPES: u16 = 5;

/// 0800 0000h General error: an unknown list type or value info (MR-J3-T04 manual §8.7).
const ABORT_GENERAL: SdoAbort = SdoAbort(0x0800_0000);
/// 0504 0001h for a model that does not offer SDO Information.
const ABORT_NOT_OFFERED: SdoAbort = SdoAbort(0x0504_0001);

/// Value info bits of Get Entry Description (ETG.1000.6 §5.6.3.6): 4 default, 5 minimum,
/// 6 maximum (each of the entry's size, in that order, before the name). Bits 0–2 ask for
/// access and mappability, which the response always carries; bit 3 (unit type) is not
/// answered (no manual gives unit codes); bit 7 is unused and refused.
const VALUE_DEFAULT: u8 = 0x10;
const VALUE_MIN: u8 = 0x20;
const VALUE_MAX: u8 = 0x40;
const VALUE_UNUSED: u8 = 0x80;

/// Object access word bits (ETG.1000.6 Table 49; MR-J3-T04 manual §8.7).
mod access {
    /// Readable in PRE-OP, SAFE-OP and OP.
    pub const READ: u16 = 0x07;
    /// Writable in PRE-OP only.
    pub const WRITE_PRE_OP: u16 = 0x08;
    /// Writable in PRE-OP, SAFE-OP and OP.
    pub const WRITE: u16 = 0x38;
    pub const RX_MAPPABLE: u16 = 0x40;
    pub const TX_MAPPABLE: u16 = 0x80;
}

/// Object codes (CiA 301 Table 38).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
enum ObjectCode {
    Var = 7,
    Array = 8,
    Record = 9,
}

/// Data type codes (CiA 301 Table 44; ETG.1000.6 Table 64): the basic ones of the profiles,
/// and the records SDO Information names.
mod data_type {
    pub use cellrt_cia402::profiles::facts::cia301_type::*;
    pub const PDO_MAPPING: u16 = 0x0021;
    pub const IDENTITY: u16 = 0x0023;
    pub const SYNC_PAR: u16 = 0x0029;
    /// A record whose type the manual does not give.
    pub const NOT_GIVEN: u16 = 0x0000;
}

/// The longest object name a Get Object Description answers (MR-J3-T04 manual §8.7: "a name of
/// ≤ 46 characters").
const MAX_OBJECT_NAME: usize = 46;

/// One sub-index as Get Entry Description describes it.
#[derive(Debug, Clone, PartialEq, Eq)]
struct EntryInfo {
    sub: u8,
    data_type: u16,
    bits: u16,
    access: u16,
    name: String,
    default: Option<i64>,
    range: Option<(i64, i64)>,
}

/// One object as Get Object Description describes it, with its entries.
#[derive(Debug, Clone, PartialEq, Eq)]
struct ObjectInfo {
    index: u16,
    code: ObjectCode,
    data_type: u16,
    name: String,
    entries: Vec<EntryInfo>,
}

impl ObjectInfo {
    fn max_sub(&self) -> u8 {
        self.entries.iter().map(|e| e.sub).max().unwrap_or(0)
    }

    fn access_any(&self, bit: u16) -> bool {
        self.entries.iter().any(|e| e.access & bit != 0)
    }
}

/// Answers one SDO Information request `body` (from the CoE header on): the first message into
/// `response` (a whole mailbox buffer), any further fragments into `fragments`.
pub(super) fn serve(
    ctx: &mut CoeContext<'_>,
    body: &[u8],
    response: &mut [u8],
    fragments: &mut VecDeque<Vec<u8>>,
) {
    fragments.clear();
    let data = body.get(2 + INFO_HEADER_LEN..).unwrap_or_default();
    let op = body.get(2).map_or(0, |o| o & !INCOMPLETE);
    let answer = if !ctx.profile().comm.sdo_info.offered {
        Err(ABORT_NOT_OFFERED)
    } else {
        match op {
            opcode::OD_LIST_REQUEST => od_list(ctx, data),
            opcode::OBJECT_REQUEST => object_description(ctx, data),
            opcode::ENTRY_REQUEST => entry_description(ctx, data),
            _ => Err(super::ABORT_BAD_COMMAND),
        }
    };
    let (op, payload) = match answer {
        Ok(a) => a,
        Err(abort) => (opcode::ERROR, abort.0.to_le_bytes().to_vec()),
    };
    let room = response.len() - DATA_START;
    let chunks: Vec<&[u8]> = if payload.is_empty() {
        vec![&[]]
    } else {
        payload.chunks(room).collect()
    };
    let last = chunks.len() - 1;
    for (k, chunk) in chunks.into_iter().enumerate() {
        let mut msg = vec![0u8; response.len()];
        let len = 2 + INFO_HEADER_LEN + chunk.len();
        msg[0..2].copy_from_slice(&(len as u16).to_le_bytes());
        msg[5] = MAILBOX_TYPE_COE;
        let h = MAILBOX_HEADER_LEN;
        msg[h..h + 2].copy_from_slice(&(SERVICE_SDO_INFO << 12).to_le_bytes());
        msg[h + 2] = op | if k < last { INCOMPLETE } else { 0 };
        msg[h + 4..h + 6].copy_from_slice(&((last - k) as u16).to_le_bytes());
        msg[DATA_START..DATA_START + chunk.len()].copy_from_slice(chunk);
        if k == 0 {
            response.copy_from_slice(&msg);
            super::finish_response(ctx, response, len);
        } else {
            fragments.push_back(msg);
        }
    }
}

type Answer = Result<(u8, Vec<u8>), SdoAbort>;

fn u16_at(data: &[u8], at: usize) -> Option<u16> {
    data.get(at..at + 2)
        .map(|b| u16::from_le_bytes([b[0], b[1]]))
}

/// Get OD List: the list type, then the indexes (or, for type 0, the five counts).
fn od_list(ctx: &mut CoeContext<'_>, data: &[u8]) -> Answer {
    let list_type = u16_at(data, 0).ok_or(super::ABORT_BAD_COMMAND)?;
    if list_type > LIST_TYPES {
        return Err(ABORT_GENERAL);
    }
    let objects = dictionary(ctx);
    let listed = |t: u16| -> Vec<u16> {
        objects
            .iter()
            .filter(|o| match t {
                2 => o.access_any(access::RX_MAPPABLE),
                3 => o.access_any(access::TX_MAPPABLE),
                // No object is stored for device replacement or marked a start-up parameter
                // (access bits 8 and 9): no manual names one.
                4 | 5 => false,
                _ => true,
            })
            .map(|o| o.index)
            .collect()
    };
    let mut out = list_type.to_le_bytes().to_vec();
    if list_type == 0 {
        for t in 1..=LIST_TYPES {
            out.extend_from_slice(&(listed(t).len() as u16).to_le_bytes());
        }
    } else {
        for i in listed(list_type) {
            out.extend_from_slice(&i.to_le_bytes());
        }
    }
    Ok((opcode::OD_LIST_RESPONSE, out))
}

/// Get Object Description: index, data type, max sub-index, object code, name.
fn object_description(ctx: &mut CoeContext<'_>, data: &[u8]) -> Answer {
    let index = u16_at(data, 0).ok_or(super::ABORT_BAD_COMMAND)?;
    let o = object(ctx, index).ok_or(SdoAbort::NO_OBJECT)?;
    let mut out = index.to_le_bytes().to_vec();
    out.extend_from_slice(&o.data_type.to_le_bytes());
    out.push(o.max_sub());
    out.push(o.code as u8);
    out.extend_from_slice(truncated(&o.name, MAX_OBJECT_NAME).as_bytes());
    Ok((opcode::OBJECT_RESPONSE, out))
}

/// Get Entry Description: index, sub-index, value info, data type, bit length, access, the
/// values asked for, name.
fn entry_description(ctx: &mut CoeContext<'_>, data: &[u8]) -> Answer {
    let (Some(index), Some(&sub), Some(&info)) = (u16_at(data, 0), data.get(2), data.get(3)) else {
        return Err(super::ABORT_BAD_COMMAND);
    };
    if info & VALUE_UNUSED != 0 {
        return Err(ABORT_GENERAL);
    }
    let o = object(ctx, index).ok_or(SdoAbort::NO_OBJECT)?;
    let e = o
        .entries
        .iter()
        .find(|e| e.sub == sub)
        .ok_or(SdoAbort::NO_SUBINDEX)?;
    let numeric = e.data_type != data_type::VISIBLE_STRING;
    let known = |bit: u8| match bit {
        VALUE_DEFAULT => e.default,
        VALUE_MIN => e.range.map(|r| r.0),
        _ => e.range.map(|r| r.1),
    };
    let mut answered = info & 0x07;
    let mut values = Vec::new();
    for bit in [VALUE_DEFAULT, VALUE_MIN, VALUE_MAX] {
        if info & bit == 0 || !numeric {
            continue;
        }
        if let Some(v) = known(bit) {
            answered |= bit;
            let n = usize::from(e.bits.div_ceil(8)).clamp(1, 8);
            values.extend_from_slice(&v.to_le_bytes()[..n]);
            if ctx.profile().comm.sdo_info.one_value_per_entry {
                break;
            }
        }
    }
    let mut out = index.to_le_bytes().to_vec();
    out.push(sub);
    out.push(answered);
    out.extend_from_slice(&e.data_type.to_le_bytes());
    out.extend_from_slice(&e.bits.to_le_bytes());
    out.extend_from_slice(&e.access.to_le_bytes());
    out.extend_from_slice(&values);
    // The name fills what one mailbox holds (SOEM reads a description from one message).
    let room = usize::from(crate::ethercat::layout::MAILBOX_LEN) - DATA_START - out.len();
    out.extend_from_slice(truncated(&e.name, room).as_bytes());
    Ok((opcode::ENTRY_RESPONSE, out))
}

/// `name` cut to at most `max` bytes at a character boundary.
fn truncated(name: &str, max: usize) -> &str {
    let mut end = name.len().min(max);
    while !name.is_char_boundary(end) {
        end -= 1;
    }
    &name[..end]
}

/// Every object the station serves, by index.
fn dictionary(ctx: &mut CoeContext<'_>) -> Vec<ObjectInfo> {
    candidate_indexes(ctx)
        .into_iter()
        .filter_map(|i| object(ctx, i))
        .collect()
}

/// The communication objects, the mapping objects, the ESI's objects and every axis' profile
/// objects at their indexes on the unit.
fn candidate_indexes(ctx: &CoeContext<'_>) -> BTreeSet<u16> {
    let mut set: BTreeSet<u16> = COMMUNICATION_OBJECTS.iter().copied().collect();
    set.extend(ctx.pdo.object_indexes());
    if let Some(d) = ctx.esi.filter(|d| d.has_dictionary()) {
        set.extend(d.objects.iter().map(|o| o.index));
    }
    let p = ctx.profile();
    let bases = p.all_objects().map(|o| o.index).chain([ERROR_CODE, 0x1C33]);
    for base in bases {
        if base < 0x2000 {
            set.insert(base);
            continue;
        }
        for slot in 0..p.axes_per_unit {
            set.extend(p.axis_object(base, slot));
        }
    }
    set
}

/// The objects [`super::upload`] serves itself (CiA 301, ETG.1000.6).
const COMMUNICATION_OBJECTS: [u16; 8] = [
    0x1000, 0x1008, 0x1009, 0x100A, 0x1018, 0x1C00, 0x1C12, 0x1C13,
];

/// Object `index` as the station serves it: its entries from the communication objects, the
/// ESI or the profile, each kept if an upload finds it.
fn object(ctx: &mut CoeContext<'_>, index: u16) -> Option<ObjectInfo> {
    let mut o = communication_object(ctx, index)
        .or_else(|| esi_object(ctx, index))
        .or_else(|| profile_object(ctx, index))?;
    o.entries.retain(|e| served(ctx, index, e.sub));
    (!o.entries.is_empty()).then_some(o)
}

/// True if an SDO upload of `index:sub` finds the entry (a refused read still finds it).
fn served(ctx: &mut CoeContext<'_>, index: u16, sub: u8) -> bool {
    let esi = ctx.esi;
    !matches!(
        crate::ethercat::esi_od::upload(esi, ctx, index, sub, super::upload),
        Err(a) if a == SdoAbort::NO_OBJECT || a == SdoAbort::NO_SUBINDEX
    )
}

fn entry(sub: u8, data_type: u16, bits: u16, access: u16, name: &str) -> EntryInfo {
    EntryInfo {
        sub,
        data_type,
        bits,
        access,
        name: name.to_string(),
        default: None,
        range: None,
    }
}

fn shaped(
    index: u16,
    name: &str,
    code: ObjectCode,
    data_type: u16,
    entries: Vec<EntryInfo>,
) -> ObjectInfo {
    ObjectInfo {
        index,
        code,
        data_type,
        name: name.to_string(),
        entries,
    }
}

/// The objects [`super::upload`] answers itself, with their CiA 301 / ETG.1000.6 types; the
/// assignment and mapping objects writable in PRE-OP only as the model's rules allow.
fn communication_object(ctx: &CoeContext<'_>, index: u16) -> Option<ObjectInfo> {
    use data_type::*;
    let ro = access::READ;
    let pre_op = access::READ | access::WRITE_PRE_OP;
    let string = |name: &str, value: &str| {
        let e = entry(0, VISIBLE_STRING, 8 * value.len() as u16, ro, name);
        Some(shaped(
            index,
            name,
            ObjectCode::Var,
            VISIBLE_STRING,
            vec![e],
        ))
    };
    let count = |n: &str, access: u16| entry(0, UNSIGNED8, 8, access, n);
    match index {
        0x1000 => Some(shaped(
            index,
            "Device type",
            ObjectCode::Var,
            UNSIGNED32,
            vec![entry(0, UNSIGNED32, 32, ro, "Device type")],
        )),
        0x1008 => string("Manufacturer device name", ctx.profile().name),
        0x1009 => string(
            "Manufacturer hardware version",
            super::EMULATED_HARDWARE_VERSION,
        ),
        0x100A => string(
            "Manufacturer software version",
            &super::emulated_software_version(),
        ),
        0x1018 => {
            let mut v = vec![count("Number of entries", ro)];
            for (s, n) in [
                (1, "Vendor ID"),
                (2, "Product code"),
                (3, "Revision number"),
                (4, "Serial number"),
            ] {
                v.push(entry(s, UNSIGNED32, 32, ro, n));
            }
            Some(shaped(index, "Identity", ObjectCode::Record, IDENTITY, v))
        }
        0x1C00 => {
            let mut v = vec![count("Number of sync managers", ro)];
            for s in 1..=super::SM_COMMUNICATION_TYPES.len() as u8 {
                v.push(entry(
                    s,
                    UNSIGNED8,
                    8,
                    ro,
                    &format!("Communication type SM{}", s - 1),
                ));
            }
            Some(shaped(
                index,
                "Sync manager communication type",
                ObjectCode::Array,
                UNSIGNED8,
                v,
            ))
        }
        0x1C12 | 0x1C13 => {
            let (count_access, entry_access) = match ctx.pdo.rules.assignment {
                PdoAssignment::ReadOnly => (ro, ro),
                PdoAssignment::FixedCount => (ro, pre_op),
                PdoAssignment::Writable => (pre_op, pre_op),
            };
            let sm = if index == 0x1C12 { 2 } else { 3 };
            let mut v = vec![count("Number of assigned PDOs", count_access)];
            for s in 1..=ctx.pdo.axis_count() {
                v.push(entry(s, UNSIGNED16, 16, entry_access, &format!("PDO {s}")));
            }
            let name = format!("Sync manager {sm} PDO assignment");
            Some(shaped(index, &name, ObjectCode::Array, UNSIGNED16, v))
        }
        _ => {
            let (direction, len) = ctx.pdo.object_shape(index)?;
            let what = match direction {
                PdoDirection::Rx => "RxPDO",
                PdoDirection::Tx => "TxPDO",
            };
            let mut v = vec![count("Number of mapped objects", pre_op)];
            for s in 1..=len {
                v.push(entry(
                    s,
                    UNSIGNED32,
                    32,
                    pre_op,
                    &format!("Mapping entry {s}"),
                ));
            }
            let name = format!("{what} mapping {index:04X}h");
            Some(shaped(index, &name, ObjectCode::Record, PDO_MAPPING, v))
        }
    }
}

/// The unsigned type of `bits`: how an entry whose type is not stated is described (it is
/// uploaded as that many bytes).
fn unsigned_of(bits: u16) -> u16 {
    use data_type::*;
    match bits {
        1 => BOOLEAN,
        8 => UNSIGNED8,
        16 => UNSIGNED16,
        64 => UNSIGNED64,
        _ => UNSIGNED32,
    }
}

/// Object `index` as the station's ESI describes it.
fn esi_object(ctx: &CoeContext<'_>, index: u16) -> Option<ObjectInfo> {
    let d = ctx.esi.filter(|d| d.has_dictionary())?;
    let entries: Vec<EntryInfo> = d
        .objects
        .iter()
        .filter(|o| o.index == index)
        .map(|o| {
            let mut a = match o.access {
                Access::Rw => access::READ | access::WRITE,
                Access::Wo => access::WRITE,
                Access::Ro | Access::Unstated => access::READ,
            };
            if o.write_restriction.as_deref() == Some("PreOP") && a & access::WRITE != 0 {
                a = a & !access::WRITE | access::WRITE_PRE_OP;
            }
            if o.pdo.rx {
                a |= access::RX_MAPPABLE;
            }
            if o.pdo.tx {
                a |= access::TX_MAPPABLE;
            }
            EntryInfo {
                default: o.default,
                ..entry(o.sub, type_code(o.coe_type(), o.bits), o.bits, a, &o.name)
            }
        })
        .collect();
    let profile = ctx.profile();
    shape(profile, index, entries)
}

/// The profile's code of `t` for an entry uploaded as `bits`.
fn type_code(t: DataType, bits: u16) -> u16 {
    t.cia301_index().unwrap_or_else(|| unsigned_of(bits))
}

/// Object `index` (on the unit) from the profile's tables of its axis.
fn profile_object(ctx: &CoeContext<'_>, index: u16) -> Option<ObjectInfo> {
    let p = ctx.profile();
    let (_, base) = p.object_slot(index)?;
    let mut rows: Vec<OdEntry> = Vec::new();
    for o in p.all_objects().filter(|o| o.index == base) {
        if !rows.iter().any(|r| r.sub == o.sub) {
            rows.push(*o);
        }
    }
    // Served live where the model's table leaves them out: 603Fh (CiA 402, mandatory), 1C33h:02
    // (follows 1C32h:02).
    if base == ERROR_CODE && rows.is_empty() {
        rows.push(OdEntry {
            index: ERROR_CODE,
            sub: 0,
            name: "Error code",
            data_type: DataType::U16,
            access: Access::Ro,
            pdo: Pdo::No,
            default: None,
            range: Range::Type,
            unit: Unit::None,
            source: "CiA 402 603Fh, served live where the model's table leaves it out",
        });
    }
    if base == 0x1C33 && !rows.iter().any(|r| r.sub == 2) {
        if let Some(cycle) = p.object(0x1C32, 2) {
            rows.push(OdEntry {
                index: 0x1C33,
                access: Access::Ro,
                ..*cycle
            });
        }
    }
    if let Some(highest) = super::highest_sub_index(p, base) {
        rows.push(OdEntry {
            index: base,
            sub: 0,
            name: "Highest sub-index supported",
            data_type: DataType::U8,
            access: Access::Ro,
            pdo: Pdo::No,
            default: Some(i64::from(highest)),
            range: Range::Type,
            unit: Unit::None,
            source: "CiA 301 §7.4.3: sub-index 0 of an array or record",
        });
    }
    let read_only_cycle = matches!(ctx.variant.cycle_time, CycleTimeObject::ReadOnly(_));
    let entries = rows
        .iter()
        .map(|o| {
            let bits = super::served_bits(p, o.index, o.sub);
            let mut a = match o.access {
                Access::Rw => access::READ | access::WRITE,
                Access::Wo => access::WRITE,
                Access::Ro | Access::Unstated => access::READ,
            };
            // The cycle time is written only in PRE-OP (each extract's §2.1).
            if (o.index, o.sub) == (0x1C32, 2) && a & access::WRITE != 0 {
                a = if read_only_cycle {
                    access::READ
                } else {
                    access::READ | access::WRITE_PRE_OP
                };
            }
            if p.mappable(PdoDirection::Rx, o.index, o.sub) {
                a |= access::RX_MAPPABLE;
            }
            if p.mappable(PdoDirection::Tx, o.index, o.sub) {
                a |= access::TX_MAPPABLE;
            }
            let bits = match o.data_type {
                DataType::VisibleString { octets } => 8 * u16::from(octets),
                t => t.bits().unwrap_or(bits),
            };
            EntryInfo {
                default: o.default,
                range: o.range.bounds(),
                ..entry(o.sub, type_code(o.data_type, bits), bits, a, o.name)
            }
        })
        .collect();
    shape(p, index, entries)
}

/// Entries of one object shaped as VAR (sub 0 only), ARRAY (its elements of one type) or
/// RECORD, with the object's type: the model's record types, the standard ones, else the
/// elements' type for an array.
fn shape(p: &DriveProfile, index: u16, mut entries: Vec<EntryInfo>) -> Option<ObjectInfo> {
    entries.sort_by_key(|e| e.sub);
    let first = entries.first()?;
    let name = first.name.clone();
    if entries.len() == 1 && first.sub == 0 {
        let t = first.data_type;
        return Some(shaped(index, &name, ObjectCode::Var, t, entries));
    }
    let base = p.object_slot(index).map_or(index, |(_, b)| b);
    let listed = p
        .comm
        .sdo_info
        .record_types
        .iter()
        .find(|(lo, hi, _)| (*lo..=*hi).contains(&base))
        .map(|r| r.2);
    let standard = match base {
        0x1C32 | 0x1C33 => Some(data_type::SYNC_PAR),
        _ => None,
    };
    let elements: Vec<u16> = entries
        .iter()
        .filter(|e| e.sub > 0)
        .map(|e| e.data_type)
        .collect();
    let uniform = elements.windows(2).all(|w| w[0] == w[1]);
    let (code, t) = match (listed.or(standard), elements.first()) {
        (Some(t), _) => (ObjectCode::Record, t),
        (None, Some(&t)) if uniform => (ObjectCode::Array, t),
        _ => (ObjectCode::Record, data_type::NOT_GIVEN),
    };
    Some(shaped(index, &name, code, t, entries))
}
