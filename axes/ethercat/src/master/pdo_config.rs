//! The PDO configuration in PRE-OP: mapping objects, their assignment, the mode where the RxPDO
//! does not carry it (all required), and the SM2 cycle time (best effort where SYNC0 sets it).

use super::refusal::RefusedSdo;
use super::segment::{SegmentConfig, SegmentStation};
use cellrt_cia402::pdo::objects::MODES_OF_OPERATION;
use cellrt_cia402::pdo::PdoEntry;
use cellrt_cia402::profiles::PdoAssignment;

/// 1C32h:02 SM2 cycle time.
const SM2_CYCLE_TIME: (u16, u8) = (0x1C32, 2);
/// 1C12h / 1C13h PDO assignment.
const RX_ASSIGN: u16 = 0x1C12;
const TX_ASSIGN: u16 = 0x1C13;

/// Configures station `plan` in PRE-OP: each slot's PDO mapping objects at its offset index
/// (count to 0, entries, count last; MR-J3-T04 manual §8.4.1(3), MR-J5-G-N1 manual §2.1, §4.4, §1.5), the
/// assignment 1C12h/1C13h with every slot's PDO in slot order (MR-J5-G-N1 manual §2.2, §3.1, §4.3, §4.4
/// [inferred]: one assigned PDO per axis), as far as the model lets it be written (MR-J3-T04:
/// read-only, §4.4; MR-J4-TM: the count fixed at 1, §5.1), each axis' 6060h (at its offset
/// index) where its RxPDO does not carry it, and the station's cycle time 1C32h:02 once
/// ([`set_cycle_time`]).
pub(super) async fn configure_station<S: std::ops::Deref<Target = ethercrab::SubDevice>>(
    sd: &ethercrab::SubDeviceRef<'_, S>,
    config: &SegmentConfig,
    plan: &SegmentStation,
) -> Result<CycleTimeOutcome, ethercrab::error::Error> {
    let model = plan.model;
    let at = |index: u16, slot: usize| model.axis_object(index, slot as u8).unwrap_or(index);
    // What the ESI fixes (a single-slot station: the axis' device) is left as it is.
    let fixed = plan.slots[0]
        .and_then(|a| config.drives.get(a))
        .map(|d| d.fixed_pdo)
        .unwrap_or_default();
    for (direction, assign) in [RX_ASSIGN, TX_ASSIGN].into_iter().enumerate() {
        let (mapping_fixed, assignment_fixed) = if direction == 0 {
            (fixed.rx_mapping, fixed.rx_assignment)
        } else {
            (fixed.tx_mapping, fixed.tx_assignment)
        };
        let assignment = if assignment_fixed {
            PdoAssignment::ReadOnly
        } else {
            model.pdo.rules.assignment
        };
        if assignment == PdoAssignment::Writable {
            sd.sdo_write(assign, 0, 0u8).await?;
        }
        for slot in 0..plan.slots.len() {
            let p = plan.slot_profile(config, slot);
            let map = if direction == 0 { &p.pdo.rx } else { &p.pdo.tx };
            let index = at(map.index, slot);
            if mapping_fixed {
                if assignment != PdoAssignment::ReadOnly {
                    sd.sdo_write(assign, (slot + 1) as u8, index).await?;
                }
                continue;
            }
            sd.sdo_write(index, 0, 0u8).await?;
            for (i, e) in map.entries.iter().enumerate() {
                let e = if e.is_padding() {
                    *e
                } else {
                    PdoEntry {
                        index: at(e.index, slot),
                        ..*e
                    }
                };
                sd.sdo_write(index, (i + 1) as u8, e.mapping_word()).await?;
            }
            sd.sdo_write(index, 0, map.entries.len() as u8).await?;
            if assignment != PdoAssignment::ReadOnly {
                sd.sdo_write(assign, (slot + 1) as u8, index).await?;
            }
        }
        if assignment == PdoAssignment::Writable {
            sd.sdo_write(assign, 0, plan.slots.len() as u8).await?;
        }
    }
    for (slot, axis) in plan.slots.iter().enumerate() {
        let Some(d) = axis.map(|a| &config.drives[a]) else {
            continue;
        };
        if !d.profile.pdo.rx.maps(MODES_OF_OPERATION) {
            sd.sdo_write(at(MODES_OF_OPERATION, slot), 0, d.mode.as_i8())
                .await?;
        }
    }
    if model.object(SM2_CYCLE_TIME.0, SM2_CYCLE_TIME.1).is_none() {
        return Ok(CycleTimeOutcome::NotAnObject);
    }
    set_cycle_time(sd, config.cycle.as_nanos() as u32).await
}

/// What became of 1C32h:02 at a station.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum CycleTimeOutcome {
    /// The model has no 1C32h:02 in its profile: not touched.
    NotAnObject,
    /// It already held the cycle (read-only or not: nothing to write).
    Matches,
    /// Written.
    Written,
    /// The drive does not have it or does not let it be written (an abort of
    /// [`super::refusal::OPTIONAL_OBJECT_ABORTS`]); the value read first, where it could be.
    Refused {
        /// The value read.
        read: Option<u32>,
        /// The refused SDO.
        sdo: RefusedSdo,
    },
}

/// 1C32h:02 read first (ETG.1020: some drives declare it read-only); written only where it
/// differs. An absent or read-only object is [`CycleTimeOutcome::Refused`], for bring-up to
/// accept where SYNC0 sets the cycle; any other abort is an error.
async fn set_cycle_time<S: std::ops::Deref<Target = ethercrab::SubDevice>>(
    sd: &ethercrab::SubDeviceRef<'_, S>,
    wanted_ns: u32,
) -> Result<CycleTimeOutcome, ethercrab::error::Error> {
    let (index, sub) = SM2_CYCLE_TIME;
    let read = sd.sdo_read::<u32>(index, sub).await;
    let error = match read {
        Ok(v) if v == wanted_ns => return Ok(CycleTimeOutcome::Matches),
        Ok(_) => match sd.sdo_write(index, sub, wanted_ns).await {
            Ok(()) => return Ok(CycleTimeOutcome::Written),
            Err(e) => e,
        },
        Err(e) => e,
    };
    match RefusedSdo::of(&error).filter(RefusedSdo::is_optional_object_abort) {
        Some(sdo) => Ok(CycleTimeOutcome::Refused {
            read: read.ok(),
            sdo,
        }),
        None => Err(error),
    }
}
