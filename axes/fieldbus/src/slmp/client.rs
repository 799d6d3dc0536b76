//! An SLMP client for one MR-JE-C (MR-JE-C manual §2.4): binary 3E or 4E frames over UDP 5010
//! or TCP 5012, one request in flight (the drive serves one at a time, §2.4.1 POINT), a reply
//! deadline, and with 4E frames a serial number per request so that a late reply to an
//! earlier request is dropped.

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream, UdpSocket};
use std::time::{Duration, Instant};

use super::{
    decode_response, encode_request, Command, EndCode, Reply, Request, Route, SlmpError, Subheader,
    MAX_FRAME,
};

/// Why a client request failed.
#[derive(Debug, thiserror::Error)]
pub enum ClientError {
    /// The socket failed or the connection broke.
    #[error("SLMP {0}")]
    Io(#[from] std::io::Error),
    /// A frame was refused.
    #[error("SLMP: {0}")]
    Frame(#[from] SlmpError),
    /// The drive answered with an abnormal end code.
    #[error("SLMP: the drive answered {0}")]
    EndCode(EndCode),
    /// No reply before the deadline.
    #[error("SLMP: no reply within {0:?}")]
    Timeout(Duration),
}

/// The frame type a client sends.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FrameType {
    /// 3E: no serial number; over UDP a late reply cannot be told from the awaited one.
    E3,
    /// 4E: a serial number per request, echoed by the drive.
    #[default]
    E4,
}

enum Link {
    Udp(UdpSocket),
    Tcp(TcpStream),
}

/// A client of one drive's SLMP server.
pub struct SlmpClient {
    link: Link,
    frame: FrameType,
    serial: u16,
    route: Route,
    timeout: Duration,
    out: [u8; MAX_FRAME],
    inbox: Vec<u8>,
    /// The drive's software version, for typed object access (`crate::mr_je_c::access`).
    pub software: crate::mr_je_c::SoftwareVersion,
}

/// A normal reply's content, owned.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Answer {
    /// Upload: the value's bytes.
    Data(Vec<u8>),
    /// Download: the count echoed.
    Written,
    /// Model read: the name (trailing spaces removed) and the model code.
    Model(String, u16),
}

impl SlmpClient {
    /// A UDP client of `addr` (port 5010 on a drive).
    pub fn udp(addr: SocketAddr, frame: FrameType, timeout: Duration) -> Result<Self, ClientError> {
        let local: SocketAddr = if addr.is_ipv4() {
            "0.0.0.0:0".parse().expect("literal")
        } else {
            "[::]:0".parse().expect("literal")
        };
        Self::udp_from(local, addr, frame, timeout)
    }

    /// A UDP client of `addr` sending from `local` (the address a drive's IP rules judge).
    pub fn udp_from(
        local: SocketAddr,
        addr: SocketAddr,
        frame: FrameType,
        timeout: Duration,
    ) -> Result<Self, ClientError> {
        let socket = UdpSocket::bind(local)?;
        socket.connect(addr)?;
        Ok(Self::new(Link::Udp(socket), frame, timeout))
    }

    /// A TCP client of `addr` (port 5012 on a drive, one connection).
    pub fn tcp(addr: SocketAddr, frame: FrameType, timeout: Duration) -> Result<Self, ClientError> {
        let stream = TcpStream::connect_timeout(&addr, timeout)?;
        stream.set_nodelay(true)?;
        Ok(Self::new(Link::Tcp(stream), frame, timeout))
    }

    fn new(link: Link, frame: FrameType, timeout: Duration) -> Self {
        SlmpClient {
            link,
            frame,
            serial: 0,
            route: Route::default(),
            timeout,
            out: [0; MAX_FRAME],
            inbox: Vec::with_capacity(2 * MAX_FRAME),
            software: crate::mr_je_c::SoftwareVersion::default(),
        }
    }

    /// The amplifier's model name and model code (0101h).
    pub fn model(&mut self) -> Result<(String, u16), ClientError> {
        match self.request(Command::ModelRead)? {
            Answer::Model(name, code) => Ok((name, code)),
            _ => Err(ClientError::Frame(SlmpError::Mismatch { what: "command" })),
        }
    }

