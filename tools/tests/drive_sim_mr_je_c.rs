//! `cellrt drive-sim mr-je-c` on loopback: our Modbus/TCP and SLMP clients reach it, SIGTERM
//! ends it cleanly, and bad arguments are refused naming what is wrong.

use std::net::{SocketAddr, TcpListener, UdpSocket};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use cellrt_axes::modbus::client::TcpClient;
use cellrt_axes::mr_je_c::access::typed::Statusword;
use cellrt_axes::mr_je_c::{ObjectAccess, OverModbus};
use cellrt_axes::slmp::client::{FrameType, SlmpClient};

fn free_tcp() -> u16 {
    TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port()
}

fn free_udp() -> u16 {
    UdpSocket::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port()
}

fn cellrt(args: &[String]) -> Child {
    Command::new(env!("CARGO_BIN_EXE_cellrt"))
        .args(["drive-sim", "mr-je-c"])
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

#[test]
fn serves_modbus_and_slmp_until_sigterm() {
    let (m, u, t) = (free_tcp(), free_udp(), free_tcp());
    let args = [
        "--listen",
        "127.0.0.1",
        "--modbus-port",
        &m.to_string(),
        "--slmp-udp-port",
        &u.to_string(),
        "--slmp-tcp-port",
        &t.to_string(),
    ]
    .map(String::from);
    let child = cellrt(&args);
    let addr: SocketAddr = format!("127.0.0.1:{m}").parse().unwrap();
    let end = Instant::now() + Duration::from_secs(30);
    let client = loop {
        match TcpClient::connect(addr, Duration::from_secs(1)) {
            Ok(c) => break c,
            Err(e) if Instant::now() > end => panic!("drive-sim did not listen: {e}"),
            Err(_) => std::thread::sleep(Duration::from_millis(50)),
        }
    };
    let mut drive = OverModbus::new(client, Default::default());
    // Switch on disabled after power-on, main power on.
    assert_eq!(drive.read::<Statusword>().unwrap().0 & 0x4F, 0x40);
    let udp: SocketAddr = format!("127.0.0.1:{u}").parse().unwrap();
    let mut slmp = SlmpClient::udp(udp, FrameType::E4, Duration::from_secs(2)).unwrap();
    assert_eq!(slmp.model().unwrap().0, "MR-JE-20C");
    drop(drive);
    nix::sys::signal::kill(
        nix::unistd::Pid::from_raw(child.id() as i32),
        nix::sys::signal::Signal::SIGTERM,
    )
    .unwrap();
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    assert!(
        stderr.contains("MR-JE-20C (software A4) on Modbus/TCP 127.0.0.1:"),
        "{stderr}"
    );
    assert!(stderr.contains("stopped after"), "{stderr}");
}

#[test]
fn bad_arguments_are_refused() {
    let out = cellrt(&["--listen", "127.0.0.1", "--software", "B7"].map(String::from))
        .wait_with_output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("software version \"B7\""), "{stderr}");
    // A port taken by someone else.
    let taken = TcpListener::bind("127.0.0.1:0").unwrap();
    let port = taken.local_addr().unwrap().port().to_string();
    let out = cellrt(&["--listen", "127.0.0.1", "--modbus-port", &port].map(String::from))
        .wait_with_output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("error: cannot listen on 127.0.0.1"),
        "{stderr}"
    );
}
