//! Servo parameters as objects (MR-JE-C manual §5, §7.3): [Pr. PA01] is object 2001h, [Pr.
//! PN02] 2582h, and so on. The initial values and ranges the network manual gives, for the
//! parameters it describes; the others start at 0 (their manuals are companions we do not
//! have) and take any U32.

use super::types::Range;

/// A parameter group and its object block base (index = base + number).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, strum::Display)]
pub enum Group {
    /// Basic setting, 2001h–2020h.
    PA,
    /// Gain/filter, 2081h–20C0h.
    PB,
    /// Extension setting, 2101h–2150h.
    PC,
    /// I/O setting, 2181h–21B0h.
    PD,
    /// Extension setting 2, 2201h–2240h.
    PE,
    /// Extension setting 3, 2281h–22B0h.
    PF,
    /// Positioning control, 2481h–24D0h.
    PT,
    /// Network setting, 2581h–25B0h.
    PN,
}

impl Group {
    const fn base(self) -> u16 {
        match self {
            Group::PA => 0x2000,
            Group::PB => 0x2080,
            Group::PC => 0x2100,
            Group::PD => 0x2180,
            Group::PE => 0x2200,
            Group::PF => 0x2280,
            Group::PT => 0x2480,
            Group::PN => 0x2580,
        }
    }
}

/// One parameter, e.g. [Pr. PN02].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Parameter {
    /// Group.
    pub group: Group,
    /// Number within the group (1-based).
    pub number: u8,
}

impl Parameter {
    /// Its object index.
    pub const fn index(self) -> u16 {
        self.group.base() + self.number as u16
    }
}

impl std::fmt::Display for Parameter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "[Pr. {}{:02}]", self.group, self.number)
    }
}

const fn p(group: Group, number: u8) -> Parameter {
    Parameter { group, number }
}

/// [Pr. PC03] S-pattern acceleration/deceleration time constant, ms (MR-JE-C manual §5.1.1).
pub const PC03: Parameter = p(Group::PC, 3);
/// The largest [Pr. PC03], ms. The network manual gives PC03 no setting range (its range is in
/// the servo amplifier instruction manual, which we do not have): 5000 ms, the MR-JE/MR-J4
/// families' upper limit, is our choice.
pub const PC03_MAX_MS: i64 = 5000;
/// [Pr. PC30] Acceleration time constant 2, ms (idx with C_RT, MR-JE-C manual §7.5.8).
pub const PC30: Parameter = p(Group::PC, 30);
/// [Pr. PC31] Deceleration time constant 2, ms (idx with C_RT, MR-JE-C manual §7.5.8).
pub const PC31: Parameter = p(Group::PC, 31);
/// [Pr. PC70] Modbus RTU station number (0: never answers).
pub const PC70: Parameter = p(Group::PC, 70);
/// [Pr. PC71] Function selection C-F: digit `__x_` the Modbus RTU bit rate (§5.2.3).
pub const PC71: Parameter = p(Group::PC, 71);
/// [Pr. PF45] Function selection F-12: digit `___x` the Modbus RTU parity and stop bits (§5.2.6).
pub const PF45: Parameter = p(Group::PF, 45);
/// [Pr. PF46] Modbus RTU communication time-out, s (0: not checked).
pub const PF46: Parameter = p(Group::PF, 46);
/// [Pr. PT28] Number of stations per rotation (idx, MR-JE-C manual §7.3 607Bh, 6092h).
pub const PT28: Parameter = p(Group::PT, 28);
/// [Pr. PN02] CC-Link IE Field Basic communication error detection time, ms (0: off).
pub const PN02: Parameter = p(Group::PN, 2);
/// [Pr. PN08] Function selection N-2 (digit x___: 0 Ethernet, 1 RS-485).
pub const PN08: Parameter = p(Group::PN, 8);
/// [Pr. PN10] Ethernet communication time-out selection, s (0: off; SW A4+).
pub const PN10: Parameter = p(Group::PN, 10);
/// [Pr. PN23] KeepAlive time, s: the interval of the TCP alive check on Modbus/TCP (§5.2.3).
pub const PN23: Parameter = p(Group::PN, 23);

