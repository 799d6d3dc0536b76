//! The static fact tables a drive profile is made of: object dictionary entries, alarms,
//! encoder and units, identity, communication checks.
//!
//! Each model module declares its facts once as `const` tables of these types; the simulator and
//! the master read them from the profile, never from literals of their own.

use std::fmt;

use crate::comm::CounterParams;
pub use crate::homing::HomeSetting;
use crate::pdo::PdoEntry;

/// Data type of an object (CiA 301 §7.4.7), one vocabulary for the CoE dictionaries of the
/// EtherCAT models and the MR-JE-C dictionary (MR-JE-C manual §7.3 "Data Type").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DataType {
    /// BOOLEAN.
    Bool,
    /// INTEGER8.
    I8,
    /// INTEGER16.
    I16,
    /// INTEGER32.
    I32,
    /// UNSIGNED8.
    U8,
    /// UNSIGNED16.
    U16,
    /// UNSIGNED32.
    U32,
    /// VISIBLE_STRING of a fixed length (the MR-JE-C manual counts it in Modbus registers,
    /// two characters each).
    VisibleString {
        /// Length in octets (characters).
        octets: u8,
    },
    /// Not stated by the source manual (the entry cites the gap).
    Unstated,
}

/// CiA 301 data type indexes (§7.4.7, ETG.1000.6 Table 64) of the basic types.
pub mod cia301_type {
    /// BOOLEAN.
    pub const BOOLEAN: u16 = 0x0001;
    /// INTEGER8.
    pub const INTEGER8: u16 = 0x0002;
    /// INTEGER16.
    pub const INTEGER16: u16 = 0x0003;
    /// INTEGER32.
    pub const INTEGER32: u16 = 0x0004;
    /// UNSIGNED8.
    pub const UNSIGNED8: u16 = 0x0005;
    /// UNSIGNED16.
    pub const UNSIGNED16: u16 = 0x0006;
    /// UNSIGNED32.
    pub const UNSIGNED32: u16 = 0x0007;
    /// VISIBLE_STRING.
    pub const VISIBLE_STRING: u16 = 0x0009;
    /// INTEGER64.
    pub const INTEGER64: u16 = 0x0015;
    /// UNSIGNED64.
    pub const UNSIGNED64: u16 = 0x001B;
}

impl DataType {
    /// Size in bits, `None` for [`DataType::Unstated`].
    pub const fn bits(self) -> Option<u16> {
        match self {
            Self::Bool => Some(1),
            Self::I8 | Self::U8 => Some(8),
            Self::I16 | Self::U16 => Some(16),
            Self::I32 | Self::U32 => Some(32),
            Self::VisibleString { octets } => Some(8 * octets as u16),
            Self::Unstated => None,
        }
    }

    /// Octets of a value on the wire (SDO, SLMP): BOOLEAN and the 8-bit types one, strings
    /// their length; 0 for [`DataType::Unstated`], which has no stated size.
    pub const fn bytes(self) -> usize {
        match self {
            Self::Bool | Self::I8 | Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
            Self::I32 | Self::U32 => 4,
            Self::VisibleString { octets } => octets as usize,
            Self::Unstated => 0,
        }
    }

    /// 16-bit registers of a value (Modbus): 8- and 16-bit types one, 32-bit two, strings two
    /// characters each (MR-JE-C manual §3.1, read with the examples of §3.6, not the POINT's
    /// garbled byte counts).
    pub const fn registers(self) -> usize {
        self.bytes().div_ceil(2)
    }

