//! Servo parameters by the names the manuals give them (PA01, PC02, …): one row per parameter
//! with the object that carries it, its default and its setting range, and per model the
//! parameter save (1010h) and the alarm history objects. One definition read by the operator's
//! `cellrt param` / `cellrt alarms` checks and by the simulated drive's SDO surface.

mod mr_j3_t04;
mod mr_jet_g_n1;

pub use mr_j3_t04::FACTS as MR_J3_T04;
pub use mr_jet_g_n1::FACTS as MR_JET_G_N1;

/// MR-J4-TM: the copy of the manual cellrt has ends after §5.4.10.
pub const MR_J4_TM: ParameterFacts = ParameterFacts::none(
    "the MR-J4-TM manual's parameter objects (§6.5) and Store parameters 1010h (§7.1) are \
     missing from its copy (it ends after §5.4.10), and it gives no alarm history object",
);

/// A generic CiA 402 drive: no vendor parameters.
pub const GENERIC_CIA402: ParameterFacts = ParameterFacts::none(
    "a generic CiA 402 drive (CiA 402 / ETG.6010) has no vendor parameter table, save or alarm \
     history in cellrt; use `cellrt sdo` with the drive's own manual",
);

use super::facts::{od, Access, DataType, OdEntry, Pdo, Range};

/// What a model's manual states about its parameters, their storage and its alarm history.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ParameterFacts {
    /// The parameters the manual gives with their object, one row each.
    pub table: &'static [Parameter],
    /// Where the table comes from, or why the manual gives none.
    pub table_source: &'static str,
    /// The save and alarm-history objects the table's model serves besides its profile's.
    pub objects: &'static [OdEntry],
    /// The parameter save (1010h), or why the model has none (the manual named).
    pub save: Result<SaveFacts, &'static str>,
    /// The alarm history objects, or why the model has none (the manual named).
    pub alarm_history: Result<AlarmHistoryFacts, &'static str>,
    /// The parameter-write inhibit parameter (MR-J3-T04 PA19), where the model has one.
    pub write_inhibit: Option<WriteInhibit>,
}

impl ParameterFacts {
    /// A model whose manual gives no parameter objects, no save and no alarm history: each
    /// refusal names `why` (the manual and what it lacks).
    pub const fn none(why: &'static str) -> ParameterFacts {
        ParameterFacts {
            table: &[],
            table_source: why,
            objects: &[],
            save: Err(why),
            alarm_history: Err(why),
            write_inhibit: None,
        }
    }

    /// The parameter named `name` (case-insensitive, as the manual prints it: "PA14").
    pub fn parameter(&self, name: &str) -> Option<&'static Parameter> {
        self.table
            .iter()
            .find(|p| p.name.eq_ignore_ascii_case(name))
    }

    /// The parameter carried by object `index:sub`.
    pub fn by_object(&self, index: u16, sub: u8) -> Option<&'static Parameter> {
        self.table
            .iter()
            .find(|p| p.object.index == index && p.object.sub == sub)
    }
}

/// One servo parameter as its manual gives it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Parameter {
    /// The parameter number, e.g. "PA14".
    pub name: &'static str,
    /// The abbreviation as printed, with the manual's `*` for "takes effect after power off/on"
    /// (e.g. "*POL"); "" where the manual prints none.
    pub symbol: &'static str,
    /// The object that carries it: index, sub-index, the parameter's name, type, access,
    /// default and the envelope of its setting range, with the manual's section.
    pub object: OdEntry,
    /// The values the manual allows.
    pub setting: Setting,
    /// How a value is shown (function-selection parameters in hex, as the manual prints them).
    pub display: Display,
    /// Whether cellrt writes it while the axis is in Operation enabled.
    pub while_enabled: WhileEnabled,
    /// A value the drive sets itself, where the manual says so.
    pub derived: Option<Derived>,
}

/// A parameter value the drive sets itself.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Derived {
    /// Follows the control mode in force: `position` in a position mode or homing, `velocity`
    /// in a velocity mode (MR-J3-T04 PA01: "automatically changed according to the current
    /// operating mode", 0 position/homing, 2 speed).
    ControlMode {
        /// The value in csp, hm (and the other position modes).
        position: i64,
        /// The value in csv (and the other velocity modes).
        velocity: i64,
    },
}

impl Parameter {
    /// When a written value takes effect: the manual's `*` symbol.
    pub fn effect(&self) -> Effect {
        if self.symbol.starts_with('*') {
            Effect::AfterPowerCycle
        } else {
            Effect::Immediately
        }
    }

    /// `value` as the manual prints it ("000Eh" or "250").
    pub fn format(&self, value: i64) -> String {
        self.display.format(value)
    }

    /// Why `value` may not be written ("PA14 takes 0..1: 2 is out of it"); `None` if it may.
    pub fn refuse(&self, value: i64) -> Option<String> {
        match self.setting {
            Setting::DoNotChange => Some(format!(
                "{} ({}) is not to be changed (\"Setting is invalid. Do not change this \
                 parameter.\", {}); not written",
                self.name, self.object.name, self.object.source
            )),
            s if s.allows(value) => None,
            s => Some(format!(
                "{} ({}) takes {}: {} is out of it; not written",
                self.name,
                self.object.name,
                s.text(self.display),
                self.format(value)
            )),
        }
    }
}

