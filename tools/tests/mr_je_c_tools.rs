//! The MR-JE-C tools on loopback: `cellrt drive-sim mr-je-c` (our Modbus/TCP and SLMP clients
//! reach it, SIGTERM ends it cleanly) and `cellrt je-c read|write` against an emulator (values,
//! end codes and exceptions, unreachable drives), bad arguments refused naming what is wrong.

use std::net::{SocketAddr, TcpListener, UdpSocket};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use cellrt_fieldbus::modbus::client::TcpClient;
use cellrt_fieldbus::mr_je_c::access::typed::Statusword;
use cellrt_fieldbus::mr_je_c::{ObjectAccess, ObjectId, OverModbus, Value};
use cellrt_fieldbus::slmp::client::{FrameType, SlmpClient};

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

/// A drive-sim on free loopback ports with `extra` arguments, and our Modbus/TCP client of it
/// once it listens; the ports (Modbus/TCP, SLMP UDP, SLMP TCP, cyclic link, NodeSearch).
fn drive_sim_on_loopback(extra: &[&str]) -> (Child, OverModbus, [u16; 5]) {
    let ports = [free_tcp(), free_udp(), free_tcp(), free_udp(), free_udp()];
    let mut args = vec!["--listen".to_string(), "127.0.0.1".to_string()];
    for (flag, port) in [
        "--modbus-port",
        "--slmp-udp-port",
        "--slmp-tcp-port",
        "--cclink-port",
        "--search-port",
    ]
    .iter()
    .zip(ports)
    {
        args.extend([flag.to_string(), port.to_string()]);
    }
    args.extend(extra.iter().map(|a| a.to_string()));
    let child = cellrt(&args);
    let addr: SocketAddr = format!("127.0.0.1:{}", ports[0]).parse().unwrap();
    let end = Instant::now() + Duration::from_secs(30);
    let client = loop {
        match TcpClient::connect(addr, Duration::from_secs(1)) {
            Ok(c) => break c,
            Err(e) if Instant::now() > end => panic!("drive-sim did not listen: {e}"),
            Err(_) => std::thread::sleep(Duration::from_millis(50)),
        }
    };
    (child, OverModbus::new(client, Default::default()), ports)
}

