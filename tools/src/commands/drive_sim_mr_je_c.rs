//! `cellrt drive-sim mr-je-c`: one simulated MR-JE-C serving Modbus/TCP and SLMP on an
//! address, for commissioning tools and cells on the other end.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

use cellrt_axes::mr_je_c::emulator::server::{Ports, Server};
use cellrt_axes::mr_je_c::emulator::{MrJeC, MrJeCParams};

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
    let ports = Ports {
        modbus_tcp: args.modbus_port,
        slmp_udp: args.slmp_udp_port,
        slmp_tcp: args.slmp_tcp_port,
        cclink: args.cclink_port,
    };
    let params = MrJeCParams {
        software: args.software,
        ..Default::default()
    };
    let model = params.model.clone();
    let server = match Server::start(MrJeC::new(params), args.listen, ports) {
        Ok(s) => s,
        Err(e) => {
            let hint = if e.kind() == std::io::ErrorKind::PermissionDenied {
                " (ports below 1024 need root or CAP_NET_BIND_SERVICE: choose --modbus-port)"
            } else {
                ""
            };
            eprintln!(
                "error: cannot listen on {} (Modbus/TCP {}, SLMP UDP {}, SLMP TCP {}, CC-Link IE Field Basic UDP {}): {e}{hint}",
                args.listen, ports.modbus_tcp, ports.slmp_udp, ports.slmp_tcp, ports.cclink
            );
            return Exit::Failed;
        }
    };
    eprintln!(
        "cellrt drive-sim: {model} (software {}) on Modbus/TCP {}, SLMP UDP {}, SLMP TCP {}, CC-Link IE Field Basic UDP {}",
        args.software, server.modbus_tcp, server.slmp_udp, server.slmp_tcp, server.cclink
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
