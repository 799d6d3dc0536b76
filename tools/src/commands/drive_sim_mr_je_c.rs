//! `cellrt drive-sim mr-je-c`: one simulated MR-JE-C serving Modbus/TCP and SLMP on an
//! address, or simulated MR-JE-Cs on a Modbus RTU line over a pseudo-terminal, for
//! commissioning tools and cells on the other end.

use std::net::IpAddr;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

use cellrt_emulator::mr_je_c::rs485::Rs485Line;
use cellrt_emulator::mr_je_c::server::{Ports, Server};
use cellrt_emulator::mr_je_c::{MrJeC, MrJeCParams};
use cellrt_fieldbus::modbus::serial::LineSettings;
use cellrt_fieldbus::mr_je_c::parameters::{PC70, PN08};
use cellrt_fieldbus::mr_je_c::{ObjectId, SoftwareVersion, Value};
use cellrt_fieldbus::slmp::node_search::Mac;
use serialport::{SerialPort, TTYPort};

use crate::cli::MrJeCSimArgs;
use crate::exit::Exit;

/// Runs `cellrt drive-sim mr-je-c`.
pub fn run(args: MrJeCSimArgs) -> Exit {
    let stop = Arc::new(AtomicBool::new(false));
    for sig in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        if let Err(e) = signal_hook::flag::register(sig, stop.clone()) {
            eprintln!("error: cannot install the signal handler: {e}");
            return Exit::Failed;
        }
    }
    match (args.listen, &args.rs485_pty) {
        (_, Some(link)) => serve_rs485(link, &args, &stop),
        (Some(ip), None) => serve_ethernet(ip, &args, &stop),
        (None, None) => {
            eprintln!("error: give --listen ADDR or --rs485-pty PATH");
            Exit::BadInput
        }
    }
}

/// One drive on Modbus/TCP, SLMP and the cyclic link at `ip`.
fn serve_ethernet(ip: IpAddr, args: &MrJeCSimArgs, stop: &AtomicBool) -> Exit {
    let ports = Ports {
        modbus_tcp: args.modbus_port,
        slmp_udp: args.slmp_udp_port,
        slmp_tcp: args.slmp_tcp_port,
        cclink: args.cclink_port,
        search: args.search_port,
    };
    let params = MrJeCParams {
        software: args.software,
        mac: args.mac.unwrap_or_else(|| mac_of(ip)),
        link_layout: args.link_layout,
        ..Default::default()
    };
    let (model, mac) = (params.model.clone(), params.mac);
    let server = match Server::start(MrJeC::new(params), ip, ports) {
        Ok(s) => s,
        Err(e) => {
            let hint = if e.kind() == std::io::ErrorKind::PermissionDenied {
                " (ports below 1024 need root or CAP_NET_BIND_SERVICE: choose --modbus-port)"
            } else {
                ""
            };
            eprintln!(
                "error: cannot listen on {} (Modbus/TCP {}, SLMP UDP {}, SLMP TCP {}, CC-Link IE Field Basic UDP {}, NodeSearch UDP {}): {e}{hint}",
                ip, ports.modbus_tcp, ports.slmp_udp, ports.slmp_tcp, ports.cclink, ports.search
            );
            return Exit::Failed;
        }
    };
    eprintln!(
        "cellrt drive-sim: {model} (software {}, MAC {mac}) on Modbus/TCP {}, SLMP UDP {}, SLMP TCP {}, CC-Link IE Field Basic UDP {} (link devices of {}), NodeSearch UDP {}",
        args.software, server.modbus_tcp, server.slmp_udp, server.slmp_tcp, server.cclink, args.link_layout, server.search
    );
    while !stop.load(Ordering::Relaxed) {
        std::thread::sleep(Duration::from_millis(50));
    }
    let drive = server.drive();
    eprintln!(
        "cellrt drive-sim: stopped after {:.1} s; {} ({}), alarm {}",
        server.now().as_secs_f64(),
        drive.state(),
        drive.statusword(),
        drive.alarm().map_or("none".to_string(), |a| a.to_string())
    );
    drop(drive);
    server.stop();
    Exit::Ok
}

