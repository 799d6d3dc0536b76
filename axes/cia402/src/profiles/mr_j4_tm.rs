//! Mitsubishi MR-J4-_TM_ with the ABCC-M40-ECT EtherCAT module, per the MR-J4-TM manual (
//! SH(NA)030208 rev. E, **truncated after §5.4.10**: no §5.5–§5.12, §6, chapter 7; MR-J4-TM manual).

use super::facts::{alarm, obj, od, Unit};
use super::{AccelerationUnit, PositionUnit, Stated, TorqueUnit, VelocityUnit};
use super::{
    Access, AlarmInfo, AlarmKind, Clearing, CommCheck, DataType, DriveModel, DriveProfile,
    Identity, OdEntry, Pdo, PdoAssignment, PdoRules, StopBehaviour, Units,
};
use super::{CommFacts, CycleFacts, FaultFacts, HomingSetup, LimitFacts, PdoFacts};
use super::{HomeReference, ProfileSelector, TorqueLimitSelection};
use crate::comm::CounterParams;
use crate::fsa::FsaQuirks;
use crate::mode::ModeOfOperation as M;
use crate::pdo::PdoMap;
use crate::shared_slice::SharedSlice;
use Access::{Ro, Rw};
use DataType::{I16, I32, I8, U16, U32, U8};
use Pdo::{No, Rx as PdoRx, Tx as PdoTx};

/// Default RxPDO 1600h (csp/csv/cst/hm), 29 bytes, fields unaligned after the 1-byte 6060h
/// (MR-J4-TM manual §3.3(1); offsets derived from the chapter 5 types).
pub const RX_PDO_1600: PdoMap = PdoMap {
    index: 0x1600,
    entries: SharedSlice::Static(&[
        obj(0x6060, 8),  // 0  Modes of operation
        obj(0x6040, 16), // 1  Controlword
        obj(0x2D01, 16), // 3  Control DI 1
        obj(0x2D02, 16), // 5  Control DI 2
        obj(0x2D03, 16), // 7  Control DI 3
        obj(0x607A, 32), // 9  Target position
        obj(0x60FF, 32), // 13 Target velocity
        obj(0x2D20, 32), // 17 Velocity limit value
        obj(0x6071, 16), // 21 Target torque
        obj(0x60E0, 16), // 23 Positive torque limit value
        obj(0x60E1, 16), // 25 Negative torque limit value
        obj(0x60B8, 16), // 27 Touch probe function
    ]),
};

/// Default RxPDO 1601h (pp/pv/tq/hm, the PA01 `___2` profile-mode group), 45 bytes, with
/// 6081h/6083h/6084h/6087h for the profile modes (MR-J4-TM manual §3.3(1); offsets derived).
pub const RX_PDO_1601: PdoMap = PdoMap {
    index: 0x1601,
    entries: SharedSlice::Static(&[
        obj(0x6060, 8),  // 0  Modes of operation
        obj(0x6040, 16), // 1  Controlword
        obj(0x2D01, 16), // 3  Control DI 1
        obj(0x2D02, 16), // 5  Control DI 2
        obj(0x2D03, 16), // 7  Control DI 3
        obj(0x607A, 32), // 9  Target position
        obj(0x60FF, 32), // 13 Target velocity
        obj(0x2D20, 32), // 17 Velocity limit value
        obj(0x6071, 16), // 21 Target torque
        obj(0x6081, 32), // 23 Profile velocity
        obj(0x6083, 32), // 27 Profile acceleration
        obj(0x6084, 32), // 31 Profile deceleration
        obj(0x6087, 32), // 35 Torque slope
        obj(0x60E0, 16), // 39 Positive torque limit value
        obj(0x60E1, 16), // 41 Negative torque limit value
        obj(0x60B8, 16), // 43 Touch probe function
    ]),
};

/// Default TxPDO 1A00h, 41 bytes (MR-J4-TM manual §3.3(2)).
pub const TX_PDO_1A00: PdoMap = PdoMap {
    index: 0x1A00,
    entries: SharedSlice::Static(&[
        obj(0x6061, 8),  // 0  Modes of operation display
        obj(0x6041, 16), // 1  Statusword
        obj(0x2D11, 16), // 3  Status DO 1
        obj(0x2D12, 16), // 5  Status DO 2
        obj(0x2D13, 16), // 7  Status DO 3
        obj(0x6064, 32), // 9  Position actual value
        obj(0x606C, 32), // 13 Velocity actual value
        obj(0x60F4, 32), // 17 Following error actual value
        obj(0x6077, 16), // 21 Torque actual value
        obj(0x60B9, 16), // 23 Touch probe status
        obj(0x60BA, 32), // 25 Touch probe pos1 pos value
        obj(0x60BB, 32), // 29 Touch probe pos1 neg value
        obj(0x60BC, 32), // 33 Touch probe pos2 pos value
        obj(0x60BD, 32), // 37 Touch probe pos2 neg value
    ]),
};

/// Alarm code encoding of this module: AL. XX.Y → 0x0XXY (AL. 86.1 → 0x0861); the alarm
/// objects are in the missing §6.4.
pub const AL_86_1: u16 = 0x0861;

/// The master's check of the 2D24h echo (Watch dog counter UL = DL + 1, provisional): the
/// algorithm's section is missing from the manual (MR-J4-TM manual §6.2), so the lag and the
/// levels are the MR-J3-T04's placeholders; `[watchdogs]` `counter_*` override them.
pub const MASTER_COUNTER_CHECK: CounterParams = super::mr_j3_t04::MASTER_COUNTER_CHECK;

/// AL. F4.8: a relative pp set-point with the degree position unit (MR-J4-TM manual §5.4.6 bit 6, §9).
pub const AL_F4_8: u16 = 0x0F48;
/// AL. 90 Home position return incomplete warning (§9; stroke end in methods 3–6, §5.4.9).
pub const AL_90: u16 = 0x0900;
// Following-error and overspeed alarms: no alarm chapter in this manual (MR-J4-TM manual);
// CiA 402 8611h (configurable) and 8400h [background].
pub use crate::error_code::{FOLLOWING_ERROR, OVERSPEED};

