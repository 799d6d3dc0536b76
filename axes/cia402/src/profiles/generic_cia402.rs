//! A generic CiA 402 drive (`drive = "cia402"`): any CoE SubDevice with the CiA 402 drive
//! profile as IEC 61800-7-201 (CiA 402) and the EtherCAT implementation directive ETG.6010
//! describe it, with nothing vendor-specific. Every fact below is the profile's default or a
//! named, documented choice; what a real drive deviates in (its cycle times, its fault-reset
//! timing, its mappable objects, its limits) is the user's to check in the drive's own manual.
//!
//! * Identity: the profile has none. An EtherCAT axis of this model must give the SubDevice's
//!   1018h:01/02 in `[axes.ethercat] vendor_id` / `product_code` (the configuration refuses it
//!   otherwise); the emulator presents that identity.
//! * Modes: csp, csv, cst and hm (6060h = 8, 9, 10, 6; 6502h bits 7, 8, 9, 5).
//! * Cycle times: every cycle cellrt runs (125–8000 µs). A real drive supports fewer; the
//!   user must pick one its manual allows (its 1C32h:02 / 1C33h:04).
//! * Default maps: RxPDO 1600h = 6040h, 6060h, 607Ah, 60FFh, 6071h; TxPDO 1A00h = 6041h,
//!   6061h, 6064h, 606Ch, 6077h, 60F4h, 603Fh (the objects the common CiA 402 / ETG.6010
//!   csp/csv/cst mappings carry; a real drive's predefined mappings may differ), an 8-bit
//!   padding after each 8-bit mode object so the 32-bit values stay 16-bit aligned.
//! * FSA: plain CiA 402 (no multi-state jumps, quick stop present, 605Ah default 2: no
//!   transition (16) back to Operation enabled).
//! * Communication check: the sync-error counter against 10F1h:02 (ETG.1020).

use super::facts::{alarm, obj, od, Unit};
use super::{AccelerationUnit, PositionUnit, Stated, TorqueUnit, VelocityUnit};
use super::{
    Access, AlarmInfo, AlarmKind, Clearing, CommCheck, DataType, DriveModel, DriveProfile,
    Identity, OdEntry, Pdo, PdoAssignment, PdoRules, StopBehaviour, Units,
};
use super::{CommFacts, CycleFacts, FaultFacts, HomingSetup, LimitFacts, PdoFacts};
use super::{HomeReference, TorqueLimitSelection};
use crate::cycles::ALLOWED_MICROS;
use crate::fsa::FsaQuirks;
use crate::mode::ModeOfOperation as M;
use crate::pdo::{PdoEntry, PdoMap};
use crate::shared_slice::SharedSlice;

/// Where the facts of this module come from.
pub const SOURCE: &str = "CiA 402 / ETG.6010";

/// Default RxPDO 1600h, 14 bytes (CiA 402 / ETG.6010 csp/csv/cst objects).
pub const RX_PDO_1600: PdoMap = PdoMap {
    index: 0x1600,
    entries: SharedSlice::Static(&[
        obj(0x6040, 16),      // 0  Controlword
        obj(0x6060, 8),       // 2  Modes of operation
        PdoEntry::padding(8), // 3  padding
        obj(0x607A, 32),      // 4  Target position
        obj(0x60FF, 32),      // 8  Target velocity
        obj(0x6071, 16),      // 12 Target torque
    ]),
};

/// Default TxPDO 1A00h, 20 bytes (CiA 402 / ETG.6010 csp/csv/cst objects).
pub const TX_PDO_1A00: PdoMap = PdoMap {
    index: 0x1A00,
    entries: SharedSlice::Static(&[
        obj(0x6041, 16),      // 0  Statusword
        obj(0x6061, 8),       // 2  Modes of operation display
        PdoEntry::padding(8), // 3  padding
        obj(0x6064, 32),      // 4  Position actual value
        obj(0x606C, 32),      // 8  Velocity actual value
        obj(0x6077, 16),      // 12 Torque actual value
        obj(0x60F4, 32),      // 14 Following error actual value
        obj(0x603F, 16),      // 18 Error code
    ]),
};

