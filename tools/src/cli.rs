//! Command-line interface.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand};

/// cellrt: a deterministic real-time motion controller for robot and machine cells.
#[derive(Debug, Parser)]
#[command(name = "cellrt", version, about)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
    /// Which running cell the operator commands address.
    #[command(flatten)]
    pub target: crate::commands::operate::Target,
}

/// Subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run a cell controller: RT loop, planner, drives, recording.
    Run(RunArgs),
    /// Run a program (or serve the operator) as a planner process of its own, against a
    /// running `cellrt run --external-planner` of the same cell.
    Planner(PlannerArgs),
    /// Summarise a recording: cell, channels, timing percentiles, events and faults.
    Inspect(InspectArgs),
    /// Rewrite a truncated recording (after a crash) into a complete, indexed one.
    Recover(RecoverArgs),
    /// Plots per axis and a latency histogram of a recording, with index.html (and CSV).
    Report(ReportArgs),
    /// Re-run a recording's setpoint stream through simulated drives and compare the feedback.
    Replay(ReplayArgs),
    /// Emulate drives on a network: EtherCAT SubDevices on an interface (a cell
    /// configuration's drives, or listed models), or MR-JE-C drives on an address.
    DriveSim(DriveSimArgs),
    /// Look at a fieldbus without running a cell.
    Bus(BusArgs),
    /// Read or write one object of an MR-JE-C over SLMP or Modbus/TCP (commissioning).
    #[command(name = "je-c")]
    JeC(crate::commands::je_c::JeCArgs),
    /// ESI files (EtherCAT Slave Information, ETG.2000): what cellrt takes from them.
    Esi(crate::commands::esi::EsiArgs),
    /// Benchmarks: wakeup latency, comparison with cyclictest, the full loop with N axes.
    Bench(crate::commands::bench::BenchArgs),
    /// Read or write one object of an axis' drive on a running cell (SDO), checked against
    /// the drive's object dictionary first.
    Sdo(crate::commands::sdo::SdoArgs),
    /// Servo parameters of an axis' drive by their manual names (PA14, PC02, …): list, get,
    /// set (range-checked first), save (1010h), diff against the initial values.
    Param(crate::commands::param::ParamArgs),
    /// The alarm history of an axis' drive, or `--clear` it.
    Alarms(crate::commands::param::AlarmsArgs),
    /// Print a shell completion script to stdout, e.g. `cellrt completions bash >
    /// /etc/bash_completion.d/cellrt`.
    Completions {
        /// The shell.
        #[arg(value_enum)]
        shell: clap_complete::Shell,
    },
    /// Print the man page (roff) to stdout, or with `--out DIR` write one page per command
    /// (cellrt.1, cellrt-run.1, …) into DIR.
    Man {
        /// Folder for the pages (created).
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
    },
    /// Operator commands to a running cell.
    #[command(flatten)]
    Operate(crate::commands::operate::OperatorCommand),
}

/// `cellrt inspect`.
#[derive(Debug, Args)]
pub struct InspectArgs {
    /// The recording (MCAP).
    pub file: PathBuf,
    /// Print how long the inspection took (to stderr).
    #[arg(long)]
    pub timing: bool,
    /// Print the inspection as one JSON document (events with their fields apart).
    #[arg(long)]
    pub json: bool,
}

/// `cellrt recover`.
#[derive(Debug, Args)]
pub struct RecoverArgs {
    /// The truncated recording.
    pub input: PathBuf,
    /// Where to write the recovered, indexed recording.
    pub output: PathBuf,
}

/// `cellrt report`.
#[derive(Debug, Args)]
pub struct ReportArgs {
    /// The recording (MCAP).
    pub file: PathBuf,
    /// Output folder (created).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Also export per-cycle data as CSV (one file per axis, one for the cycle timing).
    #[arg(long)]
    pub csv: bool,
    /// The per-move table's settling band, counts: an axis has settled once |actual − final
    /// setpoint| stays within it (one band for all axes; the drives' own in-position range is
    /// [Pr. PA10] / 6067h).
    #[arg(long, value_name = "COUNTS",
          default_value_t = DEFAULT_SETTLE_BAND_COUNTS)]
    pub settle_band: f64,
}

/// `cellrt report`'s default settling band, counts: an axis has settled once |actual − final
/// setpoint| stays within it. The manuals set an in-position range per drive ([Pr. PA10],
/// 6067h); the report takes one band for every axis, in the drive's counts.
pub const DEFAULT_SETTLE_BAND_COUNTS: f64 = 10.0;

/// `cellrt replay`.
#[derive(Debug, Args)]
pub struct ReplayArgs {
    /// The recording (MCAP) to replay.
    pub file: PathBuf,
}