    /// The name CiA 301 §7.4.7 gives the type (e.g. "UNSIGNED16"), "unstated" for
    /// [`DataType::Unstated`].
    pub const fn cia301_name(self) -> &'static str {
        match self {
            Self::Bool => "BOOLEAN",
            Self::I8 => "INTEGER8",
            Self::I16 => "INTEGER16",
            Self::I32 => "INTEGER32",
            Self::U8 => "UNSIGNED8",
            Self::U16 => "UNSIGNED16",
            Self::U32 => "UNSIGNED32",
            Self::VisibleString { .. } => "VISIBLE_STRING",
            Self::Unstated => "unstated",
        }
    }

    /// The type of CiA 301 data type index `index` (§7.4.7, e.g. 0006h UNSIGNED16) whose values
    /// are `bits` wide; `None` for a type no profile uses (REAL32, UNSIGNED64, records, …).
    pub fn from_cia301_index(index: u16, bits: u16) -> Option<DataType> {
        use cia301_type::*;
        Some(match index {
            BOOLEAN => Self::Bool,
            INTEGER8 => Self::I8,
            INTEGER16 => Self::I16,
            INTEGER32 => Self::I32,
            UNSIGNED8 => Self::U8,
            UNSIGNED16 => Self::U16,
            UNSIGNED32 => Self::U32,
            VISIBLE_STRING => Self::VisibleString {
                octets: u8::try_from(bits / 8).ok()?,
            },
            _ => return None,
        })
    }

    /// This type's CiA 301 data type index (§7.4.7; SDO Information describes entries by it);
    /// `None` for [`DataType::Unstated`].
    pub const fn cia301_index(self) -> Option<u16> {
        use cia301_type::*;
        Some(match self {
            Self::Bool => BOOLEAN,
            Self::I8 => INTEGER8,
            Self::I16 => INTEGER16,
            Self::I32 => INTEGER32,
            Self::U8 => UNSIGNED8,
            Self::U16 => UNSIGNED16,
            Self::U32 => UNSIGNED32,
            Self::VisibleString { .. } => VISIBLE_STRING,
            Self::Unstated => return None,
        })
    }

    /// The values the type holds (inclusive), `None` for strings and [`DataType::Unstated`].
    pub const fn value_range(self) -> Option<(i64, i64)> {
        Some(match self {
            Self::Bool => (0, 1),
            Self::I8 => (i8::MIN as i64, i8::MAX as i64),
            Self::I16 => (i16::MIN as i64, i16::MAX as i64),
            Self::I32 => (i32::MIN as i64, i32::MAX as i64),
            Self::U8 => (0, u8::MAX as i64),
            Self::U16 => (0, u16::MAX as i64),
            Self::U32 => (0, u32::MAX as i64),
            Self::VisibleString { .. } | Self::Unstated => return None,
        })
    }
}

/// Access right of an object (CiA 301; MR-JE-C manual §7.3 "Access").
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, strum::Display, serde::Serialize, serde::Deserialize,
)]
#[strum(serialize_all = "lowercase")]
#[serde(rename_all = "lowercase")]
pub enum Access {
    /// Read only.
    Ro,
    /// Read/write.
    Rw,
    /// Write only.
    Wo,
    /// Not stated by the source manual.
    Unstated,
}

impl Access {
    /// Reading is stated as allowed (ro or rw).
    pub const fn readable(self) -> bool {
        matches!(self, Self::Ro | Self::Rw)
    }

    /// Writing is stated as allowed (rw or wo).
    pub const fn writable(self) -> bool {
        matches!(self, Self::Rw | Self::Wo)
    }
}

/// The values a write may carry, where a model's dictionary says more than a span (MR-JE-C
/// manual §7.3 "Range", or the tighter "[Setting range]" of an object's description, which the
/// manual gives precedence).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Range {
    /// Any value of the data type.
    Type,
    /// Only the default ("(fixed)").
    Fixed,
    /// One of these inclusive spans.
    Spans(&'static [(i64, i64)]),
    /// From the first to the second value, inclusive: the envelope of a setting derived at
    /// build time (a digit-wise hex parameter's), where no table of spans exists.
    Between(i64, i64),
    /// Only this value; any other is refused with "outside the parameter range" (2D52h,
    /// MR-JE-C manual §6.2).
    Only(i64),
    /// 0 up to the motor's instantaneous permissible speed (a property of the motor).
    PermissibleSpeed,
    /// Set automatically by the drive; a write is refused with "outside the parameter range"
    /// (607Bh:1/2, MR-JE-C manual §7.3; 607Ch "causes an error", the same code by our choice).
    Automatic,
}

impl Range {
    /// Whether `value` lies outside the spans the manual gives ([`Range::Spans`]); the other
    /// kinds need the drive's context (its fixed value, the motor) and are judged by the drive.
    pub fn refuses(self, value: i64) -> bool {
        match self {
            Range::Spans(spans) => !spans.iter().any(|&(lo, hi)| lo <= value && value <= hi),
            Range::Between(lo, hi) => value < lo || value > hi,
            _ => false,
        }
    }

    /// The smallest and largest value the range states, where it states numbers.
    pub fn bounds(self) -> Option<(i64, i64)> {
        match self {
            Range::Spans(spans) => {
                let lo = spans.iter().map(|s| s.0).min()?;
                let hi = spans.iter().map(|s| s.1).max()?;
                Some((lo, hi))
            }
            Range::Between(lo, hi) => Some((lo, hi)),
            Range::Only(x) => Some((x, x)),
            _ => None,
        }
    }
}

