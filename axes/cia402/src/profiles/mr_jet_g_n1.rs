//! Mitsubishi MR-JET-G-N1, per the MR-JET-G-N1 manual ( IB(NA)-0300500ENG-H).

use super::facts::{alarm, obj, od, Unit};
use super::{AccelerationUnit, PositionUnit, Stated, TorqueUnit, VelocityUnit};
use super::{
    Access, AlarmInfo, AlarmKind, Clearing, CommCheck, DataType, DriveModel, DriveProfile,
    FsoeCommandBits, FsoeFacts, FsoeFrameLayout, FsoeStatusBits, Identity, OdEntry, Pdo,
    PdoAssignment, PdoRules, SafeBit, StopBehaviour, Units,
};
use super::{CommFacts, CycleFacts, FaultFacts, HomingSetup, LimitFacts, PdoFacts};
use super::{HomeReference, TorqueLimitSelection};
use crate::cycles::ALLOWED_MICROS;
use crate::fsa::FsaQuirks;
use crate::mode::ModeOfOperation as M;
use crate::pdo::{PdoEntry, PdoMap};
use crate::shared_slice::SharedSlice;
use Access::{Ro, Rw};
use DataType::{Bool, I16, I32, I8, U16, U32, U8};
use Pdo::{No, Rx as PdoRx, Tx as PdoTx};

/// Default 1st RxPDO 1600h, 24 bytes (MR-JET-G-N1 manual §4.3; sizes inferred from the total).
pub const RX_PDO_1600: PdoMap = PdoMap {
    index: 0x1600,
    entries: SharedSlice::Static(&[
        obj(0x6060, 8),       // 0  Modes of operation
        PdoEntry::padding(8), // 1  padding
        obj(0x6040, 16),      // 2  Controlword
        obj(0x2D01, 16),      // 4  Control DI 1
        obj(0x2D02, 16),      // 6  Control DI 2
        obj(0x2D03, 16),      // 8  Control DI 3
        obj(0x607A, 32),      // 10 Target position
        obj(0x60FF, 32),      // 14 Target velocity
        obj(0x2D20, 32),      // 18 Velocity limit value
        obj(0x6071, 16),      // 22 Target torque
    ]),
};

/// Default 1st TxPDO 1A00h, 24 bytes (MR-JET-G-N1 manual §4.3).
pub const TX_PDO_1A00: PdoMap = PdoMap {
    index: 0x1A00,
    entries: SharedSlice::Static(&[
        obj(0x6061, 8),       // 0  Modes of operation display
        PdoEntry::padding(8), // 1  padding
        obj(0x6041, 16),      // 2  Statusword
        obj(0x2D11, 16),      // 4  Status DO 1
        obj(0x2D12, 16),      // 6  Status DO 2
        obj(0x2D13, 16),      // 8  Status DO 3
        obj(0x6064, 32),      // 10 Position actual value
        obj(0x606C, 32),      // 14 Velocity actual value
        obj(0x60F4, 32),      // 18 Following error actual value
        obj(0x6077, 16),      // 22 Torque actual value
    ]),
};

/// Alarm code encoding: AL.XXX.Y → 0xXXXY (AL.086.1 → 0x0861); no alarm object in the manual.
pub const AL_086_1: u16 = 0x0861;
/// AL.037 Parameter error (§1.2, §8.2: e.g. an infinite-feed gear whose reduced m ≥ 16384).
pub const AL_037: u16 = 0x0370;
/// Infinite feed (PT85.0 = 1): the reduced numerator m of 2^32 × cmx / (fbpm × cdv) must be
/// below this (§8.2).
pub const INFINITE_FEED_MAX_M: u64 = 16384;

/// The infinite-feed gear check of §8.2 (TV-13): reduces 2^32 × cmx / (fbpm × cdv) to m/n
/// and returns it, or [`AL_037`] when m ≥ [`INFINITE_FEED_MAX_M`] or a term is zero.
/// `cmx`/`cdv` are the electronic gear [Pr. PA06]/[Pr. PA07], `fbpm` the encoder pulses/rev.
pub fn infinite_feed_gear(cmx: u32, cdv: u32, fbpm: u32) -> Result<(u64, u64), u16> {
    if cmx == 0 || cdv == 0 || fbpm == 0 {
        return Err(AL_037);
    }
    let num = (1u128 << 32) * u128::from(cmx);
    let den = u128::from(fbpm) * u128::from(cdv);
    let (mut a, mut b) = (num, den);
    while b != 0 {
        (a, b) = (b, a % b);
    }
    let (m, n) = (num / a, den / a);
    if m >= u128::from(INFINITE_FEED_MAX_M) {
        return Err(AL_037);
    }
    Ok((m as u64, n as u64))
}
/// AL.537.2 Parameter combination error A (safety sub-function) (§7.1, §9; the triggering
/// combination is [garbled] in the manual and not simulated).
pub const AL_537_2: u16 = 0x5372;
/// AL.584.1 FSoE Address mismatch error (safety sub-function): [Pr. PSC07] differs from the
/// address configured in the FSoE master (§7.1, §9).
pub const AL_584_1: u16 = 0x5841;