/// `cellrt run`.
#[derive(Debug, Args)]
pub struct RunArgs {
    /// Cell configuration (TOML).
    pub config: PathBuf,
    /// Program to run instead of the one the configuration names.
    #[arg(long, conflicts_with = "no_program")]
    pub program: Option<PathBuf>,
    /// Run no program: stay up until SIGINT/SIGTERM or --duration.
    #[arg(long)]
    pub no_program: bool,
    /// Stop after this long: seconds, or a duration such as 90s, 10m, 1h30m.
    #[arg(long, value_name = "DURATION", allow_negative_numbers = true)]
    pub duration: Option<String>,
    /// Record to this MCAP file (default: the configuration's recording path).
    #[arg(long, value_name = "FILE", conflicts_with = "no_record")]
    pub record: Option<PathBuf>,
    /// Do not record.
    #[arg(long)]
    pub no_record: bool,
    /// Also write the summary as JSON to this file.
    #[arg(long, value_name = "FILE")]
    pub summary_json: Option<PathBuf>,
    /// Run no planner in this process: a `cellrt planner` process provides the setpoints
    /// (the controller runs until SIGINT/SIGTERM or --duration).
    #[arg(long, conflicts_with_all = ["program", "no_program"])]
    pub external_planner: bool,
    /// The EtherCAT interface instead of the configuration's `[ethercat] interface`
    /// ("in-process": the emulated segment, no network or root).
    #[arg(long, value_name = "IF")]
    pub interface: Option<String>,
    /// Serve the live view (Foxglove WebSocket protocol) on ADDR, e.g. 127.0.0.1:8765,
    /// instead of the configuration's `[live] listen`.
    #[arg(long, value_name = "ADDR", value_parser = cellrt_config::parse_live_addr)]
    pub live: Option<std::net::SocketAddr>,
}

/// `cellrt bus`.
#[derive(Debug, Args)]
pub struct BusArgs {
    /// What to do on the bus.
    #[command(subcommand)]
    pub command: BusCommand,
}

/// `cellrt bus` subcommands.
#[derive(Debug, Subcommand)]
pub enum BusCommand {
    /// List the EtherCAT SubDevices on a network interface without configuring anything:
    /// position, identity (vendor, product, revision, serial), name from the SII, AL state and
    /// status code, mailbox protocols, distributed clocks. Needs a raw socket (root or
    /// CAP_NET_RAW).
    Scan {
        /// The network interface the SubDevices are wired to.
        #[arg(long, value_name = "IF")]
        interface: String,
        /// Print the SubDevices as JSON (each field apart) instead of the table.
        #[arg(long)]
        json: bool,
    },
    /// SDO upload or download to one SubDevice without a cell: the segment is taken to
    /// PRE-OP (refused while a cell runs on the interface).
    Sdo {
        /// Read or write.
        #[command(subcommand)]
        command: crate::commands::bus_commission::BusSdoCommand,
    },
    /// The PDO assignment each SubDevice holds (1C12h/1C13h and the mapping objects), read in
    /// PRE-OP without a cell.
    Pdos {
        /// The network interface the SubDevices are wired to.
        #[arg(long, value_name = "IF")]
        interface: String,
        /// Only the SubDevice at this position.
        #[arg(long, short = 'p', value_name = "N")]
        position: Option<usize>,
        /// Print the assignment as JSON.
        #[arg(long)]
        json: bool,
    },
    /// The AL state of each SubDevice, after requesting `--state` from one (`--position`) or
    /// all; without a cell (the segment goes to PRE-OP first, for its mailboxes). Exit 3
    /// where a SubDevice does not reach the state asked for.
    States {
        /// The network interface the SubDevices are wired to.
        #[arg(long, value_name = "IF")]
        interface: String,
        /// Only the SubDevice at this position is asked.
        #[arg(long, short = 'p', value_name = "N")]
        position: Option<usize>,
        /// The state to request.
        #[arg(long, value_enum)]
        state: Option<crate::commands::bus_commission::StateArg>,
        /// How long a SubDevice may take to reach it (seconds, or e.g. 500ms).
        #[arg(long, default_value = "5", value_parser = crate::numbers::reply_timeout)]
        timeout: f64,
        /// Print the states as JSON.
        #[arg(long)]
        json: bool,
    },
    /// The SubDevices' SII EEPROM, without a cell.
    Sii {
        /// What to do.
        #[command(subcommand)]
        command: crate::commands::bus_commission::BusSiiCommand,
    },
    /// Diagnostics of a running EtherCAT cell (`--cell NAME`): per SubDevice its ports' links
    /// and ESC error counters (0300h–0313h), AL state and code, DC time difference, mailbox
    /// messages and Emergencies; the master's lost frames and working-counter errors. Two
    /// readings `--interval-ms` apart: a port whose counters grew between them is marked.
    Diag {
        /// Time between the two readings, ms (0: one reading, nothing marked).
        #[arg(long, value_name = "MS", default_value_t = 1000)]
        interval_ms: u64,
        /// Print the readings as JSON.
        #[arg(long)]
        json: bool,
    },
}

