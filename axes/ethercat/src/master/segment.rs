//! The segment cellrt expects on the link: the axes in axis order, their places on multi-axis
//! amplifiers, and the SubDevices (stations) they make, checked against the models.

use super::error::EthercatError;
use crate::identity::ExpectedIdentity;
use cellrt_cia402::cycles::CycleTime;
use cellrt_cia402::mode::ModeOfOperation;
use cellrt_cia402::profiles::{DriveProfile, SharedProfile};

/// One axis of the segment, in axis order.
#[derive(Debug, Clone)]
pub struct SegmentDrive {
    /// The axis name (for errors).
    pub axis: String,
    /// The drive's profile.
    pub profile: SharedProfile,
    /// What its 1018h must show.
    pub identity: ExpectedIdentity,
    /// The mode written to 6060h at bring-up where 6060h is not in the RxPDO.
    pub mode: ModeOfOperation,
    /// The multi-axis amplifier this axis is a slot of; `None`: a station of its own (slot 0).
    pub amplifier: Option<AmplifierSlot>,
    /// SYNC0 from distributed clocks on this axis' SubDevice (`[axes.ethercat]
    /// distributed_clocks`); false: the SubDevice runs free (SM2-synchronous, ETG.1020).
    pub distributed_clocks: bool,
    /// What the device's ESI fixes of its PDO configuration: bring-up does not write it.
    pub fixed_pdo: crate::esi::conform::FixedPdo,
    /// SDO downloads bring-up makes in PRE-OP before the PDO configuration, in order
    /// (`[[axes.ethercat.startup_sdo]]`, a TwinCAT or IgH start-up list).
    pub startup_sdo: Vec<StartupSdo>,
}

/// One download of a start-up list: the object as given (on the axis' SubDevice), its bytes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StartupSdo {
    /// Object index.
    pub index: u16,
    /// Sub-index.
    pub sub: u8,
    /// The value, little-endian: 1, 2 or 4 bytes (an expedited download).
    pub data: Vec<u8>,
}

/// An axis' place on a multi-axis amplifier (config keys `amplifier`, `amplifier_axis`).
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct AmplifierSlot {
    /// The amplifier's label; axes with the same label are one SubDevice.
    pub label: String,
    /// The axis' slot on it (0 = axis A).
    pub slot: u8,
}

/// The segment cellrt expects on the link.
#[derive(Debug, Clone)]
pub struct SegmentConfig {
    /// The cycle time of the cell.
    pub cycle: CycleTime,
    /// The axes in axis order; the SubDevices are in line in the order of their first axis.
    pub drives: Vec<SegmentDrive>,
}

/// One SubDevice of the segment: a drive, or a multi-axis amplifier with its slots.
#[derive(Debug, Clone)]
pub struct SegmentStation {
    /// The model's profile (the unit's base profile).
    pub model: &'static DriveProfile,
    /// The amplifier label, where the axes named one.
    pub label: Option<String>,
    /// Per slot of the unit: the configured axis (index into `SegmentConfig::drives`); `None`
    /// for a slot no axis uses (its drive is configured with the model's default maps and
    /// left disabled).
    pub slots: Vec<Option<usize>>,
    /// SYNC0 from distributed clocks (every axis of a unit says the same).
    pub distributed_clocks: bool,
}

impl SegmentConfig {
    /// The SubDevices the axes make, in line order (one per amplifier label, or per unlabelled
    /// axis), with the labels, slots and models checked.
    pub fn stations(&self) -> Result<Vec<SegmentStation>, EthercatError> {
        plan_stations(self)
    }
}

impl SegmentStation {
    /// The first configured axis (identity and error messages).
    pub fn first_axis(&self) -> usize {
        self.slots.iter().flatten().copied().next().unwrap_or(0)
    }

    /// The profile slot `slot` runs: its axis' (with its mapping), or the model's default for
    /// an unused slot.
    pub(super) fn slot_profile<'a>(
        &'a self,
        config: &'a SegmentConfig,
        slot: usize,
    ) -> &'a DriveProfile {
        self.slots[slot].map_or(self.model, |a| &config.drives[a].profile)
    }
}