// 603Fh codes for a following error and for a command beyond the maximum speed: the CiA 402
// error codes.
pub use crate::error_code::{FOLLOWING_ERROR, OVERSPEED};
/// 603Fh code for lost process data and for leaving OP while the PDS is switched on: CiA 301
/// 8100h "Communication – generic". Chosen over CiA 402 8700h "Sync controller" because both
/// events are a loss of the cyclic communication, not a fault of the drive's synchronisation
/// controller; a real drive reports its own code (the runtime shows whatever 603Fh holds).
pub const COMMUNICATION: u16 = 0x8100;
/// Minimum Fault Reset hold, ms: CiA 402 needs only a rising edge of controlword bit 7; the
/// master holds it 10 ms (at least one cycle) so a drive that samples the controlword in a
/// slower task still sees it. A named default: check the real drive's manual.
pub const FAULT_RESET_HOLD_MS: u32 = 10;
/// 10F1h:02 Sync Error Counter Limit default (ETG.1020 §"Sync error counter"; the simulator's
/// counting rule).
pub const SYNC_ERROR_COUNTER_LIMIT: i64 = 4;
/// 6502h Supported drive modes: hm (bit 5), csp (bit 7), csv (bit 8), cst (bit 9).
pub const SUPPORTED_DRIVE_MODES: i64 = (1 << 5) | (1 << 7) | (1 << 8) | (1 << 9);

/// The 603Fh codes this profile raises (CiA 402 / CiA 301 error codes). CiA 402 leaves the
/// fault reaction (605Eh) and what a reset clears to the manufacturer: every code here is
/// cleared by a Fault Reset once its cause is gone.
#[rustfmt::skip]
pub const ALARMS: &[AlarmInfo] = &[
    alarm(COMMUNICATION, "8100h", "Communication (CiA 301)", AlarmKind::Alarm, StopBehaviour::Unstated, Clearing::FaultReset, "CiA 301 emergency error code 8100h; used for lost process data (10F1h:02, ETG.1020) and leaving OP (CiA 402 / ETG.6010 choice, see COMMUNICATION)"),
    alarm(OVERSPEED, "8400h", "Velocity speed controller (CiA 402)", AlarmKind::Alarm, StopBehaviour::Unstated, Clearing::FaultReset, "CiA 402 / ETG.6010 error code 8400h; reaction per 605Eh (manufacturer-specific)"),
    alarm(FOLLOWING_ERROR, "8611h", "Following error (CiA 402)", AlarmKind::Alarm, StopBehaviour::Unstated, Clearing::FaultReset, "CiA 402 / ETG.6010 error code 8611h; window 6065h, time-out 6066h"),
];

use Access::{Ro, Rw};
use DataType::{I16, I32, I8, U16, U32, U8};
use Pdo::{No, Rx as PdoRx, Tx as PdoTx};

