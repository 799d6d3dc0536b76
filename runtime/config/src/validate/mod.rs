//! Cross-field validation of a parsed configuration into a [`CellConfig`].

use std::collections::HashSet;
use std::path::Path;

use cellrt_cia402::comm::{DetectorParams, MAX_INTERMITTENT};
use cellrt_cia402::profiles::DriveModel;
use cellrt_cia402::{CycleTime, Cycles};

use super::je_c_axis::{self, JecAxisConfig};
use super::raw::{RawAxis, RawCellConfig, RawRecording, RawRt, RawSetpoints, RawWatchdogs};
use super::{
    AxisConfig, CellConfig, CommWatchdogConfig, Compression, ConfigError, EthercatConfig,
    EthercatInterface, FaultReaction, MissedDeadlines, RecordingConfig, RtConfig, SetpointConfig,
    Transport, WatchdogConfig, DEFAULT_FRAME_TIMEOUT_US, IN_PROCESS_INTERFACE, MAX_AXES,
};
use crate::CellAxes;

mod axis;
mod axis_key;
mod cycle_reach;
mod esi;
mod homing;
mod inject;
mod motor;
mod operator;
mod startup_sdo;
use axis::{check_amplifier, validate_axis};
use inject::validate_injections;

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
            format!(
                "'{}' is not a valid name (1-32 characters of A-Z a-z 0-9 _ -)",
                crate::echo::Echo(name)
            ),
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

/// Checks every section of `raw` (read from `file`, whose `text` the config keeps) and builds
/// the cell configuration.
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

    let rt = rt_config(file, &raw.rt)?;
    let capture_raw = (
        raw.recording.mode.clone(),
        raw.recording.pre_s,
        raw.recording.post_s,
        raw.recording.triggers.clone(),
    );
    let mut recording = recording_config(file, raw.recording)?;
    let setpoints = setpoint_config(file, &raw.setpoints, cycle_time)?;
    let watchdogs = watchdog_config(file, &raw.watchdogs)?;
    let operator = operator::operator_config(file, &raw.operator)?;
    let (live, live_page) = crate::live::live_config(file, &raw.live)?;
    let axes = validate_axes(file, cycle_time, raw.axes, watchdogs.communication_reaction)?;
    let (mode, pre_s, post_s, triggers) = capture_raw;
    recording.capture =
        crate::capture::capture_config(file, &mode, pre_s, post_s, &triggers, axes.on_loop())?;

    let ethercat = validate_ethercat(file, raw.ethercat, axes.on_loop())?;
    let inject = validate_injections(
        file,
        cycle_time,
        &raw.inject,
        axes.on_loop(),
        ethercat.as_ref(),
    )?;

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
        operator,
        live,
        live_page,
        inject,
        axes,
        ethercat,
    })
}

