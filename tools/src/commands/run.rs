//! `cellrt run`: validates the configuration and program, runs the cell, prints the summary.

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Duration;

use cellrt_config::{AxisKind, CellConfig};
use cellrt_runtime::host::cell_lock::CellLockError;
use cellrt_runtime::host::controller::{self, Outcome, RunError, RunOptions};
use cellrt_runtime::host::program::Program;

use crate::cli::RunArgs;
use crate::exit::Exit;
use crate::summary;

/// Runs `cellrt run`.
pub fn run(args: RunArgs) -> Exit {
    let mut cell = match CellConfig::load(&args.config) {
        Ok(c) => c,
        Err(e) => return bad_input(e),
    };
    if let Some(interface) = &args.interface {
        if let Err(e) = cell.set_ethercat_interface(interface) {
            return bad_input(e);
        }
    }
    if let Some(addr) = args.live {
        if let Err(e) = cell.live_page.addr(addr) {
            return bad_input(format!("--live {addr}: {e}"));
        }
        cell.live = Some(addr);
    }
    let program = if args.no_program || args.external_planner {
        None
    } else if let Some(p) = &args.program {
        match Program::load(p, &cell) {
            Ok(p) => Some(p),
            Err(e) => return bad_input(e),
        }
    } else if let Some(p) = &cell.program {
        if !p.exists() {
            return bad_input(format!(
                "{}: cell.program: program file {} not found",
                args.config.display(),
                p.display()
            ));
        }
        match Program::load(p, &cell) {
            Ok(p) => Some(p),
            Err(e) => return bad_input(e),
        }
    } else {
        None
    };
    let duration = match args.duration.as_deref() {
        None => None,
        Some(text) => match crate::numbers::duration_seconds(text) {
            Ok(d) if d <= 1e7 => Some(Duration::from_secs_f64(d)),
            _ => {
                return bad_input(format!(
                    "--duration: must be seconds or a duration such as 90s, 10m, 1h30m, in (0, 1e7 s] (got {})",
                    cellrt_config::echo::Echo(text)
                ))
            }
        },
    };
    let record = if args.no_record {
        None
    } else if let Some(p) = args.record.clone() {
        Some(p)
    } else if cell.recording.enabled {
        Some(recording_path(&cell.recording.path, &cell.name))
    } else {
        None
    };

    // The summary's file is created before anything moves: a path that cannot be written is
    // bad input now, not a failure after the program has run.
    let summary_file = match &args.summary_json {
        None => None,
        Some(p) => match cellrt_runtime::output_file::create(p) {
            Ok(f) => Some(f),
            Err(e) => return bad_input(format!("--summary-json {}: {e}", p.display())),
        },
    };
    let shutdown = Arc::new(AtomicBool::new(false));
    for sig in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        if let Err(e) = signal_hook::flag::register(sig, shutdown.clone()) {
            eprintln!("error: cannot install the signal handler: {e}");
            return Exit::Failed;
        }
    }

    eprintln!(
        "cellrt: cell '{}' — {} axes at {} µs ({}){}{}",
        cell.name,
        cell.axes.count(),
        cell.cycle_time.as_micros(),
        axes_line(&cell),
        program
            .as_ref()
            .map(|p| format!(", program {}", p.source.display()))
            .unwrap_or_default(),
        record
            .as_ref()
            .map(|p| format!(", recording to {}", p.display()))
            .unwrap_or_default()
    );
    announce_faults_left_to_segment(&cell);
    if let Some(cellrt_config::EthercatInterface::Nic(nic)) =
        cell.ethercat.as_ref().map(|e| &e.interface)
    {
        if !cellrt_ethercat::raw_socket::interface_exists(nic) {
            return bad_input(format!(
                "EtherCAT interface '{nic}': network interface '{nic}' does not exist"
            ));
        }
    }
    if args.external_planner {
        eprintln!(
            "cellrt: waiting for a planner: cellrt planner {}",
            args.config.display()
        );
    }
    let result = controller::run(
        &cell,
        RunOptions {
            program,
            duration,
            record,
            shutdown,
            hook: None,
            external_planner: args.external_planner,
        },
    );
    let summary = match result {
        Ok(s) => s,
        Err(e) => {
            eprintln!("error: {e}");
            return match e {
                // A recording path, a live-view address or an interface name that cannot be
                // used: nothing ran.
                RunError::RecordingPath(_)
                | RunError::Live(_)
                | RunError::CellLock(CellLockError::InterfaceName { .. }) => Exit::BadInput,
                // The cell runs already: its controller keeps it.
                RunError::CellLock(_) => Exit::Rejected,
                _ => Exit::Failed,
            };
        }
    };
    print!("{}", summary::render(&summary));
    if let (Some(path), Some(mut file)) = (&args.summary_json, summary_file) {
        let json = serde_json::to_string_pretty(&summary).expect("summary serialises");
        if let Err(e) = std::io::Write::write_all(&mut file, (json + "\n").as_bytes()) {
            eprintln!("error: cannot write {}: {e}", path.display());
            return Exit::Failed;
        }
    }
    match summary.outcome {
        Outcome::ProgramFailed => Exit::Failed,
        _ => Exit::Ok,
    }
}

