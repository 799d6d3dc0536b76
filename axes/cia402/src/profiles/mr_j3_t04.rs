//! Mitsubishi MR-J3-□A-RJ158 + MR-J3-T04 EtherCAT option, per the MR-J3-T04 manual (
//! "MR-J3-□A-RJ158 / MR-J3-T04 Specifications", 2011-12-01).

use super::facts::{alarm, obj, od, Unit};
use super::{AccelerationUnit, PositionUnit, Stated, TorqueUnit, VelocityUnit};
use super::{
    Access, AlarmInfo, AlarmKind, Clearing, CommCheck, DataType, DriveModel, DriveProfile,
    Identity, OdEntry, Pdo, PdoAssignment, PdoRules, StopBehaviour, Units,
};
use super::{CommFacts, CycleFacts, FaultFacts, HomingSetup, LimitFacts, PdoFacts};
use super::{HomeReference, HomeSetting, TorqueLimitSelection};
use crate::comm::CounterParams;
use crate::fsa::FsaQuirks;
use crate::mode::ModeOfOperation as M;
use crate::pdo::PdoMap;
use crate::shared_slice::SharedSlice;
use Access::{Ro, Rw};
use DataType::{I16, I32, I8, U16, U32, U8};
use Pdo::{No, Rx as PdoRx, Tx as PdoTx};

/// The master's check of the 2021h echo: lag L = 1 (the timing figure is lost, MR-J3-T04
/// manual §8.11.1, errata #4) and 3 wrong echoes in a row, or 3 within 1000 cycles, stop the
/// cell. The manual raises AL.34 "consecutively or frequently more than a regulated level"
/// without the level (§8.11.1, errata #3): **placeholders**, `[watchdogs]` `counter_*` override
/// them.
pub const MASTER_COUNTER_CHECK: CounterParams = CounterParams {
    echo_lag: crate::comm::DEFAULT_ECHO_LAG,
    detector: crate::comm::UNSTATED_LEVEL,
};

/// Default RxPDO 1614h, 30 bytes (MR-J3-T04 manual §8.5.1, §8.6.2, 13 entries).
pub const RX_PDO_1614: PdoMap = PdoMap {
    index: 0x1614,
    entries: SharedSlice::Static(&[
        obj(0x2020, 8),  // 0  Incremental counter (RxPDO)
        obj(0x2022, 8),  // 1  Frame ID (reserved)
        obj(0x6040, 16), // 2  Controlword
        obj(0x2001, 16), // 4  Controlword2
        obj(0x2002, 16), // 6  Controlword3 (reserved)
        obj(0x2003, 16), // 8  Controlword4 (reserved)
        obj(0x2004, 16), // 10 Controlword5 (reserved)
        obj(0x607A, 32), // 12 Target position
        obj(0x60FF, 32), // 16 Target velocity
        obj(0x2050, 32), // 20 Max velocity (reserved)
        obj(0x6071, 16), // 24 Target torque (reserved)
        obj(0x60E0, 16), // 26 Positive torque limit value
        obj(0x60E1, 16), // 28 Negative torque limit value
    ]),
};

/// Default TxPDO 1A14h, 26 bytes (MR-J3-T04 manual §8.5.2, §8.6.2, 11 entries).
pub const TX_PDO_1A14: PdoMap = PdoMap {
    index: 0x1A14,
    entries: SharedSlice::Static(&[
        obj(0x2021, 8),  // 0  Incremental counter (TxPDO)
        obj(0x2023, 8),  // 1  Frame ID (reserved, sent as 0)
        obj(0x6041, 16), // 2  Statusword
        obj(0x2011, 16), // 4  Statusword2
        obj(0x2012, 16), // 6  Statusword3 (reserved)
        obj(0x2013, 16), // 8  Statusword4 (reserved)
        obj(0x2014, 16), // 10 Statusword5 (reserved)
        obj(0x6064, 32), // 12 Position actual value
        obj(0x606C, 32), // 16 Velocity actual value
        obj(0x60F4, 32), // 20 Following error actual value
        obj(0x6077, 16), // 24 Torque actual value
    ]),
};

/// Alarm code encoding: the display number as hex-coded BCD, AL.34 → 0x0034 (2041h encoding is
/// not in the manual; MR-J3-T04 manual (inferred) default, configurable).
pub const AL_34: u16 = 0x0034;
/// AL.35 Command frequency error: commands beyond the maximum motor speed (§7.2).
pub const AL_35: u16 = 0x0035;
/// AL.36 Receive error 2: RxPDO lost for about 7 ms (§6.4).
pub const AL_36: u16 = 0x0036;
/// AL.E6 Servo emergency stop (warning): EM1 OFF (§3.7).
pub const AL_E6: u16 = 0x00E6;
/// AL.E9 Main circuit off warning: Enable operation with the main circuit off (§3.7).
pub const AL_E9: u16 = 0x00E9;
/// AL.99 Stroke limit warning: LSP or LSN in the commanded direction is OFF (§7.2, §9.1).
pub const AL_99: u16 = 0x0099;
/// AL.90 Home position not completed (warning, §7.2: homing aborted).
pub const AL_90: u16 = 0x0090;
/// AL.37 Parameter error (§7.2).
pub const AL_37: u16 = 0x0037;
/// AL.52 Error excessive: standard MR-J3-A alarm, **not in this manual** (§7.1).
pub const AL_52: u16 = 0x0052;
/// AL.61 Operation error: AL state left OP during operation (§2.5, §7.2).
pub const AL_61: u16 = 0x0061;

