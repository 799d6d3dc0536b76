//! A blocking cyclic master for a group of MR-JE-C stations, or one (MR-JE-C manual §2.2.1,
//! §2.5.1): one request in flight, responses matched by the echoed sequence number and the
//! slave ID (a late response to an earlier request is dropped), a response deadline. Buffers
//! are allocated once.

use std::net::{IpAddr, SocketAddr, UdpSocket};
use std::time::{Duration, Instant};

use super::{CyclicError, CyclicRequest, CyclicResponse, EndCode, StationData, MAX_STATIONS};

/// Why an exchange failed.
#[derive(Debug, thiserror::Error)]
pub enum MasterError {
    /// The socket failed.
    #[error("CC-Link IE Field Basic: {0}")]
    Io(#[from] std::io::Error),
    /// A frame could not be encoded.
    #[error("CC-Link IE Field Basic: {0}")]
    Frame(#[from] CyclicError),
    /// No response before the deadline.
    #[error("CC-Link IE Field Basic: no response within {0:?}")]
    Timeout(Duration),
    /// The drive answered with an abnormal end code (e.g. CFE0h: another master).
    #[error("CC-Link IE Field Basic: end code {0:?}")]
    EndCode(EndCode),
    /// The master's or the drive's address is not IPv4.
    #[error("CC-Link IE Field Basic needs IPv4 addresses, not {0}")]
    NotIpv4(IpAddr),
    /// A group of no drives or of more than 16.
    #[error("CC-Link IE Field Basic: a group has 1–16 stations, not {0}")]
    Stations(usize),
}

/// The link's settings for one drive.
#[derive(Debug, Clone, Copy)]
pub struct MasterParams {
    /// Group No. (1–64).
    pub group: u8,
    /// Supervision timeout per request, ms (the drive's master-lost time is this × count).
    pub timeout_ms: u16,
    /// Supervision count.
    pub parallel_off_count: u16,
    /// How long to wait for a response.
    pub response_timeout: Duration,
}

impl Default for MasterParams {
    /// Group 1, 50 ms × 3 (about 5 × the drive's 10 ms response time, manual §2.2.1), 50 ms.
    fn default() -> Self {
        MasterParams {
            group: 1,
            timeout_ms: 50,
            parallel_off_count: 3,
            response_timeout: Duration::from_millis(50),
        }
    }
}

fn ipv4(ip: IpAddr) -> Result<u32, MasterError> {
    match ip {
        IpAddr::V4(v4) => Ok(u32::from(v4)),
        other => Err(MasterError::NotIpv4(other)),
    }
}

/// The largest request: the header and 16 stations.
const MAX_REQUEST: usize = 67 + 76 * MAX_STATIONS;

/// A cyclic master of a group of up to 16 drives, one occupied station each (MR-JE-C manual
/// §2.2.1): one request per cycle to the group's destination (its directed broadcast address,
/// or a single drive's address), each drive answering unicast with its own station. Answers
/// are matched by sequence number and slave ID; a late one is dropped and counted.
pub struct GroupMaster {
    socket: UdpSocket,
    destination: SocketAddr,
    request: CyclicRequest,
    timeout: Duration,
    out: [u8; MAX_REQUEST],
    inbox: [u8; 1500],
    /// Responses dropped as late (a sequence number other than the awaited one) or from a
    /// slave ID not in the group.
    pub stale: u64,
}

impl GroupMaster {
    /// A master bound to `local` (its IP is the master ID) sending to `destination`, with one
    /// station per address of `drives` (their IPs are the slave IDs), in order.
    pub fn new(
        local: SocketAddr,
        destination: SocketAddr,
        drives: &[IpAddr],
        p: MasterParams,
    ) -> Result<Self, MasterError> {
        if drives.is_empty() || drives.len() > MAX_STATIONS {
            return Err(MasterError::Stations(drives.len()));
        }
        let socket = UdpSocket::bind(local)?;
        socket.set_broadcast(true)?;
        let master_id = ipv4(socket.local_addr()?.ip())?;
        let mut station = [StationData::default(); MAX_STATIONS];
        for (s, ip) in station.iter_mut().zip(drives) {
            s.slave_id = ipv4(*ip)?;
        }
        Ok(GroupMaster {
            socket,
            destination,
            request: CyclicRequest {
                protocol_version: 2,
                unit_info: 1,
                clock_ms: 0,
                master_id,
                group: p.group,
                sequence: 0,
                timeout_ms: p.timeout_ms,
                parallel_off_count: p.parallel_off_count,
                parameter_no: 1,
                transmission: 0,
                stations: drives.len(),
                station,
            },
            timeout: p.response_timeout,
            out: [0; MAX_REQUEST],
            inbox: [0; 1500],
            stale: 0,
        })
    }

    /// The number of stations.
    pub fn stations(&self) -> usize {
        self.request.stations
    }

    /// Station `k`'s (0-based) RWw and RY for the next exchange.
    pub fn set_station(&mut self, k: usize, rww: &[u8; 64], ry: &[u8; 8]) {
        if let Some(s) = self.request.station[..self.request.stations].get_mut(k) {
            s.words = *rww;
            s.bits = *ry;
        }
    }

    /// One exchange: the request with the transmission bits `transmit` (bit k for station
    /// k + 1), then each station's response into `responses[k]` until all have answered or
    /// the response time is over (the others stay `None`). The number that answered.
    pub fn exchange(
        &mut self,
        transmit: u16,
        responses: &mut [Option<CyclicResponse>; MAX_STATIONS],
    ) -> Result<usize, MasterError> {
        let r = &mut self.request;
        r.sequence = r.sequence.wrapping_add(1);
        r.transmission = transmit;
        let n = r.encode(&mut self.out)?;
        *responses = [None; MAX_STATIONS];
        self.socket.send_to(&self.out[..n], self.destination)?;
        let stations = self.request.stations;
        let deadline = Instant::now() + self.timeout;
        let mut answered = 0;
        while answered < stations {
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                break;
            }
            self.socket.set_read_timeout(Some(left))?;
            let k = match crate::reply_read::sort(self.socket.recv(&mut self.inbox), false)? {
                crate::reply_read::Read::Bytes(k) => k,
                crate::reply_read::Read::TimedOut => break,
            };
            let Ok(response) = CyclicResponse::decode(&self.inbox[..k]) else {
                continue;
            };
            let at = self.request.station[..stations]
                .iter()
                .position(|s| s.slave_id == response.station.slave_id);
            match at {
                Some(at) if response.sequence == self.request.sequence => {
                    if responses[at].replace(response).is_none() {
                        answered += 1;
                    }
                }
                _ => self.stale += 1,
            }
        }
        Ok(answered)
    }
}

/// A cyclic master of one drive (one occupied station), addressed directly.
pub struct CyclicMaster {
    group: GroupMaster,
    /// Responses dropped as late (a sequence number other than the awaited one).
    pub stale: u64,
}

impl CyclicMaster {
    /// A master bound to `local` (its IP is the master ID) exchanging with the drive at
    /// `drive` (its IP is the station's slave ID).
    pub fn new(local: SocketAddr, drive: SocketAddr, p: MasterParams) -> Result<Self, MasterError> {
        Ok(CyclicMaster {
            group: GroupMaster::new(local, drive, &[drive.ip()], p)?,
            stale: 0,
        })
    }

    /// One exchange: RWw and RY to the station (transmission bit `transmit`), its RWr and RX
    /// back.
    pub fn exchange(
        &mut self,
        transmit: bool,
        rww: &[u8; 64],
        ry: &[u8; 8],
    ) -> Result<CyclicResponse, MasterError> {
        self.group.set_station(0, rww, ry);
        let mut responses = [None; MAX_STATIONS];
        let got = self.group.exchange(u16::from(transmit), &mut responses);
        self.stale = self.group.stale;
        got?;
        let response = responses[0].ok_or(MasterError::Timeout(self.group.timeout))?;
        if response.end_code != EndCode::Normal {
            return Err(MasterError::EndCode(response.end_code));
        }
        Ok(response)
    }
}