/// The FSoE frame in the safety PDOs 1608h / 1A08h, 11 bytes each way (§5.4): Command at 0,
/// SafeData[0] at 1, SafeData[1] at 2, CRC_0 at 3–4, SafeData[2] at 5, SafeData[3] at 6, CRC_1
/// at 7–8, ConnectionID at 9–10.
pub const FSOE_FRAME: FsoeFrameLayout = FsoeFrameLayout {
    len: 11,
    command: 0,
    safe_data: [1, 2, 5, 6],
    crc: [3, 7],
    connection_id: 9,
};

/// SafeData commands, master → slave (§7.2 first table; F701h sub-indexes). 0 = function
/// active. Bits 2–4 of SafeData[0], bit 4 of SafeData[1], bits 1–7 of SafeData[2] and all of
/// SafeData[3] are "not available" (sent as 0).
pub const FSOE_COMMANDS: FsoeCommandBits = FsoeCommandBits {
    sto: SafeBit::new(0, 0, 0x01),
    ss1: SafeBit::new(0, 1, 0x02),
    sdip: SafeBit::new(0, 5, 0x04),
    sdin: SafeBit::new(0, 6, 0x05),
    error_ack: SafeBit::new(0, 7, 0x06),
    sls: [
        SafeBit::new(1, 0, 0x07),
        SafeBit::new(1, 1, 0x08),
        SafeBit::new(1, 2, 0x09),
        SafeBit::new(1, 3, 0x0A),
    ],
    slt: [
        SafeBit::new(1, 5, 0x0C),
        SafeBit::new(1, 6, 0x0D),
        SafeBit::new(1, 7, 0x0E),
        SafeBit::new(2, 0, 0x0F),
    ],
};

/// SafeData status, slave → master (§7.2 second table; F601h sub-indexes). 1 = active.
pub const FSOE_STATUS: FsoeStatusBits = FsoeStatusBits {
    sto: SafeBit::new(0, 0, 0x01),
    ssm: SafeBit::new(0, 1, 0x02),
    error: SafeBit::new(0, 7, 0x04),
    ss1: SafeBit::new(1, 0, 0x05),
    sdip: SafeBit::new(1, 2, 0x07),
    sdin: SafeBit::new(1, 3, 0x08),
    sls: [
        SafeBit::new(1, 4, 0x09),
        SafeBit::new(1, 5, 0x0A),
        SafeBit::new(1, 6, 0x0B),
        SafeBit::new(1, 7, 0x0C),
    ],
    sbc: SafeBit::new(2, 0, 0x0D),
    slt: [
        SafeBit::new(2, 2, 0x0F),
        SafeBit::new(2, 3, 0x10),
        SafeBit::new(2, 4, 0x11),
        SafeBit::new(2, 5, 0x12),
    ],
};

/// The FSoE objects as far as the manual states them (§6 table, §7.1; types and access of
/// E600h/E700h/E901h are not stated).
#[rustfmt::skip]
pub const FSOE_OBJECTS: &[OdEntry] = &[
    od(0x1608, 0, "9th Receive PDO Mapping (safety)", U8, Ro, No).default(0x24).cite("§5.1, §5.4: 36 entries, fixed (§4.4's \"1 to 104\" conflicts; 36 used)"),
    od(0x1A08, 0, "9th Transmit PDO Mapping (safety)", U8, Ro, No).default(0x24).cite("§5.1, §5.4: 36 entries, fixed"),
    od(0xE600, 1, "FSoE Slave Command", DataType::Unstated, Ro, PdoTx).cite("§6: type not stated; ro [background]"),
    od(0xE600, 2, "FSoE Slave ConnectionID", DataType::Unstated, Ro, PdoTx).cite("§6, §5.4: 2 bytes in the frame"),
    od(0xE600, 3, "FSoE Slave CRC_0", DataType::Unstated, Ro, PdoTx).cite("§6, §5.4: 2 bytes in the frame"),
    od(0xE600, 4, "FSoE Slave CRC_1", DataType::Unstated, Ro, PdoTx).cite("§6, §5.4: 2 bytes in the frame"),
    od(0xE700, 1, "FSoE Master Command", DataType::Unstated, Access::Unstated, PdoRx).cite("§6: type and access not stated"),
    od(0xE700, 2, "FSoE Master ConnectionID", DataType::Unstated, Access::Unstated, PdoRx).cite("§6, §5.4: 2 bytes in the frame"),
    od(0xE700, 3, "FSoE Master CRC_0", DataType::Unstated, Access::Unstated, PdoRx).cite("§6, §5.4: 2 bytes in the frame"),
    od(0xE700, 4, "FSoE Master CRC_1", DataType::Unstated, Access::Unstated, PdoRx).cite("§6, §5.4: 2 bytes in the frame"),
    od(0xE901, 4, "Watchdog Time", DataType::Unstated, Access::Unstated, No).unit(Unit::Millisecond).cite("§7.1 item 4, §7.3: set by the master's connection parameter set; shows the value received"),
    od(0xE901, 7, "Communication Parameter Length", DataType::Unstated, Access::Unstated, No).cite("§7.1 item 4"),
    od(0xE901, 8, "Application Parameter Length", DataType::Unstated, Access::Unstated, No).cite("§7.1 item 4"),
];