/// The alarms and warnings of MR-J3-T04 manual §7.1, §7.2, §3.7, §3.9, §5.1, §8.5.2 (deactivation columns of §7.1),
/// with the cause and action columns of §7.2 where the manual fills them (none for AL.92, AL.9F, AL.E3, AL.E6, AL.EA
/// or the standard-J3A AL.52).
#[rustfmt::skip]
pub const ALARMS: &[AlarmInfo] = &[
    alarm(0x0013, "AL.13", "Clock error", AlarmKind::Alarm, StopBehaviour::DynamicBrake, Clearing::PowerCycle, "§7.2; reset rule from the standard J3A manual (not in manual)").explained(Some("Noise in the synchronous signal; or parts in the servo amplifier or the option unit are faulty"), Some("Configure the synchronization in the master again after acting against noise and restarting the servo amplifier; else replace the servo amplifier or the option unit")),
    alarm(0x0026, "AL.26", "Home position setting error", AlarmKind::Alarm, StopBehaviour::DynamicBrake, Clearing::PowerCycle, "§7.2").explained(Some("C_CR2 turned on before the Z-phase was passed"), Some("Turn C_CR2 on after the Z-phase has been passed")),
    alarm(AL_34, "AL.34", "Receive error 1", AlarmKind::Alarm, StopBehaviour::DynamicBrake, Clearing::PowerCycle, "§6.4, §7.2: incremental-counter update error").explained(Some("Update error in the incremental counter; or leakage in the synchronization signal reception"), Some("Update the incremental counter as specified, send PDOs and configure correct synchronization; else replace the servo amplifier or the option unit")),
    alarm(AL_35, "AL.35", "Command frequency error", AlarmKind::Alarm, StopBehaviour::DynamicBrake, Clearing::FaultReset, "§7.2: the only alarm of this manual cleared by fault reset").explained(Some("Commands exceeded the servo motor maximum speed; or command data damaged by noise"), Some("Check the operation program; act against noise")),
    alarm(AL_36, "AL.36", "Receive error 2", AlarmKind::Alarm, StopBehaviour::DynamicBrake, Clearing::PowerCycle, "§6.4, §7.2: RxPDO lost about 7 ms").explained(Some("PDO communication faulty: EtherCAT cable faulty, master communication settings/processing faulty, or faulty parts in the servo amplifier or option unit"), Some("Replace the EtherCAT cable; use a master that satisfies the EtherCAT standards; else replace the servo amplifier or the option unit")),
    alarm(AL_37, "AL.37", "Parameter error", AlarmKind::Alarm, StopBehaviour::DynamicBrake, Clearing::PowerCycle, "§7.2").explained(Some("Parameters rewritten by a servo amplifier fault; a regenerative option not for this amplifier selected in PA02; over 100,000 EEPROM writes; or incremental-counter update error detection enabled in asynchronous mode"), Some("Replace the servo amplifier; set PA02 correctly; use asynchronous mode only without the incremental-counter update error detection")),
    alarm(AL_52, "AL.52", "Error excessive", AlarmKind::Alarm, StopBehaviour::DynamicBrake, Clearing::FaultReset, "not in manual: standard MR-J3-A (±3 rev), §7.1"),
    alarm(AL_61, "AL.61", "Operation error", AlarmKind::Alarm, StopBehaviour::DynamicBrake, Clearing::PowerCycle, "§2.5, §7.2").explained(Some("The AL state changed to other than Operational during operation (master request)"), Some("Restart the servo amplifier and start the operation again")),
    alarm(0x0074, "AL.74", "Option card error", AlarmKind::Alarm, StopBehaviour::DynamicBrake, Clearing::PowerCycle, "§7.2").explained(Some("Initial synchronization failed in synchronous mode; or the MR-J3-T04 option unit is faulty"), Some("Configure correct synchronization in the master after acting against noise and restarting the servo amplifier; else replace the option unit")),
    alarm(0x0076, "AL.76", "Synchronization error", AlarmKind::Alarm, StopBehaviour::DynamicBrake, Clearing::PowerCycle, "§7.2").explained(Some("Synchronization setting incorrect, noise on the synchronous signal, bad connection to the MR-J3-T04, master timing error, or broken communication cable"), Some("Correct the synchronization settings; act against noise; review the amplifier to option unit connection, the master timing settings and the communication cable")),
    alarm(AL_90, "AL.90", "Home position not completed", AlarmKind::Warning, StopBehaviour::SlowStop, Clearing::Automatic, "§7.2: homing aborted").explained(Some("Homing could not decelerate to creep speed; or a limit switch acted during a homing started other than beyond the dog"), Some("Review the homing speed, creep speed and proximity dog position")),
    alarm(0x0092, "AL.92", "Battery cable disconnection", AlarmKind::Warning, StopBehaviour::Continues, Clearing::Automatic, "§7.2 (standard J3A)"),
    alarm(0x0096, "AL.96", "Home position setting warning", AlarmKind::Warning, StopBehaviour::Continues, Clearing::Automatic, "§7.2").explained(Some("C_CR2 turned on before the Z-phase was passed"), Some("Turn C_CR2 on after the Z-phase has been passed")),
    alarm(AL_99, "AL.99", "Stroke limit warning", AlarmKind::Warning, StopBehaviour::SlowStop, Clearing::Automatic, "§7.2, §9.1").explained(Some("The stroke end (LSP or LSN) of the commanded direction is off"), Some("Review the operation pattern so LSP and LSN stay on")),
    alarm(0x009F, "AL.9F", "Battery warning", AlarmKind::Warning, StopBehaviour::Continues, Clearing::Automatic, "§7.2 (standard J3A)"),
    alarm(0x00E3, "AL.E3", "Absolute position counter warning", AlarmKind::Warning, StopBehaviour::Continues, Clearing::Automatic, "§7.2"),
    alarm(AL_E6, "AL.E6", "Servo emergency stop", AlarmKind::Warning, StopBehaviour::ServoOff, Clearing::Automatic, "§3.7, §7.2"),
    alarm(AL_E9, "AL.E9", "Main circuit off warning", AlarmKind::Warning, StopBehaviour::Continues, Clearing::Automatic, "§7.2").explained(Some("Enable operation while the main circuit power supply is off"), Some("Turn on the main circuit power supply")),
    alarm(0x00EA, "AL.EA", "(name not given)", AlarmKind::Warning, StopBehaviour::ServoOff, Clearing::Automatic, "§7.2"),
];