/// `cellrt drive-sim mr-je-c`.
#[derive(Debug, Args)]
pub struct MrJeCSimArgs {
    /// The IP address to listen on (e.g. 127.0.0.1, or an address in a network namespace).
    #[arg(long, value_name = "ADDR", required_unless_present = "rs485_pty")]
    pub listen: Option<std::net::IpAddr>,
    /// Serve Modbus RTU instead: an RS-485 line on a new pseudo-terminal, linked at PATH
    /// (the controller opens PATH as its serial device).
    #[arg(long, value_name = "PATH", conflicts_with = "listen")]
    pub rs485_pty: Option<std::path::PathBuf>,
    /// With `--rs485-pty`: the station numbers of the drives on the line (1–247), one drive each.
    #[arg(long, value_name = "N,..", value_delimiter = ',', default_value = "1")]
    pub stations: Vec<u8>,
    /// Modbus/TCP port (502 on a drive; below 1024 needs root).
    #[arg(long, value_name = "PORT", default_value_t = 502)]
    pub modbus_port: u16,
    /// SLMP UDP port.
    #[arg(long, value_name = "PORT", default_value_t = 5010)]
    pub slmp_udp_port: u16,
    /// SLMP TCP port.
    #[arg(long, value_name = "PORT", default_value_t = 5012)]
    pub slmp_tcp_port: u16,
    /// CC-Link IE Field Basic cyclic port (UDP).
    #[arg(long, value_name = "PORT", default_value_t = 61450)]
    pub cclink_port: u16,
    /// NodeSearch / IPAddressSet port (UDP).
    #[arg(long, value_name = "PORT", default_value_t = 61451)]
    pub search_port: u16,
    /// The drive's MAC address (NodeSearch reports it, IPAddressSet picks the drive by it);
    /// default 02:00 followed by the listen address' four octets.
    #[arg(long, value_name = "MAC")]
    pub mac: Option<cellrt_fieldbus::slmp::node_search::Mac>,
    /// The drive's software version: A0, A3 or A4 (objects, [Pr. PN10], 6502h).
    #[arg(long, value_name = "VERSION", default_value = "A4")]
    pub software: cellrt_fieldbus::mr_je_c::SoftwareVersion,
    /// The cyclic link's RWw/RWr devices and default response mapping: `profile` (manual
    /// Table 2.2: profile, position/speed/torque and homing modes) or `positioning` (Table 2.3:
    /// point table, indexer, jog and homing).
    #[arg(
        long,
        value_name = "TABLE",
        default_value = "profile",
        conflicts_with = "rs485_pty"
    )]
    pub link_layout: cellrt_emulator::mr_je_c::cyclic::LinkLayout,
}

impl Command {
    /// True for a command that reads, prints and exits: no controller, planner, emulator or
    /// benchmark cell runs in its process, and it talks to no cell.
    pub fn only_prints(&self) -> bool {
        matches!(
            self,
            Command::Inspect(_)
                | Command::Recover(_)
                | Command::Report(_)
                | Command::Replay(_)
                | Command::Esi(crate::commands::esi::EsiArgs {
                    command: crate::commands::esi::EsiCommand::Show { .. }
                })
                | Command::Completions { .. }
                | Command::Man { .. }
        )
    }
}

/// `cellrt drive-sim`.
// The operator commands' global --cell names a running cell; here it is a configuration file,
// which only `ethercat` takes (as its --cell): this hidden one keeps the global's help out.
#[derive(Debug, Args)]
#[command(arg(clap::Arg::new("cell").long("cell").global(true).hide(true)))]
pub struct DriveSimArgs {
    /// Which bus to emulate.
    #[command(subcommand)]
    pub bus: DriveSimBus,
}