/// FSoE on the MR-JET-G-N1 (FW D8 or later; §5.4, §6, §7). The watchdog minimum is the
/// manual's T_Ref + 4 × T_Com = 15 ms + 4 × 0.25 ms = 16 ms (§7.3); FSoE needs a cycle of at
/// least 0.25 ms (**[inferred]** from §4.4's size table and §9.3's "250 µs or longer", §1.3).
/// PSC07's range is printed "1 to 65355" (**[garbled]**); 1–65535 is used.
pub const FSOE: FsoeFacts = FsoeFacts {
    rx_pdo: 0x1608,
    tx_pdo: 0x1A08,
    mapping_entries: 0x24,
    frame: FSOE_FRAME,
    commands: FSOE_COMMANDS,
    status: FSOE_STATUS,
    command_object: 0xF701,
    status_object: 0xF601,
    master_frame_object: 0xE700,
    slave_frame_object: 0xE600,
    info_object: 0xE901,
    watchdog_sub: 0x04,
    comm_param_len_sub: 0x07,
    app_param_len_sub: 0x08,
    t_ref_us: 15_000,
    t_com_min_us: 250,
    watchdog_min_ms: 16,
    min_cycle_us: 250,
    address_range: (1, 65535),
    address_mismatch_alarm: AL_584_1,
    objects: FSOE_OBJECTS,
};

// Following-error and overspeed alarms: the manual has no alarm list (§9); CiA 402 8611h and
// 8400h [background].
pub use crate::error_code::{FOLLOWING_ERROR, OVERSPEED};

/// The alarms and warnings the manual names (MR-JET-G-N1 manual; no stop methods there), with causes and
/// remedies only where it states them (§6.1, §7.4, §8.1, §8.3 disconnection procedure, §9.2, §9.3).
#[rustfmt::skip]
pub const ALARMS: &[AlarmInfo] = &[
    alarm(0x0250, "AL.025", "Absolute position erased", AlarmKind::Alarm, StopBehaviour::Unstated, Clearing::Unstated, "§9, §8").explained(None, Some("Home again through the controller")),
    alarm(0x0251, "AL.025.1", "Servo motor encoder absolute position erased", AlarmKind::Alarm, StopBehaviour::Unstated, Clearing::PowerCycle, "§8: cycle the power after 5 s").explained(Some("First set-up of the absolute position detection system"), Some("Wait 5 s, then cycle the power")),
    alarm(AL_037, "AL.037", "Parameter error", AlarmKind::Alarm, StopBehaviour::Unstated, Clearing::Unstated, "§1.2, §8.2").explained(Some("[Pr. PT01.2] mm/inch with [Pr. PA01.0] = 0, [Pr. PT85.0] = 1 in linear, fully closed or scale-measurement use, or an infinite-feed gear m of 16384 or more"), None),
    alarm(AL_086_1, "AL.086.1", "Network receive data error (Network communication error 1)", AlarmKind::Alarm, StopBehaviour::Unstated, Clearing::Unstated, "§2.4: PN18 / 10F1h:02, counting rule not given").explained(Some("Communication errors passed [Pr. PN18] / 10F1h:02 Sync Error Counter Limit, or the network was dropped without the disconnection procedure"), Some("Disconnect in order: stop the motor, Shutdown in 6040h (servo off), Pre-Operational, then power off")),
    alarm(0x0901, "AL.090.1", "Homing incomplete", AlarmKind::Warning, StopBehaviour::Unstated, Clearing::Automatic, "§8").explained(Some("Servo-on without a home position ([Pr. PC41.0])"), None),
    alarm(0x0905, "AL.090.5", "Homing incomplete warning", AlarmKind::Warning, StopBehaviour::Unstated, Clearing::Automatic, "§8.2").explained(Some("[Pr. PT85.0] changed and homing not repeated"), None),
    alarm(0x09E9, "AL.09E.9", "Control mode setting warning", AlarmKind::Warning, StopBehaviour::Continues, Clearing::Automatic, "§1.4").explained(Some("Firmware earlier than B6 driving csp/csv/cst in free-run"), None),
    alarm(0x0E31, "AL.0E3.1", "Multi-revolution counter travel distance exceeded warning", AlarmKind::Warning, StopBehaviour::Continues, Clearing::Automatic, "§8, §8.2").explained(Some("32768 revolutions or more from home ([Pr. PC29.5])"), None),
    alarm(AL_537_2, "AL.537.2", "Parameter combination error A (safety)", AlarmKind::Alarm, StopBehaviour::Unstated, Clearing::Unstated, "§9"),
    alarm(AL_584_1, "AL.584.1", "FSoE Address mismatch error", AlarmKind::Alarm, StopBehaviour::Unstated, Clearing::Unstated, "§9").explained(Some("[Pr. PSC07] differs from the FSoE address configured in the master"), None),
    alarm(FOLLOWING_ERROR, "8611h", "Following error (CiA 402)", AlarmKind::Alarm, StopBehaviour::DynamicBrake, Clearing::FaultReset, "not in the manual (§9 has no complete list): CiA 402 [background]"),
    alarm(OVERSPEED, "8400h", "Overspeed (CiA 402)", AlarmKind::Alarm, StopBehaviour::DynamicBrake, Clearing::FaultReset, "not in the manual: CiA 402 [background]"),
];