/// `[rt]`: the RT thread's CPU and SCHED_FIFO priority.
fn rt_config(file: &Path, raw: &RawRt) -> Result<RtConfig, ConfigError> {
    let rt = RtConfig {
        cpu: raw.cpu,
        priority: raw.priority,
        planner_priority: (raw.planner_priority != 0).then_some(raw.planner_priority),
        lock_memory: raw.lock_memory,
        reserve_cpu: raw.reserve_cpu,
        missed_deadlines: MissedDeadlines::parse(&raw.missed_deadlines).ok_or_else(|| {
            ConfigError::new(
                file,
                "rt.missed_deadlines",
                format!(
                    "must be one of {} (got \"{}\")",
                    MissedDeadlines::NAMES,
                    raw.missed_deadlines
                ),
            )
        })?,
    };
    if !(1..=99).contains(&rt.priority) {
        return Err(ConfigError::new(
            file,
            "rt.priority",
            format!("SCHED_FIFO priority must be 1..=99 (got {})", rt.priority),
        ));
    }
    if raw.planner_priority >= rt.priority {
        return Err(ConfigError::new(
            file,
            "rt.planner_priority",
            format!(
                "the planner thread's SCHED_FIFO priority must be below the RT thread's ({}), or 0 for SCHED_OTHER (got {})",
                rt.priority, raw.planner_priority
            ),
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
    Ok(rt)
}

/// `[recording]`: compression, chunk size, queue, flush and rotation of the MCAP recording.
fn recording_config(file: &Path, raw: RawRecording) -> Result<RecordingConfig, ConfigError> {
    let compression = match raw.compression.as_str() {
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
    if raw.path.trim().is_empty() {
        return Err(ConfigError::new(
            file,
            "recording.path",
            "must not be empty",
        ));
    }
    if !(1..=65536).contains(&raw.chunk_size_kib) {
        return Err(ConfigError::new(
            file,
            "recording.chunk_size_kib",
            format!("must be 1..=65536 KiB (got {})", raw.chunk_size_kib),
        ));
    }
    let queue_seconds = positive(file, "recording.queue_seconds", raw.queue_seconds)?;
    if queue_seconds > 60.0 {
        return Err(ConfigError::new(
            file,
            "recording.queue_seconds",
            format!("must be at most 60 s (got {queue_seconds})"),
        ));
    }
    if !(10..=60_000).contains(&raw.flush_ms) {
        return Err(ConfigError::new(
            file,
            "recording.flush_ms",
            format!("must be 10..=60000 ms (got {})", raw.flush_ms),
        ));
    }
    if let Some(mib) = raw.rotate_mib {
        if !(1..=1_048_576).contains(&mib) {
            return Err(ConfigError::new(
                file,
                "recording.rotate_mib",
                format!("must be 1..=1048576 MiB (got {mib})"),
            ));
        }
    }
    if let Some(secs) = raw.rotate_seconds {
        if !(secs.is_finite() && (1.0..=1e7).contains(&secs)) {
            return Err(ConfigError::new(
                file,
                "recording.rotate_seconds",
                format!("must be 1..=1e7 seconds (got {secs})"),
            ));
        }
    }
    Ok(RecordingConfig {
        enabled: raw.enabled,
        path: raw.path,
        compression,
        chunk_size: raw.chunk_size_kib * 1024,
        queue_seconds,
        flush_ms: raw.flush_ms,
        rotate_bytes: raw.rotate_mib.map(|m| m * 1024 * 1024),
        rotate_seconds: raw.rotate_seconds,
        capture: None,
    })
}

/// `[setpoints]`: lookahead and start delay, within what the setpoint buffer holds at this
/// cycle time.
fn setpoint_config(
    file: &Path,
    raw: &RawSetpoints,
    cycle_time: CycleTime,
) -> Result<SetpointConfig, ConfigError> {
    let lookahead = positive(file, "setpoints.lookahead_ms", raw.lookahead_ms)? / 1e3;
    let start_delay = positive(file, "setpoints.start_delay_ms", raw.start_delay_ms)? / 1e3;
    if lookahead > 10.0 || start_delay > 10.0 {
        return Err(ConfigError::new(
            file,
            "setpoints",
            "lookahead_ms and start_delay_ms must be at most 10000 ms",
        ));
    }
    // The subscriber's buffer is the lookahead queue; more would overwrite unread blocks.
    let max_cycles = (crate::SETPOINT_BUFFER_BLOCKS - 4) * crate::BLOCK_CYCLES;
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
    let max_start_slip = start_slip(file, raw, cycles, max_cycles, cycle_time)?;
    Ok(SetpointConfig {
        lookahead,
        start_delay,
        max_start_slip,
    })
}

/// How late a first block may start (`setpoints.max_start_slip_ms`): the blocks published
/// meanwhile wait in the setpoint buffer, so the slip and the lookahead share its room.
fn start_slip(
    file: &Path,
    raw: &RawSetpoints,
    lookahead_cycles: f64,
    max_cycles: usize,
    cycle_time: CycleTime,
) -> Result<Cycles, ConfigError> {
    const DEFAULT_MS: f64 = 100.0;
    let us = f64::from(cycle_time.as_micros());
    let room = max_cycles as f64 - lookahead_cycles;
    let cycles = match raw.max_start_slip_ms {
        None => (DEFAULT_MS * 1e3 / us).ceil().min(room),
        Some(ms) if !ms.is_finite() || ms < 0.0 => {
            return Err(ConfigError::new(
                file,
                "setpoints.max_start_slip_ms",
                format!("{ms} is not a duration of 0 ms or more"),
            ))
        }
        Some(ms) => {
            let cycles = (ms * 1e3 / us).ceil();
            if cycles > room {
                return Err(ConfigError::new(
                    file,
                    "setpoints.max_start_slip_ms",
                    format!(
                        "{ms} ms is {cycles} cycles; with the lookahead the setpoint buffer has room for {room} more cycles ({:.0} ms)",
                        room * us / 1e3
                    ),
                ));
            }
            cycles
        }
    };
    Ok(Cycles(cycles as u32))
}

/// `[watchdogs]`: the fault reaction of each watchdog.
fn watchdog_config(file: &Path, raw: &RawWatchdogs) -> Result<WatchdogConfig, ConfigError> {
    let reaction = |key: &str, v: &str| {
        FaultReaction::parse(v).ok_or_else(|| {
            ConfigError::new(
                file,
                format!("watchdogs.{key}"),
                format!("unknown reaction '{v}' (allowed: controlled_stop, quick_stop, disable)"),
            )
        })
    };
    Ok(WatchdogConfig {
        max_consecutive_overruns: raw.max_consecutive_overruns,
        overrun_reaction: reaction("overrun_reaction", &raw.overrun_reaction)?,
        underrun_reaction: reaction("underrun_reaction", &raw.underrun_reaction)?,
        drive_fault_reaction: reaction("drive_fault_reaction", &raw.drive_fault_reaction)?,
        communication_reaction: reaction("communication_reaction", &raw.communication_reaction)?,
        comm: CommWatchdogConfig {
            max_lost_frames: raw.max_lost_frames,
            max_working_counter_errors: raw.max_working_counter_errors,
            max_cycles_out_of_op: raw.max_cycles_out_of_op,
            counter: counter_levels(file, raw)?,
        },
    })
}

/// `watchdogs.counter_*`: all three or none (then each model's own levels).
fn counter_levels(file: &Path, raw: &RawWatchdogs) -> Result<Option<DetectorParams>, ConfigError> {
    let set = [
        ("counter_continuous_errors", raw.counter_continuous_errors),
        (
            "counter_intermittent_errors",
            raw.counter_intermittent_errors,
        ),
        (
            "counter_intermittent_window",
            raw.counter_intermittent_window,
        ),
    ];
    if set.iter().all(|(_, v)| v.is_none()) {
        return Ok(None);
    }
    if let Some((key, _)) = set.iter().find(|(_, v)| v.is_none()) {
        return Err(ConfigError::new(
            file,
            format!("watchdogs.{key}"),
            "missing: the counter_* levels are set all three together (or none: each model's own)",
        ));
    }
    let [continuous, intermittent, window] = set.map(|(_, v)| v.unwrap_or(0));
    let max = u32::from(MAX_INTERMITTENT);
    let intermittent = u8::try_from(intermittent)
        .ok()
        .filter(|&n| u32::from(n) <= max)
        .ok_or_else(|| {
            ConfigError::new(
                file,
                "watchdogs.counter_intermittent_errors",
                format!("{intermittent} is above the largest supported level {max}"),
            )
        })?;
    if intermittent > 0 && window == 0 {
        return Err(ConfigError::new(
            file,
            "watchdogs.counter_intermittent_window",
            "must be at least 1 cycle while counter_intermittent_errors is on",
        ));
    }
    Ok(Some(DetectorParams {
        continuous,
        intermittent,
        intermittent_window: window,
    }))
}

/// `[[axes]]`: at least one, at most [`MAX_AXES`] on the RT loop, unique names, amplifier
/// slots shared consistently; each axis on the backend its drive takes.
fn validate_axes(
    file: &Path,
    cycle_time: CycleTime,
    raw: Vec<RawAxis>,
    communication_reaction: crate::FaultReaction,
) -> Result<CellAxes, ConfigError> {
    if raw.is_empty() {
        return Err(ConfigError::new(
            file,
            "axes",
            "a cell needs at least one [[axes]] entry",
        ));
    }
    let on_loop = raw.iter().filter(|a| a.drive != je_c_axis::DRIVE).count();
    if on_loop > MAX_AXES {
        return Err(ConfigError::new(
            file,
            "axes",
            format!("{on_loop} axes on the RT loop; a cell has at most {MAX_AXES}"),
        ));
    }
    let mut seen = HashSet::new();
    let mut axes = CellAxes::default();
    let mut amplifiers: Vec<(String, DriveModel, Vec<u8>)> = Vec::new();
    for (i, a) in raw.into_iter().enumerate() {
        let key = format!("axes[{i}]");
        if a.drive == je_c_axis::DRIVE {
            if !seen.insert(a.name.clone()) {
                return Err(duplicate(file, &key, &a.name));
            }
            check_name(file, &format!("{key}.name"), &a.name)?;
            axes.push_link(link_axis(file, &key, &a, communication_reaction)?);
            continue;
        }
        let amplifier = check_amplifier(file, &key, &a, &mut amplifiers)?;
        if !seen.insert(a.name.clone()) {
            return Err(duplicate(file, &key, &a.name));
        }
        if a.je_c.is_some() {
            return Err(ConfigError::new(
                file,
                format!("{key}.je_c"),
                format!(
                    "axis '{}': [axes.je_c] is for drive = \"{}\" only",
                    a.name,
                    je_c_axis::DRIVE
                ),
            ));
        }
        let mut axis = validate_axis(file, &key, cycle_time, a)?;
        axis.amplifier = amplifier;
        axes.push_loop(axis);
    }
    Ok(axes)
}

/// An `[[axes]]` entry with `drive = "mr-je-c"`: driven over its link, with its torque limits.
fn link_axis(
    file: &Path,
    key: &str,
    a: &RawAxis,
    communication_reaction: crate::FaultReaction,
) -> Result<JecAxisConfig, ConfigError> {
    let mut j = je_c_axis::validate(file, key, a, communication_reaction)?;
    let at = axis_key::AxisKey { file, key };
    j.torque = axis::torque_limits(&at, a, cellrt_cia402::mode::ModeOfOperation::ProfileTorque)?;
    if j.mode == je_c_axis::JecMode::Tq && j.torque.is_none() {
        return Err(at.err(
            "limits.torque",
            format!(
                "axis '{}' runs in tq and needs limits.torque (% of rated torque, 0 < t ≤ {})",
                a.name,
                super::MAX_TORQUE_PERCENT
            ),
        ));
    }
    Ok(j)
}

fn duplicate(file: &Path, key: &str, name: &str) -> ConfigError {
    ConfigError::new(
        file,
        format!("{key}.name"),
        format!("duplicate axis name '{name}'"),
    )
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
                .map_err(|e| ConfigError::new(file, "ethercat.interface", e.to_string()))?;
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