/// The objects of the CiA 402 profile the runtime, the simulator and the mapping checks use,
/// with CiA 402's types, access and PDO mapping (the mappable ones are marked `Rx`/`Tx`; CiA
/// 402 marks most of them "optional" mappable: a real drive may map fewer).
#[rustfmt::skip]
pub const OBJECTS: &[OdEntry] = &[
    od(0x10F1, 2, "Sync Error Counter Limit", U16, Rw, No).default(SYNC_ERROR_COUNTER_LIMIT).unit(Unit::Times).cite("ETG.1020 (10F1h:02); default the simulator's, a real drive's differs"),
    od(0x1C32, 2, "Cycle time", U32, Rw, No).default(1_000_000).range(&[(125_000, 8_000_000)]).unit(Unit::Nanosecond).cite("ETG.1020 / ETG.6010 (1C32h:02); range = the cycles cellrt runs, the drive's own limits are the user's to respect"),
    od(0x603F, 0, "Error code", U16, Ro, PdoTx).default(0).cite(SOURCE),
    od(0x6040, 0, "Controlword", U16, Rw, PdoRx).default(0).cite(SOURCE),
    od(0x6041, 0, "Statusword", U16, Ro, PdoTx).cite(SOURCE),
    od(0x605A, 0, "Quick stop option code", I16, Rw, No).default(2).range(&[(0, 8)]).cite("CiA 402 / ETG.6010: default 2 (quick stop ramp, then Switch on disabled: no transition 16)"),
    od(0x605B, 0, "Shutdown option code", I16, Rw, No).default(0).range(&[(0, 1)]).cite(SOURCE),
    od(0x605C, 0, "Disable operation option code", I16, Rw, No).default(1).range(&[(0, 1)]).cite(SOURCE),
    od(0x605D, 0, "Halt option code", I16, Rw, No).default(1).range(&[(1, 4)]).cite(SOURCE),
    od(0x605E, 0, "Fault reaction option code", I16, Rw, No).default(2).range(&[(0, 4)]).cite("CiA 402 / ETG.6010: default manufacturer-specific (2 = quick stop ramp assumed)"),
    od(0x6060, 0, "Modes of operation", I8, Rw, PdoRx).default(0).cite(SOURCE),
    od(0x6061, 0, "Modes of operation display", I8, Ro, PdoTx).default(0).cite(SOURCE),
    od(0x6062, 0, "Position demand value", I32, Ro, PdoTx).unit(Unit::PosUnits).cite(SOURCE),
    od(0x6063, 0, "Position actual internal value", I32, Ro, PdoTx).unit(Unit::Increment).cite(SOURCE),
    od(0x6064, 0, "Position actual value", I32, Ro, PdoTx).unit(Unit::PosUnits).cite(SOURCE),
    od(0x6065, 0, "Following error window", U32, Rw, PdoRx).unit(Unit::PosUnits).cite(SOURCE),
    od(0x6066, 0, "Following error time out", U16, Rw, PdoRx).unit(Unit::Millisecond).cite(SOURCE),
    od(0x606B, 0, "Velocity demand value", I32, Ro, PdoTx).unit(Unit::VelUnits).cite(SOURCE),
    od(0x606C, 0, "Velocity actual value", I32, Ro, PdoTx).unit(Unit::VelUnits).cite(SOURCE),
    od(0x6071, 0, "Target torque", I16, Rw, PdoRx).default(0).unit(Unit::TenthPercentRated).cite(SOURCE),
    od(0x6072, 0, "Max torque", U16, Rw, PdoRx).unit(Unit::TenthPercentRated).cite(SOURCE),
    od(0x6074, 0, "Torque demand", I16, Ro, PdoTx).unit(Unit::TenthPercentRated).cite(SOURCE),
    od(0x6077, 0, "Torque actual value", I16, Ro, PdoTx).unit(Unit::TenthPercentRated).cite(SOURCE),
    od(0x607A, 0, "Target position", I32, Rw, PdoRx).default(0).unit(Unit::PosUnits).cite(SOURCE),
    od(0x607C, 0, "Home offset", I32, Rw, PdoRx).default(0).unit(Unit::PosUnits).cite(SOURCE),
    od(0x607D, 1, "Min position limit", I32, Rw, PdoRx).unit(Unit::PosUnits).cite(SOURCE),
    od(0x607D, 2, "Max position limit", I32, Rw, PdoRx).unit(Unit::PosUnits).cite(SOURCE),
    od(0x607F, 0, "Max profile velocity", U32, Rw, PdoRx).unit(Unit::VelUnits).cite(SOURCE),
    od(0x6080, 0, "Max motor speed", U32, Rw, PdoRx).unit(Unit::Rpm).cite(SOURCE),
    od(0x6081, 0, "Profile velocity", U32, Rw, PdoRx).unit(Unit::VelUnits).cite(SOURCE),
    od(0x6083, 0, "Profile acceleration", U32, Rw, PdoRx).unit(Unit::AccUnits).cite(SOURCE),
    od(0x6084, 0, "Profile deceleration", U32, Rw, PdoRx).unit(Unit::AccUnits).cite(SOURCE),
    od(0x6085, 0, "Quick stop deceleration", U32, Rw, PdoRx).unit(Unit::AccUnits).cite(SOURCE),
    od(0x6098, 0, "Homing method", I8, Rw, PdoRx).default(37).range(&[(-128, 127)]).cite("CiA 402 / ETG.6010: default manufacturer-specific; 37 (homing on the current position) assumed"),
    od(0x6099, 1, "Speed during search for switch", U32, Rw, PdoRx).unit(Unit::VelUnits).cite(SOURCE),
    od(0x6099, 2, "Speed during search for zero", U32, Rw, PdoRx).unit(Unit::VelUnits).cite(SOURCE),
    od(0x609A, 0, "Homing acceleration", U32, Rw, PdoRx).unit(Unit::AccUnits).cite(SOURCE),
    od(0x60B0, 0, "Position offset", I32, Rw, PdoRx).default(0).unit(Unit::PosUnits).cite(SOURCE),
    od(0x60B1, 0, "Velocity offset", I32, Rw, PdoRx).default(0).unit(Unit::VelUnits).cite(SOURCE),
    od(0x60B2, 0, "Torque offset", I16, Rw, PdoRx).default(0).unit(Unit::TenthPercentRated).cite(SOURCE),
    od(0x60B8, 0, "Touch probe function", U16, Rw, PdoRx).default(0).cite(SOURCE),
    od(0x60B9, 0, "Touch probe status", U16, Ro, PdoTx).cite(SOURCE),
    od(0x60BA, 0, "Touch probe 1 positive edge", I32, Ro, PdoTx).unit(Unit::PosUnits).cite(SOURCE),
    od(0x60BB, 0, "Touch probe 1 negative edge", I32, Ro, PdoTx).unit(Unit::PosUnits).cite(SOURCE),
    od(0x60BC, 0, "Touch probe 2 positive edge", I32, Ro, PdoTx).unit(Unit::PosUnits).cite(SOURCE),
    od(0x60BD, 0, "Touch probe 2 negative edge", I32, Ro, PdoTx).unit(Unit::PosUnits).cite(SOURCE),
    od(0x60C2, 1, "Interpolation time period value", U8, Rw, No).cite(SOURCE),
    od(0x60C2, 2, "Interpolation time index", I8, Rw, No).default(-3).cite(SOURCE),
    od(0x60E0, 0, "Positive torque limit value", U16, Rw, PdoRx).unit(Unit::TenthPercentRated).cite(SOURCE),
    od(0x60E1, 0, "Negative torque limit value", U16, Rw, PdoRx).unit(Unit::TenthPercentRated).cite(SOURCE),
    od(0x60F4, 0, "Following error actual value", I32, Ro, PdoTx).unit(Unit::PosUnits).cite(SOURCE),
    od(0x60FC, 0, "Position demand internal value", I32, Ro, PdoTx).unit(Unit::Increment).cite(SOURCE),
    od(0x60FD, 0, "Digital inputs", U32, Ro, PdoTx).cite(SOURCE),
    od(0x60FE, 1, "Digital outputs: physical outputs", U32, Rw, PdoRx).default(0).cite(SOURCE),
    od(0x60FE, 2, "Digital outputs: bit mask", U32, Rw, No).default(0).cite(SOURCE),
    od(0x60FF, 0, "Target velocity", I32, Rw, PdoRx).default(0).unit(Unit::VelUnits).cite(SOURCE),
    od(0x6502, 0, "Supported drive modes", U32, Ro, No).default(SUPPORTED_DRIVE_MODES).cite("CiA 402 / ETG.6010: bits 5 (hm), 7 (csp), 8 (csv), 9 (cst)"),
];

