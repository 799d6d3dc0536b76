//! Cross-field validation of a parsed configuration into a [`CellConfig`].

use std::collections::HashSet;
use std::path::Path;

use cellrt_axes::cia402::mode::ModeOfOperation;
use cellrt_axes::profiles::{profile, DriveModel};
use cellrt_axes::CycleTime;
use cellrt_trajectory::limits::{KinematicLimits, PositionRange};
use cellrt_trajectory::units::Scaling;
use strum::VariantNames;

use super::raw::{RawAxis, RawCellConfig};
use super::{
    AxisConfig, CellConfig, Compression, ConfigError, EthercatConfig, EthercatInterface, FaultKind,
    FaultReaction, InjectedFault, Injection, RecordingConfig, RtConfig, SetpointConfig,
    SimAxisConfig, TorqueLimits, TorquePercent, Transport, WatchdogConfig,
    DEFAULT_CSV_POSITION_GAIN, DEFAULT_FRAME_TIMEOUT_US, DEFAULT_TORQUE_SLOPE,
    IN_PROCESS_INTERFACE, MAX_AXES, MAX_TORQUE_PERCENT,
};
use cellrt_axes::ethercat::identity::{maker_vendor_id, ExpectedIdentity};
use cellrt_axes::ethercat::master::AmplifierSlot;

/// Checks a name used in service names and file names: 1–32 of `[A-Za-z0-9_-]`.
pub(crate) fn check_name(file: &Path, key: &str, name: &str) -> Result<(), ConfigError> {
    let ok = !name.is_empty()
        && name.len() <= 32
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
    if ok {
        Ok(())
    } else {
        Err(ConfigError::new(
            file,
            key,
            format!("'{name}' is not a valid name (1-32 characters of A-Z a-z 0-9 _ -)"),
        ))
    }
}

/// A finite number > 0.
pub(crate) fn positive(file: &Path, key: &str, v: f64) -> Result<f64, ConfigError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(ConfigError::new(
            file,
            key,
            format!("must be a finite number > 0 (got {v})"),
        ))
    }
}

