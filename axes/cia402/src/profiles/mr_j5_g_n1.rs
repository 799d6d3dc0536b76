//! Mitsubishi MR-J5-G-N1 (1-axis), per the MR-J5-G-N1 manual ( SH(NA)-030372CHN-A).

use super::facts::{alarm, od, Unit};
use super::{AccelerationUnit, PositionUnit, Stated, TorqueUnit, VelocityUnit};
use super::{
    Access, AlarmInfo, AlarmKind, Clearing, CommCheck, DataType, DriveModel, DriveProfile,
    Identity, InvalidAxisSwitch, OdEntry, Pdo, StopBehaviour, UnitPdoLimit, Units,
};
use super::{CommFacts, CycleFacts, FaultFacts, HomingSetup, LimitFacts, PdoFacts};
use super::{HomeReference, TorqueLimitSelection};
use crate::cycles::ALLOWED_MICROS;
use crate::fsa::FsaQuirks;
use crate::mode::ModeOfOperation as M;
use crate::shared_slice::SharedSlice;
use Access::{Ro, Rw};
use DataType::{I16, I32, I8, U16, U32, U8};
use Pdo::{No, Rx as PdoRx, Tx as PdoTx};

// The default 1st RxPDO 1600h / TxPDO 1A00h (24 bytes each, §4.3), the alarm
// code encoding and the AL.086.1, following-error and overspeed codes are the MR-JET-G-N1's
// (MR-J5-G-N1 manual "Same in both"): one definition, in `mr_jet_g_n1`.
pub use super::mr_jet_g_n1::{AL_086_1, FOLLOWING_ERROR, OVERSPEED, RX_PDO_1600, TX_PDO_1A00};

/// AL.011.2 Invalid axis setting error (§8, 1-axis SW3 setting).
pub const AL_011_2: u16 = 0x0112;

/// The SW3 setting a 1-axis MR-J5-G-N1 refuses: SW3-1 OFF (down) with SW3-2 ON (up) raises
/// [`AL_011_2`] (MR-J5-G-N1 manual §2.2, §3.1, §4.3, §4.4 and TV-14; manual §8 Point, seed 004 L1258). What SW3
/// selects, and when the amplifier checks it, the manual does not say.
pub const INVALID_AXIS_SWITCH_1_AXIS: InvalidAxisSwitch = InvalidAxisSwitch {
    sw3_1: false,
    sw3_2: true,
    alarm: AL_011_2,
};

/// The alarms and warnings the manual names (§9). Stop methods are not in this manual; causes and remedies
/// only where it states them (§6.1, §8, §8.1, §8.3 disconnection procedure).
#[rustfmt::skip]
pub const ALARMS: &[AlarmInfo] = &[
    // [inferred] SW3 is read at power-on (TV-14), so a Fault Reset cannot remove the
    // cause: the simulator keeps the alarm until a power cycle with a valid setting.
    alarm(AL_011_2, "AL.011.2", "Invalid axis setting error", AlarmKind::Alarm, StopBehaviour::Unstated, Clearing::PowerCycle, "§9; §8 Point (SW3 on a 1-axis unit); clearing not stated: power cycle [inferred]").explained(Some("A 1-axis amplifier with SW3-1 OFF and SW3-2 ON"), None),
    alarm(0x0250, "AL.025", "Absolute position lost", AlarmKind::Alarm, StopBehaviour::Unstated, Clearing::Unstated, "§9, §8.1").explained(None, Some("Home again through the controller")),
    alarm(0x0251, "AL.025.1", "Servo motor encoder absolute position lost", AlarmKind::Alarm, StopBehaviour::Unstated, Clearing::PowerCycle, "§8.1: cycle the power after 5 s").explained(Some("First set-up of the absolute position detection system"), Some("Wait 5 s, then cycle the power")),
    alarm(AL_086_1, "AL.086.1", "Network receive data error (Network communication error 1)", AlarmKind::Alarm, StopBehaviour::Unstated, Clearing::Unstated, "§2.4, §9: PN18 / 10F1h:02; counting rule not given").explained(Some("Communication errors passed [Pr. PN18] / 10F1h:02 Sync Error Counter Limit, or the network was dropped without the disconnection procedure"), Some("Set a threshold suited to the controller in [Pr. PN18] or 10F1h:02; Disconnect in order: stop the motor, Shutdown in 6040h (servo off), Pre-Operational, then power off")),
    alarm(0x0901, "AL.090.1", "Homing incomplete", AlarmKind::Warning, StopBehaviour::Unstated, Clearing::Automatic, "§8, §9").explained(Some("Servo-on without a home position ([Pr. PC41.0])"), None),
    alarm(0x09E9, "AL.09E.9", "Control mode setting warning", AlarmKind::Warning, StopBehaviour::Continues, Clearing::Automatic, "§1.4: FW < B6, free-run csp/csv/cst").explained(Some("Firmware earlier than B6 driving csp/csv/cst in free-run"), None),
    alarm(0x0E31, "AL.0E3.1", "Absolute position counter warning", AlarmKind::Warning, StopBehaviour::Continues, Clearing::Automatic, "§8.1").explained(Some("32768 revolutions or more from home ([Pr. PC29.5])"), None),
    alarm(FOLLOWING_ERROR, "8611h", "Following error (CiA 402)", AlarmKind::Alarm, StopBehaviour::DynamicBrake, Clearing::FaultReset, "not in the manual (§9 has no alarm list): CiA 402 [background]"),
    alarm(OVERSPEED, "8400h", "Overspeed (CiA 402)", AlarmKind::Alarm, StopBehaviour::DynamicBrake, Clearing::FaultReset, "not in the manual (§9 has no alarm list): CiA 402 [background]"),
];

