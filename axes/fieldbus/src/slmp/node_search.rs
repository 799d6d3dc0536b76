//! SLMP NodeSearch (0E30h) and IPAddressSet (0E31h) in 4E frames, as the MR-JE-C takes them on
//! UDP 61451 (CC-Link IE Field Basic) (MR-JE-C manual §2.4.3, §2.5.2, §5.2.3): the master finds
//! drives by a broadcast and sets the IP address, subnet mask and default gateway of one chosen
//! by its MAC address; the drive keeps them in [Pr. PN11]–[Pr. PN22], effective at the next
//! power-on. The manual lists the commands without their data; the layout is the CLPA one as
//! an independent open implementation (rt-labs c-link) has it: MAC addresses in reversed byte
//! order, IPv4 addresses little-endian, each preceded by its size (4).

use std::net::Ipv4Addr;

use super::frame::{head, read_head, Route, SlmpError, Subheader};

/// NodeSearch.
pub const NODE_SEARCH: u16 = 0x0E30;
/// IPAddressSet.
pub const IP_ADDRESS_SET: u16 = 0x0E31;
/// "Not set" in an address field (target IP, gateway) and the target port.
const NOT_SET: u32 = 0xFFFF_FFFF;
/// Protocol settings: UDP.
const PROTOCOL_UDP: u8 = 0x01;
/// The largest frame of either command.
pub const MAX_SEARCH_FRAME: usize = 128;

/// An Ethernet MAC address, in wire order of its display (`00:1A:…`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Mac(pub [u8; 6]);

impl std::fmt::Display for Mac {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let m = self.0;
        write!(
            f,
            "{:02X}:{:02X}:{:02X}:{:02X}:{:02X}:{:02X}",
            m[0], m[1], m[2], m[3], m[4], m[5]
        )
    }
}

/// Text that is not a MAC address.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("MAC address {0:?}: expected six hex bytes like 02:00:5E:10:00:01")]
pub struct ParseMacError(pub String);

impl std::str::FromStr for Mac {
    type Err = ParseMacError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let bad = || ParseMacError(s.to_string());
        let mut mac = [0u8; 6];
        let mut parts = s.split([':', '-']);
        for b in &mut mac {
            let p = parts.next().ok_or_else(bad)?;
            if p.len() != 2 {
                return Err(bad());
            }
            *b = u8::from_str_radix(p, 16).map_err(|_| bad())?;
        }
        if parts.next().is_some() {
            return Err(bad());
        }
        Ok(Mac(mac))
    }
}

/// The master's own identity, in every request and echoed in every response.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Master {
    /// Its MAC address.
    pub mac: Mac,
    /// Its IPv4 address.
    pub ip: Ipv4Addr,
}

/// What a drive reports of itself to a NodeSearch.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NodeInfo {
    /// The drive's MAC address.
    pub mac: Mac,
    /// Its IP address.
    pub ip: Ipv4Addr,
    /// Its subnet mask.
    pub subnet: Ipv4Addr,
    /// Its default gateway.
    pub gateway: Ipv4Addr,
    /// Vendor code.
    pub vendor_code: u16,
    /// Model code.
    pub model_code: u32,
    /// Equipment version.
    pub equipment_version: u16,
    /// Status (0000h: normal).
    pub status: u16,
    /// The port the drive answers on (61451).
    pub port: u16,
}

/// An IPAddressSet: the drive with `mac` takes `ip`, `subnet` and `gateway` (None: not set).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct IpAddressSet {
    /// The drive chosen.
    pub mac: Mac,
    /// Its new IP address.
    pub ip: Ipv4Addr,
    /// Its new subnet mask.
    pub subnet: Ipv4Addr,
    /// Its new default gateway, or none.
    pub gateway: Option<Ipv4Addr>,
}

/// A request on the search port.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SearchRequest {
    /// 0E30h from `master`.
    NodeSearch(Master),
    /// 0E31h from `master`.
    IpAddressSet(Master, IpAddressSet),
}

/// A response on the search port.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SearchResponse {
    /// A drive found.
    Node(Master, NodeInfo),
    /// A drive took the addresses (echoes the master's MAC).
    AddressSet(Mac),
}