/// The alarms and warnings the seed names (MR-J4-TM manual; resettability mostly [MISSING]), with the cause
/// the seed gives in passing (§4.10.1, §5.2, §5.4.6; shared/spec/mr-j4-tm.md §9) and the disconnection
/// procedure of §1.4.4 as the remedy of AL. 86.1; the seed has no remedy column.
#[rustfmt::skip]
pub const ALARMS: &[AlarmInfo] = &[
    alarm(0x0100, "AL. 10", "Undervoltage", AlarmKind::Alarm, StopBehaviour::Unstated, Clearing::Unstated, "§9"),
    alarm(0x0250, "AL. 25", "Absolute position erased", AlarmKind::Alarm, StopBehaviour::Unstated, Clearing::Unstated, "§9"),
    alarm(0x0370, "AL. 37", "Parameter error", AlarmKind::Alarm, StopBehaviour::Unstated, Clearing::PowerCycle, "§9 [EXT]: not cleared by fault reset").explained(Some("Gear ratio 6091h other than 1 in a cyclic synchronous mode (software B2 or earlier)"), None),
    alarm(0x0690, "AL. 69", "Command error", AlarmKind::Alarm, StopBehaviour::Unstated, Clearing::Unstated, "§9"),
    alarm(AL_86_1, "AL. 86.1", "Network communication error 1", AlarmKind::Alarm, StopBehaviour::Unstated, Clearing::FaultReset, "§2.4, §8.3; [EXT] clears with fault reset").explained(Some("The network was disconnected other than by the procedure of §1.4.4"), Some("Disconnect in order: stop the motor, Shutdown in 6040h (servo off), Pre-Operational, then power off")),
    alarm(AL_90, "AL. 90", "Home position return incomplete warning", AlarmKind::Warning, StopBehaviour::SlowStop, Clearing::Automatic, "§9: the motor stops").explained(Some("Stroke end or proximity dog problem during homing"), None),
    alarm(0x0905, "AL. 90.5", "Z-phase unpassed", AlarmKind::Warning, StopBehaviour::Unstated, Clearing::Automatic, "§9").explained(Some("Homing started before the Z-phase was passed (linear, fully closed or direct drive set-ups)"), None),
    alarm(0x0920, "AL. 92", "Battery cable disconnection warning", AlarmKind::Warning, StopBehaviour::Continues, Clearing::Automatic, "§9"),
    alarm(0x09F0, "AL. 9F", "Battery warning", AlarmKind::Warning, StopBehaviour::Continues, Clearing::Automatic, "§9"),
    alarm(0x0E30, "AL. E3", "Absolute position counter warning", AlarmKind::Warning, StopBehaviour::Continues, Clearing::Automatic, "§9"),
    alarm(0x0F40, "AL. F4", "Positioning warning", AlarmKind::Warning, StopBehaviour::Unstated, Clearing::Automatic, "§9: reset by C_ORST"),
    alarm(AL_F4_8, "AL. F4.8", "Positioning warning (relative pp in degree)", AlarmKind::Warning, StopBehaviour::Unstated, Clearing::Automatic, "§9").explained(Some("A relative pp set-point while the position unit is degree"), None),
    alarm(FOLLOWING_ERROR, "8611h", "Following error (CiA 402)", AlarmKind::Alarm, StopBehaviour::DynamicBrake, Clearing::FaultReset, "not in this manual (no alarm chapter, §0): CiA 402 [background]"),
    alarm(OVERSPEED, "8400h", "Overspeed (CiA 402)", AlarmKind::Alarm, StopBehaviour::DynamicBrake, Clearing::FaultReset, "not in this manual (no alarm chapter, §0): CiA 402 [background]"),
];

