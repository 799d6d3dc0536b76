//! The master's side of NodeSearch and IPAddressSet (MR-JE-C manual §2.4.3, §2.5.2): a request
//! to a broadcast (or one drive's) address on UDP 61451, the answers collected for a while.
//! With an interface named, the socket is bound to it (`SO_BINDTODEVICE`, needs CAP_NET_RAW) so
//! the broadcast leaves through that interface, and the master's MAC is the interface's.

use std::io;
use std::net::{IpAddr, Ipv4Addr, SocketAddr, UdpSocket};
use std::time::{Duration, Instant};

use socket2::{Domain, Protocol, Socket, Type};

use super::node_search::{
    decode_response, encode_request, IpAddressSet, Mac, Master, NodeInfo, SearchRequest,
    SearchResponse, IP_ADDRESS_SET, MAX_SEARCH_FRAME, NODE_SEARCH,
};

/// Where a search goes and from where.
#[derive(Debug, Clone)]
pub struct SearchLink {
    /// The broadcast or drive address and port (61451).
    pub to: SocketAddr,
    /// The interface to send through, if one is named.
    pub interface: Option<String>,
}

/// A drive that answered, and from where.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Found {
    /// The address the answer came from.
    pub from: SocketAddr,
    /// What the drive says of itself.
    pub node: NodeInfo,
}

/// The MAC address of `interface` (from sysfs).
pub fn interface_mac(interface: &str) -> io::Result<Mac> {
    let path = format!("/sys/class/net/{interface}/address");
    let text = std::fs::read_to_string(&path)
        .map_err(|e| io::Error::new(e.kind(), format!("interface {interface:?}: {e}")))?;
    text.trim()
        .parse()
        .map_err(|e| io::Error::new(io::ErrorKind::InvalidData, format!("{path}: {e}")))
}

impl SearchLink {
    /// A socket for the exchange: broadcast allowed, bound to the interface where named.
    fn socket(&self) -> io::Result<UdpSocket> {
        let socket = Socket::new(Domain::IPV4, Type::DGRAM, Some(Protocol::UDP))?;
        socket.set_broadcast(true)?;
        if let Some(i) = &self.interface {
            socket.bind_device(Some(i.as_bytes())).map_err(|e| {
                io::Error::new(
                    e.kind(),
                    format!("cannot send through interface {i:?} (needs root or CAP_NET_RAW): {e}"),
                )
            })?;
        }
        socket.bind(&SocketAddr::from((Ipv4Addr::UNSPECIFIED, 0)).into())?;
        Ok(socket.into())
    }

    /// The master's identity as the drives see it: the interface's MAC (zeros without one)
    /// and the local address that reaches `to`.
    fn master(&self) -> io::Result<Master> {
        let mac = match &self.interface {
            Some(i) => interface_mac(i)?,
            None => Mac::default(),
        };
        let probe = self.socket()?;
        probe.connect(self.to)?;
        let ip = match probe.local_addr()?.ip() {
            IpAddr::V4(v4) => v4,
            IpAddr::V6(_) => Ipv4Addr::UNSPECIFIED,
        };
        Ok(Master { mac, ip })
    }

    /// NodeSearch: every drive that answers within `window`, in the order they answered.
    pub fn search(&self, window: Duration) -> io::Result<Vec<Found>> {
        let socket = self.socket()?;
        let master = self.master()?;
        let serial = serial();
        let mut buf = [0u8; MAX_SEARCH_FRAME];
        let n = encode_request(&SearchRequest::NodeSearch(master), serial, &mut buf);
        socket.send_to(&buf[..n], self.to)?;
        let mut found = Vec::new();
        let end = Instant::now() + window;
        while let Some((k, from)) = receive(&socket, end, &mut buf)? {
            if let Ok(SearchResponse::Node(_, node)) =
                decode_response(&buf[..k], serial, NODE_SEARCH)
            {
                if !found.iter().any(|f: &Found| f.node.mac == node.mac) {
                    found.push(Found { from, node });
                }
            }
        }
        Ok(found)
    }

    /// IPAddressSet: the drive with `set.mac` takes the addresses; true once it answered within
    /// `timeout` (a drive with another MAC stays silent).
    pub fn set_address(&self, set: &IpAddressSet, timeout: Duration) -> io::Result<bool> {
        let socket = self.socket()?;
        let master = self.master()?;
        let serial = serial();
        let mut buf = [0u8; MAX_SEARCH_FRAME];
        let n = encode_request(&SearchRequest::IpAddressSet(master, *set), serial, &mut buf);
        socket.send_to(&buf[..n], self.to)?;
        let end = Instant::now() + timeout;
        while let Some((k, _)) = receive(&socket, end, &mut buf)? {
            if decode_response(&buf[..k], serial, IP_ADDRESS_SET)
                == Ok(SearchResponse::AddressSet(master.mac))
            {
                return Ok(true);
            }
        }
        Ok(false)
    }
}

/// A serial number for the 4E header, different per request.
fn serial() -> [u8; 2] {
    let t = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap_or_default();
    (t.subsec_nanos() as u16 ^ std::process::id() as u16).to_le_bytes()
}

/// The next datagram before `end`, or none once it has passed.
fn receive(
    socket: &UdpSocket,
    end: Instant,
    buf: &mut [u8; MAX_SEARCH_FRAME],
) -> io::Result<Option<(usize, SocketAddr)>> {
    loop {
        let left = end.saturating_duration_since(Instant::now());
        if left.is_zero() {
            return Ok(None);
        }
        socket.set_read_timeout(Some(left))?;
        match socket.recv_from(buf) {
            Ok(got) => return Ok(Some(got)),
            Err(e)
                if matches!(
                    e.kind(),
                    io::ErrorKind::WouldBlock | io::ErrorKind::TimedOut
                ) => {}
            Err(e) => return Err(e),
        }
    }
}
