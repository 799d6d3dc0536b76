//! The MR-JE-C object dictionary as one table (MR-JE-C manual §7.3 "Object dictionary list",
//! with the details of §7.4–§7.6 where they are stricter): index, sub-index, name, data type,
//! access, variable mapping (may be placed in the CC-Link IE Field Basic response, 1A00h),
//! default, range, unit, Modbus "continuous read/write" and the software version an object
//! needs. Both ends use it: the clients to type values and lay out Modbus registers, the drive
//! emulator to hold the dictionary and refuse what the drive refuses.

use super::types::{Access, DataType, Initial, Range, SoftwareVersion, Unit};
use DataType::*;

/// One sub-index, or a run of sub-indexes with the same description.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Sub {
    /// First sub-index.
    pub first: u8,
    /// Last sub-index (the same as `first` for one).
    pub last: u8,
    /// Name ("" for the sub 0 of a single-value object: the object's name).
    pub name: &'static str,
    /// Data type.
    pub ty: DataType,
    /// Access rule.
    pub access: Access,
    /// Variable mapping "Possible": may be mapped into the cyclic response (1A00h).
    pub mappable: bool,
    /// Default.
    pub initial: Initial,
    /// Values a write may carry.
    pub range: Range,
    /// Unit.
    pub unit: Unit,
    /// Software version the sub-index needs.
    pub since: SoftwareVersion,
}

/// One object, or a run of objects with the same description (parameter blocks, point
/// tables, alarm history entries, Control DI / Status DO).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Object {
    /// First index.
    pub first: u16,
    /// Last index (the same as `first` for one).
    pub last: u16,
    /// Name.
    pub name: &'static str,
    /// Modbus "continuous read/continuous write" possible: may share a request with the
    /// objects beside it (MR-JE-C manual §3.6.2, §7.3).
    pub continuous: bool,
    /// Software version the object needs.
    pub since: SoftwareVersion,
    /// The sub-indexes, ascending.
    pub subs: &'static [Sub],
}

/// An object and sub-index.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ObjectId {
    /// Index.
    pub index: u16,
    /// Sub-index.
    pub sub: u8,
}

impl ObjectId {
    /// Index and sub-index.
    pub const fn new(index: u16, sub: u8) -> ObjectId {
        ObjectId { index, sub }
    }
}

impl std::fmt::Display for ObjectId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{:04X}h:{}", self.index, self.sub)
    }
}

/// An object named in a form [`ObjectId`] does not read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("object {0:?}: expected an index in hex with an optional :sub, e.g. 6041 or 1018:2")]
pub struct BadObjectId(pub String);

impl std::str::FromStr for ObjectId {
    type Err = BadObjectId;

    /// "6041", "6041h", "0x6041", "1018:2" or "1018h:2".
    fn from_str(s: &str) -> Result<ObjectId, BadObjectId> {
        let bad = || BadObjectId(s.to_string());
        let (index, sub) = s.split_once(':').unwrap_or((s, "0"));
        let index = index
            .trim()
            .trim_start_matches("0x")
            .trim_end_matches(['h', 'H']);
        let index = u16::from_str_radix(index, 16).map_err(|_| bad())?;
        let sub = sub.trim().parse::<u8>().map_err(|_| bad())?;
        Ok(ObjectId { index, sub })
    }
}

impl Sub {
    const fn new(sub: u8, name: &'static str, ty: DataType, access: Access) -> Sub {
        Sub {
            first: sub,
            last: sub,
            name,
            ty,
            access,
            mappable: false,
            initial: Initial::Unstated,
            range: Range::Type,
            unit: Unit::None,
            since: SoftwareVersion::A0,
        }
    }
    const fn to(self, last: u8) -> Sub {
        Sub { last, ..self }
    }
    const fn map(self) -> Sub {
        Sub {
            mappable: true,
            ..self
        }
    }
    const fn def(self, v: i64) -> Sub {
        Sub {
            initial: Initial::Value(v),
            ..self
        }
    }
    const fn by_sw(self, a3: i64, a4: i64) -> Sub {
        Sub {
            initial: Initial::BySoftware { a3, a4 },
            ..self
        }
    }
    const fn range(self, range: Range) -> Sub {
        Sub { range, ..self }
    }
    const fn fixed(self) -> Sub {
        self.range(Range::Fixed)
    }
    const fn span(self, lo: i64, hi: i64) -> Sub {
        self.range(Range::Spans(single(lo, hi)))
    }
    const fn unit(self, unit: Unit) -> Sub {
        Sub { unit, ..self }
    }
    const fn since(self, since: SoftwareVersion) -> Sub {
        Sub { since, ..self }
    }

    /// Whether `sub` is one of this row's sub-indexes.
    pub const fn covers(&self, sub: u8) -> bool {
        self.first <= sub && sub <= self.last
    }
}

/// The single spans the table uses (a `const fn` cannot make a `'static` slice of its
/// arguments).
const fn single(lo: i64, hi: i64) -> &'static [(i64, i64)] {
    macro_rules! spans {
        ($(($a:expr, $b:expr)),* $(,)?) => {
            $(if lo == $a && hi == $b { return &[($a, $b)]; })*
        };
    }
    spans!(
        (0, 1),
        (0, 3),
        (0, 100),
        (0, 200),
        (0, 255),
        (-1, 255),
        (0, 500),
        (0, 0x63),
        (0, 20000),
        (0, 10000),
        (0, 32),
        (0, 0xC0),
        (0, 0xC00F),
        (0, 2000000),
        (0, 10000000),
        (1, 16777215),
        (-43, 39),
        (-999_999, 999_999),
        (0, 0),
        (0, 2),
    );
    panic!("a span the table uses is missing from `single`")
}

