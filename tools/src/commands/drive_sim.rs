//! `cellrt drive-sim ethercat`: the cell's drives as emulated EtherCAT SubDevices on a network
//! interface, for a `cellrt run` of the same cell on the other end of the link.

use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use cellrt_axes::ethercat::emulator::{wire, FaultSchedule, ScheduledFault, WireFault};
use cellrt_axes::ethercat::raw_socket::RawSocket;
use cellrt_runtime::config::CellConfig;
use cellrt_runtime::host::cell_bus::{emulated_segment, segment_config};

use crate::cli::{DriveSimArgs, DriveSimBus};
use crate::exit::Exit;

/// Runs `cellrt drive-sim`.
pub fn run(args: DriveSimArgs, cell: Option<String>) -> Exit {
    let interface = match args.bus {
        DriveSimBus::Ethercat { interface } => interface,
        DriveSimBus::MrJeC(args) => return super::drive_sim_mr_je_c::run(args),
    };
    let Some(cell) = cell.map(std::path::PathBuf::from) else {
        eprintln!(
            "error: --cell CONFIG: the cell configuration whose drives to emulate is required"
        );
        return Exit::BadInput;
    };
    let config = match CellConfig::load(&cell) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("error: {e}");
            return Exit::BadInput;
        }
    };
    if config.ethercat.is_none() {
        eprintln!(
            "error: {}: cell '{}' has no EtherCAT axes (transport = \"ethercat\" and an [ethercat] section)",
            cell.display(),
            config.name
        );
        return Exit::BadInput;
    }
    let socket = match RawSocket::open(&interface) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("error: {e}");
            return Exit::Failed;
        }
    };
    let stop = Arc::new(AtomicBool::new(false));
    for sig in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        if let Err(e) = signal_hook::flag::register(sig, stop.clone()) {
            eprintln!("error: cannot install the signal handler: {e}");
            return Exit::Failed;
        }
    }
    // Like a drive's hardware, the emulator answers at once: on the cell's RT CPU, one
    // priority above its RT thread (best effort without root), memory locked.
    let rt = cellrt_runtime::config::RtConfig {
        cpu: config.rt.cpu,
        priority: config.rt.priority.saturating_add(1).min(99),
        planner_priority: None,
        lock_memory: true,
        reserve_cpu: false,
    };
    let report = cellrt_runtime::rt::thread::setup_current_thread(&rt);
    eprintln!("cellrt drive-sim: {}", report.describe());
    let mut segment = match emulated_segment(&config) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("error: {e}");
            return Exit::Failed;
        }
    };
    let stations = match segment_config(&config).stations() {
        Ok(s) => s,
        Err(e) => {
            eprintln!("error: {e}");
            return Exit::Failed;
        }
    };
    let axis_names = |st: &cellrt_axes::ethercat::master::SegmentStation| -> String {
        let v: Vec<&str> = st
            .slots
            .iter()
            .flatten()
            .map(|&a| config.axes[a].name.as_str())
            .collect();
        v.join("+")
    };
    let names: Vec<String> = stations
        .iter()
        .map(|st| format!("{} ({})", axis_names(st), st.model.model))
        .collect();
    eprintln!(
        "cellrt drive-sim: {} EtherCAT SubDevice(s) on {interface}: {}",
        names.len(),
        names.join(", ")
    );
    // The config names faults by axis; the segment has one station per SubDevice.
    let schedule = config
        .wire_schedule()
        .into_iter()
        .map(|f| ScheduledFault {
            fault: match f.fault.station() {
                Some(axis) => f.fault.at_station(
                    stations
                        .iter()
                        .position(|st| st.slots.contains(&Some(axis)))
                        .unwrap_or(axis),
                ),
                None => f.fault,
            },
            ..f
        })
        .collect();
    let station_names: Vec<String> = stations.iter().map(axis_names).collect();
    let mut faults = match FaultSchedule::new(schedule, config.cycle_time, segment.stations().len())
    {
        Ok(f) => f,
        Err(e) => {
            eprintln!("error: {}: {e}", cell.display());
            return Exit::BadInput;
        }
    };
    announce(&config, &station_names, &faults);
    match wire::serve(&socket, &mut segment, &mut faults, &stop) {
        Ok(stats) => {
            eprintln!(
                "cellrt drive-sim: {} frames served, {} malformed dropped, {} lost and {} delayed by injected faults",
                stats.frames, stats.malformed, stats.lost, stats.delayed
            );
            if !faults.faults().is_empty() {
                eprintln!(
                    "cellrt drive-sim: injected {} of {} scheduled wire fault(s): {}",
                    stats.injected.total(),
                    faults.faults().len(),
                    stats.injected.describe()
                );
            }
            for (plan, st) in stations.iter().zip(segment.stations()) {
                let alarms: Vec<String> = st
                    .drives()
                    .iter()
                    .filter_map(|d| d.alarm().map(|c| format!(", alarm {c:#06x}")))
                    .collect();
                eprintln!(
                    "  {}: AL state {}{}",
                    axis_names(plan),
                    st.al_state().as_str(),
                    alarms.concat()
                );
            }
            Exit::Ok
        }
        Err(e) => {
            eprintln!("error: {interface}: {e}");
            Exit::Failed
        }
    }
}

/// Prints the wire faults the segment will inject, and when.
fn announce(config: &CellConfig, stations: &[String], faults: &FaultSchedule) {
    if faults.faults().is_empty() {
        return;
    }
    eprintln!(
        "cellrt drive-sim: {} wire fault(s) of the cell's [[inject]], at cycles of {} µs counted from the first process-data frame (cycle 0):",
        faults.faults().len(),
        faults.cycle_time().as_micros()
    );
    for f in faults.faults() {
        eprintln!("  {}", describe(config, stations, f));
    }
}

/// One scheduled fault as a line, e.g. "cycle 600 (600 ms): link_loss in front of x, 30 frames".
fn describe(config: &CellConfig, stations: &[String], f: &ScheduledFault) -> String {
    let ms = f.cycle as f64 * config.cycle_time.as_nanos() as f64 / 1e6;
    let at = |station: usize| {
        stations
            .get(station)
            .cloned()
            .unwrap_or_else(|| format!("SubDevice {station}"))
    };
    let what = match f.fault {
        WireFault::FrameLoss { .. } => "every frame lost (rx_loss)".to_string(),
        WireFault::FrameDelay { delay_ns, .. } => {
            format!("frame_delay by {} µs", delay_ns as f64 / 1e3)
        }
        WireFault::FrameCorruption { station, .. } => {
            format!("frame_corruption in front of {}", at(station))
        }
        WireFault::DatagramDrop { .. } => "datagram_drop".to_string(),
        WireFault::LinkLoss { station, .. } => format!("link_loss in front of {}", at(station)),
        WireFault::SubdeviceStall { station, .. } => format!("subdevice_stall of {}", at(station)),
    };
    format!(
        "cycle {} ({ms} ms): {what}, {} frames",
        f.cycle,
        f.fault.frames()
    )
}