pub(super) fn validate(
    file: &Path,
    text: &str,
    raw: RawCellConfig,
) -> Result<CellConfig, ConfigError> {
    check_name(file, "cell.name", &raw.cell.name)?;
    let cycle_time = CycleTime::from_micros(raw.cell.cycle_time_us)
        .map_err(|e| ConfigError::new(file, "cell.cycle_time_us", e.to_string()))?;
    let program = raw.cell.program.map(|p| {
        if p.is_absolute() {
            p
        } else {
            file.parent().unwrap_or(Path::new(".")).join(p)
        }
    });

    let rt = RtConfig {
        cpu: raw.rt.cpu,
        priority: raw.rt.priority,
        lock_memory: raw.rt.lock_memory,
        reserve_cpu: raw.rt.reserve_cpu,
    };
    if !(1..=99).contains(&rt.priority) {
        return Err(ConfigError::new(
            file,
            "rt.priority",
            format!("SCHED_FIFO priority must be 1..=99 (got {})", rt.priority),
        ));
    }
    if let Some(cpu) = rt.cpu {
        let n = std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1);
        if cpu >= n {
            return Err(ConfigError::new(
                file,
                "rt.cpu",
                format!(
                    "CPU {cpu} does not exist (this machine has CPUs 0..={})",
                    n - 1
                ),
            ));
        }
    }

    let compression = match raw.recording.compression.as_str() {
        "zstd" => Compression::Zstd,
        "lz4" => Compression::Lz4,
        "none" => Compression::None,
        other => {
            return Err(ConfigError::new(
                file,
                "recording.compression",
                format!("unknown compression '{other}' (allowed: zstd, lz4, none)"),
            ))
        }
    };
    if raw.recording.path.trim().is_empty() {
        return Err(ConfigError::new(
            file,
            "recording.path",
            "must not be empty",
        ));
    }
    if !(1..=65536).contains(&raw.recording.chunk_size_kib) {
        return Err(ConfigError::new(
            file,
            "recording.chunk_size_kib",
            format!(
                "must be 1..=65536 KiB (got {})",
                raw.recording.chunk_size_kib
            ),
        ));
    }
    let queue_seconds = positive(file, "recording.queue_seconds", raw.recording.queue_seconds)?;
    if queue_seconds > 60.0 {
        return Err(ConfigError::new(
            file,
            "recording.queue_seconds",
            format!("must be at most 60 s (got {queue_seconds})"),
        ));
    }
    if !(10..=60_000).contains(&raw.recording.flush_ms) {
        return Err(ConfigError::new(
            file,
            "recording.flush_ms",
            format!("must be 10..=60000 ms (got {})", raw.recording.flush_ms),
        ));
    }
    if let Some(mib) = raw.recording.rotate_mib {
        if !(1..=1_048_576).contains(&mib) {
            return Err(ConfigError::new(
                file,
                "recording.rotate_mib",
                format!("must be 1..=1048576 MiB (got {mib})"),
            ));
        }
    }
    if let Some(secs) = raw.recording.rotate_seconds {
        if !(secs.is_finite() && (1.0..=1e7).contains(&secs)) {
            return Err(ConfigError::new(
                file,
                "recording.rotate_seconds",
                format!("must be 1..=1e7 seconds (got {secs})"),
            ));
        }
    }
    let recording = RecordingConfig {
        enabled: raw.recording.enabled,
        path: raw.recording.path,
        compression,
        chunk_size: raw.recording.chunk_size_kib * 1024,
        queue_seconds,
        flush_ms: raw.recording.flush_ms,
        rotate_bytes: raw.recording.rotate_mib.map(|m| m * 1024 * 1024),
        rotate_seconds: raw.recording.rotate_seconds,
    };

    let lookahead = positive(file, "setpoints.lookahead_ms", raw.setpoints.lookahead_ms)? / 1e3;
    let start_delay = positive(
        file,
        "setpoints.start_delay_ms",
        raw.setpoints.start_delay_ms,
    )? / 1e3;
    if lookahead > 10.0 || start_delay > 10.0 {
        return Err(ConfigError::new(
            file,
            "setpoints",
            "lookahead_ms and start_delay_ms must be at most 10000 ms",
        ));
    }
    // The subscriber's buffer is the lookahead queue; more would overwrite unread blocks.
    let max_cycles = (crate::services::SETPOINT_BUFFER_BLOCKS - 4) * crate::setpoints::BLOCK_CYCLES;
    let cycles = (lookahead.max(start_delay) * 1e6 / f64::from(cycle_time.as_micros())).ceil();
    if cycles > max_cycles as f64 {
        return Err(ConfigError::new(
            file,
            "setpoints.lookahead_ms",
            format!(
                "{} ms is {cycles} cycles at {} µs; the setpoint buffer holds at most {max_cycles} cycles ({:.0} ms)",
                lookahead.max(start_delay) * 1e3,
                cycle_time.as_micros(),
                max_cycles as f64 * f64::from(cycle_time.as_micros()) / 1e3
            ),
        ));
    }
    let setpoints = SetpointConfig {
        lookahead,
        start_delay,
    };

    let reaction = |key: &str, v: &str| {
        FaultReaction::parse(v).ok_or_else(|| {
            ConfigError::new(
                file,
                format!("watchdogs.{key}"),
                format!("unknown reaction '{v}' (allowed: controlled_stop, quick_stop, disable)"),
            )
        })
    };
    let watchdogs = WatchdogConfig {
        max_consecutive_overruns: raw.watchdogs.max_consecutive_overruns,
        overrun_reaction: reaction("overrun_reaction", &raw.watchdogs.overrun_reaction)?,
        underrun_reaction: reaction("underrun_reaction", &raw.watchdogs.underrun_reaction)?,
        drive_fault_reaction: reaction(
            "drive_fault_reaction",
            &raw.watchdogs.drive_fault_reaction,
        )?,
        communication_reaction: reaction(
            "communication_reaction",
            &raw.watchdogs.communication_reaction,
        )?,
    };

    if raw.axes.is_empty() {
        return Err(ConfigError::new(
            file,
            "axes",
            "a cell needs at least one [[axes]] entry",
        ));
    }
    if raw.axes.len() > MAX_AXES {
        return Err(ConfigError::new(
            file,
            "axes",
            format!(
                "{} axes configured; a cell has at most {MAX_AXES}",
                raw.axes.len()
            ),
        ));
    }
    let mut seen = HashSet::new();
    let mut axes = Vec::with_capacity(raw.axes.len());
    let mut amplifiers: Vec<(String, DriveModel, Vec<u8>)> = Vec::new();
    for (i, a) in raw.axes.into_iter().enumerate() {
        let key = format!("axes[{i}]");
        let amplifier = check_amplifier(file, &key, &a, &mut amplifiers)?;
        if !seen.insert(a.name.clone()) {
            return Err(ConfigError::new(
                file,
                format!("{key}.name"),
                format!("duplicate axis name '{}'", a.name),
            ));
        }
        let mut axis = validate_axis(file, &key, cycle_time, a)?;
        axis.amplifier = amplifier;
        axes.push(axis);
    }

    let ethercat = validate_ethercat(file, raw.ethercat, &axes)?;
    let inject = validate_injections(file, cycle_time, &raw.inject, &axes, ethercat.as_ref())?;

    Ok(CellConfig {
        source: file.to_path_buf(),
        text: text.to_string(),
        name: raw.cell.name,
        cycle_time,
        program,
        rt,
        recording,
        setpoints,
        watchdogs,
        inject,
        axes,
        ethercat,
    })
}