/// The buses `cellrt drive-sim` emulates.
#[derive(Debug, Subcommand)]
pub enum DriveSimBus {
    /// Serve one simulated MR-JE-C on an address: Modbus/TCP (3 connections), SLMP over UDP
    /// and TCP (1 connection), the CC-Link IE Field Basic cyclic link (CSR/SSR, RWw/RWr), one
    /// request at a time, until SIGINT/SIGTERM; or with `--rs485-pty` drives on a Modbus RTU
    /// line. The motor moves in the modes the emulator has (pp, pv, tq, hm method 37, jg, pt,
    /// idx); the time-outs ([Pr. PN02], [Pr. PN10], [Pr. PF46]) run on the time since start.
    #[command(name = "mr-je-c")]
    MrJeC(MrJeCSimArgs),
    /// Present emulated drives as EtherCAT SubDevices on a network interface (line topology),
    /// for any MainDevice, until SIGINT/SIGTERM: the drives of a cell configuration file
    /// (`--config FILE`), or, without one, the models `--drives` lists and the devices of
    /// `--esi` files.
    ///
    /// With a configuration, the SubDevices are its EtherCAT axes' drives in axis order (a
    /// multi-axis amplifier is one), running its cycle time, and the cell's wire faults in
    /// `[[inject]]` (rx_loss as frame loss, frame_delay, frame_corruption, datagram_drop,
    /// link_loss, subdevice_stall) are injected here, on the cell's cycle clock as the segment
    /// sees it: cycle 0 is the first frame with a process-data (LRD/LWR/LRW) datagram, cycle n
    /// is n cycle times later; `at_ms` counts from there and each fault lasts duration_ms worth
    /// of frames. `cellrt run` on the other end sends that frame one cycle before its own
    /// loop's cycle 0.
    ///
    /// Without one, each model of `--drives` is one SubDevice with default settings (an
    /// MR-J5W2/W3-G-N1 one SubDevice with all its axes; `cia402` with the placeholder identity
    /// of configs/cia402-generic.toml), followed by one generic CiA 402 SubDevice per `--esi`
    /// file presenting that file's device (identity, modes, default PDOs, object dictionary),
    /// at `--cycle-time-us`; no wire faults. The start line lists each SubDevice's identity.
    Ethercat(EthercatSimArgs),
}

/// `cellrt drive-sim ethercat`.
#[derive(Debug, Args)]
pub struct EthercatSimArgs {
    /// The network interface to serve the SubDevices on (e.g. one end of a veth pair);
    /// required.
    #[arg(long, value_name = "IF")]
    pub interface: Option<String>,
    /// The cell configuration file (TOML) whose EtherCAT axes' drives to emulate.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// The cell configuration file, as --config: its older spelling, also taken before
    /// `drive-sim` (where the operator commands' global --cell names a running cell).
    // Its id is the global option's: clap then leaves that one out of this command.
    #[arg(long = "cell", id = "cell", value_name = "FILE")]
    pub cell: Option<String>,
    /// Without a configuration: the drive models to emulate, one SubDevice each, in line in
    /// this order (the names a configuration's `drive` takes).
    #[arg(long, value_name = "MODEL,..", num_args = 0..=1, default_missing_value = "",
          help = drives_help())]
    pub drives: Option<String>,
    /// Without a configuration: an ESI file (ETG.2000 XML) describing one CiA 402 device,
    /// emulated as a generic CiA 402 SubDevice behind those of --drives; repeatable.
    #[arg(long, value_name = "FILE")]
    pub esi: Vec<PathBuf>,
    /// Without a configuration: the drives' cycle time, µs (a configuration's
    /// `cycle_time_us`; default 1000); the SYNC0 cycle the MainDevice sets decides when they
    /// take each frame.
    #[arg(long, value_name = "US")]
    pub cycle_time_us: Option<u32>,
    /// The drives live on the MainDevice's clock (as on the in-process segment of `cellrt
    /// run`): in OP each process-data frame is one SYNC0 cycle, whatever the time between two,
    /// so a stall of the master's host or of this machine is no lost frame. Frames lost by an
    /// injected wire fault still count, and the fault schedule counts these cycles. For a
    /// loaded or virtual machine; real drives count every missed SYNC0.
    #[arg(long)]
    pub excuse_host_stalls: bool,
}

/// The help of `--drives`, with the model names as the configuration takes them.
fn drives_help() -> String {
    format!(
        "Without a configuration: the drive models to emulate, one SubDevice each, in line in \
         this order, e.g. mr-j4-tm,mr-j5w2-g-n1,cia402 (the names a configuration's `drive` \
         takes: {})",
        cellrt_cia402::profiles::DriveModel::names()
    )
}

/// `cellrt planner`.
#[derive(Debug, Args)]
pub struct PlannerArgs {
    /// Cell configuration (TOML), the same file the controller runs.
    pub config: PathBuf,
    /// Program to run instead of the one the configuration names.
    #[arg(long, conflicts_with = "no_program")]
    pub program: Option<PathBuf>,
    /// Run no program: serve the operator's commands (`cellrt move`, `jog`, `program`, …)
    /// until SIGINT/SIGTERM, as `cellrt run --no-program` does in the controller's process.
    #[arg(long)]
    pub no_program: bool,
    /// How long to wait for the controller, in seconds.
    #[arg(long, value_name = "SECONDS", default_value_t = 10.0)]
    pub connect_timeout: f64,
}