/// Units (CiA 402 factor group 608Fh–6092h: the drive's user units; cellrt's
/// `counts_per_unit` maps them to the axis unit).
pub const UNITS: Units = Units {
    counts_per_rev: None,
    other_counts_per_rev: &[],
    position: PositionUnit::Count,
    velocity: Stated::Unstated(VelocityUnit::CountsPerSecond),
    linear_motors: true,
    command_truncation_exp10: None,
    acceleration: Stated::Unstated(AccelerationUnit::VelocityUnitsPerSecond),
    torque: TorqueUnit::PerMilleOfRated,
    source: "CiA 402 / ETG.6010: velocity units are user-defined by the drive's factor group \
             (608Fh–6092h); default position units (counts) per second, configurable \
             (motor.velocity_unit); torque objects 0.1 % of rated torque",
};

/// Variable PDO mapping (CiA 301 / ETG.1020 / ETG.6010): mapping and assignment written in
/// PRE-OP (count to 0, entries, count last), generous limits (32 entries, 64 bytes each way),
/// the CiA 301 abort codes. A real drive may take fewer entries or bytes and answer with the
/// same codes, which bring-up reports with the object named.
pub const PDO_RULES: PdoRules = PdoRules {
    max_entries: 32,
    max_rx_bytes: 64,
    max_tx_bytes: 64,
    // Every object CiA 402 marks mappable into the RxPDO / TxPDO (also in `OBJECTS` as
    // `Pdo::Rx` / `Pdo::Tx` rows with their sub-indexes).
    rx_mappable: &[
        0x6040, 0x6060, 0x6065, 0x6066, 0x6071, 0x6072, 0x607A, 0x607C, 0x607F, 0x6080, 0x6081,
        0x6083, 0x6084, 0x6085, 0x6098, 0x609A, 0x60B0, 0x60B1, 0x60B2, 0x60B8, 0x60E0, 0x60E1,
        0x60FF,
    ],
    tx_mappable: &[
        0x603F, 0x6041, 0x6061, 0x6062, 0x6063, 0x6064, 0x606B, 0x606C, 0x6074, 0x6077, 0x60B9,
        0x60BA, 0x60BB, 0x60BC, 0x60BD, 0x60F4, 0x60FC, 0x60FD,
    ],
    // CiA 301 SDO abort codes: 0604 0041h "object cannot be mapped into the PDO", 0604 0042h
    // "number and length of the objects to be mapped would exceed PDO length", 0800 0022h
    // "data cannot be transferred because of the present device state", 0601 0002h "attempt
    // to write a read only object" (a cyclically written object).
    not_mappable_abort: 0x0604_0041,
    too_long_abort: 0x0604_0042,
    locked_abort: 0x0800_0022,
    mapped_write_abort: 0x0601_0002,
    wrong_state_abort: 0x0800_0022,
    // The drive runs on SYNC0 (ETG.6010 DC synchronous mode); no alarm is stated.
    sync_mismatch_alarms: &[],
    assignment: PdoAssignment::Writable,
    frozen_after_safe_op: false,
    source: "CiA 402 / ETG.6010 (mappable objects), CiA 301 (abort codes), ETG.1020 (assignment 1C12h/1C13h)",
};

