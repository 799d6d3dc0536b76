//! The simulated MR-JE-C on real sockets (MR-JE-C manual §2.2.1, §2.2.2, §3.2): Modbus/TCP (at
//! most 3 connections, each with the [Pr. PN23] alive check), SLMP over UDP (any number of
//! peers) and over TCP (1 connection), and the CC-Link IE Field Basic cyclic link on UDP
//! (answered to the sender's address). A connection beyond the limit is closed at once. One
//! request is processed at a time across all of them (the drive is behind one lock). The
//! virtual clock is the time since the server started; a ticker advances it every 10 ms so
//! that the time-outs expire while nobody talks.

use std::io::{self, Read, Write};
use std::net::{IpAddr, Ipv4Addr, SocketAddr, TcpListener, TcpStream, UdpSocket};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use super::{modbus, slmp, KeepAlive, MrJeC};
use cellrt_fieldbus::modbus::tcp;

/// How often idle threads look at the stop flag and the ticker runs.
const POLL: Duration = Duration::from_millis(10);
/// Modbus/TCP connections the drive accepts (§3.2).
pub const MODBUS_CONNECTIONS: usize = 3;
/// SLMP TCP connections the drive accepts (§2.2.2).
pub const SLMP_TCP_CONNECTIONS: usize = 1;

/// The ports to listen on (0: any free port, for tests).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Ports {
    /// Modbus/TCP (502).
    pub modbus_tcp: u16,
    /// SLMP over UDP (5010).
    pub slmp_udp: u16,
    /// SLMP over TCP (5012).
    pub slmp_tcp: u16,
    /// CC-Link IE Field Basic cyclic data (UDP 61450).
    pub cclink: u16,
    /// NodeSearch and IPAddressSet (UDP 61451).
    pub search: u16,
}

impl Ports {
    /// Any free port for each (tests).
    pub const ANY: Ports = Ports {
        modbus_tcp: 0,
        slmp_udp: 0,
        slmp_tcp: 0,
        cclink: 0,
        search: 0,
    };
}

impl Default for Ports {
    fn default() -> Self {
        Ports {
            modbus_tcp: tcp::PORT,
            slmp_udp: cellrt_fieldbus::slmp::UDP_PORT,
            slmp_tcp: cellrt_fieldbus::slmp::TCP_PORT,
            cclink: cellrt_fieldbus::cclink_ief_basic::CYCLIC_PORT,
            search: cellrt_fieldbus::cclink_ief_basic::SEARCH_PORT,
        }
    }
}

struct Shared {
    drive: Mutex<MrJeC>,
    /// The cyclic link's state (its master, CSR/SSR), whichever socket a request came by.
    cyclic: Mutex<super::cyclic::CyclicLink>,
    stop: AtomicBool,
    /// The link is cut: requests are taken off the wire and dropped unseen by the drive.
    cut: AtomicBool,
    start: Instant,
}

impl Shared {
    fn cut(&self) -> bool {
        self.cut.load(Ordering::Relaxed)
    }

    fn now(&self) -> Duration {
        self.start.elapsed()
    }

    fn drive(&self) -> MutexGuard<'_, MrJeC> {
        self.drive.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The IP filter admits `peer` (an IPv6 peer only while the filter is off).
    fn admits(&self, peer: IpAddr) -> bool {
        self.drive().address_rules().admits(v4(peer))
    }

    /// The operation specification lets `peer` write.
    fn may_operate(&self, peer: IpAddr) -> bool {
        self.drive().address_rules().may_operate(v4(peer))
    }
}

fn v4(ip: IpAddr) -> Ipv4Addr {
    match ip {
        IpAddr::V4(v4) => v4,
        IpAddr::V6(v6) => v6.to_ipv4_mapped().unwrap_or(Ipv4Addr::UNSPECIFIED),
    }
}

