//! `[[axes]]`: one axis' drive, transport, mode, PDO mapping, scaling and limits.

use std::path::Path;

use cellrt_cia402::mode::ModeOfOperation;
use cellrt_cia402::profiles::{profile, DriveModel};
use cellrt_cia402::{CycleTime, SharedProfile};
use cellrt_emulator::ethercat::{CycleTimeObject, EmulatedDc, SubDeviceVariant};
use cellrt_ethercat::identity::{maker_vendor_id, ExpectedIdentity};
use cellrt_ethercat::master::AmplifierSlot;
use cellrt_trajectory::limits::{KinematicLimits, PositionRange};
use cellrt_trajectory::units::Scaling;

use super::axis_key::AxisKey;
use super::check_name;
use crate::raw::RawAxis;
use crate::{
    AxisConfig, ConfigError, SimAxisConfig, TorqueLimits, TorquePercent, Transport,
    DEFAULT_CSV_POSITION_GAIN, DEFAULT_TORQUE_SLOPE, MAX_TORQUE_PERCENT,
};
use crate::{ProfileMode, ProfileObjects};

/// `axes.amplifier` / `axes.amplifier_axis`: axes sharing an amplifier label must name the same
/// model, take distinct slots, and be no more than the model's axes per unit (W2 = 2, W3 = 3).
/// Returns the axis' amplifier and slot.
pub(super) fn check_amplifier(
    file: &Path,
    key: &str,
    a: &RawAxis,
    amplifiers: &mut Vec<(String, DriveModel, Vec<u8>)>,
) -> Result<Option<AmplifierSlot>, ConfigError> {
    let Some(label) = &a.amplifier else {
        if a.amplifier_axis.is_some() {
            return Err(ConfigError::new(
                file,
                format!("{key}.amplifier_axis"),
                format!("axis '{}': amplifier_axis needs amplifier", a.name),
            ));
        }
        return Ok(None);
    };
    let Ok(model) = a.drive.parse::<DriveModel>() else {
        return Ok(None); // reported with the axis' drive key
    };
    let per_unit = profile(model).axes_per_unit;
    let err = |sub: &str, msg: String| ConfigError::new(file, format!("{key}.{sub}"), msg);
    let idx = match amplifiers.iter().position(|(l, _, _)| l == label) {
        Some(i) => i,
        None => {
            amplifiers.push((label.clone(), model, Vec::new()));
            amplifiers.len() - 1
        }
    };
    let (_, unit_model, slots) = &mut amplifiers[idx];
    if *unit_model != model {
        return Err(err(
            "amplifier",
            format!(
                "axis '{}': amplifier '{label}' is a {unit_model}, not a {model}",
                a.name
            ),
        ));
    }
    let slot = a.amplifier_axis.unwrap_or(slots.len() as u8);
    if slot >= per_unit || slots.len() >= usize::from(per_unit) {
        return Err(err(
            if a.amplifier_axis.is_some() && slot >= per_unit {
                "amplifier_axis"
            } else {
                "amplifier"
            },
            format!(
                "axis '{}': amplifier '{label}' ({model}) has {per_unit} axis slot(s) (allowed amplifier_axis 0..={})",
                a.name,
                per_unit - 1
            ),
        ));
    }
    if slots.contains(&slot) {
        return Err(err(
            "amplifier_axis",
            format!(
                "axis '{}': slot {slot} of amplifier '{label}' ({model}) is already used",
                a.name
            ),
        ));
    }
    slots.push(slot);
    Ok(Some(AmplifierSlot {
        label: label.clone(),
        slot,
    }))
}

/// The drive model of an axis, its profile and the SubDevice identity it must report.
struct AxisDrive {
    drive: DriveModel,
    profile: SharedProfile,
    transport: Transport,
    ethercat_identity: ExpectedIdentity,
    esi: Option<std::sync::Arc<cellrt_ethercat::esi::EsiDevice>>,
}