/// The object dictionary (MR-J3-T04 manual): the objects the runtime and the simulator use and
/// the rest of the §8.3.2 object list (the reserved objects included), with the types, access,
/// mapping and defaults of §8.2–§8.12 where the manual gives them. 1C10h/1C11h (named in the
/// list's "1C10h to 1C13h") are not served: the mailbox sync managers carry no PDOs.
#[rustfmt::skip]
pub const OBJECTS: &[OdEntry] = &[
    od(0x6098, 0, "Homing method", I8, Rw, No).default(-1).range(&[(-17, 35)]).cite("§8.1: −1 (default), −17, 35"),
    od(0x607C, 0, "Home offset", I32, Ro, No).default(0).unit(Unit::Pulse).cite("§8.2: −(raw position of the home)"),
    od(0x6099, 1, "Speed during search for switch", U32, Rw, No).default(500_000).unit(Unit::MilliRpm).cite("§8.11.4.1: 500000 = 500 r/min"),
    od(0x6099, 2, "Speed during search for zero", U32, Rw, No).default(10_000).unit(Unit::MilliRpm).cite("§8.11.4.1: 10000 = 10 r/min (creep)"),
    od(0x609A, 0, "Homing acceleration", U32, Rw, No).default(100).unit(Unit::Millisecond).cite("§8.11.4.1: acceleration time constant"),
    od(0x2080, 0, "Home position shift distance", U32, Rw, No).default(0).unit(Unit::Pulse).cite("§8.11.4.1: shift from the Z phase"),
    od(0x1C32, 2, "Cycle time", U32, Rw, No).default(500_000).range(&[(500_000, 2_000_000)]).unit(Unit::Nanosecond).cite("§5.2: only 500000/1000000/2000000"),
    od(0x1C32, 0, "SM output parameter", U8, Ro, No).default(9).cite("§8.2.2 (SM output/input parameter)"),
    od(0x1C32, 1, "Synchronization type", U16, Rw, No).default(2).cite("§8.2.2 (SM output/input parameter); 2 = DC SYNC0 (ETG.1020; the manual gives the value, not its meaning)"),
    od(0x1C32, 3, "Shift time", U32, Ro, No).default(0).unit(Unit::Nanosecond).cite("§8.2.2 (SM output/input parameter)"),
    od(0x1C32, 4, "Synchronization types supported", U16, Ro, No).default(0x0004).cite("§8.2.2 (SM output/input parameter)"),
    od(0x1C32, 5, "Minimum cycle time", U32, Ro, No).default(500_000).unit(Unit::Nanosecond).cite("§8.2.2 (SM output/input parameter)"),
    od(0x1C32, 6, "Calc and copy time", U32, Ro, No).default(166_666).unit(Unit::Nanosecond).cite("§8.2.2 (SM output/input parameter); at 0.5 ms (216200 at 1 ms, 316200 at 2 ms: the emulator keeps the 0.5 ms value)"),
    od(0x1C32, 7, "Reserved", U32, Ro, No).default(0).cite("§8.2.2 (SM output/input parameter)"),
    od(0x1C32, 8, "Get cycle time", U16, Rw, No).default(0).cite("§8.2.2 (SM output/input parameter)"),
    od(0x1C32, 9, "Delay time", U32, Ro, No).default(166_666).unit(Unit::Nanosecond).cite("§8.2.2 (SM output/input parameter)"),
    od(0x1C33, 0, "SM input parameter", U8, Ro, No).default(9).cite("§8.2.2 (SM output/input parameter)"),
    od(0x1C33, 1, "Synchronization type", U16, Rw, No).default(2).cite("§8.2.2 (SM output/input parameter); 2 = DC SYNC0 (ETG.1020; the manual gives the value, not its meaning)"),
    od(0x1C33, 3, "Shift time", U32, Ro, No).default(0).unit(Unit::Nanosecond).cite("§8.2.2 (SM output/input parameter)"),
    od(0x1C33, 4, "Synchronization types supported", U16, Ro, No).default(0x0004).cite("§8.2.2 (SM output/input parameter)"),
    od(0x1C33, 5, "Minimum cycle time", U32, Ro, No).default(500_000).unit(Unit::Nanosecond).cite("§8.2.2 (SM output/input parameter)"),
    od(0x1C33, 6, "Calc and copy time", U32, Ro, No).default(166_666).unit(Unit::Nanosecond).cite("§8.2.2 (SM output/input parameter); at 0.5 ms (216200 at 1 ms, 316200 at 2 ms: the emulator keeps the 0.5 ms value)"),
    od(0x1C33, 7, "Reserved", U32, Ro, No).default(0).cite("§8.2.2 (SM output/input parameter)"),
    od(0x1C33, 8, "Get cycle time", U16, Rw, No).default(0).cite("§8.2.2 (SM output/input parameter)"),
    od(0x1C33, 9, "Delay time", U32, Ro, No).default(0).unit(Unit::Nanosecond).cite("§8.2.2 (SM output/input parameter)"),
    od(0x1C33, 2, "Cycle time", U32, Ro, No).unit(Unit::Nanosecond).cite("§8.2.2 (SM output/input parameter); follows 1C32h:02"),
    od(0x2001, 0, "Controlword2", U16, Rw, PdoRx).default(0).cite("§3.6"),
    od(0x2011, 0, "Statusword2", U16, Ro, PdoTx).cite("§3.6"),
    od(0x2020, 0, "Incremental counter (RxPDO)", U8, Rw, PdoRx).range(&[(0, 255)]).cite("§6"),
    od(0x2021, 0, "Incremental counter (TxPDO)", U8, Ro, PdoTx).range(&[(0, 255)]).cite("§6"),
    od(0x2041, 0, "Current alarm", U16, Ro, PdoTx).cite("§5.3: encoding not specified"),
    od(0x6040, 0, "Controlword", U16, Rw, PdoRx).default(0).cite("§5.4"),
    od(0x6041, 0, "Statusword", U16, Ro, PdoTx).cite("§5.4"),
    od(0x605D, 0, "Halt option code", I16, Rw, No).default(1).range(&[(1, 1)]).cite("§3.8: hm only"),
    od(0x6060, 0, "Modes of operation", I8, Rw, PdoRx).default(0).cite("§5.4: 0, 6, 8, 9"),
    od(0x6061, 0, "Modes of operation display", I8, Ro, PdoTx).default(0).cite("§5.4: set from PO02 at power-on"),
    od(0x6064, 0, "Position actual value", I32, Ro, PdoTx).unit(Unit::Pulse).cite("§5.4"),
    od(0x606C, 0, "Velocity actual value", I32, Ro, PdoTx).unit(Unit::MilliRpm).cite("§5.4"),
    od(0x6071, 0, "Target torque", I16, Rw, PdoRx).default(0).unit(Unit::None).cite("§5.4: not supported"),
    od(0x6077, 0, "Torque actual value", I16, Ro, PdoTx).unit(Unit::TenthPercentRated).cite("§5.4 (printed RW, treated RO)"),
    od(0x607A, 0, "Target position", I32, Rw, PdoRx).default(0).unit(Unit::Pulse).cite("§5.4"),
    od(0x60E0, 0, "Positive torque limit value", U16, Rw, PdoRx).default(3000).unit(Unit::TenthPercentRated).cite("§5.4, §9.4"),
    od(0x60E1, 0, "Negative torque limit value", U16, Rw, PdoRx).default(3000).unit(Unit::TenthPercentRated).cite("§5.4, §9.4"),
    od(0x60F4, 0, "Following error actual value", I32, Ro, PdoTx).unit(Unit::Pulse).cite("§5.4: csp only"),
    od(0x60FF, 0, "Target velocity", I32, Rw, PdoRx).default(0).unit(Unit::MilliRpm).cite("§5.4: clamped at 120 % max speed"),
    od(0x6502, 0, "Supported drive modes", U32, Ro, No).default(0x0000_01A0).cite("§1.2: bits 5, 7, 8"),
    // The rest of the §8.3.2 object list (the reserved objects as the manual lists them).
    od(0x2002, 0, "Controlword3 (not supported)", U16, Rw, PdoRx).default(0).cite("§8.3.2, §8.5.3: (Reserved)"),
    od(0x2003, 0, "Controlword4 (not supported)", U16, Rw, PdoRx).default(0).cite("§8.3.2, §8.5.3: (Reserved)"),
    od(0x2004, 0, "Controlword5 (not supported)", U16, Rw, PdoRx).default(0).cite("§8.3.2, §8.5.3: (Reserved)"),
    od(0x2012, 0, "Statusword3 (not supported)", U16, Ro, PdoTx).cite("§8.3.2, §8.5.4: (Reserved); no default stated"),
    od(0x2013, 0, "Statusword4 (not supported)", U16, Ro, PdoTx).cite("§8.3.2, §8.5.4: (Reserved); no default stated"),
    od(0x2014, 0, "Statusword5 (not supported)", U16, Ro, PdoTx).cite("§8.3.2, §8.5.4: (Reserved); no default stated"),
    od(0x2022, 0, "Frame ID (RxPDO) (not supported)", U8, Rw, PdoRx).cite("§8.3.2, §8.5.3: (Reserved); no default stated"),
    od(0x2023, 0, "Frame ID (TxPDO) (not supported)", U8, Ro, PdoTx).cite("§8.3.2, §8.5.4: (Reserved); no default stated"),
    od(0x2024, 0, "Slave Axis No.", U16, Rw, No).default(0).cite("§8.3.2, §8.11.2: 0000h no axis number on the 7-segment LED, 0001h–FFFFh shown"),
    od(0x2050, 0, "Max velocity (not supported)", U32, Rw, PdoRx).default(0).range(&[(0, 0x7FFF_FFFF)]).unit(Unit::MilliRpm).cite("§8.3.2, §8.5.3: (Reserved), torque mode only; 0 = rated speed"),
    od(0x2100, 0, "Monitor (Servo)", U8, Ro, No).default(25).cite("§8.8: number of entries; access not printed (RO: §8.8 \"read by SDO\")"),
    od(0x2100, 1, "Monitor 1 Cumulative feedback pulses", I32, Access::Unstated, No).unit(Unit::Pulse).cite("§8.8: I32, no default; access not printed; cleared by writing 00001EA5h, a clear the emulator does not model (a write is stored)"),
    od(0x2100, 2, "Monitor 2 Servo motor speed", I32, Ro, No).unit(Unit::Rpm).cite("§8.8: I32, no default; access not printed (RO: §8.8 \"read by SDO\")"),
    od(0x2100, 3, "Monitor 3 Droop pulses", I32, Ro, No).unit(Unit::Pulse).cite("§8.8: I32, no default; access not printed (RO: §8.8 \"read by SDO\")"),
    od(0x2100, 4, "Monitor 4 Cumulative command pulses", I32, Access::Unstated, No).unit(Unit::Pulse).cite("§8.8: I32, no default; access not printed; cleared by writing 00001EA5h, a clear the emulator does not model (a write is stored)"),
    od(0x2100, 5, "Monitor 5 Command pulse frequency", I32, Ro, No).unit(Unit::KiloPulsePerSecond).cite("§8.8: I32, no default; access not printed (RO: §8.8 \"read by SDO\")"),
    od(0x2100, 6, "Monitor 6 (not supported) Analog speed command voltage", I32, Ro, No).cite("§8.8: I32, no default; access not printed (RO: §8.8 \"read by SDO\"); (Reserved)"),
    od(0x2100, 7, "Monitor 7 (not supported) Analog torque command voltage", I32, Ro, No).cite("§8.8: I32, no default; access not printed (RO: §8.8 \"read by SDO\"); (Reserved)"),
    od(0x2100, 8, "Monitor 8 Regenerative load ratio", I32, Ro, No).unit(Unit::Percent).cite("§8.8: I32, no default; access not printed (RO: §8.8 \"read by SDO\")"),
    od(0x2100, 9, "Monitor 9 Effective load ratio", I32, Ro, No).unit(Unit::Percent).cite("§8.8: I32, no default; access not printed (RO: §8.8 \"read by SDO\")"),
    od(0x2100, 10, "Monitor 10 Peak load ratio", I32, Ro, No).unit(Unit::Percent).cite("§8.8: I32, no default; access not printed (RO: §8.8 \"read by SDO\")"),
    od(0x2100, 11, "Monitor 11 Instantaneous torque", I32, Ro, No).unit(Unit::Percent).cite("§8.8: I32, no default; access not printed (RO: §8.8 \"read by SDO\")"),
    od(0x2100, 12, "Monitor 12 Within one-revolution position", I32, Ro, No).unit(Unit::Pulse).cite("§8.8: I32, no default; access not printed (RO: §8.8 \"read by SDO\")"),
    od(0x2100, 13, "Monitor 13 ABS counter", I32, Ro, No).unit(Unit::Revolution).cite("§8.8: I32, no default; access not printed (RO: §8.8 \"read by SDO\")"),
    od(0x2100, 14, "Monitor 14 Load inertia moment ratio", I32, Ro, No).cite("§8.8: I32, no default; access not printed (RO: §8.8 \"read by SDO\"); unit: multiplier"),
    od(0x2100, 15, "Monitor 15 Bus voltage", I32, Ro, No).unit(Unit::Volt).cite("§8.8: I32, no default; access not printed (RO: §8.8 \"read by SDO\")"),
    od(0x2100, 16, "Monitor 16 (not supported) Ext. encoder cumulative F/B pulses", I32, Ro, No).cite("§8.8: I32, no default; access not printed (RO: §8.8 \"read by SDO\"); (Reserved)"),
    od(0x2100, 17, "Monitor 17 (not supported) External encoder droop pulses", I32, Ro, No).cite("§8.8: I32, no default; access not printed (RO: §8.8 \"read by SDO\"); (Reserved)"),
    od(0x2100, 18, "Monitor 18 (not supported) In 1-rev pos. of ext. encoder", I32, Ro, No).cite("§8.8: I32, no default; access not printed (RO: §8.8 \"read by SDO\"); (Reserved)"),
    od(0x2100, 19, "Monitor 19 (not supported) External encoder ABS counter", I32, Ro, No).cite("§8.8: I32, no default; access not printed (RO: §8.8 \"read by SDO\"); (Reserved)"),
    od(0x2100, 20, "Monitor 20 (not supported) Analog monitor output voltage 1", I32, Ro, No).cite("§8.8: I32, no default; access not printed (RO: §8.8 \"read by SDO\"); (Reserved)"),
    od(0x2100, 21, "Monitor 21 (not supported) Analog monitor output voltage 2", I32, Ro, No).cite("§8.8: I32, no default; access not printed (RO: §8.8 \"read by SDO\"); (Reserved)"),
    od(0x2100, 22, "Monitor 22 (not supported) Cumulative encoder output pulses", I32, Ro, No).cite("§8.8: I32, no default; access not printed (RO: §8.8 \"read by SDO\"); (Reserved)"),
    od(0x2100, 23, "Monitor 23 (not supported) Motor thermistor temperature", I32, Ro, No).cite("§8.8: I32, no default; access not printed (RO: §8.8 \"read by SDO\"); (Reserved)"),
    od(0x2100, 24, "Monitor 24 (not supported) Motor side cumu. FBpls (BeforGear)", I32, Ro, No).cite("§8.8: I32, no default; access not printed (RO: §8.8 \"read by SDO\"); (Reserved)"),
    od(0x2100, 25, "Monitor 25 (not supported) Electreal angle", I32, Ro, No).cite("§8.8: I32, no default; access not printed (RO: §8.8 \"read by SDO\"); (Reserved)"),
    od(0x6062, 0, "Position demand value", I32, Ro, PdoTx).unit(Unit::Pulse).cite("§8.3.2, §8.5.4: internal position command (command unit)"),
    od(0x6065, 0, "Following error window", DataType::Unstated, Access::Unstated, No).cite("§8.3.2 (named only), §8.5.2 statusword bit 13; type, access and default not stated; not in the §8.5.3/§8.5.4 mappable lists"),
    od(0x6066, 0, "Following error time out", DataType::Unstated, Access::Unstated, No).unit(Unit::Millisecond).cite("§8.3.2 (named only), §8.5.2 statusword bit 13 (unit msec); type, access and default not stated; not in the §8.5.3/§8.5.4 mappable lists"),
    od(0x6067, 0, "Position window", DataType::Unstated, Access::Unstated, No).cite("§8.3.2, §8.5.2: the in-position range (PA10); type, access, unit and default not stated; not in the §8.5.3/§8.5.4 mappable lists"),
    od(0x607D, 0, "Software position limit (Reserved)", DataType::Unstated, Access::Unstated, No).cite("§8.3.2: listed as reserved; sub-indexes, type, access and default not stated; not in the §8.5.3/§8.5.4 mappable lists"),
    od(0x6083, 0, "Profile acceleration (Reserved)", DataType::Unstated, Access::Unstated, No).cite("§8.3.2: listed as reserved; type, access and default not stated; not in the §8.5.3/§8.5.4 mappable lists"),
    od(0x60C2, 0, "Interpolation time period", U8, Ro, No).default(2).cite("§8.2.2: number of entries"),
    od(0x60C2, 1, "Interpolation time period value", U8, Rw, No).default(5).cite("§8.2.2: 5 at 0.5 ms, 1 at 1 ms, 2 at 2 ms (follows the cycle, not changeable manually: the emulator keeps the 0.5 ms value and stores a write)"),
    od(0x60C2, 2, "Interpolation time index", I8, Rw, No).default(-4).cite("§8.2.2: −4 at 0.5 ms, −3 at 1 ms and 2 ms (follows the cycle, not changeable manually: the emulator keeps the 0.5 ms value and stores a write)"),
    od(0x60FC, 0, "Position demand internal value", I32, Ro, PdoTx).unit(Unit::Pulse).cite("§8.3.2, §8.5.4: internal position command (encoder unit)"),
];