/// A running emulator.
pub struct Server {
    shared: Arc<Shared>,
    threads: Vec<JoinHandle<()>>,
    /// Where Modbus/TCP listens.
    pub modbus_tcp: SocketAddr,
    /// Where SLMP listens over UDP.
    pub slmp_udp: SocketAddr,
    /// Where SLMP listens over TCP.
    pub slmp_tcp: SocketAddr,
    /// Where the cyclic link listens.
    pub cclink: SocketAddr,
    /// Where NodeSearch and IPAddressSet are answered.
    pub search: SocketAddr,
}

impl Server {
    /// Serves `drive` on `ip` at `ports`; `ip` is the drive's own address, the slave ID the
    /// cyclic link looks for in a request (so give the drive's address, not 0.0.0.0).
    pub fn start(drive: MrJeC, ip: IpAddr, ports: Ports) -> io::Result<Server> {
        let shared = Arc::new(Shared {
            drive: Mutex::new(drive),
            cyclic: Mutex::new(Default::default()),
            stop: AtomicBool::new(false),
            cut: AtomicBool::new(false),
            start: Instant::now(),
        });
        let modbus = TcpListener::bind((ip, ports.modbus_tcp))?;
        let udp = UdpSocket::bind((ip, ports.slmp_udp))?;
        let slmp_tcp = TcpListener::bind((ip, ports.slmp_tcp))?;
        let cclink = UdpSocket::bind((ip, ports.cclink))?;
        let addrs = (
            modbus.local_addr()?,
            udp.local_addr()?,
            slmp_tcp.local_addr()?,
        );
        let cclink_addr = cclink.local_addr()?;
        let own = match ip {
            IpAddr::V4(v4) => u32::from(v4),
            IpAddr::V6(_) => 0,
        };
        let search = UdpSocket::bind((ip, ports.search))?;
        let search_addr = search.local_addr()?;
        let mut threads = Vec::new();
        let mut cyclic = vec![cclink];
        let mut searches = vec![search];
        if let IpAddr::V4(v4) = ip.to_canonical() {
            if !v4.is_loopback() && !v4.is_unspecified() {
                // Broadcasts reach only sockets bound to the broadcast address: the cyclic
                // link's directed broadcast, NodeSearch's limited one.
                let subnet = shared.drive().subnet_mask();
                let directed = Ipv4Addr::from(u32::from(v4) | !u32::from(subnet));
                cyclic.push(broadcast_socket(directed, cclink_addr.port())?);
                searches.push(broadcast_socket(Ipv4Addr::BROADCAST, search_addr.port())?);
            }
        }
        // Answers leave from the drive's own address, also to a broadcast.
        let cyclic_reply = cyclic[0].try_clone()?;
        for socket in cyclic {
            socket.set_read_timeout(Some(POLL))?;
            let (s, reply) = (shared.clone(), cyclic_reply.try_clone()?);
            threads.push(std::thread::spawn(move || {
                serve_cclink(&socket, &reply, own, &s)
            }));
        }
        let search_reply = searches[0].try_clone()?;
        for socket in searches {
            socket.set_read_timeout(Some(POLL))?;
            let (s, reply) = (shared.clone(), search_reply.try_clone()?);
            let own = Ipv4Addr::from(own);
            threads.push(std::thread::spawn(move || {
                serve_search(&socket, &reply, own, &s)
            }));
        }
        let s = shared.clone();
        threads.push(std::thread::spawn(move || ticker(&s)));
        let s = shared.clone();
        threads.push(accept_thread(modbus, MODBUS_CONNECTIONS, s, serve_modbus)?);
        let s = shared.clone();
        threads.push(accept_thread(
            slmp_tcp,
            SLMP_TCP_CONNECTIONS,
            s,
            serve_slmp_tcp,
        )?);
        let s = shared.clone();
        udp.set_read_timeout(Some(POLL))?;
        threads.push(std::thread::spawn(move || serve_slmp_udp(&udp, &s)));
        Ok(Server {
            shared,
            threads,
            modbus_tcp: addrs.0,
            slmp_udp: addrs.1,
            slmp_tcp: addrs.2,
            cclink: cclink_addr,
            search: search_addr,
        })
    }