pub(super) fn validate_axis(
    file: &Path,
    key: &str,
    cycle_time: CycleTime,
    a: RawAxis,
) -> Result<AxisConfig, ConfigError> {
    check_name(file, &format!("{key}.name"), &a.name)?;
    let at = AxisKey { file, key };
    let AxisDrive {
        drive,
        profile,
        transport,
        ethercat_identity,
        esi,
    } = axis_drive(&at, &a, cycle_time)?;
    let (mode, profile) = axis_mode(&at, &a, drive, profile)?;
    if let Some(device) = &esi {
        super::esi::check(file, key, &a.name, device, &profile, mode, cycle_time)?;
    }
    let (scaling, position) = scaling_and_range(&at, &a)?;
    let limits = KinematicLimits {
        velocity: at.positive("limits.velocity", a.limits.velocity)?,
        acceleration: at.positive("limits.acceleration", a.limits.acceleration)?,
        jerk: at.positive("limits.jerk", a.limits.jerk)?,
    };
    let stop_deceleration = at.positive(
        "limits.stop_deceleration",
        a.limits.stop_deceleration.unwrap_or(limits.acceleration),
    )?;
    let stop_jerk = at.positive(
        "limits.stop_jerk",
        a.limits.stop_jerk.unwrap_or(limits.jerk),
    )?;
    let following_error_limit = at.positive(
        "limits.following_error",
        a.limits.following_error.unwrap_or(limits.velocity * 0.1),
    )?;
    let torque = torque_limits(&at, &a, mode)?;
    let ramps = super::cycle_reach::RampLimits {
        kinematic: &limits,
        stop_deceleration,
        stop_jerk,
        torque: torque.as_ref(),
    };
    super::cycle_reach::check(&at, &a.unit, cycle_time, &ramps)?;
    let csv_position_gain = match a.csv_position_gain {
        None => DEFAULT_CSV_POSITION_GAIN,
        Some(g) if g.is_finite() && g >= 0.0 => g,
        Some(g) => {
            return Err(at.err(
                "csv_position_gain",
                format!("{g} is not a gain (1/s, finite, ≥ 0)"),
            ))
        }
    };
    let mut sim = sim_axis(&at, &a, scaling, position)?;
    if let Some(group) = a.sim.mode_group.as_deref() {
        let own = group_profile(&at, "sim.mode_group", group, drive)?;
        sim.profile = (own.name != profile.name).then_some(own);
    }
    sim.switches = super::homing::switches(&at, &a, scaling)?;
    sim.homing.travel_after_dog = super::homing::travel_after_dog(&at, &a, scaling)?;
    sim.subdevice = emulated_subdevice(&at, &a, drive, cycle_time)?;
    let distributed_clocks = a.ethercat.distributed_clocks.unwrap_or(true);
    let startup_sdo = super::startup_sdo::startup_sdo(&at, &a, &profile, transport)?;
    let s = scaling.counts_per_unit();
    let drive_units = super::motor::drive_units(
        &at,
        &a,
        &profile,
        super::motor::VelocityDemand {
            mode,
            velocity_counts: limits.velocity * s,
            correction_counts: csv_position_gain * following_error_limit * s,
        },
    )?;
    let rated_speed = crate::profile_axis::rated_speed(
        ProfileMode::of(mode),
        &profile,
        a.motor.rated_speed,
        &drive_units,
    )
    .map_err(|(k, m)| at.err(k, format!("axis '{}': {m}", a.name)))?;
    let homing = super::homing::homing(&at, &a, &profile, scaling, &drive_units)?;
    let profile_objects = ProfileMode::of(mode).map(|m| ProfileObjects::of_profile(m, &profile));
    Ok(AxisConfig {
        name: a.name,
        drive,
        profile,
        transport,
        ethercat_identity,
        mode,
        profile_objects,
        rated_speed,
        unit: a.unit,
        scaling,
        position,
        limits,
        stop_deceleration,
        stop_jerk,
        following_error_limit,
        sim,
        homing,
        drive_units,
        torque,
        csv_position_gain,
        amplifier: None,
        distributed_clocks,
        startup_sdo,
        esi,
    })
}

