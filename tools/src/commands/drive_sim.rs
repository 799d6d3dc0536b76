//! `cellrt drive-sim ethercat`: the cell's drives as emulated EtherCAT SubDevices on a network
//! interface, for a `cellrt run` of the same cell on the other end of the link.

use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use cellrt_axes::ethercat::emulator::wire;
use cellrt_axes::ethercat::raw_socket::RawSocket;
use cellrt_runtime::cell_bus::{emulated_segment, segment_config};
use cellrt_runtime::config::CellConfig;

use crate::cli::{DriveSimArgs, DriveSimBus};
use crate::exit::Exit;

/// Runs `cellrt drive-sim`.
pub fn run(args: DriveSimArgs, cell: Option<String>) -> Exit {
    let DriveSimBus::Ethercat { interface } = args.bus;
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
    match wire::serve(&socket, &mut segment, &stop) {
        Ok(stats) => {
            eprintln!(
                "cellrt drive-sim: {} frames served, {} malformed dropped",
                stats.frames, stats.malformed
            );
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