/// `[ethercat]` against the axes' transports: one cell runs one transport, EtherCAT axes need
/// the section and the section needs EtherCAT axes.
fn validate_ethercat(
    file: &Path,
    raw: Option<super::raw::RawEthercat>,
    axes: &[AxisConfig],
) -> Result<Option<EthercatConfig>, ConfigError> {
    let ethercat_axis = axes.iter().position(|a| a.transport == Transport::Ethercat);
    let sim_axis = axes.iter().position(|a| a.transport == Transport::Sim);
    if let (Some(e), Some(s)) = (ethercat_axis, sim_axis) {
        return Err(ConfigError::new(
            file,
            format!("axes[{s}].transport"),
            format!(
                "axis '{}' uses transport 'sim' and axis '{}' uses 'ethercat'; a cell runs one transport",
                axes[s].name, axes[e].name
            ),
        ));
    }
    match (raw, ethercat_axis) {
        (None, None) => Ok(None),
        (None, Some(e)) => Err(ConfigError::new(
            file,
            format!("axes[{e}].transport"),
            format!(
                "axis '{}' uses transport 'ethercat' but the config has no [ethercat] section (interface = \"<NIC>\" or \"{IN_PROCESS_INTERFACE}\")",
                axes[e].name
            ),
        )),
        (Some(_), None) => Err(ConfigError::new(
            file,
            "ethercat",
            "[ethercat] is set but no axis has transport = \"ethercat\"",
        )),
        (Some(r), Some(_)) => {
            let interface = EthercatInterface::parse(&r.interface)
                .map_err(|e| ConfigError::new(file, "ethercat.interface", e))?;
            let us = r.frame_timeout_us.unwrap_or(DEFAULT_FRAME_TIMEOUT_US);
            if !(10..=1_000_000).contains(&us) {
                return Err(ConfigError::new(
                    file,
                    "ethercat.frame_timeout_us",
                    format!("must be 10..=1000000 µs (got {us})"),
                ));
            }
            Ok(Some(EthercatConfig {
                interface,
                frame_timeout: std::time::Duration::from_micros(u64::from(us)),
            }))
        }
    }
}