/// The generic CiA 402 profile.
pub const PROFILE: DriveProfile = DriveProfile {
    model: DriveModel::GenericCia402,
    name: "generic CiA 402 drive",
    identity: Identity {
        vendor_id: None,
        product_code: None,
        revision: None,
        source: "CiA 402 / ETG.6010: none; the cell config gives the SubDevice's 1018h ([axes.ethercat] vendor_id, product_code)",
        maker_vendor_id: None,
        emulator_product_code: 0,
    },
    cycle: CycleFacts {
        modes: SharedSlice::Static(&[
            M::Homing,
            M::CyclicSyncPosition,
            M::CyclicSyncVelocity,
            M::CyclicSyncTorque,
        ]),
        cycle_times_us: &ALLOWED_MICROS,
        // CiA 402: halt (controlword bit 8) is defined for the profile modes and hm; the cyclic
        // synchronous modes leave it reserved.
        halt_in_cyclic_modes: false,
        csp_entry: crate::mode_switch::CspEntry::ActualPosition,
    },
    pdo: PdoFacts {
        rx: RX_PDO_1600,
        tx: TX_PDO_1A00,
        unit_limits: &[],
        rules: PDO_RULES,
    },
    quirks: FsaQuirks::STRICT,
    faults: FaultFacts {
        reset_hold_ms: FAULT_RESET_HOLD_MS,
        reset_hold_long_cycle_ms: FAULT_RESET_HOLD_MS,
        long_cycle_from_us: u32::MAX,
        alarms: ALARMS,
    },
    axes_per_unit: 1,
    units: UNITS,
    objects: OBJECTS,
    comm: CommFacts {
        check: CommCheck::SyncErrorCounter {
            alarm: COMMUNICATION,
        },
        leave_op_alarm: COMMUNICATION,
        // ETG.6010: a drive leaving OP while enabled takes its fault reaction; it is not
        // re-initialised (the PDS stays in Fault until reset).
        reinit_on_leaving_op: false,
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
        relative_degree_warning: None,
    },
    sdo_write_refusals: &[],
    homing: HomingSetup {
        // CiA 402 homing on the current position: 35 (the original number) and 37 (its
        // replacement in the current edition, first: the default `cellrt home` uses). Other
        // methods need switches or an index pulse the generic model cannot assert; a real drive
        // lists its own in its manual.
        methods: &[35, 37],
        data_set_methods: &[37, 35],
        // CiA 402: after homing the position actual value is the home position (607Ch).
        reference: HomeReference::PositionPreset,
        setting: None,
    },
    store_restore_objects: &[],
    invalid_axis_switch: None,
    profile_selector: None,
    fsoe: None,
    parameters: &super::params::GENERIC_CIA402,
};