/// Little writer over a frame buffer; every write is within [`MAX_SEARCH_FRAME`].
struct Out<'b> {
    buf: &'b mut [u8],
    at: usize,
}

impl Out<'_> {
    fn bytes(&mut self, b: &[u8]) {
        self.buf[self.at..self.at + b.len()].copy_from_slice(b);
        self.at += b.len();
    }
    fn mac(&mut self, m: Mac) {
        let mut r = m.0;
        r.reverse();
        self.bytes(&r);
    }
    fn ip(&mut self, ip: u32) {
        self.bytes(&[4]);
        self.bytes(&ip.to_le_bytes());
    }
    fn addr(&mut self, ip: Ipv4Addr) {
        self.bytes(&u32::from(ip).to_le_bytes());
    }
}

/// Little reader; a short frame is a [`SlmpError::Truncated`].
struct In<'f> {
    data: &'f [u8],
    at: usize,
    frame_len: usize,
}

impl In<'_> {
    fn bytes<const N: usize>(&mut self) -> Result<[u8; N], SlmpError> {
        let b = self
            .data
            .get(self.at..self.at + N)
            .ok_or(SlmpError::Truncated {
                got: self.frame_len,
                need: self.frame_len + self.at + N - self.data.len(),
            })?;
        self.at += N;
        Ok(b.try_into().expect("N bytes"))
    }
    fn mac(&mut self) -> Result<Mac, SlmpError> {
        let mut m = self.bytes::<6>()?;
        m.reverse();
        Ok(Mac(m))
    }
    /// An address preceded by its size, which must be 4 (IPv4).
    fn sized_ip(&mut self) -> Result<u32, SlmpError> {
        if self.bytes::<1>()? != [4] {
            return Err(SlmpError::Mismatch {
                what: "IP address size",
            });
        }
        Ok(u32::from_le_bytes(self.bytes::<4>()?))
    }
    fn addr(&mut self) -> Result<Ipv4Addr, SlmpError> {
        Ok(Ipv4Addr::from(u32::from_le_bytes(self.bytes::<4>()?)))
    }
    fn u16(&mut self) -> Result<u16, SlmpError> {
        Ok(u16::from_le_bytes(self.bytes::<2>()?))
    }
    fn end(&self) -> Result<(), SlmpError> {
        if self.at == self.data.len() {
            Ok(())
        } else {
            Err(SlmpError::Mismatch { what: "length" })
        }
    }
}

/// Master: the 4E frame of `request` with serial `serial`; its length.
pub fn encode_request(
    request: &SearchRequest,
    serial: [u8; 2],
    buf: &mut [u8; MAX_SEARCH_FRAME],
) -> usize {
    let len_at = head(Subheader::E4 { serial }, Route::default(), true, buf);
    let mut o = Out {
        buf,
        at: len_at + 2,
    };
    let (command, master) = match request {
        SearchRequest::NodeSearch(m) => (NODE_SEARCH, m),
        SearchRequest::IpAddressSet(m, _) => (IP_ADDRESS_SET, m),
    };
    o.bytes(&0u16.to_le_bytes()); // monitoring timer
    o.bytes(&command.to_le_bytes());
    o.bytes(&0u16.to_le_bytes());
    o.mac(master.mac);
    o.ip(u32::from(master.ip));
    if let SearchRequest::IpAddressSet(_, set) = request {
        o.mac(set.mac);
        o.ip(u32::from(set.ip));
        o.addr(set.subnet);
        o.addr(set.gateway.unwrap_or(Ipv4Addr::from(NOT_SET)));
        o.bytes(&[0]); // host name size
        o.ip(NOT_SET); // target IP
        o.bytes(&0xFFFFu16.to_le_bytes()); // target port
        o.bytes(&[PROTOCOL_UDP]);
    }
    let end = o.at;
    let body = (end - len_at - 2) as u16;
    buf[len_at..len_at + 2].copy_from_slice(&body.to_le_bytes());
    end
}