/// 1010h:01 / 1011h:01 store and restore (MR-JET-G-N1 manual, manual §3.2; MR-J5 the same,
/// MR-J5-G-N1 manual and TV-12), served by the simulator's SDO surface.
#[rustfmt::skip]
pub const STORE_RESTORE_OBJECTS: &[OdEntry] = &[
    od(0x1010, 1, "Save all parameters", U32, Rw, No).default(1).cite("§6 (manual §3.2): write 65766173h; bit0 = 0 while saving (about 25 s)"),
    od(0x1011, 1, "Restore all default parameters", U32, Rw, No).default(1).cite("§6 (manual §3.2): write 64616F6Ch; any other value is an error"),
];

// The rows the MR-JET-G-N1 and MR-J5-G-N1 manuals print alike (§7.2, §7.3, §4.3, §8.3 of both):
// one definition each, listed by both models' tables.

/// 2D02h Control DI 2.
#[rustfmt::skip]
pub const CONTROL_DI_2: OdEntry = od(0x2D02, 0, "Control DI 2", U16, Rw, PdoRx).cite("§6 / manual §7.2: U16 rw printed; mapped in 1600h–1602h (manual §4.3); no default");
/// 2D03h Control DI 3 (its bits differ: all reserved on the MR-JET, bit 8 C_ABS2 on the MR-J5).
#[rustfmt::skip]
pub const CONTROL_DI_3: OdEntry = od(0x2D03, 0, "Control DI 3", U16, Rw, PdoRx).cite("§6 / manual §7.2: the table elides the rows after 2D02h (\":\"): U16 rw as 2D01h/2D02h [inferred]; mapped in 1600h–1602h (manual §4.3); no default");
/// 2D11h Status DO 1.
#[rustfmt::skip]
pub const STATUS_DO_1: OdEntry = od(0x2D11, 0, "Status DO 1", U16, Ro, PdoTx).cite("§6 / manual §7.3: U16 ro printed; mapped in 1A00h/1A01h (manual §4.3)");
/// 2D12h Status DO 2.
#[rustfmt::skip]
pub const STATUS_DO_2: OdEntry = od(0x2D12, 0, "Status DO 2", U16, Ro, PdoTx).cite("§6 / manual §7.3: U16 ro printed (its index misprinted 2D02h); mapped in 1A00h/1A01h (manual §4.3)");
/// 2D13h Status DO 3.
#[rustfmt::skip]
pub const STATUS_DO_3: OdEntry = od(0x2D13, 0, "Status DO 3", U16, Ro, PdoTx).cite("§6 / manual §7.3: the table elides the rows after Status DO 2 (\":\"): U16 ro as 2D11h [inferred]; mapped in 1A00h/1A01h (manual §4.3)");
/// 2D15h Status DO 5.
#[rustfmt::skip]
pub const STATUS_DO_5: OdEntry = od(0x2D15, 0, "Status DO 5", U16, Ro, PdoTx).cite("§6 / manual §7.3: the table elides the rows after Status DO 2 (\":\"): U16 ro as 2D11h [inferred]; mapped in 1A01h (manual §4.3)");
/// 2D17h Status DO 7.
#[rustfmt::skip]
pub const STATUS_DO_7: OdEntry = od(0x2D17, 0, "Status DO 7", U16, Ro, PdoTx).cite("§6 / manual §7.3: the table elides the rows after Status DO 2 (\":\"): U16 ro as 2D11h [inferred]; mapped in 1A01h (manual §4.3)");
/// 6098h Homing method.
#[rustfmt::skip]
pub const HOMING_METHOD: OdEntry = od(0x6098, 0, "Homing method", I8, Rw, Pdo::Unstated).cite("§6 / manual §8.3: the methods, the default and the mapping not stated; type I8 and rw: CiA 402 [background]");