impl Object {
    const fn new(first: u16, name: &'static str, subs: &'static [Sub]) -> Object {
        Object {
            first,
            last: first,
            name,
            continuous: false,
            since: SoftwareVersion::A0,
            subs,
        }
    }
    const fn to(self, last: u16) -> Object {
        Object { last, ..self }
    }
    const fn cont(self) -> Object {
        Object {
            continuous: true,
            ..self
        }
    }
    const fn since(self, since: SoftwareVersion) -> Object {
        Object { since, ..self }
    }

    /// The row of `sub` present on software `sw`.
    pub fn sub(&self, sub: u8, sw: SoftwareVersion) -> Option<&'static Sub> {
        self.subs.iter().find(|s| s.covers(sub) && s.since <= sw)
    }

    /// The highest sub-index on software `sw`.
    pub fn last_sub(&self, sw: SoftwareVersion) -> u8 {
        self.subs
            .iter()
            .filter(|s| s.since <= sw)
            .map(|s| s.last)
            .max()
            .unwrap_or(0)
    }

    /// Every sub-index on `sw`, ascending, with its row.
    pub fn each_sub(&self, sw: SoftwareVersion) -> impl Iterator<Item = (u8, &'static Sub)> {
        let subs = self.subs;
        subs.iter()
            .filter(move |s| s.since <= sw)
            .flat_map(|s| (s.first..=s.last).map(move |k| (k, s)))
    }

    /// Modbus registers of the whole object on `sw` ("No. of points/No. of Registers"): an
    /// object is read and written whole, sub 0 included (MR-JE-C manual §7.1 note).
    pub fn registers(&self, sw: SoftwareVersion) -> usize {
        self.each_sub(sw).map(|(_, s)| s.ty.registers()).sum()
    }

    /// Whether the object has sub-indexes beyond 0 (a record).
    pub fn is_record(&self) -> bool {
        self.subs.len() > 1 || self.subs[0].last > 0
    }
}

/// The object at `index` on software `sw`.
pub fn object(index: u16, sw: SoftwareVersion) -> Option<&'static Object> {
    let at = DICTIONARY.partition_point(|o| o.last < index);
    DICTIONARY
        .get(at)
        .filter(|o| o.first <= index && o.since <= sw)
}

/// The row of `id` on software `sw`.
pub fn entry(id: ObjectId, sw: SoftwareVersion) -> Option<(&'static Object, &'static Sub)> {
    let o = object(id.index, sw)?;
    Some((o, o.sub(id.sub, sw)?))
}

use Access::{Ro, Rw, Wo};
use SoftwareVersion::{A3, A4};

const fn s(sub: u8, name: &'static str, ty: DataType, access: Access) -> Sub {
    Sub::new(sub, name, ty, access)
}

/// A single-value object: sub 0 only.
const fn v(ty: DataType, access: Access) -> Sub {
    Sub::new(0, "", ty, access)
}

/// "Number of entries" of a record.
const fn n(ty: DataType, entries: i64) -> Sub {
    Sub::new(0, "Number of entries", ty, Ro)
        .def(entries)
        .fixed()
}

/// 1010h / 1011h "save" / "load" sub-indexes: 0 (no action) or the keyword.
const SAVE: Range = Range::Spans(&[(0, 0), (0x6576_6173, 0x6576_6173)]);
const LOAD: Range = Range::Spans(&[(0, 0), (0x6461_6F6C, 0x6461_6F6C)]);
/// 2801h:6 auxiliary function.
const AUXILIARY: Range = Range::Spans(&[(0, 3), (8, 11)]);
/// 6067h: 0–65534, or 4294967295 to disable.
const POSITION_WINDOW: Range = Range::Spans(&[(0, 65534), (0xFFFF_FFFF, 0xFFFF_FFFF)]);
/// 6092h:2.
const SHAFT_REVOLUTIONS: Range = Range::Spans(&[(1, 1), (10, 10), (100, 100), (1000, 1000)]);

use Unit as U;

/// A live monitor (2B01h–2B35h) or its alarm-time copy (2B81h–2BB5h): ro, mappable.
const fn mon(ty: DataType, unit: Unit) -> Sub {
    v(ty, Ro).map().unit(unit)
}

