//! `cellrt bench je-c`: the round trip of each MR-JE-C transport against the emulated drive on
//! this host, beside a raw echo on the same path, sampled in the same ticks. Every tick (the
//! drive's 10 ms response time by default) runs one exchange of each path in turn:
//!
//! * `cclink`: one CC-Link IE Field Basic cyclic exchange (UDP), against `udp-echo`;
//! * `cclink-bare`: the same exchange against a bare responder (it decodes the request and
//!   answers at once, no drive behind it), against `udp-echo`: the client's own cost;
//! * `slmp-udp` / `slmp-tcp`: an SLMP 4020h upload of 6041h, against `udp-echo` / `tcp-echo`;
//! * `modbus-tcp`: a Modbus/TCP 03h read of 6041h, against `tcp-echo`;
//! * `modbus-rtu`: a Modbus RTU 03h read on a pseudo-terminal line, against `pty-echo`. Its
//!   round trip includes the frame silence the drive waits for before answering (3.5
//!   characters, at least 1.75 ms: MR-JE-C manual §4.5).
//!
//! The echoes answer a datagram, a TCP segment or a burst of the same size at once. A failed
//! exchange (no answer within the response time) counts as lost; the cyclic link must lose
//! none. The client's buffers are allocated once (counting-allocator tests in the crate's tests
//! prove the cyclic client allocation-free per cycle).

use std::io::{Read, Write};
use std::net::{IpAddr, Ipv4Addr, TcpListener, TcpStream, UdpSocket};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use cellrt_emulator::mr_je_c::rs485::Rs485Line;
use cellrt_emulator::mr_je_c::server::{Ports, Server};
use cellrt_emulator::mr_je_c::{MrJeC, MrJeCParams};
use cellrt_fieldbus::cclink_ief_basic::master::{GroupMaster, MasterParams};
use cellrt_fieldbus::cclink_ief_basic::MAX_STATIONS;
use cellrt_fieldbus::modbus::client::{Registers, TcpClient};
use cellrt_fieldbus::modbus::serial::{LineSettings, RtuClient};
use cellrt_fieldbus::mr_je_c::{ObjectId, Value};
use cellrt_fieldbus::slmp::client::{FrameType, SlmpClient};
use cellrt_fieldbus::slmp::Command;
use cellrt_runtime::rt::histogram::{NsHistogram, Percentiles};
use serde::Serialize;
use serialport::{SerialPort, TTYPort};

use crate::BenchError;

/// The paths measured, in the order of each tick.
pub const PATHS: [&str; 9] = [
    "cclink",
    "cclink-bare",
    "udp-echo",
    "slmp-udp",
    "slmp-tcp",
    "modbus-tcp",
    "tcp-echo",
    "modbus-rtu",
    "pty-echo",
];

/// What to run.
#[derive(Debug, Clone, Serialize)]
pub struct JeCBenchOptions {
    /// Time between ticks.
    pub interval_ms: u64,
    /// Length of the run, s.
    pub duration_s: f64,
    /// The paths to measure (names of [`PATHS`]).
    pub paths: Vec<String>,
}

/// One path's figures.
#[derive(Debug, Clone, Serialize)]
pub struct PathReport {
    /// Path name.
    pub path: String,
    /// Round-trip percentiles.
    pub round_trip: Percentiles,
    /// Exchanges without an answer in time.
    pub lost: u64,
    /// The raw echo it is compared with, and the p50 difference, µs.
    pub against: Option<(String, f64)>,
}

/// The result.
#[derive(Debug, Clone, Serialize)]
pub struct JeCBenchReport {
    /// What ran.
    pub options: JeCBenchOptions,
    /// Ticks run.
    pub ticks: u64,
    /// Per path.
    pub paths: Vec<PathReport>,
}

/// The raw echo a transport is compared with.
fn raw_of(path: &str) -> Option<&'static str> {
    match path {
        "cclink" | "cclink-bare" | "slmp-udp" => Some("udp-echo"),
        "slmp-tcp" | "modbus-tcp" => Some("tcp-echo"),
        "modbus-rtu" => Some("pty-echo"),
        _ => None,
    }
}

/// The emulated drive, the RS-485 line, the echoes, and a client of each.
struct Bench {
    stop: Arc<AtomicBool>,
    _server: Server,
    _line: Rs485Line,
    cclink: GroupMaster,
    /// The last cyclic exchange went unanswered.
    cclink_lost: bool,
    /// A master of the bare responder.
    cclink_bare: GroupMaster,
    slmp_udp: SlmpClient,
    slmp_tcp: SlmpClient,
    modbus_tcp: TcpClient,
    modbus_rtu: RtuClient,
    udp_echo: UdpSocket,
    tcp_echo: TcpStream,
    pty_echo: TTYPort,
    words: [u16; 1],
    buf: [u8; 256],
}