/// Encoder and units (MR-J3-T04 manual §1.3, §1.5, §8.11.3, §9.6).
pub const UNITS: Units = Units {
    counts_per_rev: Some(262_144),
    other_counts_per_rev: &[131_072],
    position: PositionUnit::Count,
    velocity: Stated::Manual(VelocityUnit::MILLI_RPM),
    linear_motors: false,
    command_truncation_exp10: Some(-2),
    acceleration: Stated::Manual(AccelerationUnit::NotSupported),
    torque: TorqueUnit::PerMilleOfRated,
    source:
        "MR-J3-T04 manual §1.3, §1.5, §8.3.2, §8.5.2, §8.5.3, §9.6 (60FFh/606Ch/6099h 0.001 r/min, \
             commands truncated to 0.01 r/min; 60E0h/60E1h/6077h 0.1 %; 6083h reserved; 18-bit \
             encoder, 17-bit motors named)",
};

/// The MR-J3-T04 profile.
///
/// Identity from §1.1. Modes hm, csp, csv; **no cst** (§1.2). Cycles 0.5/1/2 ms (§1.3). Quirks:
/// shortcuts (§3.2), **no quick stop** (bit 5 always 1; Quick Stop in OE acts as Disable
/// Voltage, the simulator default of §3.3), no (16). Fault Reset held ≥ 10 ms (§3.3).
pub const PROFILE: DriveProfile = DriveProfile {
    model: DriveModel::MrJ3T04,
    name: "Mitsubishi MR-J3-T04",
    identity: Identity {
        vendor_id: Some(0x0000_0A1E),
        product_code: Some(0x0000_0102),
        revision: Some(0x0200_0000),
        source: "MR-J3-T04 manual §8.1(4), §1.4.1(3) (manual §8.1(4))",
        maker_vendor_id: Some(super::MITSUBISHI_VENDOR_ID),
        emulator_product_code: 0x0000_0102,
    },
    cycle: CycleFacts {
        modes: SharedSlice::Static(&[M::Homing, M::CyclicSyncPosition, M::CyclicSyncVelocity]),
        cycle_times_us: &[500, 1000, 2000],
        // §3.8: halt is invalid in csp and csv (hm only).
        halt_in_cyclic_modes: false,
        csp_entry: crate::mode_switch::CspEntry::PositionDemand,
    },
    pdo: PdoFacts {
        rx: RX_PDO_1614,
        tx: TX_PDO_1A14,
        unit_limits: &[],
        rules: PdoRules {
            max_entries: 15,
            max_rx_bytes: 30,
            max_tx_bytes: 30,
            // §4.5: the manual's lists (reserved objects may be mapped but do nothing).
            rx_mappable: &[
                0x2020, 0x2022, 0x6040, 0x2001, 0x2002, 0x2003, 0x2004, 0x607A, 0x60FF, 0x2050,
                0x6071, 0x60E0, 0x60E1, 0x6060,
            ],
            tx_mappable: &[
                0x2021, 0x2023, 0x6041, 0x2011, 0x2012, 0x2013, 0x2014, 0x6064, 0x606C, 0x60F4,
                0x6077, 0x6061, 0x6062, 0x60FC, 0x2041,
            ],
            not_mappable_abort: 0x0604_0041,
            too_long_abort: 0x0604_0042,
            locked_abort: 0x0601_0000,
            // §4.4, §3.9: any PDO-mapped object, 6060h included.
            mapped_write_abort: 0x0601_0000,
            // §5.8: "write to an object that is not writable in the current AL state".
            wrong_state_abort: 0x0601_0002,
            // TV-IC-5: §8.2.3(1) says only that invalid cycles make operation "not performed
            // properly"; AL.76 (synchronization setting incorrect) or AL.74 (initial
            // synchronisation failed) are the candidates: AL.76 by default, AL.74 selectable
            // (`SimDriveParams::sync_mismatch_alarm`).
            sync_mismatch_alarms: &[0x0076, 0x0074],
            assignment: PdoAssignment::ReadOnly,
            frozen_after_safe_op: true,
            source:
                "MR-J3-T04 manual §8.6.1, §8.6.2, §8.7.1, §4.5, §5.8 (manual §8.6.1, §8.6.2, §8.7)",
        },
    },
    quirks: FsaQuirks {
        shortcut_transitions: true,
        has_quick_stop: false,
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
        check: CommCheck::IncrementalCounter {
            rx_index: 0x2020,
            tx_index: 0x2021,
            counter_alarm: AL_34,
            loss_alarm: AL_36,
            free_run_alarm: AL_37,
            master: MASTER_COUNTER_CHECK,
        },
        leave_op_alarm: AL_61,
        // §2.2: no re-initialisation is stated; the alarm (or none) is the whole effect.
        reinit_on_leaving_op: false,
        emergency: EMERGENCY,
        sdo_info: SDO_INFO,
    },
    limits: LimitFacts {
        following_error_alarm: AL_52,
        overspeed_alarm: AL_35,
        torque_limit_selection: TorqueLimitSelection::Controlword2 {
            c_tl_bit: 3,
            c_tl1_bit: 4,
        },
        stroke_end_warning: Some(AL_99),
        power_warnings: Some((AL_E6, AL_E9)),
        manual_stop_bit: Some(8),
        relative_degree_warning: None,
    },
    sdo_write_refusals: &[],
    homing: HomingSetup {
        // §8.1: dog type −1 / −17 and data set 35.
        methods: &[-1, -17, 35],
        data_set_methods: &[35],
        reference: HomeReference::OffsetObject,
        // §8.3 (manual §8.11.6): C_CR = 2001h bit 7, C_CR2 = bit 6; 2011h S_OSET bit 8, S_ZPAS
        // bit 7, S_OP bit 9 (§3.3 tables).
        setting: Some(HomeSetting {
            clear_bit: 7,
            clear_z_bit: 6,
            set_bit: 8,
            z_passed_bit: 7,
            z_pulse_bit: 9,
            before_z_warning: 0x0096,
            before_z_alarm: 0x0026,
        }),
    },
    store_restore_objects: &[],
    invalid_axis_switch: None,
    profile_selector: None,
    fsoe: None,
    parameters: &super::params::MR_J3_T04,
};

