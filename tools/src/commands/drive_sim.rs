//! `cellrt drive-sim ethercat`: emulated drives as EtherCAT SubDevices on a network interface,
//! for a `cellrt run` of the same cell or any other MainDevice on the other end of the link:
//! a cell configuration's drives, or the models and ESI devices listed on the command line.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use cellrt_cia402::CycleTime;
use cellrt_config::{CellConfig, RtConfig};
use cellrt_emulator::ethercat::{wire, FaultSchedule, ScheduledFault, Segment, WireFault};
use cellrt_ethercat::raw_socket::RawSocket;
use cellrt_runtime::host::cell_bus::{emulated_segment, segment_config, segment_of};

use super::drive_sim_lineup::{models, Lineup};
use crate::cli::{DriveSimArgs, DriveSimBus, EthercatSimArgs};
use crate::exit::Exit;

/// Runs `cellrt drive-sim`.
pub fn run(args: DriveSimArgs) -> Exit {
    let args = match args.bus {
        DriveSimBus::Ethercat(args) => args,
        DriveSimBus::MrJeC(args) => return super::drive_sim_mr_je_c::run(args),
    };
    match serve_ethercat(args) {
        Ok(()) => Exit::Ok,
        Err(exit) => exit,
    }
}

/// Prints `e` as the error and returns `exit`.
fn fail(e: impl std::fmt::Display, exit: Exit) -> Exit {
    eprintln!("error: {e}");
    exit
}

/// Where the SubDevices come from.
#[derive(Debug)]
enum Drives {
    /// A cell configuration file's EtherCAT axes.
    Config(PathBuf),
    /// The models and ESI files of the command line.
    Listed(Lineup),
}

/// The interface and the SubDevices the command line asks for, or why it is refused.
fn request(args: EthercatSimArgs) -> Result<(String, Drives), String> {
    let interface = args
        .interface
        .ok_or("--interface IF: the network interface to serve the SubDevices on is required")?;
    let config = match (args.config, args.cell) {
        (Some(_), Some(_)) => {
            return Err("--config and --cell both name a configuration file; give one".into())
        }
        (config, cell) => config.or(cell.map(PathBuf::from)),
    };
    let listed = args.drives.is_some() || !args.esi.is_empty();
    let drives = match config {
        Some(file) if listed => {
            return Err(format!(
                "{}: a configuration lists its own drives; give it or --drives/--esi, not both",
                file.display()
            ))
        }
        Some(_) if args.cycle_time_us.is_some() => {
            return Err(
                "--cycle-time-us: a configuration gives its own cycle time (cycle_time_us)".into(),
            )
        }
        Some(file) => Drives::Config(file),
        None if !listed => {
            return Err(
                "no drives to emulate: give --config FILE (a cell configuration), or --drives MODEL,.. and/or --esi FILE".into(),
            )
        }
        None => Drives::Listed(Lineup {
            models: args.drives.as_deref().map_or(Ok(Vec::new()), models)?,
            esi: args.esi,
            cycle: cellrt_cia402::CycleTime::from_micros(
                args.cycle_time_us.unwrap_or(DEFAULT_CYCLE_US),
            )
            .map_err(|e| format!("--cycle-time-us: {e}"))?,
        }),
    };
    Ok((interface, drives))
}

/// The cycle time of drives listed without a configuration, µs: one every model runs (the
/// shipped configurations' too).
const DEFAULT_CYCLE_US: u32 = 1000;

/// The cell whose drives to emulate, with EtherCAT axes.
fn ethercat_cell(cell: &std::path::Path) -> Result<CellConfig, Exit> {
    let config = CellConfig::load(cell).map_err(|e| fail(e, Exit::BadInput))?;
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
    Ok(config)
}

/// What drive-sim serves and how its messages name the SubDevices.
struct Emulation {
    segment: Segment,
    /// Per SubDevice, its name in the messages: its axes (`x+y`), or its model.
    names: Vec<String>,
    /// Per SubDevice, how the start line lists it.
    listing: Vec<String>,
    /// The emulator thread's real-time settings.
    rt: RtConfig,
    /// The wire faults to inject.
    faults: FaultSchedule,
    /// The drives' cycle time (the SYNC0 cycle).
    cycle: CycleTime,
}

/// The emulator thread's settings: like a drive's hardware it answers at once, so on the
/// cell's RT CPU one priority above its RT thread (best effort without root), memory locked.
fn emulator_rt(cpu: Option<usize>, cell_priority: u8) -> RtConfig {
    RtConfig {
        cpu,
        priority: cell_priority.saturating_add(1).min(99),
        planner_priority: None,
        lock_memory: true,
        reserve_cpu: false,
        missed_deadlines: Default::default(),
    }
}