/// Unit of an object's value (MR-JE-C manual §7.3 "Units", §10.4 of the extract).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, strum::Display)]
pub enum Unit {
    /// No unit.
    #[default]
    #[strum(serialize = "")]
    None,
    /// The position command unit of the drive (MR-JE-C: [Pr. PT01], mm, inch, degree or pulse).
    #[strum(serialize = "pos units")]
    PosUnits,
    /// Encoder pulses.
    #[strum(serialize = "pulse")]
    Pulse,
    /// kpulse/s.
    #[strum(serialize = "kpulse/s")]
    KiloPulsePerSecond,
    /// r/min.
    #[strum(serialize = "r/min")]
    Rpm,
    /// 0.01 r/min.
    #[strum(serialize = "0.01 r/min")]
    CentiRpm,
    /// Milliseconds (accelerations are time constants to rated speed).
    #[strum(serialize = "ms")]
    Millisecond,
    /// Hours.
    #[strum(serialize = "hour")]
    Hour,
    /// Percent.
    #[strum(serialize = "%")]
    Percent,
    /// 0.1 % (of rated torque for torques).
    #[strum(serialize = "0.1%")]
    TenthPercent,
    /// 0.1 % of the rated torque (6071h, 6072h, 6077h; CiA 402).
    #[strum(serialize = "0.1 % rated")]
    TenthPercentRated,
    /// 0.1 % per second (6087h).
    #[strum(serialize = "0.1%/s")]
    TenthPercentPerSecond,
    /// Volt.
    #[strum(serialize = "V")]
    Volt,
    /// 0.01 V.
    #[strum(serialize = "0.01 V")]
    CentiVolt,
    /// Revolutions.
    #[strum(serialize = "rev")]
    Revolution,
    /// 0.01 times (inertia ratio).
    #[strum(serialize = "0.01 times")]
    CentiTimes,
    /// Degree Celsius.
    #[strum(serialize = "°C")]
    Celsius,
    /// 0.001 r/min (the MR-J3-T04's velocity unit, manual §9.6).
    #[strum(serialize = "0.001 r/min")]
    MilliRpm,
    /// The drive's velocity unit (CiA 402 "vel units", set by the model or its parameters).
    #[strum(serialize = "vel units")]
    VelUnits,
    /// The drive's acceleration unit (CiA 402 "acc units").
    #[strum(serialize = "acc units")]
    AccUnits,
    /// Encoder increments (6063h).
    #[strum(serialize = "inc")]
    Increment,
    /// Nanoseconds (1C32h cycle times).
    #[strum(serialize = "ns")]
    Nanosecond,
    /// The manual does not state the unit.
    #[strum(serialize = "not stated")]
    Unstated,
    /// Hertz.
    #[strum(serialize = "Hz")]
    Hertz,
    /// Watt.
    #[strum(serialize = "W")]
    Watt,
    /// Watt hours.
    #[strum(serialize = "Wh")]
    WattHour,
    /// A count of events.
    #[strum(serialize = "times")]
    Times,
}

/// Which PDO an object may be mapped into.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Pdo {
    /// RxPDO (master → drive).
    Rx,
    /// TxPDO (drive → master).
    Tx,
    /// SDO only.
    No,
    /// Not stated by the source manual.
    Unstated,
}

/// One object-dictionary entry, as far as the source manual states it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct OdEntry {
    /// Object index (axis A on multi-axis units).
    pub index: u16,
    /// Sub-index.
    pub sub: u8,
    /// Name as in the manual.
    pub name: &'static str,
    /// Data type.
    pub data_type: DataType,
    /// Access.
    pub access: Access,
    /// PDO mapping.
    pub pdo: Pdo,
    /// Default value, `None` where the manual gives none.
    pub default: Option<i64>,
    /// Value range ([`Range::Type`] where the manual gives none).
    pub range: Range,
    /// Unit of one LSB ([`Unit::None`] for dimensionless).
    pub unit: Unit,
    /// Spec section the row comes from, with the gap named where a field is not stated.
    pub source: &'static str,
}

/// Alarm or warning.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum AlarmKind {
    /// Alarm: statusword bit 3, (13) Fault reaction active → (14) Fault.
    Alarm,
    /// Warning: statusword bit 7, no PDS state change (unless its stop says otherwise).
    Warning,
}

/// What the drive does to the motor when the alarm or warning occurs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum StopBehaviour {
    /// Base circuit off and dynamic brake (sudden stop).
    DynamicBrake,
    /// Slow stop on a deceleration ramp.
    SlowStop,
    /// Operation continues (warning only).
    Continues,
    /// Servo off (base off + dynamic brake) while the warning lasts, PDS state kept.
    ServoOff,
    /// Not stated by the source manual.
    Unstated,
}

/// How an alarm is cleared.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Clearing {
    /// Controlword Fault Reset edge (transition 15) once the cause is gone.
    FaultReset,
    /// Only a control-power cycle.
    PowerCycle,
    /// Clears itself when the cause goes (warnings).
    Automatic,
    /// Not stated by the source manual (the simulator treats it as [`Clearing::FaultReset`]).
    Unstated,
}

/// One alarm or warning of a model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct AlarmInfo {
    /// The code the simulator reports in 603Fh/2041h (encoding per model module).
    pub code: u16,
    /// Display number as printed, e.g. "AL.34" or "AL.086.1".
    pub display: &'static str,
    /// Name as printed.
    pub name: &'static str,
    /// Alarm or warning.
    pub kind: AlarmKind,
    /// Stop behaviour.
    pub stop: StopBehaviour,
    /// How it is cleared.
    pub clearing: Clearing,
    /// Spec section, or the gap it fills.
    pub source: &'static str,
    /// The cause the manual gives, `None` where it gives none.
    pub cause: Option<&'static str>,
    /// What to do, as the manual says it; `None` where it says nothing.
    pub remedy: Option<&'static str>,
}