    /// The simulated drive (locked: requests wait meanwhile).
    pub fn drive(&self) -> MutexGuard<'_, MrJeC> {
        self.shared.drive()
    }

    /// The emulator's clock: time since start.
    pub fn now(&self) -> Duration {
        self.shared.now()
    }

    /// Cuts the link (`true`: every request is dropped before the drive sees it, as a pulled
    /// cable would; the drive's time-outs run on) or restores it.
    pub fn cut_link(&self, cut: bool) {
        self.shared.cut.store(cut, Ordering::Relaxed);
    }

    /// Whether a stop was asked for.
    pub fn stopping(&self) -> bool {
        self.shared.stop.load(Ordering::Relaxed)
    }

    /// Stops every thread and waits for them.
    pub fn stop(mut self) {
        self.halt();
    }

    fn halt(&mut self) {
        self.shared.stop.store(true, Ordering::Relaxed);
        for t in self.threads.drain(..) {
            let _ = t.join();
        }
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        self.halt();
    }
}

fn ticker(s: &Shared) {
    while !s.stop.load(Ordering::Relaxed) {
        let now = s.now();
        s.drive().tick(now);
        std::thread::sleep(POLL);
    }
}

type Serve = fn(&mut TcpStream, &Shared) -> io::Result<()>;

/// Accepts connections up to `limit` at a time, each served by `serve` on its own thread.
fn accept_thread(
    listener: TcpListener,
    limit: usize,
    s: Arc<Shared>,
    serve: Serve,
) -> io::Result<JoinHandle<()>> {
    listener.set_nonblocking(true)?;
    Ok(std::thread::spawn(move || {
        let open = Arc::new(AtomicUsize::new(0));
        let mut conns = Vec::new();
        while !s.stop.load(Ordering::Relaxed) {
            match listener.accept() {
                Ok((stream, _)) if open.load(Ordering::SeqCst) >= limit => drop(stream),
                // The IP filter: the connection is closed at once.
                Ok((stream, peer)) if !s.admits(peer.ip()) => drop(stream),
                Ok((mut stream, _)) => {
                    open.fetch_add(1, Ordering::SeqCst);
                    let (s, open) = (s.clone(), open.clone());
                    conns.push(std::thread::spawn(move || {
                        let ok = stream
                            .set_nonblocking(false)
                            .and_then(|()| stream.set_read_timeout(Some(POLL)))
                            .and_then(|()| stream.set_nodelay(true));
                        if ok.is_ok() {
                            let _ = serve(&mut stream, &s);
                        }
                        open.fetch_sub(1, Ordering::SeqCst);
                    }));
                }
                Err(_) => std::thread::sleep(POLL),
            }
        }
        for c in conns {
            let _ = c.join();
        }
    }))
}

/// Reads into `inbox` until it holds a frame `split` can cut, or the peer leaves (`Ok(false)`)
/// or the server stops.
fn fill(stream: &mut TcpStream, s: &Shared, inbox: &mut Vec<u8>) -> io::Result<bool> {
    let mut chunk = [0u8; 1024];
    loop {
        if s.stop.load(Ordering::Relaxed) {
            return Ok(false);
        }
        match stream.read(&mut chunk) {
            Ok(0) => return Ok(false),
            Ok(k) => {
                inbox.extend_from_slice(&chunk[..k]);
                return Ok(true);
            }
            Err(e)
                if matches!(
                    e.kind(),
                    io::ErrorKind::WouldBlock | io::ErrorKind::TimedOut
                ) => {}
            Err(e) => return Err(e),
        }
    }
}