/// The emulation of a cell configuration's drives, its wire faults announced.
fn of_config(file: &std::path::Path) -> Result<Emulation, Exit> {
    let config = ethercat_cell(file)?;
    let segment = emulated_segment(&config).map_err(|e| fail(e, Exit::Failed))?;
    let stations = segment_config(&config)
        .stations()
        .map_err(|e| fail(e, Exit::Failed))?;
    let names: Vec<String> = stations.iter().map(|st| axis_names(&config, st)).collect();
    let listing = stations
        .iter()
        .zip(&names)
        .map(|(st, n)| format!("{n} ({})", st.model.model))
        .collect();
    let schedule = station_schedule(&config, &stations);
    let faults = FaultSchedule::new(schedule, config.cycle_time, segment.stations().len())
        .map_err(|e| fail(format!("{}: {e}", file.display()), Exit::BadInput))?;
    Ok(Emulation {
        segment,
        names,
        listing,
        rt: emulator_rt(config.rt.cpu, config.rt.priority),
        faults,
        cycle: config.cycle_time,
    })
}

/// The emulation of the listed drives: no wire faults, the default RT priority.
fn of_lineup(lineup: &Lineup) -> Result<Emulation, Exit> {
    let line = lineup.stations().map_err(|e| fail(e, Exit::BadInput))?;
    let names: Vec<String> = line.iter().map(|st| st.name.clone()).collect();
    let segment = segment_of(line.into_iter().map(|st| st.station).collect())
        .map_err(|e| fail(e, Exit::Failed))?;
    let listing = names
        .iter()
        .zip(segment.stations())
        .map(|(name, st)| {
            let id = st.identity();
            let axes = match st.drives().len() {
                1 => "1 axis".to_owned(),
                n => format!("{n} axes"),
            };
            format!(
                "{name} (vendor {:#010x}, product {:#010x}, {axes})",
                id.vendor_id, id.product_code
            )
        })
        .collect();
    let faults = FaultSchedule::new(Vec::new(), lineup.cycle, names.len())
        .map_err(|e| fail(e, Exit::Failed))?;
    Ok(Emulation {
        segment,
        names,
        listing,
        rt: emulator_rt(None, cellrt_config::raw::RawRt::default().priority),
        faults,
        cycle: lineup.cycle,
    })
}

/// Serves the requested drives on the interface until SIGINT or SIGTERM.
fn serve_ethercat(args: EthercatSimArgs) -> Result<(), Exit> {
    let excuse_host_stalls = args.excuse_host_stalls;
    let (interface, drives) = request(args).map_err(|e| fail(e, Exit::BadInput))?;
    let mut emulation = match &drives {
        Drives::Config(file) => of_config(file)?,
        Drives::Listed(lineup) => of_lineup(lineup)?,
    };
    let socket = RawSocket::open(&interface).map_err(|e| fail(e, Exit::Failed))?;
    let stop = Arc::new(AtomicBool::new(false));
    for sig in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        signal_hook::flag::register(sig, stop.clone()).map_err(|e| {
            fail(
                format!("cannot install the signal handler: {e}"),
                Exit::Failed,
            )
        })?;
    }
    let report = cellrt_runtime::rt::thread::setup_current_thread(&emulation.rt);
    eprintln!("cellrt drive-sim: {}", report.describe());
    eprintln!(
        "cellrt drive-sim: {} EtherCAT SubDevice(s) on {interface}: {}",
        emulation.listing.len(),
        emulation.listing.join(", ")
    );
    announce(&emulation.names, &emulation.faults);
    let stalls = if excuse_host_stalls {
        eprintln!(
            "cellrt drive-sim: the drives live on the MainDevice's clock, one cycle per process-data frame in OP (--excuse-host-stalls)"
        );
        wire::HostStalls::Excused {
            cycle: emulation.cycle.as_duration(),
        }
    } else {
        wire::HostStalls::Counted
    };
    let Emulation {
        segment,
        names,
        faults,
        ..
    } = &mut emulation;
    let stats = wire::serve(&socket, segment, faults, stalls, &stop)
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
    for (name, st) in names.iter().zip(segment.stations()) {
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
fn announce(stations: &[String], faults: &FaultSchedule) {
    if faults.faults().is_empty() {
        return;
    }
    eprintln!(
        "cellrt drive-sim: {} wire fault(s) of the cell's [[inject]], at cycles of {} µs counted from the first process-data frame (cycle 0):",
        faults.faults().len(),
        faults.cycle_time().as_micros()
    );
    for f in faults.faults() {
        eprintln!("  {}", describe(faults.cycle_time(), stations, f));
    }
}

/// One scheduled fault as a line, e.g. "cycle 600 (600 ms): link_loss in front of x, 30 frames".
fn describe(cycle: cellrt_cia402::CycleTime, stations: &[String], f: &ScheduledFault) -> String {
    let ms = f.cycle as f64 * cycle.as_nanos() as f64 / 1e6;
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