/// When a parameter change takes effect.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Effect {
    /// At once.
    Immediately,
    /// After the control power is switched off and on (the manual's `*`); the value must be
    /// saved (1010h) first or it is lost.
    AfterPowerCycle,
}

impl Effect {
    /// Short text for listings.
    pub const fn as_str(self) -> &'static str {
        match self {
            Effect::Immediately => "immediately",
            Effect::AfterPowerCycle => "after power cycle",
        }
    }
}

/// Whether cellrt writes a parameter while its axis is in Operation enabled. The manuals do
/// not forbid it; cellrt's own rule refuses it for a parameter that takes effect at once and
/// shapes the motion of an enabled axis (a ramp or a torque limit), so a commissioning write
/// cannot change a moving axis under the operator's feet.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WhileEnabled {
    /// Written in any state.
    Allowed,
    /// Refused while the axis is in Operation enabled (cellrt's rule, see above).
    Refused,
}

/// How a parameter's value is printed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Display {
    /// Decimal.
    Decimal,
    /// Four (or eight) hex digits with the manual's `h`, e.g. "000Eh".
    Hex,
}

impl Display {
    /// `value` in this display.
    pub fn format(self, value: i64) -> String {
        match self {
            Display::Decimal => value.to_string(),
            Display::Hex if (0..=0xFFFF).contains(&value) => format!("{value:04X}h"),
            Display::Hex => format!("{:08X}h", value as u32),
        }
    }
}

/// The values a parameter takes, as its manual states them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Setting {
    /// Any value in one of these inclusive ranges (a single value is a range of one).
    Ranges(&'static [(i64, i64)]),
    /// Hex digits from digit 0 up, each one of the listed values; higher digits are 0.
    Digits(&'static [&'static [u8]]),
    /// "Setting is invalid. Do not change this parameter.": cellrt does not write it.
    DoNotChange,
}

impl Setting {
    /// True if the manual allows `v`.
    pub fn allows(self, v: i64) -> bool {
        match self {
            Setting::Ranges(r) => r.iter().any(|(lo, hi)| (*lo..=*hi).contains(&v)),
            Setting::Digits(d) => {
                let digits_left = v >> (4 * d.len());
                v >= 0
                    && digits_left == 0
                    && d.iter()
                        .enumerate()
                        .all(|(i, ok)| ok.contains(&(((v >> (4 * i)) & 0xF) as u8)))
            }
            Setting::DoNotChange => false,
        }
    }

    /// The allowed values as text, e.g. "0..20000" or "0000h, 0002h" or "digit 0: 0/1, …".
    pub fn text(self, display: Display) -> String {
        match self {
            Setting::Ranges(r) => {
                let parts: Vec<String> = r
                    .iter()
                    .map(|(lo, hi)| match lo == hi {
                        true => display.format(*lo),
                        false => format!("{}..{}", display.format(*lo), display.format(*hi)),
                    })
                    .collect();
                parts.join(", ")
            }
            Setting::Digits(d) => {
                let parts: Vec<String> = d
                    .iter()
                    .enumerate()
                    .map(|(i, ok)| {
                        let v: Vec<String> = ok.iter().map(|x| format!("{x:X}")).collect();
                        format!("digit {i}: {}", v.join("/"))
                    })
                    .collect();
                format!("hex {}", parts.join(", "))
            }
            Setting::DoNotChange => "(do not change)".into(),
        }
    }

    /// The object's stated range: the spans of a range setting, the envelope of a digit-wise
    /// one.
    const fn envelope(self) -> Range {
        match self {
            Setting::Ranges([]) => Range::Type,
            Setting::Ranges(r) => Range::Spans(r),
            Setting::Digits(d) => {
                let mut hi = 0i64;
                let mut i = 0;
                while i < d.len() {
                    let mut j = 0;
                    let mut top = 0u8;
                    while j < d[i].len() {
                        if d[i][j] > top {
                            top = d[i][j];
                        }
                        j += 1;
                    }
                    hi |= (top as i64) << (4 * i);
                    i += 1;
                }
                Range::Between(0, hi)
            }
            Setting::DoNotChange => Range::Type,
        }
    }
}

/// The value written to 1010h:01 to save the parameters: "save" as little-endian ASCII.
pub const SAVE_SIGNATURE: u32 = 0x6576_6173;

/// The parameter save of a model (CiA 301 1010h Store parameters).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SaveFacts {
    /// The object written to save every parameter (1010h:01).
    pub object: (u16, u8),
    /// The value that starts the save, "save" as little-endian ASCII (65766173h).
    pub signature: u32,
    /// What a read of the object returns.
    pub readback: SaveReadback,
    /// Sub-indices of the save object that store one parameter group, with the group's
    /// object (MR-J3-T04 1010h:04 PA … 1010h:13 PO); empty where the model stores all only.
    pub groups: &'static [(u8, u16)],
    /// The manual's section.
    pub source: &'static str,
}