/// One Modbus/TCP connection: ADUs framed by the MBAP length; a length that cannot frame an
/// ADU closes the connection. A 10h from a client the operation specification excludes is
/// discarded without an answer.
fn serve_modbus(stream: &mut TcpStream, s: &Shared) -> io::Result<()> {
    let operate = s.may_operate(stream.peer_addr()?.ip());
    set_keep_alive(stream, s.drive().keep_alive())?;
    let mut inbox = Vec::new();
    loop {
        let cut = tcp::split(&inbox).map_err(|e| io::Error::new(io::ErrorKind::InvalidData, e))?;
        let Some((adu, used)) = cut else {
            if !fill(stream, s, &mut inbox)? {
                return Ok(());
            }
            continue;
        };
        let discard =
            s.cut() || (!operate && adu.pdu.first() == Some(&cellrt_fieldbus::modbus::WRITE));
        let reply = if discard {
            None
        } else {
            modbus::answer_adu(&mut s.drive(), &adu, s.now())
        };
        inbox.drain(..used);
        if let Some(r) = reply {
            stream.write_all(&r)?;
        }
    }
}

/// Arms the kernel's TCP keep-alive as [Pr. PN23] asks (see [`KeepAlive`]).
fn set_keep_alive(stream: &TcpStream, k: KeepAlive) -> io::Result<()> {
    let probes = socket2::TcpKeepalive::new()
        .with_time(k.interval)
        .with_interval(k.interval)
        .with_retries(super::KEEP_ALIVE_UNANSWERED);
    socket2::SockRef::from(stream).set_tcp_keepalive(&probes)
}

/// One SLMP TCP connection: frames cut by their request data length.
fn serve_slmp_tcp(stream: &mut TcpStream, s: &Shared) -> io::Result<()> {
    let operate = s.may_operate(stream.peer_addr()?.ip());
    let mut inbox = Vec::new();
    loop {
        let len = cellrt_fieldbus::slmp::client::frame_length(&inbox)
            .map_err(|e| io::Error::new(io::ErrorKind::InvalidData, e))?;
        match len {
            Some(n) if inbox.len() >= n => {
                let reply = if s.cut() {
                    None
                } else {
                    answer_slmp(s, &inbox[..n], operate)
                };
                inbox.drain(..n);
                if let Some(r) = reply {
                    stream.write_all(&r)?;
                }
            }
            _ => {
                if !fill(stream, s, &mut inbox)? {
                    return Ok(());
                }
            }
        }
    }
}

/// The answer to an SLMP frame; downloads from a peer the operation specification excludes
/// are discarded without an answer (§5.2.3 PN31–PN36), and so is the answer to a request whose
/// monitoring timer runs out while the drive processes it
/// ([`MrJeCParams::slmp_processing_time`](super::MrJeCParams::slmp_processing_time)).
fn answer_slmp(s: &Shared, frame: &[u8], operate: bool) -> Option<Vec<u8>> {
    use cellrt_fieldbus::slmp::Command;
    let request = cellrt_fieldbus::slmp::decode_request(frame).ok();
    let write = request.as_ref().is_some_and(|r| {
        matches!(
            r.command,
            Command::Download { .. } | Command::BlockDownload { .. }
        )
    });
    if write && !operate {
        return None;
    }
    let processing = s.drive().params().slmp_processing_time;
    if !processing.is_zero() {
        std::thread::sleep(processing);
        let timer = request.map_or(0, |r| r.monitoring_timer);
        if cellrt_fieldbus::slmp::monitoring_timer_expires(timer, processing) {
            return None;
        }
    }
    slmp::answer_frame(&mut s.drive(), frame, s.now())
}

fn serve_slmp_udp(socket: &UdpSocket, s: &Shared) {
    let mut buf = [0u8; cellrt_fieldbus::slmp::MAX_FRAME];
    while !s.stop.load(Ordering::Relaxed) {
        let Ok((n, peer)) = socket.recv_from(&mut buf) else {
            continue;
        };
        if s.cut() || !s.admits(peer.ip()) {
            continue;
        }
        let reply = answer_slmp(s, &buf[..n], s.may_operate(peer.ip()));
        if let Some(r) = reply {
            let _ = socket.send_to(&r, peer);
        }
    }
}