const TIMEOUT: Duration = Duration::from_millis(100);
const STATUSWORD: ObjectId = ObjectId::new(0x6041, 0);

fn failed(what: &str) -> impl Fn(String) -> BenchError + '_ {
    move |e| BenchError::failed(format!("{what}: {e}"))
}

impl Bench {
    fn start() -> Result<Bench, BenchError> {
        let ip = IpAddr::V4(Ipv4Addr::LOCALHOST);
        let server = Server::start(MrJeC::new(MrJeCParams::default()), ip, Ports::ANY)
            .map_err(|e| failed("the emulated drive")(e.to_string()))?;
        let (master, slave) =
            TTYPort::pair().map_err(|e| failed("a pseudo-terminal")(e.to_string()))?;
        let mut rtu_drive = MrJeC::new(MrJeCParams::default());
        for (index, v) in [(0x2588, 0x1000), (0x2146, 1)] {
            rtu_drive
                .write(ObjectId::new(index, 0), &Value::U32(v), Duration::ZERO)
                .map_err(|e| failed("the RS-485 drive")(e.to_string()))?;
        }
        let line = LineSettings::default();
        let rs485 = Rs485Line::start(vec![rtu_drive], Box::new(master), line)
            .map_err(|e| failed("the RS-485 line")(e.to_string()))?;
        let stop = Arc::new(AtomicBool::new(false));
        let params = MasterParams {
            response_timeout: TIMEOUT,
            ..Default::default()
        };
        let mut cclink = GroupMaster::new((ip, 0).into(), server.cclink, &[ip], params)
            .map_err(|e| failed("the cyclic master")(e.to_string()))?;
        // A drive takes a new master by a request that does not transmit to it.
        let mut r = [None; MAX_STATIONS];
        cclink
            .exchange(0, &mut r)
            .map_err(|e| failed("the cyclic link")(e.to_string()))?;
        let bare = bare_responder(&stop)?;
        let mut cclink_bare = GroupMaster::new((ip, 0).into(), bare, &[ip], params)
            .map_err(|e| failed("the bare responder's master")(e.to_string()))?;
        cclink_bare
            .exchange(0, &mut r)
            .map_err(|e| failed("the bare responder")(e.to_string()))?;
        let (echo_pty, client_pty) =
            TTYPort::pair().map_err(|e| failed("a pseudo-terminal")(e.to_string()))?;
        Ok(Bench {
            udp_echo: udp_echo(&stop)?,
            tcp_echo: tcp_echo(&stop)?,
            pty_echo: {
                pty_echo(echo_pty, &stop);
                client_pty
            },
            slmp_udp: SlmpClient::udp(server.slmp_udp, FrameType::E4, TIMEOUT)
                .map_err(|e| failed("SLMP UDP")(e.to_string()))?,
            slmp_tcp: SlmpClient::tcp(server.slmp_tcp, FrameType::E4, TIMEOUT)
                .map_err(|e| failed("SLMP TCP")(e.to_string()))?,
            modbus_tcp: TcpClient::connect(server.modbus_tcp, TIMEOUT)
                .map_err(|e| failed("Modbus/TCP")(e.to_string()))?,
            modbus_rtu: RtuClient::new(Box::new(slave), line, 1, TIMEOUT)
                .map_err(|e| failed("Modbus RTU")(e.to_string()))?,
            cclink,
            cclink_lost: false,
            cclink_bare,
            stop,
            _server: server,
            _line: rs485,
            words: [0],
            buf: [0; 256],
        })
    }