fn validate_injections(
    file: &Path,
    cycle_time: CycleTime,
    raw: &[super::raw::RawInjection],
    axes: &[AxisConfig],
    ethercat: Option<&EthercatConfig>,
) -> Result<Vec<Injection>, ConfigError> {
    let mut out = Vec::with_capacity(raw.len());
    for (i, r) in raw.iter().enumerate() {
        let key = |k: &str| format!("inject[{i}].{k}");
        if !r.at_ms.is_finite() || r.at_ms < 0.0 || r.at_ms > 86_400_000.0 {
            return Err(ConfigError::new(
                file,
                key("at_ms"),
                format!("must be 0..=86400000 ms (got {})", r.at_ms),
            ));
        }
        let cycle = (r.at_ms * 1e3 / f64::from(cycle_time.as_micros())).round() as u64;
        let duration = |max_ms: f64| -> Result<u64, ConfigError> {
            match r.duration_ms {
                Some(d) if d.is_finite() && d > 0.0 && d <= max_ms => Ok((d * 1e6) as u64),
                Some(d) => Err(ConfigError::new(
                    file,
                    key("duration_ms"),
                    format!("must be > 0 and at most {max_ms} ms (got {d})"),
                )),
                None => Err(ConfigError::new(
                    file,
                    key("duration_ms"),
                    format!("fault '{}' needs duration_ms", r.fault),
                )),
            }
        };
        let axis_named = |name: &str| {
            axes.iter().position(|a| a.name == name).ok_or_else(|| {
                ConfigError::new(file, key("axis"), format!("no axis named '{name}'"))
            })
        };
        let cycles_of = |ns: u64| (ns / cycle_time.as_nanos()).max(1) as u32;
        if r.delay_us.is_some() && r.fault.parse() != Ok(FaultKind::FrameDelay) {
            return Err(ConfigError::new(
                file,
                key("delay_us"),
                format!(
                    "only fault 'frame_delay' takes delay_us (fault is '{}')",
                    r.fault
                ),
            ));
        }
        let kind = r.fault.parse::<FaultKind>().map_err(|_| {
            ConfigError::new(
                file,
                key("fault"),
                format!(
                    "unknown fault '{}' (allowed: {})",
                    r.fault,
                    FaultKind::VARIANTS.join(", ")
                ),
            )
        })?;
        let fault = match kind {
            FaultKind::FrameDelay => {
                let delay_ns = match r.delay_us {
                    Some(d) if d.is_finite() && d > 0.0 && d <= 1_000_000.0 => (d * 1e3) as u64,
                    Some(d) => {
                        return Err(ConfigError::new(
                            file,
                            key("delay_us"),
                            format!("must be > 0 and at most 1000000 µs (got {d})"),
                        ))
                    }
                    None => {
                        return Err(ConfigError::new(
                            file,
                            key("delay_us"),
                            "fault 'frame_delay' needs delay_us",
                        ))
                    }
                };
                let cycles = cycles_of(duration(60_000.0)?);
                InjectedFault::FrameDelay { delay_ns, cycles }
            }
            FaultKind::DatagramDrop => InjectedFault::DatagramDrop {
                cycles: cycles_of(duration(60_000.0)?),
            },
            FaultKind::FrameCorruption | FaultKind::LinkLoss => {
                let axis = match r.axis.as_deref() {
                    Some(name) => axis_named(name)?,
                    None => 0,
                };
                let cycles = cycles_of(duration(60_000.0)?);
                if kind == FaultKind::LinkLoss {
                    InjectedFault::LinkLoss { axis, cycles }
                } else {
                    InjectedFault::FrameCorruption { axis, cycles }
                }
            }
            FaultKind::Stall => InjectedFault::Stall {
                ns: duration(1000.0)?,
            },
            FaultKind::PlannerStall => InjectedFault::PlannerStall {
                ns: duration(60_000.0)?,
            },
            FaultKind::RxLoss | FaultKind::CounterCorruption | FaultKind::SubdeviceStall => {
                let name = r.axis.as_deref().ok_or_else(|| {
                    ConfigError::new(file, key("axis"), format!("fault '{}' needs axis", r.fault))
                })?;
                let axis = axes.iter().position(|a| a.name == name).ok_or_else(|| {
                    ConfigError::new(file, key("axis"), format!("no axis named '{name}'"))
                })?;
                let ns = duration(60_000.0)?;
                let cycles = (ns / cycle_time.as_nanos()).max(1) as u32;
                match kind {
                    FaultKind::RxLoss => InjectedFault::RxLoss { axis, cycles },
                    FaultKind::SubdeviceStall => InjectedFault::SubdeviceStall { axis, cycles },
                    _ => InjectedFault::CounterCorruption { axis, cycles },
                }
            }
            FaultKind::DriveAlarm => {
                let name = r.axis.as_deref().ok_or_else(|| {
                    ConfigError::new(file, key("axis"), "fault 'drive_alarm' needs axis")
                })?;
                let axis = axes.iter().position(|a| a.name == name).ok_or_else(|| {
                    ConfigError::new(file, key("axis"), format!("no axis named '{name}'"))
                })?;
                let code = match r.code {
                    Some(c @ 1..=0xFFFF) => c as u16,
                    Some(c) => {
                        return Err(ConfigError::new(
                            file,
                            key("code"),
                            format!("alarm code must be 0x0001..=0xFFFF (got {c:#x})"),
                        ))
                    }
                    None => {
                        return Err(ConfigError::new(
                            file,
                            key("code"),
                            "fault 'drive_alarm' needs code",
                        ))
                    }
                };
                InjectedFault::DriveAlarm { axis, code }
            }
        };
        if fault.needs_emulated_segment() && ethercat.is_none() {
            return Err(ConfigError::new(
                file,
                key("fault"),
                format!(
                    "fault '{}' is an EtherCAT fault of the emulated segment; the cell has no EtherCAT axes",
                    r.fault
                ),
            ));
        }
        out.push(Injection { cycle, fault });
    }
    out.sort_by_key(|i| i.cycle);
    Ok(out)
}

