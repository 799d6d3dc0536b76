//! A blocking cyclic master for one MR-JE-C station (MR-JE-C manual §2.2.1, §2.5.1): one
//! request in flight, responses matched by the echoed sequence number (a late response to an
//! earlier request is dropped), a response deadline. Buffers are allocated once.

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

/// A cyclic master of one drive (one occupied station).
pub struct CyclicMaster {
    socket: UdpSocket,
    drive: SocketAddr,
    request: CyclicRequest,
    timeout: Duration,
    out: [u8; 67 + 76],
    inbox: [u8; 1500],
    /// Responses dropped as late (a sequence number other than the awaited one).
    pub stale: u64,
}

fn ipv4(ip: IpAddr) -> Result<u32, MasterError> {
    match ip {
        IpAddr::V4(v4) => Ok(u32::from(v4)),
        other => Err(MasterError::NotIpv4(other)),
    }
}

impl CyclicMaster {
    /// A master bound to `local` (its IP is the master ID) exchanging with the drive at
    /// `drive` (its IP is the station's slave ID).
    pub fn new(local: SocketAddr, drive: SocketAddr, p: MasterParams) -> Result<Self, MasterError> {
        let socket = UdpSocket::bind(local)?;
        let master_id = ipv4(socket.local_addr()?.ip())?;
        let mut station = [StationData::default(); MAX_STATIONS];
        station[0].slave_id = ipv4(drive.ip())?;
        Ok(CyclicMaster {
            socket,
            drive,
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
                stations: 1,
                station,
            },
            timeout: p.response_timeout,
            out: [0; 67 + 76],
            inbox: [0; 1500],
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
        let r = &mut self.request;
        r.sequence = r.sequence.wrapping_add(1);
        r.transmission = u16::from(transmit);
        r.station[0].words = *rww;
        r.station[0].bits = *ry;
        let n = r.encode(&mut self.out)?;
        self.socket.send_to(&self.out[..n], self.drive)?;
        let deadline = Instant::now() + self.timeout;
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return Err(MasterError::Timeout(self.timeout));
            }
            self.socket.set_read_timeout(Some(left))?;
            let k = match crate::reply_read::sort(self.socket.recv(&mut self.inbox), false)? {
                crate::reply_read::Read::Bytes(k) => k,
                crate::reply_read::Read::TimedOut => {
                    return Err(MasterError::Timeout(self.timeout))
                }
            };
            let Ok(response) = CyclicResponse::decode(&self.inbox[..k]) else {
                continue;
            };
            if response.sequence != self.request.sequence {
                self.stale += 1;
                continue;
            }
            if response.end_code != EndCode::Normal {
                return Err(MasterError::EndCode(response.end_code));
            }
            return Ok(response);
        }
    }
}