/// The object dictionary: the objects §6 names (axis A indexes, +800h per axis for CiA 402
/// objects, +1000h for manufacturer objects, §1.5). Types of 60xxh are [background]/[inferred]
/// from the map sizes (§5.2, §6 note). Control DI 4–10 and Status DO 4, 6, 8–10 are left out:
/// the manual elides their rows, their indexes are only inferred (§6).
#[rustfmt::skip]
pub const OBJECTS: &[OdEntry] = &[
    od(0x10F1, 2, "Sync Error Counter Limit", U16, Rw, No).default(super::generic_cia402::SYNC_ERROR_COUNTER_LIMIT).unit(Unit::Times).cite("§2.4: type, default and counting rule not stated; U16 rw as ETG.1020 has it [background], default the simulator's"),
    od(0x1C32, 2, "Cycle time", U32, Rw, No).default(250_000).unit(Unit::Nanosecond).cite("§1.3: 125000…8000000 (W2/W3 from 250000), written in PreOp; unit: CiA 402 [background]"),
    od(0x1C32, 0, "SM output parameter", U8, Ro, No).default(12).cite("§4.2 (subs listed); the highest sub-index listed"),
    od(0x1C32, 1, "Synchronization type", U16, Rw, No).default(0).cite("§4.2 (subs listed); DC or free run; 0 = free run until the master selects DC (ETG.1020 [background])"),
    od(0x1C32, 4, "Synchronization types supported", U16, Ro, No).default(0x0005).cite("§4.2 (subs listed); free run and DC SYNC0 (ETG.1020 bits 0 and 2 [background])"),
    od(0x1C32, 5, "Minimum cycle time", U32, Ro, No).default(125_000).unit(Unit::Nanosecond).cite("§4.2 (subs listed); §1.3: 0.125 ms (1-axis; W2/W3 from 0.25 ms)"),
    od(0x1C32, 6, "Calc and copy time", U32, Ro, No).unit(Unit::Nanosecond).cite("§4.2 (subs listed); not stated"),
    od(0x1C32, 9, "Delay time", U32, Ro, No).unit(Unit::Nanosecond).cite("§4.2 (subs listed); not stated"),
    od(0x1C32, 12, "Cycle time too small", U16, Ro, No).default(0).cite("§4.2 (subs listed); a counter"),
    od(0x1C33, 0, "SM input parameter", U8, Ro, No).default(12).cite("§4.2 (subs listed); the highest sub-index listed"),
    od(0x1C33, 1, "Synchronization type", U16, Rw, No).default(0).cite("§4.2 (subs listed); DC or free run; 0 = free run until the master selects DC (ETG.1020 [background])"),
    od(0x1C33, 4, "Synchronization types supported", U16, Ro, No).default(0x0005).cite("§4.2 (subs listed); free run and DC SYNC0 (ETG.1020 bits 0 and 2 [background])"),
    od(0x1C33, 5, "Minimum cycle time", U32, Ro, No).default(125_000).unit(Unit::Nanosecond).cite("§4.2 (subs listed); §1.3: 0.125 ms (1-axis; W2/W3 from 0.25 ms)"),
    od(0x1C33, 6, "Calc and copy time", U32, Ro, No).unit(Unit::Nanosecond).cite("§4.2 (subs listed); not stated"),
    od(0x1C33, 9, "Delay time", U32, Ro, No).unit(Unit::Nanosecond).cite("§4.2 (subs listed); not stated"),
    od(0x1C33, 12, "Cycle time too small", U16, Ro, No).default(0).cite("§4.2 (subs listed); a counter"),
    od(0x1C33, 2, "Cycle time", U32, Ro, No).unit(Unit::Nanosecond).cite("§4.2 (subs listed); follows 1C32h:02"),
    od(0x2D01, 0, "Control DI 1", U16, Rw, PdoRx).default(0).cite("§6"),
    od(0x2D20, 0, "Velocity limit value", DataType::Unstated, Access::Unstated, PdoRx).cite("§5.2: 4 bytes inferred from the map size"),
    od(0x6040, 0, "Controlword", U16, Rw, PdoRx).default(0).cite("§3.3"),
    od(0x6041, 0, "Statusword", U16, Ro, PdoTx).cite("§3.4"),
    od(0x605A, 0, "Quick stop option code", DataType::Unstated, Access::Unstated, Pdo::Unstated).range(&[(1, 4)]).cite("§3.5: only 1–4 documented"),
    od(0x6060, 0, "Modes of operation", I8, Rw, PdoRx).default(8).cite("§1.2: initial 8 with PT01.2 = pulse"),
    od(0x6061, 0, "Modes of operation display", I8, Ro, PdoTx).default(8).cite("§1.2"),
    od(0x6064, 0, "Position actual value", I32, Ro, PdoTx).unit(Unit::Pulse).cite("§6 (type inferred)"),
    od(0x606C, 0, "Velocity actual value", I32, Ro, PdoTx).unit(Unit::Unstated).cite("§6 (type inferred)"),
    od(0x6071, 0, "Target torque", I16, Rw, PdoRx).default(0).unit(Unit::TenthPercentRated).cite("§6 (type inferred); unit: CiA 402 [background]"),
    od(0x6077, 0, "Torque actual value", I16, Ro, PdoTx).unit(Unit::TenthPercentRated).cite("§6 (type inferred); unit: CiA 402 [background]"),
    od(0x607A, 0, "Target position", I32, Rw, PdoRx).default(0).unit(Unit::Pulse).cite("§6 (type inferred)"),
    od(0x60E0, 0, "Positive torque limit value", U16, Access::Unstated, Pdo::Unstated).unit(Unit::TenthPercentRated).cite("§8: = PA11"),
    od(0x60E1, 0, "Negative torque limit value", U16, Access::Unstated, Pdo::Unstated).unit(Unit::TenthPercentRated).cite("§8: = PA12"),
    od(0x60F4, 0, "Following error actual value", I32, Ro, PdoTx).unit(Unit::Pulse).cite("§6 (type inferred)"),
    od(0x60FF, 0, "Target velocity", I32, Rw, PdoRx).default(0).unit(Unit::Unstated).cite("§6 (type inferred)"),
    od(0x6502, 0, "Supported drive modes", U32, Ro, No).default(0x0002_03AD).cite("§1.2: bits 0, 2, 3, 5, 7, 8, 9, 17"),
    od(0x6081, 0, "Profile velocity", U32, Rw, PdoRx).unit(Unit::Unstated).cite("§6 / manual 4.3: 4 B, rw, mappable (1601h); units and default not stated"),
    od(0x6083, 0, "Profile acceleration", U32, Rw, PdoRx).unit(Unit::Unstated).cite("§6 / manual 4.3: 4 B, rw, mappable (1601h); units and default not stated"),
    od(0x6084, 0, "Profile deceleration", U32, Rw, PdoRx).unit(Unit::Unstated).cite("§6 / manual 4.3: 4 B, rw, mappable (1601h); units and default not stated"),
    od(0x6087, 0, "Torque slope", U32, Rw, PdoRx).unit(Unit::Unstated).cite("§4.1 (tq, recommended in the RxPDO) / manual 4.3: 4 B, rw, mappable (1601h); units and default not stated (0.1 %/s: CiA 402 [background])"),
    od(0x607D, 1, "Min position limit", I32, Rw, Pdo::Unstated).unit(Unit::Pulse).cite("§8.1: 607Dh named only, unusable without a home set in the drive; type I32 and 0/0 = disabled: CiA 402 [background]"),
    od(0x607D, 2, "Max position limit", I32, Rw, Pdo::Unstated).unit(Unit::Pulse).cite("§8.1: as 607Dh:1"),
    od(0x60B0, 0, "Position offset", I32, Rw, Pdo::Unstated).default(0).unit(Unit::Pulse).cite("§4.3 rule 2/3 (manual §7.4): csp entry rule; type, access and default not stated (I32, 0: CiA 402 [background])"),
    // The rest of the objects the manual names (§6 of the extract): types and access where the manual prints them, the gaps named.
    super::mr_jet_g_n1::CONTROL_DI_2,
    super::mr_jet_g_n1::CONTROL_DI_3,
    super::mr_jet_g_n1::STATUS_DO_1,
    super::mr_jet_g_n1::STATUS_DO_2,
    super::mr_jet_g_n1::STATUS_DO_3,
    super::mr_jet_g_n1::STATUS_DO_5,
    super::mr_jet_g_n1::STATUS_DO_7,
    od(0x2D60, 0, "Manufacturer setting", DataType::Unstated, Access::Unstated, PdoRx).cite("§6 / manual §4.3: mapped in 1602h, 2 bytes inferred from the map size; type, access and default not stated"),
    od(0x2D68, 0, "Manufacturer setting", DataType::Unstated, Access::Unstated, PdoTx).cite("§6 / manual §4.3: mapped in 1A01h, 2 bytes inferred from the map size; type and access not stated"),
    od(0x2D69, 0, "Manufacturer setting", DataType::Unstated, Access::Unstated, PdoTx).cite("§6 / manual §4.3: mapped in 1A01h, 2 bytes inferred from the map size; type and access not stated"),
    od(0x2D6A, 0, "Manufacturer setting", DataType::Unstated, Access::Unstated, PdoTx).cite("§6 / manual §4.3: mapped in 1A01h, 1 byte inferred from the map size; type and access not stated"),
    super::mr_jet_g_n1::HOMING_METHOD,
];

