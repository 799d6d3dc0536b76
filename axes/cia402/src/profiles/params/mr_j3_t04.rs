//! MR-J3-T04 parameters (MR-J3-T04 manual §5.1: the parameters changed from the standard
//! MR-J3-A, with their initial values and setting ranges; the others are in the MR-J3-A manual,
//! which cellrt does not have). Each parameter is sub-index `nn` of its group's object (§8.10.1:
//! PA 2300h, PB 2301h, PC 2302h, PD 2303h, PO 2309h; the text's "3000h" is a misprint), all I32.
//! Store Parameter 1010h (§8.10.2), alarm history 2030h–2035h and its clear 2040h (§8.9), and
//! the PA19 read/write ranges (§5.1).

use super::{
    history_sub, par, AlarmHistoryFacts, ParameterFacts, SaveFacts, SaveReadback, Setting,
    WriteInhibit,
};
use crate::profiles::facts::Unit;
use crate::profiles::facts::{od, Access::*, DataType::*, OdEntry, Pdo::No};

/// Parameter group objects (§8.10.1).
const PA: u16 = 0x2300;
const PB: u16 = 0x2301;
const PC: u16 = 0x2302;
const PD: u16 = 0x2303;
const PO: u16 = 0x2309;

/// MR-J3-T04 manual §5.1, one row per parameter. Digit layouts the manual's figures lose are
/// marked [inferred] (the spec extract's reading of them).
#[rustfmt::skip]
pub const TABLE: &[super::Parameter] = &[
    par("PA01", "*STY", "Control mode", (PA, 1), I32).default(0).hex().follows_control_mode(0x0000, 0x0002).cite("§5.1: set automatically from PO02 / 6060h; do not change"),
    par("PA03", "*ABS", "Absolute position detection system", (PA, 3), I32).default(0).hex().setting(Setting::Digits(&[&[0, 2]])).cite("§5.1: 0 invalid, 2 valid (ABS transfer via EtherCAT)"),
    par("PA05", "*FBP", "For manufacturer setting", (PA, 5), I32).default(0).cite("§5.1: 0, 1000 to 50000; setting is invalid, do not change"),
    par("PA06", "*CMX", "For manufacturer setting", (PA, 6), I32).default(1).cite("§5.1: 1 to 1048576; setting is invalid, do not change"),
    par("PA07", "*CDV", "For manufacturer setting", (PA, 7), I32).default(1).cite("§5.1: 1 to 1048576; setting is invalid, do not change"),
    par("PA14", "*POL", "Rotation direction selection", (PA, 14), I32).default(0).setting(Setting::Ranges(&[(0, 1)])).cite("§5.1: 0 CCW, 1 CW for increasing address / positive speed"),
    par("PA19", "*BLK", "Parameter writing inhibit", (PA, 19), I32).default(0x000E).hex().setting(Setting::Ranges(&[(0, 0xFFFF)])).cite("§5.1: 000Bh/000Ch/000Eh/100Bh/100Ch/100Eh, any other setting PA only; the range is the MR-J3-A manual's (not in this manual): 0000h-FFFFh taken"),
    par("PB03", "PST", "Position command acceleration/deceleration time constant", (PB, 3), I32).default(0).unit(Unit::Millisecond).setting(Setting::Ranges(&[(0, 20_000)])).cite("§5.1: invalid during positioning"),
    par("PB25", "*BOP1", "Function selection B-1", (PB, 25), I32).default(0).hex().setting(Setting::Ranges(&[(0, 0)])).cite("§5.1: no other setting described"),
    par("PC01", "STA", "Acceleration time constant", (PC, 1), I32).default(0).unit(Unit::Millisecond).setting(Setting::Ranges(&[(0, 50_000)])).cite("§5.1: not applied in position control"),
    par("PC02", "STB", "Deceleration time constant", (PC, 2), I32).default(0).unit(Unit::Millisecond).setting(Setting::Ranges(&[(0, 50_000)])).not_while_enabled().cite("§5.1: slow-stop ramp of LSP/LSN/MSTOP, at most 1000 ms in csp"),
    par("PC23", "*COP2", "Function selection C-2", (PC, 23), I32).default(0).hex().setting(Setting::Ranges(&[(0, 0)])).cite("§5.1: every digit \"Please set 0\""),
    par("PC25", "*COP4", "Function selection C-4", (PC, 25), I32).default(0).hex().setting(Setting::Digits(&[&[0], &[0, 1]])).cite("§5.1: AL.E3 0 valid / 1 invalid; digit 1 [inferred]"),
    par("PC36", "*DMD", "LED power-on display selection", (PC, 36), I32).default(0).hex().setting(Setting::Ranges(&[(0, 0), (0x05, 0x06), (0x10, 0x1F)])).cite("§5.1: 00h automatic, 05h/06h/10h-1Fh EtherCAT communication status"),
    par("PD01", "*DIA1", "Input signal automatic ON selection 1", (PD, 1), I32).default(0).hex().setting(Setting::Ranges(&[(0, 0), (0x0400, 0x0400), (0x0800, 0x0800), (0x0C00, 0x0C00)])).cite("§5.1: LSP 0400h, LSN 0800h, both 0C00h; SON/PC/TL auto-ON invalid"),
    par("PD04", "*DI2", "Input signal device selection 2 (CN1-16)", (PD, 4), I32).default(0x0021_212B).hex().setting(Setting::Ranges(&[(0, 0x003F_3F3F)])).cite("§5.1: device codes 0, Ah LSP, Bh LSN, 2Bh DOG"),
    par("PD20", "*DOP1", "Function selection D-1", (PD, 20), I32).default(0).hex().setting(Setting::Digits(&[&[0, 1], &[0, 1]])).cite("§5.1: stop at LSP/LSN off (always slow in EtherCAT), base at fault reset; digits [inferred]"),
    par("PD22", "*DOP3", "Function selection D-3", (PD, 22), I32).default(0).hex().setting(Setting::Ranges(&[(0, 0x1111)])).cite("§5.1: DOG input logic"),
    par("PD24", "*DOP5", "Function selection D-5", (PD, 24), I32).default(0).hex().setting(Setting::Digits(&[&[0], &[0, 1]])).cite("§5.1: alarm code output not available (0); WNG/ALM at warning; digit 1 [inferred]"),
    par("PO02", "*ECAT", "Operation mode", (PO, 2), I32).default(0).hex().setting(Setting::Digits(&[&[0, 1], &[0, 6, 8, 9], &[0, 1, 2]])).cite("§5.1, §8.2.3: sync mode (digit 0), initial control mode, PDO cycle; digits 1-2 [inferred]"),
    par("PO03", "*CPRO", "Communication protection switch", (PO, 3), I32).default(0).hex().setting(Setting::Digits(&[&[0, 1, 2, 3], &[0], &[0, 2]])).cite("§5.1, §8.11.1: counter detection (digit 0), RxPDO error detection (digit 2)"),
];