/// What the drive answers of SDO Information.
pub const SDO_INFO: super::SdoInfoFacts = super::SdoInfoFacts {
    offered: true,
    one_value_per_entry: true,
    record_types: &[
        (0x1010, 0x1010, 0x07),
        (0x2030, 0x2035, 0x40),
        (0x2100, 0x2100, 0x41),
        (0x2300, 0x2309, 0x50),
        (0x60C2, 0x60C2, 0x80),
    ],
    source: "MR-J3-T04 manual §8.7 (Get OD List types 00h–05h, Object Description with record data-type codes, Entry Description value-info bits 0, 2, 4, 5, 6; several of 4–6: only the lowest answered)",
};

/// Whether alarms are also sent as CoE Emergency (payload: [`crate::profiles::facts::EMERGENCY_LAYOUT`]).
pub const EMERGENCY: super::EmergencyFacts = super::EmergencyFacts {
    sends: false,
    source: "MR-J3-T04 manual §1.7, §8.2.2, §8.2.3: \"The manual describes no CoE Emergency messages\" (alarms by PDO only: statusword bit 3)",
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tv_pdo_default_rx_layout_1614h() {
        // §4.1 offsets and §4.3 mapping words.
        let m = &PROFILE.pdo.rx;
        assert_eq!(m.byte_len(), 30);
        let expect = [
            (0x2020, 0),
            (0x2022, 1),
            (0x6040, 2),
            (0x2001, 4),
            (0x2002, 6),
            (0x2003, 8),
            (0x2004, 10),
            (0x607A, 12),
            (0x60FF, 16),
            (0x2050, 20),
            (0x6071, 24),
            (0x60E0, 26),
            (0x60E1, 28),
        ];
        for (idx, off) in expect {
            assert_eq!(m.offset_of(idx, 0), Some(off), "{idx:#06x}");
        }
        let words: Vec<u32> = m.entries.iter().map(|e| e.mapping_word()).collect();
        assert_eq!(
            words,
            [
                0x2020_0008,
                0x2022_0008,
                0x6040_0010,
                0x2001_0010,
                0x2002_0010,
                0x2003_0010,
                0x2004_0010,
                0x607A_0020,
                0x60FF_0020,
                0x2050_0020,
                0x6071_0010,
                0x60E0_0010,
                0x60E1_0010
            ]
        );
        assert!(m.has_counter());
    }

    #[test]
    fn tv_pdo_default_tx_layout_1a14h() {
        let m = &PROFILE.pdo.tx;
        assert_eq!(m.byte_len(), 26);
        let words: Vec<u32> = m.entries.iter().map(|e| e.mapping_word()).collect();
        assert_eq!(
            words,
            [
                0x2021_0008,
                0x2023_0008,
                0x6041_0010,
                0x2011_0010,
                0x2012_0010,
                0x2013_0010,
                0x2014_0010,
                0x6064_0020,
                0x606C_0020,
                0x60F4_0020,
                0x6077_0010
            ]
        );
        for (idx, off) in [
            (0x2021, 0),
            (0x6041, 2),
            (0x6064, 12),
            (0x606C, 16),
            (0x60F4, 20),
            (0x6077, 24),
        ] {
            assert_eq!(m.offset_of(idx, 0), Some(off), "{idx:#06x}");
        }
        assert!(m.has_counter());
    }

    #[test]
    fn identity_modes_cycles() {
        assert_eq!(PROFILE.vendor_id(), Some(0xA1E));
        assert_eq!(PROFILE.product_code(), Some(0x102));
        assert_eq!(PROFILE.identity.revision, Some(0x0200_0000));
        assert!(!PROFILE.supports_mode(M::CyclicSyncTorque));
        assert_eq!(PROFILE.modes_text(), "hm, csp, csv");
        assert_eq!(PROFILE.cycle_times_text(), "500, 1000, 2000 µs");
        assert!(!PROFILE.alarm_resettable(AL_34) && PROFILE.alarm_resettable(AL_35));
        assert_eq!(
            PROFILE.object(0x60E0, 0).and_then(|o| o.default),
            Some(3000)
        );
        assert_eq!(PROFILE.units.counts_per_rev, Some(262_144));
    }

    #[test]
    fn the_object_list_of_8_3_2_is_served() {
        // (index, sub, type, access, PDO, default) as §8.2.2, §8.5.3, §8.5.4, §8.8, §8.11.2 print them.
        let rows = [
            (0x2002, 0, U16, Rw, PdoRx, Some(0)),
            (0x2014, 0, U16, Ro, PdoTx, None),
            (0x2022, 0, U8, Rw, PdoRx, None),
            (0x2024, 0, U16, Rw, No, Some(0)),
            (0x2050, 0, U32, Rw, PdoRx, Some(0)),
            (0x2100, 0, U8, Ro, No, Some(25)),
            (0x2100, 15, I32, Ro, No, None),
            (0x6062, 0, I32, Ro, PdoTx, None),
            (0x60C2, 0, U8, Ro, No, Some(2)),
            (0x60C2, 1, U8, Rw, No, Some(5)),
            (0x60C2, 2, I8, Rw, No, Some(-4)),
            (0x60FC, 0, I32, Ro, PdoTx, None),
        ];
        super::super::assert_rows(&PROFILE, &rows);
        assert_eq!(
            PROFILE.object(0x2050, 0).and_then(|o| o.range.bounds()),
            Some((0, 0x7FFF_FFFF))
        );
        // Named in §8.3.2 with nothing more: served, every field unstated (not mappable: the
        // §8.5.3/§8.5.4 lists leave them out).
        let named = [0x6065, 0x6066, 0x6067, 0x607D, 0x6083]
            .map(|index| (index, 0, DataType::Unstated, Access::Unstated, No, None));
        super::super::assert_rows(&PROFILE, &named);
        assert_eq!(
            (1..=25)
                .filter(|&s| PROFILE.object(0x2100, s).is_some())
                .count(),
            25
        );
    }
}