/// The object dictionary (MR-J4-TM manual, chapter 7 itself MISSING): every object the seed
/// names with the attributes its chapter 3 and 5 object tables give, except the point tables
/// 2801h–28FFh and the mapping objects other than the default maps (1601h–1603h, 1A01h–1A03h:
/// the station serves one assignable mapping object per direction, [`PROFILE`] 1600h/1A00h,
/// [`PROFILE_MODE_GROUP`] 1601h/1A00h).
#[rustfmt::skip]
pub const OBJECTS: &[OdEntry] = &[
    od(0x2001, 0, "PA01 Operation mode", U32, Rw, No).default(0x1000).cite("[INFER] the copy's parameter objects (§6.5) are missing (extract §7.4: servo parameters in 2000h–25FFh); 2001h as in the MR-J4 family's MR-JE-C manual §7.3 (2001h \"PA01 to PA32\"), default 1000h; last digit: §1.3 control-mode group (PA01_SELECTOR)"),
    od(0x6098, 0, "Homing method", I8, Rw, No).default(-1).range(&[(-43, 37)]).cite("§4.10: default −1 (seed; the general manual gives 37)"),
    od(0x607C, 0, "Home offset", I32, Ro, No).default(0).unit(Unit::Pulse).cite("§4.10: always 0 without absolute position detection"),
    od(0x6099, 1, "Speed during search for switch", U32, Rw, No).default(10_000).unit(Unit::CentiRpm).cite("§5.4.9: 10000; speed until the dog"),
    od(0x6099, 2, "Speed during search for zero", U32, Rw, No).default(1_000).unit(Unit::CentiRpm).cite("§5.4.9: 1000; creep speed"),
    od(0x609A, 0, "Homing acceleration", U32, Rw, No).default(0).unit(Unit::Millisecond).cite("§5.4.9: acceleration/deceleration time constant"),
    od(0x60FD, 0, "Digital inputs", U32, Ro, No).cite("§5.4.9: stroke-end state; bits as CiA 402 [background]"),
    od(0x1C32, 2, "Cycle time", U32, Rw, No).default(250_000).range(&[(250_000, 2_000_000)]).unit(Unit::Nanosecond).cite("§1.6: 250000/500000/1000000/2000000"),
    od(0x1C32, 0, "SM output parameter", U8, Ro, No).default(12).cite("§7.3 / §3.2 (SM output/input parameter)"),
    od(0x1C32, 1, "Synchronization type", U16, Rw, No).default(0).cite("§7.3 / §3.2 (SM output/input parameter)"),
    od(0x1C32, 3, "Shift time", U32, Rw, No).default(222_222).unit(Unit::Nanosecond).cite("§7.3 / §3.2 (SM output/input parameter); set automatically, any write aborts 0609 0030h"),
    od(0x1C32, 4, "Synchronization types supported", U16, Ro, No).default(0x0025).cite("§7.3 / §3.2 (SM output/input parameter)"),
    od(0x1C32, 5, "Minimum cycle time", U32, Ro, No).default(250_000).unit(Unit::Nanosecond).cite("§7.3 / §3.2 (SM output/input parameter)"),
    od(0x1C32, 6, "Calc and copy time", U32, Ro, No).default(222_722).unit(Unit::Nanosecond).cite("§7.3 / §3.2 (SM output/input parameter)"),
    od(0x1C32, 9, "Delay time", U32, Ro, No).default(0).unit(Unit::Nanosecond).cite("§7.3 / §3.2 (SM output/input parameter)"),
    od(0x1C32, 12, "Cycle time too small", U16, Ro, No).default(0).cite("§7.3 / §3.2 (SM output/input parameter)"),
    od(0x1C33, 0, "SM input parameter", U8, Ro, No).default(12).cite("§7.3 / §3.2 (SM output/input parameter)"),
    od(0x1C33, 1, "Synchronization type", U16, Rw, No).default(0).cite("§7.3 / §3.2 (SM output/input parameter)"),
    od(0x1C33, 3, "Shift time", U32, Rw, No).default(27_778).unit(Unit::Nanosecond).cite("§7.3 / §3.2 (SM output/input parameter); set automatically, any write aborts 0609 0030h"),
    od(0x1C33, 4, "Synchronization types supported", U16, Ro, No).default(0x0025).cite("§7.3 / §3.2 (SM output/input parameter)"),
    od(0x1C33, 5, "Minimum cycle time", U32, Ro, No).default(250_000).unit(Unit::Nanosecond).cite("§7.3 / §3.2 (SM output/input parameter)"),
    od(0x1C33, 6, "Calc and copy time", U32, Ro, No).default(306_055).unit(Unit::Nanosecond).cite("§7.3 / §3.2 (SM output/input parameter)"),
    od(0x1C33, 9, "Delay time", U32, Ro, No).default(0).unit(Unit::Nanosecond).cite("§7.3 / §3.2 (SM output/input parameter)"),
    od(0x1C33, 12, "Cycle time too small", U16, Ro, No).default(0).cite("§7.3 / §3.2 (SM output/input parameter)"),
    od(0x1C33, 2, "Cycle time", U32, Ro, No).unit(Unit::Nanosecond).cite("§7.3 / §3.2 (SM output/input parameter); follows 1C32h:02"),
    od(0x2D20, 0, "Velocity limit value", I32, Rw, PdoRx).default(50_000).unit(Unit::CentiRpm).cite("§5.2; default 50000 vs 5000 unresolved (§13 q7)"),
    od(0x2D23, 0, "Watch dog counter DL", DataType::Unstated, Access::Unstated, PdoRx).cite("§8.3: §6.2 MISSING (width, rule, alarm unknown)"),
    od(0x2D24, 0, "Watch dog counter UL", DataType::Unstated, Access::Unstated, PdoTx).cite("§8.3: §6.2 MISSING"),
    od(0x6040, 0, "Controlword", U16, Rw, PdoRx).default(0).cite("§3.4"),
    od(0x6041, 0, "Statusword", U16, Ro, PdoTx).cite("§3.5"),
    od(0x605A, 0, "Quick stop option code", I16, Rw, Pdo::Unstated).default(2).cite("§8.1: values in MISSING §5.6"),
    od(0x605D, 0, "Halt option code", DataType::Unstated, Access::Unstated, Pdo::Unstated).cite("§8.2: values in MISSING §5.7"),
    od(0x6060, 0, "Modes of operation", I8, Rw, PdoRx).default(8).cite("§1.3"),
    od(0x6061, 0, "Modes of operation display", I8, Ro, PdoTx).default(8).cite("§1.3"),
    od(0x6064, 0, "Position actual value", I32, Ro, PdoTx).unit(Unit::Pulse).cite("§5.3"),
    od(0x606C, 0, "Velocity actual value", I32, Ro, PdoTx).unit(Unit::CentiRpm).cite("§4.2"),
    od(0x6071, 0, "Target torque", I16, Rw, PdoRx).default(0).unit(Unit::TenthPercentRated).cite("§4.2"),
    od(0x6077, 0, "Torque actual value", I16, Ro, PdoTx).unit(Unit::TenthPercentRated).cite("§5.3 (printed I32 in ch. 5, mapped 16 bits)"),
    od(0x607A, 0, "Target position", I32, Rw, PdoRx).default(0).unit(Unit::Pulse).cite("§5.2"),
    od(0x6085, 0, "Quick stop deceleration", U32, Rw, Pdo::Unstated).default(100).unit(Unit::Millisecond).cite("§8.1"),
    od(0x60E0, 0, "Positive torque limit value", U16, Rw, PdoRx).default(10_000).unit(Unit::TenthPercentRated).cite("§8.6: 0 = no torque"),
    od(0x60E1, 0, "Negative torque limit value", U16, Rw, PdoRx).default(10_000).unit(Unit::TenthPercentRated).cite("§8.6: 0 = no torque"),
    od(0x60F4, 0, "Following error actual value", I32, Ro, PdoTx).unit(Unit::Pulse).cite("§5.3"),
    od(0x60FF, 0, "Target velocity", I32, Rw, PdoRx).default(0).unit(Unit::CentiRpm).cite("§4.2"),
    od(0x607F, 0, "Max profile velocity", U32, Rw, Pdo::Unstated).default(2_000_000).unit(Unit::CentiRpm).cite("§4.7 (pp): limits 6081h"),
    od(0x6081, 0, "Profile velocity", U32, Rw, PdoRx).default(10_000).unit(Unit::CentiRpm).cite("§4.7 (pp); mapped in 1601h (§5.2)"),
    od(0x6083, 0, "Profile acceleration", U32, Rw, PdoRx).default(0).unit(Unit::Millisecond).cite("§4.7: acceleration time constant at the start of a move; 1601h"),
    od(0x6084, 0, "Profile deceleration", U32, Rw, PdoRx).default(0).unit(Unit::Millisecond).cite("§4.7: deceleration time constant on arrival; 1601h"),
    od(0x6080, 0, "Max motor speed", U32, Rw, Pdo::Unstated).unit(Unit::Rpm).cite("§4.7/§4.8: limits pp and pv; default \"(model)\": none here"),
    od(0x6087, 0, "Torque slope", U32, Rw, PdoRx).default(0).unit(Unit::TenthPercentPerSecond).cite("§4.9 (tq); 1601h"),
    od(0x607D, 1, "Min position limit", I32, Rw, Pdo::Unstated).default(0).unit(Unit::Pulse).cite("§4.7: 607Dh:1, default 0 (0/0: disabled, §8.5)"),
    od(0x607D, 2, "Max position limit", I32, Rw, Pdo::Unstated).default(0).unit(Unit::Pulse).cite("§4.7: 607Dh:2, default 0"),
    od(0x606D, 0, "Velocity window", U16, Rw, Pdo::Unstated).default(2_000).unit(Unit::CentiRpm).cite("§4.8 (pv target reached)"),
    od(0x606E, 0, "Velocity window time", U16, Rw, Pdo::Unstated).default(0).unit(Unit::Millisecond).cite("§4.8"),
    od(0x606F, 0, "Velocity threshold", U16, Rw, Pdo::Unstated).default(5_000).unit(Unit::CentiRpm).cite("§4.8 (pv bit 12)"),
    od(0x6070, 0, "Velocity threshold time", U16, Rw, Pdo::Unstated).default(10).unit(Unit::Millisecond).cite("§4.8"),
    od(0x6067, 0, "Position window", DataType::Unstated, Rw, Pdo::Unstated).unit(Unit::Pulse).cite("§4.7 (pp target reached); type and default in MISSING ch. 7 (§13 q4)"),
    od(0x6068, 0, "Position window time", DataType::Unstated, Rw, Pdo::Unstated).unit(Unit::Millisecond).cite("§4.7; type and default in MISSING ch. 7 (§13 q4)"),
    od(0x6502, 0, "Supported drive modes", U32, Ro, No).default(0x0000_03A0).cite("§1.3: \"differs depending on [Pr. PA01]\"; bit layout (§7.3.8(8)) MISSING, CiA 402's used: the default PA01 group hm, csp, csv, cst = bits 5, 7, 8, 9 (a live drive reported 0x3AD, field notes)"),
    // The rest of the objects the seed names (its chapter 7 object list is MISSING): types, access and defaults from the object tables of chapters 3 and 5, the gaps named.
    od(0x2A43, 0, "Point table error", U8, Ro, Pdo::Unstated).default(2).cite("§5.4.10 object table (extract §4.11): number of entries; PDO mapping in the MISSING ch. 7"),
    od(0x2A43, 1, "Point table error No.", I32, Ro, Pdo::Unstated).cite("§5.4.10 object table (extract §4.11); no default; PDO mapping in the MISSING ch. 7"),
    od(0x2A43, 2, "Point table error factor", I32, Ro, Pdo::Unstated).cite("§5.4.10 object table (extract §4.11): bit-coded (§7.3.17(5) MISSING); no default; PDO mapping in the MISSING ch. 7"),
    od(0x2D01, 0, "Control DI 1", U16, Rw, PdoRx).cite("§5.2.2, §3.3(1) (extract §3.6, §7.6): mapped in 1600h–1602h; default not stated"),
    od(0x2D02, 0, "Control DI 2", U16, Rw, PdoRx).cite("§5.2.2, §3.3(1) (extract §3.6, §7.6): mapped in 1600h–1602h; default not stated"),
    od(0x2D03, 0, "Control DI 3", U16, Rw, PdoRx).cite("§5.2.2, §3.3(1) (extract §3.6, §7.6): mapped in 1600h–1602h; default not stated"),
    od(0x2D11, 0, "Status DO 1", U16, Ro, PdoTx).cite("§5.3.2, §3.3(2) (extract §3.7, §7.6): mapped in 1A00h/1A01h; no default"),
    od(0x2D12, 0, "Status DO 2", U16, Ro, PdoTx).cite("§5.3.2, §3.3(2) (extract §3.7, §7.6): mapped in 1A00h/1A01h; no default"),
    od(0x2D13, 0, "Status DO 3", U16, Ro, PdoTx).cite("§5.3.2, §3.3(2) (extract §3.7, §7.6): mapped in 1A00h/1A01h; no default"),
    od(0x2D15, 0, "Status DO 5", U16, Ro, PdoTx).cite("§5.3.2, §3.3(2) (extract §3.7, §7.6): mapped in 1A01h; no default"),
    od(0x2D17, 0, "Status DO 7", U16, Ro, PdoTx).cite("§5.3.2, §3.3(2) (extract §3.7, §7.6): mapped in 1A01h; no default"),
    od(0x2D60, 0, "Target point table", I16, Rw, PdoRx).default(0).range(&[(-1, 255)]).cite("§5.4.10, §3.3(1) (extract §4.11): 0 no operation, 1–255 the point table, −1 high-speed homing; mapped in 1602h"),
    od(0x2D68, 0, "Point demand value", I16, Ro, PdoTx).cite("§5.4.10, §3.3(2) (extract §4.11): mapped in 1A01h; no default"),
    od(0x2D69, 0, "Point actual value", I16, Ro, PdoTx).cite("§5.4.10, §3.3(2) (extract §4.11): mapped in 1A01h; no default"),
    od(0x2D6A, 0, "M code actual value", U8, Ro, PdoTx).cite("§5.4.10, §3.3(2) (extract §4.11): mapped in 1A01h; no default"),
    od(0x2D6B, 0, "Torque limit value2", DataType::Unstated, Access::Unstated, Pdo::Unstated).cite("§5.4.9 (extract §4.10, §7.6): named by the indexer homing methods only; type, access, mapping and default in the MISSING ch. 7"),
    od(0x6063, 0, "Position actual internal value", I32, Ro, Pdo::Unstated).unit(Unit::Increment).cite("§5.4.3 object table (extract §7.8): encoder increments; PDO mapping in the MISSING ch. 7"),
    od(0x6065, 0, "Following error window", DataType::Unstated, Access::Unstated, Pdo::Unstated).cite("§5.4.3, §5.4.6 (extract §7.8): named for statusword bit 13; type, access, mapping and default in the MISSING ch. 7"),
    od(0x6066, 0, "Following error time out", DataType::Unstated, Access::Unstated, Pdo::Unstated).cite("§5.4.3, §5.4.6 (extract §7.8): named for statusword bit 13; type, access, mapping and default in the MISSING ch. 7"),
    od(0x606B, 0, "Velocity demand value", I32, Ro, Pdo::Unstated).cite("§5.4.4, §5.4.7 object tables (extract §7.9); PDO mapping in the MISSING ch. 7"),
    od(0x6072, 0, "Max torque", U16, Rw, Pdo::Unstated).cite("§5.4.5, §5.4.8 object tables (extract §7.9, §8.6): limits cst/tq; default and mapping in the MISSING ch. 7"),
    od(0x6074, 0, "Torque demand", I16, Ro, Pdo::Unstated).cite("§5.4.5, §5.4.8 object tables (extract §7.9); PDO mapping in the MISSING ch. 7"),
    od(0x607B, 0, "Position range limit", U8, Ro, Pdo::Unstated).default(2).cite("§5.4.3 object table (extract §7.9): number of entries"),
    od(0x607B, 1, "Min position range limit", I32, Rw, Pdo::Unstated).default(-2_147_483_648).unit(Unit::Pulse).cite("§5.4.3 object table (extract §7.9, §8.8): set automatically from [Pr. PT01]: −2147483648 with pulse (the unit emulated), 0 with degree"),
    od(0x607B, 2, "Max position range limit", I32, Rw, Pdo::Unstated).default(2_147_483_647).unit(Unit::Pulse).cite("§5.4.3 object table (extract §7.9, §8.8): set automatically from [Pr. PT01]: 2147483647 with pulse (the unit emulated), 359999 with degree"),
    od(0x607E, 0, "Polarity", U8, Rw, Pdo::Unstated).default(0).cite("§5.4.3 object table (extract §7.13, §8.7): bit 7 position, bit 6 velocity, bit 5 torque (B0 or later); §5.10 MISSING; PDO mapping not stated"),
    od(0x6086, 0, "Motion profile type", I16, Rw, Pdo::Unstated).default(0).cite("§5.4.6, §5.4.7 object tables (extract §7.9); PDO mapping in the MISSING ch. 7"),
    od(0x6088, 0, "Torque profile type", U32, Rw, Pdo::Unstated).default(0).cite("§5.4.8 object table (extract §7.9): printed U32; PDO mapping in the MISSING ch. 7"),
    od(0x608F, 0, "Position encoder resolution", DataType::Unstated, Access::Unstated, Pdo::Unstated).cite("§5.4.3(2) (extract §7.11): named in the gear formula only; sub-indexes, type, access and default in the MISSING ch. 7"),
    od(0x6091, 0, "Gear ratio", U8, Ro, Pdo::Unstated).default(2).cite("§5.4.3 object table (extract §7.11): number of entries"),
    od(0x6091, 1, "Motor revolutions", U32, Rw, Pdo::Unstated).default(1).cite("§5.4.3 object table (extract §7.11), Note 1: other than 1 in a cyclic mode raises AL. 37 on software B2 or earlier (not emulated)"),
    od(0x6091, 2, "Shaft revolutions", U32, Rw, Pdo::Unstated).default(1).cite("§5.4.3 object table (extract §7.11), Note 1: other than 1 in a cyclic mode raises AL. 37 on software B2 or earlier (not emulated)"),
    od(0x6092, 0, "Feed constant", U8, Ro, Pdo::Unstated).default(2).cite("§5.4.3 object table (extract §7.11), Note 2: B0 or later; number of entries"),
    od(0x6092, 1, "Feed", U32, Rw, Pdo::Unstated).cite("§5.4.3 object table (extract §7.11): travel distance per output-shaft revolution; default not legible in the seed (§7.3.14(4) MISSING)"),
    od(0x6092, 2, "Shaft revolutions", U32, Rw, Pdo::Unstated).cite("§5.4.3 object table (extract §7.11): default not legible in the seed (the extract guesses 1 [G])"),
    od(0x60A8, 0, "SI unit position", U32, Rw, Pdo::Unstated).default(0).cite("§5.4.3 object table (extract §7.11), Note 2: B0 or later; set automatically"),
    od(0x60A9, 0, "SI unit velocity", U32, Rw, Pdo::Unstated).default(0).cite("§5.4.3 object table (extract §7.11), Note 2: B0 or later"),
    od(0x60B2, 0, "Torque offset", I16, Rw, Pdo::Unstated).default(0).unit(Unit::TenthPercentRated).cite("§5.4.3 object table (extract §8.9), Note 3: B2 or later; §5.12 MISSING; PDO mapping not stated"),
    od(0x60B8, 0, "Touch probe function", U16, Rw, PdoRx).cite("§3.3(1) (extract §7.12): mapped in 1600h–1602h, type from the map size; §5.5 MISSING; no default"),
    od(0x60B9, 0, "Touch probe status", U16, Ro, PdoTx).cite("§3.3(2) (extract §7.12): mapped in 1A00h/1A01h, type from the map size; §5.5 MISSING"),
    od(0x60BA, 0, "Touch probe pos1 pos value", I32, Ro, PdoTx).cite("§3.3(2) (extract §7.12): mapped in 1A00h/1A01h, type from the map size; §5.5 MISSING"),
    od(0x60BB, 0, "Touch probe pos1 neg value", I32, Ro, PdoTx).cite("§3.3(2) (extract §7.12): mapped in 1A00h/1A01h, type from the map size; §5.5 MISSING"),
    od(0x60BC, 0, "Touch probe pos2 pos value", I32, Ro, PdoTx).cite("§3.3(2) (extract §7.12): mapped in 1A00h/1A01h, type from the map size; §5.5 MISSING"),
    od(0x60BD, 0, "Touch probe pos2 neg value", I32, Ro, PdoTx).cite("§3.3(2) (extract §7.12): mapped in 1A00h/1A01h, type from the map size; §5.5 MISSING; unit not stated"),
    od(0x60E3, 0, "Supported homing method", U8, Ro, Pdo::Unstated).default(39).cite("§5.4.9 object table (extract §4.10): number of entries"),
    od(0x60E3, 1, "1st supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 2, "2nd supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 3, "3rd supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 4, "4th supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 5, "5th supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 6, "6th supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 7, "7th supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 8, "8th supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 9, "9th supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 10, "10th supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 11, "11th supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 12, "12th supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 13, "13th supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 14, "14th supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 15, "15th supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 16, "16th supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 17, "17th supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 18, "18th supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 19, "19th supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 20, "20th supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 21, "21st supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 22, "22nd supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 23, "23rd supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 24, "24th supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 25, "25th supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 26, "26th supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 27, "27th supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 28, "28th supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 29, "29th supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 30, "30th supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 31, "31st supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 32, "32nd supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 33, "33rd supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 34, "34th supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 35, "35th supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 36, "36th supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 37, "37th supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 38, "38th supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60E3, 39, "39th supported homing method", I8, Ro, Pdo::Unstated).cite("§5.4.9 object table (extract §4.10): which method each sub-index holds is not stated"),
    od(0x60FA, 0, "Control effort", I32, Ro, Pdo::Unstated).unit(Unit::CentiRpm).cite("§5.4.3 object table (extract §7.8): position loop output, Vel unit; PDO mapping in the MISSING ch. 7"),
];