/// A parameter the network manual describes: initial value and setting range.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ParameterDef {
    /// The parameter.
    pub parameter: Parameter,
    /// Symbol.
    pub symbol: &'static str,
    /// Initial value.
    pub initial: u32,
    /// Setting range ([`Range::Type`] where the manual gives none).
    pub range: Range,
}

const fn d(parameter: Parameter, symbol: &'static str, initial: u32, range: Range) -> ParameterDef {
    ParameterDef {
        parameter,
        symbol,
        initial,
        range,
    }
}

const OCTET: Range = Range::Between(0, 255);
const OCTET_END: Range = Range::Between(0, 256);

/// The parameters of MR-JE-C manual §5 that the emulator uses: communication (§5.2), and the
/// PC parameters linked to objects (§5.1, `links`).
pub const PARAMETERS: &[ParameterDef] = &[
    d(p(Group::PC, 1), "STA", 0, Range::Type),
    d(p(Group::PC, 2), "STB", 0, Range::Type),
    d(PC03, "STC", 0, Range::Between(0, PC03_MAX_MS)),
    // "1000.0 %" printed: 10000 in the 0.1 % of its object 2D6Bh (§7.3).
    d(p(Group::PC, 35), "TL2", 10000, Range::Type),
    d(p(Group::PC, 51), "RSBR", 100, Range::Type),
    d(PC70, "*SNOM", 0, Range::Between(0, 247)),
    d(PC71, "*COPF", 0x0040, Range::Type),
    d(p(Group::PC, 72), "*COPG", 0x0000, Range::Type),
    d(p(Group::PC, 75), "FEWL", 0x0000, Range::Type),
    d(p(Group::PC, 76), "FEWH", 0x00C0, Range::Type),
    d(p(Group::PC, 77), "FEWF", 10, Range::Type),
    d(PF45, "*FOP12", 0x0000, Range::Type),
    d(PF46, "MIC", 0, Range::Between(0, 60)),
    d(PN02, "CERT", 1000, Range::Between(0, 1000)),
    d(PN08, "*NOP2", 0x0000, Range::Type),
    d(PN10, "EIC", 0, Range::Between(0, 60)),
    d(p(Group::PN, 11), "*IPAD1", 192, OCTET),
    d(p(Group::PN, 12), "*IPAD2", 168, OCTET),
    d(p(Group::PN, 13), "*IPAD3", 3, OCTET),
    d(p(Group::PN, 14), "*IPAD4", 0, OCTET),
    d(p(Group::PN, 15), "*SNMK1", 255, OCTET),
    d(p(Group::PN, 16), "*SNMK2", 255, OCTET),
    d(p(Group::PN, 17), "*SNMK3", 255, OCTET),
    d(p(Group::PN, 18), "*SNMK4", 0, OCTET),
    d(p(Group::PN, 19), "*DGW1", 192, OCTET),
    d(p(Group::PN, 20), "*DGW2", 168, OCTET),
    d(p(Group::PN, 21), "*DGW3", 3, OCTET),
    d(p(Group::PN, 22), "*DGW4", 1, OCTET),
    d(PN23, "*KAA", 3600, Range::Between(1, 7200)),
    d(p(Group::PN, 24), "*IPAF1", 0, OCTET),
    d(p(Group::PN, 25), "*IPAF2", 0, OCTET),
    d(p(Group::PN, 26), "*IPAF3", 0, OCTET),
    d(p(Group::PN, 27), "*IPAF4", 0, OCTET),
    d(p(Group::PN, 28), "*IPFR2", 256, OCTET_END),
    d(p(Group::PN, 29), "*IPFR3", 256, OCTET_END),
    d(p(Group::PN, 30), "*IPFR4", 256, OCTET_END),
    d(p(Group::PN, 31), "*IPOA1", 0, OCTET),
    d(p(Group::PN, 32), "*IPOA2", 0, OCTET),
    d(p(Group::PN, 33), "*IPOA3", 0, OCTET),
    d(p(Group::PN, 34), "*IPOA4", 0, OCTET),
    d(p(Group::PN, 35), "*IPOR3", 256, OCTET_END),
    d(p(Group::PN, 36), "*IPOR4", 256, OCTET_END),
];

/// The description of the parameter at object `index`, if the manual gives one.
pub fn definition(index: u16) -> Option<&'static ParameterDef> {
    PARAMETERS.iter().find(|d| d.parameter.index() == index)
}