/// Encoder and units: the manual gives no encoder resolution or factor group (§8).
pub const UNITS: Units = Units {
    counts_per_rev: None,
    other_counts_per_rev: &[],
    position: PositionUnit::Count,
    velocity: Stated::Unstated(VelocityUnit::CENTI_RPM),
    linear_motors: true,
    command_truncation_exp10: None,
    acceleration: Stated::Unstated(AccelerationUnit::TimeConstantMs),
    torque: TorqueUnit::PerMilleOfRated,
    source: "MR-J5-G-N1 manual: no encoder resolution, velocity unit or factor group (object \
             dictionary manual): default 0.01 r/min and ms time constants as on the MR-J4-TM \
             (Mitsubishi's convention), configurable (motor.velocity_unit); torque 0.1 %",
};

const FSA: FsaQuirks = FsaQuirks {
    shortcut_transitions: true,
    has_quick_stop: true,
    quick_stop_returns_to_enabled: false,
    quick_stop_options_5_to_8: false,
};

const IDENTITY: Identity = Identity {
    vendor_id: None,
    product_code: None,
    revision: None,
    source: "MR-J5-G-N1 manual §1.1, §2.1: vendor ID / product code only in the ESI",
    maker_vendor_id: Some(super::MITSUBISHI_VENDOR_ID),
    emulator_product_code: 0xCE11_0501,
};