    /// Sends `command` and waits for its answer; an abnormal end code is an error.
    pub fn request(&mut self, command: Command<'_>) -> Result<Answer, ClientError> {
        self.serial = self.serial.wrapping_add(1);
        let request = Request {
            subheader: match self.frame {
                FrameType::E3 => Subheader::E3,
                FrameType::E4 => Subheader::E4 {
                    serial: self.serial.to_le_bytes(),
                },
            },
            route: self.route,
            monitoring_timer: super::monitoring_timer_for(self.timeout),
            command,
        };
        let n = encode_request(&request, &mut self.out)?;
        match &mut self.link {
            Link::Udp(s) => {
                s.send(&self.out[..n])?;
            }
            Link::Tcp(s) => s.write_all(&self.out[..n])?,
        }
        let deadline = Instant::now() + self.timeout;
        loop {
            if let Some(len) = self.next_frame(deadline)? {
                let frame: Vec<u8> = self.inbox.drain(..len).collect();
                match decode_response(&request, &frame) {
                    // A reply to an earlier request: dropped.
                    Err(SlmpError::Mismatch { what: "serial" }) => continue,
                    Err(e) => return Err(e.into()),
                    Ok(r) => return answer(r.reply),
                }
            }
        }
    }

    /// The length of the next whole frame in the inbox, reading until one is there.
    fn next_frame(&mut self, deadline: Instant) -> Result<Option<usize>, ClientError> {
        loop {
            if let Some(len) = frame_length(&self.inbox)? {
                if self.inbox.len() >= len {
                    return Ok(Some(len));
                }
            }
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return Err(ClientError::Timeout(self.timeout));
            }
            let mut chunk = [0u8; MAX_FRAME];
            let got = match &mut self.link {
                Link::Udp(s) => {
                    s.set_read_timeout(Some(left))?;
                    // A datagram is one frame: drop whatever is left of a bad one.
                    self.inbox.clear();
                    s.recv(&mut chunk)
                }
                Link::Tcp(s) => {
                    s.set_read_timeout(Some(left))?;
                    s.read(&mut chunk)
                }
            };
            let stream = matches!(self.link, Link::Tcp(_));
            match crate::reply_read::sort(got, stream)? {
                crate::reply_read::Read::Bytes(k) => self.inbox.extend_from_slice(&chunk[..k]),
                crate::reply_read::Read::TimedOut => {
                    return Err(ClientError::Timeout(self.timeout))
                }
            }
        }
    }
}

/// The total length of the SLMP frame (request or response) starting `bytes`, once its header
/// is there; a subheader that is no SLMP binary frame's is an error (the stream has lost its
/// framing).
pub fn frame_length(bytes: &[u8]) -> Result<Option<usize>, SlmpError> {
    let Some(sh) = bytes.first_chunk::<2>() else {
        return Ok(None);
    };
    let at = match sh {
        [0xD0, 0x00] | [0x50, 0x00] => 2,
        [0xD4, 0x00] | [0x54, 0x00] => 6,
        _ => return Err(SlmpError::Subheader(*sh)),
    };
    let Some(len) = bytes.get(at + 5..at + 7) else {
        return Ok(None);
    };
    let total = at + 7 + usize::from(u16::from_le_bytes([len[0], len[1]]));
    if total > MAX_FRAME {
        return Err(SlmpError::Truncated {
            got: MAX_FRAME,
            need: total,
        });
    }
    Ok(Some(total))
}

fn answer(reply: Reply<'_>) -> Result<Answer, ClientError> {
    Ok(match reply {
        Reply::Upload { data, .. } => Answer::Data(data.to_vec()),
        Reply::Download { .. } => Answer::Written,
        Reply::Model { name, code } => {
            Answer::Model(String::from_utf8_lossy(&name).trim_end().to_string(), code)
        }
        Reply::Error { code, .. } => return Err(ClientError::EndCode(code)),
    })
}