impl AlarmInfo {
    /// True if a Fault Reset edge clears it (unstated clearing counts as resettable).
    pub const fn resettable(&self) -> bool {
        matches!(self.clearing, Clearing::FaultReset | Clearing::Unstated)
    }

    /// The row with the manual's cause and remedy (each `None` where the manual gives none).
    pub const fn explained(
        self,
        cause: Option<&'static str>,
        remedy: Option<&'static str>,
    ) -> AlarmInfo {
        AlarmInfo {
            cause,
            remedy,
            ..self
        }
    }

    /// The alarm of `table` reported as `code`, if the table names it.
    pub fn find(table: &'static [AlarmInfo], code: u16) -> Option<&'static AlarmInfo> {
        table.iter().find(|a| a.code == code)
    }
}

/// Where a drive reports its alarm code, for the words around a decoded code.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum AlarmRegister {
    /// CiA 402 error code 603Fh (the EtherCAT models).
    ErrorCode603F,
    /// MR-JE-C Current alarm 2, 2A42h: alarm No. in bits 8–15, detail in 0–7 (MR-JE-C manual §7.3).
    CurrentAlarm2A42,
}

impl AlarmRegister {
    /// The object as written in the manuals, e.g. "603Fh".
    pub const fn object(self) -> &'static str {
        match self {
            AlarmRegister::ErrorCode603F => "603Fh",
            AlarmRegister::CurrentAlarm2A42 => "2A42h",
        }
    }
}

/// A drive's alarm code in words: the one decode of a code every view uses (events, status,
/// `alarms`, the live page, the summary). Built on the host side, never on the RT thread.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct AlarmText {
    /// The code as the drive reported it.
    pub code: u16,
    /// Where the drive reported it.
    pub register: AlarmRegister,
    /// The manual's row for the code; `None` where the model's manual does not list it.
    pub info: Option<&'static AlarmInfo>,
    /// The drive, named where the code is not in its manual's list.
    pub drive: &'static str,
}

impl AlarmText {
    /// `code` of `register` looked up in `table`, the alarm list of `drive`.
    pub fn decode(
        table: &'static [AlarmInfo],
        drive: &'static str,
        register: AlarmRegister,
        code: u16,
    ) -> AlarmText {
        AlarmText {
            code,
            register,
            info: AlarmInfo::find(table, code),
            drive,
        }
    }

    /// The manual's number and name, e.g. "AL.36 Receive error 2"; `None` for a code the manual
    /// does not list.
    pub fn name(&self) -> Option<String> {
        self.info.map(|a| format!("{} {}", a.display, a.name))
    }

    /// The manual's cause, where it gives one.
    pub fn cause(&self) -> Option<&'static str> {
        self.info.and_then(|a| a.cause)
    }

    /// The manual's remedy, where it gives one.
    pub fn remedy(&self) -> Option<&'static str> {
        self.info.and_then(|a| a.remedy)
    }

    /// The one-line text with cause and remedy where the manual gives them, e.g.
    /// "AL.36 Receive error 2 (603Fh = 0036h); cause: …; remedy: …".
    pub fn long(&self) -> String {
        let mut s = self.to_string();
        if let Some(c) = self.cause() {
            s += &format!("; cause: {c}");
        }
        if let Some(r) = self.remedy() {
            s += &format!("; remedy: {r}");
        }
        s
    }
}

/// "AL.36 Receive error 2 (603Fh = 0036h)", or for a code the manual does not list
/// "603Fh = 2220h (not listed for Mitsubishi MR-J5-G-N1)".
impl fmt::Display for AlarmText {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let object = self.register.object();
        match self.info {
            Some(a) => write!(
                f,
                "{} {} ({object} = {:04X}h)",
                a.display, a.name, self.code
            ),
            None => write!(
                f,
                "{object} = {:04X}h (not listed for {})",
                self.code, self.drive
            ),
        }
    }
}

/// EtherCAT identity (1018h), each `None` where the manual does not give it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Identity {
    /// 1018h:01 vendor ID.
    pub vendor_id: Option<u32>,
    /// 1018h:02 product code.
    pub product_code: Option<u32>,
    /// 1018h:03 revision number.
    pub revision: Option<u32>,
    /// Where the values come from, or which gap leaves them `None`.
    pub source: &'static str,
    /// The maker's vendor ID where the source gives no 1018h:01 (Mitsubishi's for its models);
    /// `None` for a model with no maker (generic CiA 402: the cell config names it).
    pub maker_vendor_id: Option<u32>,
    /// The product code the emulator presents where no source gives one: a named placeholder,
    /// not the vendor's value.
    pub emulator_product_code: u32,
}