/// The MR-J5-G-N1 1-axis profile.
///
/// Identity is `None`: vendor ID and product code are only in the ESI (§1.1). Modes: all seven
/// with PT01.2 = pulse (§1.2). Cycles 0.125–8 ms (§1.3). Quirks: shortcut transitions (§3.2),
/// quick stop present, transition 16 not supported (§3.1). Fault Reset held ≥ 10 ms, ≥ 20 ms at
/// the 8 ms cycle (§7.1).
pub const PROFILE: DriveProfile = DriveProfile {
    model: DriveModel::MrJ5GN1,
    name: "Mitsubishi MR-J5-G-N1",
    identity: IDENTITY,
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
        // §3.5: "HALT (bit 8) = 1 means temporary stop"; modes not restricted there [inferred].
        halt_in_cyclic_modes: true,
        csp_entry: crate::mode_switch::CspEntry::ActualPosition,
    },
    pdo: PdoFacts {
        rx: RX_PDO_1600,
        tx: TX_PDO_1A00,
        unit_limits: &[UnitPdoLimit {
            from_us: 0,
            to_us: u32::MAX,
            max_rx_bytes: 64,
            max_tx_bytes: 64,
        }],
        rules: super::mr_jet_g_n1::PDO_RULES,
    },
    quirks: FSA,
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
        // §8: hm exists, but the methods are not in this manual.
        methods: &[],
        data_set_methods: &[],
        reference: HomeReference::PositionPreset,
        setting: None,
    },
    store_restore_objects: super::mr_jet_g_n1::STORE_RESTORE_OBJECTS,
    invalid_axis_switch: Some(INVALID_AXIS_SWITCH_1_AXIS),
    profile_selector: None,
    // §7: this manual has no safety PDOs and no FSoE objects ("should not expose 1608h/1A08h").
    fsoe: None,
    parameters: &super::params::MR_JET_G_N1,
};