/// Ends `child` with SIGTERM; its exit code and what it printed.
fn terminate(child: Child) -> (Option<i32>, String) {
    nix::sys::signal::kill(
        nix::unistd::Pid::from_raw(child.id() as i32),
        nix::sys::signal::Signal::SIGTERM,
    )
    .unwrap();
    let out = child.wait_with_output().unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The response mapping's number of entries (1A00h:0).
fn mapped_entries(drive: &mut OverModbus) -> Value {
    drive.read_object(ObjectId::new(0x1A00, 0)).unwrap()
}

#[test]
fn serves_modbus_and_slmp_until_sigterm() {
    let (child, mut drive, [_, u, _, _, n]) = drive_sim_on_loopback(&[]);
    // Switch on disabled after power-on, main power on.
    assert_eq!(drive.read::<Statusword>().unwrap().0 & 0x4F, 0x40);
    // Table 2.2's default response mapping: 15 entries (§7.4.6).
    assert_eq!(mapped_entries(&mut drive), Value::U8(15));
    let udp: SocketAddr = format!("127.0.0.1:{u}").parse().unwrap();
    let mut slmp = SlmpClient::udp(udp, FrameType::E4, Duration::from_secs(2)).unwrap();
    assert_eq!(slmp.model().unwrap().0, "MR-JE-20C");
    drop(drive);
    let (code, stderr) = terminate(child);
    assert_eq!(code, Some(0), "{stderr}");
    assert!(
        stderr.contains("MR-JE-20C (software A4, MAC 02:00:7F:00:00:01) on Modbus/TCP 127.0.0.1:"),
        "{stderr}"
    );
    assert!(
        stderr.contains("(link devices of Table 2.2 (profile))"),
        "{stderr}"
    );
    assert!(
        stderr.contains(&format!("NodeSearch UDP 127.0.0.1:{n}")),
        "{stderr}"
    );
    assert!(stderr.contains("stopped after"), "{stderr}");
}

/// `--link-layout positioning`: the drive's cyclic link follows the manual's Table 2.3, whose
/// default response mapping has 20 entries (§7.4.6).
#[test]
fn the_positioning_link_layout_is_table_2_3() {
    let (child, mut drive, _) = drive_sim_on_loopback(&["--link-layout", "positioning"]);
    assert_eq!(mapped_entries(&mut drive), Value::U8(20));
    drop(drive);
    let (code, stderr) = terminate(child);
    assert_eq!(code, Some(0), "{stderr}");
    assert!(
        stderr.contains("(link devices of Table 2.3 (positioning))"),
        "{stderr}"
    );
}

#[test]
fn bad_arguments_are_refused() {
    let out = cellrt(&["--listen", "127.0.0.1", "--software", "B7"].map(String::from))
        .wait_with_output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("software version \"B7\""), "{stderr}");
    let out = cellrt(&["--listen", "127.0.0.1", "--link-layout", "2.4"].map(String::from))
        .wait_with_output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains(
            "link layout \"2.4\": expected profile (Table 2.2) or positioning (Table 2.3)"
        ),
        "{stderr}"
    );
    // A port taken by someone else.
    let taken = TcpListener::bind("127.0.0.1:0").unwrap();
    let port = taken.local_addr().unwrap().port().to_string();
    let c = free_udp().to_string();
    let out = cellrt(
        &[
            "--listen",
            "127.0.0.1",
            "--modbus-port",
            &port,
            "--cclink-port",
            &c,
        ]
        .map(String::from),
    )
    .wait_with_output()
    .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("error: cannot listen on 127.0.0.1"),
        "{stderr}"
    );
}