/// Drive: the request in `frame` and its serial, or why it is not one.
pub fn decode_request(frame: &[u8]) -> Result<(SearchRequest, [u8; 2]), SlmpError> {
    let (subheader, _route, len_at) = read_head(frame, true)?;
    let Subheader::E4 { serial } = subheader else {
        return Err(SlmpError::Mismatch { what: "frame type" });
    };
    let body = &frame[len_at + 2..];
    if usize::from(u16::from_le_bytes([frame[len_at], frame[len_at + 1]])) != body.len() {
        return Err(SlmpError::Mismatch { what: "length" });
    }
    let mut r = In {
        data: body,
        at: 0,
        frame_len: frame.len(),
    };
    let _timer = r.u16()?;
    let (command, sub) = (r.u16()?, r.u16()?);
    if sub != 0 || (command != NODE_SEARCH && command != IP_ADDRESS_SET) {
        return Err(SlmpError::Mismatch { what: "command" });
    }
    let master = Master {
        mac: r.mac()?,
        ip: Ipv4Addr::from(r.sized_ip()?),
    };
    if command == NODE_SEARCH {
        r.end()?;
        return Ok((SearchRequest::NodeSearch(master), serial));
    }
    let mac = r.mac()?;
    let ip = Ipv4Addr::from(r.sized_ip()?);
    let subnet = r.addr()?;
    let gateway = Some(r.addr()?).filter(|g| u32::from(*g) != NOT_SET);
    let host_name = r.bytes::<1>()?[0];
    r.at += usize::from(host_name);
    let _target_ip = r.sized_ip()?;
    let _target_port = r.u16()?;
    let _protocol = r.bytes::<1>()?;
    r.end()?;
    let set = IpAddressSet {
        mac,
        ip,
        subnet,
        gateway,
    };
    Ok((SearchRequest::IpAddressSet(master, set), serial))
}

/// Drive: the 4E response frame of `response` with serial `serial`; its length.
pub fn encode_response(
    response: &SearchResponse,
    serial: [u8; 2],
    buf: &mut [u8; MAX_SEARCH_FRAME],
) -> usize {
    let len_at = head(Subheader::E4 { serial }, Route::default(), false, buf);
    let mut o = Out {
        buf,
        at: len_at + 2,
    };
    o.bytes(&0u16.to_le_bytes()); // end code: normal
    match response {
        SearchResponse::Node(master, n) => {
            o.mac(master.mac);
            o.ip(u32::from(master.ip));
            o.mac(n.mac);
            o.ip(u32::from(n.ip));
            o.addr(n.subnet);
            o.addr(n.gateway);
            o.bytes(&[0]); // host name size
            o.bytes(&n.vendor_code.to_le_bytes());
            o.bytes(&n.model_code.to_le_bytes());
            o.bytes(&n.equipment_version.to_le_bytes());
            o.ip(NOT_SET); // target IP
            o.bytes(&0xFFFFu16.to_le_bytes()); // target port
            o.bytes(&n.status.to_le_bytes());
            o.bytes(&n.port.to_le_bytes());
            o.bytes(&[PROTOCOL_UDP]);
        }
        SearchResponse::AddressSet(mac) => o.mac(*mac),
    }
    let end = o.at;
    let body = (end - len_at - 2) as u16;
    buf[len_at..len_at + 2].copy_from_slice(&body.to_le_bytes());
    end
}