/// What a completed homing changes (the home position reference).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum HomeReference {
    /// 607Ch Home offset := −(raw position); 6064h stays raw and the master converts
    /// (MR-J3-T04 §8.2).
    OffsetObject,
    /// 6064h is preset to the home position address (MR-J4-TM §4.10 TV-8: "6064h = the home
    /// position address"; 607Ch stays 0 without absolute detection).
    PositionPreset,
}

/// Where the drive's torque limits come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum TorqueLimitSelection {
    /// 60E0h / 60E1h as received, in 0.1 % of rated torque (CiA 402).
    Objects,
    /// MR-J3-T04 (MR-J3-T04 manual §8.14, §1.2.1, manual §8.14): Controlword2 bits C_TL / C_TL1 select
    /// between the parameters PA11 (forward) / PA12 (reverse), PC35 (internal) and 60E0h/60E1h;
    /// each direction takes the lowest selected value.
    Controlword2 {
        /// Bit of 2001h that adds 60E0h/60E1h (C_TL).
        c_tl_bit: u8,
        /// Bit of 2001h that adds PC35 (C_TL1).
        c_tl1_bit: u8,
    },
    /// MR-JET / MR-J5 torque limit 2 (MR-JET-G-N1 manual §9.1/§9.1, MR-J5-G-N1 manual): with
    /// 2D6Dh:01 = 1, controlword bit CPTL / CNTL replaces 60E0h / 60E1h by 2D6Dh:02 / :03.
    TorqueLimit2 {
        /// Controlword bit selecting the forward limit 2 (CPTL, bit 11).
        cptl_bit: u8,
        /// Controlword bit selecting the reverse limit 2 (CNTL, bit 12).
        cntl_bit: u8,
    },
}

/// A DIP-switch setting the amplifier refuses with an alarm (MR-J5-G-N1 SW3, MR-J5-G-N1 manual §2.2, §3.1, §4.3, §4.4
/// and TV-14, manual §8 Point: on a 1-axis amplifier SW3-1 OFF with SW3-2 ON raises AL.011.2).
/// The manual does not say what SW3 selects, nor when the setting is checked.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct InvalidAxisSwitch {
    /// SW3-1 in the refused setting (ON = up).
    pub sw3_1: bool,
    /// SW3-2 in the refused setting (ON = up).
    pub sw3_2: bool,
    /// The alarm raised (603Fh code).
    pub alarm: u16,
}

/// One bit of the FSoE SafeData (MR-JET-G-N1 manual §9.3, manual §9.3): SafeData byte 0–3, bit
/// 0–7, and the sub-index of its object (F701h for the master's commands, F601h for the
/// slave's status).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct SafeBit {
    /// SafeData byte, 0–3.
    pub byte: u8,
    /// Bit in that byte, 0–7.
    pub bit: u8,
    /// Sub-index of the bit's F701h / F601h entry.
    pub sub: u8,
}

impl SafeBit {
    /// Bit `bit` of SafeData byte `byte`, object sub-index `sub`.
    pub const fn new(byte: u8, bit: u8, sub: u8) -> SafeBit {
        SafeBit { byte, bit, sub }
    }

    /// The bit's value in `safe_data` (false for a byte outside it).
    pub fn get(self, safe_data: &[u8; 4]) -> bool {
        safe_data
            .get(usize::from(self.byte))
            .is_some_and(|b| (b >> (self.bit & 7)) & 1 != 0)
    }

    /// Sets the bit in `safe_data` (nothing for a byte outside it).
    pub fn set(self, safe_data: &mut [u8; 4], on: bool) {
        if let Some(b) = safe_data.get_mut(usize::from(self.byte)) {
            let m = 1u8 << (self.bit & 7);
            if on {
                *b |= m;
            } else {
                *b &= !m;
            }
        }
    }
}

/// The master's SafeData command bits (safety RxPDO 1608h, F701h): **0 activates** the
/// function (safe state), 1 cancels it; Error Ack acts on its 0→1 edge (MR-JET-G-N1 manual §9.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct FsoeCommandBits {
    /// STOC, STO command.
    pub sto: SafeBit,
    /// SS1C, SS1 command.
    pub ss1: SafeBit,
    /// SDIPC, safe direction positive.
    pub sdip: SafeBit,
    /// SDINC, safe direction negative.
    pub sdin: SafeBit,
    /// Error Ack (error clear command, rising edge).
    pub error_ack: SafeBit,
    /// SLS1C–SLS4C, safely-limited speed 1–4.
    pub sls: [SafeBit; 4],
    /// SLT1C–SLT4C, safely-limited torque 1–4.
    pub slt: [SafeBit; 4],
}