/// Encoder and units (MR-J4-TM manual, §4.2).
pub const UNITS: Units = Units {
    counts_per_rev: Some(4_194_304),
    other_counts_per_rev: &[],
    position: PositionUnit::Count,
    velocity: Stated::Manual(VelocityUnit::CENTI_RPM),
    linear_motors: true,
    command_truncation_exp10: None,
    acceleration: Stated::Manual(AccelerationUnit::TimeConstantMs),
    torque: TorqueUnit::PerMilleOfRated,
    source: "MR-J4-TM manual §1.2 (22-bit rotary encoder), §4.2 (Vel unit 0.01 r/min or 0.01 mm/s \
             for 60FFh/606Ch/6081h/6099h/2D20h; 6083h–6085h time constants in ms; torque objects \
             0.1 %)",
};

/// The MR-J4-TM profile (PA01 = `___0`/`___1`: the cyclic group csp/csv/cst/hm).
///
/// Identity: vendor/product only from an external source ([EXT] linuxcnc-ethercat), so `None`
/// here per the spec rule (manual silent). Cycles 0.25–2 ms (§1.6; no 0.125, 4 or 8 ms). Quirks:
/// skips allowed (§3.2), quick stop present, **never returns from Quick stop active** (16 not
/// supported, §3.3). Fault reset held ≥ 10 ms (§3.2).
pub const PROFILE: DriveProfile = DriveProfile {
    model: DriveModel::MrJ4TM,
    name: "Mitsubishi MR-J4-TM",
    identity: Identity {
        vendor_id: None,
        product_code: None,
        revision: None,
        source: "MR-J4-TM manual: not in the manual; [EXT] 0x00000A1E / 0x00000201 unverified",
        maker_vendor_id: Some(super::MITSUBISHI_VENDOR_ID),
        // The [EXT] value (unverified).
        emulator_product_code: 0x0000_0201,
    },
    cycle: CycleFacts {
        // §1.3: the PA01 groups are exclusive; the default group is csp/csv/cst/hm ([EXT]/[G]).
        modes: SharedSlice::Static(&[
            M::Homing,
            M::CyclicSyncPosition,
            M::CyclicSyncVelocity,
            M::CyclicSyncTorque,
        ]),
        cycle_times_us: &[250, 500, 1000, 2000],
        // §8.2: bit 8 is reserved in csp/csv/cst.
        halt_in_cyclic_modes: false,
        csp_entry: crate::mode_switch::CspEntry::ActualPosition,
    },
    pdo: PdoFacts {
        rx: RX_PDO_1600,
        tx: TX_PDO_1A00,
        unit_limits: &[],
        rules: PdoRules {
            // §5.1: 1C12h:0 = 1C13h:0 = 1 read-only; sub 1 selects one of 1600h–1603h / 1A00h–1A03h.
            assignment: PdoAssignment::FixedCount,
            source: "MR-J4-TM manual §3.2, §3.4 (32 objects, 64 bytes, only in PRE-OP), §6.2 (the same abort list as the MR-JET)",
            ..super::mr_jet_g_n1::PDO_RULES
        },
    },
    quirks: FsaQuirks {
        shortcut_transitions: true,
        has_quick_stop: true,
        quick_stop_returns_to_enabled: false,
        quick_stop_options_5_to_8: false,
    },
    faults: FaultFacts {
        reset_hold_ms: 10,
        reset_hold_long_cycle_ms: 10,
        long_cycle_from_us: u32::MAX,
        alarms: ALARMS,
    },
    axes_per_unit: 1,
    units: UNITS,
    objects: OBJECTS,
    comm: CommFacts {
        check: CommCheck::WatchdogCounter {
            rx_index: 0x2D23,
            tx_index: 0x2D24,
            loss_alarm: AL_86_1,
            master: MASTER_COUNTER_CHECK,
        },
        leave_op_alarm: AL_86_1,
        // §10: leaving Op clears the internal state (servo off, SOD) [D].
        reinit_on_leaving_op: true,
        emergency: EMERGENCY,
        sdo_info: SDO_INFO,
    },
    limits: LimitFacts {
        following_error_alarm: FOLLOWING_ERROR,
        overspeed_alarm: OVERSPEED,
        torque_limit_selection: TorqueLimitSelection::Objects,
        stroke_end_warning: None,
        power_warnings: None,
        manual_stop_bit: None,
        relative_degree_warning: Some(AL_F4_8),
    },
    sdo_write_refusals: &[
        // §12 TV-10: the shift times 1C32h:03 / 1C33h:03 are not settable (0609 0030h; the
        // extract's §7.3: "any write to 1C32h:3 or 1C33h:3").
        (0x1C32, 3, 0x0609_0030),
        (0x1C33, 3, 0x0609_0030),
    ],
    homing: HomingSetup {
        // §4.10.1: the 39 methods of 60E3h (−3 data set, 35/37 current position).
        methods: &[
            -1, -33, -2, -34, -3, -4, -36, -6, -38, -7, -39, -8, -40, -9, -41, -10, -42, -11, -43, 3,
            4, 5, 6, 7, 8, 11, 12, 19, 20, 21, 22, 23, 24, 27, 28, 33, 34, 35, 37,
        ],
        data_set_methods: &[-3, 35, 37],
        reference: HomeReference::PositionPreset,
        setting: None,
    },
    store_restore_objects: &[],
    invalid_axis_switch: None,
    profile_selector: Some(PA01_SELECTOR),
    fsoe: None,
    parameters: &super::params::MR_J4_TM,
};