/// The object dictionary (MR-JET-G-N1 manual): the objects its §4.3, §7 and §8 tables name, the
/// FSoE objects apart ([`FSOE_OBJECTS`]). Control DI 4–10 and Status DO 4, 6, 8–10 are left
/// out: the manual elides their rows, their indexes are only inferred (§6).
#[rustfmt::skip]
pub const OBJECTS: &[OdEntry] = &[
    od(0x10F1, 2, "Sync Error Counter Limit", U16, Rw, No).default(super::generic_cia402::SYNC_ERROR_COUNTER_LIMIT).unit(Unit::Times).cite("§2.4: type, default, counting rule not stated; U16 rw as ETG.1020 has it [background], default the simulator's"),
    od(0x1C32, 2, "Cycle time", U32, Rw, No).default(250_000).range(&[(125_000, 8_000_000)]).unit(Unit::Nanosecond).cite("§1.3, §6; unit: CiA 402 [background]"),
    od(0x1C32, 0, "SM output parameter", U8, Ro, No).default(12).cite("§4.2 (subs listed); the highest sub-index listed"),
    od(0x1C32, 1, "Synchronization type", U16, Rw, No).default(0).cite("§4.2 (subs listed); DC or free run; 0 = free run until the master selects DC (ETG.1020 [background])"),
    od(0x1C32, 4, "Synchronization types supported", U16, Ro, No).default(0x0005).cite("§4.2 (subs listed); free run and DC SYNC0 (ETG.1020 bits 0 and 2 [background])"),
    od(0x1C32, 5, "Minimum cycle time", U32, Ro, No).default(125_000).unit(Unit::Nanosecond).cite("§4.2 (subs listed); §1.3: 0.125 ms (0.125 ms)"),
    od(0x1C32, 6, "Calc and copy time", U32, Ro, No).unit(Unit::Nanosecond).cite("§4.2 (subs listed); not stated"),
    od(0x1C32, 9, "Delay time", U32, Ro, No).unit(Unit::Nanosecond).cite("§4.2 (subs listed); not stated"),
    od(0x1C32, 11, "SM-Event Missed", U16, Ro, No).default(0).cite("§4.2 (subs listed); a counter"),
    od(0x1C32, 12, "Cycle time too small", U16, Ro, No).default(0).cite("§4.2 (subs listed); a counter"),
    od(0x1C32, 13, "Shift Time Too Short", U16, Ro, No).default(0).cite("§4.2 (subs listed); a counter"),
    od(0x1C32, 32, "Sync Error", Bool, Ro, No).default(0).cite("§4.2 (subs listed)"),
    od(0x1C33, 0, "SM input parameter", U8, Ro, No).default(12).cite("§4.2 (subs listed); the highest sub-index listed"),
    od(0x1C33, 1, "Synchronization type", U16, Rw, No).default(0).cite("§4.2 (subs listed); DC or free run; 0 = free run until the master selects DC (ETG.1020 [background])"),
    od(0x1C33, 4, "Synchronization types supported", U16, Ro, No).default(0x0005).cite("§4.2 (subs listed); free run and DC SYNC0 (ETG.1020 bits 0 and 2 [background])"),
    od(0x1C33, 5, "Minimum cycle time", U32, Ro, No).default(125_000).unit(Unit::Nanosecond).cite("§4.2 (subs listed); §1.3: 0.125 ms (0.125 ms)"),
    od(0x1C33, 6, "Calc and copy time", U32, Ro, No).unit(Unit::Nanosecond).cite("§4.2 (subs listed); not stated"),
    od(0x1C33, 9, "Delay time", U32, Ro, No).unit(Unit::Nanosecond).cite("§4.2 (subs listed); not stated"),
    od(0x1C33, 11, "SM-Event Missed", U16, Ro, No).default(0).cite("§4.2 (subs listed); a counter"),
    od(0x1C33, 12, "Cycle time too small", U16, Ro, No).default(0).cite("§4.2 (subs listed); a counter"),
    od(0x1C33, 13, "Shift Time Too Short", U16, Ro, No).default(0).cite("§4.2 (subs listed); a counter"),
    od(0x1C33, 32, "Sync Error", Bool, Ro, No).default(0).cite("§4.2 (subs listed)"),
    od(0x1C33, 2, "Cycle time", U32, Ro, No).unit(Unit::Nanosecond).cite("§4.2 (subs listed); follows 1C32h:02"),
    od(0x2D01, 0, "Control DI 1", U16, Rw, PdoRx).default(0).cite("§6"),
    od(0x2D20, 0, "Velocity limit value", DataType::Unstated, Access::Unstated, PdoRx).cite("§6: 4 bytes inferred"),
    od(0x6040, 0, "Controlword", U16, Rw, PdoRx).default(0).cite("§3.3"),
    od(0x6041, 0, "Statusword", U16, Ro, PdoTx).cite("§3.4"),
    od(0x605A, 0, "Quick stop option code", DataType::Unstated, Access::Unstated, Pdo::Unstated).range(&[(1, 8)]).cite("§3.5: 5–8 FW D0 or later; default not stated"),
    od(0x6060, 0, "Modes of operation", I8, Rw, PdoRx).default(8).cite("§1.2"),
    od(0x6061, 0, "Modes of operation display", I8, Ro, PdoTx).default(8).cite("§1.2"),
    od(0x6064, 0, "Position actual value", I32, Ro, PdoTx).unit(Unit::PosUnits).cite("§6 (type inferred)"),
    od(0x606C, 0, "Velocity actual value", I32, Ro, PdoTx).unit(Unit::Unstated).cite("§6"),
    od(0x6071, 0, "Target torque", I16, Rw, PdoRx).default(0).unit(Unit::TenthPercentRated).cite("§6; unit: CiA 402 [background]"),
    od(0x6077, 0, "Torque actual value", I16, Ro, PdoTx).unit(Unit::TenthPercentRated).cite("§6; unit: CiA 402 [background]"),
    od(0x607A, 0, "Target position", I32, Rw, PdoRx).default(0).unit(Unit::PosUnits).cite("§6"),
    od(0x60E0, 0, "Positive torque limit value", DataType::Unstated, Access::Unstated, Pdo::Unstated).unit(Unit::TenthPercentRated).cite("§6: = PA11"),
    od(0x60E1, 0, "Negative torque limit value", DataType::Unstated, Access::Unstated, Pdo::Unstated).unit(Unit::TenthPercentRated).cite("§6: = PA12"),
    od(0x60F4, 0, "Following error actual value", I32, Ro, PdoTx).unit(Unit::PosUnits).cite("§6"),
    od(0x60FF, 0, "Target velocity", I32, Rw, PdoRx).default(0).unit(Unit::Unstated).cite("§6"),
    od(0x6502, 0, "Supported drive modes", U32, Ro, No).default(0x0003_03AD).cite("§1.2: bits 0, 2, 3, 5, 7, 8, 9, 16, 17"),
    od(0x6081, 0, "Profile velocity", U32, Rw, PdoRx).unit(Unit::Unstated).cite("§6 / manual 4.3: 4 B, rw, mappable (1601h); units and default not stated"),
    od(0x6083, 0, "Profile acceleration", U32, Rw, PdoRx).unit(Unit::Unstated).cite("§6 / manual 4.3: 4 B, rw, mappable (1601h); units and default not stated"),
    od(0x6084, 0, "Profile deceleration", U32, Rw, PdoRx).unit(Unit::Unstated).cite("§6 / manual 4.3: 4 B, rw, mappable (1601h); units and default not stated"),
    od(0x6087, 0, "Torque slope", U32, Rw, PdoRx).unit(Unit::Unstated).cite("§4.1 (tq, recommended in the RxPDO) / manual 4.3: 4 B, rw, mappable (1601h); units and default not stated (0.1 %/s: CiA 402 [background])"),
    od(0x607D, 1, "Min position limit", I32, Rw, Pdo::Unstated).unit(Unit::Pulse).cite("§8.1: 607Dh named only, unusable without a home set in the drive; type I32 and 0/0 = disabled: CiA 402 [background]"),
    od(0x607D, 2, "Max position limit", I32, Rw, Pdo::Unstated).unit(Unit::Pulse).cite("§8.1: as 607Dh:1"),
    od(0x60B0, 0, "Position offset", I32, Rw, Pdo::Unstated).default(0).unit(Unit::Pulse).cite("§4.3 rule 2/3 (manual §7.4): csp entry rule; type, access and default not stated (I32, 0: CiA 402 [background])"),
    // The rest of the objects the manual names (§6 of the extract): types and access where the manual prints them, the gaps named.
    CONTROL_DI_2,
    CONTROL_DI_3,
    STATUS_DO_1,
    STATUS_DO_2,
    STATUS_DO_3,
    STATUS_DO_5,
    STATUS_DO_7,
    od(0x2D60, 0, "Target point table", DataType::Unstated, Access::Unstated, PdoRx).cite("§6 / manual §4.3: mapped in 1602h, 2 bytes inferred from the map size; type, access and default not stated"),
    od(0x2D68, 0, "Point demand value", DataType::Unstated, Ro, PdoTx).cite("§6 / manual §4.3: mapped in 1A01h, 2 bytes inferred from the map size; type not stated; ro [background]"),
    od(0x2D69, 0, "Point actual value", DataType::Unstated, Ro, PdoTx).cite("§6 / manual §4.3: mapped in 1A01h, 2 bytes inferred from the map size; type not stated; ro [background]"),
    od(0x2D6A, 0, "M code actual value", DataType::Unstated, Ro, PdoTx).cite("§6 / manual §4.3: mapped in 1A01h, 1 byte inferred from the map size; type not stated; ro [background]"),
    HOMING_METHOD,
];