/// Modes of the multi-axis units: pv and tq are not usable (§1.2, §6.1 *2).
pub const MULTI_AXIS_MODES: &[M] = &[
    M::ProfilePosition,
    M::Homing,
    M::CyclicSyncPosition,
    M::CyclicSyncVelocity,
    M::CyclicSyncTorque,
];

/// Cycle times of the multi-axis units: no 0.125 ms (§1.3, §2.1 remark).
pub const MULTI_AXIS_CYCLES_US: &[u32] = &[250, 500, 1000, 2000, 4000, 8000];

/// The MR-J5W2-G-N1 (2-axis) profile: per axis the same maps as axis A at offset indexes (§1.5).
pub const PROFILE_W2: DriveProfile = DriveProfile {
    model: DriveModel::MrJ5W2GN1,
    name: "Mitsubishi MR-J5W2-G-N1",
    identity: Identity {
        emulator_product_code: 0xCE11_0502,
        ..IDENTITY
    },
    cycle: CycleFacts {
        modes: SharedSlice::Static(MULTI_AXIS_MODES),
        cycle_times_us: MULTI_AXIS_CYCLES_US,
        ..PROFILE.cycle
    },
    axes_per_unit: 2,
    pdo: PdoFacts {
        // §5.1: no multi-axis entry at 0.125 ms.
        unit_limits: &[UnitPdoLimit {
            from_us: 250,
            to_us: u32::MAX,
            max_rx_bytes: 108,
            max_tx_bytes: 120,
        }],
        ..PROFILE.pdo
    },
    // §1.5: the AL.011.2 rule is stated for 1-axis amplifiers only; "Multi-axis SW3 settings
    // are not given", so no SW3 setting is refused on the W2/W3.
    invalid_axis_switch: None,
    profile_selector: None,
    ..PROFILE
};

/// The MR-J5W3-G-N1 (3-axis) profile.
pub const PROFILE_W3: DriveProfile = DriveProfile {
    model: DriveModel::MrJ5W3GN1,
    name: "Mitsubishi MR-J5W3-G-N1",
    identity: Identity {
        emulator_product_code: 0xCE11_0503,
        ..IDENTITY
    },
    axes_per_unit: 3,
    pdo: PdoFacts {
        unit_limits: &[
            UnitPdoLimit {
                from_us: 250,
                to_us: 250,
                max_rx_bytes: 120,
                max_tx_bytes: 120,
            },
            UnitPdoLimit {
                from_us: 251,
                to_us: u32::MAX,
                max_rx_bytes: 144,
                max_tx_bytes: 162,
            },
        ],
        ..PROFILE_W2.pdo
    },
    ..PROFILE_W2
};

/// Offset per axis of the CiA 402 area 6000h–67FFh (axis B 6800h, axis C 7000h; §1.5, manual §3.1).
pub const AXIS_OFFSET_CIA402: u16 = 0x800;
/// Offset per axis of the manufacturer areas 2000h–2FFFh (axis B 3000h, axis C 4000h; §1.5).
pub const AXIS_OFFSET_MANUFACTURER: u16 = 0x1000;
/// Offset per axis of the PDO mapping objects 1600h–1603h / 1A00h–1A03h (axis B 1610h, axis C
/// 1620h; §1.5, manual §4.4).
pub const AXIS_OFFSET_PDO_MAPPING: u16 = 0x10;
/// Most axes a unit has (MR-J5W3-G-N1).
pub const MAX_UNIT_AXES: u8 = 3;