/// `axes.amplifier` / `axes.amplifier_axis`: axes sharing an amplifier label must name the same
/// model, take distinct slots, and be no more than the model's axes per unit (W2 = 2, W3 = 3).
/// Returns the axis' amplifier and slot.
fn check_amplifier(
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

fn validate_axis(
    file: &Path,
    key: &str,
    cycle_time: CycleTime,
    a: RawAxis,
) -> Result<AxisConfig, ConfigError> {
    check_name(file, &format!("{key}.name"), &a.name)?;
    let err = |sub: &str, msg: String| ConfigError::new(file, format!("{key}.{sub}"), msg);

    let drive: DriveModel = a
        .drive
        .parse()
        .map_err(|e: cellrt_axes::profiles::ParseModelError| err("drive", e.to_string()))?;
    let profile = profile(drive);
    if !profile.supports_cycle_time(cycle_time) {
        return Err(err(
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
            return Err(err(
                "transport",
                format!("unknown transport '{other}' (available: sim, ethercat)"),
            ))
        }
    };
    // A model without a maker (the generic CiA 402 drive) has no identity to check the
    // SubDevice against: an EtherCAT axis must name it.
    if transport == Transport::Ethercat && maker_vendor_id(drive).is_none() {
        for (sub, given) in [
            ("ethercat.vendor_id", a.ethercat.vendor_id.is_some()),
            ("ethercat.product_code", a.ethercat.product_code.is_some()),
        ] {
            if !given {
                return Err(err(
                    sub,
                    format!(
                        "axis '{}': drive '{drive}' needs the SubDevice's identity: set [axes.ethercat] vendor_id and product_code (1018h:01/02, from the drive's ESI file or manual)",
                        a.name
                    ),
                ));
            }
        }
    }
    // The configured identity is the one the drive must report and the one the emulator
    // presents for it.
    let profile = profile.with_identity(a.ethercat.vendor_id, a.ethercat.product_code);
    let mut ethercat_identity = ExpectedIdentity::of_profile(profile);
    if let Some(v) = a.ethercat.vendor_id {
        ethercat_identity.vendor_id = v;
    }
    if let Some(p) = a.ethercat.product_code {
        ethercat_identity.product_code = Some(p);
    }
    let mode: ModeOfOperation = a.mode.parse().map_err(|e| err("mode", format!("{e}")))?;
    let profile = pdo_mapping(profile, mode, &a.pdo)
        .map_err(|(k, m)| err(k, format!("axis '{}': {m}", a.name)))?;
    if !profile.supports_mode(mode) {
        return Err(err(
            "mode",
            format!(
                "axis '{}': {drive} ({}) has no mode {} (allowed: {})",
                a.name,
                profile.name,
                mode.as_str(),
                profile.modes_text()
            ),
        ));
    }
    if !mode.is_cyclic() {
        return Err(err(
            "mode",
            format!(
                "axis '{}': mode {} is not a cyclic mode; the RT loop drives csp, csv and cst",
                a.name,
                mode.as_str()
            ),
        ));
    }
    let scaling =
        Scaling::new(a.counts_per_unit).map_err(|e| err("counts_per_unit", e.to_string()))?;
    let position = PositionRange {
        min: a.limits.position[0],
        max: a.limits.position[1],
    };
    position
        .validate()
        .map_err(|e| err("limits.position", e.to_string()))?;
    for (end, v) in [("min", position.min), ("max", position.max)] {
        scaling.to_counts_i32(v).map_err(|_| {
            err(
                "limits.position",
                format!(
                    "position {end} {v} {} is {} counts, outside the drive's 32-bit position range",
                    a.unit,
                    scaling.to_counts(v)
                ),
            )
        })?;
    }
    let limits = KinematicLimits {
        velocity: positive(file, &format!("{key}.limits.velocity"), a.limits.velocity)?,
        acceleration: positive(
            file,
            &format!("{key}.limits.acceleration"),
            a.limits.acceleration,
        )?,
        jerk: positive(file, &format!("{key}.limits.jerk"), a.limits.jerk)?,
    };
    let stop_deceleration = positive(
        file,
        &format!("{key}.limits.stop_deceleration"),
        a.limits.stop_deceleration.unwrap_or(limits.acceleration),
    )?;
    let stop_jerk = positive(
        file,
        &format!("{key}.limits.stop_jerk"),
        a.limits.stop_jerk.unwrap_or(limits.jerk),
    )?;
    let following_error_limit = positive(
        file,
        &format!("{key}.limits.following_error"),
        a.limits.following_error.unwrap_or(limits.velocity * 0.1),
    )?;
    let torque = match a.limits.torque {
        None if mode == ModeOfOperation::CyclicSyncTorque => {
            return Err(err(
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
                return Err(err(
                    "limits.torque",
                    format!("{t} is not a torque limit (% of rated torque, 0 < t ≤ {MAX_TORQUE_PERCENT})"),
                ));
            }
            let slope = positive(
                file,
                &format!("{key}.limits.torque_slope"),
                a.limits.torque_slope.unwrap_or(DEFAULT_TORQUE_SLOPE),
            )?;
            Some(TorqueLimits {
                max: TorquePercent(t),
                slope,
            })
        }
    };
    if torque.is_none() && a.limits.torque_slope.is_some() {
        return Err(err(
            "limits.torque_slope",
            "is set without limits.torque".to_string(),
        ));
    }
    let csv_position_gain = match a.csv_position_gain {
        None => DEFAULT_CSV_POSITION_GAIN,
        Some(g) if g.is_finite() && g >= 0.0 => g,
        Some(g) => {
            return Err(err(
                "csv_position_gain",
                format!("{g} is not a gain (1/s, finite, ≥ 0)"),
            ))
        }
    };
    let sim = SimAxisConfig {
        initial_position: a.sim.initial_position,
        position_bandwidth_hz: positive(
            file,
            &format!("{key}.sim.position_bandwidth_hz"),
            a.sim.position_bandwidth_hz,
        )?,
        velocity_bandwidth_hz: positive(
            file,
            &format!("{key}.sim.velocity_bandwidth_hz"),
            a.sim.velocity_bandwidth_hz,
        )?,
        z_phase_position: a.sim.z_phase_position,
        motor_speed_factor: a.sim.motor_speed_factor,
    };
    if !(1.0..=10.0).contains(&sim.motor_speed_factor) {
        return Err(err(
            "sim.motor_speed_factor",
            format!(
                "must be 1..=10 (the motor's speed over the axis velocity limit; got {})",
                sim.motor_speed_factor
            ),
        ));
    }
    if let Err(e) = scaling.to_counts_i32(sim.z_phase_position) {
        return Err(err("sim.z_phase_position", e.to_string()));
    }
    if !sim.initial_position.is_finite() || position.check(sim.initial_position).is_err() {
        return Err(err(
            "sim.initial_position",
            format!(
                "{} is outside the position range [{}, {}]",
                sim.initial_position, position.min, position.max
            ),
        ));
    }
    Ok(AxisConfig {
        name: a.name,
        drive,
        profile,
        transport,
        ethercat_identity,
        mode,
        unit: a.unit,
        scaling,
        position,
        limits,
        stop_deceleration,
        stop_jerk,
        following_error_limit,
        sim,
        torque,
        csv_position_gain,
        amplifier: None,
    })
}

/// The axis' profile with its `[axes.pdo]` mapping (the model's default maps where a direction
/// is not given), checked against the model's rules and against what the RT loop exchanges:
/// controlword, statusword, actual position, and the cyclic mode's target (csp 607Ah, csv
/// 60FFh, cst 6071h and 60FFh: the axis runs in csv between torque steps).
fn pdo_mapping(
    base: &'static cellrt_axes::DriveProfile,
    mode: ModeOfOperation,
    pdo: &super::raw::RawPdo,
) -> Result<&'static cellrt_axes::DriveProfile, (&'static str, String)> {
    use cellrt_axes::pdo::objects::{
        CONTROLWORD, POSITION_ACTUAL, STATUSWORD, TARGET_POSITION, TARGET_TORQUE, TARGET_VELOCITY,
    };
    use cellrt_axes::profiles::mapping::PdoDirection;
    use cellrt_axes::PdoEntry;
    if pdo.rx.is_none() && pdo.tx.is_none() {
        return Ok(base);
    }
    let entries = |words: &Option<Vec<u32>>, default: &'static [PdoEntry]| -> Vec<PdoEntry> {
        words.as_ref().map_or_else(
            || default.to_vec(),
            |w| w.iter().map(|w| PdoEntry::from_mapping_word(*w)).collect(),
        )
    };
    let rx = entries(&pdo.rx, base.rx_pdo.entries);
    let tx = entries(&pdo.tx, base.tx_pdo.entries);
    let key = |d: PdoDirection| match d {
        PdoDirection::Rx => "pdo.rx",
        PdoDirection::Tx => "pdo.tx",
    };
    let profile = base
        .with_pdo_maps(&rx, &tx)
        .map_err(|e| (key(e.direction()), e.to_string()))?;
    let mut needed_rx = vec![CONTROLWORD];
    needed_rx.extend(match mode {
        ModeOfOperation::CyclicSyncPosition => &[TARGET_POSITION][..],
        ModeOfOperation::CyclicSyncVelocity => &[TARGET_VELOCITY][..],
        ModeOfOperation::CyclicSyncTorque => &[TARGET_TORQUE, TARGET_VELOCITY][..],
        _ => &[][..],
    });
    for (direction, map, needed) in [
        (PdoDirection::Rx, &profile.rx_pdo, needed_rx),
        (
            PdoDirection::Tx,
            &profile.tx_pdo,
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
