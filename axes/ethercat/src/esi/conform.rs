//! What an ESI forbids a cell configuration: the checks made before the bus is touched, each
//! naming what the configuration would have to change.

use super::device::{EsiDevice, EsiPdo};
use cellrt_cia402::mode::ModeOfOperation;
use cellrt_cia402::pdo::{PdoEntry, PdoMap};
use cellrt_cia402::profiles::mapping::PdoDirection;
use cellrt_cia402::profiles::{Access, DriveProfile};

/// 1C32h:05 Minimum cycle time (ETG.1020 SM synchronisation), ns.
const MIN_CYCLE_TIME: (u16, u8) = (0x1C32, 5);

/// The part of the configuration an [`EsiConflict`] is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ConflictSubject {
    /// The device itself (no CoE, not a drive).
    Device,
    /// The axis' mode of operation (or homing).
    Mode,
    /// The RxPDO mapping or assignment.
    RxPdo,
    /// The TxPDO mapping or assignment.
    TxPdo,
    /// The cell's cycle time.
    CycleTime,
    /// An object the master writes at bring-up.
    Object,
}

/// Something the configuration asks that the ESI forbids.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct EsiConflict {
    /// What it is about.
    pub subject: ConflictSubject,
    /// Why, naming the objects and the ESI's facts.
    pub message: String,
}

/// What the master will do with the device: the profile it runs (PDO maps after any
/// `[axes.pdo]` remap), the modes it uses, the cycle and the objects it writes at bring-up.
#[derive(Debug, Clone, Copy)]
pub struct Intent<'a> {
    /// The profile the axis runs.
    pub profile: &'a DriveProfile,
    /// The modes of operation the axis will ask for.
    pub modes: &'a [ModeOfOperation],
    /// The bus (and SYNC0) cycle, ns.
    pub cycle_ns: u32,
    /// Objects the master writes in PRE-OP besides the PDO mapping and assignment, which
    /// must exist and be writable (optional ones, such as 1C32h:02, are not listed).
    pub writes: &'a [(u16, u8)],
}

fn conflict(subject: ConflictSubject, message: String) -> Result<(), EsiConflict> {
    Err(EsiConflict { subject, message })
}

/// Checks `intent` against `device`; the first thing the ESI forbids.
pub fn check(device: &EsiDevice, intent: &Intent<'_>) -> Result<(), EsiConflict> {
    if !device.offers(super::MailboxProtocol::CoE) {
        return conflict(
            ConflictSubject::Device,
            format!(
                "{}: the ESI offers no CoE mailbox; a CiA 402 drive is configured by CoE SDO",
                device.type_name
            ),
        );
    }
    modes(device, intent)?;
    for direction in [PdoDirection::Rx, PdoDirection::Tx] {
        pdo(device, intent.profile, direction)?;
    }
    cycle(device, intent.cycle_ns)?;
    for &(index, sub) in intent.writes {
        match device.object(index, sub) {
            None if device.has_dictionary() => {
                return conflict(
                    ConflictSubject::Object,
                    format!("the master writes {index:04X}h:{sub:02X} at bring-up; the ESI's object dictionary has no such entry"),
                )
            }
            Some(o) if o.access == Access::Ro => {
                return conflict(
                    ConflictSubject::Object,
                    format!("the master writes {index:04X}h:{sub:02X} ({}) at bring-up; the ESI marks it read-only", o.name),
                )
            }
            _ => {}
        }
    }
    Ok(())
}

fn modes(device: &EsiDevice, intent: &Intent<'_>) -> Result<(), EsiConflict> {
    let Some(supported) = device.supported_modes() else {
        return Ok(());
    };
    if let Some(m) = intent.modes.iter().find(|m| !supported.contains(m)) {
        let v: Vec<&str> = supported.iter().map(|m| m.as_str()).collect();
        return conflict(
            ConflictSubject::Mode,
            format!(
                "mode {} is not among the drive's supported modes (6502h default in the ESI: {})",
                m.as_str(),
                if v.is_empty() {
                    "none".to_owned()
                } else {
                    v.join(", ")
                }
            ),
        );
    }
    Ok(())
}