/// The index of axis-A object `index` on axis `axis` (0 = A) of a multi-axis unit (§1.5):
/// +800h per axis in the CiA 402 area (6000h–67FFh), +1000h in the manufacturer areas
/// (2000h–2FFFh), +10h for the PDO mapping objects (1600h–1603h, 1A00h–1A03h); 1000h–1FFFh
/// otherwise shared. `None` for an axis the area has no copy for.
pub const fn axis_index(index: u16, axis: u8) -> Option<u16> {
    if axis >= MAX_UNIT_AXES {
        return None;
    }
    let a = axis as u16;
    Some(match index {
        0x6000..=0x67FF => index + AXIS_OFFSET_CIA402 * a,
        0x2000..=0x2FFF => index + AXIS_OFFSET_MANUFACTURER * a,
        0x1600..=0x1603 | 0x1A00..=0x1A03 => index + AXIS_OFFSET_PDO_MAPPING * a,
        _ => index,
    })
}

/// The axis and axis-A index of object `index` on a unit of `axes` axes, the inverse of
/// [`axis_index`]; a shared object is axis 0's. `None` for an index in the per-axis area of an
/// axis the unit does not have (e.g. 7040h on an MR-J5W2).
pub const fn index_axis(index: u16, axes: u8) -> Option<(u8, u16)> {
    let (axis, base) = match index {
        0x6000..=0x77FF => (
            (index - 0x6000) / AXIS_OFFSET_CIA402,
            0x6000 + (index - 0x6000) % AXIS_OFFSET_CIA402,
        ),
        0x2000..=0x4FFF => (
            (index - 0x2000) / AXIS_OFFSET_MANUFACTURER,
            0x2000 + (index - 0x2000) % AXIS_OFFSET_MANUFACTURER,
        ),
        0x1600..=0x1603 | 0x1A00..=0x1A03 => (0, index),
        0x1610..=0x1613 | 0x1A10..=0x1A13 => (1, index - AXIS_OFFSET_PDO_MAPPING),
        0x1620..=0x1623 | 0x1A20..=0x1A23 => (2, index - 2 * AXIS_OFFSET_PDO_MAPPING),
        _ => (0, index),
    };
    if axis as u8 >= axes {
        None
    } else {
        Some((axis as u8, base))
    }
}

/// The most RxPDO and TxPDO bytes a unit of `axes` axes exchanges per cycle at `cycle_us`
/// (§5.1, manual §4.4: 1-axis 64/64; 2-axis 108/120; 3-axis 120/120 at 0.25 ms, 144/162 from
/// 0.5 ms), from the profiles' [`super::PdoFacts::unit_limits`]. `None` where the table has no
/// entry (multi-axis at 0.125 ms).
pub fn unit_pdo_limit(axes: u8, cycle_us: u32) -> Option<(u16, u16)> {
    let unit = match axes {
        1 => &PROFILE,
        2 => &PROFILE_W2,
        3 => &PROFILE_W3,
        _ => return None,
    };
    unit.unit_pdo_limit(cycle_us)
}

/// What the drive answers of SDO Information.
pub const SDO_INFO: super::SdoInfoFacts = super::SdoInfoFacts {
    offered: true,
    one_value_per_entry: false,
    record_types: &[],
    source: "MR-J5-G-N1 manual §5 (Get OD List, Get Object Description, Get Entry Description); record type codes and value-info rules not given",
};

/// Whether alarms are also sent as CoE Emergency (payload: [`crate::profiles::facts::EMERGENCY_LAYOUT`]).
pub const EMERGENCY: super::EmergencyFacts = super::EmergencyFacts {
    sends: true,
    source:
        "MR-J5-G-N1 manual §5 (Emergency: alarm notification; codes not given), also MR-J5W2/W3",
};

#[cfg(test)]
mod tests {
    use super::*;
    use crate::controlword::Controlword;
    use crate::cycles::{CycleTime, Cycles};
    use crate::pdo::{PdoError, RxPdo, TxPdo};
    use crate::profiles::{profile, DriveModel};
    use crate::statusword::Statusword;