/// `sim.cycle_time_object`, `sim.following_error_object`, `sim.distributed_clocks`: how the
/// emulated SubDevice of a generic CiA 402 axis departs from its profile (a read-only 1C32h:02
/// holds the cell's cycle). The Mitsubishi models behave as their manuals say: refused there.
fn emulated_subdevice(
    at: &AxisKey<'_>,
    a: &RawAxis,
    drive: DriveModel,
    cycle_time: CycleTime,
) -> Result<SubDeviceVariant, ConfigError> {
    let given = [
        ("sim.cycle_time_object", a.sim.cycle_time_object.is_some()),
        (
            "sim.following_error_object",
            a.sim.following_error_object.is_some(),
        ),
        ("sim.distributed_clocks", a.sim.distributed_clocks.is_some()),
    ];
    if drive != DriveModel::GenericCia402 {
        if let Some((key, _)) = given.iter().find(|(_, g)| *g) {
            return Err(at.err(
                key,
                format!("only for drive = \"cia402\" (a {drive} emulates its manual)"),
            ));
        }
    }
    let cycle_time_object = match a.sim.cycle_time_object.as_deref() {
        None | Some("read-write") => CycleTimeObject::ReadWrite,
        Some("read-only") => CycleTimeObject::ReadOnly(cycle_time.as_nanos() as u32),
        Some("absent") => CycleTimeObject::Absent,
        Some(other) => {
            return Err(at.err(
                "sim.cycle_time_object",
                format!("unknown '{other}' (available: read-write, read-only, absent)"),
            ))
        }
    };
    let distributed_clocks = match a.sim.distributed_clocks.as_deref() {
        None | Some("optional") => EmulatedDc::Optional,
        Some("required") => EmulatedDc::Required,
        Some("absent") => EmulatedDc::Absent,
        Some(other) => {
            return Err(at.err(
                "sim.distributed_clocks",
                format!("unknown '{other}' (available: optional, required, absent)"),
            ))
        }
    };
    Ok(SubDeviceVariant {
        cycle_time: cycle_time_object,
        following_error_object: a.sim.following_error_object.unwrap_or(true),
        distributed_clocks,
        sdo_response_delay_ns: sdo_response(at, a)?,
    })
}

/// `sim.sdo_response_ms`: the emulated SubDevice's SDO answer time (EtherCAT axes; 0–1000 ms).
fn sdo_response(at: &AxisKey<'_>, a: &RawAxis) -> Result<u64, ConfigError> {
    const KEY: &str = "sim.sdo_response_ms";
    let Some(ms) = a.sim.sdo_response_ms else {
        return Ok(0);
    };
    if a.transport != "ethercat" {
        return Err(at.err(
            KEY,
            "only for transport = \"ethercat\" (SDOs go over a mailbox)".into(),
        ));
    }
    if !ms.is_finite() || !(0.0..=1000.0).contains(&ms) {
        return Err(at.err(KEY, format!("{ms} is not between 0 and 1000 ms")));
    }
    Ok((ms * 1e6).round() as u64)
}