/// Groups the axes of `config` into SubDevices (one per amplifier label, or per unlabelled
/// axis), checking labels, slots and models.
fn plan_stations(config: &SegmentConfig) -> Result<Vec<SegmentStation>, EthercatError> {
    let mut plans: Vec<SegmentStation> = Vec::new();
    for (i, d) in config.drives.iter().enumerate() {
        let model = cellrt_cia402::profiles::profile(d.profile.model);
        let per_unit = usize::from(model.axes_per_unit);
        let amplifier_error = |what: String| EthercatError::Amplifier {
            axis: d.axis.clone(),
            what,
        };
        let Some(a) = &d.amplifier else {
            let mut slots = vec![None; per_unit];
            slots[0] = Some(i);
            plans.push(SegmentStation {
                model,
                label: None,
                slots,
                distributed_clocks: d.distributed_clocks,
            });
            continue;
        };
        let slot = usize::from(a.slot);
        if slot >= per_unit {
            return Err(amplifier_error(format!(
                "amplifier_axis {} on amplifier '{}': {} has slots 0..={}",
                a.slot,
                a.label,
                model.model,
                per_unit - 1
            )));
        }
        let plan = match plans
            .iter_mut()
            .position(|p| p.label.as_deref() == Some(a.label.as_str()))
        {
            Some(p) => &mut plans[p],
            None => {
                plans.push(SegmentStation {
                    model,
                    label: Some(a.label.clone()),
                    slots: vec![None; per_unit],
                    distributed_clocks: d.distributed_clocks,
                });
                plans.last_mut().expect("just pushed")
            }
        };
        if plan.model.model != model.model {
            return Err(amplifier_error(format!(
                "amplifier '{}' is a {}, not a {}",
                a.label, plan.model.model, model.model
            )));
        }
        if plan.distributed_clocks != d.distributed_clocks {
            return Err(amplifier_error(format!(
                "distributed_clocks differs between the axes of amplifier '{}' (one SubDevice, one setting)",
                a.label
            )));
        }
        if let Some(other) = plan.slots[slot] {
            return Err(amplifier_error(format!(
                "slot {} of amplifier '{}' is already axis '{}'",
                a.slot, a.label, config.drives[other].axis
            )));
        }
        plan.slots[slot] = Some(i);
    }
    Ok(plans)
}

/// Each axis' cycle time and mode must be ones its model runs.
pub(super) fn check_models(config: &SegmentConfig) -> Result<(), EthercatError> {
    for d in &config.drives {
        if !d.profile.supports_cycle_time(config.cycle) {
            return Err(EthercatError::CycleTime {
                axis: d.axis.clone(),
                model: d.profile.model.as_str(),
                cycle_us: config.cycle.as_micros(),
                allowed: d.profile.cycle_times_text(),
            });
        }
        if !d.profile.supports_mode(d.mode) {
            return Err(EthercatError::Mode {
                axis: d.axis.clone(),
                model: d.profile.model.as_str(),
                mode: d.mode.as_str(),
                allowed: d.profile.modes_text(),
            });
        }
    }
    Ok(())
}

/// On a multi-axis unit, the sum of its slots' PDOs must fit the unit's limit at the cycle
/// (MR-J5-G-N1 manual §2.1, §4.4, TV-7: e.g. J5W3 at 0.25 ms: 120 bytes each way).
pub(super) fn check_unit_pdo_limits(
    config: &SegmentConfig,
    plans: &[SegmentStation],
) -> Result<(), EthercatError> {
    for (position, plan) in plans.iter().enumerate() {
        if !plan.model.is_multi_axis() {
            continue;
        }
        let d = &config.drives[plan.first_axis()];
        let Some((max_rx, max_tx)) = plan.model.unit_pdo_limit(config.cycle.as_micros()) else {
            return Err(EthercatError::CycleTime {
                axis: d.axis.clone(),
                model: plan.model.model.as_str(),
                cycle_us: config.cycle.as_micros(),
                allowed: plan.model.cycle_times_text(),
            });
        };
        let (mut rx, mut tx) = (0, 0);
        for slot in 0..plan.slots.len() {
            let p = plan.slot_profile(config, slot);
            rx += p.pdo.rx.byte_len();
            tx += p.pdo.tx.byte_len();
        }
        if rx > usize::from(max_rx) || tx > usize::from(max_tx) {
            return Err(EthercatError::ProcessImage {
                position,
                axis: d.axis.clone(),
                what: format!(
                    "the axes of amplifier {} map {rx} RxPDO and {tx} TxPDO bytes; {} takes at most {max_rx} and {max_tx} at {} µs",
                    plan.label.as_deref().unwrap_or("(unlabelled)"),
                    plan.model.model,
                    config.cycle.as_micros()
                ),
            });
        }
    }
    Ok(())
}