/// What an SDO read of 1010h:01 returns on a model.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SaveReadback {
    /// 00000003h where the parameters can be stored, 00000000h where not (MR-J3-T04 manual
    /// §8.10.2; the same section's "returns to 0 after storing" is the ambiguity the extract
    /// flags: cellrt serves the availability code).
    Availability,
    /// bit 0 = 1 when idle, 0 while saving (MR-JET-G-N1 / MR-J5-G-N1 manuals §3.2).
    IdleBit,
}

/// A model's alarm history objects.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AlarmHistoryFacts {
    /// The newest entry's record (2030h); entry n is at `first + n`.
    pub first: u16,
    /// Number of entries (MR-J3-T04: 6, the newest and the five before it).
    pub entries: u8,
    /// The clear object and the value that clears (2040h, 1EA5h).
    pub clear: (u16, u16),
    /// The manual's section.
    pub source: &'static str,
}

/// Sub-indices of one alarm history record (MR-J3-T04 manual §8.9).
pub mod history_sub {
    /// Alarm No.
    pub const NUMBER: u8 = 1;
    /// Alarm time (hours of operation).
    pub const TIME: u8 = 2;
    /// Alarm detail.
    pub const DETAIL: u8 = 3;
}

/// The parameter-write inhibit (MR-J3-T04 PA19 *BLK, manual §5.1): which parameter groups
/// (by object index) can be read and written, by its setting at power-on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WriteInhibit {
    /// The inhibit parameter's object.
    pub object: (u16, u8),
    /// Per setting: the readable groups' objects, and whether writing is limited to the
    /// inhibit parameter itself (else the writable range equals the readable one).
    pub settings: &'static [(i64, &'static [u16], bool)],
    /// The groups of any other setting (readable and writable).
    pub otherwise: &'static [u16],
}

impl SaveFacts {
    /// What writing the signature to save-object sub-index `sub` stores: `Some(None)` every
    /// parameter, `Some(Some(group))` one group's; `None` for no store sub-index.
    pub fn stores(&self, sub: u8) -> Option<Option<u16>> {
        if sub == self.object.1 {
            return Some(None);
        }
        self.groups
            .iter()
            .find(|(s, _)| *s == sub)
            .map(|(_, g)| Some(*g))
    }
}

impl WriteInhibit {
    /// (readable groups, writing limited to the inhibit parameter) for `setting`.
    pub fn access(&self, setting: i64) -> (&'static [u16], bool) {
        self.settings
            .iter()
            .find(|(s, _, _)| *s == setting)
            .map_or((self.otherwise, false), |(_, g, only)| (*g, *only))
    }
}

/// A parameter row being written: [`par`] starts it, the default and the setting follow, and
/// [`ParRow::cite`] completes it with the manual's section.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ParRow(Parameter);

/// Starts a parameter row: number, symbol, name, the object (index, sub-index) and its type.
pub(crate) const fn par(
    name: &'static str,
    symbol: &'static str,
    title: &'static str,
    object: (u16, u8),
    data_type: DataType,
) -> ParRow {
    ParRow(Parameter {
        name,
        symbol,
        object: od(object.0, object.1, title, data_type, Access::Rw, Pdo::No).cite(""),
        setting: Setting::DoNotChange,
        display: Display::Decimal,
        while_enabled: WhileEnabled::Allowed,
        derived: None,
    })
}

impl ParRow {
    /// The initial value the manual gives.
    pub(crate) const fn default(self, value: i64) -> ParRow {
        let mut p = self.0;
        p.object.default = Some(value);
        ParRow(p)
    }

    /// The values the manual allows.
    pub(crate) const fn setting(self, setting: Setting) -> ParRow {
        let mut p = self.0;
        p.setting = setting;
        p.object.range = setting.envelope();
        ParRow(p)
    }

    /// Shown in hex, as the manual prints it.
    pub(crate) const fn hex(self) -> ParRow {
        let mut p = self.0;
        p.display = Display::Hex;
        ParRow(p)
    }

    /// The unit of one LSB.
    pub(crate) const fn unit(self, unit: super::facts::Unit) -> ParRow {
        let mut p = self.0;
        p.object.unit = unit;
        ParRow(p)
    }

    /// Refused while the axis is enabled ([`WhileEnabled::Refused`]).
    pub(crate) const fn not_while_enabled(self) -> ParRow {
        let mut p = self.0;
        p.while_enabled = WhileEnabled::Refused;
        ParRow(p)
    }

    /// Set by the drive from the control mode in force ([`Derived::ControlMode`]).
    pub(crate) const fn follows_control_mode(self, position: i64, velocity: i64) -> ParRow {
        let mut p = self.0;
        p.derived = Some(Derived::ControlMode { position, velocity });
        ParRow(p)
    }

    /// The finished row with its source.
    pub(crate) const fn cite(self, source: &'static str) -> Parameter {
        let mut p = self.0;
        p.object.source = source;
        p
    }
}

#[cfg(test)]
mod tests;