/// The slave's SafeData status bits (safety TxPDO 1A08h, F601h): **1 = function active**
/// (MR-JET-G-N1 manual §9.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct FsoeStatusBits {
    /// STOS: STO active, energy cut.
    pub sto: SafeBit,
    /// SSMS: speed at or below the SSM speed (0 with SSM disabled).
    pub ssm: SafeBit,
    /// Error: an error is present.
    pub error: SafeBit,
    /// SS1S.
    pub ss1: SafeBit,
    /// SDIPS.
    pub sdip: SafeBit,
    /// SDINS.
    pub sdin: SafeBit,
    /// SLS1S–SLS4S.
    pub sls: [SafeBit; 4],
    /// SBCS: STO active and the brake supply cut.
    pub sbc: SafeBit,
    /// SLT1S–SLT4S.
    pub slt: [SafeBit; 4],
}

/// Byte offsets of one FSoE frame in a safety PDO (MR-JET-G-N1 manual §4.3, §9.3): the same layout both
/// ways (1608h master → slave, 1A08h slave → master).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct FsoeFrameLayout {
    /// Frame size in bytes.
    pub len: u8,
    /// FSoE Command (E700h:01 / E600h:01), 1 byte.
    pub command: u8,
    /// SafeData[0]–[3], 1 byte each.
    pub safe_data: [u8; 4],
    /// CRC_0 (E700h:03 / E600h:03) and CRC_1 (:04), 2 bytes each.
    pub crc: [u8; 2],
    /// ConnectionID (E700h:02 / E600h:02), 2 bytes.
    pub connection_id: u8,
}

/// What a model's manual states about FSoE (Safety over EtherCAT, ETG.5100): the safety PDOs,
/// the SafeData bits, the objects, the watchdog and address rules (MR-JET-G-N1:
/// MR-JET-G-N1 manual §4.3, §9.3, §6, §7). The ETG.5100 command byte, CRC and connection sequence are
/// not described by the manual (§7.1 item 5).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct FsoeFacts {
    /// Safety RxPDO mapping object (1608h).
    pub rx_pdo: u16,
    /// Safety TxPDO mapping object (1A08h).
    pub tx_pdo: u16,
    /// Entries of each safety mapping (sub 00h).
    pub mapping_entries: u8,
    /// The frame layout.
    pub frame: FsoeFrameLayout,
    /// The master's command bits.
    pub commands: FsoeCommandBits,
    /// The slave's status bits.
    pub status: FsoeStatusBits,
    /// FSoE output object holding the command bits (F701h).
    pub command_object: u16,
    /// FSoE input object holding the status bits (F601h).
    pub status_object: u16,
    /// FSoE Master frame fields (E700h: :01 Command, :02 ConnectionID, :03/:04 CRC_0/CRC_1).
    pub master_frame_object: u16,
    /// FSoE Slave frame fields (E600h, same sub-indexes).
    pub slave_frame_object: u16,
    /// FSoE information object of the connection parameter set (E901h).
    pub info_object: u16,
    /// E901h sub-index of the Watchdog Time.
    pub watchdog_sub: u8,
    /// E901h sub-index of the Communication Parameter Length.
    pub comm_param_len_sub: u8,
    /// E901h sub-index of the Application Parameter Length.
    pub app_param_len_sub: u8,
    /// T_Ref, the safety refresh response processing time, µs.
    pub t_ref_us: u32,
    /// T_Com, the network response time at the shortest FSoE cycle, µs.
    pub t_com_min_us: u32,
    /// Minimum configurable watchdog time, ms (T_Ref + 4 × T_Com).
    pub watchdog_min_ms: u32,
    /// Shortest PDO cycle with FSoE, µs (**[inferred]** where the manual gives it only
    /// indirectly).
    pub min_cycle_us: u32,
    /// Range of the FSoE slave address parameter (PSC07).
    pub address_range: (u16, u16),
    /// Alarm when the slave's address differs from the master's (AL.584.1).
    pub address_mismatch_alarm: u16,
    /// The object-dictionary rows of the FSoE objects, as far as the manual states them.
    pub objects: &'static [OdEntry],
}