/// Master: the response in `frame` to a request with serial `serial` of kind `command`
/// ([`NODE_SEARCH`] or [`IP_ADDRESS_SET`]).
pub fn decode_response(
    frame: &[u8],
    serial: [u8; 2],
    command: u16,
) -> Result<SearchResponse, SlmpError> {
    let (subheader, _route, len_at) = read_head(frame, false)?;
    if subheader != (Subheader::E4 { serial }) {
        return Err(SlmpError::Mismatch { what: "serial" });
    }
    let body = &frame[len_at + 2..];
    if usize::from(u16::from_le_bytes([frame[len_at], frame[len_at + 1]])) != body.len() {
        return Err(SlmpError::Mismatch { what: "length" });
    }
    let mut r = In {
        data: body,
        at: 0,
        frame_len: frame.len(),
    };
    let end = r.u16()?;
    if end != 0 {
        return Err(SlmpError::UnknownEndCode(end));
    }
    if command == IP_ADDRESS_SET {
        let mac = r.mac()?;
        r.end()?;
        return Ok(SearchResponse::AddressSet(mac));
    }
    let master = Master {
        mac: r.mac()?,
        ip: Ipv4Addr::from(r.sized_ip()?),
    };
    let mac = r.mac()?;
    let ip = Ipv4Addr::from(r.sized_ip()?);
    let (subnet, gateway) = (r.addr()?, r.addr()?);
    let host_name = r.bytes::<1>()?[0];
    r.at += usize::from(host_name);
    let vendor_code = r.u16()?;
    let model_code = u32::from_le_bytes(r.bytes::<4>()?);
    let equipment_version = r.u16()?;
    let _target_ip = r.sized_ip()?;
    let _target_port = r.u16()?;
    let status = r.u16()?;
    let port = r.u16()?;
    let _protocol = r.bytes::<1>()?;
    r.end()?;
    Ok(SearchResponse::Node(
        master,
        NodeInfo {
            mac,
            ip,
            subnet,
            gateway,
            vendor_code,
            model_code,
            equipment_version,
            status,
            port,
        },
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    const MASTER: Master = Master {
        mac: Mac([0x02, 0x00, 0x00, 0x00, 0x00, 0x01]),
        ip: Ipv4Addr::new(192, 168, 3, 100),
    };

    /// The request bytes: 4E header (5400h, serial, 0000h, net 00, station FF, 03FFh, 00),
    /// length, timer, 0E30h/0000h, then the MAC reversed, size 4 and the IP little-endian.
    #[test]
    fn node_search_request_bytes() {
        let mut buf = [0u8; MAX_SEARCH_FRAME];
        let n = encode_request(&SearchRequest::NodeSearch(MASTER), [0x34, 0x12], &mut buf);
        assert_eq!(
            &buf[..n],
            &[
                0x54, 0x00, 0x34, 0x12, 0x00, 0x00, 0x00, 0xFF, 0xFF, 0x03, 0x00, 0x11, 0x00, 0x00,
                0x00, 0x30, 0x0E, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x00, 0x02, 0x04, 100, 3,
                168, 192
            ]
        );
        assert_eq!(
            decode_request(&buf[..n]).unwrap(),
            (SearchRequest::NodeSearch(MASTER), [0x34, 0x12])
        );
        assert!(decode_request(&buf[..n - 1]).is_err());
    }

    #[test]
    fn ip_address_set_and_node_info_round_trip() {
        let set = IpAddressSet {
            mac: "02:00:5E:10:00:07".parse().unwrap(),
            ip: Ipv4Addr::new(10, 0, 0, 7),
            subnet: Ipv4Addr::new(255, 255, 255, 0),
            gateway: None,
        };
        let mut buf = [0u8; MAX_SEARCH_FRAME];
        let req = SearchRequest::IpAddressSet(MASTER, set);
        let n = encode_request(&req, [1, 2], &mut buf);
        assert_eq!(decode_request(&buf[..n]).unwrap(), (req, [1, 2]));
        let info = NodeInfo {
            mac: set.mac,
            ip: Ipv4Addr::new(10, 0, 0, 7),
            subnet: set.subnet,
            gateway: Ipv4Addr::new(10, 0, 0, 1),
            vendor_code: 0x0000,
            model_code: 0x1234_5678,
            equipment_version: 1,
            status: 0,
            port: 61451,
        };
        let resp = SearchResponse::Node(MASTER, info);
        let n = encode_response(&resp, [1, 2], &mut buf);
        assert_eq!(
            decode_response(&buf[..n], [1, 2], NODE_SEARCH).unwrap(),
            resp
        );
        assert!(decode_response(&buf[..n], [9, 9], NODE_SEARCH).is_err());
        let n = encode_response(&SearchResponse::AddressSet(MASTER.mac), [1, 2], &mut buf);
        assert_eq!(
            decode_response(&buf[..n], [1, 2], IP_ADDRESS_SET).unwrap(),
            SearchResponse::AddressSet(MASTER.mac)
        );
    }

    #[test]
    fn mac_text() {
        let m: Mac = "02-00-5e-10-00-07".parse().unwrap();
        assert_eq!(m.to_string(), "02:00:5E:10:00:07");
        for bad in [
            "02:00:5E:10:00",
            "02:00:5E:10:00:07:01",
            "0200:5E:10:00:07",
            "zz:00:00:00:00:00",
        ] {
            assert!(bad.parse::<Mac>().is_err(), "{bad}");
        }
    }
}