/// What the drive answers of SDO Information.
pub const SDO_INFO: super::SdoInfoFacts = super::SdoInfoFacts {
    offered: true,
    one_value_per_entry: false,
    record_types: &[],
    source: "cellrt's choice for the generic CiA 402 drive: SDO Information offered, as most CiA 402 servo drives do (ETG.1000.6 §5.6.3; some do not: see field-notes)",
};

/// Whether alarms are also sent as CoE Emergency (payload: [`crate::profiles::facts::EMERGENCY_LAYOUT`]).
pub const EMERGENCY: super::EmergencyFacts = super::EmergencyFacts {
    sends: true,
    source: "CiA 301 §7.2.7 (a device sends EMCY on an internal error), ETG.1000.6 §5.6.2.1",
};

/// Likely causes of a refused state change by AL status code (ETG.1000.6 Table 11 meanings,
/// ETG.6010 / ETG.1020 for what a CiA 402 drive checks at PRE-OP → SAFE-OP).
pub const BRING_UP_CAUSES: &[super::BringUpCause] = &[
    super::BringUpCause {
        al_codes: &[0x0027, 0x0028, 0x0030, 0x0036],
        modes: &[],
        free_run_only: false,
        cause: "the drive needs (or rejects) SYNC0 as configured: check [axes.ethercat] distributed_clocks against the DC modes of its ESI",
        source: "ETG.1000.6 Table 11, ETG.6010 (DC synchronous mode)",
    },
    super::BringUpCause {
        al_codes: &[0x001D, 0x001E, 0x0024, 0x0025],
        modes: &[],
        free_run_only: false,
        cause: "the drive does not take the PDO mapping or assignment written in PRE-OP: check [axes.pdo] against its ESI's PDOs",
        source: "ETG.1000.6 Table 11, ETG.1020 (PDO assignment 1C12h/1C13h)",
    },
    super::BringUpCause {
        al_codes: &[0x0035],
        modes: &[],
        free_run_only: false,
        cause: "the cell's cycle time is not one the drive runs: check its minimum cycle (1C32h:05) and the cycle times of its manual",
        source: "ETG.1000.6 Table 11, ETG.1020 (1C32h SM output parameter)",
    },
];

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cycles::{CycleTime, Cycles};
    use crate::profiles::mapping::PdoDirection;

    #[test]
    fn default_maps_are_the_cia402_objects_at_aligned_offsets() {
        let rx = &PROFILE.pdo.rx;
        assert_eq!(rx.index, 0x1600);
        assert_eq!(rx.byte_len(), 14);
        for (idx, off) in [
            (0x6040, 0),
            (0x6060, 2),
            (0x607A, 4),
            (0x60FF, 8),
            (0x6071, 12),
        ] {
            assert_eq!(rx.offset_of(idx, 0), Some(off), "{idx:#06x}");
        }
        let tx = &PROFILE.pdo.tx;
        assert_eq!(tx.index, 0x1A00);
        assert_eq!(tx.byte_len(), 20);
        for (idx, off) in [
            (0x6041, 0),
            (0x6061, 2),
            (0x6064, 4),
            (0x606C, 8),
            (0x6077, 12),
            (0x60F4, 14),
            (0x603F, 18),
        ] {
            assert_eq!(tx.offset_of(idx, 0), Some(off), "{idx:#06x}");
        }
        assert!(!rx.has_counter() && !tx.has_counter());
    }

    #[test]
    fn nothing_vendor_specific() {
        assert_eq!(PROFILE.vendor_id(), None);
        assert_eq!(PROFILE.product_code(), None);
        assert_eq!(PROFILE.modes_text(), "hm, csp, csv, cst");
        assert_eq!(
            PROFILE.cycle_times_text(),
            "125, 250, 500, 1000, 2000, 4000, 8000 µs"
        );
        // Only CiA 402 / CiA 301 / ETG objects: no manufacturer area (2000h–5FFFh).
        for o in PROFILE.objects {
            assert!(!(0x2000..0x6000).contains(&o.index), "{:04X}h", o.index);
            assert!(
                o.source.contains("CiA 402 / ETG.6010") || o.source.contains("ETG.1020"),
                "{:04X}h: {}",
                o.index,
                o.source
            );
        }
        for e in PROFILE.pdo.rx.entries.iter().chain(&PROFILE.pdo.tx.entries) {
            assert!(e.is_padding() || e.index >= 0x6000, "{:04X}h", e.index);
        }
        assert_eq!(PROFILE.quirks, FsaQuirks::STRICT);
        assert_eq!(
            PROFILE.object(0x605A, 0).and_then(|o| o.default),
            Some(2),
            "no transition 16 by default"
        );
        assert_eq!(
            PROFILE.object(0x6502, 0).and_then(|o| o.default),
            Some(0x3A0)
        );
        for a in PROFILE.faults.alarms {
            assert!(PROFILE.alarm_resettable(a.code), "{a}");
        }
    }

    #[test]
    fn homing_defaults_to_the_current_position_method_37() {
        use crate::homing::choose_method;
        assert_eq!(choose_method(&PROFILE, None), Ok(37));
        assert_eq!(choose_method(&PROFILE, Some(35)), Ok(35));
        assert!(choose_method(&PROFILE, Some(1)).is_err());
        assert_eq!(PROFILE.object(0x6098, 0).and_then(|o| o.default), Some(37));
    }

    #[test]
    fn fault_reset_hold_is_the_named_default() {
        for (us, n) in [
            (125, 80),
            (250, 40),
            (500, 20),
            (1000, 10),
            (2000, 5),
            (4000, 3),
            (8000, 2),
        ] {
            let c = CycleTime::from_micros(us).unwrap();
            assert_eq!(PROFILE.fault_reset_hold(c), Cycles(n), "{us} µs");
        }
    }

    #[test]
    fn every_cia402_mappable_object_maps_and_others_are_refused() {
        for &i in PDO_RULES.rx_mappable {
            assert!(PROFILE.mappable(PdoDirection::Rx, i, 0), "{i:04X}h");
        }
        for &i in PDO_RULES.tx_mappable {
            assert!(PROFILE.mappable(PdoDirection::Tx, i, 0), "{i:04X}h");
        }
        for o in PROFILE.objects {
            match o.pdo {
                Pdo::Rx => assert!(PROFILE.mappable(PdoDirection::Rx, o.index, o.sub)),
                Pdo::Tx => assert!(PROFILE.mappable(PdoDirection::Tx, o.index, o.sub)),
                _ => {}
            }
        }
        assert!(PROFILE.mappable(PdoDirection::Rx, 0x607D, 2));
        assert!(PROFILE.mappable(PdoDirection::Rx, 0x60FE, 1));
        // Direction, SDO-only objects and manufacturer objects are refused with CiA 301's
        // 0604 0041h; a too-long mapping with 0604 0042h.
        for (dir, i) in [
            (PdoDirection::Rx, 0x6041),
            (PdoDirection::Tx, 0x6040),
            (PdoDirection::Rx, 0x605A),
            (PdoDirection::Rx, 0x2D01),
        ] {
            let e = PROFILE
                .check_mapping(dir, &[PdoEntry::object(i, 0, 16)])
                .unwrap_err();
            assert_eq!(e.abort_code(&PROFILE.pdo.rules), 0x0604_0041, "{i:04X}h");
        }
        let long = [PdoEntry::object(0x607A, 0, 32); 17];
        let e = PROFILE.check_mapping(PdoDirection::Rx, &long).unwrap_err();
        assert_eq!(e.abort_code(&PROFILE.pdo.rules), 0x0604_0042);
        PROFILE
            .check_mapping(PdoDirection::Rx, &long[..16])
            .unwrap();
    }
}