/// `drive`, `transport` and `[axes.ethercat]`: a model that runs the cell's cycle time, and the
/// identity the SubDevice must report (the configured one, else the model's).
fn axis_drive(
    at: &AxisKey<'_>,
    a: &RawAxis,
    cycle_time: CycleTime,
) -> Result<AxisDrive, ConfigError> {
    let drive: DriveModel = a
        .drive
        .parse()
        .map_err(|e: cellrt_cia402::profiles::ParseModelError| at.err("drive", e.to_string()))?;
    let profile = profile(drive);
    if !profile.supports_cycle_time(cycle_time) {
        return Err(at.err(
            "drive",
            format!(
                "axis '{}': {drive} ({}) does not support a {} µs cycle (allowed: {})",
                a.name,
                profile.name,
                cycle_time.as_micros(),
                profile.cycle_times_text()
            ),
        ));
    }
    let transport = match a.transport.as_str() {
        "sim" => Transport::Sim,
        "ethercat" => Transport::Ethercat,
        other => {
            return Err(at.err(
                "transport",
                format!("unknown transport '{other}' (available: sim, ethercat)"),
            ))
        }
    };
    let esi = super::esi::load_device(at.file, at.key, a, drive)?;
    // A model without a maker (the generic CiA 402 drive) has no identity to check the
    // SubDevice against: an EtherCAT axis must name it, or its ESI.
    if transport == Transport::Ethercat && maker_vendor_id(drive).is_none() && esi.is_none() {
        for (sub, given) in [
            ("ethercat.vendor_id", a.ethercat.vendor_id.is_some()),
            ("ethercat.product_code", a.ethercat.product_code.is_some()),
        ] {
            if !given {
                return Err(at.err(
                    sub,
                    format!(
                        "axis '{}': drive '{drive}' needs the SubDevice's identity: set esi (the drive's ESI file) or [axes.ethercat] vendor_id and product_code (1018h:01/02, from the drive's ESI file or manual)",
                        a.name
                    ),
                ));
            }
        }
    }
    // The configured identity is the one the drive must report and the one the emulator
    // presents for it.
    let profile = SharedProfile::new(match &esi {
        Some(device) => cellrt_ethercat::esi::EsiProfile::with_esi(profile, device),
        None => profile.with_identity(a.ethercat.vendor_id, a.ethercat.product_code),
    });
    let mut ethercat_identity = ExpectedIdentity::of_profile(&profile);
    if let Some(v) = a.ethercat.vendor_id {
        ethercat_identity.vendor_id = v;
    }
    if let Some(p) = a.ethercat.product_code {
        ethercat_identity.product_code = Some(p);
    }
    Ok(AxisDrive {
        drive,
        profile,
        transport,
        ethercat_identity,
        esi,
    })
}

/// `mode`, `mode_group` and `[axes.pdo]`: a cyclic (csp/csv/cst) or profile (pp/pv/tq) mode the
/// drive has in its configured mode group, with a PDO mapping that carries it.
fn axis_mode(
    at: &AxisKey<'_>,
    a: &RawAxis,
    drive: DriveModel,
    profile: SharedProfile,
) -> Result<(ModeOfOperation, SharedProfile), ConfigError> {
    let mode: ModeOfOperation = a.mode.parse().map_err(|e| at.err("mode", format!("{e}")))?;
    let profile = mode_group(at, a, drive, profile)?;
    let profile = pdo_mapping(profile, mode, &a.pdo)
        .map_err(|(k, m)| at.err(k, format!("axis '{}': {m}", a.name)))?;
    if !profile.supports_mode(mode) {
        let hint = if drive == DriveModel::MrJ4TM && ProfileMode::of(mode).is_some() {
            " (the profile modes need [Pr. PA01] ___2: mode_group = \"profile\")"
        } else {
            ""
        };
        return Err(at.err(
            "mode",
            format!(
                "axis '{}': {drive} ({}) has no mode {} (allowed: {}){hint}",
                a.name,
                profile.name,
                mode.as_str(),
                profile.modes_text()
            ),
        ));
    }
    if !mode.is_cyclic() && ProfileMode::of(mode).is_none() {
        return Err(at.err(
            "mode",
            format!(
                "axis '{}': mode {} is not an axis mode; an axis runs in csp, csv, cst (streamed) or pp, pv, tq (drive profile)",
                a.name,
                mode.as_str()
            ),
        ));
    }
    Ok((mode, profile))
}

/// `mode_group`: the MR-J4-TM [Pr. PA01] group (MR-J4-TM manual §1.1(2), §5.4.1: csp/csv/cst/hm
/// or pp/pv/tq/hm, never together); other models have no such key.
fn mode_group(
    at: &AxisKey<'_>,
    a: &RawAxis,
    drive: DriveModel,
    profile: SharedProfile,
) -> Result<SharedProfile, ConfigError> {
    match a.mode_group.as_deref() {
        None => Ok(profile),
        Some(group) => group_profile(at, "mode_group", group, drive),
    }
}