fn je_c(args: &[&str]) -> (Option<i32>, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_cellrt"))
        .arg("je-c")
        .args(args)
        .output()
        .unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn je_c_reads_and_writes_objects() {
    use cellrt_emulator::mr_je_c::server::{Ports, Server};
    use cellrt_emulator::mr_je_c::{MrJeC, MrJeCParams};
    let any = Ports::ANY;
    let s = Server::start(
        MrJeC::new(MrJeCParams::default()),
        "127.0.0.1".parse().unwrap(),
        any,
    )
    .unwrap();
    let (udp, tcp, modbus) = (
        s.slmp_udp.to_string(),
        s.slmp_tcp.to_string(),
        s.modbus_tcp.to_string(),
    );
    let (code, out, err) = je_c(&["write", &udp, "607A", "-5000"]);
    assert_eq!(code, Some(0), "{err}");
    assert_eq!(out, "607Ah:0 Target position written -5000 pos units\n");
    let (code, out, _) = je_c(&["read", &modbus, "607a", "--via", "modbus-tcp"]);
    assert_eq!(
        (code, out.as_str()),
        (Some(0), "607Ah:0 Target position = -5000 pos units\n")
    );
    let (code, out, _) = je_c(&["read", &tcp, "1018:2", "--via", "slmp-tcp"]);
    assert_eq!(
        (code, out.as_str()),
        (Some(0), "1018h:2 Product Code = 4099 (00001003h)\n")
    );
    // A read-only object is refused by the dictionary before anything is sent: exit 2.
    let (code, _, err) = je_c(&["write", &udp, "6041", "0"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("6041h:0: read-only"), "{err}");
    // The drive refuses: exit 3 with the end code or the exception.
    let (code, _, err) = je_c(&["write", &udp, "6098", "40"]);
    assert_eq!(code, Some(3), "{err}");
    assert!(err.contains("end code"), "{err}");
    let (code, _, err) = je_c(&["write", &modbus, "6098", "40", "--via", "modbus-tcp"]);
    assert_eq!(code, Some(3), "{err}");
    assert!(err.contains("exception 03h"), "{err}");
    // Bad input: exit 2 naming the object or value.
    let (code, _, err) = je_c(&["read", &udp, "5FFF"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("object 5FFFh:0: not in the MR-JE-C object dictionary"),
        "{err}"
    );
    let (code, _, err) = je_c(&["write", &udp, "6060", "300"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("value for 6060h:0"), "{err}");
    // Nobody there: exit 4.
    let gone = free_tcp().to_string();
    let (code, _, err) = je_c(&[
        "read",
        &format!("127.0.0.1:{gone}"),
        "6041",
        "--via",
        "modbus-tcp",
    ]);
    assert_eq!(code, Some(4), "{err}");
    assert!(err.starts_with("error: 127.0.0.1:"), "{err}");
}

/// `cellrt drive-sim mr-je-c --rs485-pty`: two stations on a Modbus RTU line over a
/// pseudo-terminal, reached by `cellrt je-c --via modbus-rtu`; an absent station is silent
/// (exit 4), a bad station number or bit rate refused (exit 2); SIGTERM removes the link.
#[test]
fn je_c_over_modbus_rtu_on_an_emulated_line() {
    let dir = tempfile::tempdir().unwrap();
    let link = dir.path().join("line");
    let path = link.to_str().unwrap().to_string();
    let child = cellrt(&["--rs485-pty", &path, "--stations", "1,2"].map(String::from));
    let end = Instant::now() + Duration::from_secs(30);
    while !link.exists() {
        assert!(Instant::now() < end, "drive-sim made no line at {path}");
        std::thread::sleep(Duration::from_millis(50));
    }
    let rtu = |args: &[&str]| {
        let mut all = args.to_vec();
        all.extend(["--via", "modbus-rtu"]);
        je_c(&all)
    };
    let (code, out, err) = rtu(&["write", &path, "607A", "-5000", "--station", "2"]);
    assert_eq!(code, Some(0), "{err}");
    assert!(out.contains("written -5000"), "{out}");
    let (code, out, _) = rtu(&["read", &path, "607A", "--station", "2"]);
    assert_eq!(code, Some(0));
    assert!(out.contains("= -5000"), "{out}");
    // Station 1 is another drive.
    let (_, out, _) = rtu(&["read", &path, "607A", "--station", "1"]);
    assert!(out.contains("= 0 "), "{out}");
    let (code, _, err) = rtu(&[
        "read",
        &path,
        "6041",
        "--station",
        "3",
        "--timeout-ms",
        "200",
    ]);
    assert_eq!(code, Some(4), "{err}");
    assert!(err.contains("station 3: no reply"), "{err}");
    let (code, _, err) = rtu(&["read", &path, "6041", "--station", "0"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("--station 0"), "{err}");
    let (code, _, err) = rtu(&["read", &path, "6041", "--baud", "14400"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("14400"), "{err}");
    nix::sys::signal::kill(
        nix::unistd::Pid::from_raw(child.id() as i32),
        nix::sys::signal::Signal::SIGTERM,
    )
    .unwrap();
    let out = child.wait_with_output().unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(!link.exists(), "the link outlived drive-sim");
}

/// As root, two emulated drives in a network namespace behind a veth pair: `je-c scan` on the
/// near end finds both by a broadcast NodeSearch, `je-c set-ip` by broadcast changes the
/// addresses of the one with its MAC only ([Pr. PN11]–[Pr. PN14], read back over SLMP), and
/// one cyclic request to the directed broadcast 10.77.0.255 is answered by both stations.
/// Skipped, saying why, without root.
#[test]
fn broadcasts_reach_the_drives_in_a_namespace() {
    use cellrt_rt_tests::netns::VethNamespace;
    let ns = match VethNamespace::create(&format!("jc{}", std::process::id() % 100_000)) {
        Ok(ns) => ns,
        Err(why) => {
            println!("SKIPPED broadcasts_reach_the_drives_in_a_namespace: {why}");
            return;
        }
    };
    let ip = |args: &[&str]| {
        let ok = Command::new("ip").args(args).status().unwrap().success();
        assert!(ok, "ip {args:?}");
    };
    ip(&["addr", "add", "10.77.0.1/24", "dev", &ns.near]);
    for a in ["10.77.0.2/24", "10.77.0.3/24"] {
        ip(&["-n", &ns.namespace, "addr", "add", a, "dev", &ns.far]);
    }
    let exe = std::path::Path::new(env!("CARGO_BIN_EXE_cellrt"));
    let drives: Vec<Child> = ["10.77.0.2", "10.77.0.3"]
        .iter()
        .map(|addr| {
            ns.command(exe)
                .args(["drive-sim", "mr-je-c", "--listen", addr])
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .spawn()
                .unwrap()
        })
        .collect();
    let scan = || {
        Command::new(exe)
            .args(["je-c", "scan", "--interface", &ns.near, "--wait-ms", "500"])
            .output()
            .unwrap()
    };
    let end = Instant::now() + Duration::from_secs(30);
    let table = loop {
        let out = scan();
        let text = String::from_utf8_lossy(&out.stdout).into_owned();
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        if text.contains("02:00:0A:4D:00:02") && text.contains("02:00:0A:4D:00:03") {
            break text;
        }
        assert!(
            Instant::now() < end,
            "scan did not find both drives:\n{text}"
        );
        std::thread::sleep(Duration::from_millis(200));
    };
    assert!(
        table.contains("10.77.0.2 ") && table.contains("10.77.0.3 "),
        "{table}"
    );
    let out = Command::new(exe)
        .args([
            "je-c",
            "set-ip",
            "02:00:0A:4D:00:03",
            "10.77.0.33",
            "--interface",
            &ns.near,
        ])
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let pn14 = |drive: &str| je_c(&["read", drive, "258E"]).1;
    assert!(pn14("10.77.0.3").contains("= 33 "), "{}", pn14("10.77.0.3"));
    assert!(pn14("10.77.0.2").contains("= 0 "), "{}", pn14("10.77.0.2"));
    directed_broadcast_cycle();
    for mut d in drives {
        let _ = d.kill();
        let _ = d.wait();
    }
}

/// Cyclic exchanges of a two-station group to 10.77.0.255: both drives answer each, with their
/// own slave IDs.
fn directed_broadcast_cycle() {
    use cellrt_fieldbus::cclink_ief_basic::master::{GroupMaster, MasterParams};
    use cellrt_fieldbus::cclink_ief_basic::MAX_STATIONS;
    use std::net::{IpAddr, Ipv4Addr};
    let drives: [IpAddr; 2] = [
        Ipv4Addr::new(10, 77, 0, 2).into(),
        Ipv4Addr::new(10, 77, 0, 3).into(),
    ];
    let p = MasterParams {
        response_timeout: Duration::from_secs(2),
        ..Default::default()
    };
    let mut m = GroupMaster::new(
        "10.77.0.1:0".parse().unwrap(),
        "10.77.0.255:61450".parse().unwrap(),
        &drives,
        p,
    )
    .unwrap();
    let mut responses = [None; MAX_STATIONS];
    // A drive takes a new master by a request that does not transmit to it (§2.5.1).
    assert_eq!(m.exchange(0, &mut responses).unwrap(), 2);
    assert_eq!(m.exchange(0b11, &mut responses).unwrap(), 2);
    for (k, ip) in drives.iter().enumerate() {
        let r = responses[k].expect("station answered");
        let IpAddr::V4(v4) = ip else { unreachable!() };
        assert_eq!(r.station.slave_id, u32::from(*v4), "station {}", k + 1);
    }
    assert_eq!(m.stale, 0);
}