/// Store Parameter's group sub-indices (§8.10.2): 4 PA, 5 PB, 6 PC, 7 PD, 13 PO.
const STORE_GROUPS: &[(u8, u16)] = &[(4, PA), (5, PB), (6, PC), (7, PD), (13, PO)];

/// The names of the Store Parameter group sub-indices, in [`STORE_GROUPS`] order.
const STORE_GROUP_NAMES: [&str; 5] = [
    "Store basic setting (PA)",
    "Store gain/filter (PB)",
    "Store extension setting (PC)",
    "Store I/O setting (PD)",
    "Store option unit (PO)",
];

/// The names of the alarm history records 2030h–2035h (§8.9).
const HISTORY_NAMES: [&str; 6] = [
    "Alarm history 0",
    "Alarm history 1",
    "Alarm history 2",
    "Alarm history 3",
    "Alarm history 4",
    "Alarm history 5",
];

/// Alarm history record `n` (2030h + n): its number of entries and three entries (§8.9). The
/// manual leaves the number's encoding open; the simulator reports the display number in hex
/// digits (AL.36 = 0036h), as the spec extract infers.
#[rustfmt::skip]
const fn history_record(n: usize) -> [OdEntry; 4] {
    let index = 0x2030 + n as u16;
    [
        od(index, 0, HISTORY_NAMES[n], U8, Ro, No).default(3).cite("§8.9: number of entries"),
        od(index, history_sub::NUMBER, "Alarm No.", U16, Ro, No).default(0).cite("§8.9"),
        od(index, history_sub::TIME, "Alarm time", U32, Ro, No).default(0).unit(Unit::Hour).cite("§8.9: hours of operation"),
        od(index, history_sub::DETAIL, "Alarm detail", U16, Ro, No).default(0).cite("§8.9"),
    ]
}

/// Store Parameter for all and by group (§8.10.2), the six alarm history records and the
/// history's clear (§8.9).
#[rustfmt::skip]
const fn objects() -> [OdEntry; 31] {
    let store = od(0x1010, 1, "Store all parameters", U32, Rw, No).default(3).cite("§8.10.2: write 65766173h; read 00000003h storable / 00000000h not (PA19)");
    let mut out = [store; 31];
    let mut g = 0;
    while g < STORE_GROUPS.len() {
        out[26 + g] = od(0x1010, STORE_GROUPS[g].0, STORE_GROUP_NAMES[g], U32, Rw, No).default(3).cite("§8.10.2: write 65766173h to store the group; read 3 / 0 as 1010h:01");
        g += 1;
    }
    let mut n = 0;
    while n < HISTORY_NAMES.len() {
        let record = history_record(n);
        let mut s = 0;
        while s < record.len() {
            out[1 + 4 * n + s] = record[s];
            s += 1;
        }
        n += 1;
    }
    out[25] = od(0x2040, 0, "Clear alarm history", U16, Wo, No).range(&[(0x1EA5, 0x1EA5)]).cite("§8.9: write 1EA5h");
    out
}

/// The objects of [`objects`].
pub const OBJECTS: &[OdEntry] = &objects();

/// Everything the MR-J3-T04 manual states about parameters and the alarm history.
pub const FACTS: ParameterFacts = ParameterFacts {
    table: TABLE,
    table_source: "MR-J3-T04 manual §5.1, §8.10",
    objects: OBJECTS,
    save: Ok(SaveFacts {
        object: (0x1010, 1),
        signature: super::SAVE_SIGNATURE,
        readback: SaveReadback::Availability,
        groups: STORE_GROUPS,
        source: "MR-J3-T04 manual §8.10.2",
    }),
    alarm_history: Ok(AlarmHistoryFacts {
        first: 0x2030,
        entries: 6,
        clear: (0x2040, 0x1EA5),
        source: "MR-J3-T04 manual §8.9",
    }),
    write_inhibit: Some(WriteInhibit {
        object: (PA, 19),
        settings: &[
            (0x000B, &[PA, PB, PC], false),
            (0x000C, &[PA, PB, PC, PD], false),
            (0x000E, &[PA, PB, PC, PD, PO], false),
            (0x100B, &[PA], true),
            (0x100C, &[PA, PB, PC, PD], true),
            (0x100E, &[PA, PB, PC, PD, PO], true),
        ],
        otherwise: &[PA],
    }),
};