/// The MR-J4-TM profile of [Pr. PA01] group `group`, as config key `key`.
fn group_profile(
    at: &AxisKey<'_>,
    key: &str,
    group: &str,
    drive: DriveModel,
) -> Result<SharedProfile, ConfigError> {
    use cellrt_cia402::profiles::mr_j4_tm::ModeGroup;
    if drive != DriveModel::MrJ4TM {
        return Err(at.err(
            key,
            format!("only for drive = \"mr-j4-tm\" ([Pr. PA01]); a {drive} has no mode groups"),
        ));
    }
    match group {
        "cyclic" => Ok(ModeGroup::CyclicSynchronous.profile().shared()),
        "profile" => Ok(ModeGroup::Profile.profile().shared()),
        other => Err(at.err(
            key,
            format!("unknown '{other}' (available: cyclic, profile)"),
        )),
    }
}

/// `counts_per_unit` and `limits.position`: a range whose ends fit the drive's 32-bit position.
fn scaling_and_range(
    at: &AxisKey<'_>,
    a: &RawAxis,
) -> Result<(Scaling, PositionRange), ConfigError> {
    let scaling =
        Scaling::new(a.counts_per_unit).map_err(|e| at.err("counts_per_unit", e.to_string()))?;
    let position = PositionRange {
        min: a.limits.position[0],
        max: a.limits.position[1],
    };
    position
        .validate()
        .map_err(|e| at.err("limits.position", e.to_string()))?;
    for (end, v) in [("min", position.min), ("max", position.max)] {
        scaling.to_counts_i32(v).map_err(|_| {
            at.err(
                "limits.position",
                format!(
                    "position {end} {v} {} is {} counts, outside the drive's 32-bit position range",
                    a.unit,
                    scaling.to_counts(v)
                ),
            )
        })?;
    }
    Ok((scaling, position))
}

/// `limits.torque` and `limits.torque_slope`: required in cst, optional otherwise.
pub(super) fn torque_limits(
    at: &AxisKey<'_>,
    a: &RawAxis,
    mode: ModeOfOperation,
) -> Result<Option<TorqueLimits>, ConfigError> {
    let torque = match a.limits.torque {
        None if mode == ModeOfOperation::CyclicSyncTorque => {
            return Err(at.err(
                "limits.torque",
                format!(
                    "axis '{}' runs in cst and needs limits.torque (% of rated torque, 0 < t ≤ {MAX_TORQUE_PERCENT})",
                    a.name
                ),
            ))
        }
        None => None,
        Some(t) => {
            if !(t.is_finite() && t > 0.0 && t <= MAX_TORQUE_PERCENT) {
                return Err(at.err(
                    "limits.torque",
                    format!("{t} is not a torque limit (% of rated torque, 0 < t ≤ {MAX_TORQUE_PERCENT})"),
                ));
            }
            let slope = at.positive(
                "limits.torque_slope",
                a.limits.torque_slope.unwrap_or(DEFAULT_TORQUE_SLOPE),
            )?;
            Some(TorqueLimits {
                max: TorquePercent(t),
                slope,
            })
        }
    };
    if torque.is_none() && a.limits.torque_slope.is_some() {
        return Err(at.err(
            "limits.torque_slope",
            "is set without limits.torque".to_string(),
        ));
    }
    Ok(torque)
}