/// The MR-JE-C object dictionary, ascending by index (MR-JE-C manual §7.3).
pub const DICTIONARY: &[Object] = &[
    Object::new(
        0x1000,
        "Device Type",
        &[v(U32, Ro).def(0x0002_0192).fixed()],
    ),
    Object::new(0x1001, "Error Register", &[v(U8, Ro).def(0).span(0, 1)]),
    Object::new(
        0x1008,
        "Manufacturer Device Name",
        &[v(VisibleString { octets: 32 }, Ro)],
    ),
    Object::new(
        0x1009,
        "Manufacturer Hardware Version",
        &[v(VisibleString { octets: 2 }, Ro)],
    ),
    Object::new(
        0x100A,
        "Manufacturer Software Version",
        &[v(VisibleString { octets: 16 }, Ro)],
    ),
    Object::new(
        0x1010,
        "Store parameters",
        &[
            s(0, "Number of entries", I8, Ro).by_sw(1, 5).fixed(),
            s(1, "Save all parameters", U32, Rw).def(1).range(SAVE),
            // "save" to subs 2 and 3 is accepted and stores nothing (§7.4.4 table; the list's
            // "Set 0" is the less specific).
            s(2, "Save communication parameters", U32, Rw)
                .def(0)
                .range(SAVE)
                .since(A4),
            s(3, "Save application parameters", U32, Rw)
                .def(0)
                .range(SAVE)
                .since(A4),
            s(4, "Save manufacturer defined parameters", U32, Rw)
                .def(1)
                .range(SAVE)
                .since(A4),
            s(5, "Save point table", U32, Rw)
                .def(1)
                .range(SAVE)
                .since(A4),
        ],
    ),
    Object::new(
        0x1011,
        "Restore default parameters",
        &[
            s(0, "Number of entries", U8, Ro).by_sw(1, 5).fixed(),
            s(1, "Restore all default parameters", U32, Rw)
                .def(1)
                .range(LOAD),
            s(2, "Restore communication default parameters", U32, Rw)
                .def(0)
                .span(0, 0)
                .since(A4),
            s(3, "Restore application default parameters", U32, Rw)
                .def(0)
                .span(0, 0)
                .since(A4),
            s(
                4,
                "Restore manufacturer defined default parameters",
                U32,
                Rw,
            )
            .def(1)
            .range(LOAD)
            .since(A4),
            s(5, "Restore point table", U32, Rw)
                .def(1)
                .range(LOAD)
                .since(A4),
        ],
    ),
    Object::new(
        0x1018,
        "Identity Object",
        &[
            n(U8, 4),
            s(1, "Vendor ID", U32, Ro).def(2).fixed(),
            s(2, "Product Code", U32, Ro).def(0x1003).fixed(),
            s(3, "Revision Number", U32, Ro),
            s(4, "Serial Number", U32, Ro).def(0),
        ],
    ),
    Object::new(
        0x1A00,
        "Transmit PDO Mapping",
        &[
            s(0, "Number of entries", U8, Rw).def(15).span(0, 32),
            s(1, "Mapped Object 001", U32, Rw).def(0x6061_0008),
            s(2, "Mapped Object 002 to 032", U32, Rw).to(32),
        ],
    ),
    // Parameter blocks (§7.3; [Pr. PC__], [Pr. PF__], [Pr. PN__] in §5): sub 0, U32, rw,
    // saved in EEPROM, continuous access possible. Their ranges are in `parameters`.
    Object::new(0x2001, "PA01 to PA32", &[v(U32, Rw)])
        .to(0x2020)
        .cont(),
    Object::new(0x2081, "PB01 to PB64", &[v(U32, Rw)])
        .to(0x20C0)
        .cont(),
    Object::new(0x2101, "PC01 to PC80", &[v(U32, Rw)])
        .to(0x2150)
        .cont(),
    Object::new(0x2181, "PD01 to PD48", &[v(U32, Rw)])
        .to(0x21B0)
        .cont(),
    Object::new(0x2201, "PE01 to PE64", &[v(U32, Rw)])
        .to(0x2240)
        .cont(),
    Object::new(0x2281, "PF01 to PF48", &[v(U32, Rw)])
        .to(0x22B0)
        .cont(),
    Object::new(0x2481, "PT01 to PT80", &[v(U32, Rw)])
        .to(0x24D0)
        .cont(),
    Object::new(0x2581, "PN01 to PN48", &[v(U32, Rw)])
        .to(0x25B0)
        .cont(),
    Object::new(
        0x2801,
        "Point table 001 to Point table 255",
        &[
            n(U8, 7),
            s(1, "Point data", I32, Rw).unit(U::PosUnits),
            s(2, "Speed", I32, Rw)
                .range(Range::PermissibleSpeed)
                .unit(U::CentiRpm),
            s(3, "Acceleration", I32, Rw)
                .span(0, 20000)
                .unit(U::Millisecond),
            s(4, "Deceleration", I32, Rw)
                .span(0, 20000)
                .unit(U::Millisecond),
            s(5, "Dwell", I32, Rw).span(0, 20000).unit(U::Millisecond),
            s(6, "Auxiliary", I32, Rw).range(AUXILIARY),
            s(7, "M code", I32, Rw).span(0, 0x63),
        ],
    )
    .to(0x28FF)
    .since(A4),
    Object::new(
        0x2A00,
        "Alarm history (2A00h newest to 2A0Fh oldest)",
        &[
            n(U8, 3),
            s(1, "Alarm No.", U32, Ro).def(0),
            s(2, "Alarm time (Hour)", U32, Ro).def(0).unit(U::Hour),
            s(3, "Alarm2 No.", U16, Ro).def(0),
        ],
    )
    .to(0x2A0F),
    Object::new(0x2A40, "Clear alarm history", &[v(U16, Wo)]),
    Object::new(0x2A41, "Current alarm", &[v(U32, Ro).map().def(0)]),
    Object::new(0x2A42, "Current alarm 2", &[v(U16, Ro).map().def(0)]),
    Object::new(
        0x2A43,
        "Point table error",
        &[
            n(U8, 2),
            s(1, "Point table error No.", U32, Ro)
                .map()
                .def(0)
                .span(0, 255),
            s(2, "Point table error factor", U32, Ro).map().def(0),
        ],
    )
    .since(A4),
    Object::new(
        0x2A44,
        "Parameter error number",
        &[v(U16, Ro).def(0).span(0, 500)],
    ),
    Object::new(
        0x2A45,
        "Parameter error list",
        &[
            n(U8, 32),
            s(1, "Parameter error list 1 to 32", U16, Ro).to(32).def(0),
        ],
    ),
    Object::new(0x2A46, "Reset alarm", &[v(U16, Wo)]),
    Object::new(0x2A60, "SDO abort code", &[v(U32, Ro)]).since(A3),
    Object::new(0x2A64, "Access log 1", &[v(U32, Ro)]).since(A3),
    Object::new(0x2A65, "Access log 2", &[v(U16, Ro)]).since(A3),
    Object::new(0x2A68, "Communication error count", &[v(U16, Rw)]).since(A4),
    Object::new(
        0x2B01,
        "Cumulative feedback pulses",
        &[v(I32, Rw).map().unit(U::Pulse)],
    )
    .cont(),
    Object::new(0x2B02, "Servo motor speed", &[mon(I32, U::Rpm)]).cont(),
    Object::new(0x2B03, "Droop pulses", &[mon(I32, U::Pulse)]).cont(),
    Object::new(0x2B04, "Cumulative command pulses", &[mon(I32, U::Pulse)]).cont(),
    Object::new(
        0x2B05,
        "Command pulse frequency",
        &[mon(I32, U::KiloPulsePerSecond)],
    )
    .cont(),
    Object::new(0x2B06, "Analog speed command voltage", &[mon(I16, U::Volt)]).cont(),
    Object::new(
        0x2B07,
        "Analog torque limit voltage/Analog torque command voltage",
        &[mon(I16, U::Volt)],
    )
    .cont(),
    Object::new(0x2B08, "Regenerative load ratio", &[mon(U16, U::Percent)]).cont(),
    Object::new(0x2B09, "Effective load ratio", &[mon(U16, U::Percent)]).cont(),
    Object::new(0x2B0A, "Peak load ratio", &[mon(U16, U::Percent)]).cont(),
    Object::new(0x2B0B, "Instantaneous torque", &[mon(I16, U::Percent)]).cont(),
    Object::new(
        0x2B0C,
        "Within one-revolution position",
        &[mon(I32, U::Pulse)],
    )
    .cont(),
    Object::new(0x2B0D, "ABS counter", &[mon(I32, U::Revolution)]).cont(),
    Object::new(
        0x2B0E,
        "Load to motor inertia ratio",
        &[mon(U16, U::CentiTimes)],
    )
    .cont(),
    Object::new(0x2B0F, "Bus voltage", &[mon(U16, U::Volt)]).cont(),
    Object::new(
        0x2B16,
        "Cumulative encoder out pulses",
        &[mon(I32, U::Pulse)],
    ),
    Object::new(
        0x2B25,
        "Internal temperature of encoder",
        &[mon(I16, U::Celsius)],
    ),
    Object::new(0x2B26, "Settling time", &[mon(I16, U::Millisecond)]),
    Object::new(
        0x2B27,
        "Oscillation detection frequency",
        &[mon(I16, U::Hertz)],
    ),
    Object::new(
        0x2B28,
        "Number of tough drive operations",
        &[mon(U16, U::Times)],
    ),
    Object::new(
        0x2B2A,
        "Internal temperature of amplifier",
        &[mon(I16, U::Celsius)],
    ),
    Object::new(0x2B2D, "Unit power consumption", &[mon(I16, U::Watt)]).cont(),
    Object::new(
        0x2B2E,
        "Unit total power consumption",
        &[mon(I32, U::WattHour)],
    )
    .cont(),
    Object::new(0x2B2F, "Current position", &[mon(I32, U::None)]).cont(),
    Object::new(0x2B30, "Command position", &[mon(I32, U::None)]).cont(),
    Object::new(0x2B31, "Command remaining distance", &[mon(I32, U::None)]).cont(),
    Object::new(
        0x2B32,
        "Point table No./Station position No.",
        &[mon(I16, U::None).span(0, 255)],
    )
    .cont()
    .since(A4),
    Object::new(0x2B34, "Override voltage", &[mon(I16, U::CentiVolt)])
        .cont()
        .since(A4),
    Object::new(0x2B35, "Override level", &[mon(I16, U::Percent)])
        .cont()
        .since(A4),
    Object::new(
        0x2B81,
        "Alarm Monitor 1 Cumulative feedback pulses",
        &[mon(I32, U::Pulse)],
    )
    .cont(),
    Object::new(
        0x2B82,
        "Alarm Monitor 2 Servo motor speed",
        &[mon(I32, U::Rpm)],
    )
    .cont(),
    Object::new(
        0x2B83,
        "Alarm Monitor 3 Droop pulses",
        &[mon(I32, U::Pulse)],
    )
    .cont(),
    Object::new(
        0x2B84,
        "Alarm Monitor 4 Cumulative command pulses",
        &[mon(I32, U::Pulse)],
    )
    .cont(),
    Object::new(
        0x2B85,
        "Alarm Monitor 5 Command pulse frequency",
        &[mon(I32, U::KiloPulsePerSecond)],
    )
    .cont(),
    Object::new(
        0x2B86,
        "Alarm Monitor 6 Analog speed command voltage",
        &[mon(I16, U::Volt)],
    )
    .cont(),
    Object::new(
        0x2B87,
        "Alarm Monitor 7 Analog torque limit voltage",
        &[mon(I16, U::Volt)],
    )
    .cont(),
    Object::new(
        0x2B88,
        "Alarm Monitor 8 Regenerative load ratio",
        &[mon(U16, U::Percent)],
    )
    .cont(),
    Object::new(
        0x2B89,
        "Alarm Monitor 9 Effective load ratio",
        &[mon(U16, U::Percent)],
    )
    .cont(),
    Object::new(
        0x2B8A,
        "Alarm Monitor 10 Peak load ratio",
        &[mon(U16, U::Percent)],
    )
    .cont(),
    Object::new(
        0x2B8B,
        "Alarm Monitor 11 Instantaneous torque",
        &[mon(I16, U::Percent)],
    )
    .cont(),
    Object::new(
        0x2B8C,
        "Alarm Monitor 12 Within one-revolution position",
        &[mon(I32, U::Pulse)],
    )
    .cont(),
    Object::new(
        0x2B8D,
        "Alarm Monitor 13 ABS counter",
        &[mon(I32, U::Revolution)],
    )
    .cont(),
    Object::new(
        0x2B8E,
        "Alarm Monitor 14 Load to motor inertia ratio",
        &[mon(U16, U::CentiTimes)],
    )
    .cont(),
    Object::new(0x2B8F, "Alarm Monitor 15 Bus voltage", &[mon(U16, U::Volt)]).cont(),
    Object::new(
        0x2B96,
        "Alarm Monitor 22 Cumulative encoder out pulses",
        &[mon(I32, U::Pulse)],
    )
    .cont(),
    Object::new(
        0x2BA5,
        "Alarm Monitor 37 Internal temperature of encoder",
        &[mon(I16, U::Celsius)],
    )
    .cont(),
    Object::new(
        0x2BA6,
        "Alarm Monitor 38 Settling time",
        &[mon(I16, U::Millisecond)],
    )
    .cont(),
    Object::new(
        0x2BA7,
        "Alarm Monitor 39 Oscillation detection frequency",
        &[mon(I16, U::Hertz)],
    )
    .cont(),
    Object::new(
        0x2BA8,
        "Alarm Monitor 40 Number of tough drive operations",
        &[mon(U16, U::Times)],
    )
    .cont(),
    Object::new(
        0x2BAA,
        "Alarm Monitor 42 Internal temperature of amplifier",
        &[mon(I16, U::Celsius)],
    )
    .cont(),
    Object::new(
        0x2BAD,
        "Alarm Monitor 45 Unit power consumption",
        &[mon(I16, U::Watt)],
    )
    .cont(),
    Object::new(
        0x2BAE,
        "Alarm Monitor 46 Unit total power consumption",
        &[mon(I32, U::WattHour)],
    )
    .cont(),
    Object::new(
        0x2BAF,
        "Alarm Monitor 47 Current position",
        &[mon(I32, U::None)],
    )
    .cont(),
    Object::new(
        0x2BB0,
        "Alarm Monitor 48 Command position",
        &[mon(I32, U::None)],
    )
    .cont(),
    Object::new(
        0x2BB1,
        "Alarm Monitor 49 Command remaining distance",
        &[mon(I32, U::None)],
    )
    .cont(),
    Object::new(
        0x2BB2,
        "Alarm Monitor 50 Point table No./Station position No.",
        &[mon(I16, U::None).span(0, 255)],
    )
    .cont()
    .since(A4),
    Object::new(
        0x2BB4,
        "Alarm Monitor 52 Override voltage",
        &[mon(I16, U::CentiVolt)],
    )
    .cont()
    .since(A4),
    Object::new(
        0x2BB5,
        "Alarm Monitor 53 Override level",
        &[mon(I16, U::Percent)],
    )
    .cont()
    .since(A4),
    // §7.3 lists 1 entry, §7.5.5 / §7.5.6 say 02h is returned; the list is kept.
    Object::new(
        0x2C10,
        "External Input pin display",
        &[
            s(0, "Number of entries", U8, Ro).def(1),
            s(1, "External Input pin display1", U32, Ro).map(),
        ],
    ),
    Object::new(
        0x2C11,
        "External Output pin display",
        &[
            s(0, "Number of entries", U8, Ro).def(1),
            s(1, "External Output pin display1", U32, Ro).map(),
        ],
    ),
    Object::new(
        0x2C12,
        "External Input signal display",
        &[
            s(0, "Number of entries", U8, Ro).def(4),
            s(1, "External Input signal display1 to 4", U32, Ro)
                .map()
                .to(4),
        ],
    ),
    // The list's OCR lost these two indexes; §6.4 gives them.
    Object::new(
        0x2C18,
        "Power ON cumulative time",
        &[v(U32, Ro).def(0).unit(U::Hour)],
    ),
    Object::new(
        0x2C19,
        "Number of inrush relay on/off times",
        &[v(U32, Ro).def(0).unit(U::Times)],
    ),
    Object::new(0x2C20, "Machine diagnostic status", &[v(U16, Ro).def(0)]).cont(),
    Object::new(
        0x2C21,
        "Static friction torque at forward rotation",
        &[v(I16, Ro).def(0).unit(U::TenthPercent)],
    )
    .cont(),
    Object::new(
        0x2C22,
        "Dynamic friction torque at forward rotation (at rated speed)",
        &[v(I16, Ro).def(0).unit(U::TenthPercent)],
    )
    .cont(),
    Object::new(
        0x2C23,
        "Static friction torque at reverse rotation",
        &[v(I16, Ro).def(0).unit(U::TenthPercent)],
    )
    .cont(),
    Object::new(
        0x2C24,
        "Dynamic friction torque at reverse rotation (at rated speed)",
        &[v(I16, Ro).def(0).unit(U::TenthPercent)],
    )
    .cont(),
    Object::new(
        0x2C25,
        "Oscillation frequency during motor stop",
        &[v(I16, Ro).def(0).unit(U::Hertz)],
    )
    .cont(),
    Object::new(
        0x2C26,
        "Vibration level during motor stop",
        &[v(I16, Ro).def(0).unit(U::TenthPercent)],
    )
    .cont(),
    Object::new(
        0x2C27,
        "Oscillation frequency during motor operating",
        &[v(I16, Ro).def(0).unit(U::Hertz)],
    )
    .cont(),
    Object::new(
        0x2C28,
        "Vibration level during motor operating",
        &[v(I16, Ro).def(0).unit(U::TenthPercent)],
    )
    .cont(),
    Object::new(
        0x2D01,
        "Control DI 1 to Control DI 10",
        &[v(U16, Rw).map().def(0)],
    )
    .to(0x2D0A)
    .cont(),
    Object::new(0x2D11, "Status DO 1 to Status DO 10", &[v(U16, Ro).map()])
        .to(0x2D1A)
        .cont(),
    Object::new(
        0x2D20,
        "Velocity limit value",
        &[v(I32, Rw)
            .map()
            .def(50000)
            .range(Range::PermissibleSpeed)
            .unit(U::CentiRpm)],
    ),
    Object::new(0x2D28, "Motor rated speed", &[v(U32, Ro).unit(U::Rpm)]),
    Object::new(0x2D29, "Motor max speed", &[v(U32, Ro).unit(U::Rpm)]),
    Object::new(
        0x2D30,
        "Manufacturer Device Name 2",
        &[v(VisibleString { octets: 32 }, Ro)],
    )
    .since(A4),
    Object::new(
        0x2D31,
        "Manufacturer Hardware Version 2",
        &[v(VisibleString { octets: 2 }, Ro)],
    )
    .since(A4),
    Object::new(
        0x2D32,
        "Manufacturer Software Version 2",
        &[v(VisibleString { octets: 16 }, Ro)],
    )
    .since(A4),
    Object::new(
        0x2D33,
        "Serial Number 2",
        &[v(VisibleString { octets: 16 }, Ro)],
    )
    .since(A4),
    Object::new(
        0x2D35,
        "Encoder status",
        &[n(U8, 1), s(1, "Encoder status1", U32, Ro).span(0, 1)],
    ),
    Object::new(0x2D42, "Max ABS counter", &[v(U32, Ro).unit(U::Revolution)]),
    Object::new(
        0x2D50,
        "One-touch tuning mode",
        &[v(U8, Rw).def(0).span(0, 3)],
    ),
    Object::new(
        0x2D51,
        "One-touch tuning status",
        &[v(I8, Ro).def(0).span(0, 100).unit(U::Percent)],
    ),
    Object::new(
        0x2D52,
        "One-touch tuning Stop",
        &[v(I16, Wo).range(Range::Only(0x1EA5))],
    ),
    Object::new(0x2D53, "One-touch tuning Clear", &[v(I16, Wo).span(0, 1)]),
    Object::new(0x2D54, "One-touch tuning Error Code", &[v(I16, Ro).def(0)]),
    Object::new(
        0x2D60,
        "Target point table",
        &[v(I16, Rw).map().span(-1, 255)],
    )
    .since(A4),
    Object::new(
        0x2D68,
        "Point demand value",
        &[v(I16, Ro).map().span(0, 255)],
    )
    .cont()
    .since(A4),
    Object::new(
        0x2D69,
        "Point actual value",
        &[v(I16, Ro).map().span(0, 255)],
    )
    .cont()
    .since(A4),
    Object::new(
        0x2D6A,
        "M code actual value",
        &[v(U8, Ro).map().span(0, 0x63)],
    )
    .cont()
    .since(A4),
    Object::new(
        0x2D6B,
        "Torque limit value 2",
        &[v(U16, Rw)
            .map()
            .def(10000)
            .span(0, 10000)
            .unit(U::TenthPercent)],
    )
    .cont()
    .since(A4),
    Object::new(
        0x2D98,
        "Select behavior of broadcast message",
        &[v(U8, Rw).def(0).span(0, 1)],
    )
    .since(A4),
    // 2D99h–2D9Bh: wo in the list, rw in §7.5.15–§7.5.17; the list is kept.
    Object::new(
        0x2D99,
        "Setup S/W graph trigger",
        &[v(U8, Wo).def(0).span(0, 1)],
    )
    .since(A4),
    Object::new(
        0x2D9A,
        "Set controlword bit 4",
        &[v(U8, Wo).def(0).span(0, 1)],
    )
    .since(A4),
    Object::new(0x2D9B, "C_EM1/2 command", &[v(U8, Wo).def(0).span(0, 1)]).since(A4),
    Object::new(
        0x2DB0,
        "Override",
        &[v(U16, Rw).map().def(0).span(0, 200).unit(U::Percent)],
    )
    .since(A4),
    Object::new(0x2DD1, "Target speed No.", &[v(I16, Rw).map().span(0, 255)]).since(A4),
    Object::new(0x603F, "Error code", &[v(U16, Ro).map().def(0)]),
    Object::new(0x6040, "Controlword", &[v(U16, Rw).map().def(0)]),
    Object::new(0x6041, "Statusword", &[v(U16, Ro).map()]),
    Object::new(
        0x605A,
        "Quick stop option code",
        &[v(I16, Rw).def(2).fixed()],
    ),
    Object::new(0x605D, "Halt option code", &[v(I16, Rw).def(1).fixed()]),
    Object::new(0x6060, "Modes of operation", &[v(I8, Rw).map().def(0)]),
    Object::new(
        0x6061,
        "Modes of operation display",
        &[v(I8, Ro).map().def(-20)],
    ),
    Object::new(
        0x6063,
        "Position actual internal value",
        &[v(I32, Ro).map().unit(U::Pulse)],
    ),
    Object::new(
        0x6064,
        "Position actual value",
        &[v(I32, Ro).map().unit(U::PosUnits)],
    ),
    Object::new(
        0x6065,
        "Following error window",
        &[v(U32, Rw).map().def(12_582_912).unit(U::PosUnits)],
    ),
    Object::new(
        0x6066,
        "Following error time out",
        &[v(U16, Rw).map().def(10).unit(U::Millisecond)],
    ),
    Object::new(
        0x6067,
        "Position window",
        &[v(U32, Rw)
            .map()
            .def(100)
            .range(POSITION_WINDOW)
            .unit(U::PosUnits)],
    ),
    Object::new(
        0x6068,
        "Position window time",
        &[v(U16, Rw).map().def(10).unit(U::Millisecond)],
    ),
    Object::new(
        0x606B,
        "Velocity demand value",
        &[v(I32, Ro).map().def(0).unit(U::CentiRpm)],
    ),
    Object::new(
        0x606C,
        "Velocity actual value",
        &[v(I32, Ro).map().unit(U::CentiRpm)],
    ),
    Object::new(
        0x606D,
        "Velocity window",
        &[v(U16, Rw).map().def(2000).unit(U::CentiRpm)],
    ),
    Object::new(
        0x606E,
        "Velocity window time",
        &[v(U16, Rw).map().def(10).unit(U::Millisecond)],
    ),
    Object::new(
        0x606F,
        "Velocity threshold",
        &[v(U16, Rw).map().def(5000).unit(U::CentiRpm)],
    ),
    Object::new(
        0x6070,
        "Velocity threshold time",
        &[v(U16, Rw).map().def(10).unit(U::Millisecond)],
    ),
    Object::new(
        0x6071,
        "Target torque",
        &[v(I16, Rw).map().def(0).unit(U::TenthPercent)],
    ),
    Object::new(
        0x6072,
        "Max torque",
        &[v(U16, Rw).map().unit(U::TenthPercent)],
    ),
    Object::new(
        0x6074,
        "Torque demand value",
        &[v(I16, Ro).map().def(0).unit(U::TenthPercent)],
    ),
    Object::new(
        0x6077,
        "Torque actual value",
        &[v(I16, Ro).map().unit(U::TenthPercent)],
    ),
    // The list's range is the I32; the description's setting range (non-degree units) wins.
    // Degree units allow −360000 to 360000.
    Object::new(
        0x607A,
        "Target position",
        &[v(I32, Rw)
            .map()
            .def(0)
            .span(-999_999, 999_999)
            .unit(U::PosUnits)],
    ),
    Object::new(
        0x607B,
        "Position range limit",
        &[
            s(0, "Number of entries", U8, Ro).def(2).span(0, 2),
            s(1, "Min position range limit", I32, Rw)
                .map()
                .range(Range::Automatic)
                .unit(U::PosUnits),
            s(2, "Max position range limit", I32, Rw)
                .map()
                .range(Range::Automatic)
                .unit(U::PosUnits),
        ],
    ),
    Object::new(
        0x607C,
        "Home offset",
        &[v(I32, Rw)
            .map()
            .def(0)
            .range(Range::Automatic)
            .unit(U::PosUnits)],
    ),
    Object::new(
        0x607D,
        "Software position limit",
        &[
            n(U8, 2),
            s(1, "Min position limit", I32, Rw)
                .map()
                .def(0)
                .unit(U::PosUnits),
            s(2, "Max position limit", I32, Rw)
                .map()
                .def(0)
                .unit(U::PosUnits),
        ],
    ),
    Object::new(0x607E, "Polarity", &[v(U8, Rw).map().def(0)]),
    Object::new(
        0x607F,
        "Max profile velocity",
        &[v(U32, Rw)
            .map()
            .def(2_000_000)
            .span(0, 2_000_000)
            .unit(U::CentiRpm)],
    ),
    Object::new(0x6080, "Max motor speed", &[v(U32, Rw).map().unit(U::Rpm)]),
    Object::new(
        0x6081,
        "Profile velocity",
        &[v(U32, Rw)
            .map()
            .def(10000)
            .range(Range::PermissibleSpeed)
            .unit(U::CentiRpm)],
    ),
    Object::new(
        0x6083,
        "Profile acceleration",
        &[v(U32, Rw).map().def(0).unit(U::Millisecond)],
    ),
    Object::new(
        0x6084,
        "Profile deceleration",
        &[v(U32, Rw).map().def(0).unit(U::Millisecond)],
    ),
    // Values above 20000 are limited to 20000, 0 acts as 100 ms (§7.3): no write is refused.
    Object::new(
        0x6085,
        "Quick stop deceleration",
        &[v(U32, Rw).map().def(100).unit(U::Millisecond)],
    ),
    Object::new(
        0x6086,
        "Motion profile type",
        &[v(I16, Rw).map().def(-1).fixed()],
    ),
    Object::new(
        0x6087,
        "Torque slope",
        &[v(U32, Rw)
            .map()
            .def(0)
            .span(0, 10_000_000)
            .unit(U::TenthPercentPerSecond)],
    ),
    Object::new(
        0x6088,
        "Torque profile type",
        &[v(I16, Rw).map().def(0).fixed()],
    ),
    Object::new(
        0x608F,
        "Position encoder resolution",
        &[
            n(U8, 2),
            s(1, "Encoder increments", U32, Rw).map().unit(U::Pulse),
            s(2, "Motor revolutions", U32, Rw)
                .map()
                .def(1)
                .fixed()
                .unit(U::Revolution),
        ],
    ),
    Object::new(
        0x6091,
        "Gear ratio",
        &[
            n(U8, 2),
            s(1, "Motor revolutions", U32, Rw)
                .map()
                .def(1)
                .span(1, 16_777_215)
                .unit(U::Revolution),
            s(2, "Shaft revolutions", U32, Rw)
                .map()
                .def(1)
                .span(1, 16_777_215)
                .unit(U::Revolution),
        ],
    ),
    Object::new(
        0x6092,
        "Feed constant",
        &[
            n(U8, 2),
            s(1, "Feed", U32, Rw).map().unit(U::PosUnits),
            s(2, "Shaft revolutions", U32, Rw)
                .map()
                .def(1)
                .range(SHAFT_REVOLUTIONS)
                .unit(U::Revolution),
        ],
    ),
    Object::new(
        0x6098,
        "Homing method",
        &[v(I8, Rw).map().def(37).span(-43, 39)],
    ),
    Object::new(
        0x6099,
        "Homing speeds",
        &[
            n(U8, 2),
            s(1, "Speed during search for switch", U32, Rw)
                .map()
                .def(10000)
                .range(Range::PermissibleSpeed)
                .unit(U::CentiRpm),
            s(2, "Speed during search for zero", U32, Rw)
                .map()
                .def(1000)
                .range(Range::PermissibleSpeed)
                .unit(U::CentiRpm),
        ],
    ),
    Object::new(
        0x609A,
        "Homing acceleration",
        &[v(U32, Rw).map().def(0).span(0, 20000).unit(U::Millisecond)],
    ),
    Object::new(0x60A8, "SI unit position", &[v(U32, Rw)]),
    Object::new(
        0x60A9,
        "SI unit velocity",
        &[v(U32, Rw).def(0xFEB4_4700).fixed()],
    ),
    Object::new(0x60B8, "Touch probe function", &[v(U16, Rw).map().def(0)]).cont(),
    Object::new(0x60B9, "Touch probe status", &[v(U16, Ro).map().def(0)]).cont(),
    Object::new(
        0x60BA,
        "Touch probe pos1 pos value",
        &[v(I32, Ro).map().def(0).unit(U::PosUnits)],
    )
    .cont(),
    Object::new(
        0x60BB,
        "Touch probe pos1 neg value",
        &[v(I32, Ro).map().def(0).unit(U::PosUnits)],
    )
    .cont(),
    Object::new(
        0x60E0,
        "Positive torque limit value",
        &[v(U16, Rw)
            .map()
            .def(10000)
            .span(0, 10000)
            .unit(U::TenthPercent)],
    ),
    Object::new(
        0x60E1,
        "Negative torque limit value",
        &[v(U16, Rw)
            .map()
            .def(10000)
            .span(0, 10000)
            .unit(U::TenthPercent)],
    ),
    Object::new(
        0x60E3,
        "Supported homing method",
        &[
            s(0, "Number of entries", U8, Ro).by_sw(39, 40),
            s(1, "1st supported homing method", I8, Ro).def(37),
            s(2, "2nd to 39th supported homing method", I8, Ro).to(39),
            s(40, "40th supported homing method", I8, Ro).since(A4),
        ],
    ),
    Object::new(
        0x60F2,
        "Positioning option code",
        &[v(U16, Rw).map().def(0).span(0, 0xC0)],
    ),
    Object::new(
        0x60F4,
        "Following error actual value",
        &[v(I32, Ro).map().unit(U::PosUnits)],
    ),
    Object::new(
        0x60FA,
        "Control effort",
        &[v(I32, Ro).map().def(0).unit(U::CentiRpm)],
    ),
    Object::new(
        0x60FF,
        "Target velocity",
        &[v(I32, Rw).map().def(0).unit(U::CentiRpm)],
    ),
    Object::new(
        0x6502,
        "Supported drive modes",
        &[v(U32, Ro).map().by_sw(0x2D, 0x000B_002D).fixed()],
    ),
];