/// The model's cyclic communication check.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CommCheck {
    /// 8-bit incremental counter: master sends `rx_index`, the drive echoes last good + 1 in
    /// `tx_index`; `counter_alarm` for counter update errors, `loss_alarm` for lost RxPDOs
    /// (MR-J3-T04 §6).
    IncrementalCounter {
        /// RxPDO object (2020h).
        rx_index: u16,
        /// TxPDO object (2021h).
        tx_index: u16,
        /// Counter update error alarm (AL.34).
        counter_alarm: u16,
        /// RxPDO reception error alarm (AL.36).
        loss_alarm: u16,
        /// Parameter error raised at power-on when the counter check is enabled (PO03 digit 0
        /// ≠ 0) in free-run mode (PO02 = 0001h): AL.37 (MR-J3-T04 §2.4, TV-IC-5).
        free_run_alarm: u16,
        /// The master's check of the echo: lag and the error levels that stop the cell.
        master: CounterParams,
    },
    /// Watchdog counters whose algorithm the manual's missing §6.2 would give (MR-J4-TM):
    /// provisional echo of DL + 1 in UL when both are mapped; lost frames count like
    /// [`CommCheck::SyncErrorCounter`].
    WatchdogCounter {
        /// RxPDO object (2D23h Watch dog counter DL).
        rx_index: u16,
        /// TxPDO object (2D24h Watch dog counter UL).
        tx_index: u16,
        /// Alarm for lost process data (AL. 86.1).
        loss_alarm: u16,
        /// The master's check of the echo: lag and the error levels that stop the cell.
        master: CounterParams,
    },
    /// Sync-error counter against 10F1h:02 raising `alarm` (MR-JET, MR-J5: AL.086.1).
    SyncErrorCounter {
        /// The alarm raised when the counter passes the limit.
        alarm: u16,
    },
}

impl CommCheck {
    /// The (rx, tx) counter objects, if the check has a counter.
    #[inline]
    pub const fn counter_objects(&self) -> Option<(u16, u16)> {
        match *self {
            Self::IncrementalCounter {
                rx_index, tx_index, ..
            }
            | Self::WatchdogCounter {
                rx_index, tx_index, ..
            } => Some((rx_index, tx_index)),
            Self::SyncErrorCounter { .. } => None,
        }
    }

    /// The counter echo a TxPDO image carries (the check's TxPDO object among
    /// [`crate::TxPdo::extras`]); 0 where the check has no counter or the image does not carry it.
    #[inline]
    pub fn tx_counter(&self, tx: &crate::TxPdo) -> u8 {
        self.counter_objects()
            .and_then(|(_, index)| tx.extra(index))
            .map_or(0, |v| v as u8)
    }

    /// The master's default check of the counter echo, if the check has a counter.
    pub const fn master_counter(&self) -> Option<CounterParams> {
        match *self {
            Self::IncrementalCounter { master, .. } | Self::WatchdogCounter { master, .. } => {
                Some(master)
            }
            Self::SyncErrorCounter { .. } => None,
        }
    }

    /// The alarm a lost RxPDO eventually raises.
    pub const fn loss_alarm(&self) -> u16 {
        match *self {
            Self::IncrementalCounter { loss_alarm, .. }
            | Self::WatchdogCounter { loss_alarm, .. } => loss_alarm,
            Self::SyncErrorCounter { alarm } => alarm,
        }
    }
}

impl fmt::Display for AlarmInfo {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {} ({:#06X})", self.display, self.name, self.code)
    }
}

/// An object-dictionary row being written: [`od`] gives what every row has, the optional
/// default, range and units follow, and [`OdRow::cite`] completes it, so no row goes without
/// its source.
#[derive(Debug, Clone, Copy)]
pub(crate) struct OdRow(OdEntry);

/// Starts an object-dictionary row (index, sub-index, name, type, access, PDO mapping); used by
/// the model modules.
pub(crate) const fn od(
    index: u16,
    sub: u8,
    name: &'static str,
    data_type: DataType,
    access: Access,
    pdo: Pdo,
) -> OdRow {
    OdRow(OdEntry {
        index,
        sub,
        name,
        data_type,
        access,
        pdo,
        default: None,
        range: Range::Type,
        unit: Unit::None,
        source: "",
    })
}

impl OdRow {
    /// The default value the manual gives.
    pub(crate) const fn default(self, value: i64) -> OdRow {
        OdRow(OdEntry {
            default: Some(value),
            ..self.0
        })
    }

    /// The inclusive value spans the manual gives.
    pub(crate) const fn range(self, spans: &'static [(i64, i64)]) -> OdRow {
        OdRow(OdEntry {
            range: Range::Spans(spans),
            ..self.0
        })
    }

    /// The unit of one LSB (dimensionless when not given).
    pub(crate) const fn unit(self, unit: Unit) -> OdRow {
        OdRow(OdEntry { unit, ..self.0 })
    }

    /// The finished row, with the spec section it comes from and the gap named where a field
    /// is not stated.
    pub(crate) const fn cite(self, source: &'static str) -> OdEntry {
        OdEntry { source, ..self.0 }
    }
}

/// Shorthand for a PDO mapping entry of sub-index 0; used by the model modules' default maps.
pub(crate) const fn obj(index: u16, bits: u16) -> PdoEntry {
    PdoEntry::object(index, 0, bits)
}

/// Shorthand for an alarm row; used by the model modules.
pub(crate) const fn alarm(
    code: u16,
    display: &'static str,
    name: &'static str,
    kind: AlarmKind,
    stop: StopBehaviour,
    clearing: Clearing,
    source: &'static str,
) -> AlarmInfo {
    AlarmInfo {
        code,
        display,
        name,
        kind,
        stop,
        clearing,
        source,
        cause: None,
        remedy: None,
    }
}

/// The most PDO bytes one amplifier exchanges per cycle over all its axes, for a range of
/// cycle times (MR-J5-G-N1 manual §4.4): one row of the manual's table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct UnitPdoLimit {
    /// Shortest cycle time (µs) the row applies to.
    pub from_us: u32,
    /// Longest cycle time (µs) the row applies to.
    pub to_us: u32,
    /// Most RxPDO bytes (master → unit).
    pub max_rx_bytes: u16,
    /// Most TxPDO bytes (unit → master).
    pub max_tx_bytes: u16,
}