    #[test]
    fn rx_offsets_match_spec_table() {
        // MR-J5-G-N1 manual §4.3, 1st RxPDO.
        let m = &PROFILE.pdo.rx;
        assert_eq!(m.byte_len(), 24);
        let expect = [
            (0x6060, 0),
            (0x6040, 2),
            (0x2D01, 4),
            (0x2D02, 6),
            (0x2D03, 8),
            (0x607A, 10),
            (0x60FF, 14),
            (0x2D20, 18),
            (0x6071, 22),
        ];
        for (idx, off) in expect {
            assert_eq!(m.offset_of(idx, 0), Some(off), "{idx:#06x}");
        }
        assert_eq!(
            m.layout().nth(1).map(|(o, e)| (o, e.is_padding())),
            Some((1, true))
        );
    }

    #[test]
    fn tx_offsets_match_spec_table() {
        // MR-J5-G-N1 manual §4.3, 1st TxPDO.
        let m = &PROFILE.pdo.tx;
        assert_eq!(m.byte_len(), 24);
        let expect = [
            (0x6061, 0),
            (0x6041, 2),
            (0x2D11, 4),
            (0x2D12, 6),
            (0x2D13, 8),
            (0x6064, 10),
            (0x606C, 14),
            (0x60F4, 18),
            (0x6077, 22),
        ];
        for (idx, off) in expect {
            assert_eq!(m.offset_of(idx, 0), Some(off), "{idx:#06x}");
        }
        assert!(!m.maps(0x603F));
    }

    #[test]
    fn rx_bytes_are_little_endian_at_the_offsets() {
        let pdo = RxPdo {
            mode: 8,
            controlword: Controlword(0x000F),
            target_position: -2,
            target_velocity: 0x0102_0304,
            velocity_limit: 0xA0B0_C0D0,
            target_torque: -300,
            ..RxPdo::default()
        };
        let mut buf = [0xEEu8; 24];
        PROFILE.pdo.rx.encode_rx(&pdo, &mut buf).unwrap();
        assert_eq!(buf[0], 8);
        assert_eq!(buf[1], 0, "padding is zero");
        assert_eq!(&buf[2..4], &[0x0F, 0x00]);
        assert_eq!(&buf[4..10], &[0; 6], "Control DI 1-3 not carried: zero");
        assert_eq!(&buf[10..14], &[0xFE, 0xFF, 0xFF, 0xFF]);
        assert_eq!(&buf[14..18], &[0x04, 0x03, 0x02, 0x01]);
        assert_eq!(&buf[18..22], &[0xD0, 0xC0, 0xB0, 0xA0]);
        assert_eq!(&buf[22..24], &(-300i16).to_le_bytes());
        assert_eq!(PROFILE.pdo.rx.decode_rx(&buf), Ok(pdo));
    }

    #[test]
    fn tx_round_trip_and_error_code_not_mapped() {
        let pdo = TxPdo {
            mode_display: -101,
            statusword: Statusword(0x0237),
            position_actual: i32::MIN,
            velocity_actual: i32::MAX,
            following_error: -12345,
            torque_actual: i16::MIN,
            error_code: 0x8611,
            extras: crate::pdo::objects::TxExtras::default(),
        };
        let mut pdo = pdo;
        crate::profiles::status_do::StatusDo([0x1000, 0x0008, 0x0020])
            .write_to(&mut pdo.extras)
            .unwrap();
        let mut buf = [0u8; 24];
        PROFILE.pdo.tx.encode_tx(&pdo, &mut buf).unwrap();
        let back = PROFILE.pdo.tx.decode_tx(&buf).unwrap();
        assert_eq!(
            back,
            TxPdo {
                error_code: 0,
                ..pdo
            }
        );
        assert_eq!(&buf[2..4], &[0x37, 0x02]);
        // Status DO 1–3 at bytes 4, 6, 8 (§4.3): S_INP, S_ZSP, S_STO.
        assert_eq!(&buf[4..10], &[0x00, 0x10, 0x08, 0x00, 0x20, 0x00]);
    }

    #[test]
    fn short_buffer_names_the_map() {
        let mut buf = [0u8; 23];
        let e = PROFILE
            .pdo
            .rx
            .encode_rx(&RxPdo::default(), &mut buf)
            .unwrap_err();
        assert_eq!(
            e,
            PdoError::Length {
                map: 0x1600,
                expected: 24,
                actual: 23
            }
        );
        assert!(e.to_string().contains("0x1600"), "{e}");
        let e = PROFILE.pdo.tx.decode_tx(&[]).unwrap_err().to_string();
        assert!(e.contains("0x1A00") && e.contains("24"), "{e}");
        assert!(PROFILE.pdo.rx.decode_rx(&buf).is_err());
        assert!(PROFILE
            .pdo
            .tx
            .encode_tx(&TxPdo::default(), &mut buf)
            .is_err());
    }