/// Encoder and units (MR-JET-G-N1 manual): 2^26 appears only as an example resolution.
pub const UNITS: Units = Units {
    counts_per_rev: None,
    other_counts_per_rev: &[67_108_864],
    position: PositionUnit::Count,
    velocity: Stated::Unstated(VelocityUnit::CENTI_RPM),
    linear_motors: true,
    command_truncation_exp10: None,
    acceleration: Stated::Unstated(AccelerationUnit::TimeConstantMs),
    torque: TorqueUnit::PerMilleOfRated,
    source: "MR-JET-G-N1 manual §8 (2^26 pulses/rev only in the infinite-feed example; torque \
             limits 0.1 %); the velocity and acceleration units are in the separate object \
             dictionary manual: default 0.01 r/min and ms time constants as on the MR-J4-TM \
             (Mitsubishi's convention), configurable (motor.velocity_unit)",
};

/// The variable-mapping rules of the MR-JET-G-N1 (and the MR-J5-G-N1 1-axis unit, whose
/// manual states the same limits: MR-J5-G-N1 manual §2.1, §4.4).
pub const PDO_RULES: PdoRules = PdoRules {
    max_entries: 32,
    max_rx_bytes: 64,
    max_tx_bytes: 64,
    rx_mappable: &[],
    tx_mappable: &[],
    // The family's abort list (MR-JET-G-N1 manual §5) has no 0604 0041h/0604 0042h: a mapping
    // the drive cannot take is answered with 0604 0043h (general parameter
    // incompatibility), and a write the state forbids with 0800 0022h (present device
    // state); the manual states neither case [D].
    not_mappable_abort: 0x0604_0043,
    too_long_abort: 0x0604_0043,
    locked_abort: 0x0800_0022,
    mapped_write_abort: 0x0601_0006,
    wrong_state_abort: 0x0800_0022,
    sync_mismatch_alarms: &[],
    assignment: PdoAssignment::Writable,
    frozen_after_safe_op: false,
    source:
        "MR-JET-G-N1 manual §2.1, §4.4 (32 objects, 64 bytes, only in PRE-OP), §6.2; MR-J5-G-N1 manual §2.1, §4.4, §4.2",
};