/// How a model's variable PDO mapping may be changed by SDO (16xxh/1Axxh in PRE-OP: count to
/// 0, entries, count last), and the abort codes it answers with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct PdoRules {
    /// Most entries in one mapping object.
    pub max_entries: u8,
    /// Most bytes of the RxPDO (master → drive).
    pub max_rx_bytes: u16,
    /// Most bytes of the TxPDO (drive → master).
    pub max_tx_bytes: u16,
    /// Objects that may be mapped into the RxPDO besides the model's default RxPDO entries and
    /// the object table's `Pdo::Rx` rows (the manual's list where it gives one).
    pub rx_mappable: &'static [u16],
    /// Objects that may be mapped into the TxPDO, likewise.
    pub tx_mappable: &'static [u16],
    /// Abort for an object that cannot be mapped.
    pub not_mappable_abort: u32,
    /// Abort for a mapping longer than the PDO allows.
    pub too_long_abort: u32,
    /// Abort for writing an entry, or a non-zero count, while the mapping is valid (locked).
    pub locked_abort: u32,
    /// Abort for an SDO download to an object the RxPDO maps (written cyclically instead).
    pub mapped_write_abort: u32,
    /// Abort for a mapping or cycle-time write outside PRE-OP (or once frozen).
    pub wrong_state_abort: u32,
    /// Alarms a SYNC0 cycle other than the PDO cycle written to 1C32h:02 raises when the drive
    /// starts synchronising (the first is the simulator's default; empty: the manual states
    /// none and the drive runs on SYNC0).
    pub sync_mismatch_alarms: &'static [u16],
    /// Which parts of the PDO assignment 1C12h/1C13h the master may write.
    pub assignment: PdoAssignment,
    /// True if the mapping and the PDO cycle (1C32h:02) freeze once the drive has reached
    /// SAFE-OP, until power-off (MR-J3-T04 §2.2 (4), §4.4).
    pub frozen_after_safe_op: bool,
    /// Spec sections, with the gaps named.
    pub source: &'static str,
}

/// Whether a model reports its alarms by CoE Emergency (ETG.1000.6 §5.6.2.1), with the source.
/// The payload is cellrt's choice where the manuals give none: [`EMERGENCY_LAYOUT`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct EmergencyFacts {
    /// True if the drive sends an Emergency when it raises an alarm.
    pub sends: bool,
    /// Spec sections, with the gaps named.
    pub source: &'static str,
}

/// What a model answers of SDO Information (ETG.1000.6 §5.6.3: Get OD List, Get Object
/// Description, Get Entry Description), with the source.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct SdoInfoFacts {
    /// True if the drive answers the three services (the SII's CoE details bit 1 says so).
    pub offered: bool,
    /// True if, of value-info bits 4–6 (default, minimum, maximum) requested together, only the
    /// lowest is answered (MR-J3-T04 manual §8.7); false: each requested one that is known.
    pub one_value_per_entry: bool,
    /// Object data types of records the manual gives: (first index, last index, type code).
    pub record_types: &'static [(u16, u16, u16)],
    /// Spec sections, with the gaps named.
    pub source: &'static str,
}

/// The Emergency payload every model that sends one is emulated with: error code = the alarm's
/// 603Fh value (the axis' own 603Fh at its offset index on a multi-axis unit), error register
/// 1001h = 01h (generic error), manufacturer byte 0 = axis slot (0 = A), bytes 1–4 = 0.
pub const EMERGENCY_LAYOUT: &str = "CiA 301 §7.2.7.3.1 and ETG.1000.6 §5.6.2.1 (error code, \
    error register, 5 manufacturer bytes); the Mitsubishi manuals give no payload \
    (MR-J4-TM manual §6.4 [MISSING], MR-J5-G-N1 manual §5, MR-JET-G-N1 manual §5: codes not given)";

/// How writable a model's PDO assignment objects (1C12h/1C13h) are.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PdoAssignment {
    /// Count and entries read/write in PRE-OP (count to 0, entries, count last).
    Writable,
    /// The count is fixed at 1 (read-only); sub 1 selects the mapping object (MR-J4-TM §5.1).
    FixedCount,
    /// Read-only: one fixed mapping object per direction (MR-J3-T04 §4.3, §4.4).
    ReadOnly,
}