/// [Pr. PA01]'s last digit selects the control-mode group (§1.3 table): `___0`/`___1` the
/// cyclic synchronous group ([`PROFILE`]), `___2` the profile modes ([`PROFILE_MODE_GROUP`]);
/// `___6`/`___8` (point table, indexer) are groups cellrt does not model. When a written PA01
/// takes effect the copy of the manual does not say: the emulator takes it at once, so a
/// start-up list can set it in PRE-OP ([INFER]).
pub const PA01_SELECTOR: ProfileSelector = ProfileSelector {
    index: 0x2001,
    sub: 0,
    select: pa01_group,
    source: "MR-J4-TM manual §1.3, §5.4.1 (PA01 groups); object 2001h [INFER]",
};

fn pa01_group(value: i64) -> Option<(&'static DriveProfile, M)> {
    let group = match value & 0xF {
        0 | 1 => ModeGroup::CyclicSynchronous,
        2 => ModeGroup::Profile,
        _ => return None,
    };
    Some((group.profile(), group.initial_mode()))
}

/// The PA01 `___2` profile-mode group: pp, pv, tq and hm with the 1601h RxPDO, initial mode pp
/// (MR-J4-TM manual §1.1(2), §5.4.1 table, §5.2). Never available together with csp/csv/cst (§1.3 [EXT]), so it
/// is a profile of its own; select it with [`ModeGroup::Profile`]. Everything else as
/// [`PROFILE`].
pub const PROFILE_MODE_GROUP: DriveProfile = DriveProfile {
    name: "Mitsubishi MR-J4-TM (PA01 ___2, profile mode)",
    cycle: CycleFacts {
        modes: SharedSlice::Static(&[
            M::ProfilePosition,
            M::ProfileVelocity,
            M::ProfileTorque,
            M::Homing,
        ]),
        ..PROFILE.cycle
    },
    pdo: PdoFacts {
        rx: RX_PDO_1601,
        ..PROFILE.pdo
    },
    ..PROFILE
};