/// A UDP socket bound to the broadcast address `addr`, shared with other emulated drives on
/// the host (`SO_REUSEADDR`: each receives every broadcast).
fn broadcast_socket(addr: Ipv4Addr, port: u16) -> io::Result<UdpSocket> {
    use socket2::{Domain, Protocol, Socket, Type};
    let socket = Socket::new(Domain::IPV4, Type::DGRAM, Some(Protocol::UDP))?;
    socket.set_reuse_address(true)?;
    socket.set_broadcast(true)?;
    socket.bind(&SocketAddr::from((addr, port)).into())?;
    Ok(socket.into())
}

/// NodeSearch and IPAddressSet, answered to the sender (the IP filter applies; an
/// IPAddressSet is a write, so the operation specification too).
fn serve_search(socket: &UdpSocket, reply_from: &UdpSocket, own: Ipv4Addr, s: &Shared) {
    let mut buf = [0u8; 256];
    while !s.stop.load(Ordering::Relaxed) {
        let Ok((n, peer)) = socket.recv_from(&mut buf) else {
            continue;
        };
        if !s.admits(peer.ip()) {
            continue;
        }
        let setting = matches!(
            cellrt_fieldbus::slmp::node_search::decode_request(&buf[..n]),
            Ok((
                cellrt_fieldbus::slmp::node_search::SearchRequest::IpAddressSet(..),
                _
            ))
        );
        if setting && !s.may_operate(peer.ip()) {
            continue;
        }
        let reply = super::search::answer(&mut s.drive(), own, &buf[..n], s.now());
        if let Some(r) = reply {
            let _ = reply_from.send_to(&r, peer);
        }
    }
}

/// The cyclic link: requests from the connected master (sent to `socket`), answered to the
/// sender from `reply_from`.
fn serve_cclink(socket: &UdpSocket, reply_from: &UdpSocket, own: u32, s: &Shared) {
    let mut buf = [0u8; 1500];
    let mut out = [0u8; cellrt_fieldbus::cclink_ief_basic::RESPONSE_SIZE];
    while !s.stop.load(Ordering::Relaxed) {
        let Ok((n, peer)) = socket.recv_from(&mut buf) else {
            continue;
        };
        let IpAddr::V4(source) = peer.ip() else {
            continue;
        };
        if s.cut() || !s.admits(peer.ip()) {
            continue;
        }
        let operate = s.may_operate(peer.ip());
        let Ok(request) =
            cellrt_fieldbus::cclink_ief_basic::CyclicRequest::decode(&buf[..n], u32::from(source))
        else {
            continue;
        };
        let mut drive = s.drive();
        if !drive.serves(super::Transport::CcLink) {
            continue;
        }
        let mut link = s.cyclic.lock().unwrap_or_else(|e| e.into_inner());
        let response = link.answer(&mut drive, &request, own, operate, s.now());
        drop(link);
        drop(drive);
        if let Some(r) = response {
            if let Ok(k) = r.encode(&mut out) {
                let _ = reply_from.send_to(&out[..k], peer);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The kernel holds the alive check [Pr. PN23] asks for on a served connection.
    #[test]
    fn a_modbus_connection_carries_the_pn23_alive_check() {
        let listener = TcpListener::bind((Ipv4Addr::LOCALHOST, 0)).unwrap();
        let _client = TcpStream::connect(listener.local_addr().unwrap()).unwrap();
        let (served, _) = listener.accept().unwrap();
        let k = KeepAlive {
            interval: Duration::from_secs(45),
        };
        set_keep_alive(&served, k).unwrap();
        let sock = socket2::SockRef::from(&served);
        assert!(sock.keepalive().unwrap());
        assert_eq!(sock.tcp_keepalive_time().unwrap(), Duration::from_secs(45));
        assert_eq!(
            sock.tcp_keepalive_interval().unwrap(),
            Duration::from_secs(45)
        );
        assert_eq!(sock.tcp_keepalive_retries().unwrap(), 7);
        assert_eq!(k.close_after(), Duration::from_secs(360));
    }
}
