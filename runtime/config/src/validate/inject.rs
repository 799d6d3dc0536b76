//! `[[inject]]`: the faults a test run injects, each at a cycle, checked against the cell's
//! axes and transport.

use std::path::Path;

use cellrt_cia402::CycleTime;
use strum::VariantNames;

use crate::raw::RawInjection;
use crate::{AxisConfig, ConfigError, EthercatConfig, FaultKind, InjectedFault, Injection};

/// `[[inject]]`: each fault at its cycle (sorted), with the keys its kind takes; faults of the
/// emulated EtherCAT segment only in a cell with EtherCAT axes.
pub(super) fn validate_injections(
    file: &Path,
    cycle_time: CycleTime,
    raw: &[RawInjection],
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
        let fault = injected_fault(file, i, r, cycle_time, axes)?;
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

/// The fault of injection `i` from its `fault` name and the keys that fault takes.
fn injected_fault(
    file: &Path,
    i: usize,
    r: &RawInjection,
    cycle_time: CycleTime,
    axes: &[AxisConfig],
) -> Result<InjectedFault, ConfigError> {
    let key = |k: &str| format!("inject[{i}].{k}");
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
        axes.iter()
            .position(|a| a.name == name)
            .ok_or_else(|| ConfigError::new(file, key("axis"), format!("no axis named '{name}'")))
    };
    let required_axis = || {
        let name = r.axis.as_deref().ok_or_else(|| {
            ConfigError::new(file, key("axis"), format!("fault '{}' needs axis", r.fault))
        })?;
        axis_named(name)
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
            let delay_ns = frame_delay_ns(r.delay_us).map_err(|e| e.at(file, key("delay_us")))?;
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
            let axis = required_axis()?;
            let cycles = cycles_of(duration(60_000.0)?);
            match kind {
                FaultKind::RxLoss => InjectedFault::RxLoss { axis, cycles },
                FaultKind::SubdeviceStall => InjectedFault::SubdeviceStall { axis, cycles },
                _ => InjectedFault::CounterCorruption { axis, cycles },
            }
        }
        FaultKind::DriveAlarm => {
            let axis = required_axis()?;
            let code = alarm_code(r.code).map_err(|e| e.at(file, key("code")))?;
            InjectedFault::DriveAlarm { axis, code }
        }
    };
    Ok(fault)
}

/// A key's value is wrong; the message, before the file and key are known.
struct BadValue(String);

impl BadValue {
    fn at(self, file: &Path, key: String) -> ConfigError {
        ConfigError::new(file, key, self.0)
    }
}

/// `delay_us` of a `frame_delay`, in ns: above 0, at most 1 s.
fn frame_delay_ns(delay_us: Option<f64>) -> Result<u64, BadValue> {
    match delay_us {
        Some(d) if d.is_finite() && d > 0.0 && d <= 1_000_000.0 => Ok((d * 1e3) as u64),
        Some(d) => Err(BadValue(format!(
            "must be > 0 and at most 1000000 µs (got {d})"
        ))),
        None => Err(BadValue("fault 'frame_delay' needs delay_us".into())),
    }
}

/// `code` of a `drive_alarm`: a 16-bit alarm code other than 0.
fn alarm_code(code: Option<u32>) -> Result<u16, BadValue> {
    match code {
        Some(c @ 1..=0xFFFF) => Ok(c as u16),
        Some(c) => Err(BadValue(format!(
            "alarm code must be 0x0001..=0xFFFF (got {c:#x})"
        ))),
        None => Err(BadValue("fault 'drive_alarm' needs code".into())),
    }
}