/// Says once which wire faults the master leaves to the emulated segment on the far end of its
/// network interface (it cannot inject them into a real wire).
fn announce_faults_left_to_segment(cell: &CellConfig) {
    let left = cell.faults_left_to_segment();
    let Some(cellrt_config::EthercatInterface::Nic(nic)) =
        cell.ethercat.as_ref().map(|e| &e.interface)
    else {
        return;
    };
    if left.is_empty() {
        return;
    }
    let names: Vec<String> = left
        .iter()
        .map(|i| format!("{} at cycle {}", i.fault.name(), i.cycle))
        .collect();
    eprintln!(
        "cellrt: wire fault(s) {} are left to the segment on the far end of '{nic}' (`cellrt drive-sim ethercat --config` injects them, counting cycles from the first process-data frame); the master does not inject them on a network interface and records each as a fault_left_to_segment event at its cycle",
        names.join(", ")
    );
}

fn bad_input(e: impl std::fmt::Display) -> Exit {
    eprintln!("error: {e}");
    Exit::BadInput
}

/// Expands `{cell}` and `{timestamp}` (UTC, `YYYYMMDD-HHMMSS`) in a recording path template.
pub fn recording_path(template: &str, cell: &str) -> PathBuf {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs())
        .unwrap_or(0);
    let (y, m, d) = civil_from_days((secs / 86_400) as i64);
    let t = secs % 86_400;
    let stamp = format!(
        "{y:04}{m:02}{d:02}-{:02}{:02}{:02}",
        t / 3600,
        t / 60 % 60,
        t % 60
    );
    Path::new(
        &template
            .replace("{cell}", cell)
            .replace("{timestamp}", &stamp),
    )
    .to_path_buf()
}

/// Days since 1970-01-01 to (year, month, day), proleptic Gregorian (H. Hinnant's algorithm).
fn civil_from_days(z: i64) -> (i64, u32, u32) {
    let z = z + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let m = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    let y = yoe + era * 400 + i64::from(m <= 2);
    (y, m, d)
}

/// Each axis and its backend, for the start line (an MR-JE-C axis with its link).
fn axes_line(cell: &CellConfig) -> String {
    let each: Vec<String> = cell
        .axes
        .iter()
        .map(|axis| match axis.config {
            AxisKind::Link(_, a) => format!(
                "{} {} over {} every {} ms{}",
                a.name,
                axis.backend().as_str(),
                a.transport.name(),
                a.period.as_millis(),
                if a.emulate { ", emulated" } else { "" }
            ),
            AxisKind::Loop(..) => format!("{} {}", axis.name(), axis.backend().as_str()),
        })
        .collect();
    each.join("; ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn civil_dates() {
        assert_eq!(civil_from_days(0), (1970, 1, 1));
        assert_eq!(civil_from_days(20_779), (2026, 11, 22));
        assert_eq!(civil_from_days(11_016), (2000, 2, 29));
    }

    #[test]
    fn template_expansion() {
        let p = recording_path("rec/{cell}-{timestamp}.mcap", "demo");
        let s = p.to_string_lossy();
        assert!(s.starts_with("rec/demo-"), "{s}");
        assert!(s.ends_with(".mcap"));
        assert_eq!(s.len(), "rec/demo-YYYYMMDD-HHMMSS.mcap".len());
    }
}