/// The MR-JET-G-N1 profile (PA01.0 = 0, PT01.2 = pulse: pp, pv, tq, hm, csp, csv, cst; jg/pt
/// need PA01.0 = 6 and are not modes this crate models).
pub const PROFILE: DriveProfile = DriveProfile {
    model: DriveModel::MrJetGN1,
    name: "Mitsubishi MR-JET-G-N1",
    identity: Identity {
        vendor_id: None,
        product_code: None,
        revision: None,
        source: "MR-JET-G-N1 manual §1.1, §2.1: not in this manual (in the ESI file)",
        maker_vendor_id: Some(super::MITSUBISHI_VENDOR_ID),
        emulator_product_code: 0xCE11_0301,
    },
    cycle: CycleFacts {
        modes: SharedSlice::Static(&[
            M::ProfilePosition,
            M::ProfileVelocity,
            M::ProfileTorque,
            M::Homing,
            M::CyclicSyncPosition,
            M::CyclicSyncVelocity,
            M::CyclicSyncTorque,
        ]),
        cycle_times_us: &ALLOWED_MICROS,
        halt_in_cyclic_modes: true,
        csp_entry: crate::mode_switch::CspEntry::ActualPosition,
    },
    pdo: PdoFacts {
        rx: RX_PDO_1600,
        tx: TX_PDO_1A00,
        unit_limits: &[],
        rules: PDO_RULES,
    },
    // (16) only with 605Ah 5–8 on FW D0+ (§7.1); the default option code is in 1–4 (§3.5)
    // [inferred]: the simulated drive has no 605Ah value until one is written.
    quirks: FsaQuirks {
        shortcut_transitions: true,
        has_quick_stop: true,
        quick_stop_returns_to_enabled: false,
        quick_stop_options_5_to_8: true,
    },
    faults: FaultFacts {
        reset_hold_ms: 10,
        reset_hold_long_cycle_ms: 20,
        long_cycle_from_us: 8000,
        alarms: ALARMS,
    },
    axes_per_unit: 1,
    units: UNITS,
    objects: OBJECTS,
    comm: CommFacts {
        check: CommCheck::SyncErrorCounter { alarm: AL_086_1 },
        leave_op_alarm: AL_086_1,
        reinit_on_leaving_op: true,
        emergency: EMERGENCY,
        sdo_info: SDO_INFO,
    },
    limits: LimitFacts {
        following_error_alarm: FOLLOWING_ERROR,
        overspeed_alarm: OVERSPEED,
        torque_limit_selection: TorqueLimitSelection::TorqueLimit2 {
            cptl_bit: 11,
            cntl_bit: 12,
        },
        stroke_end_warning: None,
        power_warnings: None,
        manual_stop_bit: None,
        relative_degree_warning: None,
    },
    sdo_write_refusals: &[],
    homing: HomingSetup {
        // §8.1: hm exists, but the methods are not in this manual.
        methods: &[],
        data_set_methods: &[],
        reference: HomeReference::PositionPreset,
        setting: None,
    },
    store_restore_objects: STORE_RESTORE_OBJECTS,
    invalid_axis_switch: None,
    profile_selector: None,
    fsoe: Some(FSOE),
    parameters: &super::params::MR_JET_G_N1,
};