fn entries_text(entries: &[PdoEntry]) -> String {
    let v: Vec<String> = entries
        .iter()
        .map(|e| format!("{:04X}h:{:02X}/{}", e.index, e.sub, e.bits))
        .collect();
    v.join(", ")
}

/// The mapping `profile` runs in `direction` against the ESI's PDOs and dictionary.
fn pdo(
    device: &EsiDevice,
    profile: &DriveProfile,
    direction: PdoDirection,
) -> Result<(), EsiConflict> {
    let (subject, map, esi_pdos, assign): (_, &PdoMap, _, u16) = match direction {
        PdoDirection::Rx => (
            ConflictSubject::RxPdo,
            &profile.pdo.rx,
            &device.rx_pdos,
            0x1C12,
        ),
        PdoDirection::Tx => (
            ConflictSubject::TxPdo,
            &profile.pdo.tx,
            &device.tx_pdos,
            0x1C13,
        ),
    };
    mapping(device, subject, direction, map, esi_pdos)?;
    assignment(device, subject, direction, map, esi_pdos, assign)?;
    mapped_entries(device, subject, direction, map)
}

/// The PDO `map` against the ESI's PDOs of its direction: it exists, and a PDO the ESI fixes
/// maps what the configuration needs.
fn mapping(
    device: &EsiDevice,
    subject: ConflictSubject,
    direction: PdoDirection,
    map: &PdoMap,
    esi_pdos: &[EsiPdo],
) -> Result<(), EsiConflict> {
    let name = direction.name();
    let listed = || {
        let v: Vec<String> = esi_pdos
            .iter()
            .map(|p| format!("{:04X}h", p.index))
            .collect();
        v.join(", ")
    };
    let esi_pdo = esi_pdos.iter().find(|p| p.index == map.index);
    if esi_pdo.is_none() && !esi_pdos.is_empty() {
        return conflict(
            subject,
            format!(
                "the {name} is mapped in {:04X}h; the ESI has no such PDO (it has {})",
                map.index,
                listed()
            ),
        );
    }
    if let Some(p) = esi_pdo {
        let mapping_ro = device
            .object(map.index, 0)
            .is_some_and(|o| o.access == Access::Ro);
        let not_configurable = device.coe.is_some_and(|c| !c.pdo_config);
        if (p.fixed || mapping_ro || not_configurable) && p.entries[..] != map.entries[..] {
            return conflict(
                subject,
                format!(
                    "{:04X}h is fixed in the ESI ({}) with {}; the configuration maps {}",
                    map.index,
                    if p.fixed {
                        "Fixed"
                    } else if mapping_ro {
                        "mapping object read-only"
                    } else {
                        "CoE PdoConfig false"
                    },
                    entries_text(&p.entries),
                    entries_text(&map.entries)
                ),
            );
        }
    }
    Ok(())
}

/// The PDO assignment (`assign`, 1C12h/1C13h): no other PDO the ESI makes mandatory, and an
/// assignment the ESI fixes assigns `map`.
fn assignment(
    device: &EsiDevice,
    subject: ConflictSubject,
    direction: PdoDirection,
    map: &PdoMap,
    esi_pdos: &[EsiPdo],
    assign: u16,
) -> Result<(), EsiConflict> {
    let name = direction.name();
    if let Some(m) = esi_pdos
        .iter()
        .find(|p| p.mandatory && p.index != map.index)
    {
        return conflict(
            subject,
            format!(
                "the ESI makes {name} {:04X}h mandatory; the configuration assigns only {:04X}h",
                m.index, map.index
            ),
        );
    }
    let assign_fixed = device.coe.is_some_and(|c| !c.pdo_assign)
        || device
            .object(assign, 1)
            .is_some_and(|o| o.access == Access::Ro);
    let default_assigned = device
        .object(assign, 1)
        .and_then(|o| o.default)
        .map(|v| v as u16)
        .or_else(|| esi_pdos.iter().find(|p| p.sm.is_some()).map(|p| p.index));
    if let Some(d) = default_assigned.filter(|d| assign_fixed && *d != map.index) {
        return conflict(
            subject,
            format!("the ESI's PDO assignment {assign:04X}h cannot be changed and assigns {d:04X}h; the configuration needs {:04X}h", map.index),
        );
    }
    Ok(())
}