    #[test]
    fn identity_modes_cycles_quirks() {
        let p = profile(DriveModel::MrJ5GN1);
        assert_eq!(p.vendor_id(), None);
        assert_eq!(p.product_code(), None);
        assert_eq!(p.cycle.modes.len(), 7);
        for us in ALLOWED_MICROS {
            assert!(p.supports_cycle_time(CycleTime::from_micros(us).unwrap()));
        }
        assert!(p.quirks.shortcut_transitions && p.quirks.has_quick_stop);
        assert!(!p.quirks.quick_stop_returns_to_enabled);
        assert_eq!(p.axes_per_unit, 1);
    }

    /// §1.5 offsets both ways, and the §5.1 unit PDO limits (TV-7: a J5W3 at 0.25 ms takes 120
    /// bytes; no multi-axis entry at 0.125 ms).
    #[test]
    fn multi_axis_offsets_and_unit_pdo_limits() {
        for (index, axis, at) in [
            (0x6040, 1, 0x6840),
            (0x6041, 2, 0x7041),
            (0x2D01, 2, 0x4D01),
            (0x1A00, 1, 0x1A10),
            (0x1C32, 2, 0x1C32),
        ] {
            assert_eq!(axis_index(index, axis), Some(at));
            let back = if at == 0x1C32 { (0, at) } else { (axis, index) };
            assert_eq!(index_axis(at, 3), Some(back));
        }
        assert_eq!(axis_index(0x6040, 3), None);
        assert_eq!(index_axis(0x7040, 2), None, "no axis C on a J5W2");
        assert_eq!(PROFILE_W2.object_slot(0x6840), Some((1, 0x6040)));
        assert_eq!(PROFILE.object_slot(0x6840), Some((0, 0x6840)));
        assert_eq!(PROFILE_W3.axis_object(0x1600, 2), Some(0x1620));
        assert_eq!(unit_pdo_limit(3, 250), Some((120, 120)));
        assert_eq!(unit_pdo_limit(3, 500), Some((144, 162)));
        assert_eq!(unit_pdo_limit(2, 8000), Some((108, 120)));
        assert_eq!(unit_pdo_limit(2, 125), None);
        assert_eq!(unit_pdo_limit(1, 125), Some((64, 64)));
    }

    #[test]
    fn fault_reset_hold_per_cycle_time() {
        // MR-J5-G-N1 TV-5 (docs/test-vectors.md).
        let expect = [
            (125, 80),
            (250, 40),
            (500, 20),
            (1000, 10),
            (2000, 5),
            (4000, 3),
            (8000, 3),
        ];
        for (us, n) in expect {
            let c = CycleTime::from_micros(us).unwrap();
            assert_eq!(PROFILE.fault_reset_hold(c), Cycles(n), "{us} µs");
        }
    }

    #[test]
    fn the_objects_the_manual_names_are_served() {
        // The rows the MR-JET-G-N1 manual prints alike (§7.2, §7.3, §8.3): the same entries.
        use super::super::mr_jet_g_n1 as jet;
        for shared in [
            jet::CONTROL_DI_2,
            jet::CONTROL_DI_3,
            jet::STATUS_DO_1,
            jet::STATUS_DO_2,
            jet::STATUS_DO_3,
            jet::STATUS_DO_5,
            jet::STATUS_DO_7,
            jet::HOMING_METHOD,
        ] {
            assert_eq!(PROFILE.object(shared.index, 0), Some(&shared));
        }
        // The "manufacturer setting" objects of the 1602h/1A01h maps (manual §4.3): named, with
        // no type, access or default (sizes inferred from the maps).
        let rows = [0x2D60, 0x2D68, 0x2D69, 0x2D6A].map(|index| {
            let pdo = if index == 0x2D60 { PdoRx } else { PdoTx };
            (index, 0, DataType::Unstated, Access::Unstated, pdo, None)
        });
        super::super::assert_rows(&PROFILE, &rows);
        assert_eq!(PROFILE.object(0x2D02, 0).map(|o| o.data_type), Some(U16));
        // A multi-axis unit serves them at each axis' offset index (manual §1.5).
        assert_eq!(PROFILE_W3.axis_object(0x2D12, 2), Some(0x4D12));
        assert_eq!(PROFILE_W3.objects, PROFILE.objects);
    }
}