/// The control-mode group selected by [Pr. PA01] (last digit, MR-J4-TM manual §1.1(2), §5.4.1 / manual
/// §5.4.1): the drive parameter that decides which modes 6060h accepts. The default is the
/// cyclic group (`___0`/`___1`, 6061h = 8 at start-up).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum ModeGroup {
    /// PA01 `___0` (automatic, [G]) or `___1`: csp, csv, cst, hm with 1600h ([`PROFILE`]).
    #[default]
    CyclicSynchronous,
    /// PA01 `___2`: pp, pv, tq, hm with 1601h ([`PROFILE_MODE_GROUP`]).
    Profile,
}

impl ModeGroup {
    /// The drive profile of this group.
    pub const fn profile(self) -> &'static DriveProfile {
        match self {
            ModeGroup::CyclicSynchronous => &PROFILE,
            ModeGroup::Profile => &PROFILE_MODE_GROUP,
        }
    }

    /// The mode 6060h/6061h hold at start-up (§1.3 table "Default 6060h/6061h").
    pub const fn initial_mode(self) -> M {
        match self {
            ModeGroup::CyclicSynchronous => M::CyclicSyncPosition,
            ModeGroup::Profile => M::ProfilePosition,
        }
    }
}

/// What the drive answers of SDO Information.
pub const SDO_INFO: super::SdoInfoFacts = super::SdoInfoFacts {
    offered: true,
    one_value_per_entry: false,
    record_types: &[],
    source: "MR-J4-TM manual §4.1 (Get OD List, Get Object Description, Get Entry Description; the AB6916-B module lists only 710 objects); record type codes and value-info rules not given",
};

