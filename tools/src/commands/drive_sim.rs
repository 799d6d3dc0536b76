//! `cellrt drive-sim ethercat`: the cell's drives as emulated EtherCAT SubDevices on a network
//! interface, for a `cellrt run` of the same cell on the other end of the link.

use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use cellrt_config::CellConfig;
use cellrt_emulator::ethercat::{wire, FaultSchedule, ScheduledFault, WireFault};
use cellrt_ethercat::raw_socket::RawSocket;
use cellrt_runtime::host::cell_bus::{emulated_segment, segment_config};

use crate::cli::{DriveSimArgs, DriveSimBus};
use crate::exit::Exit;

/// Runs `cellrt drive-sim`.
pub fn run(args: DriveSimArgs, cell: Option<String>) -> Exit {
    let interface = match args.bus {
        DriveSimBus::Ethercat { interface } => interface,
        DriveSimBus::MrJeC(args) => return super::drive_sim_mr_je_c::run(args),
    };
    match serve_ethercat(&interface, cell.map(std::path::PathBuf::from)) {
        Ok(()) => Exit::Ok,
        Err(exit) => exit,
    }
}

/// Prints `e` as the error and returns `exit`.
fn fail(e: impl std::fmt::Display, exit: Exit) -> Exit {
    eprintln!("error: {e}");
    exit
}

/// The cell whose drives to emulate: `--cell`, with EtherCAT axes.
fn ethercat_cell(
    cell: Option<std::path::PathBuf>,
) -> Result<(std::path::PathBuf, CellConfig), Exit> {
    let Some(cell) = cell else {
        return Err(fail(
            "--cell CONFIG: the cell configuration whose drives to emulate is required",
            Exit::BadInput,
        ));
    };
    let config = CellConfig::load(&cell).map_err(|e| fail(e, Exit::BadInput))?;
    if config.ethercat.is_none() {
        return Err(fail(
            format!(
                "{}: cell '{}' has no EtherCAT axes (transport = \"ethercat\" and an [ethercat] section)",
                cell.display(),
                config.name
            ),
            Exit::BadInput,
        ));
    }
    Ok((cell, config))
}

/// Serves the cell's drives on `interface` until SIGINT or SIGTERM.
fn serve_ethercat(interface: &str, cell: Option<std::path::PathBuf>) -> Result<(), Exit> {
    let (cell, config) = ethercat_cell(cell)?;
    let socket = RawSocket::open(interface).map_err(|e| fail(e, Exit::Failed))?;
    let stop = Arc::new(AtomicBool::new(false));
    for sig in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        signal_hook::flag::register(sig, stop.clone()).map_err(|e| {
            fail(
                format!("cannot install the signal handler: {e}"),
                Exit::Failed,
            )
        })?;
    }
    // Like a drive's hardware, the emulator answers at once: on the cell's RT CPU, one
    // priority above its RT thread (best effort without root), memory locked.
    let rt = cellrt_config::RtConfig {
        cpu: config.rt.cpu,
        priority: config.rt.priority.saturating_add(1).min(99),
        planner_priority: None,
        lock_memory: true,
        reserve_cpu: false,
    };
    let report = cellrt_runtime::rt::thread::setup_current_thread(&rt);
    eprintln!("cellrt drive-sim: {}", report.describe());
    let mut segment = emulated_segment(&config).map_err(|e| fail(e, Exit::Failed))?;
    let stations = segment_config(&config)
        .stations()
        .map_err(|e| fail(e, Exit::Failed))?;
    let station_names: Vec<String> = stations.iter().map(|st| axis_names(&config, st)).collect();
    let names: Vec<String> = stations
        .iter()
        .zip(&station_names)
        .map(|(st, n)| format!("{n} ({})", st.model.model))
        .collect();
    eprintln!(
        "cellrt drive-sim: {} EtherCAT SubDevice(s) on {interface}: {}",
        names.len(),
        names.join(", ")
    );
    let schedule = station_schedule(&config, &stations);
    let mut faults = FaultSchedule::new(schedule, config.cycle_time, segment.stations().len())
        .map_err(|e| fail(format!("{}: {e}", cell.display()), Exit::BadInput))?;
    announce(&config, &station_names, &faults);
    let stats = wire::serve(&socket, &mut segment, &mut faults, &stop)
        .map_err(|e| fail(format!("{interface}: {e}"), Exit::Failed))?;
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
    for (name, st) in station_names.iter().zip(segment.stations()) {
        let alarms: Vec<String> = st
            .drives()
            .iter()
            .filter_map(|d| d.alarm().map(|c| format!(", alarm {c:#06x}")))
            .collect();
        eprintln!(
            "  {name}: AL state {}{}",
            st.al_state().as_str(),
            alarms.concat()
        );
    }
    Ok(())
}

/// The axes a SubDevice carries, `x+y`.
fn axis_names(config: &CellConfig, st: &cellrt_ethercat::master::SegmentStation) -> String {
    let v: Vec<&str> = st
        .slots
        .iter()
        .flatten()
        .map(|&a| config.axes.on_loop()[a].name.as_str())
        .collect();
    v.join("+")
}

/// The cell's wire faults by station: the config names them by axis, the segment has one
/// station per SubDevice.
fn station_schedule(
    config: &CellConfig,
    stations: &[cellrt_ethercat::master::SegmentStation],
) -> Vec<ScheduledFault> {
    config
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
        .collect()
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