    /// One exchange on `path`; false when it got no answer in time.
    fn exchange(&mut self, path: &str) -> bool {
        match path {
            "cclink" => {
                let mut r = [None; MAX_STATIONS];
                if self.cclink_lost {
                    // A stall past the drive's supervision time dropped the master: the drive
                    // takes it again by a request that does not transmit to it.
                    let _ = self.cclink.exchange(0, &mut r);
                }
                let ok = self.cclink.exchange(1, &mut r).is_ok_and(|n| n == 1);
                self.cclink_lost = !ok;
                ok
            }
            "cclink-bare" => {
                let mut r = [None; MAX_STATIONS];
                self.cclink_bare.exchange(1, &mut r).is_ok_and(|n| n == 1)
            }
            "slmp-udp" => upload(&mut self.slmp_udp),
            "slmp-tcp" => upload(&mut self.slmp_tcp),
            "modbus-tcp" => self
                .modbus_tcp
                .read_registers(0x6041, &mut self.words)
                .is_ok(),
            "modbus-rtu" => self
                .modbus_rtu
                .read_registers(0x6041, &mut self.words)
                .is_ok(),
            "udp-echo" => {
                let socket = &self.udp_echo;
                socket.send(&self.buf[..72]).is_ok() && socket.recv(&mut self.buf).is_ok()
            }
            "tcp-echo" => {
                self.tcp_echo.write_all(&self.buf[..21]).is_ok()
                    && self.tcp_echo.read_exact(&mut self.buf[..21]).is_ok()
            }
            _ => {
                self.pty_echo.write_all(&self.buf[..8]).is_ok()
                    && self.pty_echo.read_exact(&mut self.buf[..7]).is_ok()
            }
        }
    }
}

impl Drop for Bench {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
    }
}

fn upload(c: &mut SlmpClient) -> bool {
    c.request(Command::Upload {
        index: STATUSWORD.index,
        sub: STATUSWORD.sub,
    })
    .is_ok()
}

/// A UDP echo on loopback; the client socket connected to it.
fn udp_echo(stop: &Arc<AtomicBool>) -> Result<UdpSocket, BenchError> {
    let io = |e: std::io::Error| failed("the UDP echo")(e.to_string());
    let server = UdpSocket::bind("127.0.0.1:0").map_err(io)?;
    server
        .set_read_timeout(Some(Duration::from_millis(50)))
        .map_err(io)?;
    let client = UdpSocket::bind("127.0.0.1:0").map_err(io)?;
    client
        .connect(server.local_addr().map_err(io)?)
        .map_err(io)?;
    client.set_read_timeout(Some(TIMEOUT)).map_err(io)?;
    let stop = stop.clone();
    std::thread::spawn(move || {
        let mut buf = [0u8; 1500];
        while !stop.load(Ordering::Relaxed) {
            if let Ok((n, peer)) = server.recv_from(&mut buf) {
                let _ = server.send_to(&buf[..n], peer);
            }
        }
    });
    Ok(client)
}

/// A bare cyclic responder on loopback: decodes each request and answers its station at
/// once (sequence and group echoed, zero RWr/RX); its address.
fn bare_responder(stop: &Arc<AtomicBool>) -> Result<std::net::SocketAddr, BenchError> {
    use cellrt_fieldbus::cclink_ief_basic::{
        CyclicRequest, CyclicResponse, EndCode, StationData, RESPONSE_SIZE,
    };
    let io = |e: std::io::Error| failed("the bare responder")(e.to_string());
    let socket = UdpSocket::bind("127.0.0.1:0").map_err(io)?;
    socket
        .set_read_timeout(Some(Duration::from_millis(50)))
        .map_err(io)?;
    let addr = socket.local_addr().map_err(io)?;
    let own = u32::from(Ipv4Addr::LOCALHOST);
    let stop = stop.clone();
    std::thread::spawn(move || {
        let (mut buf, mut out) = ([0u8; 1500], [0u8; RESPONSE_SIZE]);
        while !stop.load(Ordering::Relaxed) {
            let Ok((n, peer)) = socket.recv_from(&mut buf) else {
                continue;
            };
            let Ok(req) = CyclicRequest::decode(&buf[..n], own) else {
                continue;
            };
            let response = CyclicResponse {
                protocol_version: req.protocol_version,
                end_code: EndCode::Normal,
                vendor_code: 0,
                model_code: 0,
                equipment_version: 0,
                unit_info: 1,
                error_code: 0,
                local_info: 0,
                group: req.group,
                sequence: req.sequence,
                station: StationData {
                    slave_id: own,
                    ..StationData::default()
                },
            };
            if let Ok(k) = response.encode(&mut out) {
                let _ = socket.send_to(&out[..k], peer);
            }
        }
    });
    Ok(addr)
}