/// Each object `map` maps exists in the ESI's dictionary (where it has one) and may be mapped
/// in `direction`.
fn mapped_entries(
    device: &EsiDevice,
    subject: ConflictSubject,
    direction: PdoDirection,
    map: &PdoMap,
) -> Result<(), EsiConflict> {
    let name = direction.name();
    for e in map.entries.iter().filter(|e| !e.is_padding()) {
        let Some(o) = device.object(e.index, e.sub) else {
            if device.has_dictionary() {
                return conflict(
                    subject,
                    format!("the {name} maps {:04X}h:{:02X}; the ESI's object dictionary has no such object", e.index, e.sub),
                );
            }
            continue;
        };
        let ok = match direction {
            PdoDirection::Rx => o.pdo.rx,
            PdoDirection::Tx => o.pdo.tx,
        };
        if !ok {
            return conflict(
                subject,
                format!(
                    "the {name} maps {:04X}h:{:02X} ({}); the ESI marks it not mappable into the {name} (PdoMapping {})",
                    e.index,
                    e.sub,
                    o.name,
                    match (o.pdo.rx, o.pdo.tx) {
                        (false, false) => "none",
                        (true, _) => "R",
                        (_, true) => "T",
                    }
                ),
            );
        }
    }
    Ok(())
}

/// The cycle against the DC opmodes that run SYNC0 and 1C32h:05.
fn cycle(device: &EsiDevice, cycle_ns: u32) -> Result<(), EsiConflict> {
    let sync0: Vec<_> = device
        .dc_opmodes
        .iter()
        .filter(|m| m.uses_sync0())
        .collect();
    if !sync0.is_empty() && !sync0.iter().any(|m| m.allows_cycle(cycle_ns)) {
        let v: Vec<String> = sync0
            .iter()
            .map(|m| format!("{} ({} ns)", m.name, m.sync0.map_or(0, |c| c.ns)))
            .collect();
        return conflict(
            ConflictSubject::CycleTime,
            format!(
                "a {cycle_ns} ns cycle is not allowed by the ESI's SYNC0 opmodes: {}",
                v.join(", ")
            ),
        );
    }
    if let Some(min) = device
        .object(MIN_CYCLE_TIME.0, MIN_CYCLE_TIME.1)
        .and_then(|o| o.default)
    {
        if i64::from(cycle_ns) < min {
            return conflict(
                ConflictSubject::CycleTime,
                format!("a {cycle_ns} ns cycle is below the ESI's minimum cycle time (1C32h:05 = {min} ns)"),
            );
        }
    }
    Ok(())
}

/// The parts of a device's PDO configuration its ESI does not let the master write: each
/// direction's mapping (`Fixed`, a read-only mapping object, or CoE `PdoConfig` false) and the
/// assignment 1C12h/1C13h (CoE `PdoAssign` false, or a read-only sub 1). Bring-up leaves these
/// as the device has them ([`check`] made sure they are what the configuration runs).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct FixedPdo {
    /// The RxPDO mapping object.
    pub rx_mapping: bool,
    /// The TxPDO mapping object.
    pub tx_mapping: bool,
    /// The RxPDO assignment 1C12h.
    pub rx_assignment: bool,
    /// The TxPDO assignment 1C13h.
    pub tx_assignment: bool,
}

impl FixedPdo {
    /// What `device` fixes of the mappings `rx_index` / `tx_index` and their assignments.
    pub fn of(device: &EsiDevice, rx_index: u16, tx_index: u16) -> FixedPdo {
        let mapping = |pdos: &[crate::esi::EsiPdo], index: u16| {
            let fixed = pdos.iter().any(|p| p.index == index && p.fixed);
            let ro = device
                .object(index, 0)
                .is_some_and(|o| o.access == Access::Ro);
            fixed || ro || device.coe.is_some_and(|c| !c.pdo_config)
        };
        let assignment = |assign: u16| {
            device.coe.is_some_and(|c| !c.pdo_assign)
                || device
                    .object(assign, 1)
                    .is_some_and(|o| o.access == Access::Ro)
        };
        FixedPdo {
            rx_mapping: mapping(&device.rx_pdos, rx_index),
            tx_mapping: mapping(&device.tx_pdos, tx_index),
            rx_assignment: assignment(0x1C12),
            tx_assignment: assignment(0x1C13),
        }
    }
}