/// Whether alarms are also sent as CoE Emergency (payload: [`crate::profiles::facts::EMERGENCY_LAYOUT`]).
pub const EMERGENCY: super::EmergencyFacts = super::EmergencyFacts {
    sends: true,
    source:
        "MR-J4-TM manual §4.1 (\"Alarms are reported by CoE Emergency\"), §8.10 (payload [MISSING])",
};

/// Likely causes of a refused state change (bring-up names those that fit beside the AL status
/// code). The AL. 37 clearing class is not in the MR-J4-TM manual: it is from a reading of the
/// troubleshooting manual (SH(NA)030109) outside the manuals cellrt follows, marked so.
pub const BRING_UP_CAUSES: &[super::BringUpCause] = &[
    super::BringUpCause {
        al_codes: &[],
        modes: &[M::ProfilePosition, M::ProfileVelocity, M::ProfileTorque],
        free_run_only: false,
        cause: "pp, pv and tq run only with [Pr. PA01] last digit 2 (the profile-mode group with RxPDO 1601h; a drive in the cyclic group has no 1601h): set PA01 = ___2, e.g. in the start-up list ([[axes.ethercat.startup_sdo]] object = \"2001h\", 2001h [INFER])",
        source: "MR-J4-TM manual §5.4.1, §1.3",
    },
    super::BringUpCause {
        al_codes: &[],
        modes: &[M::CyclicSyncPosition, M::CyclicSyncVelocity, M::CyclicSyncTorque],
        free_run_only: false,
        cause: "csp, csv and cst run only with [Pr. PA01] last digit 0 or 1 (the cyclic synchronous group); PA01 ___2 selects the profile modes pp/pv/tq instead",
        source: "MR-J4-TM manual §5.4.1, §1.1(2)",
    },
    super::BringUpCause {
        al_codes: &[],
        modes: &[M::CyclicSyncPosition, M::CyclicSyncVelocity, M::CyclicSyncTorque],
        free_run_only: true,
        cause: "software B3 or earlier runs csp/csv/cst only in DC mode (free-run answers \"state transition not allowed\"); set distributed_clocks = true",
        source: "MR-J4-TM manual §1.1(2) Note 1, §1.3",
    },
    super::BringUpCause {
        al_codes: &[],
        modes: &[],
        free_run_only: false,
        cause: "AL. 37 (parameter error, e.g. 6091h gear ratio other than 1 in the cyclic synchronous modes on software B2 or earlier) clears only with a communication reset (AL state back to INIT) or a power cycle, not with a fault reset (clearing class from the troubleshooting manual SH(NA)030109, outside the manuals cellrt follows: verify)",
        source: "MR-J4-TM manual §5.4.3(2)",
    },
];

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cycles::CycleTime;

    #[test]
    fn tv_6_rx_1600h_offsets_unaligned() {
        // TV-6 step 2 bytes 0, 1–2, 9–12, 17–20, 23–24, 25–26 of the 29-byte 1600h.
        let m = &PROFILE.pdo.rx;
        assert_eq!(m.byte_len(), 29);
        let expect = [
            (0x6060, 0),
            (0x6040, 1),
            (0x2D01, 3),
            (0x2D02, 5),
            (0x2D03, 7),
            (0x607A, 9),
            (0x60FF, 13),
            (0x2D20, 17),
            (0x6071, 21),
            (0x60E0, 23),
            (0x60E1, 25),
            (0x60B8, 27),
        ];
        for (idx, off) in expect {
            assert_eq!(m.offset_of(idx, 0), Some(off), "{idx:#06x}");
        }
        assert!(!m.has_counter(), "2D23h is not in the default map");
    }

    #[test]
    fn tx_1a00h_offsets() {
        let m = &PROFILE.pdo.tx;
        assert_eq!(m.byte_len(), 41);
        for (idx, off) in [
            (0x6061, 0),
            (0x6041, 1),
            (0x6064, 9),
            (0x606C, 13),
            (0x60F4, 17),
            (0x6077, 21),
            (0x60B9, 23),
            (0x60BD, 37),
        ] {
            assert_eq!(m.offset_of(idx, 0), Some(off), "{idx:#06x}");
        }
    }

    #[test]
    fn cycles_and_modes() {
        for us in [250, 500, 1000, 2000] {
            assert!(PROFILE.supports_cycle_time(CycleTime::from_micros(us).unwrap()));
        }
        for us in [125, 4000, 8000] {
            assert!(!PROFILE.supports_cycle_time(CycleTime::from_micros(us).unwrap()));
        }
        assert!(PROFILE.supports_mode(M::CyclicSyncTorque));
        assert!(!PROFILE.supports_mode(M::ProfilePosition));
        let pm = ModeGroup::Profile.profile();
        assert!(pm.supports_mode(M::ProfilePosition) && pm.supports_mode(M::Homing));
        assert!(
            !pm.supports_mode(M::CyclicSyncPosition),
            "the groups are exclusive"
        );
        assert_eq!(pm.pdo.rx.byte_len(), 45, "1601h is 45 bytes (§5.2)");
        assert_eq!(pm.pdo.rx.offset_of(0x6081, 0), Some(23));
        assert_eq!(pm.pdo.rx.offset_of(0x60B8, 0), Some(43));
        assert_eq!(ModeGroup::default().profile(), &PROFILE);
        assert_eq!(PROFILE.vendor_id(), None);
        assert_eq!(PROFILE.units.counts_per_rev, Some(4_194_304));
    }

    #[test]
    fn the_objects_the_seed_names_are_served() {
        // (index, sub, type, access, PDO, default) as the object tables of §3.3 and §5.4 print them.
        let rows = [
            (0x2A43, 0, U8, Ro, Pdo::Unstated, Some(2)),
            (0x2D01, 0, U16, Rw, PdoRx, None),
            (0x2D17, 0, U16, Ro, PdoTx, None),
            (0x2D60, 0, I16, Rw, PdoRx, Some(0)),
            (0x2D6A, 0, U8, Ro, PdoTx, None),
            (0x6072, 0, U16, Rw, Pdo::Unstated, None),
            (0x607B, 1, I32, Rw, Pdo::Unstated, Some(-2_147_483_648)),
            (0x607B, 2, I32, Rw, Pdo::Unstated, Some(2_147_483_647)),
            (0x607E, 0, U8, Rw, Pdo::Unstated, Some(0)),
            (0x6086, 0, I16, Rw, Pdo::Unstated, Some(0)),
            (0x6088, 0, U32, Rw, Pdo::Unstated, Some(0)),
            (0x6091, 1, U32, Rw, Pdo::Unstated, Some(1)),
            (0x6092, 0, U8, Ro, Pdo::Unstated, Some(2)),
            (0x60B2, 0, I16, Rw, Pdo::Unstated, Some(0)),
            (0x60B8, 0, U16, Rw, PdoRx, None),
            (0x60BD, 0, I32, Ro, PdoTx, None),
            (0x60E3, 0, U8, Ro, Pdo::Unstated, Some(39)),
            (0x60E3, 39, I8, Ro, Pdo::Unstated, None),
            (0x60FA, 0, I32, Ro, Pdo::Unstated, None),
        ];
        super::super::assert_rows(&PROFILE, &rows);
        assert_eq!(
            PROFILE.object(0x2D60, 0).and_then(|o| o.range.bounds()),
            Some((-1, 255))
        );
        // Named only (their chapter 7 rows are MISSING): served with every field unstated.
        let named = [0x2D6B, 0x6065, 0x6066, 0x608F].map(|index| {
            (
                index,
                0,
                DataType::Unstated,
                Access::Unstated,
                Pdo::Unstated,
                None,
            )
        });
        super::super::assert_rows(&PROFILE, &named);
        // The profile-mode group serves the same dictionary.
        assert_eq!(PROFILE_MODE_GROUP.objects, PROFILE.objects);
    }
}