/// What the drive answers of SDO Information.
pub const SDO_INFO: super::SdoInfoFacts = super::SdoInfoFacts {
    offered: true,
    one_value_per_entry: false,
    record_types: &[],
    source: "MR-JET-G-N1 manual §5 (Get OD List, Get Object Description, Get Entry Description); record type codes and value-info rules not given",
};

/// Whether alarms are also sent as CoE Emergency (payload: [`crate::profiles::facts::EMERGENCY_LAYOUT`]).
pub const EMERGENCY: super::EmergencyFacts = super::EmergencyFacts {
    sends: true,
    source: "MR-JET-G-N1 manual §5 (Emergency reports an alarm; the EMCY codes are not given)",
};

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cycles::{CycleTime, Cycles};

    #[test]
    fn default_maps_24_bytes_at_the_offsets() {
        let rx = &PROFILE.pdo.rx;
        assert_eq!(rx.byte_len(), 24);
        for (idx, off) in [
            (0x6060, 0),
            (0x6040, 2),
            (0x2D01, 4),
            (0x2D02, 6),
            (0x2D03, 8),
            (0x607A, 10),
            (0x60FF, 14),
            (0x2D20, 18),
            (0x6071, 22),
        ] {
            assert_eq!(rx.offset_of(idx, 0), Some(off), "{idx:#06x}");
        }
        let tx = &PROFILE.pdo.tx;
        assert_eq!(tx.byte_len(), 24);
        for (idx, off) in [
            (0x6061, 0),
            (0x6041, 2),
            (0x2D11, 4),
            (0x6064, 10),
            (0x606C, 14),
            (0x60F4, 18),
            (0x6077, 22),
        ] {
            assert_eq!(tx.offset_of(idx, 0), Some(off), "{idx:#06x}");
        }
    }

    #[test]
    fn tv_4_fault_reset_hold_cycles() {
        // MR-JET-G-N1 TV-4 (docs/test-vectors.md) cycle counts.
        for (us, n) in [
            (125, 80),
            (250, 40),
            (500, 20),
            (1000, 10),
            (2000, 5),
            (4000, 3),
            (8000, 3),
        ] {
            let c = CycleTime::from_micros(us).unwrap();
            assert_eq!(PROFILE.fault_reset_hold(c), Cycles(n), "{us} µs");
        }
    }

    #[test]
    fn the_objects_the_manual_names_are_served() {
        // (index, sub, type, access, PDO, default) as manual §7.2, §7.3, §4.3, §8.3 give them.
        let rows = [
            (0x2D02, 0, U16, Rw, PdoRx, None),
            (0x2D03, 0, U16, Rw, PdoRx, None),
            (0x2D11, 0, U16, Ro, PdoTx, None),
            (0x2D12, 0, U16, Ro, PdoTx, None),
            (0x2D13, 0, U16, Ro, PdoTx, None),
            (0x2D15, 0, U16, Ro, PdoTx, None),
            (0x2D17, 0, U16, Ro, PdoTx, None),
            (0x2D60, 0, DataType::Unstated, Access::Unstated, PdoRx, None),
            (0x2D68, 0, DataType::Unstated, Ro, PdoTx, None),
            (0x2D6A, 0, DataType::Unstated, Ro, PdoTx, None),
            (0x6098, 0, I8, Rw, Pdo::Unstated, None),
        ];
        // No default is stated for any of them.
        super::super::assert_rows(&PROFILE, &rows);
    }
}