/// `[axes.sim]`: the simulated drive's plant, start position and Z phase.
fn sim_axis(
    at: &AxisKey<'_>,
    a: &RawAxis,
    scaling: Scaling,
    position: PositionRange,
) -> Result<SimAxisConfig, ConfigError> {
    let sim = SimAxisConfig {
        initial_position: a.sim.initial_position,
        position_bandwidth_hz: at
            .positive("sim.position_bandwidth_hz", a.sim.position_bandwidth_hz)?,
        velocity_bandwidth_hz: at
            .positive("sim.velocity_bandwidth_hz", a.sim.velocity_bandwidth_hz)?,
        z_phase_position: a.sim.z_phase_position,
        switches: Default::default(),
        homing: Default::default(),
        motor_speed_factor: a.sim.motor_speed_factor,
        subdevice: SubDeviceVariant::default(),
        profile: None,
    };
    if !(1.0..=10.0).contains(&sim.motor_speed_factor) {
        return Err(at.err(
            "sim.motor_speed_factor",
            format!(
                "must be 1..=10 (the motor's speed over the axis velocity limit; got {})",
                sim.motor_speed_factor
            ),
        ));
    }
    if let Err(e) = scaling.to_counts_i32(sim.z_phase_position) {
        return Err(at.err("sim.z_phase_position", e.to_string()));
    }
    if !sim.initial_position.is_finite() || position.check(sim.initial_position).is_err() {
        return Err(at.err(
            "sim.initial_position",
            format!(
                "{} is outside the position range [{}, {}]",
                sim.initial_position, position.min, position.max
            ),
        ));
    }
    Ok(sim)
}

/// The axis' profile with its `[axes.pdo]` mapping (the model's default maps where a direction
/// is not given), checked against the model's rules and against what the RT loop exchanges:
/// controlword, statusword, actual position, and the mode's target (csp 607Ah, csv 60FFh, cst
/// 6071h and 60FFh: the axis runs in csv between torque steps; pp 607Ah, pv 60FFh, tq 6071h).
fn pdo_mapping(
    base: SharedProfile,
    mode: ModeOfOperation,
    pdo: &crate::raw::RawPdo,
) -> Result<SharedProfile, (&'static str, String)> {
    use cellrt_cia402::pdo::objects::{
        CONTROLWORD, POSITION_ACTUAL, STATUSWORD, TARGET_POSITION, TARGET_TORQUE, TARGET_VELOCITY,
    };
    use cellrt_cia402::profiles::mapping::PdoDirection;
    use cellrt_cia402::PdoEntry;
    if pdo.rx.is_none() && pdo.tx.is_none() {
        return Ok(base);
    }
    let entries = |words: &Option<Vec<u32>>, default: &[PdoEntry]| -> Vec<PdoEntry> {
        words.as_ref().map_or_else(
            || default.to_vec(),
            |w| w.iter().map(|w| PdoEntry::from_mapping_word(*w)).collect(),
        )
    };
    let rx = entries(&pdo.rx, &base.pdo.rx.entries);
    let tx = entries(&pdo.tx, &base.pdo.tx.entries);
    let key = |d: PdoDirection| match d {
        PdoDirection::Rx => "pdo.rx",
        PdoDirection::Tx => "pdo.tx",
    };
    let profile = SharedProfile::new(
        base.with_pdo_maps(&rx, &tx)
            .map_err(|e| (key(e.direction()), e.to_string()))?,
    );
    let mut needed_rx = vec![CONTROLWORD];
    needed_rx.extend(match mode {
        ModeOfOperation::CyclicSyncPosition => &[TARGET_POSITION][..],
        ModeOfOperation::CyclicSyncVelocity => &[TARGET_VELOCITY][..],
        ModeOfOperation::CyclicSyncTorque => &[TARGET_TORQUE, TARGET_VELOCITY][..],
        _ => &[][..],
    });
    if let Some(p) = ProfileMode::of(mode) {
        needed_rx.push(p.target());
    }
    for (direction, map, needed) in [
        (PdoDirection::Rx, &profile.pdo.rx, needed_rx),
        (
            PdoDirection::Tx,
            &profile.pdo.tx,
            vec![STATUSWORD, POSITION_ACTUAL],
        ),
    ] {
        if let Some(missing) = needed.iter().find(|i| !map.maps(**i)) {
            return Err((
                key(direction),
                format!(
                    "the {} must map {missing:04X}h for mode {}",
                    direction.name(),
                    mode.as_str()
                ),
            ));
        }
    }
    Ok(profile)
}