/// A TCP echo on loopback; the client's connection to it.
fn tcp_echo(stop: &Arc<AtomicBool>) -> Result<TcpStream, BenchError> {
    let io = |e: std::io::Error| failed("the TCP echo")(e.to_string());
    let listener = TcpListener::bind("127.0.0.1:0").map_err(io)?;
    let client = TcpStream::connect(listener.local_addr().map_err(io)?).map_err(io)?;
    client.set_nodelay(true).map_err(io)?;
    client.set_read_timeout(Some(TIMEOUT)).map_err(io)?;
    let (mut conn, _) = listener.accept().map_err(io)?;
    conn.set_nodelay(true).map_err(io)?;
    conn.set_read_timeout(Some(Duration::from_millis(50)))
        .map_err(io)?;
    let stop = stop.clone();
    std::thread::spawn(move || {
        let mut buf = [0u8; 1500];
        while !stop.load(Ordering::Relaxed) {
            match conn.read(&mut buf) {
                Ok(0) => return,
                Ok(n) => {
                    let _ = conn.write_all(&buf[..n]);
                }
                Err(_) => {}
            }
        }
    });
    Ok(client)
}

/// A pseudo-terminal that answers each burst with a 7-byte one at once.
fn pty_echo(mut port: TTYPort, stop: &Arc<AtomicBool>) {
    let _ = port.set_timeout(Duration::from_millis(50));
    let stop = stop.clone();
    std::thread::spawn(move || {
        let mut buf = [0u8; 256];
        while !stop.load(Ordering::Relaxed) {
            if port.read(&mut buf).is_ok_and(|n| n > 0) {
                let _ = port.write_all(&buf[..7]);
            }
        }
    });
}

/// Runs the benchmark.
pub fn run(opts: &JeCBenchOptions) -> Result<JeCBenchReport, BenchError> {
    if opts.interval_ms == 0 || opts.interval_ms > 1000 {
        return Err(BenchError::bad("--interval-ms: must be 1..=1000"));
    }
    if !(opts.duration_s.is_finite() && opts.duration_s > 0.0 && opts.duration_s <= 86_400.0) {
        return Err(BenchError::bad(
            "--duration: must be > 0 and at most 86400 s",
        ));
    }
    if let Some(bad) = opts.paths.iter().find(|p| !PATHS.contains(&p.as_str())) {
        return Err(BenchError::bad(format!(
            "--paths: unknown path {bad:?}; the paths are {}",
            PATHS.join(", ")
        )));
    }
    let paths: Vec<&str> = PATHS
        .iter()
        .copied()
        .filter(|p| opts.paths.is_empty() || opts.paths.iter().any(|q| q == p))
        .collect();
    let mut bench = Bench::start()?;
    let mut hist: Vec<NsHistogram> = paths.iter().map(|_| NsHistogram::new()).collect();
    let mut lost = vec![0u64; paths.len()];
    let interval = Duration::from_millis(opts.interval_ms);
    let ticks = (opts.duration_s * 1000.0 / opts.interval_ms as f64).ceil() as u64;
    let mut next = Instant::now();
    for _ in 0..ticks {
        for (k, path) in paths.iter().enumerate() {
            let t = Instant::now();
            if bench.exchange(path) {
                hist[k].record(t.elapsed().as_nanos() as u64);
            } else {
                lost[k] += 1;
            }
        }
        next += interval;
        if let Some(wait) = next.checked_duration_since(Instant::now()) {
            std::thread::sleep(wait);
        }
    }
    let p50 = |name: &str| {
        paths
            .iter()
            .position(|p| *p == name)
            .map(|k| hist[k].percentiles().p50_us)
    };
    let reports = paths
        .iter()
        .enumerate()
        .map(|(k, p)| PathReport {
            path: p.to_string(),
            round_trip: hist[k].percentiles(),
            lost: lost[k],
            against: raw_of(p).and_then(|raw| {
                let own = hist[k].percentiles().p50_us;
                p50(raw).map(|r| (raw.to_string(), own - r))
            }),
        })
        .collect();
    Ok(JeCBenchReport {
        options: opts.clone(),
        ticks,
        paths: reports,
    })
}

/// The report as a table.
pub fn render(r: &JeCBenchReport) -> String {
    let mut s = format!(
        "MR-JE-C transports on loopback, {} ticks of {} ms (each path once per tick)\n{:<11} {:>8} {:>9} {:>9} {:>9} {:>6}  {}\n",
        r.ticks, r.options.interval_ms, "path", "count", "p50 µs", "p99 µs", "max µs", "lost", "p50 over the raw echo"
    );
    for p in &r.paths {
        let x = &p.round_trip;
        s += &format!(
            "{:<11} {:>8} {:>9.1} {:>9.1} {:>9.1} {:>6}  {}\n",
            p.path,
            x.count,
            x.p50_us,
            x.p99_us,
            x.max_us,
            p.lost,
            p.against
                .as_ref()
                .map_or(String::new(), |(raw, d)| format!("{d:+.1} µs over {raw}"))
        );
    }
    s
}