/// Drives at `args.stations` on one RS-485 line over a new pseudo-terminal linked at `link`.
fn serve_rs485(link: &Path, args: &MrJeCSimArgs, stop: &AtomicBool) -> Exit {
    if let Some(bad) = args.stations.iter().find(|&&n| n == 0 || n > 247) {
        eprintln!("error: --stations: {bad} is not a station number (1–247)");
        return Exit::BadInput;
    }
    let mut seen = std::collections::BTreeSet::new();
    if let Some(twice) = args.stations.iter().find(|&&n| !seen.insert(n)) {
        eprintln!("error: --stations: {twice} is given twice (one drive per station)");
        return Exit::BadInput;
    }
    let (master, slave) = match TTYPort::pair() {
        Ok(p) => p,
        Err(e) => {
            eprintln!("error: cannot create a pseudo-terminal: {e}");
            return Exit::Failed;
        }
    };
    let Some(pts) = slave.name() else {
        eprintln!("error: the pseudo-terminal has no name");
        return Exit::Failed;
    };
    if let Err(e) = link_at(link, Path::new(&pts)) {
        eprintln!("error: --rs485-pty {}: {e}", link.display());
        return Exit::BadInput;
    }
    let drives = args
        .stations
        .iter()
        .map(|&n| rs485_drive(args.software, n))
        .collect();
    let line = LineSettings::default();
    let served = match Rs485Line::start(drives, Box::new(master), line) {
        Ok(l) => l,
        Err(e) => {
            eprintln!("error: cannot serve the line: {e}");
            let _ = std::fs::remove_file(link);
            return Exit::Failed;
        }
    };
    eprintln!(
        "cellrt drive-sim: MR-JE-C (software {}) stations {:?} on Modbus RTU at {} ({pts}), {} bit/s",
        args.software,
        args.stations,
        link.display(),
        line.baud
    );
    while !stop.load(Ordering::Relaxed) {
        std::thread::sleep(Duration::from_millis(50));
    }
    eprintln!(
        "cellrt drive-sim: stopped after {:.1} s; {} overlong frames",
        served.now().as_secs_f64(),
        served.overlong_frames()
    );
    served.stop();
    drop(slave);
    let _ = std::fs::remove_file(link);
    Exit::Ok
}

/// A locally administered MAC address made of the drive's IPv4 address: 02:00:a:b:c:d.
fn mac_of(ip: IpAddr) -> Mac {
    let o = match ip.to_canonical() {
        IpAddr::V4(v4) => v4.octets(),
        IpAddr::V6(v6) => {
            let s = v6.octets();
            [s[12], s[13], s[14], s[15]]
        }
    };
    Mac([0x02, 0x00, o[0], o[1], o[2], o[3]])
}

/// A drive with [Pr. PN08] = RS-485 at station `n` ([Pr. PC70]).
fn rs485_drive(software: SoftwareVersion, n: u8) -> MrJeC {
    let mut d = MrJeC::new(MrJeCParams {
        software,
        ..Default::default()
    });
    let t = Duration::ZERO;
    // Both parameters are in range, so the writes cannot be refused.
    let _ = d.write(ObjectId::new(PN08.index(), 0), &Value::U32(0x1000), t);
    let _ = d.write(ObjectId::new(PC70.index(), 0), &Value::U32(u32::from(n)), t);
    d
}

/// A symbolic link at `link` to `target`, refusing to replace anything but an old link.
fn link_at(link: &Path, target: &Path) -> std::io::Result<()> {
    if let Ok(m) = std::fs::symlink_metadata(link) {
        if !m.file_type().is_symlink() {
            return Err(std::io::Error::new(
                std::io::ErrorKind::AlreadyExists,
                "exists and is not a symbolic link (not replaced)",
            ));
        }
        std::fs::remove_file(link)?;
    }
    std::os::unix::fs::symlink(target, link)
}
